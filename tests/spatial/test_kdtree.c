/* test_kdtree.c -- jf_index (k-NN, radius) against brute force, and
 * jf_spatial_order. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "jetfit.h"

/* ---------------------------------------------------------------- helpers */

#define JF_TEST_SEED 88172645463325252ULL
#include "test_rand.h"
#include "jf_test.h"

/* Merge sort by (d2, index): the sanitizers' qsort interceptor is slow. */
static void sort_pairs(pair *a, size_t n)
{
    pair *tmp = malloc((n ? n : 1) * sizeof *tmp);
    for (size_t w = 1; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = lo + w < n ? lo + w : n;
            size_t hi = lo + 2 * w < n ? lo + 2 * w : n;
            size_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi)
                tmp[k++] = cmp_pair(&a[j], &a[i]) < 0 ? a[j++] : a[i++];
            while (i < mid) tmp[k++] = a[i++];
            while (j < hi) tmp[k++] = a[j++];
        }
        memcpy(a, tmp, n * sizeof *a);
    }
    free(tmp);
}

/* All finite points sorted by (d2, index); d2 computed the documented way.
 * Returns their number. */
static size_t brute(const double *xyz, size_t n, const double q[3], pair *out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
        out[m].d = dx * dx + dy * dy + dz * dz;
        out[m].i = (uint32_t)i;
        m++;
    }
    sort_pairs(out, m);
    return m;
}

/* The pipeline's variant jf__index_query (up to max points within r2):
 * `want` points, the same as ref's, with their coordinates (from the
 * tree's copy) bit for bit those of the input. */
static void check_index_query(const jf_index *ix, const double *xyz, const double q[3],
                              size_t max, double r2, const pair *ref, size_t want,
                              uint32_t *idx, double *d2, double *pts)
{
    size_t found = 99;
    ck_assert_int_eq(jf__index_query(ix, q, max, r2, idx, d2, pts, &found), JF_OK);
    ck_assert_uint_eq(found, want);
    for (size_t j = 0; j < found; j++) {
        ck_assert_uint_eq(idx[j], ref[j].i);
        ck_assert(memcmp(pts + 3 * j, xyz + 3 * (size_t)idx[j], sizeof(double[3])) == 0);
    }
}

/* Checks knn for every k in ks and radius for a few r at query q. */
static void check_query(const jf_index *ix, const double *xyz, size_t n,
                        const double q[3])
{
    pair *ref = malloc((n + 1) * sizeof *ref);
    uint32_t *idx = malloc((n + 8) * sizeof *idx);
    double *d2 = malloc((n + 8) * sizeof *d2);
    double *pts = malloc(3 * (n + 8) * sizeof *pts);
    size_t m = brute(xyz, n, q, ref);
    const size_t ks[] = {1, 2, 5, 16, 33, 64, 100, 256, 500, 600, 1024, n, n + 7};
    for (size_t t = 0; t < sizeof ks / sizeof ks[0]; t++) {
        size_t k = ks[t], found = 99;
        ck_assert_int_eq(jf_index_knn(ix, q, k, idx, d2, &found), JF_OK);
        size_t want = k < m ? k : m;
        ck_assert_uint_eq(found, want);
        for (size_t j = 0; j < found; j++) {
            ck_assert_uint_eq(idx[j], ref[j].i);
            ck_assert(d2[j] == ref[j].d);
        }
        check_index_query(ix, xyz, q, k, INFINITY, ref, want, idx, NULL, pts);
    }
    /* radius: inclusive, capped to the nearest `max` */
    if (m) {
        double rs[] = {0.0, sqrt(ref[m / 3].d), sqrt(ref[m - 1].d) * 2,
                       sqrt(ref[m > 10 ? 10 : m - 1].d)};
        for (size_t t = 0; t < 4; t++) {
            double r = rs[t], r2 = r * r;
            size_t within = 0;
            while (within < m && ref[within].d <= r2) within++;
            size_t maxes[] = {n + 1, within / 2 + 1, 3};
            for (size_t u = 0; u < 3; u++) {
                size_t found = 99;
                ck_assert_int_eq(jf_index_radius(ix, q, r, maxes[u], idx, d2,
                                                 &found), JF_OK);
                size_t want = within < maxes[u] ? within : maxes[u];
                ck_assert_uint_eq(found, want);
                for (size_t j = 0; j < found; j++) {
                    ck_assert_uint_eq(idx[j], ref[j].i);
                    ck_assert(d2[j] <= r2);
                }
                check_index_query(ix, xyz, q, maxes[u], r2, ref, want, idx, d2, pts);
            }
        }
    }
    free(ref);
    free(idx);
    free(d2);
    free(pts);
}

static void check_cloud(const double *xyz, size_t n, size_t nq_random)
{
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    size_t finite = 0;
    for (size_t i = 0; i < n; i++)
        finite += isfinite(xyz[3 * i]) && isfinite(xyz[3 * i + 1]) &&
                  isfinite(xyz[3 * i + 2]);
    ck_assert_uint_eq(jf_index_size(ix), finite);
    /* the tree's storage: each finite point once, with its coordinates */
    const double *tp;
    const uint32_t *tid;
    ck_assert_uint_eq(jf__index_points(ix, &tp, &tid), finite);
    unsigned char *seen = calloc(n + 1, 1);
    for (size_t t = 0; t < finite; t++) {
        ck_assert_uint_lt(tid[t], n);
        ck_assert(!seen[tid[t]]);
        seen[tid[t]] = 1;
        ck_assert(memcmp(tp + 3 * t, xyz + 3 * (size_t)tid[t], sizeof(double[3])) == 0);
    }
    free(seen);
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++)
            if (isfinite(xyz[3 * i + d])) {
                if (xyz[3 * i + d] < lo[d]) lo[d] = xyz[3 * i + d];
                if (xyz[3 * i + d] > hi[d]) hi[d] = xyz[3 * i + d];
            }
    for (size_t t = 0; t < nq_random; t++) {
        double q[3];
        for (int d = 0; d < 3; d++) /* inside and a little outside */
            q[d] = lo[d] + (hi[d] - lo[d]) * (1.4 * urand() - 0.2);
        check_query(ix, xyz, n, q);
    }
    /* queries at data points: the point (or its smallest duplicate) first */
    for (size_t i = 0; i < n; i += n / 6 + 1) {
        const double *p = xyz + 3 * i;
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2])) continue;
        check_query(ix, xyz, n, p);
        uint32_t idx[1];
        double d2[1];
        size_t found;
        ck_assert_int_eq(jf_index_knn(ix, p, 1, idx, d2, &found), JF_OK);
        ck_assert_uint_eq(found, 1);
        ck_assert(d2[0] == 0.0);
        ck_assert_uint_le(idx[0], i);
        ck_assert(memcmp(xyz + 3 * (size_t)idx[0], p, 3 * sizeof *p) == 0);
    }
    jf_index_free(ix);
}

/* ---------------------------------------------------------------- tests */

START_TEST(knn_uniform)
{
    size_t n = 1500;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    check_cloud(xyz, n, 12);
    free(xyz);
}
END_TEST

START_TEST(knn_clustered_offset)
{
    /* tight clusters far apart, the whole cloud offset by 1e6 */
    size_t n = 1200;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        size_t c = i % 5;
        for (int d = 0; d < 3; d++)
            xyz[3 * i + d] = 1e6 + 10.0 * (double)(c * (size_t)(d + 1) % 7) +
                             1e-3 * urand();
    }
    check_cloud(xyz, n, 10);
    free(xyz);
}
END_TEST

START_TEST(knn_duplicates_grid)
{
    /* a 7x6x5 integer grid, every point written 3 times, shuffled: many
     * exact duplicates and equidistant ties */
    size_t g = 7 * 6 * 5, n = 3 * g;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        size_t c = (i * 37) % g;
        xyz[3 * i] = (double)(c % 7);
        xyz[3 * i + 1] = (double)(c / 7 % 6);
        xyz[3 * i + 2] = (double)(c / 42);
    }
    check_cloud(xyz, n, 10);
    /* half-integer queries: up to 8 grid points at one distance */
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    for (int t = 0; t < 8; t++) {
        double q[3] = {0.5 + (t % 6), 0.5 + (t % 5), 0.5 + (t % 4)};
        check_query(ix, xyz, n, q);
    }
    jf_index_free(ix);
    free(xyz);
}
END_TEST

START_TEST(knn_all_equal_and_planar)
{
    size_t n = 200;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = 2.5;
    check_cloud(xyz, n, 5);
    for (size_t i = 0; i < n; i++) { /* a flat grid: z constant */
        xyz[3 * i] = (double)(i % 20);
        xyz[3 * i + 1] = (double)(i / 20);
        xyz[3 * i + 2] = -1.0;
    }
    check_cloud(xyz, n, 8);
    free(xyz);
}
END_TEST

START_TEST(knn_nonfinite_points)
{
    size_t n = 600;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    for (size_t i = 0; i < n; i += 7) xyz[3 * i + i % 3] = NAN;
    for (size_t i = 3; i < n; i += 11) xyz[3 * i + 1] = (i % 2) ? INFINITY
                                                                  : -INFINITY;
    check_cloud(xyz, n, 10);
    free(xyz);
}
END_TEST

START_TEST(knn_edge_cases)
{
    jf_index *ix = (jf_index *)1;
    uint32_t idx[4];
    double d2[4];
    size_t found = 7;
    double q[3] = {0, 0, 0};
    /* empty and all-NaN clouds: valid, find nothing */
    ck_assert_int_eq(jf_index_build(NULL, 0, &ix), JF_OK);
    ck_assert_int_eq(jf_index_knn(ix, q, 4, idx, d2, &found), JF_OK);
    ck_assert_uint_eq(found, 0);
    jf_index_free(ix);
    double bad[6] = {NAN, 0, 0, 1, INFINITY, 1};
    ck_assert_int_eq(jf_index_build(bad, 2, &ix), JF_OK);
    ck_assert_uint_eq(jf_index_size(ix), 0);
    ck_assert_int_eq(jf_index_radius(ix, q, 10.0, 4, idx, d2, &found), JF_OK);
    ck_assert_uint_eq(found, 0);
    jf_index_free(ix);
    /* bad arguments */
    double one[3] = {1, 2, 3};
    ck_assert_int_eq(jf_index_build(one, 1, NULL), JF_ERR_INVALID);
    ck_assert_int_eq(jf_index_build(NULL, 3, &ix), JF_ERR_INVALID);
    ck_assert_ptr_null(ix);
    ck_assert_int_eq(jf_index_build(one, 1, &ix), JF_OK);
    double qn[3] = {0, NAN, 0};
    ck_assert_int_eq(jf_index_knn(ix, qn, 1, idx, d2, &found), JF_ERR_INVALID);
    ck_assert_int_eq(jf_index_radius(ix, q, -1.0, 4, idx, d2, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_index_radius(ix, q, NAN, 4, idx, d2, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_index_knn(ix, q, 0, idx, d2, &found), JF_OK);
    ck_assert_uint_eq(found, 0);
    ck_assert_int_eq(jf_index_knn(ix, q, 3, idx, NULL, &found), JF_OK);
    ck_assert_uint_eq(found, 1);
    ck_assert_uint_eq(idx[0], 0);
    /* radius is inclusive: |one| = sqrt(14) */
    ck_assert_int_eq(jf_index_radius(ix, q, sqrt(14.0), 4, idx, d2, &found),
                     JF_OK);
    ck_assert_uint_eq(found, (sqrt(14.0) * sqrt(14.0) >= 14.0) ? 1 : 0);
    ck_assert_int_eq(jf_index_radius(ix, one, 0.0, 4, idx, d2, &found), JF_OK);
    ck_assert_uint_eq(found, 1);
    ck_assert_uint_gt(jf_index_memory(ix), 0);
    jf_index_free(ix);
    jf_index_free(NULL);
}
END_TEST

START_TEST(knn_large_k_without_d2)
{
    /* k > 1024 with d2 == NULL takes the allocating path */
    size_t n = 3000, k = 2500;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    pair *ref = malloc(n * sizeof *ref);
    uint32_t *idx = malloc(k * sizeof *idx);
    double q[3] = {0.3, 0.6, 0.1};
    brute(xyz, n, q, ref);
    size_t found;
    ck_assert_int_eq(jf_index_knn(ix, q, k, idx, NULL, &found), JF_OK);
    ck_assert_uint_eq(found, k);
    for (size_t j = 0; j < k; j++) ck_assert_uint_eq(idx[j], ref[j].i);
    free(idx);
    free(ref);
    free(xyz);
    jf_index_free(ix);
}
END_TEST

START_TEST(index_memory_small)
{
    /* the index is a permuted copy (24 + 4 bytes per point) plus ~1 node
     * per 8 points: it must stay under 40 bytes per point */
    size_t n = 50000;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    ck_assert_uint_ge(jf_index_memory(ix), n * 28);
    ck_assert_uint_le(jf_index_memory(ix), n * 40);
    jf_index_free(ix);
    free(xyz);
}
END_TEST

START_TEST(knn_threads_agree)
{
    /* the same queries from several OpenMP threads give identical results */
    size_t n = 2000, k = 8;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    uint32_t *a = malloc(n * k * sizeof *a), *b = malloc(n * k * sizeof *b);
    for (size_t i = 0; i < n; i++) {
        size_t f;
        jf_index_knn(ix, xyz + 3 * i, k, a + i * k, NULL, &f);
    }
    int bad = 0;
#pragma omp parallel for num_threads(2) reduction(+ : bad)
    for (long i = 0; i < (long)n; i++) {
        size_t f;
        if (jf_index_knn(ix, xyz + 3 * i, k, b + (size_t)i * k, NULL, &f) ||
            f != k)
            bad++;
    }
    ck_assert_int_eq(bad, 0);
    ck_assert(memcmp(a, b, n * k * sizeof *a) == 0);
    free(a);
    free(b);
    free(xyz);
    jf_index_free(ix);
}
END_TEST

START_TEST(build_threads_same_tree)
{
    /* large enough for the parallel build (subtrees of >= 65536 points as
     * tasks): 1, 2 and 3 threads lay out the same tree */
    size_t n = 150000;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    xyz[3 * 77] = NAN; /* left out of the tree */
    jf_index *ix[3];
    const double *pts[3];
    const uint32_t *id[3];
    for (int t = 0; t < 3; t++) {
        ck_assert_int_eq(jf__index_build_threads(xyz, n, t + 1, &ix[t]), JF_OK);
        ck_assert_uint_eq(jf__index_points(ix[t], &pts[t], &id[t]), n - 1);
    }
    for (int t = 1; t < 3; t++) {
        ck_assert(memcmp(pts[0], pts[t], 3 * (n - 1) * sizeof(double)) == 0);
        ck_assert(memcmp(id[0], id[t], (n - 1) * sizeof(uint32_t)) == 0);
    }
    for (int t = 0; t < 3; t++) jf_index_free(ix[t]);
    free(xyz);
}
END_TEST

/* jf__index_knn_scan: the same points as jf__index_knn_pos, and its
 * record holds every point nearer than sqrt(rc2) (brute force), with
 * rc2 at least the k-th distance -- on a surface sample (the k-NN
 * cells' case), a clustered cloud, and a query outside the box. */
START_TEST(knn_scan_record)
{
    size_t n = 20000, k = 17;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        double u = urand(), v = urand();
        xyz[3 * i] = u, xyz[3 * i + 1] = v, xyz[3 * i + 2] = 0.1 * exp(2 * u + v - v * v);
        if (i % 3 == 0) xyz[3 * i + 2] += 0.5 * urand(); /* a thick part too */
    }
    jf_index *ix;
    ck_assert_int_eq(jf__index_build_threads(xyz, n, 2, &ix), JF_OK);
    const double *pts;
    const uint32_t *id;
    size_t m = jf__index_points(ix, &pts, &id);
    uint32_t a[32], b[32];
    double da[32], db[32];
    size_t gained = 0, tried = 0;
    for (size_t t = 0; t < 400; t++) {
        double q[3];
        if (t < 399) memcpy(q, pts + 3 * (t * 37 % m), sizeof q);
        else q[0] = 5, q[1] = -3, q[2] = 2; /* outside the box */
        size_t fa = 0, fb = 0;
        jf__kd_scan sc;
        ck_assert_int_eq(jf__index_knn_pos(ix, q, k, INFINITY, a, da, &fa), JF_OK);
        ck_assert_int_eq(jf__index_knn_scan(ix, q, k, b, db, &fb, &sc), JF_OK);
        ck_assert_uint_eq(fa, fb);
        ck_assert(memcmp(a, b, fa * sizeof *a) == 0 && memcmp(da, db, fa * sizeof *da) == 0);
        if (sc.rc2 == 0) { /* too many leaves: nothing promised */
            ck_assert_uint_gt(sc.n, JF_KD_SCAN_LEAVES);
            continue;
        }
        ck_assert_uint_le(sc.n, JF_KD_SCAN_LEAVES);
        ck_assert(sc.rc2 >= db[fb - 1]);
        tried++, gained += sc.rc2 > 1.1 * db[fb - 1];
        for (size_t p = 0; p < m; p++) {
            double dx = q[0] - pts[3 * p], dy = q[1] - pts[3 * p + 1], dz = q[2] - pts[3 * p + 2];
            if (!(dx * dx + dy * dy + dz * dz < sc.rc2)) continue;
            int in = 0;
            for (size_t l = 0; l < sc.n && !in; l++) in = p >= sc.first[l] && p < sc.first[l] + sc.cnt[l];
            ck_assert_msg(in, "query %zu: point %zu nearer than rc2 not in the leaves read", t, p);
        }
    }
    /* the record is worth having: rc2 well past the k-th distance often */
    ck_assert_uint_gt(tried, 300);
    ck_assert_uint_gt(2 * gained, tried);
    jf_index_free(ix);
    free(xyz);
}
END_TEST

/* A cloud of identical points (hostile input: every cell's bound ties
 * the worst): a query reads a few leaves, not the whole tree (it did:
 * 200,000 such points took 49 s for knn:16), and its answer is the
 * brute force's (the smallest indices). */
START_TEST(knn_identical_points_read_few_leaves)
{
    size_t n = 100000, k = 17;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) xyz[3 * i] = 1.5, xyz[3 * i + 1] = -2.25, xyz[3 * i + 2] = 1e-3;
    for (size_t i = 0; i < n; i += 9973) xyz[3 * i] += 1; /* a few elsewhere */
    jf_index *ix;
    ck_assert_int_eq(jf__index_build_threads(xyz, n, 2, &ix), JF_OK);
    pair *ref = malloc(n * sizeof *ref);
    uint32_t pos[32], idx[32];
    double d2[32];
    const double *pts;
    const uint32_t *id;
    jf__index_points(ix, &pts, &id);
    size_t most = 0;
    for (size_t t = 0; t < 5; t++) {
        const double *q = xyz + 3 * (1 + 7 * t);
        size_t f = 0, fi = 0;
        jf__kd_scan sc;
        ck_assert_int_eq(jf__index_knn_scan(ix, q, k, pos, d2, &f, &sc), JF_OK);
        ck_assert_int_eq(jf_index_knn(ix, q, k, idx, NULL, &fi), JF_OK);
        ck_assert_uint_eq(brute(xyz, n, q, ref), n);
        ck_assert_uint_eq(f, k);
        ck_assert_uint_eq(fi, k);
        for (size_t j = 0; j < k; j++) {
            ck_assert_uint_eq(id[pos[j]], ref[j].i);
            ck_assert_uint_eq(idx[j], ref[j].i);
        }
        most = sc.n > most ? sc.n : most;
    }
    /* a root-to-leaf path's worth (14 here: the few points moved away hold
     * small indices, so each subtree on the way to them is a candidate);
     * the whole tree before, 252 leaves with the index bound alone */
    ck_assert_msg(most <= 32, "%zu leaves read of about %zu", most, n / 18);
    jf_index_free(ix);
    free(ref);
    free(xyz);
}
END_TEST

/* ---------------------------------------------------------------- order */

START_TEST(order_is_permutation)
{
    size_t n = 5000;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand() * 100 - 50;
    for (size_t i = 5; i < n; i += 97) xyz[3 * i + 2] = NAN;
    size_t nbad = 0;
    for (size_t i = 5; i < n; i += 97) nbad++;
    uint32_t *ord = malloc(n * sizeof *ord);
    char *hit = calloc(n, 1);
    ck_assert_int_eq(jf_spatial_order(xyz, n, ord), JF_OK);
    for (size_t i = 0; i < n; i++) {
        ck_assert_uint_lt(ord[i], n);
        ck_assert(!hit[ord[i]]);
        hit[ord[i]] = 1;
    }
    /* non-finite points last, in index order */
    for (size_t j = 0; j < nbad; j++)
        ck_assert_uint_eq(ord[n - nbad + j], 5 + 97 * j);
    /* deterministic */
    uint32_t *ord2 = malloc(n * sizeof *ord2);
    ck_assert_int_eq(jf_spatial_order(xyz, n, ord2), JF_OK);
    ck_assert(memcmp(ord, ord2, n * sizeof *ord) == 0);
    /* locality: consecutive points are close on average (uniform random
     * order would give a mean step of about 66; a Z-curve through 5000
     * points in a 100-cube steps about 100/5000^(1/3) ~ 6 on average) */
    double sum = 0;
    for (size_t i = 1; i < n - nbad; i++) {
        const double *a = xyz + 3 * (size_t)ord[i - 1],
                     *b = xyz + 3 * (size_t)ord[i];
        sum += sqrt((a[0] - b[0]) * (a[0] - b[0]) +
                    (a[1] - b[1]) * (a[1] - b[1]) +
                    (a[2] - b[2]) * (a[2] - b[2]));
    }
    ck_assert_double_lt(sum / (double)(n - nbad - 1), 15.0);
    free(ord);
    free(ord2);
    free(hit);
    free(xyz);
}
END_TEST

START_TEST(order_morton_cube)
{
    /* the 8 corners of a cube, given in reverse Morton order, plus a
     * duplicate of the first corner: Z-order is x fastest, then y, then z
     * (x in the lowest key bit), duplicates in index order */
    double xyz[9 * 3];
    for (int c = 0; c < 8; c++) {
        int m = 7 - c;
        xyz[3 * c] = m & 1;
        xyz[3 * c + 1] = (m >> 1) & 1;
        xyz[3 * c + 2] = (m >> 2) & 1;
    }
    xyz[24] = 1, xyz[25] = 1, xyz[26] = 1; /* duplicate of corner 7 (c=0) */
    uint32_t ord[9];
    ck_assert_int_eq(jf_spatial_order(xyz, 9, ord), JF_OK);
    const uint32_t want[9] = {7, 6, 5, 4, 3, 2, 1, 0, 8};
    for (int i = 0; i < 9; i++) ck_assert_uint_eq(ord[i], want[i]);
    ck_assert_int_eq(jf_spatial_order(xyz, 0, NULL), JF_OK);
    ck_assert_int_eq(jf_spatial_order(NULL, 3, ord), JF_ERR_INVALID);
}
END_TEST

/* Small k (the append buffer, its bound lowered as candidates come in)
 * at every point in the tree's walk, each bounded as the pipeline bounds
 * it (the farthest of the previous point's k nearest, or none), against
 * brute force: a sphere-like surface with a cluster of exact duplicates
 * (more equal d2 than the buffer holds), a grid plane (equidistant ties)
 * and a cloud whose squared distances overflow to infinity. */
static void check_walk(const double *xyz, size_t n, size_t k)
{
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    const double *tp;
    const uint32_t *tid;
    size_t m = jf__index_points(ix, &tp, &tid);
    pair *ref = malloc(n * sizeof *ref);
    uint32_t *idx = malloc(k * sizeof *idx);
    double *d2 = malloc(k * sizeof *d2), *pts = malloc(3 * k * sizeof *pts),
           *prev = malloc(3 * k * sizeof *prev);
    size_t prev_n = 0;
    for (size_t t = 0; t < m; t += 1 + (t % 3)) {
        const double *q = tp + 3 * t;
        double b = INFINITY;
        if (prev_n == k) {
            b = 0;
            for (size_t j = 0; j < k; j++) {
                const double dx = q[0] - prev[3 * j], dy = q[1] - prev[3 * j + 1],
                             dz = q[2] - prev[3 * j + 2], d = dx * dx + dy * dy + dz * dz;
                b = d > b ? d : b;
            }
        }
        size_t all = brute(xyz, n, q, ref), want = k < all ? k : all, found = 99;
        ck_assert_int_eq(jf__index_query(ix, q, k, b, idx, d2, pts, &found), JF_OK);
        if (found < want) /* the bound rounded low: the pipeline asks again */
            ck_assert_int_eq(jf__index_query(ix, q, k, INFINITY, idx, d2, pts, &found), JF_OK);
        ck_assert_uint_eq(found, want);
        for (size_t j = 0; j < found; j++) {
            ck_assert_uint_eq(idx[j], ref[j].i);
            ck_assert(d2[j] == ref[j].d || (isnan(d2[j]) && isnan(ref[j].d)));
            ck_assert(memcmp(pts + 3 * j, xyz + 3 * (size_t)idx[j], sizeof(double[3])) == 0);
        }
        memcpy(prev, pts, 3 * found * sizeof *prev);
        prev_n = found;
    }
    free(ref), free(idx), free(d2), free(pts), free(prev);
    jf_index_free(ix);
}

START_TEST(knn_small_k_walk)
{
    size_t n = 2400;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) { /* a sphere, 200 copies of one point */
        double u = 2 * urand() - 1, a = 6.283185307179586 * urand(), r = sqrt(1 - u * u);
        if (i % 12 == 5) u = 1, r = 0, a = 0;
        xyz[3 * i] = r * cos(a), xyz[3 * i + 1] = r * sin(a), xyz[3 * i + 2] = u;
    }
    const size_t ks[] = {1, 5, 16, 24, 48};
    for (size_t t = 0; t < sizeof ks / sizeof ks[0]; t++) check_walk(xyz, n, ks[t]);
    for (size_t i = 0; i < n; i++) { /* a 40 x 60 grid plane */
        xyz[3 * i] = (double)(i % 40), xyz[3 * i + 1] = (double)(i / 40), xyz[3 * i + 2] = 3.0;
    }
    check_walk(xyz, n, 16);
    check_walk(xyz, 30, 16); /* fewer than 2k points */
    check_walk(xyz, 7, 16);  /* fewer than k */
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = (urand() - 0.5) * 4e154; /* d2 up to inf */
    check_walk(xyz, 300, 16);
    free(xyz);
}
END_TEST

static Suite *kdtree_suite(void)
{
    Suite *s = suite_create("kdtree");
    TCase *tc = tcase_create("knn");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, knn_uniform);
    tcase_add_test(tc, knn_clustered_offset);
    tcase_add_test(tc, knn_duplicates_grid);
    tcase_add_test(tc, knn_all_equal_and_planar);
    tcase_add_test(tc, knn_nonfinite_points);
    tcase_add_test(tc, knn_edge_cases);
    tcase_add_test(tc, knn_large_k_without_d2);
    tcase_add_test(tc, knn_small_k_walk);
    tcase_add_test(tc, knn_threads_agree);
    tcase_add_test(tc, knn_scan_record);
    tcase_add_test(tc, knn_identical_points_read_few_leaves);
    tcase_add_test(tc, build_threads_same_tree);
    tcase_add_test(tc, index_memory_small);
    suite_add_tcase(s, tc);
    TCase *to = tcase_create("order");
    tcase_add_test(to, order_is_permutation);
    tcase_add_test(to, order_morton_cube);
    suite_add_tcase(s, to);
    return s;
}

int main(void)
{
    return jf_test_run(kdtree_suite());
}
