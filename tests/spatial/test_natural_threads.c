/* test_natural_threads.c -- natural neighbourhoods do not depend on the
 * thread count nor on how the triangulation was built (issue 15.2):
 *  - jf_estimate natural:16 on 1, 2 and 3 threads (and twice on 2), bit for
 *    bit, on a random surface sample and on a grid cloud;
 *  - the bridge's arrays (map, adjacency, poles, hull directions) bit for
 *    bit for 1, 2, 3 threads;
 *  - on a grid over the surface of a cube (cospherical points everywhere:
 *    the Delaunay triangulation is not unique without CGAL's symbolic
 *    perturbation), the same cloud in another input order (hence another
 *    insertion order, other vertex ids, another memory layout) gives the
 *    same Delaunay neighbour sets, the same poles and the same natural
 *    neighbourhoods, point for point, bit for bit. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cgal_bridge.h"
#include "jetfit.h"
#include "jf_test.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void) { /* xorshift64*, [0, 1) */
    rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* n random points of the ellipsoid x^2 + (y/.75)^2 + (z/.5)^2 = 1 */
static double *ellipsoid(size_t n) {
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; i++) {
        double z = 2 * urand() - 1, t = 2 * 3.14159265358979 * urand(), r = sqrt(1 - z * z);
        p[3 * i] = r * cos(t), p[3 * i + 1] = 0.75 * r * sin(t), p[3 * i + 2] = 0.5 * z;
    }
    return p;
}

/* The surface of the cube [0, m]^3 sampled on the integer grid: every
 * point once; nrm gets the normal of the first face found (edges and
 * corners: any of theirs, the same in every order). */
static size_t cube_grid(int m, double **pp, double **nn) {
    size_t cap = 6 * (size_t)(m + 1) * (m + 1), n = 0;
    double *p = malloc(3 * cap * sizeof *p), *nr = malloc(3 * cap * sizeof *nr);
    for (int x = 0; x <= m; x++)
        for (int y = 0; y <= m; y++)
            for (int z = 0; z <= m; z++) {
                int c[3] = {x, y, z}, face = -1;
                for (int k = 0; k < 3 && face < 0; k++)
                    if (c[k] == 0 || c[k] == m) face = k;
                if (face < 0) continue;
                for (int k = 0; k < 3; k++) {
                    p[3 * n + k] = c[k];
                    nr[3 * n + k] = k == face ? (c[k] == 0 ? -1 : 1) : 0;
                }
                n++;
            }
    *pp = p, *nn = nr;
    return n;
}

static jf_result *estimate(const double *p, size_t n, int threads) {
    jf_cloud c;
    memset(&c, 0, sizeof c);
    c.n = n;
    c.xyz = (double *)p; /* jf_cloud's xyz is not const; estimate does not write it */
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = JF_NB_NATURAL;
    o.nb.n = 16;
    o.normal = JF_NORMAL_POLES;
    o.threads = threads;
    jf_result *r = calloc(n, sizeof *r);
    jf_error err;
    ck_assert_int_eq(jf_estimate(&c, &o, r, &err), JF_OK);
    return r;
}

/* field by field (the struct has padding) */
static int same_result(const jf_result *a, const jf_result *b) {
    return a->status == b->status && a->degree == b->degree && a->n_used == b->n_used &&
           !memcmp(&a->cond, &b->cond, sizeof a->cond) &&
           !memcmp(&a->residual, &b->residual, sizeof a->residual) &&
           !memcmp(a->pca_eval, b->pca_eval, sizeof a->pca_eval) &&
           !memcmp(a->normal, b->normal, sizeof a->normal) && !memcmp(&a->k1, &b->k1, sizeof a->k1) &&
           !memcmp(&a->k2, &b->k2, sizeof a->k2) && !memcmp(a->d1, b->d1, sizeof a->d1) &&
           !memcmp(a->d2, b->d2, sizeof a->d2) && !memcmp(a->b, b->b, sizeof a->b) &&
           !memcmp(a->c, b->c, sizeof a->c);
}

static void check_threads(const double *p, size_t n) {
    jf_result *r1 = estimate(p, n, 1);
    size_t ok = 0;
    for (size_t i = 0; i < n; i++) ok += !(r1[i].status & JF_PT_FAILED) && isfinite(r1[i].k1);
    ck_assert_uint_gt(ok, n * 9 / 10); /* the comparison below compares results */
    for (int t = 2; t <= 4; t++) {
        jf_result *rt = estimate(p, n, t == 4 ? 2 : t);
        for (size_t i = 0; i < n; i++)
            if (!same_result(&r1[i], &rt[i])) ck_abort_msg("point %zu differs at %d threads", i, t == 4 ? 2 : t);
        free(rt);
    }
    free(r1);
}

START_TEST(estimate_random_threads) {
    size_t n = 4000;
    double *p = ellipsoid(n);
    check_threads(p, n);
    free(p);
}
END_TEST

START_TEST(estimate_grid_threads) {
    double *p, *nr;
    size_t n = cube_grid(12, &p, &nr);
    check_threads(p, n);
    free(p), free(nr);
}
END_TEST

static void same_bridge(const jfb_delaunay *a, const jfb_delaunay *b) {
    ck_assert_uint_eq(a->nv, b->nv);
    ck_assert_int_eq(a->dimension, b->dimension);
    ck_assert(!memcmp(a->vertex_of, b->vertex_of, a->n * sizeof *a->vertex_of));
    ck_assert(!memcmp(a->rep, b->rep, a->nv * sizeof *a->rep));
    ck_assert(!memcmp(a->adj_off, b->adj_off, (a->nv + 1) * sizeof *a->adj_off));
    ck_assert(!memcmp(a->adj, b->adj, a->adj_off[a->nv] * sizeof *a->adj));
    ck_assert(!memcmp(a->pole, b->pole, 3 * a->nv * sizeof *a->pole));
    ck_assert(!memcmp(a->hull, b->hull, 3 * a->nv * sizeof *a->hull));
}

START_TEST(bridge_threads) {
    size_t n = 3000;
    double *p = ellipsoid(n), *g, *gn;
    size_t ng = cube_grid(9, &g, &gn);
    for (int c = 0; c < 2; c++) {
        const double *q = c ? g : p;
        size_t nq = c ? ng : n;
        jfb_delaunay d1, dt;
        ck_assert_int_eq(jfb_delaunay_build(q, nq, 1, &d1), 0);
        ck_assert_int_eq(d1.dimension, 3);
        for (int t = 2; t <= 3; t++) {
            ck_assert_int_eq(jfb_delaunay_build(q, nq, t, &dt), 0);
            same_bridge(&d1, &dt);
            jfb_delaunay_release(&dt);
        }
        jfb_delaunay_release(&d1);
    }
    free(p), free(g), free(gn);
}
END_TEST

/* the Delaunay neighbours of input i as coordinates, in the bridge's order */
static void nbr_coords(const jfb_delaunay *d, const double *p, size_t i, double *out, size_t *len) {
    uint32_t v = d->vertex_of[i];
    *len = 0;
    for (size_t k = d->adj_off[v]; k < d->adj_off[v + 1]; k++, (*len)++)
        memcpy(out + 3 * *len, p + 3 * (size_t)d->rep[d->adj[k]], 3 * sizeof(double));
}

START_TEST(grid_any_order) {
    double *p, *nr;
    size_t n = cube_grid(10, &p, &nr);
    /* another order: a fixed random permutation; q[j] = p[perm[j]] */
    size_t *perm = malloc(n * sizeof *perm), *inv = malloc(n * sizeof *inv);
    for (size_t i = 0; i < n; i++) perm[i] = i;
    for (size_t i = n - 1; i > 0; i--) {
        size_t j = (size_t)(urand() * (double)(i + 1)), t = perm[i];
        perm[i] = perm[j], perm[j] = t;
    }
    double *q = malloc(3 * n * sizeof *q), *qn = malloc(3 * n * sizeof *qn);
    for (size_t j = 0; j < n; j++) {
        inv[perm[j]] = j;
        memcpy(q + 3 * j, p + 3 * perm[j], 3 * sizeof(double));
        memcpy(qn + 3 * j, nr + 3 * perm[j], 3 * sizeof(double));
    }
    jfb_delaunay a, b;
    ck_assert_int_eq(jfb_delaunay_build(p, n, 2, &a), 0);
    ck_assert_int_eq(jfb_delaunay_build(q, n, 2, &b), 0);
    ck_assert_int_eq(a.dimension, 3);
    ck_assert_uint_eq(a.nv, n);
    double *ca = malloc(3 * n * sizeof *ca), *cb = malloc(3 * n * sizeof *cb);
    int differ = 0;
    for (size_t i = 0; i < n; i++) {
        size_t la, lb, j = inv[i];
        nbr_coords(&a, p, i, ca, &la);
        nbr_coords(&b, q, j, cb, &lb);
        ck_assert_uint_eq(la, lb);
        ck_assert(!memcmp(ca, cb, 3 * la * sizeof *ca));
        ck_assert(!memcmp(a.pole + 3 * (size_t)a.vertex_of[i], b.pole + 3 * (size_t)b.vertex_of[j],
                          3 * sizeof(double)));
        ck_assert(!memcmp(a.hull + 3 * (size_t)a.vertex_of[i], b.hull + 3 * (size_t)b.vertex_of[j],
                          3 * sizeof(double)));
        differ += a.vertex_of[i] != b.vertex_of[j]; /* the ids did change */
    }
    ck_assert_int_gt(differ, 0);
    jfb_delaunay_release(&a), jfb_delaunay_release(&b);

    /* natural neighbourhoods with the face normals, N = 16 and 40 (ties
     * in distance everywhere: the cut ring must be the same) */
    jf_natural *na, *nb;
    jf_natural_ws *wa, *wb;
    ck_assert_int_eq(jf_natural_create_threads(p, n, 1, &na), JF_OK);
    ck_assert_int_eq(jf_natural_create_threads(q, n, 3, &nb), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(na, &wa), JF_OK);
    ck_assert_int_eq(jf_natural_ws_create(nb, &wb), JF_OK);
    uint32_t ia[64], ib[64];
    for (size_t N = 16; N <= 40; N += 24)
        for (size_t i = 0; i < n; i++) {
            size_t fa, fb, j = inv[i];
            ck_assert_int_eq(jf_natural_neighbors(na, wa, i, nr + 3 * i, N, ia, 64, &fa), JF_OK);
            ck_assert_int_eq(jf_natural_neighbors(nb, wb, j, qn + 3 * j, N, ib, 64, &fb), JF_OK);
            ck_assert_uint_eq(fa, fb);
            ck_assert_uint_eq(fa, N);
            for (size_t k = 0; k < fa; k++) ck_assert_uint_eq(ia[k], perm[ib[k]]);
        }
    /* the normals from poles / mincirc too */
    double *ma = malloc(3 * n * sizeof *ma), *mb = malloc(3 * n * sizeof *mb);
    unsigned *fla = calloc(n, sizeof *fla), *flb = calloc(n, sizeof *flb);
    ck_assert_int_eq(jf_natural_normals(na, JF_NORMAL_POLES, 2, ma, fla, NULL), JF_OK);
    ck_assert_int_eq(jf_natural_normals(nb, JF_NORMAL_POLES, 1, mb, flb, NULL), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert(!memcmp(ma + 3 * i, mb + 3 * inv[i], 3 * sizeof(double)));
        ck_assert_uint_eq(fla[i], flb[inv[i]]);
    }
    jf_natural_ws_free(wa), jf_natural_ws_free(wb);
    jf_natural_free(na), jf_natural_free(nb);
    free(ma), free(mb), free(fla), free(flb), free(ca), free(cb);
    free(p), free(nr), free(q), free(qn), free(perm), free(inv);
}
END_TEST

int main(void) {
    Suite *s = suite_create("natural_threads");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, estimate_random_threads);
    tcase_add_test(tc, estimate_grid_threads);
    tcase_add_test(tc, bridge_threads);
    tcase_add_test(tc, grid_any_order);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
