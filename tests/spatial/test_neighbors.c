/* test_neighbors.c -- --neighbors specs: parsing, and jf_nb_query against
 * brute force (knn, radius, knn+radius with its minimum-count fallback). */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#define JF_TEST_SEED 0x9E3779B97F4A7C15ULL
#include "test_rand.h"
#include "jf_test.h"

static size_t brute(const double *xyz, size_t n, const double q[3], pair *out)
{
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
        out[i].d = dx * dx + dy * dy + dz * dz;
        out[i].i = (uint32_t)i;
    }
    qsort(out, n, sizeof *out, cmp_pair);
    return n;
}

/* ---------------------------------------------------------------- parse */

START_TEST(parse_valid)
{
    jf_nb_spec s;
    const char *why = "x";
    ck_assert_int_eq(jf_nb_parse("knn:16", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_KNN);
    ck_assert_uint_eq(s.k, 16);
    ck_assert_ptr_null(why);
    ck_assert_int_eq(jf_nb_parse("radius:0.25", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_RADIUS);
    ck_assert(s.r == 0.25);
    ck_assert_int_eq(jf_nb_parse("knn:32,radius:1.5e-3", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_KNN_RADIUS);
    ck_assert_uint_eq(s.k, 32);
    ck_assert(s.r == 1.5e-3);
    ck_assert_int_eq(jf_nb_parse("radius:2,knn:7", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_KNN_RADIUS);
    ck_assert_uint_eq(s.k, 7);
    ck_assert(s.r == 2.0);
    ck_assert_int_eq(jf_nb_parse("rings", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_RINGS);
    ck_assert_uint_eq(s.n, 0);
    ck_assert_int_eq(jf_nb_parse("rings:19", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_RINGS);
    ck_assert_uint_eq(s.n, 19);
    ck_assert_int_eq(jf_nb_parse("natural", &s, &why), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_NATURAL);
    ck_assert_uint_eq(s.n, 0);
    ck_assert_int_eq(jf_nb_parse("natural:12", &s, NULL), JF_OK);
    ck_assert_int_eq(s.kind, JF_NB_NATURAL);
    ck_assert_uint_eq(s.n, 12);
    ck_assert_int_eq(jf_nb_parse(".5,knn:3", &s, NULL), JF_ERR_INVALID);
    ck_assert_int_eq(jf_nb_parse("radius:.5,knn:3", &s, NULL), JF_OK);
    ck_assert(s.r == 0.5);
}
END_TEST

START_TEST(parse_errors)
{
    const char *bad[] = {
        "", "knn", "knn:", "knn:0", "knn:-3", "knn:3.5", "knn:16x", "knn: 16",
        " knn:16", "KNN:16", "radius:", "radius:0", "radius:-1", "radius:nan",
        "radius:inf", "radius:1e999", "radius:0x10", "radius:1,", "knn:3,",
        "knn:3,knn:4", "radius:1,radius:2", "knn:3;radius:1", "rings:",
        "rings:0", "rings:a", "natural:", "natural:-1", "natural:3,knn:4",
        "rings:3,radius:1", "knn:99999999999999999999999", "voronoi",
        "knn:4,rings:2"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        jf_nb_spec s = {JF_NB_RINGS, 77, 7.0, 77};
        const char *why = NULL;
        ck_assert_msg(jf_nb_parse(bad[i], &s, &why) == JF_ERR_INVALID,
                      "accepted \"%s\"", bad[i]);
        ck_assert_ptr_nonnull(why);
        ck_assert_uint_gt(strlen(why), 5);
        ck_assert_uint_eq(s.k, 77); /* untouched on error */
    }
    jf_nb_spec s;
    ck_assert_int_eq(jf_nb_parse(NULL, &s, NULL), JF_ERR_INVALID);
    ck_assert_int_eq(jf_nb_parse("knn:3", NULL, NULL), JF_ERR_INVALID);
}
END_TEST

START_TEST(format_round_trip)
{
    const char *texts[] = {"knn:16", "radius:0.125", "knn:9,radius:2.5",
                           "rings", "rings:19", "natural", "natural:30"};
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++) {
        jf_nb_spec s, t;
        char buf[64];
        ck_assert_int_eq(jf_nb_parse(texts[i], &s, NULL), JF_OK);
        ck_assert_str_eq(jf_nb_format(&s, buf, sizeof buf), texts[i]);
        ck_assert_int_eq(jf_nb_parse(buf, &t, NULL), JF_OK);
        ck_assert(s.kind == t.kind && s.k == t.k && s.r == t.r && s.n == t.n);
    }
}
END_TEST

/* ---------------------------------------------------------------- query */

START_TEST(query_semantics)
{
    size_t n = 800;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < 3 * n; i++) xyz[i] = urand();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    pair *ref = malloc(n * sizeof *ref);
    uint32_t idx[64];
    double d2[64];
    for (int t = 0; t < 60; t++) {
        const double *q = xyz + 3 * (size_t)(t * 13);
        brute(xyz, n, q, ref);
        ck_assert_uint_eq(ref[0].i, (uint32_t)(t * 13)); /* itself first */
        /* cases: (K, R, min_count, cap) */
        const double rr[] = {sqrt(ref[3].d), sqrt(ref[10].d), sqrt(ref[40].d),
                             0.0};
        for (int c = 0; c < 4; c++) {
            double r = rr[c], r2 = r * r;
            size_t within = 0;
            while (within < n && ref[within].d <= r2) within++;
            const size_t Ks[] = {6, 16, 30}, Ms[] = {0, 6, 10, 40};
            const size_t caps[] = {64, 12};
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 4; b++)
                    for (int e = 0; e < 2; e++) {
                        size_t K = Ks[a], M = Ms[b], cap = caps[e];
                        jf_nb_spec s = {JF_NB_KNN_RADIUS, K, r, 0};
                        size_t found = 999;
                        if (r == 0.0) s.r = 1e-300; /* radius must be > 0 */
                        ck_assert_int_eq(jf_nb_query(ix, &s, M, q, idx, d2,
                                                     cap, &found), JF_OK);
                        size_t kk = K < cap ? K : cap;
                        size_t in = within < kk ? within : kk;
                        size_t floor = M < kk ? M : kk;
                        size_t want = in >= floor ? in : floor;
                        ck_assert_uint_eq(found, want);
                        for (size_t j = 0; j < found; j++) {
                            ck_assert_uint_eq(idx[j], ref[j].i);
                            ck_assert(d2[j] == ref[j].d);
                        }
                    }
            /* radius alone: capped by cap, nearest first */
            if (r > 0) {
                jf_nb_spec s = {JF_NB_RADIUS, 0, r, 0};
                size_t found;
                ck_assert_int_eq(jf_nb_query(ix, &s, 50, q, idx, NULL, 12,
                                             &found), JF_OK);
                ck_assert_uint_eq(found, within < 12 ? within : 12);
                for (size_t j = 0; j < found; j++)
                    ck_assert_uint_eq(idx[j], ref[j].i);
            }
        }
        /* knn: min(K, cap), min_count ignored */
        jf_nb_spec s = {JF_NB_KNN, 20, 0, 0};
        size_t found;
        ck_assert_int_eq(jf_nb_query(ix, &s, 50, q, idx, d2, 64, &found),
                         JF_OK);
        ck_assert_uint_eq(found, 20);
        for (size_t j = 0; j < found; j++) ck_assert_uint_eq(idx[j], ref[j].i);
        ck_assert_int_eq(jf_nb_query(ix, &s, 0, q, idx, d2, 5, &found), JF_OK);
        ck_assert_uint_eq(found, 5);
    }
    /* kinds the index does not serve, and bad arguments */
    jf_nb_spec rings = {JF_NB_RINGS, 0, 0, 3}, nat = {JF_NB_NATURAL, 0, 0, 0};
    jf_nb_spec k0 = {JF_NB_KNN, 0, 0, 0};
    size_t found = 5;
    ck_assert_int_eq(jf_nb_query(ix, &rings, 6, xyz, idx, d2, 64, &found),
                     JF_ERR_INVALID);
    ck_assert_uint_eq(found, 0);
    ck_assert_int_eq(jf_nb_query(ix, &nat, 6, xyz, idx, d2, 64, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_nb_query(ix, &k0, 6, xyz, idx, d2, 64, &found),
                     JF_ERR_INVALID);
    ck_assert_int_eq(jf_nb_query(NULL, &k0, 6, xyz, idx, d2, 64, &found),
                     JF_ERR_INVALID);
    free(ref);
    free(xyz);
    jf_index_free(ix);
}
END_TEST

START_TEST(query_sparse_fallback)
{
    /* a line of points 1 apart: knn:10,radius:1.5 around point 5 holds 3
     * points (4, 5, 6); with min_count 6 the 6 nearest are taken */
    double xyz[20 * 3];
    for (int i = 0; i < 20; i++) {
        xyz[3 * i] = i;
        xyz[3 * i + 1] = 0;
        xyz[3 * i + 2] = 0;
    }
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, 20, &ix), JF_OK);
    jf_nb_spec s;
    ck_assert_int_eq(jf_nb_parse("knn:10,radius:1.5", &s, NULL), JF_OK);
    uint32_t idx[32];
    size_t found;
    ck_assert_int_eq(jf_nb_query(ix, &s, 0, xyz + 15, idx, NULL, 32, &found),
                     JF_OK);
    ck_assert_uint_eq(found, 3);
    ck_assert_uint_eq(idx[0], 5);
    ck_assert_uint_eq(idx[1], 4); /* ties: smaller index first */
    ck_assert_uint_eq(idx[2], 6);
    ck_assert_int_eq(jf_nb_query(ix, &s, 6, xyz + 15, idx, NULL, 32, &found),
                     JF_OK);
    ck_assert_uint_eq(found, 6);
    const uint32_t want[6] = {5, 4, 6, 3, 7, 2};
    for (int j = 0; j < 6; j++) ck_assert_uint_eq(idx[j], want[j]);
    /* K bounds the fallback: knn:4 and min_count 6 gives 4 */
    ck_assert_int_eq(jf_nb_parse("radius:1.5,knn:4", &s, NULL), JF_OK);
    ck_assert_int_eq(jf_nb_query(ix, &s, 6, xyz + 15, idx, NULL, 32, &found),
                     JF_OK);
    ck_assert_uint_eq(found, 4);
    jf_index_free(ix);
}
END_TEST

static Suite *nb_suite(void)
{
    Suite *s = suite_create("neighbors");
    TCase *tc = tcase_create("parse");
    tcase_add_test(tc, parse_valid);
    tcase_add_test(tc, parse_errors);
    tcase_add_test(tc, format_round_trip);
    suite_add_tcase(s, tc);
    TCase *tq = tcase_create("query");
    tcase_set_timeout(tq, 120);
    tcase_add_test(tq, query_semantics);
    tcase_add_test(tq, query_sparse_fallback);
    suite_add_tcase(s, tq);
    return s;
}

int main(void)
{
    return jf_test_run(nb_suite());
}
