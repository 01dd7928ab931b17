/* test_cli_orient.c -- `jetfit estimate --orient` end to end: on a sphere
 * viewpoint at the centre gives inward normals, mst one consistent side
 * (outward: its seed is the top point, oriented +z), input follows the
 * file's normals; curvatures, directions and Monge coefficients flip with
 * the normal (k1 = k2 = -1/R outward); on a real range scan (Stanford
 * bun090) mst agrees with the scanner's viewpoint. */
#include <check.h>

#include "test_cli_util.h"
#include "jf_test.h"

#define N 2500
static const double R = 1.5, C[3] = {0.2, -0.4, 1.1};
static double pts[3 * N];

/* (p - C) . n / |p - C| for row i */
static double radial(const jf_eval_table *t, size_t i)
{
    double d[3], s = 0, l = 0;
    static const char *const nn[] = {"nx", "ny", "nz"};
    for (int k = 0; k < 3; k++) {
        d[k] = pts[3 * i + k] - C[k];
        l += d[k] * d[k];
        s += d[k] * cli_val(t, i, nn[k]);
    }
    return s / sqrt(l);
}

static void run_ok(const char *out, const char *orient)
{
    int rc = cli_run("estimate", cli_path("s.xyz"), "-o", cli_path(out), "--neighbors", "knn:16",
                     "--degree", "3", "--orient", orient, "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s: %s", orient, cli_err);
}

START_TEST(sphere_viewpoint_mst_flip)
{
    char vp[128];
    cli_sphere(N, R, C, pts);
    cli_write_xyz(cli_path("s.xyz"), pts, NULL, N);
    snprintf(vp, sizeof vp, "viewpoint:%.17g,%.17g,%.17g", C[0], C[1], C[2]);
    run_ok("vp.csv", vp);
    run_ok("mst.csv", "mst");
    jf_eval_table a, b;
    cli_read(cli_path("vp.csv"), &a);
    cli_read(cli_path("mst.csv"), &b);
    for (size_t i = 0; i < N; i++) {
        ck_assert_msg(radial(&a, i) < -0.999, "viewpoint: row %zu not inward", i);
        ck_assert_msg(radial(&b, i) > 0.999, "mst: row %zu not outward", i);
        /* inward normal: the sphere bends towards it */
        ck_assert_double_eq_tol(cli_val(&a, i, "k1"), 1 / R, 0.02 / R);
        ck_assert_double_eq_tol(cli_val(&a, i, "k2"), 1 / R, 0.02 / R);
        ck_assert_double_eq_tol(cli_val(&b, i, "k1"), -1 / R, 0.02 / R);
        /* the flip rule, exactly: k1 <-> -k2, d1 <-> d2, b0 <-> -b3, b1 <-> -b2 */
        ck_assert(cli_val(&a, i, "nx") == -cli_val(&b, i, "nx"));
        ck_assert(cli_val(&a, i, "nz") == -cli_val(&b, i, "nz"));
        ck_assert(cli_val(&a, i, "k1") == -cli_val(&b, i, "k2"));
        ck_assert(cli_val(&a, i, "k2") == -cli_val(&b, i, "k1"));
        ck_assert(cli_val(&a, i, "d1x") == cli_val(&b, i, "d2x"));
        ck_assert(cli_val(&a, i, "d2y") == cli_val(&b, i, "d1y"));
        ck_assert(cli_val(&a, i, "b0") == -cli_val(&b, i, "b3"));
        ck_assert(cli_val(&a, i, "b1") == -cli_val(&b, i, "b2"));
        ck_assert(cli_val(&a, i, "status") == 0 && cli_val(&b, i, "status") == 0);
    }
    jf_eval_table_free(&a);
    jf_eval_table_free(&b);
}
END_TEST

/* Normals in the file: the default orientation follows them (inward
 * here); --orient none keeps the fitted side; --orient input without
 * normals is an error naming the option. */
START_TEST(input_normals)
{
    static double nrm[3 * N];
    cli_sphere(N, R, C, pts);
    for (size_t i = 0; i < N; i++)
        for (int k = 0; k < 3; k++) nrm[3 * i + k] = (C[k] - pts[3 * i + k]) / R;
    cli_write_xyz(cli_path("sn.xyz"), pts, nrm, N);
    ck_assert_int_eq(cli_run("estimate", cli_path("sn.xyz"), "-o", cli_path("in.csv"), NULL), 0);
    jf_eval_table t;
    cli_read(cli_path("in.csv"), &t);
    for (size_t i = 0; i < N; i++) ck_assert(radial(&t, i) < -0.999);
    jf_eval_table_free(&t);
    cli_write_xyz(cli_path("s.xyz"), pts, NULL, N);
    ck_assert_int_ne(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("x.csv"), "--orient",
                             "input", NULL), 0);
    ck_assert(strstr(cli_err, "orient input") != NULL);
    ck_assert(!cli_exists(cli_path("x.csv")));
}
END_TEST

/* A raw Cyberware range scan (data/bun090.ply; the scanner looks down -z
 * from far along +z): mst must agree
 * with viewpoint:0,0,1 on at least 99% of the points. */
START_TEST(bunny_scan_mst_vs_viewpoint)
{
    const char *bun = JF_TEST_DATA "/bun090.ply";
    ck_assert_int_eq(cli_run("estimate", bun, "-o", cli_path("m.ply"), "--orient", "mst", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", bun, "-o", cli_path("v.ply"), "--orient",
                             "viewpoint:0,0,1", NULL), 0);
    jf_eval_table a, b;
    cli_read(cli_path("m.ply"), &a);
    cli_read(cli_path("v.ply"), &b);
    ck_assert_uint_eq(a.nrows, 30379);
    ck_assert_uint_eq(b.nrows, 30379);
    size_t agree = 0, valid = 0;
    for (size_t i = 0; i < a.nrows; i++) {
        double s = 0;
        static const char *const nn[] = {"nx", "ny", "nz"};
        for (int k = 0; k < 3; k++) s += cli_val(&a, i, nn[k]) * cli_val(&b, i, nn[k]);
        if (!isfinite(s)) continue;
        valid++;
        agree += s > 0;
    }
    ck_assert_uint_eq(valid, a.nrows);
    ck_assert_msg(agree >= 0.99 * (double)valid, "agreement %zu / %zu", agree, valid);
    jf_eval_table_free(&a);
    jf_eval_table_free(&b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_orient");
    TCase *tc = tcase_create("cli_orient");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, sphere_viewpoint_mst_flip);
    tcase_add_test(tc, input_normals);
    tcase_add_test(tc, bunny_scan_mst_vs_viewpoint);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
