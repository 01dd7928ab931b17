/* test_io_attrs.c -- attributes carried through (issue 13.2, 13.4): a PLY
 * of every property type (uchar colour, float intensity, ...) read into
 * jf_cloud.attrs in its types, written to PLY (binary and ascii), CSV and
 * LAS with jf_writer_attrs and read back bit for bit; CSV columns packed
 * in their smallest exact type; the in_ rename; LAS files of every point
 * format 0-10 written here (with a CRS VLR, Extra Bytes of their own,
 * undescribed bytes, an EVLR) written back with every record byte, VLR
 * and EVLR kept and jetfit's columns appended as named Extra Bytes. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"

#include "test_io_util.h"
#include "test_las_bytes.h"
#include "jf_test.h"

static void setup(void) { tmpdir_setup("/tmp/jf_io_attrs_XXXXXX"); }

static char *path_of(const char *name)
{
    static char p[4][256];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", tmpdir, name);
    return p[k];
}

/* Writes a table of x y z [+ extra double columns] with c's attributes. */
static void write_table(const char *path, const jf_cloud *c, int ascii, size_t nextra,
                        const char *const *extra)
{
    jf_column cols[8] = {{"x", JF_COL_F64}, {"y", JF_COL_F64}, {"z", JF_COL_F64}};
    for (size_t j = 0; j < nextra; j++) cols[3 + j] = (jf_column){extra[j], JF_COL_F64};
    jf_writer *w;
    jf_error e;
    ck_assert_msg(jf_writer_open(path, cols, 3 + nextra, c->n, ascii, &w, &e) == JF_OK, "%s",
                  e.msg);
    ck_assert_int_eq(jf_writer_las_frame(w, c->xyz, c->n), JF_OK);
    ck_assert_int_eq(jf_writer_attrs(w, &c->attrs), JF_OK);
    for (size_t i = 0; i < c->n; i++) {
        double v[8];
        memcpy(v, c->xyz + 3 * i, 3 * sizeof *v);
        for (size_t j = 0; j < nextra; j++) v[3 + j] = 0.25 * (double)i - (double)j;
        ck_assert_int_eq(jf_writer_row(w, v), JF_OK);
    }
    ck_assert_msg(jf_writer_commit(w, &e) == JF_OK, "%s", e.msg);
}

/* ---- PLY of every type --------------------------------------------------- */

#define NP 9

static void put_le(FILE *f, const void *v, size_t n, int big)
{
    const unsigned char *b = v;
    for (size_t k = 0; k < n; k++) fputc(b[big ? n - 1 - k : k], f);
}

/* x y z double, red green blue uchar, intensity float, c char, s short,
 * us ushort, i int, u uint, d double, nx float (a clash: in_nx).  fmt 0
 * ascii, 1 binary LE, 2 binary BE. */
static void write_typed_ply(const char *path, int fmt)
{
    static const char *const f[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    FILE *o = fopen(path, "wb");
    fprintf(o, "ply\nformat %s 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
               "property double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
               "property float intensity\nproperty char c\nproperty short s\n"
               "property ushort us\nproperty int i\nproperty uint u\nproperty double d\n"
               "property float nx\nelement face 0\nproperty list uchar int vertex_indices\n"
               "end_header\n", f[fmt], NP);
    for (int k = 0; k < NP; k++) {
        double x = 1e6 + 0.1 * k, y = -2e6 + 0.37 * k * k, z = 0.003 * k, d = 1.0 / (k + 3);
        unsigned char rgb[3] = {(unsigned char)(255 - k), (unsigned char)(17 * k), 0};
        float in = 0.1f * (float)k - 0.35f, nx = -1.0f / (float)(k + 1);
        int8_t c = (int8_t)(-128 + 31 * k);
        int16_t s = (int16_t)(-32768 + 8000 * k);
        uint16_t us = (uint16_t)(65535 - 7 * k);
        int32_t i = (int32_t)(-2147483647LL + 500000000LL * k);
        uint32_t u = 4294967295u - 12345u * (uint32_t)k;
        if (fmt == 0) {
            fprintf(o, "%.17g %.17g %.17g %d %d %d %.9g %d %d %d %d %u %.17g %.9g\n", x, y, z,
                    rgb[0], rgb[1], rgb[2], (double)in, c, s, us, i, u, d, (double)nx);
            continue;
        }
        int big = fmt == 2;
        put_le(o, &x, 8, big), put_le(o, &y, 8, big), put_le(o, &z, 8, big);
        fwrite(rgb, 1, 3, o);
        put_le(o, &in, 4, big), put_le(o, &c, 1, big), put_le(o, &s, 2, big);
        put_le(o, &us, 2, big), put_le(o, &i, 4, big), put_le(o, &u, 4, big);
        put_le(o, &d, 8, big), put_le(o, &nx, 4, big);
    }
    fclose(o);
}

static const char *const ply_names[] = {"red", "green", "blue", "intensity", "c", "s",
                                        "us", "i", "u", "d", "nx"};
static const jf_attr_type ply_types[] = {JF_ATTR_U8,  JF_ATTR_U8,  JF_ATTR_U8,  JF_ATTR_F32,
                                         JF_ATTR_I8,  JF_ATTR_I16, JF_ATTR_U16, JF_ATTR_I32,
                                         JF_ATTR_U32, JF_ATTR_F64, JF_ATTR_F32};

/* Same values, bit for bit (as doubles: every type is exact in one). */
static void same_attrs(const jf_cloud *a, const jf_cloud *b, const char *what, int types)
{
    ck_assert_uint_eq(a->n, b->n);
    for (size_t j = 0; j < a->attrs.nattrs; j++) {
        int k = jf_attr_find(&b->attrs, a->attrs.attr[j].name);
        ck_assert_msg(k >= 0, "%s: %s missing", what, a->attrs.attr[j].name);
        if (types)
            ck_assert_msg(b->attrs.attr[k].type == a->attrs.attr[j].type, "%s: %s type %d vs %d",
                          what, a->attrs.attr[j].name, b->attrs.attr[k].type,
                          a->attrs.attr[j].type);
        for (size_t i = 0; i < a->n; i++) {
            double x = jf_attr_get(&a->attrs, j, i), y = jf_attr_get(&b->attrs, (size_t)k, i);
            ck_assert_msg(!memcmp(&x, &y, 8), "%s: %s row %zu: %.17g vs %.17g", what,
                          a->attrs.attr[j].name, i, x, y);
        }
    }
    for (size_t i = 0; i < 3 * a->n; i++) ck_assert(a->xyz[i] == b->xyz[i]);
}

START_TEST(ply_every_type)
{
    jf_cloud c[3];
    jf_error e;
    for (int fmt = 0; fmt < 3; fmt++) {
        char nm[16];
        snprintf(nm, sizeof nm, "t%d.ply", fmt);
        write_typed_ply(path_of(nm), fmt);
        ck_assert_msg(jf_cloud_read(path_of(nm), NULL, &c[fmt], &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(c[fmt].attrs.nattrs, 11);
        for (size_t j = 0; j < 11; j++) {
            ck_assert_str_eq(c[fmt].attrs.attr[j].name, ply_names[j]);
            ck_assert_int_eq(c[fmt].attrs.attr[j].type, ply_types[j]);
        }
        /* 3 + 4 + 1 + 2 + 2 + 4 + 4 + 8 + 4 bytes a point, not 11 doubles */
        ck_assert_uint_eq(c[fmt].attrs.stride, 32);
    }
    /* the values as written */
    for (size_t k = 0; k < NP; k++) {
        ck_assert(jf_attr_get(&c[1].attrs, 0, k) == 255.0 - (double)k);
        ck_assert(jf_attr_get(&c[1].attrs, 3, k) == (double)(0.1f * (float)k - 0.35f));
        ck_assert(jf_attr_get(&c[1].attrs, 4, k) == -128.0 + 31.0 * (double)k);
        ck_assert(jf_attr_get(&c[1].attrs, 7, k) == -2147483647.0 + 5e8 * (double)k);
        ck_assert(jf_attr_get(&c[1].attrs, 8, k) == 4294967295.0 - 12345.0 * (double)k);
    }
    same_attrs(&c[1], &c[0], "ascii vs LE", 1);
    same_attrs(&c[1], &c[2], "BE vs LE", 1);
    /* out and back: PLY keeps the types; CSV and LAS the values */
    static const char *const outs[] = {"o.ply", "oa.ply", "o.csv", "o.las"};
    for (size_t q = 0; q < 4; q++) {
        write_table(path_of(outs[q]), &c[1], q == 1, 0, NULL);
        jf_cloud r;
        ck_assert_msg(jf_cloud_read(path_of(outs[q]), NULL, &r, &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(r.attrs.nattrs, strstr(outs[q], ".las") ? 11 + 12 : 11);
        if (strstr(outs[q], ".las")) {
            /* format 0 with the attributes as Extra Bytes of their type;
             * x y z quantized to the frame, so compare values only */
            for (size_t j = 0; j < 11; j++) {
                /* a name of a format 0 dimension gets in_ */
                char nm[64];
                snprintf(nm, sizeof nm, "%s%s", j == 3 ? "in_" : "", ply_names[j]);
                int k = jf_attr_find(&r.attrs, nm);
                ck_assert_int_ge(k, 0);
                ck_assert_int_eq(r.attrs.attr[k].type, ply_types[j]);
                for (size_t i = 0; i < NP; i++) {
                    double x = jf_attr_get(&c[1].attrs, j, i), y = jf_attr_get(&r.attrs, (size_t)k, i);
                    ck_assert(!memcmp(&x, &y, 8));
                }
            }
        } else {
            same_attrs(&c[1], &r, outs[q], strstr(outs[q], ".ply") != NULL);
        }
        jf_cloud_free(&r);
    }
    for (int fmt = 0; fmt < 3; fmt++) jf_cloud_free(&c[fmt]);
}
END_TEST

/* ---- CSV: header-named columns ------------------------------------------- */

START_TEST(csv_columns)
{
    const char *txt = "id,Y,X,label,w,word,Z,neg,empty\n"
                      "0,1.5,2,300,0.1,a,3,-1,\n"
                      "1,2.5,3,301,0.2,b,4,-70000,\n"
                      "2,3.5,4,65535,-0,c,5,0,7\n";
    const char *p = fixture("in.csv", txt, strlen(txt));
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "%s", e.msg);
    ck_assert_uint_eq(c.n, 3);
    ck_assert(c.xyz[0] == 2 && c.xyz[1] == 1.5 && c.xyz[2] == 3);
    /* word (letters) is not carried; empty fields are NaN */
    static const char *const names[] = {"id", "label", "w", "neg", "empty"};
    static const jf_attr_type types[] = {JF_ATTR_U8, JF_ATTR_U16, JF_ATTR_F64, JF_ATTR_I32,
                                         JF_ATTR_F64};
    ck_assert_uint_eq(c.attrs.nattrs, 5);
    for (size_t j = 0; j < 5; j++) {
        ck_assert_str_eq(c.attrs.attr[j].name, names[j]);
        ck_assert_int_eq(c.attrs.attr[j].type, types[j]);
    }
    ck_assert(jf_attr_get(&c.attrs, 1, 2) == 65535);
    ck_assert(jf_attr_get(&c.attrs, 3, 1) == -70000);
    double z = jf_attr_get(&c.attrs, 2, 2);
    ck_assert(z == 0 && signbit(z)); /* -0 kept: a double column */
    ck_assert(isnan(jf_attr_get(&c.attrs, 4, 0)) && jf_attr_get(&c.attrs, 4, 2) == 7);
    /* headerless: nothing carried; no_attrs: nothing read */
    const char *q = fixture("plain.xyz", "1 2 3 4\n5 6 7 8\n", 16);
    jf_cloud d;
    ck_assert_int_eq(jf_cloud_read(q, NULL, &d, &e), JF_OK);
    ck_assert_uint_eq(d.attrs.nattrs, 0);
    ck_assert_ptr_null(d.attrs.rec);
    jf_cloud_free(&d);
    jf_read_opts o;
    jf_read_opts_init(&o);
    o.no_attrs = 1;
    ck_assert_int_eq(jf_cloud_read(p, &o, &d, &e), JF_OK);
    ck_assert_uint_eq(d.attrs.nattrs, 0);
    jf_cloud_free(&d);
    /* out to CSV, PLY and back: same types and bits */
    static const char *const outs[] = {"o.csv", "o.ply"};
    for (size_t k = 0; k < 2; k++) {
        write_table(path_of(outs[k]), &c, 0, 0, NULL);
        jf_cloud r;
        ck_assert_msg(jf_cloud_read(path_of(outs[k]), NULL, &r, &e) == JF_OK, "%s", e.msg);
        same_attrs(&c, &r, outs[k], 1);
        jf_cloud_free(&r);
    }
    jf_cloud_free(&c);
}
END_TEST

/* ---- the in_ rename ------------------------------------------------------- */

START_TEST(rename_clash)
{
    const char *txt = "x,y,z,nx,in_nx,k1,q\n1,2,3,4,5,6,7\n2,3,4,5,6,7,8\n";
    const char *p = fixture("r.csv", txt, strlen(txt));
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, &e), JF_OK);
    ck_assert_ptr_null(c.nrm); /* nx alone: no normals */
    static const char *const extra[] = {"nx", "k1"};
    write_table(path_of("o.csv"), &c, 0, 2, extra);
    size_t len;
    unsigned char *b = jf_test_slurp(path_of("o.csv"), &len);
    const char *head = "x,y,z,in_nx,in_in_nx,in_k1,q,nx,k1\n1,2,3,4,5,6,7,0,-1\n";
    ck_assert_msg(len > strlen(head) && !memcmp(b, head, strlen(head)), "%.*s", (int)len, b);
    free(b);
    jf_cloud_free(&c);
}
END_TEST

/* ---- LAS: the input's records, VLRs and EVLRs kept ----------------------- */

/* A VLR: user, record id, payload. */
static unsigned char *vlr(unsigned char *p, const char *user, unsigned id, const void *data,
                          size_t len)
{
    memset(p, 0, 54);
    memcpy(p + 2, user, strlen(user));
    put16(p + 18, id);
    put16(p + 20, (unsigned)len);
    memcpy(p + 54, data, len);
    return p + 54 + len;
}

#define NL 40
#define GEOKEYS 40 /* bytes of the GeoKeyDirectory payload */
#define WKT "PROJCS[\"test\",GEOGCS[\"WGS 84\"]]"

/* A LAS file of NL points of format fmt: version 1.4 with an EVLR for
 * formats >= 6, else 1.2; a GeoKeyDirectory VLR and a WKT VLR; Extra
 * Bytes "amp" (float) and "nx" (double) then 3 undescribed bytes; every
 * other record byte pseudo-random, so every bit field takes many values. */
static size_t make_las(unsigned fmt, unsigned char **out)
{
    int v14 = fmt >= 6;
    unsigned hsize = v14 ? 375 : 227, rl = base_len[fmt] + 4 + 8 + 3;
    size_t vlrs = 54 + GEOKEYS + 54 + sizeof WKT + 54 + 2 * 192;
    size_t data = hsize + vlrs, evlr = v14 ? 60 + 25 : 0;
    size_t len = data + NL * rl + evlr;
    unsigned char *b = calloc(1, len);
    memcpy(b, "LASF", 4);
    put16(b + 4, 77);          /* file source ID */
    put16(b + 6, v14 ? 17 : 1); /* global encoding: GPS time type (+ WKT) */
    memcpy(b + 8, "0123456789abcdef", 16);
    b[24] = 1;
    b[25] = v14 ? 4 : 2;
    memcpy(b + 26, "TEST SCANNER", 12);
    memcpy(b + 58, "test writer", 11);
    put16(b + 90, 123), put16(b + 92, 2024);
    put16(b + 94, hsize);
    put32(b + 96, (uint32_t)data);
    put32(b + 100, 3);
    b[104] = (unsigned char)fmt;
    put16(b + 105, rl);
    put32(b + 107, v14 ? 0 : NL);
    put32(b + 111, v14 ? 0 : NL - 5), put32(b + 115, v14 ? 0 : 5);
    putd(b + 131, 0.001), putd(b + 139, 0.002), putd(b + 147, 0.01);
    putd(b + 155, 1e6), putd(b + 163, -2e6), putd(b + 171, 350);
    putd(b + 179, 1e6 + 40), putd(b + 187, 1e6), putd(b + 195, -2e6), putd(b + 203, -2e6 - 1);
    putd(b + 211, 400), putd(b + 219, 350);
    if (v14) {
        put64(b + 235, data + NL * rl);
        put32(b + 243, 1);
        put64(b + 247, NL);
        put64(b + 255, NL - 5), put64(b + 263, 5);
    }
    unsigned char *p = b + hsize, gk[GEOKEYS], eb[2 * 192] = {0};
    for (int k = 0; k < GEOKEYS; k++) gk[k] = (unsigned char)(k * 7 + 1);
    p = vlr(p, "LASF_Projection", 34735, gk, GEOKEYS);
    p = vlr(p, "LASF_Projection", 2112, WKT, sizeof WKT);
    eb[2] = 9;
    memcpy(eb + 4, "amp", 3);
    eb[192 + 2] = 10;
    memcpy(eb + 192 + 4, "nx", 2);
    p = vlr(p, "LASF_Spec", 4, eb, sizeof eb);
    uint32_t s = 12345u + fmt;
    for (size_t i = 0; i < NL; i++) {
        unsigned char *r = b + data + i * rl;
        for (unsigned k = 0; k < rl; k++) r[k] = (unsigned char)((s = s * 1103515245u + 12345u) >> 16);
        put32(r, (uint32_t)(int32_t)(1000 * (int)i - 7));
        put32(r + 4, (uint32_t)(int32_t)(-3 * (int)i));
        put32(r + 8, (uint32_t)(int32_t)(i * i));
        float amp = 0.5f * (float)i;
        uint32_t u;
        memcpy(&u, &amp, 4);
        put32(r + base_len[fmt], u);
        putd(r + base_len[fmt] + 4, -0.125 * (double)i);
    }
    if (v14) { /* one EVLR: 60-byte header, 25 bytes */
        unsigned char *q = b + data + NL * rl;
        memcpy(q + 2, "LASF_Projection", 15);
        put16(q + 18, 2112);
        put64(q + 20, 25);
        memcpy(q + 60, "an EVLR kept byte for byt", 25);
    }
    *out = b;
    return len;
}

START_TEST(las_records_kept)
{
    static const char *const extra[] = {"nx", "k1"};
    for (unsigned fmt = 0; fmt <= 10; fmt++) {
        unsigned char *in;
        size_t inlen = make_las(fmt, &in);
        const char *p = fixture("in.las", in, inlen);
        jf_cloud c;
        jf_error e;
        ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "format %u: %s", fmt, e.msg);
        /* the Extra Bytes are named attributes after the dimensions */
        int amp = jf_attr_find(&c.attrs, "amp"), nx = jf_attr_find(&c.attrs, "nx");
        ck_assert_int_ge(amp, 0);
        ck_assert_int_eq(nx, amp + 1);
        ck_assert_uint_eq(c.attrs.nattrs, (size_t)nx + 1);
        for (size_t i = 0; i < NL; i++) {
            ck_assert(jf_attr_get(&c.attrs, (size_t)amp, i) == 0.5 * (double)i);
            ck_assert(jf_attr_get(&c.attrs, (size_t)nx, i) == -0.125 * (double)i);
        }
        write_table(path_of("out.las"), &c, 0, 2, extra);
        size_t len;
        unsigned char *b = jf_test_slurp(path_of("out.las"), &len);
        unsigned hs = g16(in + 94), rl = g16(in + 105);
        uint32_t doff = g32(b + 96), idoff = g32(in + 96);
        ck_assert_int_eq(b[25], 4);
        ck_assert_int_eq(b[104], fmt);
        ck_assert_uint_eq(g16(b + 105), rl + 16); /* + nx k1 doubles */
        ck_assert(!memcmp(b + 4, in + 4, 4 + 16)); /* source ID, encoding, GUID */
        ck_assert(!memcmp(b + 26, in + 26, 32));  /* system identifier */
        ck_assert(!memcmp(b + 90, in + 90, 4));   /* creation date */
        ck_assert(!memcmp(b + 131, in + 131, 96)); /* scale, offset, bounds */
        ck_assert_uint_eq(g64(b + 247), NL);
        ck_assert_uint_eq(g32(b + 107), fmt < 6 ? NL : 0);
        ck_assert_uint_eq(g64(b + 255), NL - 5);
        ck_assert_uint_eq(g64(b + 263), 5);
        /* the two CRS VLRs copied, then one Extra Bytes VLR */
        ck_assert_uint_eq(g32(b + 100), 3);
        size_t crs = 54 + GEOKEYS + 54 + sizeof WKT;
        ck_assert(!memcmp(b + 375, in + hs, crs));
        const unsigned char *v = b + 375 + crs;
        ck_assert(!memcmp(v + 2, "LASF_Spec", 10) && g16(v + 18) == 4);
        ck_assert_uint_eq(g16(v + 20), 5 * 192);
        ck_assert_uint_eq(doff, 375 + crs + 54 + 5 * 192);
        const unsigned char *d = v + 54;
        ck_assert(d[2] == 9 && !strcmp((const char *)d + 4, "amp"));
        ck_assert(d[192 + 2] == 10 && !strcmp((const char *)d + 192 + 4, "in_nx"));
        ck_assert(d[384 + 2] == 0 && d[384 + 3] == 3); /* undocumented */
        ck_assert(d[576 + 2] == 10 && !strcmp((const char *)d + 576 + 4, "nx"));
        ck_assert(d[768 + 2] == 10 && !strcmp((const char *)d + 768 + 4, "k1"));
        /* every record byte, then the table's columns */
        for (size_t i = 0; i < NL; i++) {
            const unsigned char *r = b + doff + i * (rl + 16);
            ck_assert_msg(!memcmp(r, in + idoff + i * rl, rl), "format %u record %zu", fmt, i);
            double x;
            memcpy(&x, r + rl, 8);
            ck_assert(x == 0.25 * (double)i);
        }
        /* the EVLR after the records, where the header says */
        if (fmt >= 6) {
            ck_assert_uint_eq(g64(b + 235), doff + NL * (rl + 16));
            ck_assert_uint_eq(g32(b + 243), 1);
            ck_assert_uint_eq(len, g64(b + 235) + 85);
            ck_assert(!memcmp(b + g64(b + 235), in + g64(in + 235), 85));
        } else {
            ck_assert_uint_eq(len, doff + NL * (rl + 16));
        }
        /* read back: the same attributes under their output names */
        jf_cloud r;
        ck_assert_msg(jf_cloud_read(path_of("out.las"), NULL, &r, &e) == JF_OK, "%s", e.msg);
        ck_assert_uint_eq(r.attrs.nattrs, c.attrs.nattrs + 2);
        for (size_t i = 0; i < 3 * NL; i++) ck_assert(r.xyz[i] == c.xyz[i]);
        for (size_t j = 0; j < c.attrs.nattrs; j++)
            for (size_t i = 0; i < NL; i++) {
                double a = jf_attr_get(&c.attrs, j, i), q = jf_attr_get(&r.attrs, j, i);
                ck_assert(!memcmp(&a, &q, 8));
            }
        ck_assert_str_eq(r.attrs.attr[nx].name, "in_nx");
        ck_assert_int_eq(jf_attr_find(&r.attrs, "k1"), (int)c.attrs.nattrs + 1);
        jf_cloud_free(&r);
        /* and to a PLY: the dimensions decoded, in their types */
        write_table(path_of("out.ply"), &c, 0, 0, NULL);
        ck_assert_int_eq(jf_cloud_read(path_of("out.ply"), NULL, &r, &e), JF_OK);
        same_attrs(&c, &r, "las -> ply", 0);
        jf_cloud_free(&r);
        free(b);
        jf_cloud_free(&c);
        free(in);
    }
}
END_TEST

/* Extra Bytes with the scale and offset options (bits 3 and 4; the doubles
 * at bytes 112 and 136 of a description, LAS 1.4 R15 table 24): the value
 * is raw * scale + offset, written as a double to PLY and text, kept raw
 * with its description in a LAS output of the same records. */
START_TEST(las_eb_scale)
{
    unsigned char *in;
    size_t inlen = make_las(1, &in);
    unsigned char *d0 = in + 227 + 54 + GEOKEYS + 54 + sizeof WKT + 54, *d1 = d0 + 192;
    ck_assert(!memcmp(d0 + 4, "amp", 4) && !memcmp(d1 + 4, "nx", 3));
    d0[3] = 8 | 16, putd(d0 + 112, 2.0), putd(d0 + 136, -1.0); /* amp = 0.5 i -> i - 1 */
    d1[3] = 16, putd(d1 + 136, 10.0);                           /* nx = 10 - i/8 */
    jf_cloud c, r;
    jf_error e;
    ck_assert_msg(jf_cloud_read(fixture("in.las", in, inlen), NULL, &c, &e) == JF_OK, "%s", e.msg);
    int amp = jf_attr_find(&c.attrs, "amp"), nx = jf_attr_find(&c.attrs, "nx");
    ck_assert(amp >= 0 && nx == amp + 1);
    for (size_t i = 0; i < NL; i++) {
        ck_assert(jf_attr_get(&c.attrs, (size_t)amp, i) == (double)i - 1);
        ck_assert(jf_attr_get(&c.attrs, (size_t)nx, i) == 10 - 0.125 * (double)i);
    }
    /* PLY and CSV: the scaled values, a PLY as double properties */
    const char *outs[2] = {"out.ply", "out.csv"};
    for (int k = 0; k < 2; k++) {
        write_table(path_of(outs[k]), &c, 0, 0, NULL);
        ck_assert_msg(jf_cloud_read(path_of(outs[k]), NULL, &r, &e) == JF_OK, "%s", e.msg);
        same_attrs(&c, &r, outs[k], 0);
        if (k == 0)
            ck_assert(r.attrs.attr[jf_attr_find(&r.attrs, "amp")].type == JF_ATTR_F64 &&
                      r.attrs.attr[jf_attr_find(&r.attrs, "nx")].type == JF_ATTR_F64);
        jf_cloud_free(&r);
    }
    /* LAS: the records and the descriptions as they were; read back the same */
    write_table(path_of("out.las"), &c, 0, 0, NULL);
    size_t len;
    unsigned char *b = jf_test_slurp(path_of("out.las"), &len);
    const unsigned char *v = b + 375 + 54 + GEOKEYS + 54 + sizeof WKT, *o0 = v + 54;
    ck_assert(!memcmp(v + 2, "LASF_Spec", 10) && g16(v + 18) == 4);
    ck_assert(!memcmp(o0, d0, 192) && !memcmp(o0 + 192, d1, 192));
    for (size_t i = 0; i < NL; i++)
        ck_assert(!memcmp(b + g32(b + 96) + i * 43, in + g32(in + 96) + i * 43, 43));
    ck_assert_msg(jf_cloud_read(path_of("out.las"), NULL, &r, &e) == JF_OK, "%s", e.msg);
    same_attrs(&c, &r, "las -> las", 1);
    jf_cloud_free(&r);
    free(b);
    jf_cloud_free(&c);
    /* a scale of 0, a NaN offset: refused, naming the file and the description */
    putd(d0 + 112, 0.0);
    ck_assert_int_eq(jf_cloud_read(fixture("bad.las", in, inlen), NULL, &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, "bad.las") && strstr(e.msg, "description 0 (\"amp\"") &&
                      strstr(e.msg, "scale 0"), "%s", e.msg);
    putd(d0 + 112, 2.0), putd(d1 + 136, NAN);
    ck_assert_int_eq(jf_cloud_read(fixture("bad.las", in, inlen), NULL, &c, &e), JF_ERR_FORMAT);
    ck_assert_msg(strstr(e.msg, "description 1 (\"nx\"") && strstr(e.msg, "offset nan"), "%s",
                  e.msg);
    free(in);
}
END_TEST

/* The dimensions of a format 3 record, decoded against the spec's bits. */
START_TEST(las_dimensions)
{
    unsigned char *in;
    size_t inlen = make_las(3, &in);
    const char *p = fixture("d.las", in, inlen);
    jf_cloud c;
    jf_error e;
    ck_assert_int_eq(jf_cloud_read(p, NULL, &c, &e), JF_OK);
    uint32_t doff = g32(in + 96);
    unsigned rl = g16(in + 105);
    for (size_t i = 0; i < NL; i++) {
        const unsigned char *r = in + doff + i * rl;
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "intensity"), i) == g16(r + 12));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "return_number"), i) == (r[14] & 7));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "number_of_returns"), i) ==
                  ((r[14] >> 3) & 7));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "edge_of_flight_line"), i) ==
                  (r[14] >> 7));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "classification"), i) == (r[15] & 31));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "withheld"), i) == (r[15] >> 7));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "scan_angle_rank"), i) ==
                  (int8_t)r[16]);
        double t;
        memcpy(&t, r + 20, 8);
        double g = jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "gps_time"), i);
        ck_assert(!memcmp(&t, &g, 8));
        ck_assert(jf_attr_get(&c.attrs, (size_t)jf_attr_find(&c.attrs, "blue"), i) == g16(r + 32));
    }
    jf_cloud_free(&c);
    free(in);
}
END_TEST

/* A LAS 1.3 file whose header is only 227 bytes (the 1.3 waveform field
 * absent), internal-waveform bit set: kept without reading past it. */
START_TEST(las_13_short_header)
{
    /* no VLR: the point data right after the 227 bytes */
    unsigned rl0 = base_len[1];
    size_t inlen = 227 + NL * rl0;
    unsigned char *in = calloc(1, inlen);
    memcpy(in, "LASF", 4);
    in[6] = 2;
    in[24] = 1, in[25] = 3;
    put16(in + 94, 227);
    put32(in + 96, 227);
    in[104] = 1;
    put16(in + 105, rl0);
    put32(in + 107, NL);
    putd(in + 131, 0.01), putd(in + 139, 0.01), putd(in + 147, 0.01);
    for (size_t i = 0; i < NL * rl0; i++) in[227 + i] = (unsigned char)(i * 37 + 11);
    const char *p = fixture("s.las", in, inlen);
    jf_cloud c;
    jf_error e;
    ck_assert_msg(jf_cloud_read(p, NULL, &c, &e) == JF_OK, "%s", e.msg);
    ck_assert_ptr_null(c.attrs.las_evlr);
    write_table(path_of("s.out.las"), &c, 0, 0, NULL);
    size_t len;
    unsigned char *b = jf_test_slurp(path_of("s.out.las"), &len);
    unsigned rl = g16(in + 105);
    uint32_t doff = g32(b + 96), idoff = g32(in + 96);
    ck_assert_uint_eq(g16(b + 105), rl);
    ck_assert_uint_eq(g64(b + 227), 0);
    ck_assert_uint_eq(len, doff + NL * rl);
    ck_assert(!memcmp(b + doff, in + idoff, NL * rl));
    free(b);
    jf_cloud_free(&c);
    free(in);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("io_attrs");
    TCase *tc = tcase_create("attrs");
    tcase_set_timeout(tc, 60);
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, ply_every_type);
    tcase_add_test(tc, csv_columns);
    tcase_add_test(tc, rename_clash);
    tcase_add_test(tc, las_records_kept);
    tcase_add_test(tc, las_eb_scale);
    tcase_add_test(tc, las_dimensions);
    tcase_add_test(tc, las_13_short_header);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
