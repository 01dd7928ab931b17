/*
 * laz_v3.c -- LASzip's layered compressors, item version 3, for the LAS
 * 1.4 point formats 6-8: POINT14 (30 bytes), RGB14, RGBNIR14, BYTE14.
 *
 * design (LASzip 3, "native LAS 1.4 extension"): a chunk holds its first
 * point raw, the chunk's point count, the byte size of every layer, then
 * the layers, each its own arithmetic-coded stream: POINT14's nine (x y
 * and returns, z, classification, flags, intensity, scan angle, user
 * data, point source, GPS time), one for RGB, two for RGB+NIR, one per
 * extra byte.  A layer of size 0 means the field never changed in the
 * chunk.  The models come in four sets, one per scanner channel: a point
 * of a channel not seen before starts that channel's set from the
 * previous point.  Every prediction below is LASzip's (the encoder makes
 * the same ones); the quirks are kept, e.g. a colour predicted from the
 * previous channel's colour right after a switch to a channel seen before.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "laz_arith.h"
#include "laz_internal.h"

static const uint8_t map6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

/* |n - r| capped at 7: the z context */
static unsigned level8(unsigned n, unsigned r) { return n > r ? (n - r > 7 ? 7 : n - r) : (r - n > 7 ? 7 : r - n); }

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static void wr16(uint8_t *p, uint32_t v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static void wr32(uint8_t *p, uint32_t v) { wr16(p, v), wr16(p + 2, v >> 16); }

/* One layer: its bytes and its decoder (size 0: the field is unchanged). */
typedef struct {
    const uint8_t *p;
    uint32_t size;
    lz_dec d;
} layer;

/* ---- POINT14 -------------------------------------------------------- */

#define GPS_MULTI 500
#define GPS_MULTI_MINUS (-10)
#define GPS_CODE_FULL (GPS_MULTI - GPS_MULTI_MINUS + 1)
#define GPS_TOTAL (GPS_MULTI - GPS_MULTI_MINUS + 5)

typedef struct {
    int used, gps_change;
    uint32_t x, y, z;
    uint16_t intensity, sangle, psid;
    uint8_t rn, nr, cflags, sc, sdir, eof, cls, ud;
    uint64_t gps;
    lz_sym changed[8], sc_m, rn_same, gmulti, g0;
    lz_sym *nr_m[16], *rn_m[16], *cls_m[64], *flag_m[64], *ud_m[64];
    lz_ic dx, dy, iz, iint, isa, ips, igps;
    uint16_t last_int[8];
    int32_t last_z[8];
    lz_med mx[12], my[12];
    unsigned gseq, gnext;
    uint64_t gt[4];
    int32_t gdiff[4], gext[4];
} p14ctx;

typedef struct {
    p14ctx c[4];
    unsigned cur;
    layer L[9]; /* xy, z, class, flags, intensity, scan angle, user data, source, gps */
} p14;

static void p14_unpack(p14ctx *c, const uint8_t *r)
{
    c->x = rd32(r), c->y = rd32(r + 4), c->z = rd32(r + 8);
    c->intensity = (uint16_t)(r[12] | r[13] << 8);
    c->rn = r[14] & 15, c->nr = r[14] >> 4;
    c->cflags = r[15] & 15, c->sc = (r[15] >> 4) & 3, c->sdir = (r[15] >> 6) & 1,
    c->eof = r[15] >> 7;
    c->cls = r[16], c->ud = r[17];
    c->sangle = (uint16_t)(r[18] | r[19] << 8);
    c->psid = (uint16_t)(r[20] | r[21] << 8);
    c->gps = rd32(r + 22) | (uint64_t)rd32(r + 26) << 32;
}

static void p14_pack(const p14ctx *c, uint8_t *r)
{
    wr32(r, c->x), wr32(r + 4, c->y), wr32(r + 8, c->z);
    wr16(r + 12, c->intensity);
    r[14] = (uint8_t)(c->rn | c->nr << 4);
    r[15] = (uint8_t)(c->cflags | c->sc << 4 | c->sdir << 6 | c->eof << 7);
    r[16] = c->cls, r[17] = c->ud;
    wr16(r + 18, c->sangle), wr16(r + 20, c->psid);
    wr32(r + 22, (uint32_t)c->gps), wr32(r + 26, (uint32_t)(c->gps >> 32));
}

/* A channel's set, started from point `from` (LASzip: the z and
 * intensity contexts all at its values, GPS sequence 0 at its time). */
static int p14_ctx_init(p14ctx *c, lz_arena *a, const p14ctx *from, const uint8_t *raw)
{
    memset(c, 0, sizeof *c);
    if (raw)
        p14_unpack(c, raw);
    else {
        c->x = from->x, c->y = from->y, c->z = from->z, c->intensity = from->intensity;
        c->rn = from->rn, c->nr = from->nr, c->cflags = from->cflags, c->sc = from->sc;
        c->sdir = from->sdir, c->eof = from->eof, c->cls = from->cls, c->ud = from->ud;
        c->sangle = from->sangle, c->psid = from->psid, c->gps = from->gps;
    }
    c->used = 1;
    for (int k = 0; k < 8; k++)
        c->last_int[k] = c->intensity, c->last_z[k] = (int32_t)c->z;
    for (int k = 0; k < 12; k++)
        lz_med_init(&c->mx[k]), lz_med_init(&c->my[k]);
    c->gt[0] = c->gps;
    return lz_ic_init(&c->dx, a, 32, 2, 8, 0) && lz_ic_init(&c->dy, a, 32, 22, 8, 0) &&
           lz_ic_init(&c->iz, a, 32, 20, 8, 0) && lz_ic_init(&c->iint, a, 16, 4, 8, 0) &&
           lz_ic_init(&c->isa, a, 16, 2, 8, 0) && lz_ic_init(&c->ips, a, 16, 1, 8, 0) &&
           lz_ic_init(&c->igps, a, 32, 9, 8, 0);
}

static int32_t mul32(int32_t a, int32_t b) { return (int32_t)((uint32_t)a * (uint32_t)b); }

static void gps_extreme(p14ctx *c, int32_t diff)
{
    if (++c->gext[c->gseq] > 3) {
        c->gext[c->gseq] = 0;
        c->gdiff[c->gseq] = diff;
    }
}

static void gps_full(p14ctx *c, lz_dec *d)
{
    c->gnext = (c->gnext + 1) & 3;
    int32_t hi = lz_ic_decode(d, &c->igps, (int32_t)(c->gt[c->gseq] >> 32), 8);
    c->gt[c->gnext] = (uint64_t)(uint32_t)hi << 32 | lz_read_int(d);
    c->gseq = c->gnext;
    c->gdiff[c->gseq] = 0;
    c->gext[c->gseq] = 0;
}

/* GPS time as in version 2 (laz_v2.c) without the "unchanged" code: the
 * change flag is in the x y layer.  0 if the stream switches sequence
 * twice in a row (the encoder never does). */
static int p14_gps(p14ctx *c, lz_dec *d)
{
    for (int hops = 0;; hops++) {
        if (hops > 1)
            return 0;
        unsigned s = c->gseq;
        if (c->gdiff[s] == 0) {
            uint32_t multi = lz_decode_lazy(d, &c->g0, 5);
            if (multi == 0) {
                c->gdiff[s] = lz_ic_decode(d, &c->igps, 0, 0);
                c->gt[s] += (uint64_t)(int64_t)c->gdiff[s];
                c->gext[s] = 0;
            } else if (multi == 1) {
                gps_full(c, d);
            } else {
                c->gseq = (s + multi - 1) & 3;
                continue;
            }
        } else {
            uint32_t multi = lz_decode_lazy(d, &c->gmulti, GPS_TOTAL);
            if (multi == 1) {
                c->gt[s] += (uint64_t)(int64_t)lz_ic_decode(d, &c->igps, c->gdiff[s], 1);
                c->gext[s] = 0;
            } else if (multi < GPS_CODE_FULL) {
                int32_t diff;
                if (multi == 0) {
                    diff = lz_ic_decode(d, &c->igps, 0, 7);
                    gps_extreme(c, diff);
                } else if (multi < GPS_MULTI) {
                    diff = lz_ic_decode(d, &c->igps, mul32((int32_t)multi, c->gdiff[s]),
                                        multi < 10 ? 2 : 3);
                } else if (multi == GPS_MULTI) {
                    diff = lz_ic_decode(d, &c->igps, mul32(GPS_MULTI, c->gdiff[s]), 4);
                    gps_extreme(c, diff);
                } else {
                    int32_t mm = GPS_MULTI - (int32_t)multi;
                    if (mm > GPS_MULTI_MINUS) {
                        diff = lz_ic_decode(d, &c->igps, mul32(mm, c->gdiff[s]), 5);
                    } else {
                        diff = lz_ic_decode(d, &c->igps, mul32(GPS_MULTI_MINUS, c->gdiff[s]), 6);
                        gps_extreme(c, diff);
                    }
                }
                c->gt[s] += (uint64_t)(int64_t)diff;
            } else if (multi == GPS_CODE_FULL) {
                gps_full(c, d);
            } else {
                c->gseq = (s + multi - GPS_CODE_FULL) & 3;
                continue;
            }
        }
        break;
    }
    c->gps = c->gt[c->gseq];
    return 1;
}

/* -1 out of memory, -2 corrupt GPS stream, else the context of the other
 * items: the new scanner channel on a point that switches channel, 0 on
 * every other point (LASzip's LASreadPoint starts each point's context at
 * 0 and only POINT14's switch sets it; laz-perf does the same), so RGB14
 * and BYTE14 go back to their channel-0 set after a switch. */
static int p14_decode(p14 *s, lz_arena *a, uint8_t *r)
{
    p14ctx *prev = &s->c[s->cur];
    lz_dec *xy = &s->L[0].d;
    unsigned lpr = (prev->rn == 1) | (prev->rn >= prev->nr) << 1 | (unsigned)prev->gps_change << 2;
    uint32_t cv = lz_decode_lazy(xy, &prev->changed[lpr], 128);
    int item_ctx = 0;
    if (cv & 64) { /* another scanner channel */
        unsigned sc = (s->cur + lz_decode_lazy(xy, &prev->sc_m, 3) + 1) % 4;
        if (!s->c[sc].used && !p14_ctx_init(&s->c[sc], a, prev, NULL))
            return -1;
        s->cur = sc;
        s->c[sc].sc = (uint8_t)sc;
        item_ctx = (int)sc;
    }
    p14ctx *c = &s->c[s->cur];
    int gpsc = (cv >> 4) & 1;
    unsigned n = c->nr, rn = c->rn;
    lz_sym *m;
    if (cv & 4) {
        if (!(m = lz_sym_lazy(&c->nr_m[n], a, 16)))
            return -1;
        n = c->nr = (uint8_t)lz_decode_sym(xy, m);
    }
    switch (cv & 3) {
    case 1:
        rn = (rn + 1) % 16;
        break;
    case 2:
        rn = (rn + 15) % 16;
        break;
    case 3:
        if (gpsc) {
            if (!(m = lz_sym_lazy(&c->rn_m[rn], a, 16)))
                return -1;
            rn = lz_decode_sym(xy, m);
        } else {
            rn = (rn + lz_decode_lazy(xy, &c->rn_same, 13) + 2) % 16;
        }
    }
    c->rn = (uint8_t)rn;
    unsigned ctx = (unsigned)map6[n][rn] << 1 | (unsigned)gpsc;
    int32_t diff = lz_ic_decode(xy, &c->dx, c->mx[ctx].v[2], n == 1);
    c->x += (uint32_t)diff;
    lz_med_add(&c->mx[ctx], diff);
    uint32_t k = (c->dx.k < 20 ? c->dx.k : 20) & ~1u;
    diff = lz_ic_decode(xy, &c->dy, c->my[ctx].v[2], (n == 1) | k);
    c->y += (uint32_t)diff;
    lz_med_add(&c->my[ctx], diff);
    if (s->L[1].size) {
        k = (c->dx.k + c->dy.k) / 2;
        k = (k < 18 ? k : 18) & ~1u;
        unsigned l = level8(n, rn);
        c->z = (uint32_t)lz_ic_decode(&s->L[1].d, &c->iz, c->last_z[l], (n == 1) | k);
        c->last_z[l] = (int32_t)c->z;
    }
    if (s->L[2].size) {
        unsigned cc = (rn == 1 && rn >= n) | (c->cls & 0x1F) << 1;
        if (!(m = lz_sym_lazy(&c->cls_m[cc], a, 256)))
            return -1;
        c->cls = (uint8_t)lz_decode_sym(&s->L[2].d, m);
    }
    if (s->L[3].size) {
        unsigned f = c->cflags | c->sdir << 4 | c->eof << 5;
        if (!(m = lz_sym_lazy(&c->flag_m[f], a, 64)))
            return -1;
        f = lz_decode_sym(&s->L[3].d, m);
        c->eof = (f >> 5) & 1, c->sdir = (f >> 4) & 1, c->cflags = f & 15;
    }
    if (s->L[4].size) {
        unsigned ic = (unsigned)gpsc | (rn >= n) << 1 | (rn == 1) << 2;
        c->intensity = c->last_int[ic] =
            (uint16_t)lz_ic_decode(&s->L[4].d, &c->iint, c->last_int[ic], ic >> 1);
    }
    if (cv & 8)
        c->sangle = (uint16_t)lz_ic_decode(&s->L[5].d, &c->isa, (int16_t)c->sangle, gpsc);
    if (s->L[6].size) {
        if (!(m = lz_sym_lazy(&c->ud_m[c->ud / 4], a, 256)))
            return -1;
        c->ud = (uint8_t)lz_decode_sym(&s->L[6].d, m);
    }
    if (cv & 32)
        c->psid = (uint16_t)lz_ic_decode(&s->L[7].d, &c->ips, c->psid, 0);
    if (gpsc && !p14_gps(c, &s->L[8].d))
        return -2;
    c->gps_change = gpsc;
    p14_pack(c, r);
    return item_ctx;
}

/* ---- RGB14, RGBNIR14 ------------------------------------------------ */

typedef struct {
    int used;
    uint16_t last[4]; /* r g b nir */
    lz_sym rgb_used, rgb_diff[6], nir_used, nir_diff[2];
} rgbctx;

typedef struct {
    rgbctx c[4];
    unsigned cur;
    int nir;
    layer L[2]; /* rgb, nir */
} rgb14;

static int rgb_ctx_init(rgbctx *c, lz_arena *a, const uint16_t *last, int nir)
{
    memset(c, 0, sizeof *c);
    memcpy(c->last, last, sizeof c->last);
    c->used = 1;
    (void)a, (void)nir; /* the models are made on first use */
    return 1;
}

static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

/* Colour as RGB12 v2 (laz_v2.c), predicted from `l`. */
static void rgb_colour(lz_dec *d, rgbctx *c, const uint16_t *l, unsigned *v)
{
    unsigned sym = lz_decode_lazy(d, &c->rgb_used, 128);
    v[0] = sym & 1 ? (lz_decode_lazy(d, &c->rgb_diff[0], 256) + (l[0] & 0xFF)) & 0xFF : l[0] & 0xFF;
    v[0] |= sym & 2 ? ((lz_decode_lazy(d, &c->rgb_diff[1], 256) + (l[0] >> 8)) & 0xFF) << 8
                    : l[0] & 0xFF00u;
    if (sym & 64) {
        int diff = (int)(v[0] & 0xFF) - (l[0] & 0xFF);
        v[1] = sym & 4 ? (lz_decode_lazy(d, &c->rgb_diff[2], 256) + clamp8(diff + (l[1] & 0xFF))) & 0xFF
                       : l[1] & 0xFFu;
        if (sym & 16) {
            diff = (diff + (int)(v[1] & 0xFF) - (l[1] & 0xFF)) / 2;
            v[2] = (lz_decode_lazy(d, &c->rgb_diff[4], 256) + clamp8(diff + (l[2] & 0xFF))) & 0xFF;
        } else {
            v[2] = l[2] & 0xFFu;
        }
        diff = (int)(v[0] >> 8) - (l[0] >> 8);
        if (sym & 8)
            v[1] |= ((lz_decode_lazy(d, &c->rgb_diff[3], 256) + clamp8(diff + (l[1] >> 8))) & 0xFF) << 8;
        else
            v[1] |= l[1] & 0xFF00u;
        if (sym & 32) {
            diff = (diff + (int)(v[1] >> 8) - (l[1] >> 8)) / 2;
            v[2] |= ((lz_decode_lazy(d, &c->rgb_diff[5], 256) + clamp8(diff + (l[2] >> 8))) & 0xFF) << 8;
        } else {
            v[2] |= l[2] & 0xFF00u;
        }
    } else {
        v[1] = v[2] = v[0];
    }
}

static int rgb14_decode(rgb14 *s, lz_arena *a, unsigned sc, uint8_t *r)
{
    uint16_t *last = s->c[s->cur].last; /* LASzip keeps the old channel's
                                           last unless the new one is fresh */
    if (s->cur != sc) {
        s->cur = sc;
        if (!s->c[sc].used) {
            if (!rgb_ctx_init(&s->c[sc], a, last, s->nir))
                return 0;
            last = s->c[sc].last;
        }
    }
    rgbctx *c = &s->c[sc];
    if (s->L[0].size) {
        unsigned v[3];
        rgb_colour(&s->L[0].d, c, last, v);
        for (int k = 0; k < 3; k++)
            last[k] = (uint16_t)v[k];
    }
    for (int k = 0; k < 3; k++)
        wr16(r + 2 * k, last[k]);
    if (s->nir) {
        if (s->L[1].size) {
            lz_dec *d = &s->L[1].d;
            unsigned sym = lz_decode_lazy(d, &c->nir_used, 4), l = last[3], v;
            v = sym & 1 ? (lz_decode_lazy(d, &c->nir_diff[0], 256) + (l & 0xFF)) & 0xFF : l & 0xFF;
            v |= sym & 2 ? ((lz_decode_lazy(d, &c->nir_diff[1], 256) + (l >> 8)) & 0xFF) << 8
                         : l & 0xFF00u;
            last[3] = (uint16_t)v;
        }
        wr16(r + 6, last[3]);
    }
    return 1;
}

/* ---- BYTE14 --------------------------------------------------------- */

typedef struct {
    int used;
    uint8_t *last;
    lz_sym *m;
} bytectx;

typedef struct {
    bytectx c[4];
    unsigned cur, n;
    layer *L; /* one per byte */
} byte14;

static int byte_ctx_init(bytectx *c, lz_arena *a, const uint8_t *last, unsigned n)
{
    c->used = 1;
    c->last = lz_alloc(a, n);
    c->m = lz_alloc(a, sizeof(lz_sym) * n);
    if (!c->last || !c->m)
        return 0;
    memcpy(c->last, last, n);
    memset(c->m, 0, sizeof(lz_sym) * n); /* made on first use */
    return 1;
}

static int byte14_decode(byte14 *s, lz_arena *a, unsigned sc, uint8_t *r)
{
    uint8_t *last = s->c[s->cur].last;
    if (s->cur != sc) {
        s->cur = sc;
        if (!s->c[sc].used) {
            if (!byte_ctx_init(&s->c[sc], a, last, s->n))
                return 0;
            last = s->c[sc].last;
        }
    }
    bytectx *c = &s->c[sc];
    for (unsigned k = 0; k < s->n; k++) {
        if (s->L[k].size)
            last[k] = (uint8_t)(last[k] + lz_decode_lazy(&s->L[k].d, &c->m[k], 256));
        r[k] = last[k];
    }
    return 1;
}

/* ---- the chunk ------------------------------------------------------ */

int jf__laz_v3_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen)
{
    if (!count)
        return 0;
    size_t avail = (size_t)(end - p);
    if (avail < (size_t)rec_len + 4) {
        snprintf(msg, msglen, "point 0: the chunk's %zu bytes do not hold its first point's %u "
                 "and its point count", avail, rec_len);
        return -1;
    }
    memcpy(out, p, rec_len); /* the first point, raw */
    p += rec_len;
    uint32_t n = rd32(p);
    p += 4;
    if (n != count) {
        snprintf(msg, msglen, "the chunk says %u points, the chunk table %u", n, count);
        return -1;
    }
    lz_arena a = {0};
    p14 *pt = NULL;
    rgb14 *rgb = NULL;
    byte14 *by = NULL;
    unsigned off_rgb = 0, off_by = 0, nl = 0;
    unsigned nbytes = 0;
    for (unsigned i = 0; i < nitems; i++)
        nbytes += items[i].type == LZ_BYTE14 ? items[i].size : 0;
    layer **all = malloc(sizeof *all * (9 + 2 + nbytes));
    int ok = all != NULL;
    for (unsigned i = 0, o = 0; i < nitems && ok; o += items[i].size, i++) {
        const uint8_t *raw = out + o;
        if (items[i].type == LZ_POINT14) {
            ok = (pt = calloc(1, sizeof *pt)) != NULL;
            if (ok) {
                unsigned sc = (raw[15] >> 4) & 3;
                pt->cur = sc;
                ok = p14_ctx_init(&pt->c[sc], &a, NULL, raw);
                for (int k = 0; k < 9; k++)
                    all[nl++] = &pt->L[k];
            }
        } else if (items[i].type == LZ_RGB14 || items[i].type == LZ_RGBNIR14) {
            ok = (rgb = calloc(1, sizeof *rgb)) != NULL;
            if (ok) {
                uint16_t last[4] = {0};
                for (int k = 0; k < 4 && 2 * k + 1 < (int)items[i].size; k++)
                    last[k] = (uint16_t)(raw[2 * k] | raw[2 * k + 1] << 8);
                rgb->nir = items[i].type == LZ_RGBNIR14;
                rgb->cur = pt ? pt->cur : 0;
                ok = rgb_ctx_init(&rgb->c[rgb->cur], &a, last, rgb->nir);
                off_rgb = o;
                all[nl++] = &rgb->L[0];
                if (rgb->nir)
                    all[nl++] = &rgb->L[1];
            }
        } else { /* LZ_BYTE14: io_laz.c admits nothing else */
            ok = (by = calloc(1, sizeof *by)) != NULL &&
                 (by->L = calloc(items[i].size, sizeof *by->L)) != NULL;
            if (ok) {
                by->n = items[i].size;
                by->cur = pt ? pt->cur : 0;
                ok = byte_ctx_init(&by->c[by->cur], &a, raw, by->n);
                off_by = o;
                for (unsigned k = 0; k < by->n; k++)
                    all[nl++] = &by->L[k];
            }
        }
    }
    int rc = 0;
    if (!ok || !pt) {
        snprintf(msg, msglen, "out of memory for the decoder's models");
        rc = -1;
    }
    /* the layers' sizes, then the layers */
    if (!rc && (size_t)(end - p) / 4 < nl) {
        snprintf(msg, msglen, "point 1: the chunk ends in its table of %u layer sizes", nl);
        rc = -1;
    }
    for (unsigned k = 0; k < nl && !rc; k++, p += 4)
        all[k]->size = rd32(p);
    for (unsigned k = 0; k < nl && !rc; k++) {
        if (all[k]->size > (size_t)(end - p)) {
            snprintf(msg, msglen, "point 1: layer %u's %u bytes run past the chunk's end "
                     "(truncated chunk)", k, all[k]->size);
            rc = -1;
            break;
        }
        all[k]->p = p;
        if (all[k]->size)
            lz_dec_init(&all[k]->d, p, p + all[k]->size);
        else
            lz_dec_init(&all[k]->d, p, p); /* never read unless the stream is corrupt */
        all[k]->d.arena = &a;
        p += all[k]->size;
    }
    if (!rc && count > 1 && !pt->L[0].size) {
        snprintf(msg, msglen, "point 1: the chunk's x y layer is empty");
        rc = -1;
    }
    for (uint32_t j = 1; j < count && !rc; j++) {
        uint8_t *r = out + (size_t)j * rec_len;
        int sc = p14_decode(pt, &a, r);
        if (sc >= 0 && rgb && !rgb14_decode(rgb, &a, (unsigned)sc, r + off_rgb))
            sc = -1;
        if (sc >= 0 && by && !byte14_decode(by, &a, (unsigned)sc, r + off_by))
            sc = -1;
        if (sc < 0) {
            snprintf(msg, msglen, sc == -1 ? "out of memory for the decoder's models"
                                           : "point %u: corrupt GPS time layer", (unsigned)j);
            rc = -1;
        }
        for (unsigned k = 0; k < nl && !rc; k++)
            if (all[k]->d.over > 4 || all[k]->d.bad) {
                snprintf(msg, msglen, "point %u: layer %u %s", (unsigned)j, k,
                         all[k]->d.bad == 2 ? "needs a model: out of memory"
                         : all[k]->d.bad    ? "is corrupt"
                                            : "ends early (truncated or corrupt chunk)");
                rc = -1;
            }
    }
    /* as in version 2: each layer's decoder reads exactly its bytes */
    for (unsigned k = 0; k < nl && !rc; k++)
        if (all[k]->size && all[k]->d.p != all[k]->p + all[k]->size) {
            snprintf(msg, msglen, "point %u: layer %u has %zu bytes more than its points use "
                     "(corrupt chunk)", (unsigned)count - 1, k,
                     (size_t)(all[k]->p + all[k]->size - all[k]->d.p));
            rc = -1;
        }
    free(all);
    free(pt);
    free(rgb);
    if (by)
        free(by->L);
    free(by);
    lz_arena_free(&a);
    return rc;
}
