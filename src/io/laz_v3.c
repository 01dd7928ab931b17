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

/* One layer: its bytes and its decoder (size 0: the field is unchanged). */
typedef struct {
    const uint8_t *p;
    uint32_t size;
    lz_dec d;
} layer;

/* ---- POINT14 -------------------------------------------------------- */

typedef struct {
    lz_p14ctx c[4];
    unsigned cur;
    layer L[9]; /* xy, z, class, flags, intensity, scan angle, user data, source, gps */
} p14;

static void p14_pack(const lz_p14pt *c, uint8_t *r)
{
    lz_wr32(r, c->x), lz_wr32(r + 4, c->y), lz_wr32(r + 8, c->z);
    lz_wr16(r + 12, c->intensity);
    r[14] = (uint8_t)(c->rn | c->nr << 4);
    r[15] = (uint8_t)(c->cflags | c->sc << 4 | c->sdir << 6 | c->eof << 7);
    r[16] = c->cls, r[17] = c->ud;
    lz_wr16(r + 18, c->sangle), lz_wr16(r + 20, c->psid);
    lz_wr32(r + 22, (uint32_t)c->gps), lz_wr32(r + 26, (uint32_t)(c->gps >> 32));
}

/* -1 out of memory, -2 corrupt GPS stream, else the context of the other
 * items: the new scanner channel on a point that switches channel, 0 on
 * every other point (LASzip's LASreadPoint starts each point's context at
 * 0 and only POINT14's switch sets it; laz-perf does the same), so RGB14
 * and BYTE14 go back to their channel-0 set after a switch. */
static int p14_decode(p14 *s, lz_arena *a, uint8_t *r)
{
    lz_p14ctx *prev = &s->c[s->cur];
    lz_dec *xy = &s->L[0].d;
    uint32_t cv = lz_decode_lazy(xy, &prev->changed[lz_p14_changed_ctx(prev)], 128);
    int item_ctx = 0;
    if (cv & 64) { /* another scanner channel */
        unsigned sc = (s->cur + lz_decode_lazy(xy, &prev->sc_m, 3) + 1) % 4;
        if (!s->c[sc].used && !lz_p14_init(&s->c[sc], a, &prev->v))
            return -1;
        s->cur = sc;
        s->c[sc].v.sc = (uint8_t)sc;
        item_ctx = (int)sc;
    }
    lz_p14ctx *c = &s->c[s->cur];
    lz_p14pt *o = &c->v;
    int gpsc = (cv >> 4) & 1;
    unsigned n = o->nr, rn = o->rn;
    lz_sym *m;
    if (cv & 4) {
        if (!(m = lz_sym_lazy(&c->nr_m[n], a, 16)))
            return -1;
        n = o->nr = (uint8_t)lz_decode_sym(xy, m);
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
    o->rn = (uint8_t)rn;
    unsigned ctx = lz_p14_xy_ctx(n, rn, gpsc);
    int32_t diff = lz_ic_decode(xy, &c->dx, c->mx[ctx].v[2], n == 1);
    o->x += (uint32_t)diff;
    lz_med_add(&c->mx[ctx], diff);
    diff = lz_ic_decode(xy, &c->dy, c->my[ctx].v[2], lz_p14_y_ctx(c, n));
    o->y += (uint32_t)diff;
    lz_med_add(&c->my[ctx], diff);
    if (s->L[1].size) {
        unsigned l = lz_p14_level(n, rn);
        o->z = (uint32_t)lz_ic_decode(&s->L[1].d, &c->iz, c->last_z[l], lz_p14_z_ctx(c, n));
        c->last_z[l] = (int32_t)o->z;
    }
    if (s->L[2].size) {
        if (!(m = lz_sym_lazy(&c->cls_m[lz_p14_cls_ctx(n, rn, o->cls)], a, 256)))
            return -1;
        o->cls = (uint8_t)lz_decode_sym(&s->L[2].d, m);
    }
    if (s->L[3].size) {
        if (!(m = lz_sym_lazy(&c->flag_m[lz_p14_flags(o)], a, 64)))
            return -1;
        unsigned f = lz_decode_sym(&s->L[3].d, m);
        o->eof = (f >> 5) & 1, o->sdir = (f >> 4) & 1, o->cflags = f & 15;
    }
    if (s->L[4].size) {
        unsigned ic = lz_p14_int_ctx(n, rn, gpsc);
        o->intensity = c->last_int[ic] =
            (uint16_t)lz_ic_decode(&s->L[4].d, &c->iint, c->last_int[ic], ic >> 1);
    }
    if (cv & 8)
        o->sangle = (uint16_t)lz_ic_decode(&s->L[5].d, &c->isa, (int16_t)o->sangle, gpsc);
    if (s->L[6].size) {
        if (!(m = lz_sym_lazy(&c->ud_m[o->ud / 4], a, 256)))
            return -1;
        o->ud = (uint8_t)lz_decode_sym(&s->L[6].d, m);
    }
    if (cv & 32)
        o->psid = (uint16_t)lz_ic_decode(&s->L[7].d, &c->ips, o->psid, 0);
    /* GPS time as in version 2 without the "unchanged" code: the change
     * flag is in the x y layer */
    if (gpsc) {
        if (!lz_gps_decode(&c->g, &s->L[8].d, 0))
            return -2;
        o->gps = c->g.t[c->g.last];
    }
    c->gps_change = gpsc;
    p14_pack(o, r);
    return item_ctx;
}

/* ---- RGB14, RGBNIR14 ------------------------------------------------ */

typedef struct {
    lz_rgb14 ch;
    layer L[2]; /* rgb, nir */
} rgb14;

static void rgb14_decode(rgb14 *s, unsigned sc, uint8_t *r)
{
    uint16_t *last = lz_rgb14_switch(&s->ch, sc);
    lz_rgbctx *c = &s->ch.c[sc];
    if (s->L[0].size) {
        unsigned v[3];
        lz_rgb_decode(&s->L[0].d, &c->rgb_used, c->rgb_diff, last, v);
        for (int k = 0; k < 3; k++)
            last[k] = (uint16_t)v[k];
    }
    for (int k = 0; k < 3; k++)
        lz_wr16(r + 2 * k, last[k]);
    if (s->ch.nir) {
        if (s->L[1].size) {
            lz_dec *d = &s->L[1].d;
            unsigned sym = lz_decode_lazy(d, &c->nir_used, 4), l = last[3], v;
            v = sym & 1 ? (lz_decode_lazy(d, &c->nir_diff[0], 256) + (l & 0xFF)) & 0xFF : l & 0xFF;
            v |= sym & 2 ? ((lz_decode_lazy(d, &c->nir_diff[1], 256) + (l >> 8)) & 0xFF) << 8
                         : l & 0xFF00u;
            last[3] = (uint16_t)v;
        }
        lz_wr16(r + 6, last[3]);
    }
}

/* ---- BYTE14 --------------------------------------------------------- */

typedef struct {
    lz_byte14 ch;
    layer *L; /* one per byte */
} byte14;

static int byte14_decode(byte14 *s, lz_arena *a, unsigned sc, uint8_t *r)
{
    uint8_t *last = lz_byte14_switch(&s->ch, a, sc);
    if (!last)
        return 0;
    lz_sym *m = s->ch.c[sc].m;
    for (unsigned k = 0; k < s->ch.n; k++) {
        if (s->L[k].size)
            last[k] = (uint8_t)(last[k] + lz_decode_lazy(&s->L[k].d, &m[k], 256));
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
    uint32_t n = lz_rd32(p);
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
        } else { /* LZ_BYTE14: io_laz.c admits nothing else */
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
        all[k]->size = lz_rd32(p);
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
        if (sc >= 0 && rgb)
            rgb14_decode(rgb, (unsigned)sc, r + off_rgb);
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
