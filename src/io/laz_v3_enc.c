/*
 * laz_v3_enc.c -- LASzip's layered compressors, item version 3, as
 * encoders: POINT14, RGB14, RGBNIR14 and BYTE14 for the LAS 1.4 point
 * formats 6-8 (laszip VLR compressor 3).
 *
 * design: the mirror of laz_v3.c.  Every point after the chunk's first
 * goes through the decoder's steps with the value known: the same models,
 * contexts, scanner-channel sets (and their quirks) and predictions, each
 * field into its layer's own encoder.  A layer whose field never changed
 * in the chunk (z, classification, flags, intensity, user data, colour,
 * NIR, each extra byte) or that no point needed (scan angle, source,
 * GPS time) is written with size 0: the decoder then keeps the field, as
 * it was.  The chunk: the first point raw, the point count, the layers'
 * sizes, the layers.
 */
#include <stdlib.h>
#include <string.h>

#include "laz_enc.h"
#include "laz_internal.h"

int jf__lz_gps_multi(int32_t d, int32_t last);
void jf__lz_rgb_encode(lz_enc *e, lz_sym *used, lz_sym *diff, const uint16_t *l,
                       const unsigned *v);

static const uint8_t map6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};

static unsigned level8(unsigned n, unsigned r) { return n > r ? (n - r > 7 ? 7 : n - r) : (r - n > 7 ? 7 : r - n); }

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }
static int32_t mul32(int32_t a, int32_t b) { return (int32_t)((uint32_t)a * (uint32_t)b); }

/* One layer: its encoder, and whether the field changed (or was used). */
typedef struct {
    lz_enc e;
    int changed;
} layer;

/* ---- POINT14 -------------------------------------------------------- */

#define GPS_MULTI 500
#define GPS_MULTI_MINUS (-10)
#define GPS_CODE_FULL (GPS_MULTI - GPS_MULTI_MINUS + 1)
#define GPS_TOTAL (GPS_MULTI - GPS_MULTI_MINUS + 5)

typedef struct {
    uint32_t x, y, z;
    uint16_t intensity, sangle, psid;
    uint8_t rn, nr, cflags, sc, sdir, eof, cls, ud;
    uint64_t gps;
} p14pt;

typedef struct {
    int used, gps_change;
    p14pt v;
    lz_sym changed[8], sc_m, rn_same, gmulti, g0;
    lz_sym nr_m[16], rn_m[16], cls_m[64], flag_m[64], ud_m[64];
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

static void unpack(p14pt *c, const uint8_t *r)
{
    c->x = rd32(r), c->y = rd32(r + 4), c->z = rd32(r + 8);
    c->intensity = rd16(r + 12);
    c->rn = r[14] & 15, c->nr = r[14] >> 4;
    c->cflags = r[15] & 15, c->sc = (r[15] >> 4) & 3, c->sdir = (r[15] >> 6) & 1,
    c->eof = r[15] >> 7;
    c->cls = r[16], c->ud = r[17];
    c->sangle = rd16(r + 18);
    c->psid = rd16(r + 20);
    c->gps = rd32(r + 22) | (uint64_t)rd32(r + 26) << 32;
}

/* A channel's set from the point `v` (laz_v3.c's p14_ctx_init). */
static int ctx_init(p14ctx *c, lz_arena *a, const p14pt *v)
{
    memset(c, 0, sizeof *c);
    c->v = *v;
    c->used = 1;
    for (int k = 0; k < 8; k++)
        c->last_int[k] = v->intensity, c->last_z[k] = (int32_t)v->z;
    for (int k = 0; k < 12; k++)
        lz_med_init(&c->mx[k]), lz_med_init(&c->my[k]);
    c->gt[0] = v->gps;
    return lz_ic_init(&c->dx, a, 32, 2, 8, 0) && lz_ic_init(&c->dy, a, 32, 22, 8, 0) &&
           lz_ic_init(&c->iz, a, 32, 20, 8, 0) && lz_ic_init(&c->iint, a, 16, 4, 8, 0) &&
           lz_ic_init(&c->isa, a, 16, 2, 8, 0) && lz_ic_init(&c->ips, a, 16, 1, 8, 0) &&
           lz_ic_init(&c->igps, a, 32, 9, 8, 0);
}

static void gps_extreme(p14ctx *c, int32_t diff)
{
    if (++c->gext[c->gseq] > 3) {
        c->gext[c->gseq] = 0;
        c->gdiff[c->gseq] = diff;
    }
}

static void gps_full(p14ctx *c, lz_enc *e, uint64_t t)
{
    lz_ic_encode(e, &c->igps, (int32_t)(c->gt[c->gseq] >> 32), (int32_t)(t >> 32), 8);
    lz_write_int(e, (uint32_t)t);
    c->gnext = (c->gnext + 1) & 3;
    c->gseq = c->gnext;
    c->gt[c->gseq] = t;
    c->gdiff[c->gseq] = 0;
    c->gext[c->gseq] = 0;
}

static unsigned gps_other(const p14ctx *c, uint64_t t)
{
    for (unsigned i = 1; i < 4; i++) {
        int64_t d = (int64_t)(t - c->gt[(c->gseq + i) & 3]);
        if (d == (int32_t)d)
            return i;
    }
    return 0;
}

/* GPS time t (not the last): laz_v3.c's p14_gps mirrored. */
static void gps_encode(p14ctx *c, lz_enc *e, uint64_t t)
{
    for (;;) {
        unsigned s = c->gseq;
        int64_t d64 = (int64_t)(t - c->gt[s]);
        int32_t d = (int32_t)d64;
        if (c->gdiff[s] == 0) {
            if (d64 == d) {
                lz_encode_lazy(e, &c->g0, 5, 0);
                lz_ic_encode(e, &c->igps, 0, d, 0);
                c->gdiff[s] = d;
                c->gt[s] = t;
                c->gext[s] = 0;
            } else {
                unsigned i = gps_other(c, t);
                if (i) {
                    lz_encode_lazy(e, &c->g0, 5, i + 1);
                    c->gseq = (s + i) & 3;
                    continue;
                }
                lz_encode_lazy(e, &c->g0, 5, 1);
                gps_full(c, e, t);
            }
        } else if (d64 == d) {
            int multi = jf__lz_gps_multi(d, c->gdiff[s]);
            if (multi == 1) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, 1);
                lz_ic_encode(e, &c->igps, c->gdiff[s], d, 1);
                c->gext[s] = 0;
            } else if (multi > 0 && multi < GPS_MULTI) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, (uint32_t)multi);
                lz_ic_encode(e, &c->igps, mul32(multi, c->gdiff[s]), d, multi < 10 ? 2 : 3);
            } else if (multi >= GPS_MULTI) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, GPS_MULTI);
                lz_ic_encode(e, &c->igps, mul32(GPS_MULTI, c->gdiff[s]), d, 4);
                gps_extreme(c, d);
            } else if (multi < 0 && multi > GPS_MULTI_MINUS) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, (uint32_t)(GPS_MULTI - multi));
                lz_ic_encode(e, &c->igps, mul32(multi, c->gdiff[s]), d, 5);
            } else if (multi < 0) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, GPS_MULTI - GPS_MULTI_MINUS);
                lz_ic_encode(e, &c->igps, mul32(GPS_MULTI_MINUS, c->gdiff[s]), d, 6);
                gps_extreme(c, d);
            } else {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, 0);
                lz_ic_encode(e, &c->igps, 0, d, 7);
                gps_extreme(c, d);
            }
            c->gt[s] = t;
        } else {
            unsigned i = gps_other(c, t);
            if (i) {
                lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, GPS_CODE_FULL + i);
                c->gseq = (s + i) & 3;
                continue;
            }
            lz_encode_lazy(e, &c->gmulti, GPS_TOTAL, GPS_CODE_FULL);
            gps_full(c, e, t);
        }
        break;
    }
}

/* One point; the other items' context (laz_v3.c: the new channel on a
 * switch, else 0), or -1 out of memory. */
static int p14_encode(p14 *s, lz_arena *a, const uint8_t *r)
{
    p14pt nv;
    unpack(&nv, r);
    p14ctx *prev = &s->c[s->cur];
    unsigned lpr = (prev->v.rn == 1) | (prev->v.rn >= prev->v.nr) << 1 |
                   (unsigned)prev->gps_change << 2;
    unsigned sc = nv.sc;
    int sw = sc != s->cur;
    p14ctx *c = &s->c[sc];
    if (sw && !c->used) { /* a new channel starts from the previous point */
        p14pt from = prev->v;
        if (!ctx_init(c, a, &from))
            return -1;
    }
    p14pt *o = &c->v;
    unsigned rnc = nv.rn == o->rn                ? 0
                   : nv.rn == ((o->rn + 1) & 15) ? 1
                   : nv.rn == ((o->rn + 15) & 15) ? 2
                                                  : 3;
    int gpsc = nv.gps != o->gps;
    unsigned cv = rnc | (unsigned)(nv.nr != o->nr) << 2 | (unsigned)(nv.sangle != o->sangle) << 3 |
                  (unsigned)gpsc << 4 | (unsigned)(nv.psid != o->psid) << 5 | (unsigned)sw << 6;
    lz_enc *xy = &s->L[0].e;
    lz_encode_lazy(xy, &prev->changed[lpr], 128, cv);
    if (sw) {
        lz_encode_lazy(xy, &prev->sc_m, 3, (sc + 3 - s->cur) & 3);
        s->cur = sc;
        o->sc = (uint8_t)sc;
    }
    if (cv & 4) {
        lz_encode_lazy(xy, &c->nr_m[o->nr], 16, nv.nr);
        o->nr = nv.nr;
    }
    if (rnc == 3) {
        if (gpsc)
            lz_encode_lazy(xy, &c->rn_m[o->rn], 16, nv.rn);
        else
            lz_encode_lazy(xy, &c->rn_same, 13, (nv.rn + 14 - o->rn) & 15);
    }
    o->rn = nv.rn;
    unsigned n = nv.nr, rn = nv.rn;
    unsigned ctx = (unsigned)map6[n][rn] << 1 | (unsigned)gpsc;
    int32_t diff = (int32_t)(nv.x - o->x);
    lz_ic_encode(xy, &c->dx, c->mx[ctx].v[2], diff, n == 1);
    lz_med_add(&c->mx[ctx], diff);
    o->x = nv.x;
    uint32_t k = (c->dx.k < 20 ? c->dx.k : 20) & ~1u;
    diff = (int32_t)(nv.y - o->y);
    lz_ic_encode(xy, &c->dy, c->my[ctx].v[2], diff, (n == 1) | k);
    lz_med_add(&c->my[ctx], diff);
    o->y = nv.y;
    /* z from the last z of the same return level */
    k = (c->dx.k + c->dy.k) / 2;
    k = (k < 18 ? k : 18) & ~1u;
    unsigned l = level8(n, rn);
    s->L[1].changed |= nv.z != o->z;
    lz_ic_encode(&s->L[1].e, &c->iz, c->last_z[l], (int32_t)nv.z, (n == 1) | k);
    c->last_z[l] = (int32_t)nv.z;
    o->z = nv.z;
    unsigned cc = (rn == 1 && rn >= n) | (o->cls & 0x1Fu) << 1;
    s->L[2].changed |= nv.cls != o->cls;
    lz_encode_lazy(&s->L[2].e, &c->cls_m[cc], 256, nv.cls);
    o->cls = nv.cls;
    unsigned f0 = o->cflags | o->sdir << 4 | o->eof << 5,
             f1 = nv.cflags | nv.sdir << 4 | nv.eof << 5;
    s->L[3].changed |= f0 != f1;
    lz_encode_lazy(&s->L[3].e, &c->flag_m[f0], 64, f1);
    o->cflags = nv.cflags, o->sdir = nv.sdir, o->eof = nv.eof;
    unsigned ic = (unsigned)gpsc | (rn >= n) << 1 | (rn == 1) << 2;
    s->L[4].changed |= nv.intensity != o->intensity;
    lz_ic_encode(&s->L[4].e, &c->iint, c->last_int[ic], nv.intensity, ic >> 1);
    o->intensity = c->last_int[ic] = nv.intensity;
    if (cv & 8) {
        s->L[5].changed = 1;
        lz_ic_encode(&s->L[5].e, &c->isa, (int16_t)o->sangle, (int16_t)nv.sangle, gpsc);
        o->sangle = nv.sangle;
    }
    s->L[6].changed |= nv.ud != o->ud;
    lz_encode_lazy(&s->L[6].e, &c->ud_m[o->ud / 4], 256, nv.ud);
    o->ud = nv.ud;
    if (cv & 32) {
        s->L[7].changed = 1;
        lz_ic_encode(&s->L[7].e, &c->ips, o->psid, nv.psid, 0);
        o->psid = nv.psid;
    }
    if (gpsc) {
        s->L[8].changed = 1;
        gps_encode(c, &s->L[8].e, nv.gps);
        o->gps = nv.gps;
    }
    c->gps_change = gpsc;
    return sw ? (int)sc : 0;
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

static void rgb14_encode(rgb14 *s, unsigned sc, const uint8_t *r)
{
    uint16_t *last = s->c[s->cur].last; /* the decoder's quirk: the old
                                           channel's last unless fresh */
    if (s->cur != sc) {
        s->cur = sc;
        if (!s->c[sc].used) {
            memset(&s->c[sc], 0, sizeof s->c[sc]);
            memcpy(s->c[sc].last, last, sizeof s->c[sc].last);
            s->c[sc].used = 1;
            last = s->c[sc].last;
        }
    }
    rgbctx *c = &s->c[sc];
    unsigned v[4];
    for (int k = 0; k < 3; k++)
        v[k] = rd16(r + 2 * k);
    s->L[0].changed |= v[0] != last[0] || v[1] != last[1] || v[2] != last[2];
    jf__lz_rgb_encode(&s->L[0].e, &c->rgb_used, c->rgb_diff, last, v);
    for (int k = 0; k < 3; k++)
        last[k] = (uint16_t)v[k];
    if (s->nir) {
        lz_enc *e = &s->L[1].e;
        unsigned l = last[3], x = rd16(r + 6);
        unsigned sym = (unsigned)((l & 0xFF) != (x & 0xFF)) | (unsigned)((l >> 8) != (x >> 8)) << 1;
        s->L[1].changed |= x != l;
        lz_encode_lazy(e, &c->nir_used, 4, sym);
        if (sym & 1)
            lz_encode_lazy(e, &c->nir_diff[0], 256, (x - l) & 0xFF);
        if (sym & 2)
            lz_encode_lazy(e, &c->nir_diff[1], 256, ((x >> 8) - (l >> 8)) & 0xFF);
        last[3] = (uint16_t)x;
    }
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
    memset(c->m, 0, sizeof(lz_sym) * n);
    return 1;
}

static int byte14_encode(byte14 *s, lz_arena *a, unsigned sc, const uint8_t *r)
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
        s->L[k].changed |= r[k] != last[k];
        lz_encode_lazy(&s->L[k].e, &c->m[k], 256, (uint8_t)(r[k] - last[k]));
        last[k] = r[k];
    }
    return 1;
}

/* ---- the chunk ------------------------------------------------------ */

static void put32(lz_enc *o, uint32_t v)
{
    uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    lz_put_bytes(o, b, 4);
}

int jf__laz_v3_encode(const lz_item *items, unsigned nitems, unsigned rec_len,
                      const uint8_t *recs, uint32_t count, lz_enc *out)
{
    if (!count)
        return 0;
    lz_arena a = {0};
    p14 *pt = NULL;
    rgb14 *rgb = NULL;
    byte14 *by = NULL;
    unsigned off_rgb = 0, off_by = 0, nl = 0, nbytes = 0;
    for (unsigned i = 0; i < nitems; i++)
        nbytes += items[i].type == LZ_BYTE14 ? items[i].size : 0;
    layer **all = malloc(sizeof *all * (9 + 2 + nbytes));
    int ok = all != NULL;
    for (unsigned i = 0, o = 0; i < nitems && ok; o += items[i].size, i++) {
        const uint8_t *raw = recs + o;
        if (items[i].type == LZ_POINT14) {
            ok = (pt = calloc(1, sizeof *pt)) != NULL;
            if (ok) {
                p14pt v;
                unpack(&v, raw);
                pt->cur = v.sc;
                ok = ctx_init(&pt->c[v.sc], &a, &v);
                for (int k = 0; k < 9; k++)
                    all[nl++] = &pt->L[k];
            }
        } else if (items[i].type == LZ_RGB14 || items[i].type == LZ_RGBNIR14) {
            ok = (rgb = calloc(1, sizeof *rgb)) != NULL;
            if (ok) {
                rgb->nir = items[i].type == LZ_RGBNIR14;
                rgb->cur = pt ? pt->cur : 0;
                for (int k = 0; k < (rgb->nir ? 4 : 3); k++)
                    rgb->c[rgb->cur].last[k] = rd16(raw + 2 * k);
                rgb->c[rgb->cur].used = 1;
                off_rgb = o;
                all[nl++] = &rgb->L[0];
                if (rgb->nir)
                    all[nl++] = &rgb->L[1];
            }
        } else { /* LZ_BYTE14 */
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
    ok = ok && pt;
    for (unsigned k = 0; k < nl; k++)
        lz_enc_init(&all[k]->e, &a);
    for (uint32_t j = 1; j < count && ok; j++) {
        const uint8_t *r = recs + (size_t)j * rec_len;
        int sc = p14_encode(pt, &a, r);
        if (sc >= 0 && rgb)
            rgb14_encode(rgb, (unsigned)sc, r + off_rgb);
        if (sc >= 0 && by && !byte14_encode(by, &a, (unsigned)sc, r + off_by))
            sc = -1;
        ok = sc >= 0;
    }
    if (ok && count > 1)
        pt->L[0].changed = 1; /* x y and the change flags: always */
    /* the first point raw, the count, the sizes, the layers */
    lz_put_bytes(out, recs, rec_len);
    put32(out, count);
    for (unsigned k = 0; k < nl && ok; k++) {
        if (all[k]->changed)
            lz_enc_done(&all[k]->e);
        ok = !all[k]->e.nomem;
        put32(out, all[k]->changed ? (uint32_t)all[k]->e.len : 0);
    }
    for (unsigned k = 0; k < nl && ok; k++)
        if (all[k]->changed)
            lz_put_bytes(out, all[k]->e.buf, all[k]->e.len);
    ok = ok && !a.failed && !out->nomem;
    for (unsigned k = 0; k < nl; k++)
        lz_enc_free(&all[k]->e);
    free(all);
    free(pt);
    free(rgb);
    if (by)
        free(by->L);
    free(by);
    lz_arena_free(&a);
    return ok ? 0 : -1;
}
