/* test_io_las.c -- the LAS reader (issue 13): every point data record
 * format 0-10 in files written here (versions 1.2 and 1.4, legacy and
 * 64-bit counts, records longer than their format), georeferenced values
 * exact; the two real laspy samples against their x y z listings; every
 * header lie, a LAS file named .e57 and a compression bit without LASzip's
 * VLR a one-line error (LAZ itself: test_io_laz.c). */
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

static void setup(void) { tmpdir_setup("/tmp/jf_io_las_XXXXXX"); }

/* A LAS file of n points in record format fmt, record length base + pad:
 * X = 1000 i - 7, Y = -3 i, Z = i * i, scale (0.001, 0.002, 0.01), offset
 * (1e6, -2e6, 350).  Version 1.4 (64-bit count only) for formats >= 6,
 * else 1.2.  Returns its size; *out malloc'd. */
static size_t make_las(unsigned fmt, unsigned pad, size_t n, unsigned char **out)
{
    int v14 = fmt >= 6;
    unsigned hsize = v14 ? 375 : 227, rl = base_len[fmt] + pad;
    size_t len = hsize + n * rl;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    b[24] = 1;
    b[25] = v14 ? 4 : 2;
    memcpy(b + 26, "jetfit test", 11);
    put16(b + 94, hsize);
    put32(b + 96, hsize);
    b[104] = (unsigned char)fmt;
    put16(b + 105, rl);
    put32(b + 107, v14 ? 0 : (uint32_t)n);
    putd(b + 131, 0.001), putd(b + 139, 0.002), putd(b + 147, 0.01);
    putd(b + 155, 1e6), putd(b + 163, -2e6), putd(b + 171, 350);
    if (v14) put64(b + 247, n);
    for (size_t i = 0; i < n; i++) {
        unsigned char *r = b + hsize + i * rl;
        put32(r, (uint32_t)(int32_t)(1000 * (int)i - 7));
        put32(r + 4, (uint32_t)(int32_t)(-3 * (int)i));
        put32(r + 8, (uint32_t)(int32_t)(i * i));
        memset(r + 12, 0xA5, rl - 12); /* the rest of the record: ignored */
    }
    *out = b;
    return len;
}

START_TEST(every_format)
{
    for (unsigned fmt = 0; fmt <= 10; fmt++)
        for (unsigned pad = 0; pad <= 5; pad += 5) {
            unsigned char *b;
            size_t len = make_las(fmt, pad, 50, &b);
            const char *p = fixture("f.las", b, len);
            jf_cloud c;
            jf_error e;
            ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "format %u: %s", fmt, e.msg);
            ck_assert_uint_eq(c.n, 50);
            for (size_t i = 0; i < 50; i++) {
                ck_assert(c.xyz[3 * i] == (1000.0 * (double)i - 7) * 0.001 + 1e6);
                ck_assert(c.xyz[3 * i + 1] == (-3.0 * (double)i) * 0.002 - 2e6);
                ck_assert(c.xyz[3 * i + 2] == (double)(i * i) * 0.01 + 350);
            }
            jf_cloud_free(&c);
            free(b);
        }
}
END_TEST

/* Every version 1.0-1.4 with its own header size (227 up to 1.2, 235 for
 * 1.3, 375 for 1.4: the point data starts after it), formats 0 and 1. */
START_TEST(every_version)
{
    static const unsigned hsz[5] = {227, 227, 227, 235, 375};
    for (unsigned minor = 0; minor <= 4; minor++)
        for (unsigned fmt = 0; fmt <= 1; fmt++) {
            unsigned char *b;
            size_t len0 = make_las(fmt, 0, 30, &b), rl = base_len[fmt];
            /* move the records behind a header of hsz[minor] bytes */
            size_t len = hsz[minor] + 30 * rl;
            unsigned char *m = calloc(1, len);
            memcpy(m, b, 227);
            memcpy(m + hsz[minor], b + (len0 - 30 * rl), 30 * rl);
            m[25] = (unsigned char)minor;
            put16(m + 94, hsz[minor]);
            put32(m + 96, hsz[minor]);
            if (minor == 4) put64(m + 247, 30);
            const char *p = fixture("v.las", m, len);
            jf_cloud c;
            jf_error e;
            ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "1.%u format %u: %s", minor, fmt,
                          e.msg);
            ck_assert_uint_eq(c.n, 30);
            for (size_t i = 0; i < 30; i++) {
                ck_assert(c.xyz[3 * i] == (1000.0 * (double)i - 7) * 0.001 + 1e6);
                ck_assert(c.xyz[3 * i + 2] == (double)(i * i) * 0.01 + 350);
            }
            jf_cloud_free(&c);
            free(m);
            free(b);
        }
}
END_TEST

/* laspy's samples against the x y z listings made from them (3 decimals,
 * so to half a millimetre; the scale is 0.01 or 0.001). */
static void sample(const char *las, const char *xyz, size_t n)
{
    jf_cloud a, t;
    jf_error e;
    ck_assert_msg(jf_cloud_read(las, NULL, &a, &e) == JF_OK, "%s", e.msg);
    ck_assert_msg(jf_cloud_read(xyz, NULL, &t, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(a.n, n);
    ck_assert_uint_eq(t.n, n);
    for (size_t i = 0; i < 3 * n; i++)
        ck_assert_msg(fabs(a.xyz[i] - t.xyz[i]) <= 5e-4, "%s: value %zu: %.17g vs %.17g", las, i,
                      a.xyz[i], t.xyz[i]);
    jf_cloud_free(&a);
    jf_cloud_free(&t);
}

START_TEST(real_samples)
{
    sample(JF_TESTS_DIR "/data/las/simple.las", JF_TESTS_DIR "/data/las/simple.xyz", 1065);
    sample(JF_TESTS_DIR "/data/las/vegetation_1_3.las", JF_TESTS_DIR "/data/las/vegetation_1_3.xyz",
           10683);
}
END_TEST

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

START_TEST(header_lies)
{
    unsigned char *b;
    size_t len = make_las(1, 0, 20, &b);
    unsigned char *m = malloc(len);
    memcpy(m, b, len);
    put32(m + 107, 21); /* one point more than the file holds */
    refused("count.las", m, len, "cannot fit");
    refused("count.las", m, len, "point count 21");
    refused("count.las", m, len, "point record 21 is missing");
    refused("trunc.las", b, len - 5, "cannot fit");
    refused("trunc.las", b, len - 5, "point record 20 is missing or cut short");
    memcpy(m, b, len);
    put32(m + 96, (uint32_t)len + 10); /* point data past the end */
    refused("off.las", m, len, "offset to point data");
    memcpy(m, b, len);
    put16(m + 105, 27); /* shorter than format 1's 28 bytes */
    refused("rl.las", m, len, "shorter than format 1");
    memcpy(m, b, len);
    m[104] = 11;
    refused("fmt.las", m, len, "record format 11");
    memcpy(m, b, len);
    m[104] = 0x80 | 1; /* laszip's compression bit without laszip's VLR */
    refused("c.las", m, len, "laszip VLR");
    refused("c.laz", m, len, "laszip VLR");
    memcpy(m, b, len);
    m[24] = 2;
    refused("v.las", m, len, "version 2");
    memcpy(m, b, len);
    putd(m + 139, 0.0);
    refused("s.las", m, len, "scale");
    memcpy(m, b, len);
    put32(m + 107, 0);
    refused("empty.las", m, len, "no points");
    refused("short.las", b, 100, "at least 227");
    refused("sig.las", (const unsigned char *)"PLY not LAS", 11, "LASF");
    refused("x.e57", b, len, "not an E57 file");
    free(m);
    free(b);
}
END_TEST

/* The writer: x y z at 1e6 (georeferenced) within half a scale step of
 * 1e-7 m, read back by our reader; the rows without a frame are refused. */
START_TEST(writer_round_trip)
{
    const size_t n = 200;
    double *xyz = malloc(n * 3 * sizeof *xyz);
    for (size_t i = 0; i < n; i++) {
        xyz[3 * i] = 1e6 + 0.37 * (double)i;
        xyz[3 * i + 1] = -4e6 + sin((double)i) * 50;
        xyz[3 * i + 2] = 123.456789 + 1e-3 * (double)(i % 7);
    }
    jf_column cols[5] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {"k1", JF_COL_F64}, {"status", JF_COL_I32}};
    char path[128];
    snprintf(path, sizeof path, "%s/w.las", tmpdir);
    jf_writer *w;
    jf_error e;
    ck_assert_int_eq(jf_writer_open(path, cols, 5, n, 0, &w, &e), JF_OK);
    double row[5] = {1, 2, 3, 4, 5};
    ck_assert_int_ne(jf_writer_row(w, row), JF_OK); /* no frame yet */
    jf_writer_abort(w);
    ck_assert(access(path, F_OK) != 0);
    ck_assert_int_eq(jf_writer_open(path, cols, 5, n, 0, &w, &e), JF_OK);
    ck_assert_int_eq(jf_writer_las_frame(w, xyz, n), JF_OK);
    for (size_t i = 0; i < n; i++) {
        double r[5] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], 0.5 * (double)i, (double)i};
        ck_assert_int_eq(jf_writer_row(w, r), JF_OK);
    }
    ck_assert_int_eq(jf_writer_commit(w, &e), JF_OK);
    jf_cloud c;
    ck_assert_msg(jf_cloud_read(path, NULL, &c, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(c.n, n);
    for (size_t i = 0; i < 3 * n; i++)
        ck_assert_msg(fabs(c.xyz[i] - xyz[i]) <= 0.5e-7 * (1 + 1e-6) + 1e-15 * fabs(xyz[i]),
                      "value %zu: %.17g vs %.17g", i, c.xyz[i], xyz[i]);
    jf_cloud_free(&c);
    free(xyz);
}
END_TEST

/* jf_cloud_write to .las (the path `jetfit generate -o x.las` takes): the
 * frame comes from the cloud, x y z read back within half a scale step,
 * the normals go as Extra Bytes.  It failed ("needs the cloud's frame")
 * before jf_cloud_write set the frame. */
START_TEST(cloud_write_las)
{
    const size_t n = 300;
    jf_cloud c = {0};
    c.n = n;
    c.xyz = malloc(3 * n * sizeof(double));
    c.nrm = malloc(3 * n * sizeof(double));
    for (size_t i = 0; i < n; i++) {
        double u = 0.1 * (double)i;
        c.xyz[3 * i] = 6.5e5 + 3 * cos(u), c.xyz[3 * i + 1] = 4.2e6 + 3 * sin(u);
        c.xyz[3 * i + 2] = 0.01 * (double)i;
        c.nrm[3 * i] = cos(u), c.nrm[3 * i + 1] = sin(u), c.nrm[3 * i + 2] = 0;
    }
    char path[128];
    snprintf(path, sizeof path, "%s/c.las", tmpdir);
    jf_error e = {{0}};
    ck_assert_msg(jf_cloud_write(path, &c, 0, &e) == JF_OK, "%s", e.msg);
    jf_cloud r;
    ck_assert_msg(jf_cloud_read(path, NULL, &r, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(r.n, n);
    for (size_t i = 0; i < 3 * n; i++)
        ck_assert_msg(fabs(r.xyz[i] - c.xyz[i]) <= 0.5e-7 * (1 + 1e-6) + 1e-15 * fabs(c.xyz[i]),
                      "value %zu: %.17g vs %.17g", i, r.xyz[i], c.xyz[i]);
    /* record format 0 plus three doubles: 20 + 24 bytes a record */
    FILE *f = fopen(path, "rb");
    unsigned char h[107];
    ck_assert_uint_eq(fread(h, 1, sizeof h, f), sizeof h);
    fclose(f);
    ck_assert_uint_eq(h[104], 0);
    ck_assert_uint_eq(h[105] | h[106] << 8, 44);
    jf_cloud_free(&r);
    jf_cloud_free(&c);
}
END_TEST

/* The compression bit decides, not the name (issue 25): an uncompressed
 * file named .laz is read as LAS, as the same bytes named .las. */
START_TEST(laz_by_name)
{
    unsigned char *b;
    size_t len = make_las(1, 0, 20, &b);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(fixture("PLAIN.LAZ", b, len), NULL, &c, &e) == JF_OK, "%s", e.msg);
    jf_cloud_free(&c);
    const char *p = fixture("plain.las", b, len);
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "%s", e.msg);
    jf_cloud_free(&c);
    free(b);
}
END_TEST

/* The test at 1e6 (test_degenerate.c) for LAS input: the same int32
 * records with offset (1e6, -2e6, 5e5) and with offset 0 give the same
 * curvatures to 1e-7 and normals to 1e-8 through the whole pipeline (the
 * reader applies scale and offset in double; the fit translates to each
 * point).  What is left is the rounding of X * 1e-7 + 2e6 to the double
 * grid (1.2e-10) over neighbourhoods of a few centimetres; sums in world
 * coordinates would lose everything (test_degenerate.c). */
static const char *las_patch(const char *name, const double off[3])
{
    enum { NP = 40 };
    size_t len = 375 + NP * 20;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    b[24] = 1, b[25] = 4;
    put16(b + 94, 375);
    put32(b + 96, 375);
    b[104] = 0;
    put16(b + 105, 20);
    put32(b + 107, NP);
    for (int a = 0; a < 3; a++) putd(b + 131 + 8 * a, 1e-7), putd(b + 155 + 8 * a, off[a]);
    put64(b + 247, NP);
    uint64_t s = 7;
    for (int i = 0; i < NP; i++) {
        double xy[2];
        for (int k = 0; k < 2; k++) {
            s ^= s << 13, s ^= s >> 7, s ^= s << 17;
            xy[k] = i ? 0.05 * (2 * ((double)(s >> 11) * 0x1p-53) - 1) : 0;
        }
        double z = 0.3 * xy[0] * xy[0] - 0.2 * xy[0] * xy[1] + 0.5 * xy[1] * xy[1];
        unsigned char *r = b + 375 + 20 * i;
        put32(r, (uint32_t)(int32_t)llround(xy[0] / 1e-7));
        put32(r + 4, (uint32_t)(int32_t)llround(xy[1] / 1e-7));
        put32(r + 8, (uint32_t)(int32_t)llround(z / 1e-7));
    }
    const char *p = fixture(name, b, len);
    free(b);
    return p;
}

START_TEST(georeferenced_fit)
{
    static const double off[2][3] = {{1e6, -2e6, 5e5}, {0, 0, 0}};
    jf_cloud c[2];
    jf_result *r[2];
    for (int k = 0; k < 2; k++) {
        char name[16];
        snprintf(name, sizeof name, "geo%d.las", k);
        char path[256];
        snprintf(path, sizeof path, "%s", las_patch(name, off[k]));
        jf_error e = {{0}};
        ck_assert_msg(jf_cloud_read(path, NULL, &c[k], &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(c[k].n, 40);
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        ck_assert_int_eq(jf_nb_parse("knn:20", &o.nb, NULL), JF_OK);
        o.params.frame = JF_FRAME_AXIS;
        o.threads = 1;
        r[k] = calloc(c[k].n, sizeof *r[k]);
        ck_assert_msg(jf_estimate(&c[k], &o, r[k], &e) == JF_OK, "%s", e.msg);
    }
    ck_assert(c[0].xyz[0] == 1e6 && c[1].xyz[0] == 0);
    for (size_t i = 0; i < 40; i++) {
        ck_assert_uint_eq(r[0][i].status, r[1][i].status);
        ck_assert_double_eq_tol(r[0][i].k1, r[1][i].k1, 1e-7);
        ck_assert_double_eq_tol(r[0][i].k2, r[1][i].k2, 1e-7);
        for (int a = 0; a < 3; a++)
            ck_assert_msg(fabs(r[0][i].normal[a] - r[1][i].normal[a]) <= 1e-8, "point %zu: %g", i,
                          r[0][i].normal[a] - r[1][i].normal[a]);
    }
    /* and the analytic curvatures at the centre (Hessian [[0.6, -0.2],
     * [-0.2, 1.0]]; the records are quantised to 1e-7) */
    const double mean = 0.8, rad = sqrt(0.08);
    ck_assert_double_eq_tol(r[0][0].k1, mean + rad, 1e-3);
    ck_assert_double_eq_tol(r[0][0].k2, mean - rad, 1e-3);
    for (int k = 0; k < 2; k++) {
        jf_cloud_free(&c[k]);
        free(r[k]);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_las");
    TCase *tc = tcase_create("las");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, every_format);
    tcase_add_test(tc, every_version);
    tcase_add_test(tc, real_samples);
    tcase_add_test(tc, header_lies);
    tcase_add_test(tc, writer_round_trip);
    tcase_add_test(tc, cloud_write_las);
    tcase_add_test(tc, laz_by_name);
    tcase_add_test(tc, georeferenced_fit);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
