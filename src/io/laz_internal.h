/*
 * laz_internal.h -- the LAZ (LASzip) decoder's pieces (not part of the
 * public API): the items of the LASzip VLR, the chunk decoders of the
 * pointwise (version 2, laz_v2.c) and layered (version 3, laz_v3.c)
 * compressors, and the item models and contexts their encoders
 * (laz_v2_enc.c, laz_v3_enc.c) share with them: an encoder must make
 * exactly its decoder's predictions and model updates, so both call the
 * one copy below.  io_laz.c reads the VLR and the chunk table and calls
 * the decoders.
 */
#ifndef JF_LAZ_INTERNAL_H
#define JF_LAZ_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "laz_arith.h"

/* LASzip item types (laszip VLR, record 22204) */
enum {
    LZ_BYTE = 0,
    LZ_POINT10 = 6,
    LZ_GPSTIME11 = 7,
    LZ_RGB12 = 8,
    LZ_WAVEPACKET13 = 9,
    LZ_POINT14 = 10,
    LZ_RGB14 = 11,
    LZ_RGBNIR14 = 12,
    LZ_WAVEPACKET14 = 13,
    LZ_BYTE14 = 14
};

typedef struct {
    unsigned type, size, version;
} lz_item;

/* Decodes one chunk of `count` points from [p, end) into out (count
 * records of rec_len bytes, the items' sizes summing to rec_len).  0 on
 * success; otherwise -1 and msg (what is wrong, naming the point of the
 * chunk, 0-based) -- a stream that ends early, collapses or asks for an
 * impossible value; or out of memory. */
int jf__laz_v2_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen);
/* jf__laz_v2_chunk on a chunk whose end is not known (a chunk table to
 * rebuild): decodes from p on, end bounding the reads, and sets *used to
 * the bytes the chunk took (the decoder ends where the encoder did). */
int jf__laz_v2_chunk_len(const lz_item *items, unsigned nitems, unsigned rec_len,
                         const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                         size_t *used, char *msg, size_t msglen);
int jf__laz_v3_chunk(const lz_item *items, unsigned nitems, unsigned rec_len,
                     const uint8_t *p, const uint8_t *end, uint32_t count, uint8_t *out,
                     char *msg, size_t msglen);

/* The streaming median of five (LASzip's StreamingMedian5): the predictor
 * of the x and y differences. */
typedef struct {
    int32_t v[5];
    int high;
} lz_med;

static inline void lz_med_init(lz_med *m)
{
    for (int k = 0; k < 5; k++)
        m->v[k] = 0;
    m->high = 1;
}

static inline void lz_med_add(lz_med *m, int32_t x)
{
    int32_t *v = m->v;
    if (m->high) {
        if (x < v[2]) {
            v[4] = v[3], v[3] = v[2];
            if (x < v[0])
                v[2] = v[1], v[1] = v[0], v[0] = x;
            else if (x < v[1])
                v[2] = v[1], v[1] = x;
            else
                v[2] = x;
        } else {
            if (x < v[3])
                v[4] = v[3], v[3] = x;
            else
                v[4] = x;
            m->high = 0;
        }
    } else {
        if (v[2] < x) {
            v[0] = v[1], v[1] = v[2];
            if (v[4] < x)
                v[2] = v[3], v[3] = v[4], v[4] = x;
            else if (v[3] < x)
                v[2] = v[3], v[3] = x;
            else
                v[2] = x;
        } else {
            if (v[1] < x)
                v[0] = v[1], v[1] = x;
            else
                v[0] = x;
            m->high = 1;
        }
    }
}

/* The context tables of POINT10 (LASzip v2) by number of returns n and
 * return number r, completed for files that number returns from 0. */
extern const uint8_t jf__lz_return_map[8][8];
extern const uint8_t jf__lz_return_level[8][8];

/* ---- little-endian record fields ------------------------------------ */

static inline uint16_t lz_rd16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static inline uint32_t lz_rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static inline uint64_t lz_rd64(const uint8_t *p) { return lz_rd32(p) | (uint64_t)lz_rd32(p + 4) << 32; }
static inline void lz_wr16(uint8_t *p, uint32_t v) { p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8); }
static inline void lz_wr32(uint8_t *p, uint32_t v) { lz_wr16(p, v), lz_wr16(p + 2, v >> 16); }
/* LASzip's 32-bit products wrap (unsigned arithmetic: no signed overflow) */
static inline int32_t lz_mul32(int32_t a, int32_t b) { return (int32_t)((uint32_t)a * (uint32_t)b); }
static inline unsigned lz_clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

/* ---- GPS time (GPSTIME11 v2; POINT14's time, v3) ---------------------
 * design (LASzip): four sequences of times, each with its last time and
 * difference; a time is coded against the current sequence as a multiple
 * of its last difference (codes 1..499 and 500 up, 0 none, 501..509
 * negative), as a full time that starts a new sequence, or as a switch to
 * another sequence whose code follows.  Version 2 also has an
 * "unchanged" code (u = 1): its codes are those of version 3 (u = 0) moved
 * up by one where they follow it. */
#define LZ_GPS_MULTI 500
#define LZ_GPS_MULTI_MINUS (-10)
#define LZ_GPS_UNCHANGED (LZ_GPS_MULTI - LZ_GPS_MULTI_MINUS + 1) /* u = 1 only */
#define LZ_GPS_CODE_FULL(u) (LZ_GPS_MULTI - LZ_GPS_MULTI_MINUS + 1 + (u))
#define LZ_GPS_TOTAL(u) (LZ_GPS_MULTI - LZ_GPS_MULTI_MINUS + 5 + (u))

typedef struct {
    uint64_t t[4];       /* each sequence's last time */
    int32_t diff[4];     /* and last difference (0: none yet) */
    uint32_t extreme[4]; /* extreme multipliers in a row */
    unsigned last, next; /* the current sequence, the one a full time starts */
    lz_sym multi, zero;  /* the code with a difference, without one */
    lz_ic ic;
} lz_gps;

static inline int lz_gps_init(lz_gps *g, lz_arena *a, uint64_t t)
{
    memset(g, 0, sizeof *g);
    g->t[0] = t;
    return lz_ic_init(&g->ic, a, 32, 9, 8, 0);
}

/* The extreme multipliers: after 4 in a row the difference is adopted. */
static inline void lz_gps_extreme(lz_gps *g, int32_t diff)
{
    if (++g->extreme[g->last] > 3) {
        g->diff[g->last] = diff;
        g->extreme[g->last] = 0;
    }
}

/* A full time t starts the next sequence. */
static inline void lz_gps_start(lz_gps *g, uint64_t t)
{
    g->next = (g->next + 1) & 3;
    g->last = g->next;
    g->t[g->last] = t;
    g->diff[g->last] = 0;
    g->extreme[g->last] = 0;
}

/* A full time: the high 32 bits predicted from the current sequence's. */
static inline void lz_gps_decode_full(lz_gps *g, lz_dec *d)
{
    int32_t hi = lz_ic_decode(d, &g->ic, (int32_t)(g->t[g->last] >> 32), 8);
    lz_gps_start(g, (uint64_t)(uint32_t)hi << 32 | lz_read_int(d));
}

/* The next time into g->t[g->last]; 0 if the stream switches sequence
 * twice in a row (the encoder never does). */
static inline int lz_gps_decode(lz_gps *g, lz_dec *d, unsigned u)
{
    for (int hops = 0;; hops++) {
        if (hops > 1)
            return 0;
        unsigned L = g->last;
        if (g->diff[L] == 0) {
            uint32_t multi = lz_decode_lazy(d, &g->zero, 5 + u);
            if (multi == u) {
                g->diff[L] = lz_ic_decode(d, &g->ic, 0, 0);
                g->t[L] += (uint64_t)(int64_t)g->diff[L];
                g->extreme[L] = 0;
            } else if (multi == u + 1) {
                lz_gps_decode_full(g, d);
            } else if (multi > u + 1) {
                g->last = (L + multi - u - 1) & 3;
                continue;
            } /* else 0 with u = 1: unchanged */
        } else {
            uint32_t multi = lz_decode_lazy(d, &g->multi, LZ_GPS_TOTAL(u));
            if (multi == 1) {
                g->t[L] += (uint64_t)(int64_t)lz_ic_decode(d, &g->ic, g->diff[L], 1);
                g->extreme[L] = 0;
            } else if (multi < LZ_GPS_CODE_FULL(0)) {
                int32_t diff;
                if (multi == 0) {
                    diff = lz_ic_decode(d, &g->ic, 0, 7);
                    lz_gps_extreme(g, diff);
                } else if (multi < LZ_GPS_MULTI) {
                    diff = lz_ic_decode(d, &g->ic, lz_mul32((int32_t)multi, g->diff[L]),
                                        multi < 10 ? 2 : 3);
                } else if (multi == LZ_GPS_MULTI) {
                    diff = lz_ic_decode(d, &g->ic, lz_mul32(LZ_GPS_MULTI, g->diff[L]), 4);
                    lz_gps_extreme(g, diff);
                } else {
                    int32_t mm = LZ_GPS_MULTI - (int32_t)multi;
                    if (mm > LZ_GPS_MULTI_MINUS) {
                        diff = lz_ic_decode(d, &g->ic, lz_mul32(mm, g->diff[L]), 5);
                    } else {
                        diff = lz_ic_decode(d, &g->ic, lz_mul32(LZ_GPS_MULTI_MINUS, g->diff[L]), 6);
                        lz_gps_extreme(g, diff);
                    }
                }
                g->t[L] += (uint64_t)(int64_t)diff;
            } else if (multi == LZ_GPS_CODE_FULL(u)) {
                lz_gps_decode_full(g, d);
            } else if (multi > LZ_GPS_CODE_FULL(u)) {
                g->last = (L + multi - LZ_GPS_CODE_FULL(u)) & 3;
                continue;
            } /* else LZ_GPS_UNCHANGED with u = 1 */
        }
        break;
    }
    return 1;
}

/* ---- RGB12 v2, RGB14 v3 ---------------------------------------------- */

/* The colour v from the last l, byte-wise: red's bytes from its own,
 * green's and blue's predicted from red's change (LASzip RGB12 v2). */
LZ_INLINE void lz_rgb_decode(lz_dec *d, lz_sym *used, lz_sym *df, const uint16_t *l, unsigned *v)
{
    unsigned sym = lz_decode_lazy(d, used, 128);
    v[0] = sym & 1 ? (lz_decode_lazy(d, &df[0], 256) + (l[0] & 0xFF)) & 0xFF : l[0] & 0xFF;
    v[0] |= sym & 2 ? ((lz_decode_lazy(d, &df[1], 256) + (l[0] >> 8)) & 0xFF) << 8 : l[0] & 0xFF00u;
    if (sym & 64) {
        int diff = (int)(v[0] & 0xFF) - (l[0] & 0xFF);
        v[1] = sym & 4 ? (lz_decode_lazy(d, &df[2], 256) + lz_clamp8(diff + (l[1] & 0xFF))) & 0xFF
                       : l[1] & 0xFFu;
        if (sym & 16) {
            diff = (diff + (int)(v[1] & 0xFF) - (l[1] & 0xFF)) / 2;
            v[2] = (lz_decode_lazy(d, &df[4], 256) + lz_clamp8(diff + (l[2] & 0xFF))) & 0xFF;
        } else {
            v[2] = l[2] & 0xFFu;
        }
        diff = (int)(v[0] >> 8) - (l[0] >> 8);
        if (sym & 8)
            v[1] |= ((lz_decode_lazy(d, &df[3], 256) + lz_clamp8(diff + (l[1] >> 8))) & 0xFF) << 8;
        else
            v[1] |= l[1] & 0xFF00u;
        if (sym & 32) {
            diff = (diff + (int)(v[1] >> 8) - (l[1] >> 8)) / 2;
            v[2] |= ((lz_decode_lazy(d, &df[5], 256) + lz_clamp8(diff + (l[2] >> 8))) & 0xFF) << 8;
        } else {
            v[2] |= l[2] & 0xFF00u;
        }
    } else {
        v[1] = v[2] = v[0];
    }
}

/* RGB14's four channel sets (LASzip v3: one per scanner channel). */
typedef struct {
    int used;
    uint16_t last[4]; /* r g b nir */
    lz_sym rgb_used, rgb_diff[6], nir_used, nir_diff[2];
} lz_rgbctx;

typedef struct {
    lz_rgbctx c[4];
    unsigned cur;
    int nir;
} lz_rgb14;

/* The chunk's first point `raw` (size bytes) starts channel sc's set. */
static inline void lz_rgb14_start(lz_rgb14 *s, unsigned sc, int nir, const uint8_t *raw,
                                  unsigned size)
{
    memset(&s->c[sc], 0, sizeof s->c[sc]);
    for (unsigned k = 0; k < 4 && 2 * k + 1 < size; k++)
        s->c[sc].last[k] = lz_rd16(raw + 2 * k);
    s->c[sc].used = 1;
    s->cur = sc, s->nir = nir;
}

/* Switches to channel sc; the colour to predict from: LASzip keeps the
 * old channel's last unless the new channel's set is fresh (its quirk,
 * kept). */
static inline uint16_t *lz_rgb14_switch(lz_rgb14 *s, unsigned sc)
{
    uint16_t *last = s->c[s->cur].last;
    if (s->cur != sc) {
        s->cur = sc;
        if (!s->c[sc].used) {
            memset(&s->c[sc], 0, sizeof s->c[sc]);
            memcpy(s->c[sc].last, last, sizeof s->c[sc].last);
            s->c[sc].used = 1;
            last = s->c[sc].last;
        }
    }
    return last;
}

/* ---- BYTE v2, BYTE14 v3 --------------------------------------------- */

/* n extra bytes: the last ones, one model each (made on first use). */
typedef struct {
    int used;
    uint8_t *last;
    lz_sym *m;
} lz_bytes;

static inline int lz_bytes_init(lz_bytes *c, lz_arena *a, const uint8_t *last, unsigned n)
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

/* BYTE14's four channel sets. */
typedef struct {
    lz_bytes c[4];
    unsigned cur, n;
} lz_byte14;

/* Switches to channel sc; the bytes to predict from (as lz_rgb14_switch:
 * the old channel's unless the new set is fresh), NULL out of memory. */
static inline uint8_t *lz_byte14_switch(lz_byte14 *s, lz_arena *a, unsigned sc)
{
    uint8_t *last = s->c[s->cur].last;
    if (s->cur != sc) {
        s->cur = sc;
        if (!s->c[sc].used) {
            if (!lz_bytes_init(&s->c[sc], a, last, s->n))
                return NULL;
            last = s->c[sc].last;
        }
    }
    return last;
}

/* ---- POINT10 v2 ----------------------------------------------------- */

/* The models and predictor state of POINT10 beside its last point. */
typedef struct {
    uint16_t last_int[16]; /* by return context */
    lz_med mx[16], my[16]; /* x, y differences by return context */
    int32_t last_h[8];     /* z by return level */
    lz_sym changed, sar_m[2];
    lz_ic ic_int, ic_psid, ic_dx, ic_dy, ic_z;
} lz_p10;

static inline int lz_p10_init(lz_p10 *s, lz_arena *a)
{
    memset(s, 0, sizeof *s);
    for (int k = 0; k < 16; k++)
        lz_med_init(&s->mx[k]), lz_med_init(&s->my[k]);
    return lz_ic_init(&s->ic_int, a, 16, 4, 8, 0) && lz_ic_init(&s->ic_psid, a, 16, 1, 8, 0) &&
           lz_ic_init(&s->ic_dx, a, 32, 2, 8, 0) && lz_ic_init(&s->ic_dy, a, 32, 22, 8, 0) &&
           lz_ic_init(&s->ic_z, a, 32, 20, 8, 0);
}

/* y's context from x's k, z's from x's and y's (nr: number of returns) */
static inline uint32_t lz_p10_y_ctx(const lz_p10 *s, unsigned nr)
{
    uint32_t k = s->ic_dx.k;
    return (nr == 1) + (k < 20 ? k & ~1u : 20);
}
static inline uint32_t lz_p10_z_ctx(const lz_p10 *s, unsigned nr)
{
    uint32_t k = (s->ic_dx.k + s->ic_dy.k) / 2;
    return (nr == 1) + (k < 18 ? k & ~1u : 18);
}

/* ---- POINT14 v3 ----------------------------------------------------- */

typedef struct {
    uint32_t x, y, z;
    uint16_t intensity, sangle, psid;
    uint8_t rn, nr, cflags, sc, sdir, eof, cls, ud;
    uint64_t gps;
} lz_p14pt;

static inline void lz_p14_unpack(lz_p14pt *c, const uint8_t *r)
{
    c->x = lz_rd32(r), c->y = lz_rd32(r + 4), c->z = lz_rd32(r + 8);
    c->intensity = lz_rd16(r + 12);
    c->rn = r[14] & 15, c->nr = r[14] >> 4;
    c->cflags = r[15] & 15, c->sc = (r[15] >> 4) & 3, c->sdir = (r[15] >> 6) & 1,
    c->eof = r[15] >> 7;
    c->cls = r[16], c->ud = r[17];
    c->sangle = lz_rd16(r + 18);
    c->psid = lz_rd16(r + 20);
    c->gps = lz_rd64(r + 22);
}

/* One scanner channel's set: its last point, models and predictors. */
typedef struct {
    int used, gps_change;
    lz_p14pt v;
    lz_sym changed[8], sc_m, rn_same;
    lz_sym *nr_m[16], *rn_m[16], *cls_m[64], *flag_m[64], *ud_m[64]; /* made on first use */
    lz_ic dx, dy, iz, iint, isa, ips;
    uint16_t last_int[8];
    int32_t last_z[8];
    lz_med mx[12], my[12];
    lz_gps g;
} lz_p14ctx;

/* A channel's set, started from point v (LASzip: the z and intensity
 * contexts all at its values, GPS sequence 0 at its time). */
static inline int lz_p14_init(lz_p14ctx *c, lz_arena *a, const lz_p14pt *v)
{
    lz_p14pt v0 = *v;
    memset(c, 0, sizeof *c);
    c->v = v0;
    c->used = 1;
    for (int k = 0; k < 8; k++)
        c->last_int[k] = v0.intensity, c->last_z[k] = (int32_t)v0.z;
    for (int k = 0; k < 12; k++)
        lz_med_init(&c->mx[k]), lz_med_init(&c->my[k]);
    return lz_ic_init(&c->dx, a, 32, 2, 8, 0) && lz_ic_init(&c->dy, a, 32, 22, 8, 0) &&
           lz_ic_init(&c->iz, a, 32, 20, 8, 0) && lz_ic_init(&c->iint, a, 16, 4, 8, 0) &&
           lz_ic_init(&c->isa, a, 16, 2, 8, 0) && lz_ic_init(&c->ips, a, 16, 1, 8, 0) &&
           lz_gps_init(&c->g, a, v0.gps);
}

/* The contexts of POINT14 v3 (n returns, rn the return number, gpsc
 * whether the time changed): the change flags' from the previous point */
static inline unsigned lz_p14_changed_ctx(const lz_p14ctx *prev)
{
    return (prev->v.rn == 1) | (prev->v.rn >= prev->v.nr) << 1 | (unsigned)prev->gps_change << 2;
}
/* x's and y's median predictors */
static inline unsigned lz_p14_xy_ctx(unsigned n, unsigned rn, int gpsc)
{
    static const uint8_t map6[16][16] = {
        {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
        {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
        {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
        {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
        {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
        {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
    return (unsigned)map6[n][rn] << 1 | (unsigned)gpsc;
}
/* y's corrector from x's k */
static inline uint32_t lz_p14_y_ctx(const lz_p14ctx *c, unsigned n)
{
    return (n == 1) | ((c->dx.k < 20 ? c->dx.k : 20) & ~1u);
}
/* z's corrector from x's and y's k */
static inline uint32_t lz_p14_z_ctx(const lz_p14ctx *c, unsigned n)
{
    uint32_t k = (c->dx.k + c->dy.k) / 2;
    return (n == 1) | ((k < 18 ? k : 18) & ~1u);
}
/* z's predictor: the last z of the return level |n - rn|, capped at 7 */
static inline unsigned lz_p14_level(unsigned n, unsigned rn)
{
    return n > rn ? (n - rn > 7 ? 7 : n - rn) : (rn - n > 7 ? 7 : rn - n);
}
/* the classification's model from the last class */
static inline unsigned lz_p14_cls_ctx(unsigned n, unsigned rn, unsigned cls)
{
    return (rn == 1 && rn >= n) | (cls & 0x1Fu) << 1;
}
/* the flags as one symbol (and the model of the next) */
static inline unsigned lz_p14_flags(const lz_p14pt *v)
{
    return v->cflags | (unsigned)v->sdir << 4 | (unsigned)v->eof << 5;
}
/* the intensity's predictor and corrector context (ic >> 1) */
static inline unsigned lz_p14_int_ctx(unsigned n, unsigned rn, int gpsc)
{
    return (unsigned)gpsc | (rn >= n) << 1 | (rn == 1) << 2;
}

#endif /* JF_LAZ_INTERNAL_H */
