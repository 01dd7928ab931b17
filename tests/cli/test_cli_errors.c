/* test_cli_errors.c -- `jetfit estimate` on bad input and bad options:
 * non-zero exit, one line on stderr naming the file (and line), and no
 * output file (nor a leftover temporary).  Also the non-fatal cases: NaN
 * coordinates and too few points give rows with a status. */
#include <check.h>

#include "test_cli_util.h"
#include "jf_test.h"

/* Runs estimate on `name` (already written in cli_dir), expects failure,
 * `want` in stderr, exactly one stderr line and only the input left. */
static void expect_fail(const char *name, const char *want)
{
    const char *in = cli_path(name), *out = cli_path("out.ply");
    int files = cli_count_files();
    int rc = cli_run("estimate", in, "-o", out, NULL);
    ck_assert_msg(rc != 0 && rc < 128, "%s: exit %d", name, rc);
    ck_assert_msg(strstr(cli_err, "jetfit") == cli_err, "%s: stderr '%s'", name, cli_err);
    ck_assert_msg(strstr(cli_err, want) != NULL, "%s: '%s' not in '%s'", name, want, cli_err);
    char *nl = strchr(cli_err, '\n');
    ck_assert_msg(nl && nl[1] == '\0', "%s: not one line: '%s'", name, cli_err);
    ck_assert(!cli_exists(out));
    ck_assert_int_eq(cli_count_files(), files);
}

START_TEST(missing_file)
{
    expect_fail("nothere.xyz", "nothere.xyz");
}
END_TEST

START_TEST(unknown_extension)
{
    cli_write_text(cli_path("a.foo"), "0 0 0\n1 0 0\n0 1 0\n");
    expect_fail("a.foo", "a.foo");
}
END_TEST

START_TEST(empty_file)
{
    cli_write_text(cli_path("empty.xyz"), "");
    expect_fail("empty.xyz", "empty.xyz");
    cli_write_text(cli_path("empty.ply"), "");
    expect_fail("empty.ply", "empty.ply");
}
END_TEST

START_TEST(bad_ply_header)
{
    cli_write_text(cli_path("h1.ply"), "ply\nformat ascii 1.0\nelement vertex 2\n"
                                       "property float x\nproperty float y\n"
                                       "property flaot z\nend_header\n0 0 0\n1 1 1\n");
    expect_fail("h1.ply", "h1.ply:6");
    cli_write_text(cli_path("h2.ply"), "ply\nformat binary_middle_endian 1.0\n"
                                       "element vertex 1\nproperty float x\nend_header\n");
    expect_fail("h2.ply", "h2.ply:2");
    cli_write_text(cli_path("h3.ply"), "plx\nformat ascii 1.0\nend_header\n");
    expect_fail("h3.ply", "h3.ply:1");
    /* no end_header */
    cli_write_text(cli_path("h4.ply"), "ply\nformat ascii 1.0\nelement vertex 1\n"
                                       "property float x\nproperty float y\nproperty float z\n");
    expect_fail("h4.ply", "h4.ply");
}
END_TEST

/* A binary PLY claiming more vertices than its bytes can hold. */
START_TEST(count_too_large)
{
    FILE *f = fopen(cli_path("big.ply"), "wb");
    fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
               "property float x\nproperty float y\nproperty float z\nend_header\n");
    float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    fwrite(v, sizeof v, 1, f);
    fclose(f);
    expect_fail("big.ply", "big.ply");
}
END_TEST

START_TEST(truncated_body)
{
    cli_write_text(cli_path("t.ply"), "ply\nformat ascii 1.0\nelement vertex 5\n"
                                      "property float x\nproperty float y\nproperty float z\n"
                                      "end_header\n0 0 0\n1 0 0\n0 1 0\n");
    expect_fail("t.ply", "t.ply");
    double xyz[30];
    for (int i = 0; i < 30; i++) xyz[i] = i;
    cli_write_ply(cli_path("tb.ply"), xyz, 10, 1);
    /* cut the binary body in the middle of a vertex */
    ck_assert_int_eq(truncate(cli_path("tb.ply"), 200), 0);
    expect_fail("tb.ply", "tb.ply");
}
END_TEST

START_TEST(non_numeric)
{
    cli_write_text(cli_path("nn.xyz"), "0 0 0\n1 0 0\n0 1 zero\n1 1 1\n");
    expect_fail("nn.xyz", "nn.xyz:3");
    cli_write_text(cli_path("nn.ply"), "ply\nformat ascii 1.0\nelement vertex 2\n"
                                       "property float x\nproperty float y\nproperty float z\n"
                                       "end_header\n0 0 0\n1 x 1\n");
    expect_fail("nn.ply", "nn.ply:9");
}
END_TEST

START_TEST(short_row)
{
    cli_write_text(cli_path("s.xyz"), "0 0 0\n1 0 0\n0 1\n1 1 1\n");
    expect_fail("s.xyz", "s.xyz:3");
    cli_write_text(cli_path("s.csv"), "x,y,z\n0,0,0\n1,0\n");
    expect_fail("s.csv", "s.csv:3");
}
END_TEST

START_TEST(output_dir_missing)
{
    cli_write_text(cli_path("ok.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0\n");
    int rc = cli_run("estimate", cli_path("ok.xyz"), "-o", cli_path("nodir/out.ply"), NULL);
    ck_assert_int_ne(rc, 0);
    ck_assert_msg(strstr(cli_err, "nodir") != NULL, "stderr '%s'", cli_err);
    ck_assert_int_eq(cli_count_files(), 1);
    rc = cli_run("estimate", cli_path("ok.xyz"), "-o", cli_path("out.unknown"), NULL);
    ck_assert_int_ne(rc, 0);
    ck_assert_int_eq(cli_count_files(), 1);
}
END_TEST

/* Bad options: one line naming the option, exit 2, nothing written. */
START_TEST(bad_options)
{
    static const char *const cases[][2] = {
        {"--degree", "0"},         {"--degree", "two"},      {"--monge-degree", "5"},
        {"--fit", "exact"},        {"--frame", "world"},     {"--max-cond", "-3"},
        {"--orient", "up"},        {"--orient", "viewpoint:1,2"}, {"--normal", "magic"},
        {"--threads", "0"},        {"--neighbors", "knn:"},  {"--neighbors", "nearest:5"},
        {"--robust", "l1"},        {"--scales", "32,16"},    {"--columns", "0,1"},
        {"--bogus", "1"},
    };
    cli_write_text(cli_path("ok.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0\n");
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int rc = cli_run("estimate", cli_path("ok.xyz"), "-o", cli_path("o.csv"), cases[k][0],
                         cases[k][1], NULL);
        ck_assert_msg(rc == 2, "%s %s: exit %d", cases[k][0], cases[k][1], rc);
        ck_assert_msg(strstr(cli_err, cases[k][0]) != NULL, "%s: '%s'", cases[k][0], cli_err);
        char *nl = strchr(cli_err, '\n');
        ck_assert_msg(nl && nl[1] == '\0', "not one line: '%s'", cli_err);
        ck_assert(!cli_exists(cli_path("o.csv")));
    }
    /* --monge-degree above --degree */
    ck_assert_int_eq(cli_run("estimate", cli_path("ok.xyz"), "-o", cli_path("o.csv"),
                             "--monge-degree", "4", NULL), 2);
    ck_assert_int_ne(cli_run("estimate", cli_path("ok.xyz"), NULL), 0);
    ck_assert_int_ne(cli_run("estimate", "-o", cli_path("o.csv"), NULL), 0);
    ck_assert_int_eq(cli_run("estimate", "--help", NULL), 0);
}
END_TEST

/* A NaN coordinate is not fatal: its row is kept (NaN values, nonfinite)
 * and the other rows equal those of the cloud without it. */
START_TEST(nan_row_kept)
{
    size_t n = 400;
    double c[3] = {0, 0, 0}, *xyz = malloc(3 * (n + 1) * sizeof *xyz);
    cli_sphere(n, 1.0, c, xyz);
    cli_write_xyz(cli_path("clean.xyz"), xyz, NULL, n);
    memmove(xyz + 3 * 101, xyz + 3 * 100, 3 * (n - 100) * sizeof *xyz);
    xyz[300] = NAN;
    xyz[301] = 0.5;
    xyz[302] = INFINITY;
    cli_write_xyz(cli_path("nan.xyz"), xyz, NULL, n + 1);
    ck_assert_int_eq(cli_run("estimate", cli_path("clean.xyz"), "-o", cli_path("a.csv"),
                             "--neighbors", "knn:16", NULL), 0);
    ck_assert_int_eq(cli_run("estimate", cli_path("nan.xyz"), "-o", cli_path("b.csv"),
                             "--neighbors", "knn:16", NULL), 0);
    jf_eval_table a, b;
    cli_read(cli_path("a.csv"), &a);
    cli_read(cli_path("b.csv"), &b);
    ck_assert_uint_eq(a.nrows, n);
    ck_assert_uint_eq(b.nrows, n + 1);
    ck_assert_uint_eq((unsigned)cli_val(&b, 100, "status"), JF_PT_NONFINITE);
    ck_assert(isnan(cli_val(&b, 100, "nx")) && isnan(cli_val(&b, 100, "k1")));
    ck_assert(isnan(cli_val(&b, 100, "x")) && cli_val(&b, 100, "y") == 0.5);
    for (size_t i = 0; i < n; i++) {
        size_t j = i < 100 ? i : i + 1;
        for (size_t k = 0; k < a.ncols; k++)
            ck_assert_msg(memcmp(&a.v[i * a.ncols + k], &b.v[j * b.ncols + k], 8) == 0,
                          "row %zu col %zu", i, k);
    }
    jf_eval_table_free(&a);
    jf_eval_table_free(&b);
    free(xyz);
}
END_TEST

/* Two points: nothing can be fitted, but every row is written. */
START_TEST(too_few_points)
{
    cli_write_text(cli_path("two.xyz"), "0 0 0\n1 0 0\n");
    ck_assert_int_eq(cli_run("estimate", cli_path("two.xyz"), "-o", cli_path("two.csv"), NULL),
                     0);
    jf_eval_table t;
    cli_read(cli_path("two.csv"), &t);
    ck_assert_uint_eq(t.nrows, 2);
    for (size_t i = 0; i < 2; i++) {
        unsigned st = (unsigned)cli_val(&t, i, "status");
        ck_assert_uint_ne(st & JF_PT_FAILED, 0);
        ck_assert(isnan(cli_val(&t, i, "k1")));
    }
    ck_assert_double_eq(cli_val(&t, 1, "x"), 1.0);
    jf_eval_table_free(&t);
    /* five points, degree 2 asked (needs 6): a lower degree, a status */
    cli_write_text(cli_path("five.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0.1\n0.5 0.3 0.02\n");
    ck_assert_int_eq(cli_run("estimate", cli_path("five.xyz"), "-o", cli_path("five.csv"), NULL),
                     0);
    cli_read(cli_path("five.csv"), &t);
    ck_assert_uint_eq(t.nrows, 5);
    for (size_t i = 0; i < 5; i++) {
        ck_assert_double_eq(cli_val(&t, i, "degree"), 1);
        unsigned st = (unsigned)cli_val(&t, i, "status");
        ck_assert_uint_ne(st & (JF_PT_LOWERED_FEW | JF_PT_FEW_NEIGHBORS), 0);
    }
    jf_eval_table_free(&t);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_errors");
    TCase *tc = tcase_create("cli_errors");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, missing_file);
    tcase_add_test(tc, unknown_extension);
    tcase_add_test(tc, empty_file);
    tcase_add_test(tc, bad_ply_header);
    tcase_add_test(tc, count_too_large);
    tcase_add_test(tc, truncated_body);
    tcase_add_test(tc, non_numeric);
    tcase_add_test(tc, short_row);
    tcase_add_test(tc, output_dir_missing);
    tcase_add_test(tc, bad_options);
    tcase_add_test(tc, nan_row_kept);
    tcase_add_test(tc, too_few_points);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
