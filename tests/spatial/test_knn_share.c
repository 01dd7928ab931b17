/* test_knn_share.c -- knn_share.c: the shared k-NN search gives, for every
 * query, the same list (indices, squared distances, coordinates, order)
 * as one jf__index_query per point, whatever the walk and the hint:
 * a noisy sphere walked in the tree's order (the pipeline's walk) and in
 * a shuffled order, a grid (many equal distances: the index breaks the
 * ties), duplicates, clouds of fewer than 2k points, and coordinates
 * whose squared distances are subnormal or near 1e10; every other query
 * with the default build's selection (jf__no_avx), the rest with the
 * machine's (AVX-512's compress where it has it); the first SH_NPOS
 * tree positions of each list (step 6's nearest) name the same points,
 * and nothing past them is written; every third query without indices. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "avx_path.h" /* jf__no_avx */
#include "index_internal.h"
#include "jetfit.h"
#include "jf_test.h"

#define SH_NPOS 7 /* positions asked of each query */

/* Every point of xyz[n] queried in the order ord (NULL: the tree's walk,
 * with its next points as the hint) through one jf__knn_share of k,
 * against jf__index_query; returns the count of points whose lists
 * differ in anything. */
static size_t mismatches(const double *xyz, size_t n, size_t k, int shuffled)
{
    jf_index *ix = NULL;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    const double *pts;
    const uint32_t *id;
    size_t m = jf__index_points(ix, &pts, &id);
    size_t *ord = malloc(m * sizeof *ord);
    for (size_t i = 0; i < m; i++) ord[i] = i;
    uint64_t st = 2711;
    for (size_t i = m; shuffled && i > 1; i--) {
        size_t j = (size_t)(jf_splitmix64(&st) % i), t = ord[i - 1];
        ord[i - 1] = ord[j];
        ord[j] = t;
    }
    jf__knn_share *sh = NULL;
    ck_assert_int_eq(jf__knn_share_create(k, SH_NPOS, &sh), JF_OK);
    uint32_t *ia = malloc(k * sizeof *ia), *ib = malloc(k * sizeof *ib);
    double *da = malloc(k * sizeof *da), *db = malloc(k * sizeof *db);
    double *xa = malloc(3 * k * sizeof *xa), *xb = malloc(3 * k * sizeof *xb);
    size_t bad = 0;
    for (size_t w = 0; w < m; w++) {
        const double *q = pts + 3 * ord[w];
        if (!shuffled) jf__knn_share_ahead(sh, q, m - w); /* as the pipeline */
        size_t fa = 0, fb = 0;
        ck_assert_int_eq(jf__index_query(ix, q, k, INFINITY, ia, da, xa, &fa), JF_OK);
        jf__no_avx = (int)(w % 2);
        uint32_t pb[SH_NPOS + 1];
        pb[SH_NPOS] = UINT32_MAX; /* must stay */
        uint32_t *ibq = w % 3 == 2 ? NULL : ib;
        ck_assert_int_eq(jf__knn_share_query(sh, ix, q, ibq, pb, db, xb, &fb), JF_OK);
        jf__no_avx = 0;
        int pos_ok = pb[SH_NPOS] == UINT32_MAX;
        for (size_t i = 0; i < SH_NPOS && i < fb && pos_ok; i++) pos_ok = id[pb[i]] == ia[i];
        if (fa != fb || (ibq && memcmp(ia, ib, fa * sizeof *ia)) || memcmp(da, db, fa * sizeof *da) ||
            memcmp(xa, xb, 3 * fa * sizeof *xa) || !pos_ok)
            bad++;
    }
    jf__knn_share_free(sh);
    jf_index_free(ix);
    free(ord);
    free(ia);
    free(ib);
    free(da);
    free(db);
    free(xa);
    free(xb);
    return bad;
}

/* uniform in [0, 1) */
static double unit(uint64_t *st) { return (double)(jf_splitmix64(st) >> 11) * 0x1p-53; }

/* n points near the unit sphere (radial noise 1%) */
static double *sphere(size_t n, uint64_t seed)
{
    double *xyz = malloc(3 * n * sizeof *xyz);
    uint64_t st = seed;
    for (size_t i = 0; i < n; i++) {
        double u = 2.0 * unit(&st) - 1.0, ph = 6.283185307179586 * unit(&st);
        double r = 1.0 + 0.01 * (unit(&st) - 0.5), s = sqrt(1.0 - u * u);
        xyz[3 * i] = r * s * cos(ph);
        xyz[3 * i + 1] = r * s * sin(ph);
        xyz[3 * i + 2] = r * u;
    }
    return xyz;
}

START_TEST(test_share_sphere)
{
    double *xyz = sphere(6000, 27);
    ck_assert_uint_eq(mismatches(xyz, 6000, 256, 0), 0);
    ck_assert_uint_eq(mismatches(xyz, 6000, 256, 1), 0);
    ck_assert_uint_eq(mismatches(xyz, 6000, 128, 0), 0);
    free(xyz);
}
END_TEST

/* a 40 x 40 grid in the plane: rings of equal distances, ties by index */
START_TEST(test_share_grid_ties)
{
    size_t n = 1600;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        xyz[3 * i] = (double)(i % 40);
        xyz[3 * i + 1] = (double)(i / 40);
        xyz[3 * i + 2] = 0.0;
    }
    ck_assert_uint_eq(mismatches(xyz, n, 256, 0), 0);
    ck_assert_uint_eq(mismatches(xyz, n, 256, 1), 0);
    free(xyz);
}
END_TEST

/* every point twice (the second copy at a higher index) */
START_TEST(test_share_duplicates)
{
    double *xyz = sphere(3000, 5);
    memcpy(xyz + 3 * 1500, xyz, 3 * 1500 * sizeof *xyz);
    ck_assert_uint_eq(mismatches(xyz, 3000, 256, 0), 0);
    free(xyz);
}
END_TEST

/* a sphere of radius 1e-155: squared distances near 1e-312, subnormal
 * (the bucket sort's scale would overflow: the plain search answers) */
START_TEST(test_share_subnormal)
{
    double *xyz = sphere(2000, 11);
    for (size_t i = 0; i < 3 * 2000; i++) xyz[i] *= 1e-155;
    ck_assert_uint_eq(mismatches(xyz, 2000, 256, 0), 0);
    for (size_t i = 0; i < 3 * 2000; i++) xyz[i] *= 1e160; /* and large ones */
    ck_assert_uint_eq(mismatches(xyz, 2000, 256, 0), 0);
    free(xyz);
}
END_TEST

/* fewer than k, between k and 2k points: the whole cloud */
START_TEST(test_share_small)
{
    double *xyz = sphere(400, 9);
    ck_assert_uint_eq(mismatches(xyz, 100, 256, 0), 0);
    ck_assert_uint_eq(mismatches(xyz, 400, 256, 0), 0);
    ck_assert_uint_eq(mismatches(xyz, 400, 256, 1), 0);
    free(xyz);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("knn_share");
    TCase *tc = tcase_create("exact");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_share_sphere);
    tcase_add_test(tc, test_share_grid_ties);
    tcase_add_test(tc, test_share_duplicates);
    tcase_add_test(tc, test_share_small);
    tcase_add_test(tc, test_share_subnormal);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
