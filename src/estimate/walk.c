/* walk.c -- the estimate's walk (pipeline.c's design, step 2): threads
 * take chunks of the walk, each with a workspace made once (a fitter per
 * lane, buffers: nothing allocated per point), fit up to four points side
 * by side, and hand the rows over in input order or in blocks; auto's
 * step 6 mixes each row from its neighbours' fits (docs/robustness.md). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#else
#define _mm_sfence() ((void)0)
#endif

#include "core/claim.h"
#include "fitter_internal.h"
#include "index_internal.h"
#include "jetfit.h"
#include "orient_internal.h"
#include "parts.h"
#include "robust_internal.h"
#include "nbctx.h"
#include "neigh_jets.h"
#include "walk.h"

#define CHUNK JF_BLOCK_MAX /* points per scheduling unit (and progress tick) */
#define LANES 4            /* fits side by side (jf__fit_point_x4) */
/* auto's step 6: the points fitted before their rows are mixed from their
 * neighbours' fits; a larger unit fits fewer neighbours twice (those in
 * units not yet done: at its border) */
#define NJ_UNIT (16 * CHUNK)
/* rows that may wait for later units, in units: the front between the
 * walked and the unwalked part of the cloud grows like its square root;
 * on a 10^6 noisy torus one unit's worth overflowed, and 2.4% of the rows
 * had a neighbour fitted twice (on demand: an unshared search, 4.5% of
 * the time), two units' 0.19% */
#define NJ_WAIT 2

/* A row for a point that cannot be fitted: NaN quantities and flags. */
static void nan_result(jf_result *r, unsigned status)
{
    memset(r, 0, sizeof *r);
    r->status = status;
    r->cond = r->residual = r->sigma = NAN;
    for (int j = 0; j < 3; j++) r->pca_eval[j] = NAN;
    jf__result_nan(r);
}

/* ---- per-thread workspace and the per-point step ----------------------- */

typedef struct {
    /* lane k of a pair or quad of fits (jf__fit_point_x2, _x4): its
     * fitter, neighbourhood and (natural fit_moved) raw ring */
    jf_fitter *fit[LANES];
    double *coords[LANES], *raw[LANES];
    jf_natural_ws *nws;
    uint32_t *idx;
    double *d2;
    jf_result *blk;       /* block modes: the chunk's results (CHUNK)   */
    jf__knn_share *share; /* auto: the shared k-NN search               */
    uint32_t *bidx;       /* and their input indices                    */
    double *bxyz;         /* and coordinates (sinkx: the walk's, in order) */
    const double *hint;   /* knn: the last query's neighbours (coords or */
    size_t hint_n;        /* coords[k]) and their count, for knn_hinted  */
    uint32_t *pos;        /* auto's step 6: the query's tree positions   */
    uint32_t *head;       /* and each unit point's nearest (positions)   */
    uint8_t *headn;       /* (JF_NJ_HEAD a point, those step 6 reads) and
                             their count                                 */
    uint32_t *lpos;       /* a lane's nearest positions until its fit    */
    uint32_t *bpos;       /* the unit's rows' tree positions             */
    jf_result *pblk;      /* rows held back to the thread's next unit    */
    uint32_t *pidx, *phead; /* (a record they read not yet fitted), as    */
    double *pxyz;         /* blk, bidx, head, headn, bxyz                */
    uint8_t *pheadn;
    size_t npend, pcap;
    uint8_t *rdy;         /* the unit's rows: all their records fitted   */
    double *dec;          /* the unit's records decoded (jf__nj_cache)   */
    uint8_t *decok;
    uint32_t *oidx;       /* a neighbour fitted on demand (its unit not  */
    double *od2, *oxyz;   /* yet done): its neighbourhood                */
} worker;

static void worker_free(worker *w)
{
    for (int k = 0; k < LANES; k++) {
        jf_fitter_free(w->fit[k]);
        free(w->coords[k]);
        free(w->raw[k]);
    }
    jf_natural_ws_free(w->nws);
    free(w->idx);
    free(w->d2);
    free(w->blk);
    free(w->bidx);
    free(w->bxyz);
    free(w->pos);
    free(w->head);
    free(w->headn);
    free(w->lpos);
    free(w->bpos);
    free(w->pblk);
    free(w->pidx);
    free(w->phead);
    free(w->pxyz);
    free(w->pheadn);
    free(w->rdy);
    free(w->dec);
    free(w->decok);
    free(w->oidx);
    free(w->od2);
    free(w->oxyz);
    jf__knn_share_free(w->share);
    memset(w, 0, sizeof *w);
}

static jf_status worker_init(worker *w, const jf_params *p, const nbctx *x, int blocks)
{
    memset(w, 0, sizeof *w);
    jf_status st = JF_OK;
    for (int k = 0; k < LANES && st == JF_OK; k++) {
        st = jf_fitter_create(p, &w->fit[k]);
        if (st != JF_OK) break;
        w->coords[k] = malloc(3 * x->cap * sizeof *w->coords[k]);
        if (x->fit_moved) w->raw[k] = malloc(3 * x->cap * sizeof *w->raw[k]);
        if (!w->coords[k] || (x->fit_moved && !w->raw[k])) st = JF_ERR_NOMEM;
    }
    if (st == JF_OK && x->nt) st = jf_natural_ws_create(x->nt, &w->nws);
    if (st == JF_OK) {
        w->idx = malloc(x->cap * sizeof *w->idx);
        w->d2 = malloc(x->cap * sizeof *w->d2);
        if (!w->idx || !w->d2) st = JF_ERR_NOMEM;
    }
    const size_t unit = x->nj ? NJ_UNIT : CHUNK;
    if (st == JF_OK && (blocks || x->nj)) {
        w->blk = malloc(unit * sizeof *w->blk);
        w->bidx = malloc(unit * sizeof *w->bidx);
        w->bxyz = malloc(3 * unit * sizeof *w->bxyz);
        if (!w->blk || !w->bidx || !w->bxyz) st = JF_ERR_NOMEM;
    }
    if (st == JF_OK && x->nj) {
        w->pos = malloc(x->cap * sizeof *w->pos);
        w->head = malloc(unit * JF_NJ_HEAD * sizeof *w->head);
        w->lpos = malloc(LANES * JF_NJ_REACH * sizeof *w->lpos);
        w->headn = malloc(unit);
        w->bpos = malloc(unit * sizeof *w->bpos);
        w->pcap = NJ_WAIT * unit; /* rows wait for the units around theirs */
        w->pblk = malloc(w->pcap * sizeof *w->pblk);
        w->pidx = malloc(w->pcap * sizeof *w->pidx);
        w->phead = malloc(w->pcap * JF_NJ_HEAD * sizeof *w->phead);
        w->pxyz = malloc(3 * w->pcap * sizeof *w->pxyz);
        w->pheadn = malloc(w->pcap);
        w->rdy = malloc(unit);
        w->dec = malloc(unit * JF_NJ_DEC * sizeof *w->dec);
        w->decok = malloc(unit);
        w->oidx = malloc(x->cap * sizeof *w->oidx);
        w->od2 = malloc(x->cap * sizeof *w->od2);
        w->oxyz = malloc(3 * x->cap * sizeof *w->oxyz);
        if (!w->pos || !w->head || !w->lpos || !w->headn || !w->bpos || !w->pblk || !w->pidx || !w->phead ||
            !w->pxyz || !w->pheadn || !w->rdy || !w->dec || !w->decok || !w->oidx ||
            !w->od2 || !w->oxyz)
            st = JF_ERR_NOMEM;
    }
    if (st == JF_OK && jf__nj_on(p, x->nb)) /* auto's search, shared along the walk */
        st = jf__knn_share_create(x->nb->k < x->cap ? x->nb->k : x->cap, x->nj->reach, &w->share);
    if (st != JF_OK) worker_free(w);
    return st;
}

/* mst: keep the gk nearest of the neighbourhood as i's graph edges. */
static void keep_edges(const nbctx *x, size_t i, const uint32_t *idx, size_t found)
{
    uint32_t *row = x->graph + i * x->gk;
    size_t m = 0;
    for (size_t j = 0; j < found && m < x->gk; j++)
        if (idx[j] != i) row[m++] = idx[j];
    while (m < x->gk) row[m++] = UINT32_MAX;
}

/* The row of a point with a non-finite coordinate (and no graph edges). */
static void nonfinite_row(const nbctx *x, size_t i, jf_result *out)
{
    if (x->graph) keep_edges(x, i, NULL, 0);
    nan_result(out, JF_PT_NONFINITE);
}

/* Row i of the output.  The rows are scattered in input order when the
 * walk is the tree's: streaming stores skip reading each row's cache
 * lines before overwriting them (measured 4% of the time at 10^6 points,
 * knn:16).  The chunk loop fences them. */
static void store_row(jf_result *out, const jf_result *r)
{
#if defined(__SSE2__) && defined(__x86_64__) && !defined(__SANITIZE_ADDRESS__)
    long long *dst = (long long *)out;
    const long long *src = (const long long *)r;
    if (sizeof *r % sizeof *src == 0 && (uintptr_t)dst % sizeof *src == 0) {
        for (size_t b = 0; b < sizeof *r / sizeof *src; b++) _mm_stream_si64(dst + b, src[b]);
        return;
    }
#endif
    *out = *r;
}

static double *raw_of(const worker *w, const double *coords)
{
    int k = 0;
    while (k + 1 < LANES && coords != w->coords[k]) k++;
    return w->raw[k];
}

/* fit_moved: the residual of the raw ring about the jet fitted to the
 * moved one (the moved points' own residual says nothing of the scan's
 * noise); plain fits only (the last fit on f is the point's). */
static void raw_residual(const worker *w, const nbctx *x, const jf_fitter *f, const double *coords,
                         size_t found, jf_result *r)
{
    if (x->fit_moved && x->plain && !(r->status & JF_PT_FAILED))
        r->residual = jf__fitter_rms(f, raw_of(w, coords), found);
}

/* Point i, at p (its coordinates, from the input or the tree's copy): its
 * neighbourhood into coords (*found points).  Returns 1 in *fit if it is
 * to be fitted; else its row is final in *row. */
static jf_status prepare(worker *w, const nbctx *x, size_t i, const double *p, double *coords,
                         jf_result *row, size_t *found, unsigned *flags, int *fit)
{
    *fit = 0;
    if (!jf__finite3(p)) {
        nonfinite_row(x, i, row);
        return JF_OK;
    }
    const double *hint = w->hint != coords ? w->hint : NULL; /* coords: overwritten */
    jf_status st =
        jf__nb_point(x, w->nws, w->share, i, p, w->idx, w->pos, w->d2, coords, found, flags, hint,
                 w->hint_n);
    if (st != JF_OK) return st;
    w->hint = coords;
    w->hint_n = *found;
    if (x->graph) keep_edges(x, i, w->idx, *found);
    if (*flags & JF_PT_FAILED) {
        nan_result(row, *flags);
        return JF_OK;
    }
    const int gathered = x->nb->kind <= JF_NB_KNN_RADIUS; /* by jf__nb_point */
    /* fit_moved: the moved points are fitted, the raw ones kept for the
     * residual (raw_of: the buffer beside coords) */
    double *raw = x->fit_moved ? raw_of(w, coords) : coords;
    if (!gathered && (x->fit_moved || x->nb->kind != JF_NB_NATURAL))
        for (size_t j = 0; j < *found; j++)
            memcpy(raw + 3 * j, x->xyz + 3 * (size_t)w->idx[j], sizeof(double[3]));
    /* natural: the structure's copy, in space order (moved: the jets') */
    if (x->nb->kind == JF_NB_NATURAL) jf__natural_coords(w->nws, *found, coords);
    *fit = 1;
    return JF_OK;
}

/* Points i[0..L-1] (L = 1, 2 or 4 consecutive points of the walk): with
 * L > 1, plain fits (x->plain) run side by side in one jf__fit_point_x2
 * or _x4 (their 2- and 4-lane eigen-solvers), the same bits as one by
 * one; a lane with no fit sends the others one by one. */
static jf_status fit_lanes(worker *w, const nbctx *x, int L, const size_t i[], const double *const p[],
                           jf_result *const out[])
{
    jf_result r[LANES];
    size_t n[LANES] = {0};
    unsigned fl[LANES] = {0};
    int fit[LANES] = {0}, all = 1;
    jf_status st = JF_OK;
    for (int k = 0; k < L && st == JF_OK; k++) {
        st = prepare(w, x, i[k], p[k], w->coords[k], &r[k], &n[k], &fl[k], &fit[k]);
        all &= fit[k];
    }
    if (st != JF_OK) return st;
    if (all && L == 4) {
        const double *const cc[4] = {w->coords[0], w->coords[1], w->coords[2], w->coords[3]};
        jf_result *const rr[4] = {&r[0], &r[1], &r[2], &r[3]};
        st = jf__fit_point_x4(w->fit, p, cc, n, rr);
    } else if (all && L == 2)
        st = jf__fit_point_x2(w->fit[0], p[0], w->coords[0], n[0], &r[0], w->fit[1], p[1],
                              w->coords[1], n[1], &r[1]);
    for (int k = 0; k < L && st == JF_OK; k++) {
        jf_fitter *f = all && L > 1 ? w->fit[k] : w->fit[0];
        if (fit[k] && !(all && L > 1)) st = jf_fit_point_full(f, p[k], w->coords[k], n[k], &r[k]);
        if (fit[k] && st == JF_OK) raw_residual(w, x, f, w->coords[k], n[k], &r[k]);
    }
    if (st != JF_OK) return st;
    for (int k = 0; k < L; k++) {
        if (fit[k]) r[k].status |= fl[k];
        store_row(out[k], &r[k]);
    }
    return JF_OK;
}


/* A block of m results (input indices idx) leaves: kept for mst, or
 * oriented point by point and handed to the sink.  Thread-safe as far as
 * the sink is. */
static jf_status deliver(const jf__runctx *R, const uint32_t *idx, const double *xyz, jf_result *res,
                         size_t m)
{
    const jf_estimate_opts *o = R->o;
    const jf_cloud *c = R->c;
    if (R->collect) {
        for (size_t j = 0; j < m; j++) {
            memcpy(R->vn + 3 * (size_t)idx[j], res[j].normal, sizeof(double[3]));
            R->vs[idx[j]] = res[j].status;
        }
        return JF_OK;
    }
    for (size_t j = 0; j < m; j++) {
        const size_t i = idx[j];
        const double *p = c->xyz + 3 * i, *s;
        double dir[3];
        switch (o->orient) {
        case JF_ORIENT_INPUT: jf__orient_point(&res[j], c->nrm + 3 * i); break;
        case JF_ORIENT_VIEWPOINT:
        case JF_ORIENT_SCANNER:
            s = o->orient == JF_ORIENT_VIEWPOINT ? o->viewpoint : c->scanner + 3 * (size_t)c->scan[i];
            for (int k = 0; k < 3; k++) dir[k] = s[k] - p[k];
            jf__orient_point(&res[j], dir);
            break;
        case JF_ORIENT_MST:
            if (R->vf[i]) jf_result_flip(&res[j]);
            res[j].status |= R->vs[i];
            break;
        default: break;
        }
    }
    /* sinkx: the block's coordinates as walked (in tree order, from the
     * tree's copy), so the sink's rows need no gather by input index */
    return R->sinkx ? R->sinkx(R->user, idx, xyz, res, m) : R->sink(R->user, idx, res, m);
}

/* natural: what jf__nb_point reads of point i by input index (its flags and
 * vertex), asked PREFETCH points of the walk ahead: in the tree's walk
 * these are cache misses (the input is in any order). */
#define PREFETCH 8
static void prefetch_natural(const nbctx *x, size_t i)
{
    __builtin_prefetch(x->nflags + i);
    jf__natural_prefetch(x->nt, i);
}

/* After a thread's chunk (or unit) of cnt walk points with status wst:
 * its failure kept, the count done, and on the calling thread only the
 * progress and cancel hooks (a stop is seen by every thread before its
 * next claim). */
static void fail_keep(jf_status st, jf_status *failed)
{
    if (st != JF_OK) {
#pragma omp atomic write
        *failed = st;
    }
}

/* Whether a thread takes no more work: its own failure or another's. */
static int stop_seen(jf_status wst, jf_status *failed)
{
    jf_status seen;
#pragma omp atomic read
    seen = *failed;
    return seen != JF_OK || wst != JF_OK;
}

static void block_done(const jf__runctx *R, jf_status wst, size_t cnt, size_t *done, jf_status *failed)
{
    const jf_estimate_opts *o = R->o;
    fail_keep(wst, failed);
    size_t now;
#pragma omp atomic capture
    now = *done += cnt;
    if (omp_get_thread_num() == 0) {
        if (o->progress) o->progress(o->progress_user, now, R->total);
        if (o->phase) o->phase(o->phase_user, JF_PHASE_FIT, now, R->total);
        if (jf__cancelled(o)) {
#pragma omp atomic write
            *failed = JF_ERR_CANCELLED;
        }
    }
}

/* Step 2 over walk[0..nwalk-1] (coordinates from walk_xyz, the tree's
 * copy, when not NULL): chunks of CHUNK points shared out dynamically. */
static jf_status fit_pass(const jf__runctx *R, const uint32_t *walk, const double *walk_xyz,
                          size_t nwalk, int nt)
{
    const jf_estimate_opts *o = R->o;
    const nbctx *x = R->x;
    const int blocks = R->out == NULL;
    size_t nchunks = (nwalk + CHUNK - 1) / CHUNK, done = R->done0;
    size_t next = 1; /* the next chunk to claim (core/claim.h) */
    jf_status failed = JF_OK;
#pragma omp parallel num_threads(nt)
    {
        worker w;
        jf_status wst = worker_init(&w, &o->params, x, blocks);
        fail_keep(wst, &failed);
        /* chunk 0 the calling thread's: its progress and cancel hooks run
         * during the pass (core/claim.h) */
        for (size_t ch = jf__claim_first(&next); ch < nchunks; ch = jf__claim_next(&next)) {
            if (stop_seen(wst, &failed)) continue;
            size_t beg = ch * CHUNK, end = beg + CHUNK < nwalk ? beg + CHUNK : nwalk;
            const uint8_t *fit = R->fit;
            size_t m = 0; /* block modes: results in w.blk */
            for (size_t k = beg; k < end && wst == JF_OK;) {
                const size_t i = walk[k];
                if (x->nt) /* k steps by up to 4 (quads) */
                    for (size_t q = k + PREFETCH; q < k + PREFETCH + 4 && q < nwalk; q++)
                        prefetch_natural(x, walk[q]);
                const double *pt = walk_xyz ? walk_xyz + 3 * k : R->c->xyz + 3 * i;
                if (fit && !fit[i]) { /* a halo point: a neighbour only */
                    if (!blocks) nan_result(&R->out[i], JF_PT_NONFINITE);
                    k++;
                    continue;
                }
                if (blocks) w.bidx[m] = (uint32_t)i, memcpy(w.bxyz + 3 * m, pt, 3 * sizeof *pt);
                jf_result *d0 = blocks ? &w.blk[m++] : &R->out[i];
                /* plain fits go four (or two) at a time while the next points
                 * are to be fitted in this chunk */
                int L = 1;
                if (x->plain && k + 3 < end &&
                    (!fit || (fit[walk[k + 1]] && fit[walk[k + 2]] && fit[walk[k + 3]])))
                    L = 4;
                else if (x->plain && k + 1 < end && (!fit || fit[walk[k + 1]]))
                    L = 2;
                size_t iq[LANES] = {i};
                const double *pq[LANES] = {pt};
                jf_result *oq[LANES] = {d0};
                for (int q = 1; q < L; q++) {
                    iq[q] = walk[k + q];
                    pq[q] = walk_xyz ? walk_xyz + 3 * (k + q) : R->c->xyz + 3 * iq[q];
                    if (blocks) w.bidx[m] = (uint32_t)iq[q], memcpy(w.bxyz + 3 * m, pq[q], 3 * sizeof *pt);
                    oq[q] = blocks ? &w.blk[m++] : &R->out[iq[q]];
                }
                if (L == 1 && w.share && walk_xyz) jf__knn_share_ahead(w.share, pt, end - k);
                wst = fit_lanes(&w, x, L, iq, pq, oq);
                k += (size_t)L;
            }
            _mm_sfence(); /* the streamed rows (store_row), before anyone reads them */
            if (wst == JF_OK && blocks && m) wst = deliver(R, w.bidx, w.bxyz, w.blk, m);
            block_done(R, wst, end - beg, &done, &failed);
        }
        worker_free(&w);
    }
    return failed;
}

/* Auto's points i[0..L-1] (rows kq[] of the unit; left[]: the walk's
 * points from each on, for the shared search): their queries one by one,
 * each one's nearest positions kept for step 6, then their fits side by
 * side (jf__fit_auto_lanes: the bits of one by one). */
static jf_status auto_lanes(worker *w, const nbctx *x, int L, const size_t i[], const double *const p[],
                            const size_t kq[], const size_t left[])
{
    jf_result r[LANES];
    size_t n[LANES] = {0}, ln[LANES] = {0};
    unsigned fl[LANES] = {0};
    int fit[LANES] = {0}, nf = 0;
    const double *pf[LANES], *cf[LANES];
    size_t nff[LANES];
    jf_result *of[LANES];
    for (int k = 0; k < L; k++) {
        if (w->share && left) jf__knn_share_ahead(w->share, p[k], left[k]);
        w->hint_n = 0;
        jf_status st = prepare(w, x, i[k], p[k], w->coords[k], &r[k], &n[k], &fl[k], &fit[k]);
        if (st != JF_OK) return st;
        /* prepare's query left the neighbourhood in w->pos: which of it
         * step 6 reads depends on the fit (jf__nj_head) */
        ln[k] = w->hint_n < x->nj->reach ? w->hint_n : x->nj->reach;
        memcpy(w->lpos + k * JF_NJ_REACH, w->pos, ln[k] * sizeof *w->lpos);
        if (fit[k]) pf[nf] = p[k], cf[nf] = w->coords[k], nff[nf] = n[k], of[nf++] = &r[k];
    }
    const jf_params *pr = jf_fitter_params(w->fit[0]);
    jf_status st = nf ? jf__fit_auto_lanes(w->fit[0], pr, nf, pf, cf, nff, of) : JF_OK;
    if (st != JF_OK) return st;
    for (int k = 0; k < L; k++) {
        if (fit[k]) r[k].status |= fl[k];
        size_t step, c = jf__nj_head(x->nj, &r[k], jf__nj_weighted(x->nj, &r[k]), &step), h = 0;
        uint32_t *hd = w->head + kq[k] * JF_NJ_HEAD;
        for (size_t t = 0; h < c && t < ln[k]; t += step) hd[h++] = w->lpos[k * JF_NJ_REACH + t];
        w->headn[kq[k]] = (uint8_t)h;
        store_row(&w->blk[kq[k]], &r[k]);
    }
    return JF_OK;
}

/* Auto's step 6: the record of the point at tree position j, fitted here
 * because its own unit is not done: the same neighbourhood (knn_share.c
 * gives one search's lists) and fit as its own walk step makes, so the
 * same bytes. */
static jf_status nj_fit_other(worker *w, const nbctx *x, uint32_t j)
{
    jf_result r;
    size_t found = 0;
    const double *p = x->pts + 3 * (size_t)j;
    jf_status st =
        jf__nb_query_xyz(x->ix, x->nb, x->min_count, p, w->oidx, w->od2, w->oxyz, x->cap, &found);
    if (st == JF_OK) st = jf_fit_point_full(w->fit[0], p, w->oxyz, found, &r);
    if (st != JF_OK) return st;
    if (found < x->want) r.status |= JF_PT_FEW_NEIGHBORS;
    jf__nj_put(x->nj, j, &r);
    return JF_OK;
}

/* Rows of step 6 not yet mixed: a unit's (the worker's blk, bidx, head,
 * headn, bxyz) or those held back (pblk, ...). */
typedef struct {
    jf_result *blk;
    uint32_t *idx, *head; /* inputs; the positions step 6 reads, JF_NJ_HEAD a row */
    double *xyz;
    uint8_t *headn;       /* how many */
} njrows;

static void nj_move(const njrows *a, size_t k, const njrows *b, size_t t)
{
    if (a == b && k == t) return;
    b->blk[t] = a->blk[k];
    b->idx[t] = a->idx[k];
    memcpy(b->xyz + 3 * t, a->xyz + 3 * k, 3 * sizeof *b->xyz);
    memcpy(b->head + t * JF_NJ_HEAD, a->head + k * JF_NJ_HEAD, a->headn[k] * sizeof *b->head);
    b->headn[t] = a->headn[k];
}

/* Whether every record row k reads is fitted. */
static int nj_ready(const nbctx *x, const njrows *r, size_t k)
{
    const uint32_t *hd = r->head + k * JF_NJ_HEAD;
    const size_t h = r->headn[k];
    for (size_t t = 0; t < h; t++)
        if (jf__nj_state(x->nj, hd[t]) == JF_NJ_EMPTY) return 0;
    return 1;
}

/* Step 6 for rows 0..m-1 of r: the records they read not yet fitted are
 * fitted here, each row mixed, the rows delivered by blocks. */
static jf_status nj_finish(const jf__runctx *R, worker *w, const jf__nj_cache *c, const njrows *r,
                           size_t m)
{
    const nbctx *x = R->x;
    jf_result *blk = r->blk;
    const uint32_t *bidx = r->idx;
    const double *bxyz = r->xyz;
    jf_status st = JF_OK;
    for (size_t k = 0; k < m && st == JF_OK; k++) {
        const uint32_t *hd = r->head + k * JF_NJ_HEAD;
        const size_t h = r->headn[k];
        for (size_t t = 0; t < h && st == JF_OK; t++)
            if (jf__nj_state(x->nj, hd[t]) == JF_NJ_EMPTY) st = nj_fit_other(w, x, hd[t]);
        if (st == JF_OK) jf__nj_mix(x->nj, c, x->pts, bxyz + 3 * k, hd, h, &blk[k]);
    }
    for (size_t k = 0; k < m && st == JF_OK; k += CHUNK) {
        const size_t b = m - k < CHUNK ? m - k : CHUNK;
        if (R->out)
            for (size_t j = k; j < k + b; j++) store_row(&R->out[bidx[j]], &blk[j]);
        else
            st = deliver(R, bidx + k, bxyz + 3 * k, blk + k, b);
    }
    _mm_sfence();
    return st;
}

/* Step 2 for auto with step 6: each unit of the walk is fitted (each
 * point's record published, its nearest kept), then each row is mixed
 * from its nearest's records; a row that reads a record not yet fitted
 * waits for the thread's next unit (on one thread the next of the walk,
 * which fits most of them), else fits it on demand.  The rows leave by
 * blocks as in fit_pass. */
static jf_status fit_pass_nj(const jf__runctx *R, const uint32_t *walk, const double *walk_xyz,
                             size_t nwalk, int nt)
{
    const jf_estimate_opts *o = R->o;
    const nbctx *x = R->x;
    /* the unit: large (few border points fitted twice), but a few per
     * thread; the rows do not depend on it */
    size_t unit = nwalk / (4 * (size_t)nt);
    unit = unit < CHUNK ? CHUNK : unit > NJ_UNIT ? NJ_UNIT : unit;
    size_t nunits = (nwalk + unit - 1) / unit, done = R->done0, next = 1;
    jf_status failed = walk_xyz == x->pts ? JF_OK : JF_ERR_INVALID; /* the tree's walk */
#pragma omp parallel num_threads(nt)
    {
        worker w = {0};
        jf_status wst = failed == JF_OK ? worker_init(&w, &o->params, x, 1) : failed;
        if (wst == JF_OK && !w.share) wst = JF_ERR_INVALID; /* positions come from it */
        if (w.pcap > NJ_WAIT * unit) w.pcap = NJ_WAIT * unit; /* a small cloud's units: a shorter list */
        fail_keep(wst, &failed);
        for (size_t u = jf__claim_first(&next); u < nunits; u = jf__claim_next(&next)) {
            if (stop_seen(wst, &failed)) continue;
            const size_t beg = u * unit, nu = beg + unit < nwalk ? unit : nwalk - beg;
            size_t m = 0; /* the unit's points to fit (a part's halo: not) */
            for (size_t kk = 0; kk < nu && wst == JF_OK;) {
                /* up to LANES points to fit, fitted side by side (auto_lanes) */
                int L = 0;
                size_t iq[LANES], kq[LANES], left[LANES];
                const double *pq[LANES];
                for (; kk < nu && L < LANES; kk++) {
                    const size_t i = walk[beg + kk], k = m;
                    const double *pt = walk_xyz ? walk_xyz + 3 * (beg + kk) : R->c->xyz + 3 * i;
                    if (R->fit && !R->fit[i]) {
                        if (R->out) nan_result(&R->out[i], JF_PT_NONFINITE);
                        continue;
                    }
                    m++;
                    w.bidx[k] = (uint32_t)i;
                    memcpy(w.bxyz + 3 * k, pt, 3 * sizeof *pt);
                    w.bpos[k] = (uint32_t)(beg + kk);
                    iq[L] = i, pq[L] = pt, kq[L] = k, left[L++] = nu - kk;
                }
                if (L) wst = auto_lanes(&w, x, L, iq, pq, kq, walk_xyz ? left : NULL);
            }
            /* the records after the fits: a locked store right after a fit
             * waits for its stores to drain */
            for (size_t k = 0; k < m && wst == JF_OK; k++) jf__nj_put(x->nj, w.bpos[k], &w.blk[k]);
            for (size_t t = 0; t < nu && wst == JF_OK; t++)
                w.decok[t] = jf__nj_state(x->nj, beg + t) == JF_NJ_EMPTY
                                 ? 2 /* a halo point: maybe fitted on demand below */
                                 : (uint8_t)jf__nj_decode(x->nj, beg + t, w.dec + JF_NJ_DEC * t);
            const jf__nj_cache cache = {w.dec, w.decok, beg, nu};
            /* the unit's rows whose records are all fitted go now (the
             * front of cur), the others wait in pend while it has room
             * (else fitted on demand); then the waiting rows now ready */
            const njrows cur = {w.blk, w.bidx, w.head, w.bxyz, w.headn};
            const njrows pend = {w.pblk, w.pidx, w.phead, w.pxyz, w.pheadn};
            size_t nr = 0, wait = 0, keep = 0;
            for (size_t k = 0; k < m; k++) wait += !(w.rdy[k] = (uint8_t)nj_ready(x, &cur, k));
            /* no room: the rows waiting longest go first (on demand) */
            size_t out = w.npend + wait > w.pcap ? w.npend + wait - w.pcap : 0;
            out = out < w.npend ? out : w.npend;
            if (out && wst == JF_OK) wst = nj_finish(R, &w, &cache, &pend, out);
            for (size_t k = out; k < w.npend; k++) nj_move(&pend, k, &pend, k - out);
            w.npend -= out;
            const size_t np0 = w.npend;
            for (size_t k = 0; k < m; k++) {
                if (!w.rdy[k] && w.npend < w.pcap) nj_move(&cur, k, &pend, w.npend++);
                else nj_move(&cur, k, &cur, nr++);
            }
            for (size_t k = 0; k < w.npend && wst == JF_OK; k++) {
                if (k >= np0 || !nj_ready(x, &pend, k)) {
                    nj_move(&pend, k, &pend, keep++);
                    continue;
                }
                if (nr == unit) { /* cur full */
                    wst = nj_finish(R, &w, &cache, &cur, nr);
                    nr = 0;
                }
                nj_move(&pend, k, &cur, nr++);
            }
            w.npend = keep;
            if (wst == JF_OK) wst = nj_finish(R, &w, &cache, &cur, nr);
            block_done(R, wst, nu, &done, &failed);
        }
        /* the last rows held back: what they read, fitted on demand */
        const njrows pend = {w.pblk, w.pidx, w.phead, w.pxyz, w.pheadn};
        if (w.npend && !stop_seen(wst, &failed)) fail_keep(nj_finish(R, &w, NULL, &pend, w.npend), &failed);
        worker_free(&w);
    }
    return failed;
}

jf_status jf__walk_nonfinite(const jf__runctx *R, size_t n)
{
    jf_result blk[64];
    uint32_t idx[64];
    double bxyz[3 * 64];
    size_t m = 0;
    jf_status st = JF_OK;
    for (size_t i = 0; i < n && st == JF_OK; i++) {
        if (jf__finite3(R->c->xyz + 3 * i)) continue;
        if (R->out) {
            nonfinite_row(R->x, i, &R->out[i]);
            continue;
        }
        nonfinite_row(R->x, i, &blk[m]);
        memcpy(bxyz + 3 * m, R->c->xyz + 3 * i, sizeof(double[3]));
        idx[m++] = (uint32_t)i;
        if (m == 64 || i + 1 == n) {
            st = deliver(R, idx, bxyz, blk, m);
            m = 0;
        }
    }
    if (st == JF_OK && m) st = deliver(R, idx, bxyz, blk, m);
    return st;
}

static jf_status pass_status(jf_status failed, jf_error *err)
{
    if (failed == JF_ERR_CANCELLED) return jf__cancel_status(err);
    if (failed != JF_OK)
        jf__set_err(err, failed == JF_ERR_NOMEM ? "out of memory (per-thread workspace)"
                                            : "a neighbourhood query or fit failed");
    return failed;
}

jf_status jf__walk_pass(const jf__runctx *R, const uint32_t *walk, const double *walk_xyz, size_t nwalk,
                        int nt, jf_error *err)
{
    const jf_status st = R->x->nj ? fit_pass_nj(R, walk, walk_xyz, nwalk, nt)
                                  : fit_pass(R, walk, walk_xyz, nwalk, nt);
    return pass_status(st, err);
}
