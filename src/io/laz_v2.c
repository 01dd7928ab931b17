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

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void wr16(uint8_t *p, uint32_t v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static void wr32(uint8_t *p, uint32_t v) { wr16(p, v), wr16(p + 2, v >> 16); }

/* ---- POINT10 -------------------------------------------------------- */

typedef struct {
    uint32_t x, y, z;
    uint16_t intensity, psid;
    uint8_t bits, cls, sar, ud;
    uint16_t last_int[16];
    lz_med mx[16], my[16];
    int32_t last_h[8];
    lz_sym changed, sar_m[2];
    lz_sym *bitm[256], *clsm[256], *udm[256];
    lz_ic ic_int, ic_psid, ic_dx, ic_dy, ic_z;
} p10;

static int p10_init(p10 *s, lz_arena *a, const uint8_t *r)
{
    memset(s, 0, sizeof *s);
    s->x = rd32(r), s->y = rd32(r + 4), s->z = rd32(r + 8);
    s->bits = r[14], s->cls = r[15], s->sar = r[16], s->ud = r[17];
    s->psid = (uint16_t)(r[18] | r[19] << 8);
    for (int k = 0; k < 16; k++)
        lz_med_init(&s->mx[k]), lz_med_init(&s->my[k]);
    return lz_ic_init(&s->ic_int, a, 16, 4, 8, 0) &&
           lz_ic_init(&s->ic_psid, a, 16, 1, 8, 0) && lz_ic_init(&s->ic_dx, a, 32, 2, 8, 0) &&
           lz_ic_init(&s->ic_dy, a, 32, 22, 8, 0) && lz_ic_init(&s->ic_z, a, 32, 20, 8, 0);
}

static int p10_decode(p10 *s, lz_dec *d, lz_arena *a, uint8_t *r)
{
    uint32_t cv = lz_decode_lazy(d, &s->changed, 64);
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
            s->last_int[m] = (uint16_t)lz_ic_decode(d, &s->ic_int, s->last_int[m], m < 3 ? m : 3);
        if (cv & 8) {
            if (!(mod = lz_sym_lazy(&s->clsm[s->cls], a, 256)))
                return 0;
            s->cls = (uint8_t)lz_decode_sym(d, mod);
        }
        if (cv & 4)
            s->sar = (uint8_t)(lz_decode_lazy(d, &s->sar_m[(s->bits >> 6) & 1], 256) + s->sar);
        if (cv & 2) {
            if (!(mod = lz_sym_lazy(&s->udm[s->ud], a, 256)))
                return 0;
            s->ud = (uint8_t)lz_decode_sym(d, mod);
        }
        if (cv & 1)
            s->psid = (uint16_t)lz_ic_decode(d, &s->ic_psid, s->psid, 0);
    } else {
        rn = s->bits & 7, nr = (s->bits >> 3) & 7;
        m = jf__lz_return_map[nr][rn], l = jf__lz_return_level[nr][rn];
    }
    s->intensity = s->last_int[m];
    /* x, y: median prediction; the contexts of y and z from x's (and y's) k */
    int32_t diff = lz_ic_decode(d, &s->ic_dx, s->mx[m].v[2], nr == 1);
    s->x += (uint32_t)diff;
    lz_med_add(&s->mx[m], diff);
    uint32_t k = s->ic_dx.k;
    diff = lz_ic_decode(d, &s->ic_dy, s->my[m].v[2], (nr == 1) + (k < 20 ? k & ~1u : 20));
    s->y += (uint32_t)diff;
    lz_med_add(&s->my[m], diff);
    k = (s->ic_dx.k + s->ic_dy.k) / 2;
    s->z = (uint32_t)lz_ic_decode(d, &s->ic_z, s->last_h[l], (nr == 1) + (k < 18 ? k & ~1u : 18));
    s->last_h[l] = (int32_t)s->z;
    wr32(r, s->x), wr32(r + 4, s->y), wr32(r + 8, s->z);
    wr16(r + 12, s->intensity);
    r[14] = s->bits, r[15] = s->cls, r[16] = s->sar, r[17] = s->ud;
    wr16(r + 18, s->psid);
    return 1;
}

/* ---- GPSTIME11 ------------------------------------------------------ */

#define GPS_MULTI 500
#define GPS_MULTI_MINUS (-10)
#define GPS_UNCHANGED (GPS_MULTI - GPS_MULTI_MINUS + 1)
#define GPS_CODE_FULL (GPS_MULTI - GPS_MULTI_MINUS + 2)
#define GPS_TOTAL (GPS_MULTI - GPS_MULTI_MINUS + 6)

typedef struct {
    uint64_t t[4];
    int32_t diff[4];
    uint32_t extreme[4];
    unsigned last, next;
    lz_sym multi, zero;
    lz_ic ic;
} gps11;

static int gps_init(gps11 *s, lz_arena *a, const uint8_t *r)
{
    memset(s, 0, sizeof *s);
    s->t[0] = rd32(r) | (uint64_t)rd32(r + 4) << 32;
    return lz_ic_init(&s->ic, a, 32, 9, 8, 0);
}

static int32_t mul32(int32_t a, int32_t b) { return (int32_t)((uint32_t)a * (uint32_t)b); }

/* A new sequence: the high 32 bits predicted from the current one's. */
static void gps_full(gps11 *s, lz_dec *d)
{
    s->next = (s->next + 1) & 3;
    int32_t hi = lz_ic_decode(d, &s->ic, (int32_t)(s->t[s->last] >> 32), 8);
    s->t[s->next] = (uint64_t)(uint32_t)hi << 32 | lz_read_int(d);
    s->last = s->next;
    s->diff[s->last] = 0;
    s->extreme[s->last] = 0;
}

/* The extreme multipliers: after 4 in a row the difference is adopted. */
static void gps_extreme(gps11 *s, int32_t diff)
{
    if (++s->extreme[s->last] > 3) {
        s->diff[s->last] = diff;
        s->extreme[s->last] = 0;
    }
}

static int gps_decode(gps11 *s, lz_dec *d, uint8_t *r)
{
    /* a switch to another sequence is followed by that sequence's code;
     * the encoder never switches twice in a row */
    for (int hops = 0;; hops++) {
        if (hops > 1)
            return 0;
        unsigned L = s->last;
        if (s->diff[L] == 0) {
            uint32_t multi = lz_decode_lazy(d, &s->zero, 6);
            if (multi == 1) {
                s->diff[L] = lz_ic_decode(d, &s->ic, 0, 0);
                s->t[L] += (uint64_t)(int64_t)s->diff[L];
                s->extreme[L] = 0;
            } else if (multi == 2) {
                gps_full(s, d);
            } else if (multi > 2) {
                s->last = (L + multi - 2) & 3;
                continue;
            }
        } else {
            uint32_t multi = lz_decode_lazy(d, &s->multi, GPS_TOTAL);
            if (multi == 1) {
                s->t[L] += (uint64_t)(int64_t)lz_ic_decode(d, &s->ic, s->diff[L], 1);
                s->extreme[L] = 0;
            } else if (multi < GPS_UNCHANGED) {
                int32_t diff;
                if (multi == 0) {
                    diff = lz_ic_decode(d, &s->ic, 0, 7);
                    gps_extreme(s, diff);
                } else if (multi < GPS_MULTI) {
                    diff = lz_ic_decode(d, &s->ic, mul32((int32_t)multi, s->diff[L]),
                                        multi < 10 ? 2 : 3);
                } else if (multi == GPS_MULTI) {
                    diff = lz_ic_decode(d, &s->ic, mul32(GPS_MULTI, s->diff[L]), 4);
                    gps_extreme(s, diff);
                } else {
                    int32_t mm = GPS_MULTI - (int32_t)multi;
                    if (mm > GPS_MULTI_MINUS) {
                        diff = lz_ic_decode(d, &s->ic, mul32(mm, s->diff[L]), 5);
                    } else {
                        diff = lz_ic_decode(d, &s->ic, mul32(GPS_MULTI_MINUS, s->diff[L]), 6);
                        gps_extreme(s, diff);
                    }
                }
                s->t[L] += (uint64_t)(int64_t)diff;
            } else if (multi == GPS_CODE_FULL) {
                gps_full(s, d);
            } else if (multi > GPS_CODE_FULL) {
                s->last = (L + multi - GPS_CODE_FULL) & 3;
                continue;
            }
        }
        break;
    }
    wr32(r, (uint32_t)s->t[s->last]);
    wr32(r + 4, (uint32_t)(s->t[s->last] >> 32));
    return 1;
}

/* ---- RGB12 ---------------------------------------------------------- */

typedef struct {
    uint16_t rgb[3];
    lz_sym used, diff[6];
} rgb12;

static int rgb_init(rgb12 *s, lz_arena *a, const uint8_t *r)
{
    memset(s, 0, sizeof *s);
    for (int c = 0; c < 3; c++)
        s->rgb[c] = (uint16_t)(r[2 * c] | r[2 * c + 1] << 8);
    (void)a; /* the models are made on first use */
    return 1;
}

static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

/* Green and blue predicted from red's change, byte by byte. */
static void rgb_decode(rgb12 *s, lz_dec *d, uint8_t *r)
{
    const uint16_t *l = s->rgb;
    unsigned sym = lz_decode_lazy(d, &s->used, 128), v[3];
    v[0] = sym & 1 ? (lz_decode_lazy(d, &s->diff[0], 256) + (l[0] & 0xFF)) & 0xFF : l[0] & 0xFF;
    v[0] |= sym & 2 ? ((lz_decode_lazy(d, &s->diff[1], 256) + (l[0] >> 8)) & 0xFF) << 8 : l[0] & 0xFF00;
    if (sym & 64) {
        int diff = (int)(v[0] & 0xFF) - (l[0] & 0xFF);
        v[1] = sym & 4 ? (lz_decode_lazy(d, &s->diff[2], 256) + clamp8(diff + (l[1] & 0xFF))) & 0xFF
                       : l[1] & 0xFF;
        if (sym & 16) {
            diff = (diff + (int)(v[1] & 0xFF) - (l[1] & 0xFF)) / 2;
            v[2] = (lz_decode_lazy(d, &s->diff[4], 256) + clamp8(diff + (l[2] & 0xFF))) & 0xFF;
        } else {
            v[2] = l[2] & 0xFF;
        }
        diff = (int)(v[0] >> 8) - (l[0] >> 8);
        if (sym & 8)
            v[1] |= ((lz_decode_lazy(d, &s->diff[3], 256) + clamp8(diff + (l[1] >> 8))) & 0xFF) << 8;
        else
            v[1] |= l[1] & 0xFF00;
        if (sym & 32) {
            diff = (diff + (int)(v[1] >> 8) - (l[1] >> 8)) / 2;
            v[2] |= ((lz_decode_lazy(d, &s->diff[5], 256) + clamp8(diff + (l[2] >> 8))) & 0xFF) << 8;
        } else {
            v[2] |= l[2] & 0xFF00;
        }
    } else {
        v[1] = v[2] = v[0];
    }
    for (int c = 0; c < 3; c++) {
        s->rgb[c] = (uint16_t)v[c];
        wr16(r + 2 * c, v[c]);
    }
}

/* ---- BYTE ----------------------------------------------------------- */

typedef struct {
    unsigned n;
    uint8_t *last;
    lz_sym *m;
} byte2;

static int byte_init(byte2 *s, lz_arena *a, const uint8_t *r, unsigned n)
{
    s->n = n;
    s->last = lz_alloc(a, n);
    s->m = lz_alloc(a, sizeof(lz_sym) * n);
    if (!s->last || !s->m)
        return 0;
    memcpy(s->last, r, n);
    memset(s->m, 0, sizeof(lz_sym) * n); /* made on first use */
    return 1;
}

static void byte_decode(byte2 *s, lz_dec *d, uint8_t *r)
{
    for (unsigned k = 0; k < s->n; k++)
        r[k] = s->last[k] = (uint8_t)(s->last[k] + lz_decode_lazy(d, &s->m[k], 256));
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
            ok = (st[i] = calloc(1, sizeof(gps11))) && gps_init(st[i], &a, r);
            break;
        case LZ_RGB12:
            ok = (st[i] = calloc(1, sizeof(rgb12))) && rgb_init(st[i], &a, r);
            break;
        default: /* LZ_BYTE: io_laz.c admits nothing else */
            ok = (st[i] = calloc(1, sizeof(byte2))) && byte_init(st[i], &a, r, items[i].size);
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
