/* test_io_las_edges.c -- the LAS edge defects of issue 30 and 33.7: the
 * point-format byte never masked into another format; a 1.4 legacy count
 * that disagrees with the 64-bit one, and whole records past the count,
 * refused; Extra Bytes names of 32 bytes kept whole and longer ones
 * shortened to distinct names with a warning (the descriptions decoded
 * here from the file's bytes); the scale rule's warning on an outlier;
 * a scale and offset given; coordinates LAS cannot hold refused with no
 * file; an input VLR that runs past the point data named. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "test_las_bytes.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_lase_XXXXXX"); }

/* n records of format fmt after a 1.2 (fmt < 6) or 1.4 header, `extra`
 * zero bytes after them; count fields as given (legacy, 64-bit for 1.4). */
static size_t make_las(unsigned fmt, size_t n, size_t extra, uint32_t legacy, uint64_t n64,
                       unsigned char **out)
{
    int v14 = fmt >= 6 || n64;
    unsigned hsize = v14 ? 375 : 227, rl = base_len[fmt];
    size_t len = hsize + n * rl + extra;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    b[24] = 1;
    b[25] = v14 ? 4 : 2;
    put16(b + 94, hsize);
    put32(b + 96, hsize);
    b[104] = (unsigned char)fmt;
    put16(b + 105, rl);
    put32(b + 107, legacy);
    for (int a = 0; a < 3; a++) putd(b + 131 + 8 * a, 0.01);
    if (v14) put64(b + 247, n64);
    for (size_t i = 0; i < n; i++) {
        unsigned char *r = b + hsize + i * rl;
        put32(r, (uint32_t)i), put32(r + 4, (uint32_t)(2 * i)), put32(r + 8, 7);
    }
    *out = b;
    return len;
}

static void refused(const char *name, const unsigned char *b, size_t len, const char *what)
{
    const char *p = fixture(name, b, len);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) != JF_OK, "%s was read", what);
    ck_assert_msg(strstr(e.msg, p) == e.msg, "'%s'", e.msg);
    ck_assert_msg(strstr(e.msg, what), "'%s' lacks '%s'", e.msg, what);
    ck_assert_ptr_null(strchr(e.msg, '\n'));
    ck_assert_ptr_null(c.xyz);
}

static size_t read_n(const unsigned char *b, size_t len)
{
    const char *p = fixture("ok.las", b, len);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "%s", e.msg);
    size_t n = c.n;
    jf_cloud_free(&c);
    return n;
}

/* 30.1: 0x41 was read as format 1, 0x46 as format 6, 99 named "format 35" */
START_TEST(format_byte)
{
    unsigned char *b;
    size_t len = make_las(1, 20, 0, 20, 0, &b);
    b[104] = 0x41; /* bit 6: LASzip's compression flag */
    refused("b6.las", b, len, "compressed point format");
    b[104] = 0x81;
    refused("b7.las", b, len, "compressed point format");
    b[104] = 99;
    refused("f99.las", b, len, "record format 99 (byte 104 holds 0x63");
    b[104] = 35;
    refused("f35.las", b, len, "record format 35 (byte 104 holds 0x23");
    b[104] = 0xFF;
    refused("fff.las", b, len, "record format 255");
    free(b);
    len = make_las(6, 20, 0, 0, 20, &b);
    ck_assert_uint_eq(read_n(b, len), 20);
    b[104] = 0x46;
    refused("b6v14.las", b, len, "compressed point format");
    b[104] = 0x0B;
    refused("f11.las", b, len, "record format 11");
    free(b);
}
END_TEST

/* 33.7: count 150 with 200 records was read as 150 rows; a 1.4 legacy count
 * of 200 with a 64-bit count of 100 read 100 rows */
START_TEST(point_counts)
{
    unsigned char *b;
    size_t len = make_las(1, 200, 0, 150, 0, &b);
    refused("more.las", b, len, "point count 150, but 50 more whole records of 28 bytes");
    put32(b + 107, 200);
    ck_assert_uint_eq(read_n(b, len), 200);
    free(b);
    /* bytes short of a record after the last are not a point */
    len = make_las(1, 200, 27, 200, 0, &b);
    ck_assert_uint_eq(read_n(b, len), 200);
    free(b);
    len = make_las(1, 200, 28, 200, 0, &b);
    refused("more1.las", b, len, "1 more whole records");
    free(b);
    /* 1.4: legacy 0 or equal; a disagreeing pair refused */
    len = make_las(1, 200, 0, 200, 100, &b);
    refused("two.las", b, len, "legacy point count 200 disagrees with the 64-bit point count 100");
    put32(b + 107, 0);
    put64(b + 247, 200);
    ck_assert_uint_eq(read_n(b, len), 200);
    put32(b + 107, 200);
    ck_assert_uint_eq(read_n(b, len), 200);
    /* 1.4 EVLRs after the records: not records */
    size_t l2 = len + 60;
    unsigned char *e = calloc(1, l2);
    memcpy(e, b, len);
    put64(e + 235, len), put32(e + 243, 1);
    ck_assert_uint_eq(read_n(e, l2), 200);
    put32(e + 243, 0); /* no EVLR declared: 60 bytes = 2 whole records */
    refused("noevlr.las", e, l2, "2 more whole records");
    free(e);
    free(b);
}
END_TEST

/* The Extra Bytes descriptions of a LAS file: count and names (32 bytes
 * each, the field as stored, NUL-padded). */
static size_t eb_names(const char *path, char names[][33], size_t max)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    static unsigned char b[1 << 16];
    size_t len = fread(b, 1, sizeof b, f);
    fclose(f);
    size_t p = b[94] | b[95] << 8, n = 0;
    uint32_t nv = g32(b + 100);
    for (uint32_t v = 0; v < nv && p + 54 <= len; v++) {
        size_t rl = b[p + 20] | b[p + 21] << 8;
        if (!memcmp(b + p + 2, "LASF_Spec", 10) && (b[p + 18] | b[p + 19] << 8) == 4)
            for (size_t d = p + 54; d + 192 <= p + 54 + rl && n < max; d += 192, n++) {
                memcpy(names[n], b + d + 4, 32);
                names[n][32] = '\0';
            }
        p += 54 + rl;
    }
    return n;
}

/* 30.2: a 32-byte name lost its last byte; two names sharing their first
 * 31 bytes became one name twice */
START_TEST(extra_bytes_names)
{
    static const char n32[] = "abcdefghijklmnopqrstuvwxyz012345";         /* 32 */
    static const char la[] = "the_same_first_thirty_one_bytes_A_longer"; /* 40 */
    static const char lb[] = "the_same_first_thirty_one_bytes_B_longer";
    ck_assert_uint_eq(strlen(n32), 32);
    jf_column cols[6] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {n32, JF_COL_F64}, {la, JF_COL_F32}, {lb, JF_COL_I32}};
    char path[128];
    snprintf(path, sizeof path, "%s/names.las", tmpdir);
    const size_t n = 10;
    double xyz[30];
    for (size_t i = 0; i < 30; i++) xyz[i] = (double)i;
    jf_writer *w;
    jf_error e = {{0}};
    ck_assert_int_eq(jf_writer_open(path, cols, 6, n, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, xyz, n), JF_OK);
    const char *warn = jf_writer_warnings(w);
    char want[512];
    snprintf(want, sizeof want, "%s: Extra Bytes name '%s' is longer than LAS's 32 bytes: "
             "written as 'the_same_first_thirty_one_byte~1'\n", path, la);
    ck_assert_msg(strstr(warn, want) == warn, "'%s'", warn);
    snprintf(want, sizeof want, "%s: Extra Bytes name '%s' is longer than LAS's 32 bytes: "
             "written as 'the_same_first_thirty_one_byte~2'\n", path, lb);
    ck_assert_msg(strstr(warn, want), "'%s'", warn);
    ck_assert_ptr_null(strstr(warn, n32)); /* 32 bytes: kept, no warning */
    for (size_t i = 0; i < n; i++) {
        double r[6] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], 0.5 * (double)i, 1, 2};
        ck_assert_int_eq(jf_writer_row(w, r), JF_OK);
    }
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
    char nm[8][33];
    ck_assert_uint_eq(eb_names(path, nm, 8), 3);
    ck_assert(!memcmp(nm[0], n32, 32)); /* all 32 bytes, no NUL */
    ck_assert_str_eq(nm[1], "the_same_first_thirty_one_byte~1");
    ck_assert_str_eq(nm[2], "the_same_first_thirty_one_byte~2");
    /* and our reader gives the 32-byte name back whole */
    jf_cloud c;
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    int k = jf_attr_find(&c.attrs, n32);
    ck_assert_int_ge(k, 0);
    ck_assert(jf_attr_get(&c.attrs, (size_t)k, 3) == 1.5);
    ck_assert_int_ge(jf_attr_find(&c.attrs, "the_same_first_thirty_one_byte~2"), 0);
    jf_cloud_free(&c);
}
END_TEST

/* 30.2: a name that already holds the shortened form pushes the rule to
 * the next N; a multi-byte UTF-8 character is never cut */
START_TEST(extra_bytes_names_distinct)
{
    static const char taken[] = "0123456789012345678901234567890~1";    /* 33: ~ at 31 */
    static const char held[] = "abcdefghijklmnopqrstuvwxyzabcd~1";     /* 32, kept */
    static const char lng[] = "abcdefghijklmnopqrstuvwxyzabcdefgh";   /* 34 */
    static const char utf[] = "abcdefghijklmnopqrstuvwxyzabc\xC3\xA9xyz"; /* é at 29-30 */
    jf_column cols[7] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {held, JF_COL_F64}, {lng, JF_COL_F64}, {utf, JF_COL_F64},
                         {taken, JF_COL_F64}};
    char path[128];
    snprintf(path, sizeof path, "%s/d.las", tmpdir);
    double xyz[3] = {1, 2, 3}, r[7] = {1, 2, 3, 4, 5, 6, 7};
    jf_writer *w;
    jf_error e = {{0}};
    ck_assert_int_eq(jf_writer_open(path, cols, 7, 1, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, xyz, 1), JF_OK);
    ck_assert_int_eq(jf_writer_row(w, r), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
    char nm[8][33];
    ck_assert_uint_eq(eb_names(path, nm, 8), 4);
    ck_assert(!memcmp(nm[0], held, 32));
    ck_assert_str_eq(nm[1], "abcdefghijklmnopqrstuvwxyzabcd~2");
    /* 30 bytes would cut é in two: 29 bytes and ~1 */
    ck_assert_str_eq(nm[2], "abcdefghijklmnopqrstuvwxyzabc~1");
    ck_assert_str_eq(nm[3], "012345678901234567890123456789~1");
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < a; b++) ck_assert_str_ne(nm[a], nm[b]);
}
END_TEST

/* A LAS input kept whole (keep mode): two Extra Bytes of the same 32-byte
 * name; the second becomes `in_` + the name (35 bytes), shortened with a
 * warning; the first and jetfit's k1 kept. */
START_TEST(extra_bytes_names_keep_mode)
{
    static const char n32[] = "abcdefghijklmnopqrstuvwxyz012345";
    const size_t n = 5, hs = 227, vl = 54 + 2 * 192, rl = 22;
    size_t len = hs + vl + n * rl;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    b[24] = 1, b[25] = 2;
    put16(b + 94, (unsigned)hs);
    put32(b + 96, (uint32_t)(hs + vl));
    put32(b + 100, 1);
    put16(b + 105, (unsigned)rl);
    put32(b + 107, (uint32_t)n);
    for (int a = 0; a < 3; a++) putd(b + 131 + 8 * a, 0.01);
    unsigned char *v = b + hs;
    memcpy(v + 2, "LASF_Spec", 9);
    put16(v + 18, 4);
    put16(v + 20, 2 * 192);
    for (int d = 0; d < 2; d++) {
        v[54 + 192 * d + 2] = 1; /* unsigned char */
        memcpy(v + 54 + 192 * d + 4, n32, 32);
    }
    for (size_t i = 0; i < n; i++) {
        unsigned char *r = b + hs + vl + i * rl;
        put32(r, (uint32_t)i);
        r[20] = (unsigned char)i, r[21] = (unsigned char)(100 + i);
    }
    const char *in = fixture("kin.las", b, len);
    jf_cloud c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
    jf_column cols[4] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {"k1", JF_COL_F64}};
    char path[128];
    snprintf(path, sizeof path, "%s/kout.las", tmpdir);
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, 4, n, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_attrs(w, &c.attrs), JF_OK);
    char want[512];
    snprintf(want, sizeof want, "%s: Extra Bytes name 'in_%s' is longer than LAS's 32 bytes: "
             "written as 'in_abcdefghijklmnopqrstuvwxyz0~1'\n", path, n32);
    ck_assert_str_eq(jf_writer_warnings(w), want);
    for (size_t i = 0; i < n; i++) {
        double r[4] = {0, 0, 0, (double)i};
        ck_assert_int_eq(jf_writer_row(w, r), JF_OK);
    }
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
    char nm[8][33];
    ck_assert_uint_eq(eb_names(path, nm, 8), 3);
    ck_assert(!memcmp(nm[0], n32, 32));
    ck_assert_str_eq(nm[1], "in_abcdefghijklmnopqrstuvwxyz0~1");
    ck_assert_str_eq(nm[2], "k1");
    jf_cloud r;
    ck_assert_msg(jf_cloud_read(path, NULL, &r, &e) == JF_OK, "%s", e.msg);
    int k = jf_attr_find(&r.attrs, "in_abcdefghijklmnopqrstuvwxyz0~1");
    ck_assert_int_ge(k, 0);
    ck_assert(jf_attr_get(&r.attrs, (size_t)k, 3) == 103);
    jf_cloud_free(&r);
    jf_cloud_free(&c);
    free(b);
}
END_TEST

/* Writes xyz (n points) as LAS with the rule's frame (or the one given);
 * returns the frame's status, *warn a copy of the warnings. */
static jf_status las_out(const char *path, const double *xyz, size_t n, const double *scale,
                         const double *offset, char *warn, size_t wl, jf_error *e)
{
    jf_column cols[3] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, 3, n, 0, &w, e), JF_OK);
    jf_status st = jf_writer_las_frame_given(w, xyz, n, scale, offset);
    snprintf(warn, wl, "%s", jf_writer_warnings(w));
    if (st != JF_OK) {
        ck_assert_int_ne(jf_writer_commit(w, e), JF_OK);
        return st;
    }
    for (size_t i = 0; i < n; i++) ck_assert_int_eq(jf_writer_row(w, xyz + 3 * i), JF_OK);
    ck_assert_int_eq(jf_writer_commit(w, e), JF_OK);
    return st;
}

/* 30.3: one outlier at x = 1e10 among points at 4,123,456.789012 +- 50
 * gave an x scale of 10 and moved every x by up to 5 m, silently */
START_TEST(scale_warning)
{
    const size_t n = 401;
    double *xyz = malloc(3 * n * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        xyz[3 * i] = 4123456.789012 + 50 * sin(0.7 * (double)i);
        xyz[3 * i + 1] = 5e6 + 50 * cos(1.3 * (double)i);
        xyz[3 * i + 2] = 100 + 0.01 * (double)i;
    }
    char path[128], warn[2048];
    jf_error e = {{0}};
    snprintf(path, sizeof path, "%s/plain.las", tmpdir);
    ck_assert_int_eq(las_out(path, xyz, n, NULL, NULL, warn, sizeof warn, &e), JF_OK);
    ck_assert_str_eq(warn, ""); /* 0.1 um: nothing to say */
    xyz[3 * 7] = 1e10;
    snprintf(path, sizeof path, "%s/outlier.las", tmpdir);
    ck_assert_int_eq(las_out(path, xyz, n, NULL, NULL, warn, sizeof warn, &e), JF_OK);
    /* the largest rounding, recomputed from the file's own records */
    jf_cloud c;
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    double r = 0;
    for (size_t i = 0; i < n; i++) r = fmax(r, fabs(c.xyz[3 * i] - xyz[3 * i]));
    ck_assert(r > 1 && r <= 5);
    char want[256];
    snprintf(want, sizeof want, "%s: x: the LAS scale 10 (for coordinates from", path);
    ck_assert_msg(strstr(warn, want) == warn, "'%s'", warn);
    snprintf(want, sizeof want, "rounds them by up to %.3g,", r);
    ck_assert_msg(strstr(warn, want), "'%s' lacks '%s'", warn, want);
    ck_assert_ptr_null(strstr(warn, "\ny:")); /* one line, x only */
    ck_assert_ptr_eq(strchr(warn, '\n'), warn + strlen(warn) - 1);
    jf_cloud_free(&c);
    /* a point 1000 km away: scale 1e-3, half a millimetre */
    xyz[3 * 7] = 4123456.789012 + 1e6;
    ck_assert_int_eq(las_out(path, xyz, n, NULL, NULL, warn, sizeof warn, &e), JF_OK);
    ck_assert_msg(strstr(warn, "x: the LAS scale 0.001 "), "'%s'", warn);
    /* given: no warning, the scale and offset in the header, counts exact */
    double sc[3] = {0.25, 1e-3, 1e-3}, of[3] = {4e6, 5e6, 0};
    xyz[3 * 7] = 4123456.789012;
    snprintf(path, sizeof path, "%s/given.las", tmpdir);
    ck_assert_int_eq(las_out(path, xyz, n, sc, of, warn, sizeof warn, &e), JF_OK);
    ck_assert_str_eq(warn, "");
    unsigned char h[227];
    FILE *f = fopen(path, "rb");
    ck_assert_uint_eq(fread(h, 1, sizeof h, f), sizeof h);
    fclose(f);
    for (int a = 0; a < 3; a++) {
        ck_assert(getd(h + 131 + 8 * a) == sc[a]);
        ck_assert(getd(h + 155 + 8 * a) == of[a]);
    }
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    for (size_t i = 0; i < n; i++)
        ck_assert(c.xyz[3 * i] == 4e6 + 0.25 * (double)llround((xyz[3 * i] - 4e6) / 0.25));
    jf_cloud_free(&c);
    /* a scale too fine for the extent: refused, no file */
    double fine[3] = {1e-9, 1e-3, 1e-3};
    snprintf(path, sizeof path, "%s/fine.las", tmpdir);
    ck_assert_int_eq(las_out(path, xyz, n, fine, NULL, warn, sizeof warn, &e), JF_ERR_TOO_LARGE);
    ck_assert_msg(strstr(e.msg, "x: coordinates from") && strstr(e.msg, "do not fit int32"),
                  "'%s'", e.msg);
    ck_assert(access(path, F_OK) != 0);
    free(xyz);
}
END_TEST

/* 30.4: +-1.7e308 gave a header whose x scale was inf (rc 0), which the
 * reader refused */
START_TEST(huge_extent)
{
    double xyz[9] = {0.5, 1, 2, -1.7e308, 1, 2, 1.7e308, 1, 2};
    char path[128], warn[512];
    jf_error e = {{0}};
    snprintf(path, sizeof path, "%s/huge.las", tmpdir);
    ck_assert_int_eq(las_out(path, xyz, 3, NULL, NULL, warn, sizeof warn, &e), JF_ERR_TOO_LARGE);
    ck_assert_msg(strstr(e.msg, path) == e.msg, "'%s'", e.msg);
    ck_assert_msg(strstr(e.msg, "x: coordinates from -1.7e+308 to 1.7e+308") ||
                      strstr(e.msg, "x: coordinates from -1.6999999999999999e+308 to "
                                    "1.6999999999999999e+308"),
                  "'%s'", e.msg);
    ck_assert(access(path, F_OK) != 0);
    /* jf_cloud_write (jetfit generate -o x.las) the same */
    jf_cloud c = {0};
    c.n = 3;
    c.xyz = xyz;
    e.msg[0] = '\0';
    ck_assert_int_eq(jf_cloud_write(path, &c, 0, &e), JF_ERR_TOO_LARGE);
    ck_assert_msg(strstr(e.msg, "too far apart"), "'%s'", e.msg);
    ck_assert(access(path, F_OK) != 0);
    /* the largest extent that works reads back */
    xyz[3] = -8e307, xyz[6] = 8e307;
    ck_assert_int_eq(las_out(path, xyz, 3, NULL, NULL, warn, sizeof warn, &e), JF_OK);
    jf_cloud r;
    ck_assert_msg(jf_cloud_read(path, NULL, &r, &e) == JF_OK, "%s", e.msg);
    ck_assert_double_eq_tol(r.xyz[6], 8e307, 1e300);
    jf_cloud_free(&r);
}
END_TEST

/* A VLR whose length runs past the point data is not copied to a LAS
 * output: the writer says so. */
START_TEST(vlr_past_data)
{
    unsigned char *b;
    size_t len0 = make_las(1, 20, 0, 20, 0, &b);
    /* a VLR of 54 + 10 bytes between the header and the records, its
     * length field saying 500 */
    size_t len = len0 + 64;
    unsigned char *m = calloc(1, len);
    memcpy(m, b, 227);
    memcpy(m + 227 + 64, b + 227, len0 - 227);
    put32(m + 96, 227 + 64);
    put32(m + 100, 1);
    memcpy(m + 227 + 2, "someone", 7);
    put16(m + 227 + 18, 1);
    put16(m + 227 + 20, 500);
    const char *in = fixture("vlr.las", m, len);
    jf_cloud c;
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
    jf_column cols[4] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {"k1", JF_COL_F64}};
    char path[128];
    snprintf(path, sizeof path, "%s/o.las", tmpdir);
    jf_writer *w;
    ck_assert_int_eq(jf_writer_open(path, cols, 4, c.n, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_attrs(w, &c.attrs), JF_OK);
    char want[256];
    snprintf(want, sizeof want, "%s: the input's VLR 1 of 1 runs past its point data: VLRs 1 "
             "to 1 are not copied\n", path);
    ck_assert_str_eq(jf_writer_warnings(w), want);
    jf_writer_abort(w);
    jf_cloud_free(&c);
    free(m);
    free(b);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("io_las_edges");
    TCase *tc = tcase_create("core");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, format_byte);
    tcase_add_test(tc, point_counts);
    tcase_add_test(tc, extra_bytes_names);
    tcase_add_test(tc, extra_bytes_names_distinct);
    tcase_add_test(tc, extra_bytes_names_keep_mode);
    tcase_add_test(tc, scale_warning);
    tcase_add_test(tc, huge_extent);
    tcase_add_test(tc, vlr_past_data);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return jf_test_run(suite());
}
