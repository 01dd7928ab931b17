/* test_io_text_edges.c -- issue 30.5 and the PTX transform check: a UTF-8
 * byte order mark before a PTX, ascii (and binary) PLY or OFF file is
 * skipped (the same cloud as without it, line numbers unchanged); a PTX
 * registration that is not a rotation (a scale, a shear, a mirror) is
 * refused naming the scan and the line, one printed to four digits read. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_txte_XXXXXX"); }

#define BOM "\xEF\xBB\xBF"

/* Reads text (or len bytes) as `name` with and without a BOM before it:
 * both read, the same points bit for bit. */
static void same_with_bom(const char *name, const char *text, size_t len)
{
    char *b = malloc(len + 3);
    memcpy(b, BOM, 3);
    memcpy(b + 3, text, len);
    jf_cloud a, c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(fixture(name, text, len), NULL, &a, &e) == JF_OK, "%s", e.msg);
    ck_assert_msg(jf_cloud_read(fixture(name, b, len + 3), NULL, &c, &e) == JF_OK,
                  "%s with a BOM: %s", name, e.msg);
    ck_assert_uint_eq(a.n, c.n);
    ck_assert_uint_eq(a.nfaces, c.nfaces);
    ck_assert(!memcmp(a.xyz, c.xyz, 3 * a.n * sizeof(double)) || a.n == 0);
    jf_cloud_free(&a);
    jf_cloud_free(&c);
    free(b);
}

static const char ptx[] = "2\n1\n"
                          "0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                          "1 0 0 0\n0 1 0 0\n0 0 1 0\n10 20 30 1\n"
                          "1 2 3 0.5\n4 5 6 0.5\n";

START_TEST(bom_skipped)
{
    same_with_bom("a.ptx", ptx, strlen(ptx));
    static const char ply[] = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\n"
                              "property double y\nproperty double z\nend_header\n1 2 3\n4 5 6.5\n";
    same_with_bom("a.ply", ply, strlen(ply));
    /* binary: the body starts where the header ends, BOM included */
    char bin[200];
    static const char bh[] = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n";
    float v[6] = {1, 2, 3, 4, 5, 6.5f};
    memcpy(bin, bh, strlen(bh));
    memcpy(bin + strlen(bh), v, sizeof v);
    same_with_bom("b.ply", bin, strlen(bh) + sizeof v);
    static const char off[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n";
    same_with_bom("a.off", off, strlen(off));
    static const char noff[] = "3 1 0\n0 0 0\n1 0 0\n0 1 0.5\n3 0 1 2\n"; /* no keyword */
    same_with_bom("n.off", noff, strlen(noff));
    /* a BOM is skipped once, at the start only: a second one is an error
     * on line 1, as any stray bytes */
    char two[sizeof ptx + 6];
    memcpy(two, BOM BOM, 6);
    memcpy(two + 6, ptx, sizeof ptx);
    jf_cloud c;
    jf_error e;
    const char *p = fixture("two.ptx", two, 6 + strlen(ptx));
    ck_assert_int_ne(jf_cloud_read(p, NULL, &c, &e), JF_OK);
    ck_assert_msg(strstr(e.msg, ":1: scan 1: expected the column count"), "'%s'", e.msg);
}
END_TEST

/* The table reader of eval and render (jf_eval_table_read): the same
 * names and values with a BOM before a CSV or a PLY. */
START_TEST(bom_eval_tables)
{
    static const char csv[] = "x,y,z,k1\n1,2,3,0.5\n";
    static const char ply[] = "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\n"
                              "property double y\nproperty double z\nproperty double k1\n"
                              "end_header\n1 2 3 0.5\n";
    const char *t[2][2] = {{"t.csv", csv}, {"t.ply", ply}};
    for (int k = 0; k < 2; k++) {
        char b[512];
        memcpy(b, BOM, 3);
        memcpy(b + 3, t[k][1], strlen(t[k][1]));
        jf_eval_table a;
        jf_error e = {{0}};
        ck_assert_msg(jf_eval_table_read(fixture(t[k][0], b, 3 + strlen(t[k][1])), &a, &e) == JF_OK,
                      "%s: %s", t[k][0], e.msg);
        ck_assert_uint_eq(a.nrows, 1);
        ck_assert_uint_eq(a.ncols, 4);
        ck_assert_str_eq(a.names[0], "x");
        ck_assert(a.v[3] == 0.5);
        jf_eval_table_free(&a);
    }
}
END_TEST

/* A one-scan PTX whose rotation rows are r (3 lines of text). */
static jf_status ptx_rot(const char *rows, jf_cloud *c, jf_error *e)
{
    char t[512];
    snprintf(t, sizeof t, "2\n1\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n%s10 20 30 1\n1 2 3 0.5\n4 5 6 0.5\n",
             rows);
    return jf_cloud_read(fixture("r.ptx", t, strlen(t)), NULL, c, e);
}

START_TEST(ptx_rotation)
{
    jf_cloud c;
    jf_error e;
    /* 30 degrees about z, printed to 17 digits and to 4 */
    char rows[256];
    double cs = sqrt(3.0) / 2, sn = 0.5;
    snprintf(rows, sizeof rows, "%.17g %.17g 0 0\n%.17g %.17g 0 0\n0 0 1 0\n", cs, sn, -sn, cs);
    ck_assert_msg(ptx_rot(rows, &c, &e) == JF_OK, "%s", e.msg);
    /* row vectors: [1 2 3 1] M */
    ck_assert_double_eq_tol(c.xyz[0], 1 * cs - 2 * sn + 10, 1e-12);
    jf_cloud_free(&c);
    ck_assert_msg(ptx_rot("0.8660 0.5000 0 0\n-0.5000 0.8660 0 0\n0 0 1 0\n", &c, &e) == JF_OK,
                  "%s", e.msg);
    jf_cloud_free(&c);
    /* a scale (mm to m), a shear, a mirror */
    ck_assert_int_eq(ptx_rot("0.001 0 0 0\n0 0.001 0 0\n0 0 0.001 0\n", &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, "r.ptx:10: scan 1: transform: the rotation rows are not "
                                "orthonormal (|R R^T - I| = 1, determinant 1e-09)"),
                  "'%s'", e.msg);
    ck_assert_int_eq(ptx_rot("1 0.1 0 0\n0 1 0 0\n0 0 1 0\n", &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, "not orthonormal (|R R^T - I| = 0.1,"), "'%s'", e.msg);
    ck_assert_int_eq(ptx_rot("1 0 0 0\n0 1 0 0\n0 0 -1 0\n", &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, "scan 1: transform: the rotation rows are a reflection "
                                "(|R R^T - I| = 0, determinant -1)"),
                  "'%s'", e.msg);
    ck_assert_ptr_null(strchr(e.msg, '\n'));
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_text_edges");
    TCase *tc = tcase_create("core");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, bom_skipped);
    tcase_add_test(tc, ptx_rotation);
    tcase_add_test(tc, bom_eval_tables);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
