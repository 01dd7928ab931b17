/* test_io_laz_write.c -- the LAZ writer (issue 25.2): what `-o out.laz`
 * writes is the LAS output compressed, nothing else.
 *  - round trip: our reader turns the .laz back into exactly the file the
 *    LAS writer writes for the same table (jf__laz_unpack: header, VLRs,
 *    records, EVLRs, byte for byte), for real LAZ/LAS inputs of formats
 *    0-3 and 6-8 with extra bytes and jetfit columns, for generated
 *    records (laz_gen.h) at chunk boundaries (1, 2, 50,000, 50,001,
 *    100,001 points), and for a non-LAS input (format 0);
 *  - the same .laz bytes for 1 and 2 threads;
 *  - the chunk coders alone: random records encoded then decoded, equal;
 *  - bad cases: an unwritable folder, a waveform format: one line naming
 *    the file, no file, an existing file untouched.
 * laz-perf's reading of our files is test_laz_perf (tests/laz.cmake). */
#define _GNU_SOURCE
#include <check.h>
#include <omp.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "jetfit.h"
#include "io_internal.h"
#include "laz_enc.h"

#include "laz_gen.h"
#include "laz_roundtrip.h"
#include "test_io_util.h"
#include "jf_test.h"

#define DATA JF_TESTS_DIR "/data/laz/"

static void setup(void)
{
    tmpdir_setup("/tmp/jf_io_lazw_XXXXXX");
    setenv("SOURCE_DATE_EPOCH", "1700000000", 1); /* the same date in both files */
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_msg(f != NULL, "%s", path);
    fseek(f, 0, SEEK_END);
    *len = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*len + 1);
    ck_assert_uint_eq(fread(b, 1, *len, f), *len);
    fclose(f);
    return b;
}

static const char *tmp(const char *name)
{
    static char p[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", tmpdir, name);
    return p[k];
}

/* The value written as nx for point i, in [-1, 1]. */
static double nx_of(size_t i) { return sin(0.7 * (double)i); }

/* The value written as k1 for point i: a double that no float holds. */
static double k1_of(const jf_cloud *c, size_t i) { return 1.0 / (1.0 + (double)i) + c->xyz[3 * i]; }

/* The cloud c written to path with x y z and, if extra, two jetfit-like
 * columns (k1 of type kt, an int) of values from the points. */
static jf_status write_table_t(const jf_cloud *c, const char *path, int extra, jf_col_type kt,
                               jf_error *e)
{
    jf_column cols[6] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64},
                         {"k1", kt}, {"status", JF_COL_I32}, {"nx", JF_COL_F32_Q16}};
    size_t nc = extra ? (extra == 2 ? 6 : 5) : 3; /* 2: nx too */
    jf_writer *w;
    jf_status st = jf_writer_open(path, cols, nc, c->n, 0, &w, e);
    if (st != JF_OK)
        return st;
    double *v = malloc(sizeof *v * nc * (c->n ? c->n : 1));
    ck_assert_ptr_nonnull(v);
    for (size_t i = 0; i < c->n; i++) {
        memcpy(v + nc * i, c->xyz + 3 * i, 3 * sizeof *v);
        if (extra) {
            v[nc * i + 3] = k1_of(c, i);
            v[nc * i + 4] = (double)(i % 7);
            if (nc == 6) v[nc * i + 5] = nx_of(i);
        }
    }
    if (c->attrs.nattrs || c->attrs.las_head)
        ck_assert_int_eq(jf_writer_attrs(w, &c->attrs), JF_OK);
    if (!(c->attrs.las_head && c->attrs.rec))
        ck_assert_int_eq(jf_writer_las_frame(w, c->xyz, c->n), JF_OK);
    jf_writer_rows(w, v, c->n, 0);
    free(v);
    return jf_writer_commit(w, e);
}

static jf_status write_table(const jf_cloud *c, const char *path, int extra, jf_error *e)
{
    return write_table_t(c, path, extra, JF_COL_F64, e);
}

/* in read, written as .las and .laz (k1 of type kt): the .laz decodes to
 * the .las file byte for byte; returns the .laz size / .las size. */
static double roundtrip_t(const char *in, int extra, jf_col_type kt, const char *tag)
{
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
    char las[80], laz[80];
    snprintf(las, sizeof las, "%s.las", tag);
    snprintf(laz, sizeof laz, "%s.laz", tag);
    const char *plas = tmp(las), *plaz = tmp(laz);
    ck_assert_msg(write_table_t(&c, plas, extra, kt, &e) == JF_OK, "%s", e.msg);
    ck_assert_msg(write_table_t(&c, plaz, extra, kt, &e) == JF_OK, "%s", e.msg);
    size_t la, lz, li;
    unsigned char *a = slurp(plas, &la), *z = slurp(plaz, &lz);
    ck_assert_msg((z[104] & 0x80) && (z[104] & 0x3f) == (a[104] & 0x3f), "%s: format byte", tag);
    char *img;
    ck_assert_msg(jf__laz_unpack((const char *)z, lz, plaz, &img, &li, &e) == JF_OK, "%s: %s",
                  tag, e.msg);
    ck_assert_msg(li == la, "%s: unpacked %zu bytes, the LAS file %zu", tag, li, la);
    ck_assert_msg(!memcmp(img, a, la), "%s: the LAZ does not unpack to the LAS file", tag);
    /* and the reader: the same records */
    jf_cloud r;
    ck_assert_msg(jf_cloud_read(plaz, NULL, &r, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(r.n, c.n);
    free(img);
    free(a);
    free(z);
    jf_cloud_free(&r);
    jf_cloud_free(&c);
    return (double)lz / (double)la;
}

static double roundtrip(const char *in, int extra, const char *tag)
{
    return roundtrip_t(in, extra, JF_COL_F64, tag);
}

/* The index of the attribute named nm, or nattrs. */
static size_t attr_index(const jf_attrs *a, const char *nm)
{
    size_t k = 0;
    while (k < a->nattrs && strcmp(a->attr[k].name, nm)) k++;
    return k;
}

/* Float columns (`--las-columns float` and `compact`, the .laz default of
 * estimate): the .laz unpacks to the .las of the same columns, and our
 * reader gives back k1 as the float nearest the double written, (float)k1
 * exactly, nx (JF_COL_F32_Q16) as a float that is a whole number of
 * 2^-16 within 2^-17 of the double, the input's attributes and
 * coordinates as they were; 4 bytes a value, not 8. */
START_TEST(float_columns)
{
    static const char *const f[] = {"append-bug.laz", "1_4_w_evlr.laz",
                                    "point-color-time.las.laz", "point10.las.laz"};
    for (size_t k = 0; k < sizeof f / sizeof *f; k++) {
        char in[256], tag[32];
        snprintf(in, sizeof in, DATA "%s", f[k]);
        snprintf(tag, sizeof tag, "float%zu", k);
        roundtrip_t(in, 2, JF_COL_F32, tag);
        jf_cloud c, r, d;
        jf_error e;
        ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
        ck_assert_msg(jf_cloud_read(in, NULL, &d, &e) == JF_OK, "%s", e.msg);
        char laz[80], dlaz[80];
        snprintf(laz, sizeof laz, "%s.laz", tag);
        snprintf(dlaz, sizeof dlaz, "%sd.laz", tag);
        ck_assert_msg(jf_cloud_read(tmp(laz), NULL, &r, &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(r.n, c.n);
        size_t j = attr_index(&r.attrs, "k1");
        ck_assert_msg(j < r.attrs.nattrs && r.attrs.attr[j].type == JF_ATTR_F32, "%s: k1", f[k]);
        size_t jn = attr_index(&r.attrs, "nx");
        ck_assert_msg(jn < r.attrs.nattrs && r.attrs.attr[jn].type == JF_ATTR_F32, "%s: nx", f[k]);
        size_t rounded = 0;
        for (size_t i = 0; i < c.n; i++) {
            double want = (double)(float)k1_of(&c, i), got = jf_attr_get(&r.attrs, j, i);
            ck_assert_msg(got == want, "%s: point %zu: k1 %.17g, (float) %.17g", f[k], i, got,
                          want);
            rounded += got != k1_of(&c, i);
            double q = jf_attr_get(&r.attrs, jn, i), q16 = q * 65536.0;
            ck_assert_msg(q16 == floor(q16) && fabs(q - nx_of(i)) <= 0x1p-17,
                          "%s: point %zu: nx %.17g for %.17g", f[k], i, q, nx_of(i));
            for (int a = 0; a < 3; a++)
                ck_assert(r.xyz[3 * i + a] == c.xyz[3 * i + a]);
        }
        ck_assert_msg(rounded > c.n / 2, "%s: k1 not rounded to float", f[k]);
        for (size_t q = 0; q < c.attrs.nattrs; q++) {
            size_t m = attr_index(&r.attrs, c.attrs.attr[q].name);
            ck_assert_msg(m < r.attrs.nattrs, "%s: %s lost", f[k], c.attrs.attr[q].name);
            for (size_t i = 0; i < c.n; i++) {
                double x = jf_attr_get(&c.attrs, q, i), y = jf_attr_get(&r.attrs, m, i);
                ck_assert_msg(!memcmp(&x, &y, sizeof x), "%s: %s, point %zu", f[k],
                              c.attrs.attr[q].name, i);
            }
        }
        /* the same table with double k1 (and no nx): the same record length */
        ck_assert_msg(write_table(&d, tmp(dlaz), 1, &e) == JF_OK, "%s", e.msg);
        jf_cloud_free(&d);
        ck_assert_msg(jf_cloud_read(tmp(dlaz), NULL, &d, &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(d.attrs.stride, r.attrs.stride);
        jf_cloud_free(&d);
        jf_cloud_free(&r);
        jf_cloud_free(&c);
    }
}
END_TEST

START_TEST(real_files)
{
    static const char *const f[] = {"point10.las.laz", "point-time.las.laz", "point-color.las.laz",
                                    "point-color-time.las.laz", "extrabytes.laz", "1815.laz",
                                    "1_4_w_evlr.laz", "simple.copc.laz", "append-bug.laz",
                                    "extra.laz"};
    for (size_t k = 0; k < sizeof f / sizeof *f; k++) {
        char in[256], tag[32];
        snprintf(in, sizeof in, DATA "%s", f[k]);
        snprintf(tag, sizeof tag, "real%zu", k);
        double r = roundtrip(in, 1, tag);
        ck_assert_msg(r < 0.9, "%s: ratio %.3f", f[k], r);
        snprintf(tag, sizeof tag, "realk%zu", k);
        roundtrip(in, 0, tag); /* records only: the input's */
    }
}
END_TEST

/* Generated records of every format, at the chunk boundaries. */
START_TEST(generated)
{
    static const unsigned fmts[] = {0, 1, 2, 3, 6, 7, 8};
    static const size_t ns[] = {1, 2, 50000, 50001, 100001};
    for (size_t i = 0; i < 7; i++)
        for (size_t j = 0; j < 5; j++) {
            /* the largest counts for two formats only: time */
            if (ns[j] > 2 && fmts[i] != 3 && fmts[i] != 8 && ns[j] != 50001)
                continue;
            size_t len;
            unsigned char *b = lazgen_las(fmts[i], (unsigned)(i + j) % 5, ns[j], 100 * i + j, &len);
            char name[64];
            snprintf(name, sizeof name, "gen%u_%zu.las", fmts[i], ns[j]);
            const char *in = fixture(name, b, len);
            free(b);
            char tag[64];
            snprintf(tag, sizeof tag, "out%u_%zu", fmts[i], ns[j]);
            roundtrip(in, j % 2, tag);
        }
}
END_TEST

/* The file does not depend on the thread count. */
START_TEST(threads)
{
    size_t len, l1, l2;
    unsigned char *b = lazgen_las(7, 3, 160000, 7, &len);
    const char *in = fixture("t.las", b, len);
    free(b);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
    int nt = omp_get_max_threads();
    omp_set_num_threads(1);
    ck_assert_int_eq(write_table(&c, tmp("t1.laz"), 1, &e), JF_OK);
    omp_set_num_threads(3);
    ck_assert_int_eq(write_table(&c, tmp("t3.laz"), 1, &e), JF_OK);
    omp_set_num_threads(nt);
    unsigned char *a = slurp(tmp("t1.laz"), &l1), *z = slurp(tmp("t3.laz"), &l2);
    ck_assert_uint_eq(l1, l2);
    ck_assert(!memcmp(a, z, l1));
    free(a);
    free(z);
    jf_cloud_free(&c);
}
END_TEST

/* A cloud from a non-LAS input: format 0, the normals as Extra Bytes. */
START_TEST(non_las)
{
    size_t n = 70000;
    jf_cloud c = {0};
    c.n = n;
    c.xyz = malloc(3 * n * sizeof *c.xyz);
    c.nrm = malloc(3 * n * sizeof *c.nrm);
    uint64_t s = 5;
    for (size_t i = 0; i < 3 * n; i++) {
        c.xyz[i] = 100.0 * jf_unit(jf_splitmix64(&s));
        c.nrm[i] = jf_unit(jf_splitmix64(&s)) - 0.5;
    }
    jf_error e;
    ck_assert_msg(jf_cloud_write(tmp("n.las"), &c, 0, &e) == JF_OK, "%s", e.msg);
    ck_assert_msg(jf_cloud_write(tmp("n.laz"), &c, 0, &e) == JF_OK, "%s", e.msg);
    size_t la, lz, li;
    unsigned char *a = slurp(tmp("n.las"), &la), *z = slurp(tmp("n.laz"), &lz);
    char *img;
    ck_assert_msg(jf__laz_unpack((const char *)z, lz, "n.laz", &img, &li, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(li, la);
    ck_assert(!memcmp(img, a, la));
    ck_assert_uint_eq(a[104], 0);
    free(img);
    free(a);
    free(z);
    free(c.xyz);
    free(c.nrm);
}
END_TEST

/* The chunk coders alone: records of every format, 1 to 400 points,
 * encoded and decoded back (a small round-trip fuzz). */
START_TEST(codec_fuzz)
{
    uint64_t s = 99;
    for (int t = 0; t < 300; t++) {
        static const unsigned fmts[] = {0, 1, 2, 3, 6, 7, 8};
        unsigned fmt = fmts[jf_splitmix64(&s) % 7], extra = (unsigned)(jf_splitmix64(&s) % 6);
        uint32_t n = 1 + (uint32_t)(jf_splitmix64(&s) % 400);
        unsigned rl = lazgen_base[fmt] + extra;
        unsigned char *rec = malloc((size_t)n * rl), *back = malloc((size_t)n * rl);
        lazgen_records(fmt, extra, n, jf_splitmix64(&s), rec);
        if (t % 3 == 0) /* fully random bytes too */
            for (size_t k = 0; k < (size_t)n * rl; k++)
                rec[k] = (unsigned char)jf_splitmix64(&s);
        jf_lazw *w = NULL;
        char why[160];
        ck_assert_ptr_nonnull(w = jf__lazw_open(fmt, rl, 0, why, sizeof why));
        jf__lazw_free(w);
        char msg[160];
        ck_assert_msg(lazrt_roundtrip(fmt, extra, rec, n, back, msg, sizeof msg) == 0,
                      "trial %d (format %u, %u points): %s", t, fmt, n, msg);
        free(rec);
        free(back);
    }
}
END_TEST

/* Bad cases: one line naming the file, no file left, nothing clobbered. */
START_TEST(bad_output)
{
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(DATA "1_4_w_evlr.laz", NULL, &c, &e), JF_OK);
    /* a folder that does not exist */
    const char *p = tmp("no/such/dir/out.laz");
    ck_assert_int_ne(write_table(&c, p, 1, &e), JF_OK);
    ck_assert_msg(strstr(e.msg, "out.laz") && !strchr(e.msg, '\n'), "%s", e.msg);
    jf_cloud_free(&c);
    /* point format 4 (waveform): refused, an existing file untouched */
    size_t len;
    unsigned char *b = lazgen_las(1, 37, 10, 3, &len); /* 28 + 37 = format 4's 57 + 8 */
    b[104] = 4;
    const char *in = fixture("w4.las", b, len);
    free(b);
    ck_assert_msg(jf_cloud_read(in, NULL, &c, &e) == JF_OK, "%s", e.msg);
    {
        const char *out = fixture("old.laz", "old", 3);
        char keep[256];
        snprintf(keep, sizeof keep, "%s", out);
        ck_assert_int_ne(write_table(&c, keep, 1, &e), JF_OK);
        ck_assert_msg(strstr(e.msg, "old.laz") && strstr(e.msg, "point format 4"), "%s", e.msg);
        unsigned char *o = slurp(keep, &len);
        ck_assert_uint_eq(len, 3);
        ck_assert(!memcmp(o, "old", 3));
        free(o);
        jf_cloud_free(&c);
    }
    struct stat st;
    ck_assert_int_ne(stat(p, &st), 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_laz_write");
    TCase *t = tcase_create("laz_write");
    tcase_add_checked_fixture(t, setup, teardown);
    tcase_set_timeout(t, 300);
    tcase_add_test(t, real_files);
    tcase_add_test(t, generated);
    tcase_add_test(t, threads);
    tcase_add_test(t, non_las);
    tcase_add_test(t, float_columns);
    tcase_add_test(t, codec_fuzz);
    tcase_add_test(t, bad_output);
    suite_add_tcase(s, t);
    return jf_test_run(s);
}
