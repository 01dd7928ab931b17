/* parts_run.c -- jf_estimate_parts: the cloud cut into parts processed one
 * at a time, each with an exact halo, so that only one part's index is
 * held at once (`jetfit estimate --memory`, issues 12.1, 28).  The same
 * results as jf_estimate_blocks, bit for bit.
 *
 * design (the requests are parts.c's, shared with jetfit-mpi):
 *  1. Parts: the finite points cut along the (Morton key, index) order at
 *     the quantiles of a sample (jf__parts_split_sampled: no sort of the
 *     cloud, 16 bytes per sampled point).
 *  2. For part a, knn with dense cells (jf__halo_by_cells, parts_halo.c): the own points
 *     counted on a grid over a's box; where a cell (or the 27 or 125
 *     around it) holds K + 1 own points, the K-th distance is bounded by
 *     the block's size, so the other parts' points in the cells that near
 *     are a superset of the halo, taken by one scan: no index, no query.
 *     Otherwise (sparse cells, radius kinds, a halo over the plan's):
 *     index its own points; walking the index's leaf order
 *     (spatially coherent) on the threads, each own point whose own k-th
 *     distance may reach a cell holding another part's point (a grid of
 *     each cell's owner part over the cloud's box, built once in step 1)
 *     turns its neighbourhood into at most two requests "the k nearest
 *     within squared distance <= bound" (jf__halo_requests); in space
 *     order a knn point whose own k-th distance is bounded by the previous
 *     query's plus the step (triangle inequality) and meets no such cell
 *     is not even queried.  Every remote neighbour of an own point lies
 *     within its request's bound (parts.c), so the halo is taken from one
 *     scan of the cloud: the points of other parts in a grid cell touched
 *     by a request's ball, and for the few balls too large for the grid
 *     (an isolated point, a part of fewer than k points) those within its
 *     k-th distance over the other parts (jf__halo_of).  A superset of the
 *     exact halo; no other part is indexed.  A knn's bounds come from
 *     the cloud, not the part (jf__wide_index): a first such pass with every
 *     ball capped at 4 times the median radius, then the requests again
 *     over own + that halo (a part's own K-th distance is unbounded on an
 *     island of it).
 *  3. The part's own points and its halo, in input-index order (so the
 *     k-d tree's tie rule, smaller position first, is the input index's),
 *     form a small cloud; jf_estimate_blocks on it fits the own points only
 *     (the halo points are neighbours): a superset of each neighbourhood
 *     that contains all of it gives the same k nearest, the same order,
 *     the same fit.  The blocks go to the caller's sink with input indices.
 *  Non-finite points belong to no part: their rows (NaN, NONFINITE) are
 *  handed over first.  Every step runs on the threads; per part: one index
 *  build (own + halo; three with a knn's requests) and two scans of the
 *  coordinates (four with a knn's requests).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "auto_cloud.h"
#include "fitter_internal.h"
#include "index_internal.h"
#include "jetfit.h"
#include "neigh_jets.h" /* jf__nj_reach */
#include "parts.h"
#include "parts_run.h"
#include "set_err.h"

/* The query of the parts from o (jf__part_query_init), the one check both
 * entry points make: JF_ERR_UNSUPPORTED with its message where parts
 * cannot serve (not a k-d tree query; mst, which orients along the whole
 * cloud's graph); JF_ERR_INVALID without one (each caller says it). */
static jf_status parts_query(const jf_estimate_opts *o, jf_part_query *q, jf_error *err)
{
    jf_status st = jf__part_query_init(o, q);
    if (st == JF_ERR_UNSUPPORTED || o->orient == JF_ORIENT_MST) {
        jf__set_err(err, "parts need a k-d tree neighbourhood (knn, radius) and a per-point "
                         "orientation (not mst)");
        return JF_ERR_UNSUPPORTED;
    }
    return st;
}

/* The sink of one part: local indices back to input indices (the
 * coordinates come with the block, the walk's copy of the part's). */
typedef struct {
    const uint32_t *ids; /* local -> input index                       */
    jf__block_xyz_fn sink;
    void *user;
} relay;

static jf_status relay_block(void *user, const uint32_t *idx, const double *xyz, jf_result *res,
                             size_t m)
{
    const relay *r = user;
    uint32_t g[256];
    if (m > 256) return JF_ERR_INVALID;
    for (size_t j = 0; j < m; j++) g[j] = r->ids[idx[j]];
    return r->sink(r->user, g, xyz, res, m);
}

/* jf_estimate_parts's sink without the coordinates. */
typedef struct {
    jf_block_fn sink;
    void *user;
} plain;

static jf_status plain_block(void *user, const uint32_t *idx, const double *xyz, jf_result *res,
                             size_t m)
{
    (void)xyz;
    const plain *p = user;
    return p->sink(p->user, idx, res, m);
}

jf_status jf_estimate_parts(const jf_cloud *c, const jf_estimate_opts *o, int nparts,
                            jf_block_fn sink, void *user, jf_error *err)
{
    if (err) err->msg[0] = '\0';
    if (!c || !o || !sink || (c->n && !c->xyz) || nparts < 1 || nparts > JF_PARTS_MAX) {
        jf__set_err(err, "jf_estimate_parts: NULL argument or nparts out of 1..65536");
        return JF_ERR_INVALID;
    }
    jf_part_query q;
    jf_status st = parts_query(o, &q, err);
    if (st == JF_ERR_UNSUPPORTED) return st;
    if (st != JF_OK || nparts == 1 || c->n == 0)
        return jf_estimate_blocks(c, o, sink, user, err); /* its own checks */
    const jf_xyz_src src = {c->xyz, -1, NULL};
    plain pl = {sink, user};
    return jf__estimate_parts_src(c, &src, o, nparts, plain_block, &pl, err);
}

/* Step 1 on the reader: the bounding box and finite counts (one scan),
 * the sample (a second), part[] with each part's box and count (a third):
 * the same parts as jf__parts_split_sampled (same sample, same keys), the
 * boxes the same min and max. */
static jf_status split(reader *rd, int P, int32_t *part, double *box, size_t *count,
                       double gbox[6], size_t *nfinite, occgrid *occ)
{
    const size_t n = rd->n, nch = rd->nch;
    const int nt = rd->nt;
    size_t *fc = calloc(nch + 1, sizeof *fc);
    double *tb = malloc((size_t)nt * 6 * (size_t)(P > 1 ? P : 1) * sizeof *tb);
    size_t *tc = calloc((size_t)nt * (size_t)P, sizeof *tc);
    jf__keyed *smp = NULL, *cut = NULL;
    /* the sample if every point is finite (finite rank = input index):
     * every stride1-th point's coordinates, taken by the first scan */
    const size_t want1 = jf__parts_sample_size(n), stride1 = n > want1 ? n / want1 : 1;
    const size_t ns1 = (n + stride1 - 1) / stride1;
    double *sx1 = malloc(ns1 * 3 * sizeof *sx1);
    jf_status st = fc && tb && tc && sx1 ? JF_OK : JF_ERR_NOMEM;
    if (st != JF_OK) goto out;
    for (size_t j = 0; j < (size_t)nt * (size_t)P; j++)
        for (int k = 0; k < 3; k++) tb[6 * j + k] = INFINITY, tb[6 * j + 3 + k] = -INFINITY;
    /* 1. box (tb's first nt boxes) and finite points per chunk */
#pragma omp parallel num_threads(nt)
    {
        double *bx = tb + 6 * (size_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 4)
        for (size_t ch = 0; ch < nch; ch++) {
            const double *x = jf__chunk_xyz(rd, ch);
            const size_t m = jf__chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
            for (size_t i = (beg + stride1 - 1) / stride1 * stride1; x && i < beg + m; i += stride1)
                memcpy(sx1 + 3 * (i / stride1), x + 3 * (i - beg), sizeof(double[3]));
            size_t f = 0;
            for (size_t j = 0; x && j < m; j++) {
                const double *p = x + 3 * j;
                if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
                f++;
                for (int d = 0; d < 3; d++) {
                    if (p[d] < bx[d]) bx[d] = p[d];
                    if (p[d] > bx[3 + d]) bx[3 + d] = p[d];
                }
            }
            fc[ch + 1] = f;
        }
    }
    if (rd->fail) goto out;
    for (int k = 0; k < 3; k++) gbox[k] = INFINITY, gbox[3 + k] = -INFINITY;
    for (int t = 0; t < nt; t++)
        for (int d = 0; d < 3; d++) {
            if (tb[6 * t + d] < gbox[d]) gbox[d] = tb[6 * t + d];
            if (tb[6 * t + 3 + d] > gbox[3 + d]) gbox[3 + d] = tb[6 * t + 3 + d];
        }
    for (size_t ch = 0; ch < nch; ch++) fc[ch + 1] += fc[ch];
    const size_t nf = fc[nch];
    *nfinite = nf;
    const double scale = jf__morton_scale(gbox);
    occ_setup(occ, gbox, jf__parts_grid_bits(n) / 8, 0);
    occ->P = P;
    if (!(occ->own = calloc(occ_cells(occ), 1))) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    /* 2. every stride-th finite point in input order (parts.c's rule) */
    const size_t want = jf__parts_sample_size(nf), stride = nf > want ? nf / want : 1;
    const size_t ns = nf ? (nf + stride - 1) / stride : 0;
    smp = malloc((ns ? ns : 1) * sizeof *smp);
    cut = malloc((size_t)P * sizeof *cut);
    if (!smp || !cut) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    if (nf == n) { /* the first scan's: the same points, stride and keys */
        for (size_t r = 0; r < ns; r++)
            smp[r] = (jf__keyed){jf__morton_key(sx1 + 3 * r, gbox, scale), (uint32_t)(r * stride)};
    } else {
#pragma omp parallel for num_threads(nt) schedule(dynamic, 4)
        for (size_t ch = 0; ch < nch; ch++) {
            size_t seen = fc[ch];
            if (fc[ch + 1] == seen) continue;
            /* the chunk's first finite rank divisible by stride */
            if ((seen + stride - 1) / stride * stride >= fc[ch + 1]) continue;
            const double *x = jf__chunk_xyz(rd, ch);
            const size_t m = jf__chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
            for (size_t j = 0; x && j < m; j++) {
                const double *p = x + 3 * j;
                if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) continue;
                if (seen % stride == 0)
                    smp[seen / stride] =
                        (jf__keyed){jf__morton_key(p, gbox, scale), (uint32_t)(beg + j)};
                seen++;
            }
        }
    }
    if (rd->fail) goto out;
    qsort(smp, ns, sizeof *smp, jf__keyed_cmp);
    int ncut = 0;
    for (int r = 1; r < P && ns; r++) cut[ncut++] = smp[(size_t)r * ns / (size_t)P];
    /* 3. part[], the parts' boxes and counts (per thread, then merged) */
#pragma omp parallel num_threads(nt)
    {
        const size_t t = (size_t)omp_get_thread_num();
        double *bx = tb + 6 * (size_t)P * t;
        size_t *cn = tc + (size_t)P * t;
#pragma omp for schedule(dynamic, 4)
        for (size_t ch = 0; ch < nch; ch++) {
            const double *x = jf__chunk_xyz(rd, ch);
            const size_t m = jf__chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
            for (size_t j = 0; x && j < m; j++) {
                const double *p = x + 3 * j;
                if (!(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]))) {
                    part[beg + j] = -1;
                    continue;
                }
                const int32_t a = jf__keyed_rank(cut, ncut, jf__morton_key(p, gbox, scale),
                                                (uint32_t)(beg + j));
                part[beg + j] = a;
                occ_set(occ, p, a);
                double *b = bx + 6 * a;
                for (int d = 0; d < 3; d++) {
                    if (p[d] < b[d]) b[d] = p[d];
                    if (p[d] > b[3 + d]) b[3 + d] = p[d];
                }
                cn[a]++;
            }
        }
    }
    if (rd->fail) goto out;
    for (int a = 0; a < P; a++) {
        double *b = box + 6 * a;
        for (int k = 0; k < 3; k++) b[k] = INFINITY, b[3 + k] = -INFINITY;
        count[a] = 0;
        for (int t = 0; t < nt; t++) {
            const double *s = tb + 6 * ((size_t)P * (size_t)t + (size_t)a);
            for (int d = 0; d < 3; d++) {
                if (s[d] < b[d]) b[d] = s[d];
                if (s[3 + d] > b[3 + d]) b[3 + d] = s[3 + d];
            }
            count[a] += tc[(size_t)P * (size_t)t + (size_t)a];
        }
    }
out:
    free(fc);
    free(tb);
    free(tc);
    free(smp);
    free(cut);
    free(sx1);
    return st;
}

/* The non-finite points' rows (NaN, NONFINITE), with the coordinates
 * read: chunks holding one are read, on the calling thread. */
static jf_status nonfinite_rows(reader *rd, const int32_t *part, jf__block_xyz_fn sink,
                                void *user)
{
    jf_result blk[64];
    uint32_t id[64];
    double xs[3 * 64];
    size_t mm = 0;
    jf_status st = JF_OK;
    for (size_t ch = 0; st == JF_OK && ch < rd->nch; ch++) {
        const size_t beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
        size_t i = beg;
        while (i < end && part[i] >= 0) i++;
        if (i == end) continue;
        const double *x = jf__chunk_xyz(rd, ch);
        if (!x) return JF_ERR_IO;
        for (; st == JF_OK && i < end; i++) {
            if (part[i] >= 0) continue;
            jf_result *r = &blk[mm];
            memset(r, 0, sizeof *r);
            r->status = JF_PT_NONFINITE;
            r->cond = r->residual = NAN;
            for (int j = 0; j < 3; j++) r->pca_eval[j] = NAN;
            jf__result_nan(r);
            memcpy(xs + 3 * mm, x + 3 * (i - beg), sizeof(double[3]));
            id[mm++] = (uint32_t)i;
            if (mm == 64) {
                st = sink(user, id, xs, blk, mm);
                mm = 0;
            }
        }
    }
    if (st == JF_OK && mm) st = sink(user, id, xs, blk, mm);
    return st;
}

jf_status jf__estimate_parts_src(const jf_cloud *c, const jf_xyz_src *src,
                                 const jf_estimate_opts *o, int nparts, jf__block_xyz_fn sink,
                                 void *user, jf_error *err)
{
    if (err) err->msg[0] = '\0';
    if (!c || !src || !o || !sink || (c->n && !src->xyz && (src->fd < 0 || !src->l)) ||
        nparts < 2 || nparts > JF_PARTS_MAX) {
        jf__set_err(err, "jf__estimate_parts_src: NULL argument or nparts out of 2..65536");
        return JF_ERR_INVALID;
    }
    jf_part_query q;
    jf_status st = parts_query(o, &q, err);
    if (st == JF_ERR_UNSUPPORTED) return st;
    if (st != JF_OK) {
        jf__set_err(err, "invalid parameters");
        return st;
    }
    /* the whole cloud's checks first (a bad option fails before any work);
     * the parts then share one resolved orientation */
    jf_estimate_opts use;
    if ((st = jf__estimate_check(c, o, &use, err)) != JF_OK) return st;
    o = &use;
    const size_t n = c->n;
    if (n == 0) return JF_OK;
    const int P = nparts, nt = o->threads > 0 ? o->threads : jf_default_threads(NULL);
    int32_t *part = malloc(n * sizeof *part);
    size_t *count = calloc((size_t)P, sizeof *count), cmax = 0, nf = 0;
    double *box = malloc((size_t)P * 6 * sizeof *box);
    uint32_t *ids = NULL;
    hpoint *halo = NULL;
    double *sxyz = NULL, *snrm = NULL;
    uint32_t *sscan = NULL;
    uint8_t *mask = NULL;
    size_t *ccnt = NULL, ncv = 0;
    jf__cvrec *cvr = NULL; /* auto's step 0: the sample's records */
    uint8_t *only = NULL;  /* and its own points in the part          */
    occgrid occ = {{0, 0, 0}, 1, {1, 1, 1}, NULL, 0, 1};
    reader rd;
    double gb[6];
    if ((st = jf__reader_open(&rd, src, n, nt)) != JF_OK) goto out;
    if (!part || !count || !box || !(ccnt = malloc((rd.nch + 1) * sizeof *ccnt))) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    if ((st = split(&rd, P, part, box, count, gb, &nf, &occ)) != JF_OK) goto out;
    if ((st = jf__reader_status(&rd, err)) != JF_OK) goto out;
    if (nf < n && (st = nonfinite_rows(&rd, part, sink, user)) != JF_OK) {
        if (rd.fail) st = jf__reader_status(&rd, err);
        goto out;
    }
    for (int b = 0; b < P; b++) cmax = count[b] > cmax ? count[b] : cmax;
    ids = malloc((cmax ? cmax : 1) * sizeof *ids);
    sxyz = malloc(3 * (cmax ? cmax : 1) * sizeof *sxyz);
    /* the most own + halo points the plan holds for a part */
    /* the cells' halo, a superset, while it stays as small as the
     * plan's least ring (else the exact requests: a smaller halo) */
    const size_t hcap = (size_t)(ceil((double)n / P) * JF_PLAN_IMBALANCE * (1 + JF_PLAN_HALO));
    if (!ids || !sxyz) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    jf_estimate_opts po = *o;
    po.progress = NULL; /* per part: the totals would restart */
    /* auto's step 0 (auto_cloud.c): a first sweep over the parts fits
     * only the sample, whose records decide the cap every part is given */
    const int cv = jf__auto_cv_wanted(&o->params, &q.nb);
    for (int sweep = cv ? 0 : 1; sweep < 2 && st == JF_OK; sweep++) {
        /* the sample's sweep reads only the sample's K nearest: no step 6
         * ball, no request from another point */
        jf_part_query qs = q;
        if (sweep == 0) qs.nj = 0;
        const size_t stride = jf__auto_cv_stride(n);
        for (int a = 0; a < P && st == JF_OK; a++) {
            if (!count[a]) continue;
            if (o->cancel && o->cancel(o->cancel_user)) {
                st = JF_ERR_CANCELLED;
                jf__set_err(err, "cancelled");
                goto out;
            }
            /* step 2: own index, requests, halo */
            size_t m = jf__gather(&rd, part, a, ids, sxyz, ccnt), nh = 0;
            if (sweep == 0) { /* the sample's requests only */
                uint8_t *on = realloc(only, m ? m : 1);
                if (!on) {
                    st = JF_ERR_NOMEM;
                    break;
                }
                only = on;
                for (size_t j = 0; j < m; j++) only[j] = ids[j] % stride == 0;
                qs.only = only;
            }
            if ((st = jf__reader_status(&rd, err)) != JF_OK) goto out;
            int served = 0;
            /* auto's step 6 needs a wider halo than the cells' rings: requests */
            if (qs.nb.kind == JF_NB_KNN && !qs.nj &&
                (st = jf__halo_by_cells(&rd, part, box + 6 * a, a, sxyz, m, qs.nb.k, hcap > m ? hcap - m : 0,
                                    jf__parts_grid_bits(n) / 8, nt, &halo, &nh, &served)) != JF_OK)
                break;
            if (!served && !rd.fail) { /* the exact requests (any kind, any cloud) */
                jf_index *own = NULL, *wide = NULL;
                if ((st = jf__index_build_threads(sxyz, m, nt, &own)) != JF_OK) break;
                if (qs.nb.kind == JF_NB_KNN) /* the balls from the cloud's distances */
                    st = jf__wide_index(&rd, part, box, P, &occ, a, own, sxyz, m, &qs, nt, &halo, &nh,
                                    &wide);
                if (st == JF_OK && !halo)
                    st = rd.fail ? JF_ERR_IO
                                 : jf__halo_of(&rd, part, box, P, &occ, a, own, wide ? wide : own, 0.0,
                                           NULL, sxyz, m, &qs, nt, &halo, &nh);
                jf_index_free(wide);
                jf_index_free(own);
            }
            if (rd.fail) st = jf__reader_status(&rd, err);
            if (st != JF_OK) break;
            /* step 3: own + halo in input order, merged from the back into
             * sxyz (the own coordinates stay ahead of the write) */
            size_t ms = m + nh, u = m, v = nh, k = ms;
            uint32_t *sid = malloc(ms * sizeof *sid);
            double *nx = realloc(sxyz, 3 * (ms > cmax ? ms : cmax) * sizeof *nx);
            mask = malloc(ms);
            if (!sid || !nx || !mask) {
                free(sid);
                if (nx) sxyz = nx;
                st = JF_ERR_NOMEM;
                break;
            }
            sxyz = nx;
            while (k > 0) {
                int own_next = v == 0 || (u > 0 && ids[u - 1] > halo[v - 1].id);
                k--;
                if (own_next) {
                    u--;
                    sid[k] = ids[u];
                    memmove(sxyz + 3 * k, sxyz + 3 * u, sizeof(double[3]));
                } else {
                    v--;
                    sid[k] = halo[v].id;
                    memcpy(sxyz + 3 * k, halo[v].x, sizeof(double[3]));
                }
                mask[k] = (uint8_t)own_next;
            }
            free(halo);
            halo = NULL;
            jf_cloud sc = {0};
            sc.n = ms;
            sc.xyz = sxyz;
            if (c->nrm && (snrm = malloc(3 * ms * sizeof *snrm)))
                for (size_t t = 0; t < ms; t++)
                    memcpy(snrm + 3 * t, c->nrm + 3 * (size_t)sid[t], sizeof(double[3]));
            if (c->scan && (sscan = malloc(ms * sizeof *sscan)))
                for (size_t t = 0; t < ms; t++) sscan[t] = c->scan[sid[t]];
            if ((c->nrm && !snrm) || (c->scan && !sscan)) {
                free(sid);
                st = JF_ERR_NOMEM;
                break;
            }
            sc.nrm = snrm;
            sc.scan = sscan;
            sc.scanner = c->scanner;
            sc.nscans = c->nscans;
            if (sweep == 0) {
                jf__cvrec *r = NULL, *g;
                size_t nr = 0;
                st = jf__auto_cv_sample(sxyz, ms, mask, sid, n, NULL, &o->params, nt, &r, &nr);
                if (st == JF_OK && nr) {
                    if ((g = realloc(cvr, (ncv + nr) * sizeof *g))) {
                        cvr = g;
                        memcpy(cvr + ncv, r, nr * sizeof *r);
                        ncv += nr;
                    } else {
                        st = JF_ERR_NOMEM;
                    }
                }
                free(r);
            } else {
                relay rl = {sid, sink, user};
                st = jf__estimate_blocks_masked_xyz(&sc, &po, mask, relay_block, &rl, err);
            }
            free(sid);
            free(snrm);
            free(sscan);
            free(mask);
            snrm = NULL;
            sscan = NULL;
            mask = NULL;
            if (st != JF_OK) goto out;
        }
        if (sweep == 0 && st == JF_OK) {
            po.params.auto_select = jf__auto_cv_select(&o->params, cvr, ncv);
            if (o->auto_chosen) *o->auto_chosen = po.params.auto_select;
            /* step 6's ball from the decision: 32 nearest where every mean
             * is weighted, up to JF_NJ_REACH otherwise */
            if (q.nj) q.nj = jf__nj_reach(&po.params);
        }
    }
    if (st == JF_OK && o->progress) o->progress(o->progress_user, n, n);
out:
    if (st != JF_OK && err && !err->msg[0])
        jf__set_err(err, st == JF_ERR_NOMEM ? "out of memory (parts)" : jf_strerror(st));
    jf__reader_close(&rd);
    free(part);
    free(count);
    free(box);
    free(ids);
    free(halo);
    free(sxyz);
    free(snrm);
    free(sscan);
    free(mask);
    free(ccnt);
    free(cvr);
    free(only);
    free(occ.own);
    return st;
}
