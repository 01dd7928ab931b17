/*
 * laz_v2.c -- LASzip's pointwise compressors, item version 2: POINT10
 * (the 20 bytes of point formats 0-5), GPSTIME11, RGB12 and BYTE (extra
 * bytes), for point formats 0-3 (laszip VLR compressor 1 or 2).
 *
 * design (LASzip, Isenburg 2013, "LASzip: lossless compression of LiDAR
 * data", section 3): a chunk starts with its first point raw (every item's
 * bytes, in item order), then one arithmetic-coded stream holds the other
 * points, item after item.  Each item predicts from the previous point:
 * POINT10 codes which fields changed (6 flags), the changed ones by
 * context models, x and y as differences from the median of the last five
 * differences of the same return context, z from the last z of the same
 * return level; GPS time as a multiple of the last difference in one of
 * four sequences; colour by byte-wise differences; extra bytes byte-wise.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "laz_arith.h"
#include "laz_internal.h"

const uint8_t jf__lz_return_map[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
    {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
    {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
const uint8_t jf__lz_return_level[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5},
    {3, 2, 1, 0, 1, 2, 3, 4}, {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2},
    {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

/* ---- POINT10 -------------------------------------------------------- */

typedef struct {
    uint32_t x, y, z;
    uint16_t intensity, psid;
    uint8_t bits, cls, sar, ud;
    lz_sym *bitm[256], *clsm[256], *udm[256];
    lz_p10 m;
} p10;

static int p10_init(p10 *s, lz_arena *a, const uint8_t *r)
{
    memset(s, 0, sizeof *s);
    s->x = lz_rd32(r), s->y = lz_rd32(r + 4), s->z = lz_rd32(r + 8);
    s->bits = r[14], s->cls = r[15], s->sar = r[16], s->ud = r[17];
    s->psid = lz_rd16(r + 18);
    return lz_p10_init(&s->m, a);
}

static int p10_decode(p10 *s, lz_dec *d, lz_arena *a, uint8_t *r)
{
    lz_p10 *q = &s->m;
    uint32_t cv = lz_decode_lazy(d, &q->changed, 64);
    unsigned rn, nr, m, l;
    if (cv) {
        lz_sym *mod;
        if (cv & 32) {
            if (!(mod = lz_sym_lazy(&s->bitm[s->bits], a, 256)))
                return 0;
            s->bits = (uint8_t)lz_decode_sym(d, mod);
        }
        rn = s->bits & 7, nr = (s->bits >> 3) & 7;
        m = jf__lz_return_map[nr][rn], l = jf__lz_return_level[nr][rn];
        if (cv & 16)
            q->last_int[m] = (uint16_t)lz_ic_decode(d, &q->ic_int, q->last_int[m], m < 3 ? m : 3);
        if (cv & 8) {
            if (!(mod = lz_sym_lazy(&s->clsm[s->cls], a, 256)))
                return 0;
            s->cls = (uint8_t)lz_decode_sym(d, mod);
        }
        if (cv & 4)
            s->sar = (uint8_t)(lz_decode_lazy(d, &q->sar_m[(s->bits >> 6) & 1], 256) + s->sar);
        if (cv & 2) {
            if (!(mod = lz_sym_lazy(&s->udm[s->ud], a, 256)))
                return 0;
            s->ud = (uint8_t)lz_decode_sym(d, mod);
        }
        if (cv & 1)
            s->psid = (uint16_t)lz_ic_decode(d, &q->ic_psid, s->psid, 0);
    } else {
        rn = s->bits & 7, nr = (s->bits >> 3) & 7;
        m = jf__lz_return_map[nr][rn], l = jf__lz_return_level[nr][rn];
    }
    s->intensity = q->last_int[m];
    /* x, y: median prediction; the contexts of y and z from x's (and y's) k */
    int32_t diff = lz_ic_decode(d, &q->ic_dx, q->mx[m].v[2], nr == 1);
    s->x += (uint32_t)diff;
    lz_med_add(&q->mx[m], diff);
    diff = lz_ic_decode(d, &q->ic_dy, q->my[m].v[2], lz_p10_y_ctx(q, nr));
    s->y += (uint32_t)diff;
    lz_med_add(&q->my[m], diff);
    s->z = (uint32_t)lz_ic_decode(d, &q->ic_z, q->last_h[l], lz_p10_z_ctx(q, nr));
    q->last_h[l] = (int32_t)s->z;
    lz_wr32(r, s->x), lz_wr32(r + 4, s->y), lz_wr32(r + 8, s->z);
    lz_wr16(r + 12, s->intensity);
    r[14] = s->bits, r[15] = s->cls, r[16] = s->sar, r[17] = s->ud;
    lz_wr16(r + 18, s->psid);
    return 1;
}

/* ---- GPSTIME11 (laz_internal.h's lz_gps, with the "unchanged" code) -- */

static int gps_decode(lz_gps *s, lz_dec *d, uint8_t *r)
{
    if (!lz_gps_decode(s, d, 1))
        return 0;
    lz_wr32(r, (uint32_t)s->t[s->last]);
    lz_wr32(r + 4, (uint32_t)(s->t[s->last] >> 32));
    return 1;
}

/* ---- RGB12 ---------------------------------------------------------- */

typedef struct {
    uint16_t rgb[3];
    lz_sym used, diff[6];
} rgb12;

static void rgb_decode(rgb12 *s, lz_dec *d, uint8_t *r)
{
    unsigned v[3];
    lz_rgb_decode(d, &s->used, s->diff, s->rgb, v);
    for (int c = 0; c < 3; c++) {
        s->rgb[c] = (uint16_t)v[c];
        lz_wr16(r + 2 * c, v[c]);
    }
}

/* ---- BYTE ----------------------------------------------------------- */

typedef struct {
    unsigned n;
    lz_bytes b;
} byte2;

static void byte_decode(byte2 *s, lz_dec *d, uint8_t *r)
{
    uint8_t *last = s->b.last;
    for (unsigned k = 0; k < s->n; k++)
        r[k] = last[k] = (uint8_t)(last[k] + lz_decode_lazy(d, &s->b.m[k], 256));
}

/* ---- the chunk ------------------------------------------------------ */

static int v2_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                    const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                    char *msg, size_t msglen, size_t *used)
{
    const uint8_t *p0 = p;
    if (!count)
        return 0;
    if ((size_t)(end - p) < rec_len) {
        snprintf(msg, msglen, "point 0: the chunk's %zu bytes do not hold its first point's %u",
                 (size_t)(end - p), rec_len);
        return -1;
    }
    memcpy(out, p, rec_len); /* the first point, raw */
    p += rec_len;
    lz_arena a = {0};
    void *st[16] = {0};
    unsigned off[16];
    int ok = 1;
    for (unsigned i = 0, o = 0; i < nitems && ok; o += items[i].size, i++) {
        off[i] = o;
        const uint8_t *r = out + o;
        switch (items[i].type) {
        case LZ_POINT10:
            ok = (st[i] = calloc(1, sizeof(p10))) && p10_init(st[i], &a, r);
            break;
        case LZ_GPSTIME11:
            ok = (st[i] = calloc(1, sizeof(lz_gps))) && lz_gps_init(st[i], &a, lz_rd64(r));
            break;
        case LZ_RGB12:
            ok = (st[i] = calloc(1, sizeof(rgb12))) != NULL;
            for (int c = 0; ok && c < 3; c++)
                ((rgb12 *)st[i])->rgb[c] = lz_rd16(r + 2 * c);
            break;
        default: /* LZ_BYTE: io_laz.c admits nothing else */
            ok = (st[i] = calloc(1, sizeof(byte2))) != NULL;
            if (ok) {
                ((byte2 *)st[i])->n = items[i].size;
                ok = lz_bytes_init(&((byte2 *)st[i])->b, &a, r, items[i].size);
            }
        }
    }
    int rc = 0;
    if (!ok) {
        snprintf(msg, msglen, "out of memory for the decoder's models");
        rc = -1;
    }
    lz_dec d;
    lz_dec_init(&d, p, end);
    d.arena = &a;
    for (uint32_t j = 1; j < count && !rc; j++) {
        uint8_t *r = out + (size_t)j * rec_len;
        for (unsigned i = 0; i < nitems && !rc; i++) {
            switch (items[i].type) {
            case LZ_POINT10:
                if (!p10_decode(st[i], &d, &a, r + off[i])) {
                    snprintf(msg, msglen, "out of memory for the decoder's models");
                    rc = -1;
                }
                break;
            case LZ_GPSTIME11:
                if (!gps_decode(st[i], &d, r + off[i])) {
                    snprintf(msg, msglen, "point %u: corrupt GPS time stream", (unsigned)j);
                    rc = -1;
                }
                break;
            case LZ_RGB12:
                rgb_decode(st[i], &d, r + off[i]);
                break;
            default:
                byte_decode(st[i], &d, r + off[i]);
            }
        }
        /* LASzip's encoder flushes 4 bytes at most past its last symbol */
        if (!rc && (d.over > 4 || d.bad)) {
            snprintf(msg, msglen, "point %u: the compressed stream %s", (unsigned)j,
                     d.bad == 2 ? "needs a model: out of memory"
                     : d.bad  ? "is corrupt"
                              : "ends early (truncated chunk)");
            rc = -1;
        }
    }
    /* the decoder reads exactly the bytes the encoder wrote (its last
     * symbol flushed, then 2 or 3 zero bytes): bytes left over mean the
     * stream did not decode as written */
    if (used)
        *used = (size_t)(d.p - p0);
    else if (!rc && d.p != end) {
        snprintf(msg, msglen, "point %u: the compressed stream has %zu bytes more than its "
                 "%u points use (corrupt chunk)", (unsigned)count - 1, (size_t)(end - d.p),
                 (unsigned)count);
        rc = -1;
    }
    for (unsigned i = 0; i < nitems; i++)
        free(st[i]);
    lz_arena_free(&a);
    return rc;
}

int jf__laz_v2_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen)
{
    return v2_chunk(items, nitems, rec_len, p, end, count, out, msg, msglen, NULL);
}

int jf__laz_v2_chunk_len(const lz_item *items, unsigned nitems, unsigned rec_len,
                         const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                         size_t *used, char *msg, size_t msglen)
{
    return v2_chunk(items, nitems, rec_len, p, end, count, out, msg, msglen, used);
}
