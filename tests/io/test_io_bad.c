/*
 * test_io_bad.c -- every kind of bad input gives a non-OK status, ONE line
 * naming the file, the place and the reason, and an empty cloud (ASan and
 * valgrind check that nothing leaks).  Also replays the fuzzers'
 * regression inputs (tests/fuzz/regress/<reader>/) through the readers.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io_internal.h"
#include "jetfit.h"

#include "test_io_util.h"
#include "jf_test.h"

/* Reads `name` holding `s`; expects status `st` and a message holding
 * the file name and every one of the (up to 3) fragments. */
static void bad(const char *name, const char *s, size_t len, jf_status st,
                const char *f1, const char *f2, const char *f3)
{
    const char *path = fixture(name, s, len ? len : strlen(s));
    jf_cloud c;
    memset(&c, 0x5a, sizeof c); /* garbage in: must come back zeroed */
    jf_error e;
    jf_status got = jf_cloud_read(path, NULL, &c, &e);
    ck_assert_msg(got == st, "%s: status %d (%s), want %d", name, got, e.msg,
                  st);
    ck_assert_msg(strstr(e.msg, path) == e.msg, "%s: message '%s'", name,
                  e.msg);
    ck_assert_ptr_null(strchr(e.msg, '\n'));
    const char *fr[3] = {f1, f2, f3};
    for (int i = 0; i < 3; i++)
        ck_assert_msg(!fr[i] || strstr(e.msg, fr[i]), "%s: '%s' lacks '%s'",
                      name, e.msg, fr[i]);
    ck_assert_uint_eq(c.n, 0);
    ck_assert_ptr_null(c.xyz);
    ck_assert_ptr_null(c.nrm);
    ck_assert_ptr_null(c.face_off);
    ck_assert_ptr_null(c.face_idx);
    ck_assert_uint_eq(c.nfaces, 0);
}

static void setup(void)
{
    tmpdir_setup("/tmp/jf_io_bad_XXXXXX");
}

START_TEST(files)
{
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read("/nonexistent/dir/x.ply", NULL, &c, &e),
                     JF_ERR_IO);
    ck_assert(strstr(e.msg, "/nonexistent/dir/x.ply: cannot open") == e.msg);
    ck_assert_ptr_null(c.xyz);
    bad("a.obj", "v 1 2 3\n", 0, JF_ERR_UNSUPPORTED, "extension", 0, 0);
    bad("noext", "1 2 3\n", 0, JF_ERR_UNSUPPORTED, "extension", 0, 0);
    ck_assert_int_eq(jf_cloud_read(tmpdir, NULL, &c, &e), JF_ERR_UNSUPPORTED);
    bad("empty.ply", "", 0, JF_ERR_FORMAT, ": empty file", 0, 0);
    bad("empty.xyz", "", 0, JF_ERR_FORMAT, "empty", 0, 0);
    bad("comments.xyz", "# nothing\n\n", 0, JF_ERR_FORMAT, "no points", 0, 0);
    bad("zero.off", "OFF\n0 0 0\n", 0, JF_ERR_FORMAT, "no points", 0, 0);
    bad("zero.ply", "ply\nformat ascii 1.0\nelement vertex 0\n"
                    "property float x\nproperty float y\nproperty float z\n"
                    "end_header\n", 0, JF_ERR_FORMAT, "no points", 0, 0);
}
END_TEST

#define H3 "element vertex 2\nproperty float x\nproperty float y\n" \
           "property float z\n"

START_TEST(ply_header)
{
    bad("h1.ply", "plyx\n", 0, JF_ERR_FORMAT, ":1: not a PLY", 0, 0);
    bad("h2.ply", "ply\n" H3 "end_header\n1 2 3\n", 0, JF_ERR_FORMAT,
        ":6: no format", 0, 0);
    bad("h3.ply", "ply\nformat binary_middle_endian 1.0\n", 0, JF_ERR_FORMAT,
        ":2: unsupported format 'binary_middle_endian'", 0, 0);
    bad("h4.ply", "ply\nformat ascii 1.0\nproperty float x\n", 0,
        JF_ERR_FORMAT, ":3: property before any element", 0, 0);
    bad("h5.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
                  "property float128 x\n", 0, JF_ERR_FORMAT,
        ":4: malformed property", 0, 0);
    bad("h6.ply", "ply\nformat ascii 1.0\n" H3 "1 2 3\n", 0, JF_ERR_FORMAT,
        ":7: unknown header line '1'", 0, 0);
    bad("h7.ply", "ply\nformat ascii 1.0\nelement vertex -3\n", 0,
        JF_ERR_FORMAT, ":3: malformed element", 0, 0);
    bad("h8.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
                  "property float x\nproperty float y\nend_header\n1 2\n", 0,
        JF_ERR_FORMAT, "no x, y, z", 0, 0);
    bad("h9.ply", "ply\nformat ascii 1.0\nbogus line\nend_header\n", 0,
        JF_ERR_FORMAT, ":3: unknown header line 'bogus'", 0, 0);
    /* a face element of no properties and a huge count: skipped at once */
    bad("h11.ply", "ply\nformat binary_little_endian 1.0\nelement face "
                   "18446744073709551615\nelement vertex 1\nproperty float x"
                   "\nproperty float y\nproperty float z\nend_header\n", 0,
        JF_ERR_TOO_LARGE, "element vertex: 1 rows cannot fit", 0, 0);
    bad("h10.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n", 0,
        JF_ERR_FORMAT, "no vertex element", 0, 0);
}
END_TEST

START_TEST(ply_counts)
{
    /* a count far beyond the file: refused before any allocation */
    bad("big.ply", "ply\nformat binary_little_endian 1.0\n"
                   "element vertex 1000000000000000\nproperty double x\n"
                   "property double y\nproperty double z\nend_header\n"
                   "0123456789abcdef01234567", 0, JF_ERR_TOO_LARGE,
        "element vertex: 1000000000000000 rows cannot fit", 0, 0);
    bad("big2.ply", "ply\nformat ascii 1.0\nelement vertex 18446744073709551615"
                    "\nproperty double x\nproperty double y\n"
                    "property double z\nend_header\n1 2 3\n", 0,
        JF_ERR_TOO_LARGE, "cannot fit", 0, 0);
    /* binary body shorter than the counts say */
    const char *h = "ply\nformat binary_little_endian 1.0\n" H3
                    "element face 1\nproperty list uchar int vertex_indices"
                    "\nend_header\n";
    char buf[256];
    size_t n = strlen(h);
    memcpy(buf, h, n);
    memset(buf + n, 0, 20);
    bad("trunc.ply", buf, n + 20, JF_ERR_TOO_LARGE,
        "trunc.ply: element vertex: 2 rows cannot fit", "truncated", 0);
    memset(buf + n, 0, 24);
    buf[n + 24] = 3; /* a triangle, but only two indices follow */
    memset(buf + n + 25, 0, 8);
    bad("trunc2.ply", buf, n + 33, JF_ERR_FORMAT,
        "trunc2.ply: element face 0: truncated", 0, 0);
}
END_TEST

START_TEST(ply_ascii_rows)
{
    const char *h = "ply\nformat ascii 1.0\n" H3 "end_header\n";
    char s[512];
    snprintf(s, sizeof s, "%s1 2 3\n4 5\n", h);
    bad("short.ply", s, 0, JF_ERR_FORMAT,
        ":9: vertex 1: expected 3 numbers, found 2", 0, 0);
    snprintf(s, sizeof s, "%s1 2 3\n4 5 6 7\n", h);
    bad("long.ply", s, 0, JF_ERR_FORMAT, ":9: vertex 1: expected 3 values, "
                                         "found 4", 0, 0);
    snprintf(s, sizeof s, "%s1 2 3\n4 five 6\n", h);
    bad("word.ply", s, 0, JF_ERR_FORMAT, ":9: vertex 1: 'five' is not a "
                                         "number", 0, 0);
    snprintf(s, sizeof s, "%s1 2 3\n", h);
    bad("ends.ply", s, 0, JF_ERR_FORMAT, "vertex 1: file ends", 0, 0);
}
END_TEST

START_TEST(faces_out_of_range)
{
    const char *s = "ply\nformat ascii 1.0\n" H3
                    "element face 2\nproperty list uchar int vertex_indices\n"
                    "end_header\n0 0 0\n1 0 0\n3 0 1 1\n3 0 1 2\n";
    bad("face.ply", s, 0, JF_ERR_FORMAT, ":13: face 1: vertex index 2 out of "
                                         "range (2 vertices)", 0, 0);
    bad("neg.ply", "ply\nformat ascii 1.0\n" H3 "element face 1\n"
                   "property list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n3 0 -1 1\n", 0, JF_ERR_FORMAT,
        "face 0: vertex index -1 out of range", 0, 0);
    bad("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 0,
        JF_ERR_FORMAT, ":6: face 0: vertex index '3' out of range", 0, 0);
    bad("f2.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", 0,
        JF_ERR_FORMAT, ":6: face 0: expected 3 indices", 0, 0);
    bad("f3.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n", 0, JF_ERR_FORMAT,
        ":5: vertex 2: expected 3 numbers, found 2", 0, 0);
    bad("f4.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 0,
        JF_ERR_FORMAT, "face 1: file ends", 0, 0);
    bad("f5.off", "OFF\n99999 1 0\n0 0 0\n", 0, JF_ERR_TOO_LARGE,
        ":2: 99999 vertices", 0, 0);
    bad("f6.off", "4OFF\n1 0 0\n0 0 0 0\n", 0, JF_ERR_UNSUPPORTED,
        ":1: unsupported OFF variant '4OFF'", 0, 0);
    bad("f7.off", "OFF\n3 x 0\n", 0, JF_ERR_FORMAT, ":2: bad count 'x'", 0,
        0);
}
END_TEST

START_TEST(text_rows)
{
    bad("s.xyz", "1 2 3\n# c\n4 5\n", 0, JF_ERR_FORMAT,
        ":3: row 2: expected 3 numbers, found 2", 0, 0);
    bad("w.xyz", "1 2 3\r\n4 x 6\r\n", 0, JF_ERR_FORMAT,
        ":2: row 2: column 2: 'x' is not a number", 0, 0);
    /* a single number that is not a count line is a short row */
    bad("one.pts", "2\n1 2 3\n7\n4 5 6\n", 0, JF_ERR_FORMAT,
        ":3: row 2: expected 3 numbers, found 1", 0, 0);
    bad("h.csv", "a,b,c\n1,2,3\n", 0, JF_ERR_FORMAT,
        ":1: CSV header has no columns named x, y and z", 0, 0);
    bad("e.csv", "x,y,z\n1,,3\n", 0, JF_ERR_FORMAT,
        ":2: row 1: empty field in column 2", 0, 0);
    bad("n.csv", "x,y,z\n1,2\n", 0, JF_ERR_FORMAT,
        ":2: row 1: expected 3 numbers, found 2", 0, 0);
    /* bad --columns */
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.columns[0] = 1;
    jf_cloud c;
    jf_error e;
    const char *p = fixture("ok.xyz", "1 2 3\n", 6);
    ck_assert_int_eq(jf_cloud_read(p, &o, &c, &e), JF_ERR_INVALID);
    ck_assert_ptr_null(c.xyz);
    o.columns[1] = 2, o.columns[2] = 7;
    ck_assert_int_eq(jf_cloud_read(p, &o, &c, &e), JF_ERR_FORMAT);
    ck_assert(strstr(e.msg, ":1: row 1: expected 8 numbers, found 3"));
}
END_TEST

/* Every file under tests/fuzz/regress/<reader>/ goes through its reader
 * (in memory, as the fuzzer did): any status is fine, a crash is not. */
START_TEST(fuzz_regressions)
{
    static const struct { const char *dir; jf_format fmt; } r[] = {
        {"ply", JF_FMT_PLY}, {"xyz", JF_FMT_XYZ}, {"pts", JF_FMT_PTS},
        {"csv", JF_FMT_CSV}, {"off", JF_FMT_OFF}, {"las", JF_FMT_LAS},
        {"ptx", JF_FMT_PTX}, {"e57", JF_FMT_E57}};
    int replayed = 0;
    for (size_t i = 0; i < sizeof r / sizeof r[0]; i++) {
        char dir[512];
        snprintf(dir, sizeof dir, "%s/../tests/fuzz/regress/%s", JF_TEST_DATA,
                 r[i].dir);
        DIR *d = opendir(dir);
        if (!d)
            continue;
        struct dirent *de;
        while ((de = readdir(d)) != NULL) {
            if (de->d_name[0] == '.')
                continue;
            char path[1024];
            snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
            FILE *f = fopen(path, "rb");
            if (!f)
                continue;
            char *buf = malloc(1 << 20);
            size_t len = fread(buf, 1, 1 << 20, f);
            fclose(f);
            /* an exact-size copy so ASan sees any over-read */
            char *exact = malloc(len ? len : 1);
            memcpy(exact, buf, len);
            free(buf);
            jf_cloud c;
            jf_error e;
            jf_read_opts o;
            jf_read_opts_init(&o);
            jf_status st = jf_cloud_read_mem(exact, len, r[i].fmt, path, &o,
                                             &c, &e);
            if (st != JF_OK)
                ck_assert_ptr_null(c.xyz);
            jf_cloud_free(&c);
            free(exact);
            replayed++;
        }
        closedir(d);
    }
    ck_assert_int_ge(replayed, 0);
}
END_TEST

/* The fuzzers' seeds (tests/fuzz/corpus/<reader>/) are valid files: each
 * reads, as a whole file through its reader, with at least one point (the
 * xyz harness's seeds start with a format byte and are left out). */
START_TEST(fuzz_seeds_read)
{
    static const struct { const char *dir; jf_format fmt; } r[] = {
        {"ply", JF_FMT_PLY}, {"off", JF_FMT_OFF}, {"las", JF_FMT_LAS}, {"ptx", JF_FMT_PTX}};
    for (size_t i = 0; i < sizeof r / sizeof r[0]; i++) {
        char dir[512];
        snprintf(dir, sizeof dir, "%s/fuzz/corpus/%s", JF_TESTS_DIR, r[i].dir);
        DIR *d = opendir(dir);
        ck_assert_msg(d != NULL, "%s", dir);
        int seeds = 0;
        struct dirent *de;
        while ((de = readdir(d)) != NULL) {
            if (de->d_name[0] == '.')
                continue;
            char path[1024];
            snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
            FILE *f = fopen(path, "rb");
            ck_assert_ptr_nonnull(f);
            char buf[1 << 16];
            size_t len = fread(buf, 1, sizeof buf, f);
            fclose(f);
            jf_cloud c;
            jf_error e;
            jf_status st = jf_cloud_read_mem(buf, len, r[i].fmt, path, NULL, &c, &e);
            ck_assert_msg(st == JF_OK && c.n > 0, "%s: %s", path, e.msg);
            jf_cloud_free(&c);
            seeds++;
        }
        closedir(d);
        ck_assert_msg(seeds > 0, "no seeds in %s", dir);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_bad");
    TCase *tc = tcase_create("bad");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, files);
    tcase_add_test(tc, ply_header);
    tcase_add_test(tc, ply_counts);
    tcase_add_test(tc, ply_ascii_rows);
    tcase_add_test(tc, faces_out_of_range);
    tcase_add_test(tc, text_rows);
    tcase_add_test(tc, fuzz_regressions);
    tcase_add_test(tc, fuzz_seeds_read);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
