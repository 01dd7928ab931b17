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

/* ---- POINT10 -------------------------------------------------------- */

typedef struct {
    uint8_t last[20];
    lz_sym bitm[256], clsm[256], udm[256];
    lz_p10 m;
} p10e;

static void p10_encode(p10e *s, lz_enc *e, const uint8_t *r)
{
    const uint8_t *l = s->last;
    lz_p10 *q = &s->m;
    unsigned rn = r[14] & 7, nr = (r[14] >> 3) & 7;
    unsigned m = jf__lz_return_map[nr][rn], lv = jf__lz_return_level[nr][rn];
    uint16_t in = lz_rd16(r + 12), psid = lz_rd16(r + 18);
    /* which fields changed: bit byte, intensity (against its return
     * context's), classification, scan angle rank, user data, source */
    unsigned cv = (unsigned)(l[14] != r[14]) << 5 | (unsigned)(q->last_int[m] != in) << 4 |
                  (unsigned)(l[15] != r[15]) << 3 | (unsigned)(l[16] != r[16]) << 2 |
                  (unsigned)(l[17] != r[17]) << 1 | (unsigned)(lz_rd16(l + 18) != psid);
    lz_encode_lazy(e, &q->changed, 64, cv);
    if (cv & 32)
        lz_encode_lazy(e, &s->bitm[l[14]], 256, r[14]);
    if (cv & 16) {
        lz_ic_encode(e, &q->ic_int, q->last_int[m], in, m < 3 ? m : 3);
        q->last_int[m] = in;
    }
    if (cv & 8)
        lz_encode_lazy(e, &s->clsm[l[15]], 256, r[15]);
    if (cv & 4)
        lz_encode_lazy(e, &q->sar_m[(r[14] >> 6) & 1], 256, (uint8_t)(r[16] - l[16]));
    if (cv & 2)
        lz_encode_lazy(e, &s->udm[l[17]], 256, r[17]);
    if (cv & 1)
        lz_ic_encode(e, &q->ic_psid, lz_rd16(l + 18), psid, 0);
    /* x, y: from the median of the context's last five differences */
    int32_t diff = (int32_t)(lz_rd32(r) - lz_rd32(l));
    lz_ic_encode(e, &q->ic_dx, q->mx[m].v[2], diff, nr == 1);
    lz_med_add(&q->mx[m], diff);
    diff = (int32_t)(lz_rd32(r + 4) - lz_rd32(l + 4));
    lz_ic_encode(e, &q->ic_dy, q->my[m].v[2], diff, lz_p10_y_ctx(q, nr));
    lz_med_add(&q->my[m], diff);
    lz_ic_encode(e, &q->ic_z, q->last_h[lv], (int32_t)lz_rd32(r + 8), lz_p10_z_ctx(q, nr));
    q->last_h[lv] = (int32_t)lz_rd32(r + 8);
    memcpy(s->last, r, 20);
}

/* ---- GPS time: GPSTIME11 (u = 1) and POINT14's (u = 0) -------------- */

/* The multiplier of the last difference nearest to d/last (LASzip rounds
 * a float quotient; any choice decodes, this one only codes well). */
static int gps_multi(int32_t d, int32_t last)
{
    double q = (double)(float)d / (double)(float)last;
    if (q >= 1000.0)
        return 1000;
    if (q <= -1000.0)
        return -1000;
    return q >= 0 ? (int)(q + 0.5) : (int)(q - 0.5);
}

static void gps_full(lz_gps *g, lz_enc *e, uint64_t t)
{
    lz_ic_encode(e, &g->ic, (int32_t)(g->t[g->last] >> 32), (int32_t)(t >> 32), 8);
    lz_write_int(e, (uint32_t)t);
    lz_gps_start(g, t);
}

/* the sequence other than last whose time t is within 32 bits of, 0 if none */
static unsigned gps_other(const lz_gps *g, uint64_t t)
{
    for (unsigned i = 1; i < 4; i++) {
        int64_t d = (int64_t)(t - g->t[(g->last + i) & 3]);
        if (d == (int32_t)d)
            return i;
    }
    return 0;
}

void jf__lz_gps_encode(lz_gps *g, lz_enc *e, uint64_t t, unsigned u)
{
    for (;;) {
        unsigned L = g->last;
        int64_t d64 = (int64_t)(t - g->t[L]);
        int32_t d = (int32_t)d64;
        if (g->diff[L] == 0) {
            if (u && t == g->t[L]) {
                lz_encode_lazy(e, &g->zero, 5 + u, 0);
            } else if (d64 == d) {
                lz_encode_lazy(e, &g->zero, 5 + u, u);
                lz_ic_encode(e, &g->ic, 0, d, 0);
                g->diff[L] = d;
                g->t[L] = t;
                g->extreme[L] = 0;
            } else {
                unsigned i = gps_other(g, t);
                if (i) { /* another sequence, then its code */
                    lz_encode_lazy(e, &g->zero, 5 + u, i + 1 + u);
                    g->last = (L + i) & 3;
                    continue;
                }
                lz_encode_lazy(e, &g->zero, 5 + u, 1 + u);
                gps_full(g, e, t);
            }
        } else if (u && t == g->t[L]) {
            lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), LZ_GPS_UNCHANGED);
        } else if (d64 == d) {
            int multi = gps_multi(d, g->diff[L]);
            if (multi == 1) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), 1);
                lz_ic_encode(e, &g->ic, g->diff[L], d, 1);
                g->extreme[L] = 0;
            } else if (multi > 0 && multi < LZ_GPS_MULTI) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), (uint32_t)multi);
                lz_ic_encode(e, &g->ic, lz_mul32(multi, g->diff[L]), d, multi < 10 ? 2 : 3);
            } else if (multi >= LZ_GPS_MULTI) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), LZ_GPS_MULTI);
                lz_ic_encode(e, &g->ic, lz_mul32(LZ_GPS_MULTI, g->diff[L]), d, 4);
                lz_gps_extreme(g, d);
            } else if (multi < 0 && multi > LZ_GPS_MULTI_MINUS) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), (uint32_t)(LZ_GPS_MULTI - multi));
                lz_ic_encode(e, &g->ic, lz_mul32(multi, g->diff[L]), d, 5);
            } else if (multi < 0) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), LZ_GPS_MULTI - LZ_GPS_MULTI_MINUS);
                lz_ic_encode(e, &g->ic, lz_mul32(LZ_GPS_MULTI_MINUS, g->diff[L]), d, 6);
                lz_gps_extreme(g, d);
            } else {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), 0);
                lz_ic_encode(e, &g->ic, 0, d, 7);
                lz_gps_extreme(g, d);
            }
            g->t[L] = t;
        } else {
            unsigned i = gps_other(g, t);
            if (i) {
                lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), LZ_GPS_CODE_FULL(u) + i);
                g->last = (L + i) & 3;
                continue;
            }
            lz_encode_lazy(e, &g->multi, LZ_GPS_TOTAL(u), LZ_GPS_CODE_FULL(u));
            gps_full(g, e, t);
        }
        break;
    }
}

/* ---- RGB12 ---------------------------------------------------------- */

typedef struct {
    uint16_t rgb[3];
    lz_sym used, diff[6];
} rgb12e;

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
            lz_encode_lazy(e, &diff[2], 256, (v[1] - lz_clamp8(d + (l[1] & 0xFF))) & 0xFF);
        if (sym & 16) {
            d = (d + (int)(v[1] & 0xFF) - (l[1] & 0xFF)) / 2;
            lz_encode_lazy(e, &diff[4], 256, (v[2] - lz_clamp8(d + (l[2] & 0xFF))) & 0xFF);
        }
        d = (int)(v[0] >> 8) - (l[0] >> 8);
        if (sym & 8)
            lz_encode_lazy(e, &diff[3], 256, ((v[1] >> 8) - lz_clamp8(d + (l[1] >> 8))) & 0xFF);
        if (sym & 32) {
            d = (d + (int)(v[1] >> 8) - (l[1] >> 8)) / 2;
            lz_encode_lazy(e, &diff[5], 256, ((v[2] >> 8) - lz_clamp8(d + (l[2] >> 8))) & 0xFF);
        }
    }
}

static void rgb_encode(rgb12e *s, lz_enc *e, const uint8_t *r)
{
    unsigned v[3];
    for (int c = 0; c < 3; c++)
        v[c] = lz_rd16(r + 2 * c);
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
            ok = (st[i] = calloc(1, sizeof(p10e))) && lz_p10_init(&((p10e *)st[i])->m, &a);
            if (ok)
                memcpy(((p10e *)st[i])->last, r, 20);
            break;
        case LZ_GPSTIME11:
            ok = (st[i] = calloc(1, sizeof(lz_gps))) && lz_gps_init(st[i], &a, lz_rd64(r));
            break;
        case LZ_RGB12:
            ok = (st[i] = calloc(1, sizeof(rgb12e))) != NULL;
            for (int c = 0; ok && c < 3; c++)
                ((rgb12e *)st[i])->rgb[c] = lz_rd16(r + 2 * c);
            break;
        default: /* LZ_BYTE: the last bytes, one model each */
            ok = (st[i] = calloc(1, sizeof(lz_bytes))) && lz_bytes_init(st[i], &a, r, items[i].size);
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
                jf__lz_gps_encode(st[i], &e, lz_rd64(r + off[i]), 1);
                break;
            case LZ_RGB12:
                rgb_encode(st[i], &e, r + off[i]);
                break;
            default: {
                lz_sym *m = ((lz_bytes *)st[i])->m;
                uint8_t *last = ((lz_bytes *)st[i])->last;
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
