/* test_cli_ptx.c -- `jetfit estimate` on a PTX file (issue 13, item 3): two
 * scans of a sphere from opposite sides, in their own frames; by default
 * every normal faces the scanner that measured its point (and the sphere's
 * outside), where --orient none leaves some facing away; the "0 0 0" cells
 * are rows with status nonfinite; --orient scanner on an .xyz is refused
 * with one line and no output. */
#include <check.h>

#include "test_cli_util.h"
#include "../io/test_ptx_sphere.h"
#include "jf_test.h"

/* n . (S - p) for row i of t, p and S from the generator (NaN for a
 * no-return cell). */
static double facing(const jf_eval_table *t, size_t i)
{
    int s = (int)(i / (PTX_COLS * PTX_ROWS)), col = (int)(i % (PTX_COLS * PTX_ROWS)) / PTX_ROWS,
        row = (int)(i % PTX_ROWS);
    if (ptx_noreturn(row, col)) return NAN;
    double p[3], d = 0;
    static const char *const nn[] = {"nx", "ny", "nz"};
    ptx_point(s, row, col, p);
    for (int k = 0; k < 3; k++) d += cli_val(t, i, nn[k]) * (ptx_S[s][k] - p[k]);
    return d;
}

START_TEST(normals_face_their_scanner)
{
    ptx_write(cli_path("two.ptx"));
    int rc = cli_run("estimate", cli_path("two.ptx"), "-o", cli_path("out.csv"), "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    rc = cli_run("estimate", cli_path("two.ptx"), "-o", cli_path("none.csv"), "--orient", "none",
                 "--quiet", NULL);
    ck_assert_msg(rc == 0, "%s", cli_err);
    jf_eval_table a, b;
    cli_read(cli_path("out.csv"), &a);
    cli_read(cli_path("none.csv"), &b);
    ck_assert_uint_eq(a.nrows, PTX_N);
    size_t away_none = 0, nonfinite = 0;
    for (size_t i = 0; i < PTX_N; i++) {
        double f = facing(&a, i);
        if (isnan(f)) {
            ck_assert_uint_eq((unsigned)cli_val(&a, i, "status"), JF_PT_NONFINITE);
            nonfinite++;
            continue;
        }
        ck_assert_msg(f > 0, "row %zu faces away from its scanner", i);
        /* and is the sphere's outward normal */
        int s = (int)(i / (PTX_COLS * PTX_ROWS));
        double p[3], r = 0;
        ptx_point(s, (int)(i % PTX_ROWS), (int)(i % (PTX_COLS * PTX_ROWS)) / PTX_ROWS, p);
        r += cli_val(&a, i, "nx") * (p[0] - ptx_C[0]) + cli_val(&a, i, "ny") * (p[1] - ptx_C[1]) +
             cli_val(&a, i, "nz") * (p[2] - ptx_C[2]);
        ck_assert_msg(r / ptx_R > 0.99, "row %zu: n . radial = %g", i, r / ptx_R);
        away_none += facing(&b, i) < 0;
    }
    ck_assert_uint_eq(nonfinite, 2 * (PTX_COLS + 1));
    ck_assert_msg(away_none > 0, "--orient none: all normals already face their scanner");
    jf_eval_table_free(&a);
    jf_eval_table_free(&b);
}
END_TEST

START_TEST(scanner_without_positions_refused)
{
    cli_write_text(cli_path("s.xyz"), "0 0 0\n1 0 0\n0 1 0\n1 1 0.1\n0.5 0.5 0\n2 0 0\n0 2 0\n");
    int rc = cli_run("estimate", cli_path("s.xyz"), "-o", cli_path("o.csv"), "--orient", "scanner",
                     NULL);
    ck_assert_int_eq(rc, 1);
    ck_assert_msg(strstr(cli_err, "s.xyz: --orient scanner needs the scanner positions"), "%s",
                  cli_err);
    ck_assert_msg(!strchr(cli_err, '\n') || strchr(cli_err, '\n')[1] == '\0', "one line: %s", cli_err);
    ck_assert(!cli_exists(cli_path("o.csv")));
}
END_TEST

/* The same on a LAS file (issue 13: "refused with a clear line"); the LAS
 * comes from `jetfit generate -o s.las`, which also checks that the
 * generator writes LAS at all. */
START_TEST(scanner_on_las_refused)
{
    ck_assert_int_eq(cli_run("generate", "sphere", "--n", "200", "-o", cli_path("s.las"), NULL), 0);
    ck_assert(cli_exists(cli_path("s.las")));
    int rc = cli_run("estimate", cli_path("s.las"), "-o", cli_path("o.las"), "--orient", "scanner",
                     NULL);
    ck_assert_int_eq(rc, 1);
    ck_assert_msg(strstr(cli_err, "s.las: --orient scanner needs the scanner positions"), "%s",
                  cli_err);
    ck_assert_msg(!strchr(cli_err, '\n') || strchr(cli_err, '\n')[1] == '\0', "one line: %s", cli_err);
    ck_assert(!cli_exists(cli_path("o.las")));
    /* without the option the LAS file is estimated */
    ck_assert_int_eq(cli_run("estimate", cli_path("s.las"), "-o", cli_path("o.las"), "--quiet",
                             NULL), 0);
    ck_assert(cli_exists(cli_path("o.las")));
}
END_TEST

int main(void)
{
    Suite *s = suite_create("cli_ptx");
    TCase *tc = tcase_create("cli_ptx");
    tcase_add_checked_fixture(tc, cli_setup, cli_teardown);
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, normals_face_their_scanner);
    tcase_add_test(tc, scanner_without_positions_refused);
    tcase_add_test(tc, scanner_on_las_refused);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
