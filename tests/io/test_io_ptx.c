/* test_io_ptx.c -- the PTX reader (issue 13, item 3): two scans of a sphere
 * from opposite sides, each in its own frame with a non-trivial rotation
 * and translation, read back into the registered frame bit for bit (the
 * reader's row-vector transform recomputed here on the written numbers)
 * and within 1e-12 of the points they were made from; "0 0 0" cells kept
 * as NaN rows; scan indices and scanner positions exact; every header lie
 * a one-line FILE:LINE error. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "test_ptx_sphere.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_ptx_XXXXXX"); }

START_TEST(two_scans_exact)
{
    char path[256];
    snprintf(path, sizeof path, "%s/two.ptx", tmpdir);
    ptx_write(path);
    jf_cloud c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(c.n, PTX_N);
    ck_assert_uint_eq(c.nscans, 2);
    ck_assert_ptr_nonnull(c.scan);
    ck_assert_ptr_null(c.nrm);
    size_t nan_rows = 0;
    for (int s = 0; s < 2; s++) {
        double R[3][3];
        const double *t = ptx_S[s];
        ptx_rot(s, R);
        for (int k = 0; k < 3; k++) ck_assert(c.scanner[3 * s + k] == t[k]);
        for (int col = 0; col < PTX_COLS; col++)
            for (int row = 0; row < PTX_ROWS; row++) {
                size_t i = (size_t)s * PTX_COLS * PTX_ROWS + (size_t)col * PTX_ROWS + row;
                const double *x = c.xyz + 3 * i;
                ck_assert_uint_eq(c.scan[i], (uint32_t)s);
                if (ptx_noreturn(row, col)) {
                    ck_assert(isnan(x[0]) && isnan(x[1]) && isnan(x[2]));
                    nan_rows++;
                    continue;
                }
                double p[3], q[3];
                ptx_point(s, row, col, p);
                for (int j = 0; j < 3; j++)
                    q[j] = (p[0] - t[0]) * R[j][0] + (p[1] - t[1]) * R[j][1] + (p[2] - t[2]) * R[j][2];
                for (int a = 0; a < 3; a++) {
                    double want = q[0] * R[0][a] + q[1] * R[1][a] + q[2] * R[2][a] + t[a];
                    ck_assert_msg(x[a] == want, "point %zu axis %d: %.17g != %.17g", i, a, x[a], want);
                    ck_assert_double_eq_tol(x[a], p[a], 1e-12);
                }
            }
    }
    ck_assert_uint_eq(nan_rows, 2 * (PTX_COLS + 1));
    jf_cloud_free(&c);
    ck_assert_ptr_null(c.scan);
    ck_assert_ptr_null(c.scanner);
    ck_assert_uint_eq(c.nscans, 0);

    /* the pipeline marks the no-return rows nonfinite */
    ck_assert(jf_cloud_read(path, NULL, &c, &e) == JF_OK);
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.orient = JF_ORIENT_SCANNER;
    jf_result *res = calloc(c.n, sizeof *res);
    ck_assert_msg(jf_estimate(&c, &o, res, &e) == JF_OK, "%s", e.msg);
    for (size_t i = 0; i < c.n; i++) {
        const double *x = c.xyz + 3 * i, *sp = c.scanner + 3 * c.scan[i];
        if (isnan(x[0])) {
            ck_assert(res[i].status & JF_PT_NONFINITE);
            continue;
        }
        double d = 0;
        for (int k = 0; k < 3; k++) d += res[i].normal[k] * (sp[k] - x[k]);
        ck_assert_msg(d > 0, "point %zu faces away from its scanner", i);
    }
    free(res);
    jf_cloud_free(&c);
}
END_TEST

static const char HDR_REST[] = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";

static void refused(const char *text, jf_status want, const char *where, const char *reason)
{
    char path[256], tag[300];
    snprintf(path, sizeof path, "%s/bad.ptx", tmpdir);
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    jf_cloud c;
    jf_error e = {{0}};
    jf_status st = jf_cloud_read(path, NULL, &c, &e);
    ck_assert_msg(st == want, "%s: status %d, %s", reason, (int)st, e.msg);
    snprintf(tag, sizeof tag, "%s%s: ", path, where);
    ck_assert_msg(!strncmp(e.msg, tag, strlen(tag)) && strstr(e.msg, reason),
                  "want '%s...%s', got '%s'", tag, reason, e.msg);
    ck_assert(!strchr(e.msg, '\n'));
    ck_assert_ptr_null(c.xyz);
    ck_assert_ptr_null(c.scan);
    ck_assert_ptr_null(c.scanner);
}

START_TEST(lies_refused)
{
    char b[1024];
    refused("abc\n2\n", JF_ERR_FORMAT, ":1", "column count");
    refused("2\n0\n", JF_ERR_FORMAT, ":2", "row count");
    refused("2\n2 3\n", JF_ERR_FORMAT, ":2", "row count");
    refused("2\n", JF_ERR_FORMAT, ":1", "ends before its row count");
    refused("1\n1\n0 0\n", JF_ERR_FORMAT, ":3", "scanner position: expected 3 numbers");
    refused("1\n1\n0 0 0\n1 0 0\n0 1 0\n", JF_ERR_FORMAT, ":5", "ends before its scanner axis Z");
    refused("1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 nan 1\n1 1 1 1\n",
            JF_ERR_FORMAT, ":10", "transform row 4: not finite");
    /* the column-vector convention (translation in the last column) */
    refused("1\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0 0 5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 1 1 1\n",
            JF_ERR_FORMAT, ":10", "last column must be 0 0 0 1");
    snprintf(b, sizeof b, "1000\n1000\n%s1 1 1 1\n", HDR_REST);
    refused(b, JF_ERR_TOO_LARGE, ":2", "cannot fit");
    snprintf(b, sizeof b, "2\n2\n%s1 1 1 1\n1 1 1 1\n1 1 1 1\n", HDR_REST);
    refused(b, JF_ERR_FORMAT, ":13", "ends after 3 of its 4 points");
    snprintf(b, sizeof b, "1\n2\n%s1 1 1 1\n1 2 3\n", HDR_REST);
    refused(b, JF_ERR_FORMAT, ":12", "expected x y z intensity [r g b]");
    snprintf(b, sizeof b, "1\n1\n%s1 2 x 4\n", HDR_REST);
    refused(b, JF_ERR_FORMAT, ":11", "expected x y z intensity");
    snprintf(b, sizeof b, "1\n1\n%s1 2 3 4 5\n", HDR_REST);
    refused(b, JF_ERR_FORMAT, ":11", "expected x y z intensity");
    /* a second scan whose header stops short */
    snprintf(b, sizeof b, "1\n1\n%s1 1 1 1\n1\n1\n0 0 0\n", HDR_REST);
    refused(b, JF_ERR_FORMAT, ":14", "scan 2: the file ends before its scanner axis X");
    refused("\n\n  \n", JF_ERR_FORMAT, "", "no scan");
}
END_TEST

/* Where the scanner is (Leica's PTX description, quoted in io_ptx.c): the
 * position line is already registered, never moved by the 4x4 M; but M
 * may also hold the export's UCS, which the line does not.  Scan 1: an
 * unregistered scan (line 0 0 0, axes identity) exported in a UCS (M a
 * rotation and a translation): its points and its scanner land in the UCS
 * frame, the scanner at M's translation row.  Scan 2: M the identity,
 * points written already registered: the position line.  Scan 3: Leica's
 * usual registered export (line = translation row): that position. */
START_TEST(scanner_position)
{
    char path[256];
    snprintf(path, sizeof path, "%s/ucs.ptx", tmpdir);
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs("1\n2\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
          "0 1 0 0\n-1 0 0 0\n0 0 1 0\n100 200 30 1\n"
          "2 0 0 0.5\n0 3 0 0.5\n", f);
    fputs("1\n1\n7 8 9\n1 0 0\n0 1 0\n0 0 1\n"
          "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"
          "9 8 7 0.5\n", f);
    fputs("1\n1\n5 6 7\n0 1 0\n-1 0 0\n0 0 1\n"
          "0 1 0 0\n-1 0 0 0\n0 0 1 0\n5 6 7 1\n"
          "1 0 0 0.5\n", f);
    fclose(f);
    jf_cloud c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(c.nscans, 3);
    ck_assert_uint_eq(c.n, 4);
    /* scan 1: (2 0 0) M = (100, 202, 30), (0 3 0) M = (97, 200, 30) */
    static const double want_xyz[4][3] = {{100, 202, 30}, {97, 200, 30}, {9, 8, 7}, {5, 7, 7}};
    static const double want_sc[3][3] = {{100, 200, 30}, {7, 8, 9}, {5, 6, 7}};
    for (int i = 0; i < 4; i++)
        for (int a = 0; a < 3; a++) ck_assert(c.xyz[3 * i + a] == want_xyz[i][a]);
    for (int s = 0; s < 3; s++)
        for (int a = 0; a < 3; a++)
            ck_assert_msg(c.scanner[3 * s + a] == want_sc[s][a], "scan %d axis %d: %g", s + 1, a,
                          c.scanner[3 * s + a]);
    jf_cloud_free(&c);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("io_ptx");
    TCase *tc = tcase_create("ptx");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, two_scans_exact);
    tcase_add_test(tc, lies_refused);
    tcase_add_test(tc, scanner_position);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return jf_test_run(suite());
}
