/*
 * io_laz_write.c -- LAS records to LAZ: the writer's back end for
 * `-o out.laz` (the records are the LAS writer's, io_las_write.c).
 *
 * design (the LASzip format, as io_laz.c reads it): the records are cut
 * into chunks of a fixed size (50,000 points, fewer for long records),
 * each compressed on its own -- formats 0-3 by the pointwise version 2
 * items (laz_v2_enc.c, compressor 2), formats 6-8 by the layered version
 * 3 items (laz_v3_enc.c, compressor 3), extra bytes as BYTE / BYTE14 --
 * as many chunks at once as there are threads, written in order.  After
 * the last chunk: the chunk table (version 0, the count, every chunk's
 * byte size arithmetic coded as a difference from the previous one).  At
 * commit the LAS prefix goes at offset 0 with bit 7 of the format byte
 * set, one more VLR (the laszip VLR: compressor, coder 0, chunk size, the
 * items and their versions) and the table's offset in the 8 bytes before
 * the first chunk; EVLRs follow the table.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <omp.h>

#include "io_internal.h"
#include "laz_enc.h"
#include "laz_internal.h"

#define LZW_CHUNK 50000u
#define LZW_CHUNK_BYTES ((size_t)1 << 28) /* a chunk's records at most */

struct jf_lazw {
    unsigned fmt, rec_len, nitems, compressor, nbuf;
    uint32_t chunk;           /* points a chunk                       */
    lz_item items[6];
    size_t prefix;            /* the LAS prefix's bytes               */
    uint8_t *buf;             /* nbuf chunks of records               */
    size_t have;              /* records in buf                       */
    uint32_t *sizes;          /* every chunk's compressed bytes       */
    size_t nchunks, cap;
    uint64_t pos;             /* file offset of the next chunk        */
    uint64_t table;           /* the chunk table's offset (finished)  */
    uint64_t end;             /* the end of the table                 */
    lz_enc *out;              /* nbuf chunk encoders' outputs         */
};

static void p16(uint8_t *p, unsigned v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static void p32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (uint8_t)(v >> (8 * k));
}
static void p64(uint8_t *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (uint8_t)(v >> (8 * k));
}
static uint64_t g64(const uint8_t *p)
{
    uint64_t v = 0;
    for (int k = 7; k >= 0; k--) v = v << 8 | p[k];
    return v;
}

jf_lazw *jf__lazw_open(unsigned fmt, unsigned rec_len, size_t prefix, char *why, size_t whylen)
{
    static const unsigned base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
    if (fmt > 10 || fmt == 4 || fmt == 5 || fmt >= 9) {
        snprintf(why, whylen, "point format %u (waveform packets) is not written as LAZ: "
                 "formats 0-3 and 6-8 are (write .las)", fmt);
        return NULL;
    }
    if (rec_len < base[fmt]) {
        snprintf(why, whylen, "point format %u with %u-byte records", fmt, rec_len);
        return NULL;
    }
    jf_lazw *z = calloc(1, sizeof *z);
    if (!z) {
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    z->fmt = fmt, z->rec_len = rec_len, z->prefix = prefix;
    unsigned n = 0;
    if (fmt < 6) { /* pointwise, version 2 */
        z->compressor = 2;
        z->items[n++] = (lz_item){LZ_POINT10, 20, 2};
        if (fmt == 1 || fmt == 3)
            z->items[n++] = (lz_item){LZ_GPSTIME11, 8, 2};
        if (fmt == 2 || fmt == 3)
            z->items[n++] = (lz_item){LZ_RGB12, 6, 2};
        if (rec_len > base[fmt])
            z->items[n++] = (lz_item){LZ_BYTE, rec_len - base[fmt], 2};
    } else { /* layered, version 3 */
        z->compressor = 3;
        z->items[n++] = (lz_item){LZ_POINT14, 30, 3};
        if (fmt == 7)
            z->items[n++] = (lz_item){LZ_RGB14, 6, 3};
        if (fmt == 8)
            z->items[n++] = (lz_item){LZ_RGBNIR14, 8, 3};
        if (rec_len > base[fmt])
            z->items[n++] = (lz_item){LZ_BYTE14, rec_len - base[fmt], 3};
    }
    z->nitems = n;
    z->chunk = LZW_CHUNK;
    if ((size_t)z->chunk * rec_len > LZW_CHUNK_BYTES) /* long records: smaller chunks */
        z->chunk = (uint32_t)(LZW_CHUNK_BYTES / rec_len);
    /* a chunk per thread at once, within 64 MB of records */
    size_t nt = (size_t)omp_get_max_threads(), fit = ((size_t)64 << 20) / ((size_t)z->chunk * rec_len);
    nt = nt < fit ? nt : fit;
    z->nbuf = nt > 1 ? (unsigned)(nt < 64 ? nt : 64) : 1;
    z->buf = malloc((size_t)z->nbuf * z->chunk * rec_len);
    z->out = calloc(z->nbuf, sizeof *z->out);
    z->pos = prefix + jf__lazw_extra(z);
    if (!z->buf || !z->out) {
        jf__lazw_free(z);
        snprintf(why, whylen, "out of memory");
        return NULL;
    }
    return z;
}

size_t jf__lazw_extra(const jf_lazw *z) { return 54 + 34 + 6 * (size_t)z->nitems + 8; }

void jf__lazw_free(jf_lazw *z)
{
    if (!z)
        return;
    for (unsigned k = 0; z->out && k < z->nbuf; k++)
        lz_enc_free(&z->out[k]);
    free(z->out);
    free(z->buf);
    free(z->sizes);
    free(z);
}

/* Compresses the records in buf (whole chunks but the last) and writes
 * them: the chunks in parallel, then in order. */
static jf_status flush(jf_lazw *z, jf_wfile *f)
{
    size_t nc = (z->have + z->chunk - 1) / z->chunk;
    if (!nc)
        return f->st;
    if (z->nchunks + nc > z->cap) {
        size_t cap = z->cap ? 2 * z->cap : 64;
        while (cap < z->nchunks + nc)
            cap *= 2;
        uint32_t *s = realloc(z->sizes, cap * sizeof *s);
        if (!s)
            return jf_wf_fail(f, JF_ERR_NOMEM, "out of memory for the LAZ chunk table");
        z->sizes = s, z->cap = cap;
    }
    int bad = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nc < z->nbuf ? (int)nc : (int)z->nbuf)
    for (size_t k = 0; k < nc; k++) {
        size_t first = k * z->chunk;
        uint32_t cnt = (uint32_t)(z->have - first < z->chunk ? z->have - first : z->chunk);
        lz_enc *o = &z->out[k];
        o->len = 0, o->nomem = 0;
        const uint8_t *r = z->buf + first * z->rec_len;
        int rc = z->compressor == 3
                     ? jf__laz_v3_encode(z->items, z->nitems, z->rec_len, r, cnt, o)
                     : jf__laz_v2_encode(z->items, z->nitems, z->rec_len, r, cnt, o);
        if (rc || o->len > UINT32_MAX) {
#pragma omp atomic write
            bad = 1;
        }
    }
    if (bad)
        return jf_wf_fail(f, JF_ERR_NOMEM, "out of memory compressing LAZ chunk %zu", z->nchunks);
    for (size_t k = 0; k < nc && f->st == JF_OK; k++) {
        jf_wf_write(f, (const char *)z->out[k].buf, z->out[k].len);
        z->sizes[z->nchunks++] = (uint32_t)z->out[k].len;
        z->pos += z->out[k].len;
    }
    z->have = 0;
    return f->st;
}

jf_status jf__lazw_add(jf_lazw *z, const char *recs, size_t n, jf_wfile *f)
{
    size_t room = (size_t)z->nbuf * z->chunk;
    while (n && f->st == JF_OK) {
        size_t k = room - z->have < n ? room - z->have : n;
        memcpy(z->buf + z->have * z->rec_len, recs, k * z->rec_len);
        z->have += k, recs += k * z->rec_len, n -= k;
        if (z->have == room)
            flush(z, f);
    }
    return f->st;
}

jf_status jf__lazw_finish(jf_lazw *z, jf_wfile *f)
{
    if (flush(z, f) != JF_OK)
        return f->st;
    /* the chunk table: version, count, then the sizes coded (LASzip's
     * integer compressor, 32 bits, context 1 for the byte counts) */
    lz_arena a = {0};
    lz_ic ic;
    lz_enc e;
    lz_enc_init(&e, &a);
    uint8_t head[8];
    p32(head, 0);
    p32(head + 4, (uint32_t)z->nchunks);
    lz_put_bytes(&e, head, 8);
    if (!lz_ic_init(&ic, &a, 32, 2, 8, 0))
        e.nomem = 1;
    /* the coder's bytes start after the 8 raw ones: encode into a second
     * encoder so its carries cannot reach them */
    lz_enc t;
    lz_enc_init(&t, &a);
    uint32_t prev = 0;
    for (size_t k = 0; k < z->nchunks && !e.nomem; k++) {
        lz_ic_encode(&t, &ic, (int32_t)prev, (int32_t)z->sizes[k], 1);
        prev = z->sizes[k];
    }
    lz_enc_done(&t);
    lz_put_bytes(&e, t.buf, t.len);
    if (e.nomem || t.nomem || a.failed) {
        jf_wf_fail(f, JF_ERR_NOMEM, "out of memory for the LAZ chunk table");
    } else {
        z->table = z->pos;
        jf_wf_write(f, (const char *)e.buf, e.len);
        z->end = z->pos + e.len;
    }
    lz_enc_free(&t);
    lz_enc_free(&e);
    lz_arena_free(&a);
    return f->st;
}

int jf__lazw_write_prefix(int fd, const jf_las_out *L, const jf_lazw *z)
{
    size_t len;
    uint8_t *b = jf__las_prefix(L, &len);
    size_t extra = jf__lazw_extra(z), total = len + extra;
    uint8_t *o = b ? realloc(b, total) : NULL;
    if (!o) {
        free(b);
        return -1;
    }
    b = o;
    /* EVLRs (and internal waveform data among them) follow the table */
    uint64_t evlr = g64(b + 235), old = len + (uint64_t)L->nrows * z->rec_len;
    if (evlr) {
        uint64_t wave = g64(b + 227);
        p64(b + 235, z->end);
        if (wave >= old)
            p64(b + 227, wave - old + z->end);
    }
    b[104] = (uint8_t)(z->fmt | 0x80); /* bit 7: compressed (LASzip) */
    p32(b + 96, (uint32_t)(len + extra - 8));
    uint32_t nvlr = (uint32_t)b[100] | (uint32_t)b[101] << 8 | (uint32_t)b[102] << 16 |
                    (uint32_t)b[103] << 24;
    p32(b + 100, nvlr + 1);
    uint8_t *v = b + len;
    memset(v, 0, extra);
    memcpy(v + 2, "laszip encoded", 14);
    p16(v + 18, 22204);
    p16(v + 20, 34 + 6 * z->nitems);
    snprintf((char *)v + 22, 32, "jetfit " JF_VERSION_STRING);
    uint8_t *q = v + 54;
    p16(q, z->compressor);
    p16(q + 2, 0);  /* coder: arithmetic */
    q[4] = 3, q[5] = 4; /* the LASzip version whose format this is */
    p16(q + 6, 3);
    p32(q + 8, 0);  /* options */
    p32(q + 12, z->chunk);
    p64(q + 16, UINT64_MAX); /* no special EVLRs (-1, -1) */
    p64(q + 24, UINT64_MAX);
    p16(q + 32, z->nitems);
    for (unsigned i = 0; i < z->nitems; i++) {
        p16(q + 34 + 6 * i, z->items[i].type);
        p16(q + 36 + 6 * i, z->items[i].size);
        p16(q + 38 + 6 * i, z->items[i].version);
    }
    p64(b + total - 8, z->table);
    int e = jf__pwrite_all(fd, b, total, 0);
    free(b);
    return e ? -1 : 0;
}
