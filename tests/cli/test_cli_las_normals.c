/* test_cli_las_normals.c -- a LAS file jetfit wrote carries its normals
 * as nx ny nz Extra Bytes; read back they are the cloud's normals (issue
 * 31), so --orient input works on it and follows them.  Its header says
 * when it was made (creation day and year, not 0/0). */
#include <time.h>
#include <check.h>

#include "jf_test.h"
#include "test_cli_util.h"

START_TEST(las_extra_bytes_are_normals)
{
    cli_setup();
    enum { N = 1500 };
    double *xyz = malloc(3 * N * sizeof *xyz);
    const double c[3] = {0, 0, 0};
    cli_sphere(N, 2.0, c, xyz);
    cli_write_xyz(cli_path("s.xyz"), xyz, NULL, N);
    /* towards the centre: every normal points inwards (n.x < 0) */
    ck_assert_int_eq(cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("in.las"), "--quiet",
                             "--orient", "viewpoint:0,0,0", NULL), 0);
    jf_cloud cl;
    jf_error e = {{0}};
    ck_assert_int_eq(jf_cloud_read(cli_path("in.las"), NULL, &cl, &e), JF_OK);
    ck_assert_ptr_nonnull(cl.nrm);
    size_t inward = 0;
    for (size_t i = 0; i < cl.n; i++) {
        double d = 0, len = 0;
        for (int a = 0; a < 3; a++) d += cl.nrm[3 * i + a] * cl.xyz[3 * i + a], len += cl.nrm[3 * i + a] * cl.nrm[3 * i + a];
        inward += d < 0;
        ck_assert_double_eq_tol(len, 1.0, 1e-9);
    }
    ck_assert_uint_eq(inward, N);
    jf_cloud_free(&cl);
    /* --orient input follows them; --keep none reads them too */
    ck_assert_int_eq(cli_run("estimate", cli_path("in.las"), "-o", cli_path("r.csv"), "--quiet",
                             "--orient", "input", "--keep", "none", "--neighbors", "knn:20", NULL), 0);
    jf_eval_table t;
    cli_read(cli_path("r.csv"), &t);
    for (size_t i = 0; i < N; i++) {
        double d = cli_val(&t, i, "nx") * cli_val(&t, i, "x") + cli_val(&t, i, "ny") * cli_val(&t, i, "y") +
                   cli_val(&t, i, "nz") * cli_val(&t, i, "z");
        ck_assert_msg(d < 0, "point %zu: n.x = %g, not inwards", i, d);
    }
    jf_eval_table_free(&t);
    free(xyz);
    cli_teardown();
}
END_TEST

/* bytes 90..93 of the header: day of year and year, little endian */
static void las_date(const char *path, unsigned *day, unsigned *year)
{
    unsigned char h[94];
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fread(h, 1, sizeof h, f), sizeof h);
    fclose(f);
    *day = h[90] | h[91] << 8;
    *year = h[92] | h[93] << 8;
}

START_TEST(las_creation_date)
{
    cli_setup();
    cli_write_text(cli_path("p.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0.1\n0.5 0.5 0\n2 2 0\n2 0 0.2\n0 2 0\n");
    time_t t0 = time(NULL);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("d.las"), "--quiet",
                             "--neighbors", "knn:6", NULL), 0);
    time_t t1 = time(NULL);
    unsigned day, year;
    las_date(cli_path("d.las"), &day, &year);
    struct tm a, b;
    gmtime_r(&t0, &a);
    gmtime_r(&t1, &b);
    ck_assert_msg((day == (unsigned)a.tm_yday + 1 && year == (unsigned)a.tm_year + 1900) ||
                      (day == (unsigned)b.tm_yday + 1 && year == (unsigned)b.tm_year + 1900),
                  "creation day %u year %u", day, year);
    /* SOURCE_DATE_EPOCH (reproducible files): 2000-03-01 is day 61 of a leap year */
    setenv("SOURCE_DATE_EPOCH", "951868800", 1);
    ck_assert_int_eq(cli_run("estimate", cli_path("p.xyz"), "-o", cli_path("e.las"), "--quiet",
                             "--neighbors", "knn:6", NULL), 0);
    unsetenv("SOURCE_DATE_EPOCH");
    las_date(cli_path("e.las"), &day, &year);
    ck_assert_uint_eq(day, 61);
    ck_assert_uint_eq(year, 2000);
    cli_teardown();
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_las_normals");
    TCase *t = tcase_create("las");
    tcase_set_timeout(t, 120);
    tcase_add_test(t, las_extra_bytes_are_normals);
    tcase_add_test(t, las_creation_date);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
