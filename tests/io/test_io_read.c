/*
 * test_io_read.c -- the readers on real files (the Stanford bunny scan, the
 * CGAL OFF meshes) and on fixtures written here: every format, byte order,
 * column selection, NaN rows, PTS count lines, CRLF, OFF variants.
 * Expected values come from the text of the files (strtod) or from the
 * bytes the test wrote itself, never from the reader's own output.
 */
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

static const char *text(const char *name, const char *s)
{
    return fixture(name, s, strlen(s));
}

static void read_ok(const char *path, const jf_read_opts *o, jf_cloud *c)
{
    jf_error e;
    jf_status st = jf_cloud_read(path, o, c, &e);
    ck_assert_msg(st == JF_OK, "%s: %s", path, e.msg);
}

static void setup(void)
{
    tmpdir_setup("/tmp/jf_io_read_XXXXXX");
}

START_TEST(bunny_scan)
{
    /* CRLF, obj_info lines, and a range_grid element of 204800 lists */
    jf_cloud c;
    read_ok(JF_TEST_DATA "/bun090.ply", NULL, &c);
    ck_assert_uint_eq(c.n, 30379);
    ck_assert_ptr_null(c.nrm);
    ck_assert_uint_eq(c.nfaces, 0);
    /* first and last vertex lines of the file */
    ck_assert(c.xyz[0] == strtod("-0.012", NULL));
    ck_assert(c.xyz[1] == strtod("0.035963", NULL));
    ck_assert(c.xyz[2] == strtod("0.0353613", NULL));
    ck_assert(c.xyz[3 * 30378 + 0] == strtod("0.023", NULL));
    ck_assert(c.xyz[3 * 30378 + 1] == strtod("0.187903", NULL));
    ck_assert(c.xyz[3 * 30378 + 2] == strtod("-0.0162106", NULL));
    jf_cloud_free(&c);
    ck_assert_ptr_null(c.xyz);
    jf_cloud_free(&c); /* twice is fine */
}
END_TEST

START_TEST(bunny_mesh)
{
    /* binary? no: ascii with x y z confidence intensity and faces */
    jf_cloud c;
    read_ok(JF_TESTS_DIR "/data/bunny/bun_zipper_res4.ply", NULL, &c);
    ck_assert_uint_eq(c.n, 453);
    ck_assert_uint_eq(c.nfaces, 948);
    for (size_t f = 0; f < c.nfaces; f++)
        ck_assert_uint_eq(c.face_off[f + 1] - c.face_off[f], 3);
    for (size_t k = 0; k < c.face_off[c.nfaces]; k++)
        ck_assert_uint_lt(c.face_idx[k], c.n);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(cgal_off)
{
    jf_cloud c;
    read_ok(JF_TESTS_DIR "/data/cgal_jet/ellipe0.003.off", NULL, &c);
    ck_assert_uint_eq(c.n, 1556);
    ck_assert_uint_eq(c.nfaces, 3108);
    ck_assert(c.xyz[0] == strtod("0.248545", NULL));
    ck_assert(c.xyz[2] == strtod("-0.256645", NULL));
    jf_cloud_free(&c);
}
END_TEST

/* ---- PLY fixtures ----------------------------------------------------- */

static size_t put_be(unsigned char *o, const void *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        o[i] = ((const unsigned char *)v)[n - 1 - i];
    return n;
}

START_TEST(ply_binary_be)
{
    /* vertex: uchar flag, double x, float y, int z, short nx ny nz (ints
     * accepted for any property), a list to skip; then a face element
     * with an extra property and a range_grid-like element after. */
    unsigned char buf[1024];
    const char *hdr = "ply\nformat binary_big_endian 1.0\ncomment c\n"
                      "element vertex 2\nproperty uchar flag\n"
                      "property double x\nproperty float y\n"
                      "property int z\nproperty list uchar float junk\n"
                      "property short nx\nproperty short ny\n"
                      "property short nz\n"
                      "element face 1\nproperty uchar flags\n"
                      "property list uchar uint vertex_indices\n"
                      "element extra 2\nproperty list int int stuff\n"
                      "end_header\n";
    size_t n = strlen(hdr);
    memcpy(buf, hdr, n);
    double xs[2] = {0.1, -1e300};
    float ys[2] = {2.5f, -0.0f};
    int32_t zs[2] = {-7, 2147483647};
    for (int i = 0; i < 2; i++) {
        buf[n++] = 9;
        n += put_be(buf + n, &xs[i], 8);
        n += put_be(buf + n, &ys[i], 4);
        n += put_be(buf + n, &zs[i], 4);
        buf[n++] = 2; /* two floats of junk */
        float j = 1.0f;
        n += put_be(buf + n, &j, 4);
        n += put_be(buf + n, &j, 4);
        int16_t nv[3] = {0, (int16_t)(i ? -1 : 1), 0};
        for (int k = 0; k < 3; k++)
            n += put_be(buf + n, &nv[k], 2);
    }
    buf[n++] = 0xff;
    buf[n++] = 3;
    uint32_t ix[3] = {1, 0, 1};
    for (int k = 0; k < 3; k++)
        n += put_be(buf + n, &ix[k], 4);
    int32_t two = 2, one = 1, zero = 0;
    n += put_be(buf + n, &two, 4);
    n += put_be(buf + n, &one, 4);
    n += put_be(buf + n, &one, 4);
    n += put_be(buf + n, &zero, 4);
    jf_cloud c;
    read_ok(fixture("be.ply", buf, n), NULL, &c);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[0] == 0.1 && c.xyz[1] == 2.5 && c.xyz[2] == -7);
    ck_assert(c.xyz[3] == -1e300 && c.xyz[4] == 0 && signbit(c.xyz[4]));
    ck_assert(c.xyz[5] == 2147483647.0);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[1] == 1 && c.nrm[4] == -1 && c.nrm[3] == 0);
    ck_assert_uint_eq(c.nfaces, 1);
    ck_assert_uint_eq(c.face_off[1], 3);
    ck_assert_uint_eq(c.face_idx[0], 1);
    ck_assert_uint_eq(c.face_idx[1], 0);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(ply_binary_le_faces)
{
    /* vertex_index (singular), int8 counts and ushort indices; a quad */
    unsigned char buf[512];
    const char *hdr = "ply\r\nformat binary_little_endian 1.0\r\n"
                      "element vertex 4\r\nproperty float x\r\n"
                      "property float y\r\nproperty float z\r\n"
                      "element face 2\r\nproperty list char ushort "
                      "vertex_index\r\nend_header\r\n";
    size_t n = strlen(hdr);
    memcpy(buf, hdr, n);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++) {
            float v = (float)(i * 3 + k) + 0.25f;
            memcpy(buf + n, &v, 4);
            n += 4;
        }
    uint16_t f0[4] = {0, 1, 2, 3}, f1[3] = {3, 2, 1};
    buf[n++] = 4;
    memcpy(buf + n, f0, 8);
    n += 8;
    buf[n++] = 3;
    memcpy(buf + n, f1, 6);
    n += 6;
    jf_cloud c;
    read_ok(fixture("le.ply", buf, n), NULL, &c);
    ck_assert_uint_eq(c.n, 4);
    ck_assert(c.xyz[11] == 11.25);
    ck_assert_uint_eq(c.nfaces, 2);
    ck_assert_uint_eq(c.face_off[1], 4);
    ck_assert_uint_eq(c.face_off[2], 7);
    ck_assert_uint_eq(c.face_idx[4], 3);
    ck_assert_uint_eq(c.face_idx[6], 1);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(ply_ascii_nan)
{
    const char *s = "ply\nformat ascii 1.0\nelement vertex 3\n"
                    "property double x\nproperty double y\n"
                    "property double z\nend_header\n"
                    "1 2 3\nnan inf -inf\n\n0x1p-3 1e-320 -0\n";
    jf_cloud c;
    read_ok(text("nan.ply", s), NULL, &c);
    ck_assert_uint_eq(c.n, 3);
    ck_assert(isnan(c.xyz[3]) && c.xyz[4] == INFINITY &&
              c.xyz[5] == -INFINITY);
    ck_assert(c.xyz[6] == 0.125 && c.xyz[7] == strtod("1e-320", NULL));
    jf_cloud_free(&c);
}
END_TEST

/* ascii PLY values: a number ending at a blank is read in one pass,
 * anything else token by token; both give strtod's double, and a token
 * with a tail is named. */
START_TEST(ply_ascii_one_pass)
{
    const char *s = "ply\nformat ascii 1.0\nelement vertex 3\n"
                    "property float x\nproperty float y\nproperty double z\nend_header\n"
                    "  0.1000000000000000055511151231257827\t-2.5e-3 7\n"
                    "12345678901234567890123 .5 5.\n"
                    "1.7976931348623157e308 4.9406564584124654e-324 -1e-5\n";
    jf_cloud c;
    read_ok(text("onepass.ply", s), NULL, &c);
    ck_assert_uint_eq(c.n, 3);
    const char *nums[] = {"0.1000000000000000055511151231257827", "-2.5e-3", "7",
                          "12345678901234567890123", ".5", "5.", "1.7976931348623157e308",
                          "4.9406564584124654e-324", "-1e-5"};
    for (size_t i = 0; i < 9; i++) {
        double want = strtod(nums[i], NULL);
        ck_assert_msg(memcmp(&want, &c.xyz[i], 8) == 0, "value %zu (%s): %.17g", i, nums[i],
                      c.xyz[i]);
    }
    jf_cloud_free(&c);
    jf_error e;
    const char *path = text("tail.ply", "ply\nformat ascii 1.0\nelement vertex 2\n"
                                        "property double x\nproperty double y\n"
                                        "property double z\nend_header\n1 2 3\n4 5 6x\n");
    ck_assert_int_eq(jf_cloud_read(path, NULL, &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, ":9:") && strstr(e.msg, "'6x' is not a number"), "%s", e.msg);
}
END_TEST

/* ---- XYZ / PTS / CSV ------------------------------------------------------ */

START_TEST(xyz_columns)
{
    const char *s = "# id a x y z\r\n// other comment\r\n"
                    "7 0 1.5 2.5 3.5\r\n8 0 -1 -2 -3 # trailing\r\n";
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.columns[0] = 2, o.columns[1] = 3, o.columns[2] = 4;
    jf_cloud c;
    read_ok(text("cols.xyz", s), &o, &c);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[0] == 1.5 && c.xyz[2] == 3.5 && c.xyz[5] == -3);
    jf_cloud_free(&c);
    /* normals by position, out of order */
    o.columns[3] = 1, o.columns[4] = 0, o.columns[5] = 1;
    read_ok(text("cols.txt", s), &o, &c);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[0] == 0 && c.nrm[1] == 7 && c.nrm[4] == 8);
    jf_cloud_free(&c);
    /* a header line of names (not a comment) picks the columns */
    read_ok(text("named.txt", "id Z y X\n1 3 2 1\n2 6 5 4\n"), NULL, &c);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[0] == 1 && c.xyz[1] == 2 && c.xyz[2] == 3);
    ck_assert(c.xyz[3] == 4 && c.xyz[5] == 6);
    jf_cloud_free(&c);
    /* default: first three columns */
    read_ok(text("plain.xyz", "1 2 3\n4,5,6\n7;8;9\n"), NULL, &c);
    ck_assert_uint_eq(c.n, 3);
    ck_assert(c.xyz[3] == 4 && c.xyz[8] == 9);
    ck_assert_ptr_null(c.nrm);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(xyz_default_normals)
{
    jf_cloud c;
    read_ok(text("n.xyz", "0 0 0 0 0 1\n1 0 0 0 1 0\n"), NULL, &c);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[2] == 1 && c.nrm[4] == 1);
    jf_cloud_free(&c);
    /* x y z r g b: colours are not normals */
    read_ok(text("rgb.xyz", "0 0 0 255 128 0\n1 0 0 0 1 0\n"), NULL, &c);
    ck_assert_ptr_null(c.nrm);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(xyz_nan_rows_kept)
{
    jf_cloud c;
    read_ok(text("nan.xyz", "1 2 3\nnan nan nan\n4 NaN 6\n-inf 0 0\n"), NULL,
            &c);
    ck_assert_uint_eq(c.n, 4);
    ck_assert(isnan(c.xyz[3]) && isnan(c.xyz[7]) && c.xyz[8] == 6);
    ck_assert(c.xyz[9] == -INFINITY);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(pts_count_line)
{
    /* x y z intensity r g b, with a count line; two scans concatenated */
    const char *s = "2\n1 2 3 -100 10 20 30\n4 5 6 -90 1 2 3\n"
                    "1\n7 8 9 0 0 0 0\n";
    jf_cloud c;
    read_ok(text("scan.pts", s), NULL, &c);
    ck_assert_uint_eq(c.n, 3);
    ck_assert_ptr_null(c.nrm);
    ck_assert(c.xyz[0] == 1 && c.xyz[3] == 4 && c.xyz[8] == 9);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(csv_header)
{
    const char *s = "id,\"NZ\",Y,x,Nx,z,ny\n"
                    "0,1,2.5,1.5,0,3.5,0\n1, 0 ,-2,-1, 1 ,-3,0\n";
    jf_cloud c;
    read_ok(text("t.CSV", s), NULL, &c);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[0] == 1.5 && c.xyz[1] == 2.5 && c.xyz[2] == 3.5);
    ck_assert(c.xyz[3] == -1 && c.xyz[4] == -2 && c.xyz[5] == -3);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[2] == 1 && c.nrm[3] == 1 && c.nrm[5] == 0);
    jf_cloud_free(&c);
    /* no header: x y z first */
    read_ok(text("nohdr.csv", "1,2,3\n4,5,6\n"), NULL, &c);
    ck_assert_uint_eq(c.n, 2);
    ck_assert(c.xyz[5] == 6);
    jf_cloud_free(&c);
}
END_TEST

/* ---- OFF -------------------------------------------------------------- */

START_TEST(off_variants)
{
    jf_cloud c;
    /* trailing space after OFF, comments, a quad and a triangle */
    const char *s = "OFF \n# a comment\n\n4 2 0\n0 0 0\n1 0 0 # c\n"
                    "1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 3 255 0 0\n";
    read_ok(text("q.off", s), NULL, &c);
    ck_assert_uint_eq(c.n, 4);
    ck_assert_uint_eq(c.nfaces, 2);
    ck_assert_uint_eq(c.face_off[1], 4);
    ck_assert_uint_eq(c.face_off[2], 7);
    ck_assert_uint_eq(c.face_idx[5], 2);
    ck_assert(c.xyz[6] == 1 && c.xyz[7] == 1);
    jf_cloud_free(&c);
    /* counts on the keyword line, CRLF */
    read_ok(text("l.off", "OFF 3 1 3\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n"),
            NULL, &c);
    ck_assert_uint_eq(c.n, 3);
    ck_assert_uint_eq(c.nfaces, 1);
    jf_cloud_free(&c);
    /* NOFF: normals; COFF: colours ignored */
    read_ok(text("n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n"
                          "0 1 0 0 0 -1\n3 0 1 2\n"), NULL, &c);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[8] == -1);
    jf_cloud_free(&c);
    read_ok(text("c.off", "COFF\n3 1 0\n0 0 0 1 1 1 1\n1 0 0 1 1 1 1\n"
                          "0 1 0 1 1 1 1\n3 0 1 2\n"), NULL, &c);
    ck_assert_ptr_null(c.nrm);
    ck_assert(c.xyz[3] == 1);
    jf_cloud_free(&c);
}
END_TEST

START_TEST(exact_decimal_parse)
{
    /* random doubles written with %.17g come back bit for bit, and short
     * decimals equal strtod's answer */
    size_t n = 20000;
    char *buf = malloc(n * 80);
    size_t len = 0;
    uint64_t s = 12345;
    double *want = malloc(3 * n * sizeof *want);
    for (size_t i = 0; i < 3 * n; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        double v;
        if (i % 3 == 0) {
            uint64_t b = s;
            memcpy(&v, &b, 8);
            if (isnan(v) || isinf(v))
                v = 1.0;
        } else if (i % 3 == 1) {
            char t[32];
            snprintf(t, sizeof t, "%.6f", (double)(int64_t)s * 1e-15);
            v = strtod(t, NULL);
        } else {
            v = (double)(int64_t)s / 3.0 * 1e-9;
        }
        want[i] = v;
        len += (size_t)sprintf(buf + len, "%.17g%c", v, i % 3 == 2 ? '\n' : ' ');
    }
    jf_cloud c;
    read_ok(fixture("exact.xyz", buf, len), NULL, &c);
    ck_assert_uint_eq(c.n, n);
    ck_assert(memcmp(c.xyz, want, 3 * n * sizeof *want) == 0);
    jf_cloud_free(&c);
    free(buf);
    free(want);
}
END_TEST

/* After the first row, rows of exactly the first row's numbers are read
 * in one pass (jf_scan_double); every other row goes field by field.
 * Both must give strtod's values, and a bad row after good ones its own
 * error, with its line. */
START_TEST(xyz_one_pass_rows)
{
    const char *s = "1 2 3\n"
                    "  -0.5\t+2.25;3e-2  \n"        /* blanks, tab, ';' */
                    "4,5,6,\n"                       /* trailing comma */
                    ".5 5. 0x1p3\n"                  /* hex: strtod */
                    "inf -nan 1\n"                   /* words: strtod */
                    "12345678901234567890123 1e-400 7\n"
                    "0.000000000000000012345678901234567 1.2345678901234567e+300 9\n";
    jf_cloud c;
    read_ok(text("onepass.xyz", s), NULL, &c);
    ck_assert_uint_eq(c.n, 7);
    const char *nums[] = {"1", "2", "3", "-0.5", "2.25", "3e-2", "4", "5", "6", ".5", "5.",
                          "0x1p3", "inf", "-nan", "1", "12345678901234567890123", "1e-400",
                          "7", "0.000000000000000012345678901234567",
                          "1.2345678901234567e+300", "9"};
    for (size_t i = 0; i < 21; i++) {
        double want = strtod(nums[i], NULL);
        ck_assert_msg(memcmp(&want, &c.xyz[i], 8) == 0 || (isnan(want) && isnan(c.xyz[i])),
                      "value %zu (%s): %.17g", i, nums[i], c.xyz[i]);
    }
    ck_assert(signbit(c.xyz[3]));
    jf_cloud_free(&c);
    /* six columns: normals; a short, a long and a broken row fail with
     * their line */
    read_ok(text("six.xyz", "0 0 0 0 0 1\n1 1 1 0.6 0.8 0\n"), NULL, &c);
    ck_assert_ptr_nonnull(c.nrm);
    ck_assert(c.nrm[3] == 0.6 && c.nrm[4] == 0.8 && c.xyz[5] == 1);
    jf_cloud_free(&c);
    static const char *const bad[][2] = {
        {"1 2 3\n4 5 6\n7 8\n", ":3:"},
        {"1 2 3\n4 5 6\n7 8 9 10\n", ":3:"},
        {"1 2 3\n4 5 6x\n", ":2:"},
        {"1 2 3\n4 5 1e\n", ":2:"},
        {"1 2 3\n4 5 --6\n", ":2:"}};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        jf_error e;
        const char *path = text("bad.xyz", bad[i][0]);
        ck_assert_int_eq(jf_cloud_read(path, NULL, &c, &e), JF_ERR_FORMAT);
        ck_assert_msg(strstr(e.msg, bad[i][1]) != NULL, "case %zu: %s", i, e.msg);
    }
}
END_TEST

START_TEST(parse_vs_strtod)
{
    /* 19-, 18-, 17- and short-digit mantissas, exponents -40..40, and
     * halfway-looking tails: the parser must agree with strtod bit for bit
     * (read through a file as the reader sees them) */
    size_t n = 60000;
    char *buf = malloc(n * 3 * 40);
    size_t len = 0;
    uint64_t s = 777;
    for (size_t i = 0; i < 3 * n; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        int digits = 1 + (int)(s % 19);
        uint64_t m = s >> 3;
        char d[24];
        int k = snprintf(d, sizeof d, "%llu", (unsigned long long)m);
        if (k > digits)
            k = digits;
        if (i % 7 == 0 && k > 2)
            d[k - 1] = '5'; /* ...5: near a rounding boundary */
        d[k] = '\0';
        int e = (int)((s >> 40) % 81) - 40;
        int point = (int)((s >> 50) % (unsigned)(k + 1));
        len += (size_t)sprintf(buf + len, "%s%.*s.%se%d%c",
                               (s >> 63) ? "-" : "", point, d, d + point, e,
                               i % 3 == 2 ? '\n' : ' ');
    }
    jf_cloud c;
    read_ok(fixture("dec.xyz", buf, len), NULL, &c);
    ck_assert_uint_eq(c.n, n);
    const char *p = buf;
    for (size_t i = 0; i < 3 * n; i++) {
        char *end;
        double want = strtod(p, &end);
        p = end + 1;
        ck_assert_msg(memcmp(&want, &c.xyz[i], 8) == 0,
                      "value %zu: %.17g vs strtod %.17g", i, c.xyz[i], want);
    }
    jf_cloud_free(&c);
    free(buf);
    /* exact halfway points between doubles (ties to even) and just off */
    static const char *const half[] = {
        "9007199254740993", "9007199254740995", "4503599627370496.5",
        "4503599627370497.5", "4503599627370496.501", "4503599627370496.499",
        "1.00000000000000011102230246251565404", "0.1e-27", "123456789e27"};
    for (size_t i = 0; i < sizeof half / sizeof *half; i++) {
        char line[128];
        snprintf(line, sizeof line, "%s 0 0\n", half[i]);
        read_ok(text("half.xyz", line), NULL, &c);
        double want = strtod(half[i], NULL);
        ck_assert_msg(memcmp(&want, &c.xyz[0], 8) == 0, "%s: %.17g vs %.17g",
                      half[i], c.xyz[0], want);
        jf_cloud_free(&c);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_read");
    TCase *tc = tcase_create("read");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, bunny_scan);
    tcase_add_test(tc, bunny_mesh);
    tcase_add_test(tc, cgal_off);
    tcase_add_test(tc, ply_binary_be);
    tcase_add_test(tc, ply_binary_le_faces);
    tcase_add_test(tc, ply_ascii_nan);
    tcase_add_test(tc, ply_ascii_one_pass);
    tcase_add_test(tc, xyz_columns);
    tcase_add_test(tc, xyz_default_normals);
    tcase_add_test(tc, xyz_nan_rows_kept);
    tcase_add_test(tc, pts_count_line);
    tcase_add_test(tc, csv_header);
    tcase_add_test(tc, off_variants);
    tcase_add_test(tc, exact_decimal_parse);
    tcase_add_test(tc, parse_vs_strtod);
    tcase_add_test(tc, xyz_one_pass_rows);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
