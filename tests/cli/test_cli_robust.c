/* test_cli_robust.c -- the command's robust-fitting flags end to end:
 * --degree-select lowers the degree where noise dominates and brings the
 * normals closer to the exact ones; --dist-weight improves the normals of
 * a large neighbourhood on exact data; bad values are clear errors.  The
 * surface is the paper's §6.1 graph z = 0.1 exp(2x + y - y^2), whose exact
 * normal is (-fx, -fy, 1)/|.|.  --robust-normals is that pair of flags. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "test_cli_util.h"
#include "jf_test.h"

#define SIDE 48

/* Median over rows of the angle (degrees) between the output normal and
 * the graph's exact normal at the row's (x, y); *lowered counts rows whose
 * degree is below `degree`. */
static double median_normal_err(const char *path, int degree, size_t *lowered)
{
    jf_eval_table t;
    cli_read(path, &t);
    static double e[SIDE * SIDE];
    ck_assert_uint_eq(t.nrows, SIDE * SIDE);
    *lowered = 0;
    for (size_t i = 0; i < t.nrows; i++) {
        double x = cli_val(&t, i, "x"), y = cli_val(&t, i, "y");
        double f = 0.1 * exp(2 * x + y - y * y);
        double n[3] = {-2 * f, -(1 - 2 * y) * f, 1}, len = sqrt(n[0] * n[0] + n[1] * n[1] + 1);
        double d = fabs(n[0] * cli_val(&t, i, "nx") + n[1] * cli_val(&t, i, "ny") +
                        n[2] * cli_val(&t, i, "nz")) / len;
        e[i] = acos(fmin(1.0, d)) * 180.0 / M_PI;
        if (cli_val(&t, i, "degree") < degree) (*lowered)++;
    }
    size_t n = t.nrows;
    jf_eval_table_free(&t);
    for (size_t i = 1; i < n; i++) /* insertion sort: n is small */
        for (size_t j = i; j > 0 && e[j] < e[j - 1]; j--) {
            double tmp = e[j];
            e[j] = e[j - 1];
            e[j - 1] = tmp;
        }
    return e[n / 2];
}

/* The §6.1 surface on a SIDE x SIDE grid (seed 7) with uniform noise of
 * 2% of the unit domain, as .xyz. */
static void write_noisy(const char *path)
{
    static double xyz[3 * SIDE * SIDE];
    cli_surface61(SIDE, xyz, 7);
    unsigned long long s = 99;
    for (size_t i = 0; i < 3 * SIDE * SIDE; i++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        xyz[i] += 0.02 * ((double)(s >> 11) / 9007199254740992.0 - 0.5);
    }
    cli_write_xyz(path, xyz, NULL, SIDE * SIDE);
}

START_TEST(degree_select_on_noise)
{
    write_noisy(cli_path("noisy.xyz"));
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("a.csv"),
                             "--neighbors", "knn:18", "--degree", "3", "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("b.csv"),
                             "--neighbors", "knn:18", "--degree", "3", "--degree-select", "1",
                             "--quiet", NULL), 0);
    size_t low_a, low_b;
    double ea = median_normal_err(cli_path("a.csv"), 3, &low_a);
    double eb = median_normal_err(cli_path("b.csv"), 3, &low_b);
    ck_assert_msg(low_b > 0 && low_b > low_a, "lowered %zu vs %zu", low_b, low_a);
    ck_assert_msg(eb < 0.8 * ea, "median normal error %g with selection vs %g", eb, ea);
    if (getenv("JF_VERBOSE")) printf("degree-select: median %g deg vs %g, %zu lowered\n", eb, ea, low_b);
}
END_TEST

START_TEST(dist_weight_on_exact)
{
    static double xyz[3 * SIDE * SIDE];
    cli_surface61(SIDE, xyz, 3);
    cli_write_xyz(cli_path("exact.xyz"), xyz, NULL, SIDE * SIDE);
    ck_assert_int_eq(cli_run("estimate", cli_path("exact.xyz"), "-o", cli_path("a.csv"),
                             "--neighbors", "knn:64", "--quiet", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("exact.xyz"), "-o", cli_path("b.csv"),
                             "--neighbors", "knn:64", "--dist-weight", "0.4", "--quiet", NULL),
                     0);
    size_t la, lb;
    double ea = median_normal_err(cli_path("a.csv"), 2, &la);
    double eb = median_normal_err(cli_path("b.csv"), 2, &lb);
    ck_assert_msg(eb < 0.9 * ea, "median normal error %g weighted vs %g", eb, ea);
}
END_TEST

START_TEST(bad_values)
{
    static double xyz[3 * 100];
    cli_surface61(10, xyz, 1);
    cli_write_xyz(cli_path("s.xyz"), xyz, NULL, 100);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("o.csv"), "--degree",
                             "2", "--degree-select", "3", NULL), 2);
    ck_assert_msg(strstr(cli_err, "--degree-select"), "stderr: %s", cli_err);
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("o.csv"),
                             "--dist-weight", "0", NULL), 2);
    ck_assert_msg(strstr(cli_err, "--dist-weight"), "stderr: %s", cli_err);
    ck_assert(!cli_exists(cli_path("o.csv")));
}
END_TEST

/* --robust-normals is listed in --help and is exactly --degree-select 1
 * --dist-weight 0.55 (rows equal bit for bit); on the noisy §6.1 surface
 * with knn:18 degree 3 it lowers the degree and the median normal error;
 * a later --degree-select overrides its lowest degree. */
START_TEST(robust_normals_preset)
{
    FILE *h = popen(JETFIT_BIN " estimate --help", "r");
    ck_assert(h != NULL);
    static char help[16384];
    size_t m = fread(help, 1, sizeof help - 1, h);
    help[m] = '\0';
    ck_assert_int_eq(pclose(h), 0);
    ck_assert_msg(strstr(help, "--robust-normals"), "not in --help");

    write_noisy(cli_path("noisy.xyz"));
    const char *k18[] = {"--neighbors", "knn:18", "--degree", "3", "--quiet"};
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("a.csv"), k18[0],
                             k18[1], k18[2], k18[3], k18[4], NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("b.csv"), k18[0],
                             k18[1], k18[2], k18[3], k18[4], "--robust-normals", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("c.csv"), k18[0],
                             k18[1], k18[2], k18[3], k18[4], "--degree-select", "1",
                             "--dist-weight", "0.55", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("noisy.xyz"), "-o", cli_path("d.csv"), k18[0],
                             k18[1], k18[2], k18[3], k18[4], "--robust-normals",
                             "--degree-select", "2", NULL), 0);
    size_t low_a, low_b;
    double ea = median_normal_err(cli_path("a.csv"), 3, &low_a);
    double eb = median_normal_err(cli_path("b.csv"), 3, &low_b);
    ck_assert_msg(low_b > 0 && low_b > low_a, "lowered %zu vs %zu", low_b, low_a);
    ck_assert_msg(eb < 0.8 * ea, "median normal error %g with --robust-normals vs %g", eb, ea);
    jf_eval_table b, c, d;
    cli_read(cli_path("b.csv"), &b);
    cli_read(cli_path("c.csv"), &c);
    cli_read(cli_path("d.csv"), &d);
    ck_assert_uint_eq(b.nrows, c.nrows);
    size_t plane_b = 0, plane_d = 0;
    for (size_t i = 0; i < b.nrows; i++) {
        const char *col[] = {"nx", "ny", "nz", "degree"};
        for (int j = 0; j < 4; j++)
            ck_assert(cli_val(&b, i, col[j]) == cli_val(&c, i, col[j]));
        plane_b += cli_val(&b, i, "degree") == 1;
        plane_d += cli_val(&d, i, "degree") == 1;
    }
    ck_assert_uint_gt(plane_b, 0);
    ck_assert_uint_eq(plane_d, 0);
    if (getenv("JF_VERBOSE"))
        printf("robust-normals: median %g deg vs %g, %zu lowered, %zu planes\n", eb, ea, low_b, plane_b);
    jf_eval_table_free(&b);
    jf_eval_table_free(&c);
    jf_eval_table_free(&d);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_robust");
    TCase *tc = tcase_create("robust flags");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, degree_select_on_noise);
    tcase_add_test(tc, dist_weight_on_exact);
    tcase_add_test(tc, bad_values);
    tcase_add_test(tc, robust_normals_preset);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
