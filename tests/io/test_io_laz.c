/* test_io_laz.c -- the LAZ reader (issue 25): real LASzip files from
 * laz-perf's and laspy's test sets (tests/data/laz/SOURCE.md), point
 * formats 0-3 and 6 and extra bytes, decoded to their uncompressed LAS
 * twins byte for byte (the twins were written by other software from the
 * same points), EVLRs kept, the same x y z without attributes; the same
 * records for 1 and N threads on a 65-chunk file; every damaged file a
 * one-line error that names the chunk.
 * Formats 7 and 8 have no twin: test_laz_perf compares them with laz-perf. */
#define _GNU_SOURCE
#include <check.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_laz_XXXXXX"); }

#define DATA JF_TESTS_DIR "/data/laz/"

static uint32_t g32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void p32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void p16(unsigned char *p, unsigned v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_msg(f != NULL, "%s", path);
    fseek(f, 0, SEEK_END);
    *len = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*len);
    ck_assert_uint_eq(fread(b, 1, *len, f), *len);
    fclose(f);
    return b;
}

/* The LAZ file's records equal the LAS twin's, byte for byte; x y z equal
 * what the LAS reader gives for the twin; the header's scale and offset
 * and the attributes' names are the twin's. */
static void twin(const char *laz, const char *las, unsigned fmt, size_t n)
{
    size_t len;
    unsigned char *b = slurp(las, &len);
    uint32_t off = g32(b + 96);
    unsigned rl = b[105] | b[106] << 8;
    if (fmt < 6)
        ck_assert_uint_eq(g32(b + 107), n);
    else
        n = g32(b + 247);
    ck_assert_uint_eq(b[104], fmt);
    jf_cloud z, s;
    jf_error e;
    ck_assert_msg(jf_cloud_read(laz, NULL, &z, &e) == JF_OK, "%s", e.msg);
    ck_assert_msg(jf_cloud_read(las, NULL, &s, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(z.n, n);
    ck_assert_uint_eq(z.attrs.stride, rl);
    ck_assert_msg(memcmp(z.attrs.rec, b + off, n * rl) == 0, "%s: records differ", laz);
    ck_assert_msg(memcmp(z.xyz, s.xyz, 3 * n * sizeof(double)) == 0, "%s: xyz differ", laz);
    ck_assert_uint_eq(z.attrs.nattrs, s.attrs.nattrs);
    for (size_t k = 0; k < z.attrs.nattrs; k++)
        ck_assert_str_eq(z.attrs.attr[k].name, s.attrs.attr[k].name);
    /* the header handed on for a LAS output: no compression bit, no laszip VLR */
    const unsigned char *h = z.attrs.las_head;
    ck_assert_uint_eq(h[104], fmt);
    ck_assert_msg(memcmp(h + 131, b + 131, 48) == 0, "%s: scale/offset differ", laz);
    ck_assert_ptr_null(memmem(h, z.attrs.las_head_len, "laszip encoded", 14));
    ck_assert_uint_eq(g32(h + 96), z.attrs.las_head_len);
    /* without attributes (the decoded records dropped): the same x y z,
     * the header still kept, no records */
    jf_read_opts o;
    jf_cloud q;
    jf_read_opts_init(&o);
    o.no_attrs = 1;
    ck_assert_msg(jf_cloud_read(laz, &o, &q, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(q.n, n);
    ck_assert_msg(memcmp(q.xyz, s.xyz, 3 * n * sizeof(double)) == 0, "%s: xyz differ", laz);
    ck_assert_ptr_null(q.attrs.rec);
    ck_assert_uint_eq(q.attrs.las_head_len, z.attrs.las_head_len);
    ck_assert(memcmp(q.attrs.las_head, h, q.attrs.las_head_len) == 0);
    jf_cloud_free(&q);
    jf_cloud_free(&z);
    jf_cloud_free(&s);
    free(b);
}

START_TEST(twins_v2)
{
    twin(DATA "point10.las.laz", DATA "point10.las", 0, 1065);
    twin(DATA "point-time.las.laz", DATA "point-time.las", 1, 1065);
    twin(DATA "point-color.las.laz", DATA "point-color.las", 2, 1065);
    twin(DATA "point-color-time.las.laz", DATA "point-color-time.las", 3, 1065);
    twin(DATA "extrabytes.laz", DATA "extrabytes.las", 3, 1065);
    twin(DATA "1815.laz", DATA "1815.las", 1, 1247);
    twin(DATA "extra.laz", DATA "extrabytes.las", 3, 1065); /* a LAS 1.4 header */
}
END_TEST

/* Layered (LAS 1.4, format 6), with an EVLR after the chunk table: the
 * records and the EVLR are the twin's. */
START_TEST(twin_v3_evlr)
{
    twin(DATA "1_4_w_evlr.laz", DATA "1_4_w_evlr.las", 6, 0);
    size_t len;
    unsigned char *b = slurp(DATA "1_4_w_evlr.las", &len);
    uint32_t at = g32(b + 235);
    jf_cloud z;
    jf_error e;
    ck_assert_msg(jf_cloud_read(DATA "1_4_w_evlr.laz", NULL, &z, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(z.attrs.las_evlr_len, len - at);
    ck_assert(memcmp(z.attrs.las_evlr, b + at, len - at) == 0);
    jf_cloud_free(&z);
    free(b);
}
END_TEST

/* A .las name with the compression bit is read as LAZ (the bit decides,
 * not the name), and the 65 variable-size chunks of a COPC file read with
 * 1 and 3 threads give the same records. */
START_TEST(by_bit_and_threads)
{
    size_t len;
    unsigned char *b = slurp(DATA "simple.copc.laz", &len);
    const char *p = fixture("named.las", b, len);
    jf_cloud a, c;
    jf_error e;
    int nt = omp_get_max_threads();
    omp_set_num_threads(1);
    ck_assert_msg(jf_cloud_read(p, NULL, &a, &e) == JF_OK, "%s", e.msg);
    omp_set_num_threads(3);
    ck_assert_msg(jf_cloud_read(DATA "simple.copc.laz", NULL, &c, &e) == JF_OK, "%s",
                  e.msg);
    ck_assert_uint_eq(a.n, 1065);
    omp_set_num_threads(nt);
    ck_assert_uint_eq(a.n, c.n);
    ck_assert(memcmp(a.attrs.rec, c.attrs.rec, a.n * a.attrs.stride) == 0);
    jf_cloud_free(&a);
    jf_cloud_free(&c);
    free(b);
}
END_TEST

/* Each damaged file: one line "NAME: reason" holding `what`, no cloud. */
static void refused(const char *name, const unsigned char *b, size_t len, const char *what)
{
    const char *p = fixture(name, b, len);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) != JF_OK, "%s was read", name);
    char pre[300];
    snprintf(pre, sizeof pre, "%s: ", p);
    ck_assert_msg(strstr(e.msg, pre) == e.msg, "'%s'", e.msg);
    ck_assert_msg(strstr(e.msg, what), "'%s' lacks '%s'", e.msg, what);
    ck_assert_ptr_null(strchr(e.msg, '\n'));
    ck_assert_ptr_null(c.xyz);
}

/* A file whose chunk table is damaged: read all the same, the records of
 * the intact file `ref`. */
static void rebuilt(const char *name, const unsigned char *b, size_t len,
                    const unsigned char *ref, size_t rlen)
{
    jf_cloud c, r;
    jf_error e;
    const char *p = fixture("ref.laz", ref, rlen);
    ck_assert_msg(jf_cloud_read(p, NULL, &r, &e) == JF_OK, "%s", e.msg);
    p = fixture(name, b, len);
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "%s: %s", name, e.msg);
    ck_assert_uint_eq(c.n, r.n);
    ck_assert(!memcmp(c.attrs.rec, r.attrs.rec, c.n * c.attrs.stride));
    jf_cloud_free(&c);
    jf_cloud_free(&r);
}

/* Where the laszip VLR's payload starts in b. */
static size_t vlr_payload(const unsigned char *b)
{
    size_t p = b[94] | b[95] << 8;
    for (uint32_t v = 0; v < g32(b + 100); v++) {
        if (!memcmp(b + p + 2, "laszip encoded", 14))
            return p + 54;
        p += 54 + (b[p + 20] | b[p + 21] << 8);
    }
    ck_abort_msg("no laszip VLR");
    return 0;
}

START_TEST(damaged)
{
    size_t len;
    unsigned char *b = slurp(DATA "point-time.las.laz", &len);
    unsigned char *m = malloc(len);
    uint32_t off = g32(b + 96);
    uint32_t table = g32(b + off); /* the chunk table's offset */
    size_t q = vlr_payload(b);
    /* the chunk table gone, pointing past the end or at itself, or
     * garbage: rebuilt from the chunks (the same records) */
    rebuilt("t1.laz", b, table, b, len);
    memcpy(m, b, len);
    p32(m + off, (uint32_t)len + 100);
    rebuilt("past.laz", m, len, b, len);
    memcpy(m, b, len);
    p32(m + off, off);
    rebuilt("self.laz", m, len, b, len);
    memcpy(m, b, len);
    memset(m + table, 0x5a, len - table);
    rebuilt("garbage.laz", m, len, b, len);
    /* the table gone and the chunk cut, or the file cut before the
     * table's offset: both reasons */
    refused("t2.laz", b, off + 4, "chunk table");
    refused("cut.laz", b, off + 8 + 500, "rebuilding it from the chunks failed: chunk 0");
    memcpy(m, b, len);
    p32(m + off, (uint32_t)len + 100);
    for (size_t k = off + 8 + 40; k < off + 8 + 140; k++)
        m[k] ^= 0x5a;
    refused("past_corrupt.laz", m, len, "past the end");
    /* more points than the chunk holds: the stream runs out */
    memcpy(m, b, len);
    p32(m + 107, 1066);
    refused("more.laz", m, len, "point 1065");
    memcpy(m, b, len);
    p32(m + 107, 1064); /* fewer: the table's chunk holds more than the header */
    refused("fewer.laz", m, len, "chunk 0");
    /* unknown compressor, coder, item version */
    memcpy(m, b, len);
    p16(m + q, 7);
    refused("comp.laz", m, len, "compressor 7");
    memcpy(m, b, len);
    p16(m + q + 2, 1);
    refused("coder.laz", m, len, "coder 1");
    memcpy(m, b, len);
    p16(m + q + 38, 1); /* POINT10 version 1 */
    refused("ver.laz", m, len, "POINT10 version 1");
    memcpy(m, b, len);
    p16(m + q + 34, 9); /* an item that is not the format's */
    refused("item.laz", m, len, "item 0");
    /* a corrupt arithmetic-coded stream: bytes of the chunk changed */
    memcpy(m, b, len);
    for (size_t k = off + 8 + 40; k < off + 8 + 140; k++)
        m[k] ^= 0x5a;
    refused("corrupt.laz", m, len, "chunk 0");
    /* a compression bit without the laszip VLR */
    memcpy(m, b, len);
    m[q - 54 + 2] = 'X';
    refused("novlr.laz", m, len, "laszip VLR");
    free(m);
    free(b);
}
END_TEST

/* The layered format: a chunk cut, a layer corrupt, a waveform format. */
START_TEST(damaged_v3)
{
    size_t len;
    unsigned char *b = slurp(DATA "simple.copc.laz", &len);
    unsigned char *m = malloc(len);
    uint32_t off = g32(b + 96);
    /* the first chunk's count (after its raw 36-byte point) */
    memcpy(m, b, len);
    p32(m + off + 8 + 36, 5000);
    refused("count.laz", m, len, "chunk 0");
    /* a layer's size past the chunk */
    memcpy(m, b, len);
    p32(m + off + 8 + 40, 1u << 30);
    refused("layer.laz", m, len, "run past the chunk");
    /* corrupt bytes in the first chunk's layers */
    memcpy(m, b, len);
    for (size_t k = off + 8 + 40 + 44 + 10; k < off + 8 + 40 + 44 + 60; k++)
        m[k] ^= 0xa5;
    refused("corrupt.laz", m, len, "chunk 0");
    /* variable-size layered chunks without their table (offset -1, the
     * file's last 8 bytes no table either): rebuilt from the chunks'
     * own counts and layer sizes */
    memcpy(m, b, len);
    for (int k = 0; k < 8; k++)
        m[off + k] = 0xff;
    rebuilt("minus1.laz", m, len, b, len);
    /* ... but not when a chunk's layer sizes then run past the file */
    p32(m + off + 8 + 40, 1u << 30);
    refused("minus1_layer.laz", m, len, "rebuilding it from the chunks failed: chunk 0");
    /* the point format of a waveform file */
    memcpy(m, b, len);
    m[104] = 0x80 | 10;
    p16(m + 105, 67);
    refused("wave.laz", m, len, "waveform");
    free(m);
    free(b);
}
END_TEST

/* Every prefix of a LAZ file is refused with one line (never a crash:
 * ASan and valgrind run this suite). */
START_TEST(every_prefix)
{
    size_t len;
    unsigned char *b = slurp(DATA "simple.copc.laz", &len);
    for (size_t k = 0; k < len; k += k < 1800 ? 97 : 1301) {
        char nm[32];
        snprintf(nm, sizeof nm, "p%zu.laz", k);
        const char *p = fixture(nm, b, k);
        jf_cloud c;
        jf_error e;
        ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) != JF_OK, "prefix %zu read", k);
        ck_assert_ptr_null(strchr(e.msg, '\n'));
    }
    free(b);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("io_laz");
    TCase *tc = tcase_create("laz");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, twins_v2);
    tcase_add_test(tc, twin_v3_evlr);
    tcase_add_test(tc, by_bit_and_threads);
    tcase_add_test(tc, damaged_v3);
    tcase_add_test(tc, damaged);
    tcase_add_test(tc, every_prefix);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    return jf_test_run(suite());
}
