/* test_io_hostile.c -- issue 11, items 8-10: inputs that used to be read
 * silently wrong now give one line naming the file and the line (each
 * case said below with what happened before), and what a raw scan
 * legitimately holds (a BOM, CR line ends, bad rows with --bad-rows skip)
 * reads right. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_hostile_XXXXXX"); }

/* Expects a failure whose one-line message starts with the path and
 * holds `what` (and `line` as ":N:" when given). */
static void refused(const char *name, const char *s, size_t len, const char *what, int line)
{
    const char *path = fixture(name, s, len ? len : strlen(s));
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) != JF_OK, "%s was read", name);
    ck_assert_msg(strstr(e.msg, path) == e.msg, "%s: '%s'", name, e.msg);
    ck_assert_msg(strstr(e.msg, what), "%s: '%s' lacks '%s'", name, e.msg, what);
    if (line) {
        char at[32];
        snprintf(at, sizeof at, ":%d:", line);
        ck_assert_msg(strstr(e.msg, at), "%s: '%s' lacks line %d", name, e.msg, line);
    }
    ck_assert_ptr_null(strchr(e.msg, '\n'));
    ck_assert_ptr_null(c.xyz);
}

/* Before: read as six numbers per row, rc 0, every row failed. */
START_TEST(decimal_commas)
{
    refused("dc.xyz", "-0,352 -0,698 0,736\n0,5 0,25 0,125\n", 0, "decimal comma", 1);
    /* a first row of integers, then commas: named too (before: "6 columns") */
    /* ';'-separated with decimal commas (before: "1,5;2,5;3,5" was 1 5 2) */
    refused("dc3.xyz", "1,5;2,5;3,5\n4,5;5,5;6,5\n", 0, "decimal comma", 1);
    refused("dc2.xyz", "0 0 1\n0,5 0,25 0,125\n", 0, "decimal comma", 2);
    /* comma-separated values are still fine */
    jf_cloud c;
    const char *p = fixture("cs.xyz", "1.5,2.5,3.5\n4,5,6\n", strlen("1.5,2.5,3.5\n4,5,6\n"));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[0] == 1.5 && c.xyz[5] == 6);
    jf_cloud_free(&c);
}
END_TEST

/* Before: a CR-only file of 100 points was one point (rc 0). */
START_TEST(cr_line_ends)
{
    char buf[4096], *o = buf;
    for (int i = 0; i < 100; i++) o += sprintf(o, "%d %d.5 %d.25\r", i, i, i);
    jf_cloud c;
    const char *p = fixture("mac.xyz", buf, (size_t)(o - buf));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert_uint_eq(c.n, 100);
    ck_assert(c.xyz[3 * 99] == 99 && c.xyz[3 * 99 + 2] == 99.25);
    jf_cloud_free(&c);
    /* CRLF still reads as before */
    p = fixture("dos.xyz", "1 2 3\r\n4 5 6\r\n", strlen("1 2 3\r\n4 5 6\r\n"));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert_uint_eq(c.n, 2);
    jf_cloud_free(&c);
}
END_TEST

/* Before: extra columns in later rows were ignored silently. */
START_TEST(column_count)
{
    refused("w.xyz", "1 2 3\n4 5 6\n7 8 9 10\n", 0, "4 columns, the first data row has 3", 3);
    refused("w.csv", "x,y,z\n1,2,3\n4,5,6,7\n", 0, "4 columns", 3);
}
END_TEST

/* Before: "'\ufeff1' is not a number"; the CSV header was not found. */
START_TEST(bom)
{
    jf_cloud c;
    const char *p = fixture("b.csv", "\xEF\xBB\xBFz,y,x\n3,2,1\n6,5,4\n", strlen("\xEF\xBB\xBFz,y,x\n3,2,1\n6,5,4\n"));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert(c.n == 2 && c.xyz[0] == 1 && c.xyz[2] == 3);
    jf_cloud_free(&c);
    p = fixture("b.xyz", "\xEF\xBB\xBF" "1 2 3\n4 5 6\n", strlen("\xEF\xBB\xBF" "1 2 3\n4 5 6\n"));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert(c.n == 2 && c.xyz[0] == 1);
    jf_cloud_free(&c);
}
END_TEST

/* Before: "'' is not a number" or a short row, with the NUL invisible. */
START_TEST(nul_byte)
{
    refused("z.xyz", "1 2 3\n4 5\0 6\n", 11, "NUL byte", 2);
    /* ascii PLY: body (before: "'' is not a number") and header (before:
     * "z\0" read as the name z, rc 0) */
    static const char zp[] = "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\n"
                             "property double y\nproperty double z\nend_header\n0 0 0\n1 \0 0\n";
    refused("z.ply", zp, sizeof zp - 1, "NUL byte", 9);
    static const char zh[] = "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\n"
                             "property double y\nproperty double z\0\nend_header\n0 0 0\n";
    refused("zh.ply", zh, sizeof zh - 1, "NUL byte in the header", 6);
    refused("z.off", "OFF\n3 1 0\n0 0 0\n1\0 0 0\n0 1 0\n3 0 1 2\n", 36, "NUL byte", 4);
}
END_TEST

/* Before: "bad count 'BINARY'". */
START_TEST(off_binary)
{
    refused("b.off", "OFF BINARY\n3 1 0\n", 0, "binary OFF is not supported", 1);
}
END_TEST

/* Before: all silent. */
START_TEST(counts_and_duplicates)
{
    refused("short.ply",
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
            "property double z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
            0, "smaller than the rows", 10);
    refused("dup.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
            "property double z\nproperty double x\nend_header\n0 0 0 1\n",
            0, "property 'x' appears twice", 7);
    refused("dup.csv", "x,y,z,x\n1,2,3,4\n", 0, "column 'x' appears twice", 1);
    /* binary: a third float row after a count of 2 (before: silent) */
    static const char hb[] = "ply\nformat binary_little_endian 1.0\nelement vertex 2\n"
                             "property float x\nproperty float y\nproperty float z\nend_header\n";
    char bin[sizeof hb + 3 * 12 + 1];
    memcpy(bin, hb, sizeof hb - 1);
    for (int i = 0; i < 9; i++) {
        float f = (float)i;
        memcpy(bin + sizeof hb - 1 + 4 * i, &f, 4);
    }
    bin[sizeof hb - 1 + 36] = '\n';
    refused("short_bin.ply", bin, sizeof hb - 1 + 36, "12 bytes after the last element", 0);
    refused("c.pts", "5\n1 2 3\n4 5 6\n7 8 9\n", 0, "count line says 5 points, 3 rows", 1);
    /* a right count, and two scans each with theirs, still read */
    jf_cloud c;
    /* two rows and a writer's trailing newline still read */
    memcpy(bin + sizeof hb - 1 + 24, "\n", 1);
    const char *b2 = fixture("nl_bin.ply", bin, sizeof hb - 1 + 25);
    ck_assert_int_eq(jf_cloud_read(b2, NULL, &c, NULL), JF_OK);
    ck_assert(c.n == 2 && c.xyz[5] == 5);
    jf_cloud_free(&c);
    const char *p = fixture("ok.pts", "2\n1 2 3\n4 5 6\n1\n7 8 9\n", strlen("2\n1 2 3\n4 5 6\n1\n7 8 9\n"));
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, NULL), JF_OK);
    ck_assert_uint_eq(c.n, 3);
    jf_cloud_free(&c);
}
END_TEST

/* bad_rows = skip: the row stays, as NaN, and every later row keeps its
 * index; the count and the lines are reported. */
START_TEST(bad_rows_skip)
{
    const char *text = "1 2 3\n4 5 6\ngarbage 1 2\n7 8 9\n10 11\n12 13 14\n";
    const char *p = fixture("g.xyz", text, strlen(text));
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, &e), JF_ERR_FORMAT);
    ck_assert_ptr_nonnull(strstr(e.msg, ":3:"));
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.bad_rows = 1;
    ck_assert_int_eq(jf_cloud_read(p, &o, &c, &e), JF_OK);
    ck_assert_uint_eq(c.n, 6);
    ck_assert_uint_eq(c.nbad, 2);
    ck_assert_uint_eq(c.bad_line[0], 3);
    ck_assert_uint_eq(c.bad_line[1], 5);
    ck_assert(isnan(c.xyz[6]) && isnan(c.xyz[12]));
    ck_assert(c.xyz[9] == 7 && c.xyz[15] == 12);
    jf_cloud_free(&c);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_hostile");
    TCase *tc = tcase_create("read");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, decimal_commas);
    tcase_add_test(tc, cr_line_ends);
    tcase_add_test(tc, column_count);
    tcase_add_test(tc, bom);
    tcase_add_test(tc, nul_byte);
    tcase_add_test(tc, off_binary);
    tcase_add_test(tc, counts_and_duplicates);
    tcase_add_test(tc, bad_rows_skip);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
