/* test_natural_own.c -- own-plane rows of the k-NN form (issue 15.2,
 * docs/natural.md "Own-plane rings"), against the on-the-fly cells of the
 * public jf_natural_rings:
 *  - each vertex's row is its first ring in its own plane (clean and
 *    0.3%-noisy ellipsoid, exact normals);
 *  - ring 2 of jf__natural_neighbors_own is the union of its ring 1's
 *    rows less what is collected; a ring kept whole comes in row order,
 *    the cut one by (distance, coordinates);
 *  - the rows and the rings are the same on 1 and 3 threads;
 *  - a cell with more neighbours than a row holds (12 around a point)
 *    and a vertex without a plane (zero normal) are made when asked. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "jetfit.h"

#define JF_TEST_SEED 0x9E3779B97F4A7C15ull
#include "test_rand.h"
#include "jf_test.h"

#define CAP 512

/* i's first ring in its own plane, made on the fly (the public API) */
static size_t ring1(const jf_natural *nt, jf_natural_ws *ws, size_t i, const double *nrm, uint32_t *idx) {
    size_t found = 0, end[2];
    ck_assert_int_eq(jf_natural_rings(nt, ws, i, nrm + 3 * i, 1, idx, CAP, &found, end), JF_OK);
    return end[1];
}

static const double *g_p, *g_o; /* qsort's key: distance to g_o, then x, y, z */
static int by_dist(const void *a, const void *b) {
    const double *p = g_p + 3 * (size_t)*(const uint32_t *)a, *q = g_p + 3 * (size_t)*(const uint32_t *)b;
    double dp = (p[0] - g_o[0]) * (p[0] - g_o[0]) + (p[1] - g_o[1]) * (p[1] - g_o[1]) + (p[2] - g_o[2]) * (p[2] - g_o[2]);
    double dq = (q[0] - g_o[0]) * (q[0] - g_o[0]) + (q[1] - g_o[1]) * (q[1] - g_o[1]) + (q[2] - g_o[2]) * (q[2] - g_o[2]);
    if (dp != dq) return dp < dq ? -1 : 1;
    for (int c = 0; c < 3; c++)
        if (p[c] != q[c]) return p[c] < q[c] ? -1 : 1;
    return 0;
}

/* a[0..m) and b[0..m) hold the same vertices (sorted in place by_dist) */
static void same_set(uint32_t *a, uint32_t *b, size_t m) {
    qsort(a, m, sizeof *a, by_dist);
    qsort(b, m, sizeof *b, by_dist);
    ck_assert_mem_eq(a, b, m * sizeof *a);
}

static void check_cloud(double sigma) {
    enum { n = 3000 };
    double *p = malloc(3 * n * sizeof *p), *nrm = malloc(3 * n * sizeof *nrm);
    ellipsoid(n, sigma, p, nrm);
    jf_natural *nt, *n3;
    jf_natural_ws *ws, *w3;
    ck_assert_int_eq(jf_natural_create_knn(p, n, 1, &nt), JF_OK);
    ck_assert_int_eq(jf_natural_create_knn(p, n, 3, &n3), JF_OK);
    ck_assert_int_eq(jf__natural_own_rows(nt, 1, nrm), JF_OK);
    ck_assert_int_eq(jf__natural_own_rows(n3, 3, nrm), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(n3, &w3), JF_OK);
    uint32_t r1[CAP], ru[CAP], own[CAP], own3[CAP], want[CAP];
    unsigned char *seen = calloc(n, 1);
    for (size_t i = 0; i < n; i++) {
        size_t m1 = ring1(nt, ws, i, nrm, r1), f = 0, f3 = 0;
        g_p = p, g_o = p + 3 * i;
        /* ring 1: the row */
        ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, m1, own, CAP, &f), JF_OK);
        ck_assert_uint_eq(f, m1);
        ck_assert_uint_eq(own[0], i);
        same_set(own + 1, r1 + 1, m1 - 1);
        /* ring 2: the rows of ring 1, less what is collected */
        size_t m2 = 0;
        for (size_t k = 0; k < m1; k++) seen[r1[k]] = 1;
        for (size_t k = 1; k < m1; k++) {
            size_t mu = ring1(nt, ws, r1[k], nrm, ru);
            for (size_t j = 1; j < mu; j++)
                if (!seen[ru[j]]) seen[ru[j]] = 1, want[m2++] = ru[j];
        }
        for (size_t k = 0; k < m1; k++) seen[r1[k]] = 0;
        for (size_t k = 0; k < m2; k++) seen[want[k]] = 0;
        qsort(want, m2, sizeof *want, by_dist);
        ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, m1 + m2, own, CAP, &f), JF_OK);
        ck_assert_uint_eq(f, m1 + m2);
        same_set(own + m1, want, m2); /* whole: row order */
        if (m2 > 1) { /* cut by one: the nearest of it, in order */
            ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, m1 + m2 - 1, own, CAP, &f), JF_OK);
            ck_assert_uint_eq(f, m1 + m2 - 1);
            ck_assert_mem_eq(own + m1, want, (m2 - 1) * sizeof *own);
        }
        /* 3 threads: the same rings (N = 64: several rings) */
        ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, 64, own, CAP, &f), JF_OK);
        ck_assert_int_eq(jf__natural_neighbors_own(n3, w3, i, nrm + 3 * i, 64, own3, CAP, &f3), JF_OK);
        ck_assert_uint_eq(f, 64);
        ck_assert_uint_eq(f3, f);
        ck_assert_mem_eq(own, own3, f * sizeof *own);
    }
    free(seen);
    jf_natural_ws_free(ws);
    jf_natural_ws_free(w3);
    jf_natural_free(nt);
    jf_natural_free(n3);
    free(p);
    free(nrm);
}

START_TEST(clean_rows) { check_cloud(0); }
END_TEST

START_TEST(noisy_rows) { check_cloud(0.003); }
END_TEST

/* Point 0 at the centre of 12 on a circle (a cell of 12 edges, more than
 * a row's 10), a grid around them; point 1 has a zero normal (no plane,
 * no row).  Ring 1 of 0 is the circle; 1's row is made in the asking
 * point's plane when a ring reaches it, as on the fly. */
START_TEST(live_rows) {
    enum { nc = 12, ng = 15 };
    const size_t n = 1 + nc + ng * ng;
    double *p = calloc(3 * n, sizeof *p), *nrm = calloc(3 * n, sizeof *nrm);
    for (size_t k = 0; k < nc; k++)
        p[3 * (1 + k)] = 0.1 * cos(2 * M_PI * k / nc), p[3 * (1 + k) + 1] = 0.1 * sin(2 * M_PI * k / nc);
    for (size_t a = 0; a < ng; a++)
        for (size_t b = 0; b < ng; b++) {
            double *q = p + 3 * (1 + nc + a * ng + b);
            q[0] = 0.17 * ((double)a - 7) + 0.01, q[1] = 0.17 * ((double)b - 7) + 0.013;
            if (fabs(q[0]) < 0.2 && fabs(q[1]) < 0.2) q[0] += 0.35; /* off the circle */
        }
    for (size_t i = 0; i < n; i++) nrm[3 * i + 2] = 1;
    nrm[3 * 1 + 2] = 0; /* vertex of point 1: no plane */
    jf_natural *nt;
    jf_natural_ws *ws;
    ck_assert_int_eq(jf_natural_create_knn(p, n, 2, &nt), JF_OK);
    ck_assert_int_eq(jf__natural_own_rows(nt, 2, nrm), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
    uint32_t own[CAP], fly[CAP];
    size_t f = 0;
    ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, 0, nrm, 1 + nc, own, CAP, &f), JF_OK);
    ck_assert_uint_eq(f, 1 + nc);
    unsigned mask = 0;
    for (size_t k = 1; k < f; k++) {
        ck_assert(own[k] >= 1 && own[k] <= nc);
        mask |= 1u << (own[k] - 1);
    }
    ck_assert_uint_eq(mask, (1u << nc) - 1);
    /* every point's rings 1 and 2 (through the two LIVE rows): as on the
     * fly, each vertex's cell in the one plane z = const (nz: point 1's
     * too, where the asking point's plane is that plane) */
    double *nz = calloc(3 * n, sizeof *nz);
    for (size_t i = 0; i < n; i++) nz[3 * i + 2] = 1;
    unsigned char *seen = calloc(n, 1);
    uint32_t ru[CAP], want[CAP];
    for (size_t i = 0; i < n; i++) {
        if (i == 1) continue;
        size_t m1 = ring1(nt, ws, i, nz, fly), m2 = 0;
        for (size_t k = 0; k < m1; k++) seen[fly[k]] = 1;
        for (size_t k = 1; k < m1; k++) {
            size_t mu = ring1(nt, ws, fly[k], nz, ru);
            for (size_t j = 1; j < mu; j++)
                if (!seen[ru[j]]) seen[ru[j]] = 1, want[m2++] = ru[j];
        }
        memset(seen, 0, n);
        g_p = p, g_o = p + 3 * i;
        qsort(want, m2, sizeof *want, by_dist);
        ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, i, nrm + 3 * i, m1 + m2, own, CAP, &f), JF_OK);
        ck_assert_uint_eq(f, m1 + m2);
        ck_assert_uint_eq(own[0], i);
        same_set(own + 1, fly + 1, m1 - 1);
        same_set(own + m1, want, m2);
    }
    free(seen);
    free(nz);
    /* point 1 itself: no plane (its caller checks the planes, and the
     * pipeline flags such a point failed): itself only, where
     * jf_natural_neighbors refuses */
    ck_assert_int_eq(jf__natural_neighbors_own(nt, ws, 1, nrm + 3, 16, own, CAP, &f), JF_OK);
    ck_assert_uint_eq(f, 1);
    ck_assert_int_eq(jf_natural_neighbors(nt, ws, 1, nrm + 3, 16, own, CAP, &f), JF_ERR_INVALID);
    jf_natural_ws_free(ws);
    jf_natural_free(nt);
    free(p);
    free(nrm);
}
END_TEST

int main(void) {
    Suite *s = suite_create("natural_own");
    TCase *tc = tcase_create("rows");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, clean_rows);
    tcase_add_test(tc, noisy_rows);
    tcase_add_test(tc, live_rows);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
