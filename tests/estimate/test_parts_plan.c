/* test_parts_plan.c -- the bounded-memory estimate's partition from a
 * sample and its memory plan (src/estimate/parts.c, issue 28): the parts
 * are runs of the (Morton key, index) order checked against
 * jf_spatial_order's full sort, near equal, non-finite points in none;
 * the plan is whole above the whole cloud's need, refuses below its least,
 * and takes fewer parts for a larger budget; and jf_estimate_parts on a
 * cloud with an isolated far point and a clump (balls too large for the
 * halo grid) and on a dense surface (halos from the cells near each
 * part's) equals the whole cloud's fit bit for bit. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "parts.h"
#include "jf_test.h"

static double *make(size_t n, uint64_t seed)
{
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        double u = jf_unit(jf_splitmix64(&seed)), v = jf_unit(jf_splitmix64(&seed));
        xyz[3 * i] = u, xyz[3 * i + 1] = v, xyz[3 * i + 2] = 0.1 * exp(2 * u + v - v * v);
    }
    return xyz;
}

/* The cloud of n points xyz (nothing else). */
static jf_cloud cloud_of(double *xyz, size_t n)
{
    jf_cloud c = {0};
    c.n = n;
    c.xyz = xyz;
    return c;
}

START_TEST(sampled_parts_are_runs_of_the_morton_order)
{
    const size_t n = 200000;
    double *xyz = make(n, 7);
    xyz[3 * 5] = NAN;           /* non-finite: no part */
    xyz[3 * 9 + 2] = INFINITY;
    memcpy(xyz + 3 * 11, xyz + 3 * 12, sizeof(double[3])); /* a duplicate */
    int32_t *part = malloc(n * sizeof *part);
    uint32_t *ord = malloc(n * sizeof *ord);
    const int P = 13;
    ck_assert_int_eq(jf__parts_split_sampled(xyz, n, P, 2, part), JF_OK);
    ck_assert_int_eq(jf_spatial_order(xyz, n, ord), JF_OK);
    size_t count[13] = {0};
    int32_t last = 0;
    for (size_t j = 0; j < n; j++) {
        int32_t p = part[ord[j]];
        if (j >= n - 2) { /* the non-finite points come last in the order */
            ck_assert_int_eq(p, -1);
            continue;
        }
        ck_assert_int_ge(p, last); /* a run of the order per part */
        ck_assert_int_lt(p, P);
        last = p;
        count[p]++;
    }
    for (int p = 0; p < P; p++) /* the sample's quantiles: within 10% */
        ck_assert_msg(fabs((double)count[p] - (double)(n - 2) / P) < 0.1 * (double)(n - 2) / P,
                      "part %d holds %zu", p, count[p]);
    /* the same for 1 or 2 threads */
    int32_t *p1 = malloc(n * sizeof *p1);
    ck_assert_int_eq(jf__parts_split_sampled(xyz, n, P, 1, p1), JF_OK);
    ck_assert_int_eq(memcmp(p1, part, n * sizeof *part), 0);
    free(p1);
    free(ord);
    free(part);
    free(xyz);
}
END_TEST

START_TEST(plan_is_monotone)
{
    const size_t n = 10000000, held = 24 * n;
    size_t whole = 0, least = 0;
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, NULL, SIZE_MAX / 2, &whole, &least), 1);
    ck_assert_uint_gt(whole, held + JF_PLAN_WHOLE_PT * n - 1);
    ck_assert_uint_lt(least, whole);
    ck_assert_uint_gt(least, held + JF_PLAN_SPLIT_PT * n);
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, NULL, whole, NULL, NULL), 1);
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, NULL, least - 1, NULL, NULL), 0);
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, NULL, least, NULL, NULL), JF_PLAN_PARTS_MAX);
    int prev = JF_PLAN_PARTS_MAX + 1;
    for (size_t b = least; b < whole; b += (whole - least) / 50) {
        int p = jf__parts_plan(n, held, 24, 2, NULL, b, NULL, NULL);
        ck_assert_int_ge(p, 2);
        ck_assert_int_le(p, prev);
        prev = p;
    }
    /* auto: step 6's records, JF_PLAN_NJ_PT more a point, whole and
     * parts; and its wider halo ring, parts only */
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    ck_assert_int_eq(jf_nb_parse("auto", &o.nb, NULL), JF_OK);
    jf_plan_nb au, rec;
    jf__plan_nb(&o, &au);
    ck_assert_uint_eq(au.fit_pt, JF_PLAN_NJ_PT);
    ck_assert(fabs(au.ball - pow(16 + 2 * sqrt(128), 2)) < 1e-9); /* r_256 + 2 r_128 */
    rec = au;
    rec.ball = 0; /* the records alone */
    size_t whole6 = 0, least6 = 0, leastr = 0;
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, &rec, SIZE_MAX / 2, &whole6, &leastr), 1);
    /* the records per point, the walk's rows per thread (2) */
    ck_assert_uint_eq(whole6 - whole, JF_PLAN_NJ_PT * n + 2 * (size_t)JF_PLAN_NJ_THREAD);
    ck_assert_uint_gt(leastr, least);
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, &au, SIZE_MAX / 2, NULL, &least6), 1);
    ck_assert_uint_gt(least6, leastr);
    ck_assert_int_eq(jf__parts_plan(n, held, 24, 2, &au, least6 - 1, NULL, NULL), 0);
    /* knn:32 is the default ring; a radius kind's ball is not known */
    jf_plan_nb k32, rad;
    o.nb = (jf_nb_spec){.kind = JF_NB_KNN, .k = 32};
    jf__plan_nb(&o, &k32);
    ck_assert(k32.ball == 32 && k32.fit_pt == 0);
    ck_assert(jf__plan_part_points(n, 32, &k32) == jf__plan_part_points(n, 32, NULL));
    o.nb = (jf_nb_spec){.kind = JF_NB_RADIUS, .r = 0.1};
    jf__plan_nb(&o, &rad);
    ck_assert(rad.ball == 0 && rad.fit_pt == 0);
}
END_TEST

/* A sink that writes each row's normal and status at its input index. */
typedef struct {
    double *nrm;
    uint32_t *status;
    size_t seen;
} rows;

static jf_status sink(void *user, const uint32_t *idx, jf_result *res, size_t m)
{
    rows *r = user;
    for (size_t j = 0; j < m; j++) {
        memcpy(r->nrm + 3 * (size_t)idx[j], res[j].normal, sizeof(double[3]));
        r->status[idx[j]] = res[j].status;
    }
#pragma omp atomic
    r->seen += m;
    return JF_OK;
}

/* jf_estimate_parts with each of P[0..np-1] parts gives the whole
 * cloud's normals and statuses, bit for bit, every row once. */
static void parts_match_whole(const jf_cloud *c, const jf_estimate_opts *o, const int *P, int np)
{
    const size_t n = c->n;
    rows w = {calloc(3 * n, sizeof(double)), calloc(n, sizeof(uint32_t)), 0};
    jf_error err;
    ck_assert_int_eq(jf_estimate_blocks(c, o, sink, &w, &err), JF_OK);
    for (int k = 0; k < np; k++) {
        rows p = {calloc(3 * n, sizeof(double)), calloc(n, sizeof(uint32_t)), 0};
        ck_assert_int_eq(jf_estimate_parts(c, o, P[k], sink, &p, &err), JF_OK);
        ck_assert_uint_eq(p.seen, n);
        ck_assert_int_eq(memcmp(p.nrm, w.nrm, 3 * n * sizeof(double)), 0);
        ck_assert_int_eq(memcmp(p.status, w.status, n * sizeof(uint32_t)), 0);
        free(p.nrm);
        free(p.status);
    }
    free(w.nrm);
    free(w.status);
}

/* Balls that reach over the whole cloud (an isolated point, a clump
 * of fewer than K): the parts' halos still give the whole cloud's rows. */
START_TEST(far_balls_exact)
{
    const size_t n = 30000;
    double *xyz = make(n, 9);
    /* an isolated point far away, and a tight clump of 5 points (fewer
     * than K) away from the rest: their balls reach over the whole cloud */
    xyz[0] = 40, xyz[1] = 40, xyz[2] = 3;
    for (int k = 1; k <= 5; k++) xyz[3 * k] = -20 + 1e-3 * k, xyz[3 * k + 1] = -20, xyz[3 * k + 2] = 0;
    const jf_cloud c = cloud_of(xyz, n);
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.threads = 2;
    o.nb.kind = JF_NB_KNN;
    o.nb.k = 16;
    static const int P[] = {2, 9, 32};
    parts_match_whole(&c, &o, P, 3);
    free(xyz);
}
END_TEST

/* A dense surface: every part's cells hold K + 1 own points, so its halo
 * comes from the cells near its own (no index of its points, no request:
 * parts_halo.c's jf__halo_by_cells); on the edges, the blocks of 27 or 125
 * cells.  The same rows as the whole cloud, bit for bit. */
START_TEST(cell_halos_exact)
{
    const size_t n = 200000;
    double *xyz = make(n, 11);
    const jf_cloud c = cloud_of(xyz, n);
    static const size_t K[] = {8, 16, 40};
    for (int kk = 0; kk < 3; kk++) {
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        o.threads = 2;
        o.nb.kind = JF_NB_KNN;
        o.nb.k = K[kk];
        o.params.degree = 1;
        static const int P[] = {2, 5, 16};
        parts_match_whole(&c, &o, P, 3);
    }
    free(xyz);
}
END_TEST

/* The plan's part (jf__plan_part_points: own points and the ring its
 * neighbourhood's ball makes) holds the largest part's real halo: a
 * surface of 60,000 points cut in 8 and 24 (parts with islands), at
 * knn:32, knn:256 and auto.  Before the balls came from the cloud's
 * distances (parts_halo.c's jf__wide_index), knn:256 in 24 parts took 25,660
 * points (now 13,545; the plan's part: 22,951). */
START_TEST(plan_holds_the_halo)
{
    const size_t n = 60000;
    double *xyz = make(n, 13);
    const jf_cloud c = cloud_of(xyz, n);
    static const struct {
        const char *nb;
        int P;
    } runs[] = {{"knn:32", 8}, {"knn:32", 24}, {"auto", 8}, {"auto", 24}, {"knn:256", 8}, {"knn:256", 24}};
    for (size_t k = 0; k < sizeof runs / sizeof *runs; k++) {
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        ck_assert_int_eq(jf_nb_parse(runs[k].nb, &o.nb, NULL), JF_OK);
        if (o.nb.kind == JF_NB_KNN) o.params.max_neighbors = o.nb.k;
        o.threads = 2;
        o.orient = JF_ORIENT_NONE;
        size_t most = 0;
        o.phase = jf_test_most_indexed;
        o.phase_user = &most;
        rows r = {calloc(3 * n, sizeof(double)), calloc(n, sizeof(uint32_t)), 0};
        jf_error err;
        ck_assert_int_eq(jf_estimate_parts(&c, &o, runs[k].P, sink, &r, &err), JF_OK);
        ck_assert_uint_eq(r.seen, n);
        jf_plan_nb nb;
        jf__plan_nb(&o, &nb);
        const double plan = jf__plan_part_points(n, runs[k].P, &nb);
        ck_assert_msg((double)most <= plan, "%s in %d parts: %zu points, the plan %.0f", runs[k].nb,
                      runs[k].P, most, plan);
        free(r.nrm);
        free(r.status);
    }
    free(xyz);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("parts_plan");
    TCase *tc = tcase_create("plan");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, sampled_parts_are_runs_of_the_morton_order);
    tcase_add_test(tc, plan_is_monotone);
    tcase_add_test(tc, far_balls_exact);
    tcase_add_test(tc, cell_halos_exact);
    tcase_add_test(tc, plan_holds_the_halo);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
