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

/* One layer: its encoder, and whether the field changed (or was used). */
typedef struct {
    lz_enc e;
    int changed;
} layer;

/* ---- POINT14 -------------------------------------------------------- */

typedef struct {
    lz_p14ctx c[4];
    unsigned cur;
    layer L[9]; /* xy, z, class, flags, intensity, scan angle, user data, source, gps */
} p14;

/* One point; the other items' context (laz_v3.c: the new channel on a
 * switch, else 0), or -1 out of memory. */
static int p14_encode(p14 *s, lz_arena *a, const uint8_t *r)
{
    lz_p14pt nv;
    lz_p14_unpack(&nv, r);
    lz_p14ctx *prev = &s->c[s->cur];
    unsigned lpr = lz_p14_changed_ctx(prev);
    unsigned sc = nv.sc;
    int sw = sc != s->cur;
    lz_p14ctx *c = &s->c[sc];
    if (sw && !c->used && !lz_p14_init(c, a, &prev->v)) /* from the previous point */
        return -1;
    lz_p14pt *o = &c->v;
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
        lz_encode_slot(xy, &c->nr_m[o->nr], 16, nv.nr);
        o->nr = nv.nr;
    }
    if (rnc == 3) {
        if (gpsc)
            lz_encode_slot(xy, &c->rn_m[o->rn], 16, nv.rn);
        else
            lz_encode_lazy(xy, &c->rn_same, 13, (nv.rn + 14 - o->rn) & 15);
    }
    o->rn = nv.rn;
    unsigned n = nv.nr, rn = nv.rn;
    unsigned ctx = lz_p14_xy_ctx(n, rn, gpsc);
    int32_t diff = (int32_t)(nv.x - o->x);
    lz_ic_encode(xy, &c->dx, c->mx[ctx].v[2], diff, n == 1);
    lz_med_add(&c->mx[ctx], diff);
    o->x = nv.x;
    diff = (int32_t)(nv.y - o->y);
    lz_ic_encode(xy, &c->dy, c->my[ctx].v[2], diff, lz_p14_y_ctx(c, n));
    lz_med_add(&c->my[ctx], diff);
    o->y = nv.y;
    /* z from the last z of the same return level */
    unsigned l = lz_p14_level(n, rn);
    s->L[1].changed |= nv.z != o->z;
    lz_ic_encode(&s->L[1].e, &c->iz, c->last_z[l], (int32_t)nv.z, lz_p14_z_ctx(c, n));
    c->last_z[l] = (int32_t)nv.z;
    o->z = nv.z;
    s->L[2].changed |= nv.cls != o->cls;
    lz_encode_slot(&s->L[2].e, &c->cls_m[lz_p14_cls_ctx(n, rn, o->cls)], 256, nv.cls);
    o->cls = nv.cls;
    unsigned f0 = lz_p14_flags(o), f1 = lz_p14_flags(&nv);
    s->L[3].changed |= f0 != f1;
    lz_encode_slot(&s->L[3].e, &c->flag_m[f0], 64, f1);
    o->cflags = nv.cflags, o->sdir = nv.sdir, o->eof = nv.eof;
    unsigned ic = lz_p14_int_ctx(n, rn, gpsc);
    s->L[4].changed |= nv.intensity != o->intensity;
    lz_ic_encode(&s->L[4].e, &c->iint, c->last_int[ic], nv.intensity, ic >> 1);
    o->intensity = c->last_int[ic] = nv.intensity;
    if (cv & 8) {
        s->L[5].changed = 1;
        lz_ic_encode(&s->L[5].e, &c->isa, (int16_t)o->sangle, (int16_t)nv.sangle, gpsc);
        o->sangle = nv.sangle;
    }
    s->L[6].changed |= nv.ud != o->ud;
    lz_encode_slot(&s->L[6].e, &c->ud_m[o->ud / 4], 256, nv.ud);
    o->ud = nv.ud;
    if (cv & 32) {
        s->L[7].changed = 1;
        lz_ic_encode(&s->L[7].e, &c->ips, o->psid, nv.psid, 0);
        o->psid = nv.psid;
    }
    if (gpsc) {
        s->L[8].changed = 1;
        jf__lz_gps_encode(&c->g, &s->L[8].e, nv.gps, 0);
        o->gps = nv.gps;
    }
    c->gps_change = gpsc;
    return sw ? (int)sc : 0;
}

/* ---- RGB14, RGBNIR14 ------------------------------------------------ */

typedef struct {
    lz_rgb14 ch;
    layer L[2]; /* rgb, nir */
} rgb14;

static void rgb14_encode(rgb14 *s, unsigned sc, const uint8_t *r)
{
    uint16_t *last = lz_rgb14_switch(&s->ch, sc);
    lz_rgbctx *c = &s->ch.c[sc];
    unsigned v[4];
    for (int k = 0; k < 3; k++)
        v[k] = lz_rd16(r + 2 * k);
    s->L[0].changed |= v[0] != last[0] || v[1] != last[1] || v[2] != last[2];
    jf__lz_rgb_encode(&s->L[0].e, &c->rgb_used, c->rgb_diff, last, v);
    for (int k = 0; k < 3; k++)
        last[k] = (uint16_t)v[k];
    if (s->ch.nir) {
        lz_enc *e = &s->L[1].e;
        unsigned l = last[3], x = lz_rd16(r + 6);
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
    lz_byte14 ch;
    layer *L; /* one per byte */
} byte14;

static int byte14_encode(byte14 *s, lz_arena *a, unsigned sc, const uint8_t *r)
{
    uint8_t *last = lz_byte14_switch(&s->ch, a, sc);
    if (!last)
        return 0;
    lz_sym *m = s->ch.c[sc].m;
    for (unsigned k = 0; k < s->ch.n; k++) {
        s->L[k].changed |= r[k] != last[k];
        lz_encode_lazy(&s->L[k].e, &m[k], 256, (uint8_t)(r[k] - last[k]));
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
                lz_p14pt v;
                lz_p14_unpack(&v, raw);
                pt->cur = v.sc;
                ok = lz_p14_init(&pt->c[v.sc], &a, &v);
                for (int k = 0; k < 9; k++)
                    all[nl++] = &pt->L[k];
            }
        } else if (items[i].type == LZ_RGB14 || items[i].type == LZ_RGBNIR14) {
            ok = (rgb = calloc(1, sizeof *rgb)) != NULL;
            if (ok) {
                lz_rgb14_start(&rgb->ch, pt ? pt->cur : 0, items[i].type == LZ_RGBNIR14, raw,
                               items[i].size);
                off_rgb = o;
                all[nl++] = &rgb->L[0];
                if (rgb->ch.nir)
                    all[nl++] = &rgb->L[1];
            }
        } else { /* LZ_BYTE14 */
            ok = (by = calloc(1, sizeof *by)) != NULL &&
                 (by->L = calloc(items[i].size, sizeof *by->L)) != NULL;
            if (ok) {
                by->ch.n = items[i].size;
                by->ch.cur = pt ? pt->cur : 0;
                ok = lz_bytes_init(&by->ch.c[by->ch.cur], &a, raw, by->ch.n);
                off_by = o;
                for (unsigned k = 0; k < by->ch.n; k++)
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
