/*
 * io_laz.c -- LAZ (LASzip-compressed LAS) to LAS: the reader's front end.
 *
 * design: a LAZ file is a LAS file whose point format byte has bit 7 (and
 * for LAS 1.4 bit 6) set, whose VLRs hold the "laszip encoded" record
 * 22204 (compressor, coder, version, chunk size, the items that make a
 * point record), and whose point data is a series of chunks, each coded
 * independently; 8 bytes at the start of the point data give the offset of
 * the chunk table (every chunk's compressed size and, for variable chunks,
 * its point count; itself arithmetic coded; an offset of -1 means it is
 * in the file's last 8 bytes).  We check the VLR, read the table, decode
 * the chunks in parallel (each into its own records: the bytes do not
 * depend on the thread count) and hand back the plain LAS file those
 * records make: the header with the compression bits cleared, the VLRs
 * without LASzip's, the records, the EVLRs -- so io_las.c reads it as any
 * LAS, every attribute kept.  Every count and offset is checked against
 * the file before use; an error names the chunk (and the point in it).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_internal.h"
#include "laz_arith.h"
#include "laz_internal.h"

static uint16_t g16(const unsigned char *p) { return (uint16_t)(p[0] | p[1] << 8); }
static uint32_t g32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint64_t g64(const unsigned char *p) { return g32(p) | (uint64_t)g32(p + 4) << 32; }
static void p32(unsigned char *p, uint32_t v)
{
    for (int k = 0; k < 4; k++) p[k] = (unsigned char)(v >> (8 * k));
}
static void p64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; k++) p[k] = (unsigned char)(v >> (8 * k));
}

#define LZ_MAX_ITEMS 16
#define LZ_VARIABLE 0xFFFFFFFFu
/* How many record bytes a compressed byte can stand for at most: LASzip's
 * adaptive models never give a symbol more than about 1 - 2^-15 of the
 * interval, so a 20-byte point costs at least ~0.008 bit (some 20,000
 * record bytes a byte); 2^18 is a bound no real file reaches, and it keeps
 * a tiny lying file from asking for gigabytes. */
#define LZ_MAX_EXPANSION 18

typedef struct {
    unsigned compressor, nitems, rec_len;
    uint32_t chunk_size;
    lz_item items[LZ_MAX_ITEMS];
    size_t vlr_at, vlr_len; /* the laszip VLR, header included */
} lz_vlr;

typedef struct {
    uint64_t start, bytes; /* file offset and compressed size */
    uint32_t count;        /* points                           */
    uint64_t first;        /* index of its first point         */
} lz_chunk;

/* Base record length and item list a point format must have (LASzip:
 * 0-5 pointwise v2, 6-10 layered v3); extra bytes as one BYTE item. */
static const unsigned lz_base[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

static const char *item_name(unsigned t)
{
    static const char *const nm[15] = {"BYTE",     "SHORT",     "INT",       "LONG",
                                       "FLOAT",    "DOUBLE",    "POINT10",   "GPSTIME11",
                                       "RGB12",    "WAVEPACKET13", "POINT14", "RGB14",
                                       "RGBNIR14", "WAVEPACKET14", "BYTE14"};
    return t < 15 ? nm[t] : "unknown";
}

/* The items the format needs, in order (the extra bytes' item aside). */
static unsigned want_items(unsigned fmt, unsigned *t)
{
    static const unsigned lists[11][4] = {
        {LZ_POINT10},
        {LZ_POINT10, LZ_GPSTIME11},
        {LZ_POINT10, LZ_RGB12},
        {LZ_POINT10, LZ_GPSTIME11, LZ_RGB12},
        {LZ_POINT10, LZ_GPSTIME11, LZ_WAVEPACKET13},
        {LZ_POINT10, LZ_GPSTIME11, LZ_RGB12, LZ_WAVEPACKET13},
        {LZ_POINT14},
        {LZ_POINT14, LZ_RGB14},
        {LZ_POINT14, LZ_RGBNIR14},
        {LZ_POINT14, LZ_WAVEPACKET14},
        {LZ_POINT14, LZ_RGBNIR14, LZ_WAVEPACKET14}};
    static const unsigned cnt[11] = {1, 2, 2, 3, 3, 4, 1, 2, 2, 2, 3};
    memcpy(t, lists[fmt], sizeof lists[fmt]);
    return cnt[fmt];
}

/* The laszip VLR among the VLRs in [hsize, data_off), checked against the
 * point format and record length. */
static jf_status find_vlr(const unsigned char *b, size_t hsize, size_t data_off, uint32_t nvlr,
                          unsigned fmt, unsigned rec_len, const char *name, lz_vlr *z,
                          jf_error *err)
{
    size_t p = hsize;
    memset(z, 0, sizeof *z);
    for (uint32_t v = 0; v < nvlr && p + 54 <= data_off; v++) {
        size_t rl = g16(b + p + 20);
        if (rl > data_off - p - 54)
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "VLR %u at byte %zu: its %zu bytes run past the point data",
                              (unsigned)v, p, rl);
        if (!memcmp(b + p + 2, "laszip encoded\0", 15) && g16(b + p + 18) == 22204) {
            const unsigned char *q = b + p + 54;
            if (rl < 34 || rl != 34 + 6u * g16(q + 32))
                return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                  "laszip VLR at byte %zu: length %zu does not match its items",
                                  p, rl);
            z->compressor = g16(q);
            unsigned coder = g16(q + 2);
            z->chunk_size = g32(q + 12);
            z->nitems = g16(q + 32);
            z->vlr_at = p, z->vlr_len = 54 + rl;
            z->rec_len = rec_len;
            if (z->compressor < 1 || z->compressor > 3)
                return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                                  "laszip VLR: compressor %u (1 pointwise, 2 pointwise "
                                  "chunked, 3 layered chunked are read)", z->compressor);
            if (coder != 0)
                return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                                  "laszip VLR: coder %u (0, arithmetic, is read)", coder);
            if (!z->nitems || z->nitems > LZ_MAX_ITEMS)
                return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                  "laszip VLR: %u items (1 to %d)", z->nitems, LZ_MAX_ITEMS);
            if (z->chunk_size == 0)
                return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "laszip VLR: chunk size 0");
            unsigned sum = 0;
            for (unsigned i = 0; i < z->nitems; i++) {
                lz_item *it = &z->items[i];
                it->type = g16(q + 34 + 6 * i);
                it->size = g16(q + 36 + 6 * i);
                it->version = g16(q + 38 + 6 * i);
                sum += it->size;
            }
            /* the items must be the format's, then the extra bytes */
            unsigned want[4], nw = want_items(fmt, want);
            int layered = fmt >= 6, wave = fmt == 4 || fmt == 5 || fmt >= 9;
            if (wave)
                return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                                  "compressed point format %u (with waveform packets) is not "
                                  "decoded: formats 0-3 and 6-8 are", fmt);
            if (layered != (z->compressor == 3))
                return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                  "laszip VLR: compressor %u for point format %u (LASzip codes "
                                  "formats 6-10 layered, compressor 3, and 0-5 pointwise)",
                                  z->compressor, fmt);
            for (unsigned i = 0; i < z->nitems; i++) {
                const lz_item *it = &z->items[i];
                unsigned need = i < nw ? want[i] : layered ? LZ_BYTE14 : LZ_BYTE;
                unsigned size = i < nw ? (need == LZ_POINT10   ? 20
                                          : need == LZ_GPSTIME11 ? 8
                                          : need == LZ_RGB12     ? 6
                                          : need == LZ_POINT14   ? 30
                                          : need == LZ_RGB14     ? 6
                                                                 : 8)
                                       : rec_len - lz_base[fmt];
                unsigned ver = layered ? 3 : 2;
                if (it->type != need || it->size != size || i > nw)
                    return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                      "laszip VLR: item %u is %s of %u bytes, point format %u "
                                      "needs %s of %u bytes there", i, item_name(it->type),
                                      it->size, fmt, item_name(need), size);
                if (it->version != ver && !(layered && it->version == 4))
                    return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                                      "laszip VLR: item %s version %u (version %u is read)",
                                      item_name(it->type), it->version, ver);
            }
            if (z->nitems < nw || sum != rec_len)
                return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                                  "laszip VLR: the items make %u-byte records, the header "
                                  "says %u", sum, rec_len);
            return JF_OK;
        }
        p += 54 + rl;
    }
    return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                      "compressed point format but no laszip VLR (user \"laszip encoded\", "
                      "record 22204)");
}

/* The chunk table: chunk sizes (and counts) from the arithmetic-coded
 * table, checked to tile [first, table) and to hold the header's n
 * points. */
static jf_status read_table(const unsigned char *b, size_t len, uint64_t data_off, uint64_t n,
                            const lz_vlr *z, const char *name, lz_chunk **out, size_t *nout,
                            int *bad_table, jf_error *err)
{
    *out = NULL, *nout = 0;
    *bad_table = 1; /* the table itself unusable (not the header lying) */
    uint64_t first = data_off + 8;
    if (z->compressor == 1) { /* pointwise, not chunked: one stream */
        lz_chunk *c = malloc(sizeof *c);
        if (!c)
            return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
        c->start = data_off, c->bytes = len - data_off, c->count = (uint32_t)n, c->first = 0;
        if (n * z->rec_len > c->bytes << LZ_MAX_EXPANSION) {
            free(c);
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "header: %llu points cannot be coded in the %llu bytes of point "
                              "data (count too large or file truncated)",
                              (unsigned long long)n, (unsigned long long)(len - data_off));
        }
        *out = c, *nout = 1;
        return JF_OK;
    }
    if (len < first)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "chunk table: the file ends before the point data's 8-byte "
                          "offset of the chunk table");
    uint64_t at = g64(b + data_off);
    if (at == UINT64_MAX && len >= 8) /* written to a stream: the offset is at the end */
        at = g64(b + len - 8);
    if (at == first - 8 || at < first || at > len - 8)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "chunk table: offset %llu is %s (the file is %zu bytes): the table "
                          "is missing or the file truncated", (unsigned long long)at,
                          at < first ? "before the chunks" : "past the end", len);
    uint32_t version = g32(b + at), nc = g32(b + at + 4);
    if (version != 0)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "chunk table at byte %llu: version %u (0 is read)",
                          (unsigned long long)at, version);
    /* each chunk holds at least one point and one byte */
    if (nc == 0 || nc > n || nc > at - first)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "chunk table at byte %llu: %u chunks for %llu points in %llu bytes",
                          (unsigned long long)at, nc, (unsigned long long)n,
                          (unsigned long long)(at - first));
    lz_chunk *c = calloc(nc, sizeof *c);
    if (!c)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %u chunks", nc);
    lz_arena a = {0};
    lz_ic ic;
    if (!lz_ic_init(&ic, &a, 32, 2, 8, 0)) {
        lz_arena_free(&a);
        free(c);
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    }
    lz_dec d;
    lz_dec_init(&d, b + at + 8, b + len);
    uint32_t pc = 0, pb = 0;
    uint64_t pos = first, total = 0;
    jf_status st = JF_OK;
    for (uint32_t i = 0; i < nc; i++) {
        if (z->chunk_size == LZ_VARIABLE) {
            pc = (uint32_t)lz_ic_decode(&d, &ic, (int32_t)pc, 0);
            c[i].count = pc;
        } else {
            c[i].count = n - total < z->chunk_size ? (uint32_t)(n - total) : z->chunk_size;
        }
        pb = (uint32_t)lz_ic_decode(&d, &ic, (int32_t)pb, 1);
        c[i].start = pos, c[i].bytes = pb, c[i].first = total;
        if (d.over > 4 || d.bad) {
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                            "chunk table at byte %llu: the table is cut short at chunk %u",
                            (unsigned long long)at, (unsigned)i);
            break;
        }
        if (c[i].count == 0 || c[i].count > n - total) {
            *bad_table = z->chunk_size == LZ_VARIABLE && !c[i].count;
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                            "chunk %u: %u points, more than the header's %llu leave "
                            "(or none)", (unsigned)i, c[i].count,
                            (unsigned long long)(n - total));
            break;
        }
        if (pb < z->rec_len || (uint64_t)c[i].count * z->rec_len > (uint64_t)pb << LZ_MAX_EXPANSION) {
            *bad_table = pb < z->rec_len;
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                            "chunk %u: %u points of %u bytes cannot be coded in its %u bytes "
                            "(a lying count or chunk table)", (unsigned)i, c[i].count,
                            z->rec_len, pb);
            break;
        }
        if (pb == 0 || pb > at - pos) {
            st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                            "chunk %u at byte %llu: %u bytes run past the chunk table at byte "
                            "%llu (truncated file or damaged table)", (unsigned)i,
                            (unsigned long long)pos, pb, (unsigned long long)at);
            break;
        }
        pos += pb;
        total += c[i].count;
    }
    lz_arena_free(&a);
    if (st == JF_OK && total != n) {
        *bad_table = 0;
        st = jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                        "chunk table: its %u chunks hold %llu points, the header says %llu",
                        nc, (unsigned long long)total, (unsigned long long)n);
    }
    if (st != JF_OK) {
        free(c);
        return st;
    }
    *out = c, *nout = nc;
    return JF_OK;
}

/* A missing or damaged chunk table rebuilt by walking the chunks from the
 * first (LASzip writes them back to back): a layered chunk (compressor 3)
 * says its point count and its layers' sizes, so its length is read off;
 * a pointwise chunk (2) of the fixed size is decoded to find where its
 * stream ends (the decoder stops where the encoder did).  Stops at the
 * header's point count; 0 and why filled when a chunk does not fit. */
static int scan_table(const unsigned char *b, size_t len, uint64_t data_off, uint64_t n,
                      const lz_vlr *z, lz_chunk **out, size_t *nout, char *why, size_t whylen)
{
    *out = NULL, *nout = 0;
    if (z->compressor == 2 && z->chunk_size == LZ_VARIABLE) {
        snprintf(why, whylen, "variable-size pointwise chunks cannot be found without it");
        return 0;
    }
    unsigned nl = 0; /* layers of a layered chunk */
    for (unsigned i = 0; i < z->nitems; i++)
        nl += z->items[i].type == LZ_POINT14 ? 9 : z->items[i].type == LZ_RGB14 ? 1
              : z->items[i].type == LZ_RGBNIR14 ? 2 : z->items[i].size;
    size_t cap = 0, nc = 0;
    lz_chunk *c = NULL;
    uint8_t *scratch = NULL;
    uint64_t pos = data_off + 8, total = 0;
    int ok = 1;
    while (ok && total < n) {
        uint32_t want = z->chunk_size == LZ_VARIABLE ? 0
                        : n - total < z->chunk_size ? (uint32_t)(n - total) : z->chunk_size;
        uint64_t bytes = 0;
        uint32_t cnt = want;
        char msg[160];
        if (pos > len) {
            snprintf(why, whylen, "the file ends before chunk %zu", nc);
            ok = 0;
        } else if (z->compressor == 3) {
            uint64_t head = (uint64_t)z->rec_len + 4 + 4 * (uint64_t)nl;
            if (len - pos < head) {
                snprintf(why, whylen, "chunk %zu at byte %llu: the file ends in its head", nc,
                         (unsigned long long)pos);
                ok = 0;
                break;
            }
            const unsigned char *q = b + pos + z->rec_len;
            cnt = g32(q);
            bytes = head;
            for (unsigned k = 0; k < nl; k++)
                bytes += g32(q + 4 + 4 * k);
            if (!cnt || cnt > n - total || (want && cnt != want) || bytes > len - pos ||
                (uint64_t)cnt * z->rec_len > bytes << LZ_MAX_EXPANSION) {
                snprintf(why, whylen, "chunk %zu at byte %llu: %u points in %llu bytes do not fit "
                         "the file", nc, (unsigned long long)pos, cnt, (unsigned long long)bytes);
                ok = 0;
                break;
            }
        } else {
            size_t used = 0;
            if ((uint64_t)want * z->rec_len > (uint64_t)(len - pos) << LZ_MAX_EXPANSION) {
                snprintf(why, whylen, "chunk %zu at byte %llu: %u points cannot be coded in the "
                         "%llu bytes left", nc, (unsigned long long)pos, want,
                         (unsigned long long)(len - pos));
                ok = 0;
                break;
            }
            /* the first chunk is the largest (fixed size) */
            if (!scratch && !(scratch = malloc((size_t)want * z->rec_len))) {
                snprintf(why, whylen, "out of memory");
                ok = 0;
                break;
            }
            if (jf__laz_v2_chunk_len(z->items, z->nitems, z->rec_len, b + pos, b + len, want,
                                     scratch, &used, msg, sizeof msg) != 0) {
                snprintf(why, whylen, "chunk %zu at byte %llu: %s", nc, (unsigned long long)pos,
                         msg);
                ok = 0;
                break;
            }
            bytes = used;
        }
        if (nc == cap) {
            cap = cap ? 2 * cap : 64;
            lz_chunk *t = realloc(c, cap * sizeof *c);
            if (!t) {
                snprintf(why, whylen, "out of memory");
                ok = 0;
                break;
            }
            c = t;
        }
        c[nc].start = pos, c[nc].bytes = bytes, c[nc].count = cnt, c[nc].first = total;
        nc++;
        pos += bytes;
        total += cnt;
    }
    free(scratch);
    if (!ok) {
        free(c);
        return 0;
    }
    *out = c, *nout = nc;
    return 1;
}

/* A LAZ file checked and indexed (jf__laz_open): the prefix of the plain
 * LAS file it stands for, its VLR and chunks, where its EVLRs are. */
struct jf_laz {
    const unsigned char *b; /* the caller's file image */
    size_t len;
    lz_vlr z;
    lz_chunk *ch;
    size_t nc;
    uint64_t n;
    unsigned char *head; /* header and VLRs without LASzip's, format cleared */
    size_t head_len;
    uint64_t evlr;       /* offset of the EVLRs in the file, 0 if none */
    size_t cached;       /* the chunk in cache (nc: none), for jf__laz_rows */
    uint8_t *cache;
    const char *name;
    char *owned;         /* the image, when L owns it */
};

void jf__laz_close(jf_laz *L)
{
    if (!L)
        return;
    free(L->ch);
    free(L->head);
    free(L->cache);
    free(L->owned);
    free(L);
}

jf_status jf__laz_open_owned(char *buf, size_t len, const char *name, jf_laz **L,
                             jf_error *err)
{
    jf_status st = jf__laz_open(buf, len, name, L, err);
    if (st != JF_OK)
        free(buf);
    else
        (*L)->owned = buf;
    return st;
}

jf_status jf__laz_open(const char *buf, size_t len, const char *name, jf_laz **out,
                       jf_error *err)
{
    const unsigned char *b = (const unsigned char *)buf;
    *out = NULL;
    if (len < 227)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: %zu bytes, a LAS header has at least 227", len);
    unsigned minor = b[25], hsize = g16(b + 94);
    uint32_t data_off = g32(b + 96), nvlr = g32(b + 100);
    unsigned fmt = b[104] & 0x3f, rec_len = g16(b + 105);
    uint64_t n = g32(b + 107);
    if (minor >= 4 && hsize >= 375 && len >= 375 && g64(b + 247))
        n = g64(b + 247);
    if (hsize < 227 || hsize > len || data_off < hsize || data_off > len)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                          "header: header size %u or offset to point data %u is outside the "
                          "file (%zu bytes)", hsize, (unsigned)data_off, len);
    if (fmt > 10) /* name the byte the file holds, not the masked format */
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: point data record format %u (byte 104 holds 0x%02x; with "
                          "the compression bits set aside, 0 to 10 are read)", (unsigned)b[104],
                          (unsigned)b[104]);
    if (rec_len < lz_base[fmt])
        return jf_io_fail(err, JF_ERR_UNSUPPORTED, name, 0,
                          "header: compressed point format %u with %u-byte records", fmt,
                          rec_len);
    if (n == 0)
        return jf_io_fail(err, JF_ERR_FORMAT, name, 0, "no points in the file");
    if (n > JF_MAX_POINTS)
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0, "%llu points: more than supported",
                          (unsigned long long)n);
    jf_laz *L = calloc(1, sizeof *L);
    if (!L)
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    L->b = b, L->len = len, L->n = n, L->name = name;
    lz_vlr *z = &L->z;
    jf_status st = find_vlr(b, hsize, data_off, nvlr, fmt, rec_len, name, z, err);
    if (st != JF_OK) {
        jf__laz_close(L);
        return st;
    }
    int bad_table = 0;
    if ((st = read_table(b, len, data_off, n, z, name, &L->ch, &L->nc, &bad_table, err)) !=
        JF_OK) {
        /* missing or damaged: rebuilt from the chunks, else both reasons */
        char why[200] = "";
        if (st == JF_ERR_NOMEM || z->compressor == 1 || !bad_table ||
            !scan_table(b, len, data_off, n, z, &L->ch, &L->nc, why, sizeof why)) {
            if (st != JF_ERR_NOMEM && z->compressor != 1 && bad_table && err) {
                size_t l = strlen(err->msg);
                snprintf(err->msg + l, sizeof err->msg - l, "; rebuilding it from the chunks "
                         "failed: %s", why);
            }
            jf__laz_close(L);
            return st;
        }
        if (err)
            err->msg[0] = '\0';
    }
    /* EVLRs (1.4) after the chunk table are kept, moved with the points */
    uint64_t evlr = 0, nevlr = 0;
    if (minor >= 4 && hsize >= 375) {
        evlr = g64(b + 235), nevlr = g32(b + 243);
        if (!nevlr || evlr < data_off || evlr > len)
            evlr = 0;
    }
    for (uint64_t k = 0, q = evlr; evlr && k < nevlr; k++) { /* a cut EVLR is lost data */
        uint64_t el = q + 60 <= len ? g64(b + q + 20) : 0;
        if (q + 60 > len || el > len - q - 60) {
            jf__laz_close(L);
            return jf_io_fail(err, JF_ERR_FORMAT, name, 0,
                              "EVLR %llu at byte %llu runs past the end of the file (%zu "
                              "bytes): truncated file", (unsigned long long)k,
                              (unsigned long long)q, len);
        }
        q += 60 + el;
    }
    L->evlr = evlr;
    size_t head = data_off - z->vlr_len, recs = (size_t)n * rec_len;
    if (recs / rec_len != n || head + recs < recs) {
        jf__laz_close(L);
        return jf_io_fail(err, JF_ERR_TOO_LARGE, name, 0, "%llu points: too large",
                          (unsigned long long)n);
    }
    L->head_len = head;
    L->cached = L->nc;
    unsigned char *o = L->head = malloc(head);
    if (!o) {
        jf__laz_close(L);
        return jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory");
    }
    /* header and VLRs without LASzip's; bits 6-7 of the format cleared */
    memcpy(o, b, z->vlr_at);
    memcpy(o + z->vlr_at, b + z->vlr_at + z->vlr_len, data_off - z->vlr_at - z->vlr_len);
    o[104] = (unsigned char)fmt;
    p32(o + 96, (uint32_t)head);
    p32(o + 100, nvlr - 1);
    if (evlr)
        p64(o + 235, head + recs);
    *out = L;
    return JF_OK;
}

const unsigned char *jf__laz_head(const jf_laz *L, size_t *head_len, uint64_t *n,
                                  unsigned *rec_len)
{
    *head_len = L->head_len, *n = L->n, *rec_len = L->z.rec_len;
    return L->head;
}

/* Chunk i decoded into out; 0, or -1 and msg. */
static int decode_chunk(const jf_laz *L, size_t i, uint8_t *out, char *msg, size_t msglen)
{
    const uint8_t *p = L->b + L->ch[i].start, *e = p + L->ch[i].bytes;
    return L->z.compressor == 3
               ? jf__laz_v3_chunk(L->z.items, L->z.nitems, L->z.rec_len, p, e, L->ch[i].count,
                                  out, msg, msglen)
               : jf__laz_v2_chunk(L->z.items, L->z.nitems, L->z.rec_len, p, e, L->ch[i].count,
                                  out, msg, msglen);
}

jf_status jf__laz_rows(jf_laz *L, uint64_t first, size_t count, char *out, jf_error *err)
{
    unsigned rl = L->z.rec_len;
    if (first > L->n || count > L->n - first)
        return jf_io_fail(err, JF_ERR_INVALID, L->name, 0, "rows past the end");
    /* the chunk holding `first` (chunks are in point order) */
    size_t lo = 0, hi = L->nc;
    while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (L->ch[mid].first <= first)
            lo = mid;
        else
            hi = mid;
    }
    for (size_t i = lo; count && i < L->nc; i++) {
        if (L->cached != i) { /* decoded once, kept for the next call */
            uint32_t most = 0;
            for (size_t k = 0; k < L->nc; k++)
                most = L->ch[k].count > most ? L->ch[k].count : most;
            if (!L->cache && !(L->cache = malloc((size_t)most * rl)))
                return jf_io_fail(err, JF_ERR_NOMEM, L->name, 0, "out of memory");
            char msg[160];
            L->cached = L->nc;
            if (decode_chunk(L, i, L->cache, msg, sizeof msg))
                return jf_io_fail(err, JF_ERR_FORMAT, L->name, 0, "chunk %zu (at byte %llu): %s",
                                  i, (unsigned long long)L->ch[i].start, msg);
            L->cached = i;
        }
        uint64_t from = first - L->ch[i].first, k = L->ch[i].count - from;
        if (k > count)
            k = count;
        memcpy(out, L->cache + from * rl, (size_t)k * rl);
        out += k * rl, first += k, count -= (size_t)k;
    }
    return JF_OK;
}

const unsigned char *jf__laz_evlr(const jf_laz *L, size_t *len)
{
    *len = L->evlr ? L->len - (size_t)L->evlr : 0;
    return L->b + (*len ? L->evlr : 0);
}

jf_status jf__laz_decode(jf_laz *L, unsigned char *rec, jf_error *err)
{
    /* the chunks, in parallel: each writes only its own records; every
     * chunk is decoded even after a failure, so the error names the first
     * bad chunk whatever the thread count */
    int failed = 0;
    size_t bad_chunk = L->nc, nc = L->nc, rec_len = L->z.rec_len;
    char bad_msg[160] = "";
#pragma omp parallel for schedule(dynamic, 1)
    for (size_t i = 0; i < nc; i++) {
        char msg[160];
        if (decode_chunk(L, i, rec + L->ch[i].first * rec_len, msg, sizeof msg)) {
#pragma omp critical(jf_laz_fail)
            if (i < bad_chunk) {
                bad_chunk = i;
                memcpy(bad_msg, msg, sizeof msg);
                failed = 1;
            }
        }
    }
    if (failed)
        return jf_io_fail(err, JF_ERR_FORMAT, L->name, 0, "chunk %zu (at byte %llu): %s",
                          bad_chunk, (unsigned long long)L->ch[bad_chunk].start, bad_msg);
    return JF_OK;
}

jf_status jf__laz_unpack(const char *buf, size_t len, const char *name, char **img,
                         size_t *img_len, jf_error *err)
{
    *img = NULL, *img_len = 0;
    jf_laz *L;
    jf_status st = jf__laz_open(buf, len, name, &L, err);
    if (st != JF_OK)
        return st;
    size_t head = L->head_len, rec_len = L->z.rec_len, recs = (size_t)L->n * rec_len, tail;
    const unsigned char *ev = jf__laz_evlr(L, &tail);
    unsigned char *o = head + recs + tail >= recs ? malloc(head + recs + tail) : NULL;
    if (!o) {
        st = jf_io_fail(err, JF_ERR_NOMEM, name, 0, "out of memory for %llu points",
                        (unsigned long long)L->n);
        jf__laz_close(L);
        return st;
    }
    memcpy(o, L->head, head);
    if (tail)
        memcpy(o + head + recs, ev, tail);
    st = jf__laz_decode(L, o + head, err);
    jf__laz_close(L);
    if (st != JF_OK) {
        free(o);
        return st;
    }
    *img = (char *)o;
    *img_len = head + recs + tail;
    return JF_OK;
}
