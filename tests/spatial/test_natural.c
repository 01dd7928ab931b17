/* test_natural.c -- natural neighbourhoods: degenerate input (fewer than 4
 * points, collinear, duplicates, NaN), the fallback on noise, thread
 * invariance, ring growth and truncation. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static const double kPi = 3.14159265358979323846;

static uint64_t rng_state = 88172645463325252ull;
static double urand(void) { /* xorshift64*, [0, 1) */
    rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}
static double grand(void) {
    double u = urand() + 1e-300, v = urand();
    return sqrt(-2 * log(u)) * cos(2 * kPi * v);
}

static double angle_deg(const double *a, const double *b) {
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                 fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])) * 180 / kPi;
}

/* n samples of the §6.1 surface z = 0.1 exp(2u + v - v^2) on [-0.5,0.5]^2
 * with normal noise sigma along the exact normal; nrm gets the exact
 * normals. */
static void surface(size_t n, double sigma, double *p, double *nrm) {
    for (size_t i = 0; i < n; i++) {
        double x = urand() - 0.5, y = urand() - 0.5, z = 0.1 * exp(2 * x + y - y * y);
        double fx = 2 * z, fy = (1 - 2 * y) * z, l = sqrt(fx * fx + fy * fy + 1);
        double t[3] = {-fx / l, -fy / l, 1 / l}, e = sigma * grand();
        p[3 * i] = x + e * t[0], p[3 * i + 1] = y + e * t[1], p[3 * i + 2] = z + e * t[2];
        memcpy(nrm + 3 * i, t, sizeof t);
    }
}

static void sphere(size_t n, double *p) {
    for (size_t i = 0; i < n; i++) {
        double v[3] = {grand(), grand(), grand()}, l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int k = 0; k < 3; k++) p[3 * i + k] = v[k] / l;
    }
}

/* 0..3 points and a collinear cloud: a status per point, no crash. */
START_TEST(tiny_and_collinear) {
    const double tri[9] = {0, 0, 0, 1, 0, 0, 0, 2, 0};
    for (size_t n = 0; n <= 3; n++) {
        jf_natural *nt;
        ck_assert_int_eq(jf_natural_create(n ? tri : NULL, n, &nt), JF_OK);
        jf_natural_stats st;
        jf_natural_get_stats(nt, &st);
        ck_assert_int_eq(st.dimension, (int)n - 1);
        double nrm[9];
        unsigned fl[3] = {0, 0, 0};
        ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 1, nrm, fl, NULL), JF_OK);
        for (size_t i = 0; i < n; i++) {
            if (n < 3) {
                ck_assert_uint_eq(fl[i], JF_PT_FAILED);
                ck_assert(isnan(nrm[3 * i]));
            } else { /* a triangle: its normal, by the fallback */
                ck_assert_uint_eq(fl[i], JF_PT_NORMAL_MINCIRC | JF_PT_NORMAL_FALLBACK);
                ck_assert_double_eq_tol(fabs(nrm[3 * i + 2]), 1.0, 1e-15);
            }
        }
        jf_natural_ws *ws;
        ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
        uint32_t idx[8];
        size_t found = 99;
        const double z[3] = {0, 0, 1};
        if (n == 0) ck_assert_int_eq(jf_natural_neighbors(nt, ws, 0, z, 4, idx, 8, &found), JF_ERR_INVALID);
        for (size_t i = 0; i < n; i++) {
            ck_assert_int_eq(jf_natural_neighbors(nt, ws, i, z, 8, idx, 8, &found), JF_OK);
            ck_assert_uint_eq(found, n); /* the whole cloud, fewer than asked */
            ck_assert_uint_eq(idx[0], i);
        }
        jf_natural_ws_free(ws);
        jf_natural_free(nt);
    }
    double line[30];
    for (int i = 0; i < 10; i++) line[3 * i] = i, line[3 * i + 1] = 2.0 * i, line[3 * i + 2] = -1.0 * i;
    jf_natural *nt;
    ck_assert_int_eq(jf_natural_create(line, 10, &nt), JF_OK);
    double nrm[30];
    unsigned fl[10] = {0};
    ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_MINCIRC, 1, nrm, fl, NULL), JF_OK);
    for (int i = 0; i < 10; i++) ck_assert(fl[i] == JF_PT_FAILED && isnan(nrm[3 * i + 1]));
    jf_natural_free(nt);
    ck_assert_int_eq(jf_natural_create(NULL, 3, &nt), JF_ERR_INVALID);
}
END_TEST

/* A sphere with 100 exact duplicates and 5 NaN points: duplicates merged
 * and mapped to the kept point, NaN points flagged, the rest exact. */
START_TEST(duplicates_and_nan) {
    const size_t n0 = 3000, nd = 100, nn = 5, n = n0 + nd + nn;
    double *p = malloc(3 * n * sizeof *p), *nrm = malloc(3 * n * sizeof *nrm);
    rng_state = 88172645463325252ull;
    sphere(n0, p);
    for (size_t k = 0; k < nd; k++) memcpy(p + 3 * (n0 + k), p + 3 * (7 * k), 3 * sizeof *p);
    for (size_t k = 0; k < nn; k++) {
        double *q = p + 3 * (n0 + nd + k);
        q[0] = 1, q[1] = k == 0 ? NAN : 0.5, q[2] = k == 0 ? 0 : (k % 2 ? INFINITY : -INFINITY);
    }
    jf_natural *nt;
    ck_assert_int_eq(jf_natural_create(p, n, &nt), JF_OK);
    jf_natural_stats st;
    jf_natural_get_stats(nt, &st);
    ck_assert_int_eq(st.dimension, 3);
    ck_assert_uint_eq(st.nvertices, n0);
    ck_assert_uint_eq(st.nduplicates, nd);
    ck_assert_uint_eq(st.nnonfinite, nn);
    for (size_t k = 0; k < nd; k++) {
        ck_assert_uint_eq(jf_natural_kept(nt, n0 + k), 7 * k);
        ck_assert_uint_eq(jf_natural_kept(nt, 7 * k), 7 * k);
    }
    ck_assert_uint_eq(jf_natural_kept(nt, n0 + nd), SIZE_MAX);
    ck_assert_uint_eq(jf_natural_kept(nt, n), SIZE_MAX);
    unsigned *fl = calloc(n, sizeof *fl);
    ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 2, nrm, fl, NULL), JF_OK);
    for (size_t i = 0; i < n0 + nd; i++) {
        ck_assert_uint_eq(fl[i], JF_PT_NORMAL_POLES);
        ck_assert_double_lt(angle_deg(nrm + 3 * i, p + 3 * i), 1e-6); /* cospherical: exact */
    }
    for (size_t i = n0 + nd; i < n; i++) {
        ck_assert_uint_eq(fl[i], JF_PT_FAILED | JF_PT_NONFINITE);
        ck_assert(isnan(nrm[3 * i]) && isnan(nrm[3 * i + 1]) && isnan(nrm[3 * i + 2]));
    }
    jf_natural_ws *ws;
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
    uint32_t a[20], b[20];
    size_t fa, fb;
    for (size_t k = 0; k < nd; k++) { /* a duplicate has its twin's neighbourhood */
        ck_assert_int_eq(jf_natural_neighbors(nt, ws, n0 + k, nrm + 3 * (n0 + k), 20, a, 20, &fa), JF_OK);
        ck_assert_int_eq(jf_natural_neighbors(nt, ws, 7 * k, nrm + 3 * 7 * k, 20, b, 20, &fb), JF_OK);
        ck_assert_uint_eq(fa, 20);
        ck_assert_uint_eq(fb, 20);
        ck_assert_uint_eq(a[0], n0 + k);
        ck_assert_uint_eq(b[0], 7 * k);
        ck_assert_mem_eq(a + 1, b + 1, 19 * sizeof *a);
    }
    for (size_t i = 0; i < n0 + nd; i += 13) { /* never a merged twin nor a NaN point */
        ck_assert_int_eq(jf_natural_neighbors(nt, ws, i, nrm + 3 * i, 20, a, 20, &fa), JF_OK);
        for (size_t k = 1; k < fa; k++) ck_assert(a[k] < n0 && a[k] != i);
    }
    const double z[3] = {0, 0, 1};
    ck_assert_int_eq(jf_natural_neighbors(nt, ws, n - 1, z, 20, a, 20, &fa), JF_OK);
    ck_assert_uint_eq(fa, 0);
    const double zero[3] = {0, 0, 0};
    ck_assert_int_eq(jf_natural_neighbors(nt, ws, 0, zero, 20, a, 20, &fa), JF_ERR_INVALID);
    jf_natural_ws_free(ws);
    jf_natural_free(nt);
    free(p), free(nrm), free(fl);
}
END_TEST

/* Clean §6.1 patch: the fallback engages only at the rim; noisy patch:
 * it engages exactly where the pole is unreliable, never NaN, and the
 * combined normals beat mincirc alone. */
START_TEST(fallback_where_it_should) {
    const size_t n = 5000;
    double *p = malloc(3 * n * sizeof *p), *t = malloc(3 * n * sizeof *t);
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b), *rel = malloc(n * sizeof *rel);
    unsigned *fa = calloc(n, sizeof *fa), *fb = calloc(n, sizeof *fb);
    const double spacing = 1.0 / sqrt((double)n);
    rng_state = 88172645463325252ull; /* same data with or without CK_FORK */
    for (int noisy = 0; noisy < 2; noisy++) {
        surface(n, noisy ? 0.3 * spacing : 0.0, p, t);
        jf_natural *nt;
        ck_assert_int_eq(jf_natural_create(p, n, &nt), JF_OK);
        memset(fa, 0, n * sizeof *fa), memset(fb, 0, n * sizeof *fb);
        ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 2, a, fa, rel), JF_OK);
        ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_MINCIRC, 1, b, fb, NULL), JF_OK);
        size_t nfall = 0, inner_fall = 0;
        double ea = 0, eb = 0, worst_inner = 0;
        for (size_t i = 0; i < n; i++) {
            ck_assert(isfinite(a[3 * i]) && isfinite(a[3 * i + 1]) && isfinite(a[3 * i + 2]));
            int fall = (fa[i] & JF_PT_NORMAL_FALLBACK) != 0;
            ck_assert_int_eq(fall, rel[i] < JF_NATURAL_MIN_RELIABILITY);
            ck_assert_uint_eq(fa[i], fall ? JF_PT_NORMAL_MINCIRC | JF_PT_NORMAL_FALLBACK : JF_PT_NORMAL_POLES);
            if (fall) ck_assert_mem_eq(a + 3 * i, b + 3 * i, 3 * sizeof *a);
            nfall += fall;
            double rim = 0.5 - fmax(fabs(p[3 * i]), fabs(p[3 * i + 1]));
            int inner = rim > 3 * spacing;
            if (inner) inner_fall += fall, worst_inner = fmax(worst_inner, angle_deg(a + 3 * i, t + 3 * i));
            ea += angle_deg(a + 3 * i, t + 3 * i), eb += angle_deg(b + 3 * i, t + 3 * i);
        }
        printf("%s patch: %zu fallbacks (%zu inside), mean error poles+fallback %.2f deg, mincirc %.2f deg\n",
               noisy ? "noisy" : "clean", nfall, inner_fall, ea / n, eb / n);
        if (!noisy) {
            ck_assert_uint_gt(nfall, 0);         /* the rim */
            ck_assert_uint_eq(inner_fall, 0);
            ck_assert_double_lt(worst_inner, 2.0); /* poles inside a clean patch */
        } else {
            ck_assert_uint_gt(nfall, 0);
            ck_assert_double_lt(ea, 0.5 * eb);
        }
        jf_natural_free(nt);
    }
    free(p), free(t), free(a), free(b), free(rel), free(fa), free(fb);
}
END_TEST

/* Normals identical for 1 and 2 threads; rings: growth, truncation to N
 * nearest-first in the last ring, a reused workspace equals a fresh one. */
START_TEST(threads_and_rings) {
    const size_t n = 4000;
    double *p = malloc(3 * n * sizeof *p), *t = malloc(3 * n * sizeof *t);
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    unsigned *fa = calloc(n, sizeof *fa), *fb = calloc(n, sizeof *fb);
    rng_state = 88172645463325252ull;
    surface(n, 0.0, p, t);
    jf_natural *nt;
    ck_assert_int_eq(jf_natural_create(p, n, &nt), JF_OK);
    ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 1, a, fa, NULL), JF_OK);
    ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 2, b, fb, NULL), JF_OK);
    ck_assert_mem_eq(a, b, 3 * n * sizeof *a);
    ck_assert_mem_eq(fa, fb, n * sizeof *fa);
    jf_natural_ws *ws, *ws2;
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws2), JF_OK);
    uint32_t full[512], cut[64], again[64];
    size_t ends[4], nf, nc, na;
    for (size_t i = 0; i < n; i += 37) {
        ck_assert_int_eq(jf_natural_rings(nt, ws, i, a + 3 * i, 3, full, 512, &nf, ends), JF_OK);
        ck_assert_uint_eq(ends[0], 1);
        ck_assert(ends[1] >= 4 && ends[1] < ends[2] && ends[2] < ends[3] && ends[3] == nf);
        for (size_t N = 2; N <= 40; N += 7) {
            ck_assert_int_eq(jf_natural_neighbors(nt, ws, i, a + 3 * i, N, cut, 64, &nc), JF_OK);
            ck_assert_int_eq(jf_natural_neighbors(nt, ws2, i, a + 3 * i, N, again, 64, &na), JF_OK);
            ck_assert_uint_eq(nc, N);
            ck_assert_uint_eq(na, N);
            ck_assert_mem_eq(cut, again, N * sizeof *cut);
            /* the cut is a prefix of the complete rings when N falls in ring 1..3 */
            if (N <= nf) ck_assert_mem_eq(cut, full, N * sizeof *cut);
        }
        /* nearest first within each ring */
        for (int r = 1; r <= 3; r++)
            for (size_t k = ends[r - 1] + 1; k < ends[r]; k++) {
                const double *q = p + 3 * i, *u = p + 3 * (size_t)full[k - 1], *v = p + 3 * (size_t)full[k];
                double du = 0, dv = 0;
                for (int c = 0; c < 3; c++) du += (u[c] - q[c]) * (u[c] - q[c]), dv += (v[c] - q[c]) * (v[c] - q[c]);
                ck_assert(du <= dv);
            }
    }
    ck_assert_int_eq(jf_natural_rings(nt, ws, 0, a, 3, full, 5, &nf, ends), JF_ERR_TOO_LARGE);
    jf_natural_ws_free(ws);
    jf_natural_ws_free(ws2);
    jf_natural_free(nt);
    free(p), free(t), free(a), free(b), free(fa), free(fb);
}
END_TEST

/* The rim of an open patch (clean §6.1 samples): natural:64's normals
 * there stay within a degree of the exact ones, near knn:64's.  With the
 * unbounded rim cells clipped far out (1e3 x the reach) the rings ran
 * along the rim and the rim's RMS error was 6-10 deg (natural.c). */
START_TEST(open_patch_rim) {
    const size_t n = 8000;
    double *p = malloc(3 * n * sizeof *p), *t = malloc(3 * n * sizeof *t);
    jf_result *r = malloc(n * sizeof *r);
    rng_state = 88172645463325252ull;
    surface(n, 0.0, p, t);
    double rms[2];
    for (int kind = 0; kind < 2; kind++) {
        jf_cloud cl = {.n = n, .xyz = p};
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        o.nb.kind = kind ? JF_NB_NATURAL : JF_NB_KNN;
        o.nb.k = o.nb.n = 64;
        o.threads = 1;
        jf_error e;
        ck_assert_int_eq(jf_estimate(&cl, &o, r, &e), JF_OK);
        double s = 0;
        size_t m = 0;
        for (size_t i = 0; i < n; i++) {
            double x = p[3 * i], y = p[3 * i + 1];
            if (fabs(x) < 0.47 && fabs(y) < 0.47) continue; /* the rim: 3% of the side */
            double a = angle_deg(r[i].normal, t + 3 * i);
            s += a * a, m++;
        }
        ck_assert_uint_gt(m, 500);
        rms[kind] = sqrt(s / (double)m);
    }
    printf("open patch rim, normal RMS: knn:64 %.4f deg, natural:64 %.4f deg\n", rms[0], rms[1]);
    ck_assert(rms[1] < 1.0);
    ck_assert(rms[1] < 20 * rms[0] + 0.05);
    free(p), free(t), free(r);
}
END_TEST

static Suite *natural_suite(void) {
    Suite *s = suite_create("natural");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, tiny_and_collinear);
    tcase_add_test(tc, duplicates_and_nan);
    tcase_add_test(tc, fallback_where_it_should);
    tcase_add_test(tc, threads_and_rings);
    tcase_add_test(tc, open_patch_rim);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) {
    return jf_test_run(natural_suite());
}
