/*
 * laz_v2_enc.c -- LASzip's pointwise compressors, item version 2, as
 * encoders: POINT10, GPSTIME11, RGB12 and BYTE, for point formats 0-3
 * (laszip VLR compressor 2).  Each is the mirror of its decoder in
 * laz_v2.c: the same predictions from the same state, so that the state
 * after each point is the decoder's (Isenburg 2013, "LASzip: lossless
 * compression of LiDAR data", section 3).
 */
#include <stdlib.h>
#include <string.h>

#include "laz_enc.h"
#include "laz_internal.h"

static uint32_t rd32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}
static uint16_t rd16(const uint8_t *p) { return (uint16_t)(p[0] | p[1] << 8); }

/* ---- POINT10 -------------------------------------------------------- */

typedef struct {
    uint8_t last[20];
    uint16_t last_int[16];
    lz_med mx[16], my[16];
    int32_t last_h[8];
    lz_sym changed, sar_m[2];
    lz_sym bitm[256], clsm[256], udm[256];
    lz_ic ic_int, ic_psid, ic_dx, ic_dy, ic_z;
} p10e;

static int p10_init(p10e *s, lz_arena *a, const uint8_t *r)
{
    memset(s, 0, sizeof *s);
    memcpy(s->last, r, 20);
    for (int k = 0; k < 16; k++)
        lz_med_init(&s->mx[k]), lz_med_init(&s->my[k]);
    return lz_ic_init(&s->ic_int, a, 16, 4, 8, 0) &&
           lz_ic_init(&s->ic_psid, a, 16, 1, 8, 0) && lz_ic_init(&s->ic_dx, a, 32, 2, 8, 0) &&
           lz_ic_init(&s->ic_dy, a, 32, 22, 8, 0) && lz_ic_init(&s->ic_z, a, 32, 20, 8, 0);
}

static void p10_encode(p10e *s, lz_enc *e, const uint8_t *r)
{
    const uint8_t *l = s->last;
    unsigned rn = r[14] & 7, nr = (r[14] >> 3) & 7;
    unsigned m = jf__lz_return_map[nr][rn], lv = jf__lz_return_level[nr][rn];
    uint16_t in = rd16(r + 12), psid = rd16(r + 18);
    /* which fields changed: bit byte, intensity (against its return
     * context's), classification, scan angle rank, user data, source */
    unsigned cv = (unsigned)(l[14] != r[14]) << 5 | (unsigned)(s->last_int[m] != in) << 4 |
                  (unsigned)(l[15] != r[15]) << 3 | (unsigned)(l[16] != r[16]) << 2 |
                  (unsigned)(l[17] != r[17]) << 1 | (unsigned)(rd16(l + 18) != psid);
    lz_encode_lazy(e, &s->changed, 64, cv);
    if (cv & 32)
        lz_encode_lazy(e, &s->bitm[l[14]], 256, r[14]);
    if (cv & 16) {
        lz_ic_encode(e, &s->ic_int, s->last_int[m], in, m < 3 ? m : 3);
        s->last_int[m] = in;
    }
    if (cv & 8)
        lz_encode_lazy(e, &s->clsm[l[15]], 256, r[15]);
    if (cv & 4)
        lz_encode_lazy(e, &s->sar_m[(r[14] >> 6) & 1], 256, (uint8_t)(r[16] - l[16]));
    if (cv & 2)
        lz_encode_lazy(e, &s->udm[l[17]], 256, r[17]);
    if (cv & 1)
        lz_ic_encode(e, &s->ic_psid, rd16(l + 18), psid, 0);
    /* x, y: from the median of the context's last five differences */
    int32_t diff = (int32_t)(rd32(r) - rd32(l));
    lz_ic_encode(e, &s->ic_dx, s->mx[m].v[2], diff, nr == 1);
    lz_med_add(&s->mx[m], diff);
    uint32_t k = s->ic_dx.k;
    diff = (int32_t)(rd32(r + 4) - rd32(l + 4));
    lz_ic_encode(e, &s->ic_dy, s->my[m].v[2], diff, (nr == 1) + (k < 20 ? k & ~1u : 20));
    lz_med_add(&s->my[m], diff);
    k = (s->ic_dx.k + s->ic_dy.k) / 2;
    lz_ic_encode(e, &s->ic_z, s->last_h[lv], (int32_t)rd32(r + 8),
                 (nr == 1) + (k < 18 ? k & ~1u : 18));
    s->last_h[lv] = (int32_t)rd32(r + 8);
    memcpy(s->last, r, 20);
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
} gps11e;

static int32_t mul32(int32_t a, int32_t b) { return (int32_t)((uint32_t)a * (uint32_t)b); }

/* The multiplier of the last difference nearest to d/last (LASzip rounds
 * a float quotient; any choice decodes, this one only codes well). */
int jf__lz_gps_multi(int32_t d, int32_t last)
{
    double q = (double)(float)d / (double)(float)last;
    if (q >= 1000.0)
        return 1000;
    if (q <= -1000.0)
        return -1000;
    return q >= 0 ? (int)(q + 0.5) : (int)(q - 0.5);
}

static void gps_extreme(gps11e *s, int32_t diff)
{
    if (++s->extreme[s->last] > 3) {
        s->diff[s->last] = diff;
        s->extreme[s->last] = 0;
    }
}

static void gps_full(gps11e *s, lz_enc *e, uint64_t t)
{
    lz_ic_encode(e, &s->ic, (int32_t)(s->t[s->last] >> 32), (int32_t)(t >> 32), 8);
    lz_write_int(e, (uint32_t)t);
    s->next = (s->next + 1) & 3;
    s->last = s->next;
    s->t[s->last] = t;
    s->diff[s->last] = 0;
    s->extreme[s->last] = 0;
}

/* the sequence other than last whose time t is within 32 bits of, 0 if none */
static unsigned gps_other(const gps11e *s, uint64_t t)
{
    for (unsigned i = 1; i < 4; i++) {
        int64_t d = (int64_t)(t - s->t[(s->last + i) & 3]);
        if (d == (int32_t)d)
            return i;
    }
    return 0;
}

static void gps_encode(gps11e *s, lz_enc *e, const uint8_t *r)
{
    uint64_t t = rd32(r) | (uint64_t)rd32(r + 4) << 32;
    for (;;) {
        unsigned L = s->last;
        int64_t d64 = (int64_t)(t - s->t[L]);
        int32_t d = (int32_t)d64;
        if (s->diff[L] == 0) {
            if (t == s->t[L]) {
                lz_encode_lazy(e, &s->zero, 6, 0);
            } else if (d64 == d) {
                lz_encode_lazy(e, &s->zero, 6, 1);
                lz_ic_encode(e, &s->ic, 0, d, 0);
                s->diff[L] = d;
                s->t[L] = t;
                s->extreme[L] = 0;
            } else {
                unsigned i = gps_other(s, t);
                if (i) { /* another sequence, then its code */
                    lz_encode_lazy(e, &s->zero, 6, i + 2);
                    s->last = (L + i) & 3;
                    continue;
                }
                lz_encode_lazy(e, &s->zero, 6, 2);
                gps_full(s, e, t);
            }
        } else if (t == s->t[L]) {
            lz_encode_lazy(e, &s->multi, GPS_TOTAL, GPS_UNCHANGED);
        } else if (d64 == d) {
            int multi = jf__lz_gps_multi(d, s->diff[L]);
            if (multi == 1) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, 1);
                lz_ic_encode(e, &s->ic, s->diff[L], d, 1);
                s->extreme[L] = 0;
            } else if (multi > 0 && multi < GPS_MULTI) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, (uint32_t)multi);
                lz_ic_encode(e, &s->ic, mul32(multi, s->diff[L]), d, multi < 10 ? 2 : 3);
            } else if (multi >= GPS_MULTI) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, GPS_MULTI);
                lz_ic_encode(e, &s->ic, mul32(GPS_MULTI, s->diff[L]), d, 4);
                gps_extreme(s, d);
            } else if (multi < 0 && multi > GPS_MULTI_MINUS) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, (uint32_t)(GPS_MULTI - multi));
                lz_ic_encode(e, &s->ic, mul32(multi, s->diff[L]), d, 5);
            } else if (multi < 0) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, GPS_MULTI - GPS_MULTI_MINUS);
                lz_ic_encode(e, &s->ic, mul32(GPS_MULTI_MINUS, s->diff[L]), d, 6);
                gps_extreme(s, d);
            } else {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, 0);
                lz_ic_encode(e, &s->ic, 0, d, 7);
                gps_extreme(s, d);
            }
            s->t[L] = t;
        } else {
            unsigned i = gps_other(s, t);
            if (i) {
                lz_encode_lazy(e, &s->multi, GPS_TOTAL, GPS_CODE_FULL + i);
                s->last = (L + i) & 3;
                continue;
            }
            lz_encode_lazy(e, &s->multi, GPS_TOTAL, GPS_CODE_FULL);
            gps_full(s, e, t);
        }
        break;
    }
}

/* ---- RGB12 ---------------------------------------------------------- */

typedef struct {
    uint16_t rgb[3];
    lz_sym used, diff[6];
} rgb12e;

static unsigned clamp8(int v) { return v < 0 ? 0u : v > 255 ? 255u : (unsigned)v; }

/* The colour v against the last l, byte-wise, green and blue predicted
 * from red's change (shared with the layered RGB14, laz_v3_enc.c). */
void jf__lz_rgb_encode(lz_enc *e, lz_sym *used, lz_sym *diff, const uint16_t *l,
                       const unsigned *v)
{
    unsigned sym = (unsigned)((l[0] & 0xFF) != (v[0] & 0xFF)) |
                   (unsigned)((l[0] >> 8) != (v[0] >> 8)) << 1 |
                   (unsigned)((l[1] & 0xFF) != (v[1] & 0xFF)) << 2 |
                   (unsigned)((l[1] >> 8) != (v[1] >> 8)) << 3 |
                   (unsigned)((l[2] & 0xFF) != (v[2] & 0xFF)) << 4 |
                   (unsigned)((l[2] >> 8) != (v[2] >> 8)) << 5 |
                   (unsigned)(v[0] != v[1] || v[0] != v[2]) << 6;
    lz_encode_lazy(e, used, 128, sym);
    if (sym & 1)
        lz_encode_lazy(e, &diff[0], 256, (v[0] - l[0]) & 0xFF);
    if (sym & 2)
        lz_encode_lazy(e, &diff[1], 256, ((v[0] >> 8) - (l[0] >> 8)) & 0xFF);
    if (sym & 64) {
        int d = (int)(v[0] & 0xFF) - (l[0] & 0xFF);
        if (sym & 4)
            lz_encode_lazy(e, &diff[2], 256, (v[1] - clamp8(d + (l[1] & 0xFF))) & 0xFF);
        if (sym & 16) {
            d = (d + (int)(v[1] & 0xFF) - (l[1] & 0xFF)) / 2;
            lz_encode_lazy(e, &diff[4], 256, (v[2] - clamp8(d + (l[2] & 0xFF))) & 0xFF);
        }
        d = (int)(v[0] >> 8) - (l[0] >> 8);
        if (sym & 8)
            lz_encode_lazy(e, &diff[3], 256, ((v[1] >> 8) - clamp8(d + (l[1] >> 8))) & 0xFF);
        if (sym & 32) {
            d = (d + (int)(v[1] >> 8) - (l[1] >> 8)) / 2;
            lz_encode_lazy(e, &diff[5], 256, ((v[2] >> 8) - clamp8(d + (l[2] >> 8))) & 0xFF);
        }
    }
}

static void rgb_encode(rgb12e *s, lz_enc *e, const uint8_t *r)
{
    unsigned v[3];
    for (int c = 0; c < 3; c++)
        v[c] = rd16(r + 2 * c);
    jf__lz_rgb_encode(e, &s->used, s->diff, s->rgb, v);
    for (int c = 0; c < 3; c++)
        s->rgb[c] = (uint16_t)v[c];
}

/* ---- the chunk ------------------------------------------------------ */

int jf__laz_v2_encode(const lz_item *items, unsigned nitems, unsigned rec_len,
                      const uint8_t *recs, uint32_t count, lz_enc *out)
{
    if (!count)
        return 0;
    lz_put_bytes(out, recs, rec_len); /* the first point, raw */
    lz_arena a = {0};
    void *st[16] = {0};
    unsigned off[16];
    int ok = nitems <= 16;
    for (unsigned i = 0, o = 0; i < nitems && ok; o += items[i].size, i++) {
        const uint8_t *r = recs + o;
        off[i] = o;
        switch (items[i].type) {
        case LZ_POINT10:
            ok = (st[i] = malloc(sizeof(p10e))) && p10_init(st[i], &a, r);
            break;
        case LZ_GPSTIME11:
            ok = (st[i] = calloc(1, sizeof(gps11e))) &&
                 lz_ic_init(&((gps11e *)st[i])->ic, &a, 32, 9, 8, 0);
            if (ok)
                ((gps11e *)st[i])->t[0] = rd32(r) | (uint64_t)rd32(r + 4) << 32;
            break;
        case LZ_RGB12:
            ok = (st[i] = calloc(1, sizeof(rgb12e))) != NULL;
            for (int c = 0; ok && c < 3; c++)
                ((rgb12e *)st[i])->rgb[c] = rd16(r + 2 * c);
            break;
        default: /* LZ_BYTE: the last bytes, one model each */
            ok = (st[i] = calloc(1, sizeof(lz_sym) * items[i].size + items[i].size)) != NULL;
            if (ok)
                memcpy((lz_sym *)st[i] + items[i].size, r, items[i].size);
        }
    }
    lz_enc e;
    lz_enc_init(&e, &a);
    for (uint32_t j = 1; j < count && ok; j++) {
        const uint8_t *r = recs + (size_t)j * rec_len;
        for (unsigned i = 0; i < nitems; i++) {
            switch (items[i].type) {
            case LZ_POINT10:
                p10_encode(st[i], &e, r + off[i]);
                break;
            case LZ_GPSTIME11:
                gps_encode(st[i], &e, r + off[i]);
                break;
            case LZ_RGB12:
                rgb_encode(st[i], &e, r + off[i]);
                break;
            default: {
                lz_sym *m = st[i];
                uint8_t *last = (uint8_t *)(m + items[i].size);
                for (unsigned k = 0; k < items[i].size; k++) {
                    lz_encode_lazy(&e, &m[k], 256, (uint8_t)(r[off[i] + k] - last[k]));
                    last[k] = r[off[i] + k];
                }
            }
            }
        }
    }
    lz_enc_done(&e);
    ok = ok && !e.nomem && !a.failed;
    if (ok)
        lz_put_bytes(out, e.buf, e.len);
    lz_enc_free(&e);
    for (unsigned i = 0; i < nitems && i < 16; i++)
        free(st[i]);
    lz_arena_free(&a);
    return ok && !out->nomem ? 0 : -1;
}
