/* parts_run.c -- jf_estimate_parts: the cloud cut into parts processed one
 * at a time, each with an exact halo, so that only one part's index is
 * held at once (`jetfit estimate --memory`, issue 12.1).  The same results
 * as jf_estimate_blocks, bit for bit.
 *
 * design (the parts and requests are parts.c's, shared with jetfit-mpi):
 *  1. Parts: the finite points in (Morton key, index) order cut into P runs
 *     of equal count (jf__parts_split); their bounding boxes.
 *  2. For part a: index its own points; each own point turns its
 *     neighbourhood into at most two requests "the k nearest within
 *     squared distance <= bound", bound its own k-th distance
 *     (jf__halo_requests; in space order, knn points whose own k-th
 *     distance is bounded below every other box's distance by the
 *     previous query's skip theirs: jf__halo_requests_near).  Every
 *     other part b whose box is within a request's bound is indexed in
 *     turn (one at a time) and answers with
 *     its k nearest within the bound; the answers' union is the halo: it
 *     holds every remote point of every own point's neighbourhood over the
 *     whole cloud (a point of b in that neighbourhood is among b's k
 *     nearest within the bound).
 *  3. The part's own points and its halo, in input-index order (so the
 *     k-d tree's tie rule, smaller position first, is the input index's),
 *     form a small cloud; jf_estimate_blocks on it fits the own points only
 *     (the halo points are neighbours): a superset of each neighbourhood
 *     that contains all of it gives the same k nearest, the same order,
 *     the same fit.  The blocks go to the caller's sink with input indices.
 *  Non-finite points belong to no part: their rows (NaN, NONFINITE) are
 *  handed over first.  Index builds: at most P per part (P^2 in all, each
 *  of n/P points).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "fitter_internal.h"
#include "index_internal.h"
#include "jetfit.h"
#include "parts.h"

static void set_err(jf_error *err, const char *msg)
{
    if (err) snprintf(err->msg, sizeof err->msg, "%s", msg);
}

/* The sink of one part: local indices back to input indices. */
typedef struct {
    const uint32_t *ids; /* local -> input index                       */
    jf_block_fn sink;
    void *user;
} relay;

static jf_status relay_block(void *user, const uint32_t *idx, jf_result *res, size_t m)
{
    const relay *r = user;
    uint32_t g[256];
    if (m > 256) return JF_ERR_INVALID;
    for (size_t j = 0; j < m; j++) g[j] = r->ids[idx[j]];
    return r->sink(r->user, g, res, m);
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The points of part a (input order) and their coordinates. */
static size_t gather(const jf_cloud *c, const int32_t *part, int32_t a, uint32_t *ids,
                     double *xyz)
{
    size_t m = 0;
    for (size_t i = 0; i < c->n; i++)
        if (part[i] == a) {
            ids[m] = (uint32_t)i;
            memcpy(xyz + 3 * m, c->xyz + 3 * i, sizeof(double[3]));
            m++;
        }
    return m;
}

typedef struct {
    uint32_t pt;      /* own point (local index)                        */
    jf_halo_req req;
} request;

/* Step 2 for part a: the halo (input indices, ascending, distinct) of
 * its m own points (ids, xyz, indexed by own). */
static jf_status halo_of(const jf_cloud *c, const int32_t *part, const size_t *count,
                         const double *box, int P, int32_t a, const jf_index *own,
                         const double *xyz, size_t m, const jf_part_query *q, int nt,
                         uint32_t **halo, size_t *nhalo)
{
    size_t scratch = (q->cap > q->min_count ? q->cap : q->min_count) + 1;
    request *rq = NULL;
    size_t nrq = 0, caprq = 0;
    uint32_t *idx = malloc(scratch * sizeof *idx), *bids = NULL, *h = NULL;
    double *d2 = malloc(scratch * sizeof *d2), *bxyz = NULL;
    size_t nh = 0, caph = 0, bmax = 0;
    uint32_t *ord = malloc((m ? m : 1) * sizeof *ord);
    jf_status st = idx && d2 && ord ? JF_OK : JF_ERR_NOMEM;
    if (st == JF_OK) st = jf_spatial_order(xyz, m, ord);
    /* requests that reach another part's box (serial: in space order only
     * the points near the part's rim query; kept compact, 32 bytes each) */
    double last[4] = {0, 0, 0, INFINITY};
    for (size_t jj = 0; st == JF_OK && jj < m; jj++) {
        const size_t j = ord[jj];
        jf_halo_req r[2];
        int nr = jf__halo_requests_near(own, q, box, P, a, xyz + 3 * j, last, idx, d2, r);
        for (int t = 0; t < nr; t++) {
            int reach = 0;
            for (int b = 0; b < P && !reach; b++)
                reach = b != a && count[b] && jf__box_dist2(box + 6 * b, xyz + 3 * j) <= r[t].bound;
            if (!reach) continue;
            if (nrq == caprq) {
                caprq = caprq ? 2 * caprq : 1024;
                request *nq = realloc(rq, caprq * sizeof *nq);
                if (!nq) {
                    st = JF_ERR_NOMEM;
                    break;
                }
                rq = nq;
            }
            rq[nrq++] = (request){(uint32_t)j, r[t]};
        }
    }
    for (int b = 0; b < P; b++) bmax = count[b] > bmax ? count[b] : bmax;
    if (st == JF_OK && nrq) {
        bids = malloc(bmax * sizeof *bids);
        bxyz = malloc(3 * bmax * sizeof *bxyz);
        if (!bids || !bxyz) st = JF_ERR_NOMEM;
    }
    for (int b = 0; st == JF_OK && nrq && b < P; b++) {
        if (b == a || !count[b]) continue;
        int touched = 0;
        for (size_t r = 0; r < nrq && !touched; r++)
            touched = jf__box_dist2(box + 6 * b, xyz + 3 * (size_t)rq[r].pt) <= rq[r].req.bound;
        if (!touched) continue;
        size_t mb = gather(c, part, b, bids, bxyz);
        jf_index *ix = NULL;
        if ((st = jf__index_build_threads(bxyz, mb, nt, &ix)) != JF_OK) break;
        for (size_t r = 0; st == JF_OK && r < nrq; r++) {
            const double *p = xyz + 3 * (size_t)rq[r].pt;
            if (!(jf__box_dist2(box + 6 * b, p) <= rq[r].req.bound)) continue;
            size_t found = 0;
            st = jf__index_query(ix, p, rq[r].req.k, rq[r].req.bound, idx, d2, NULL, &found);
            if (st == JF_OK && nh + found > caph) {
                caph = (nh + found) * 2;
                uint32_t *nhp = realloc(h, caph * sizeof *nhp);
                if (!nhp) st = JF_ERR_NOMEM;
                else h = nhp;
            }
            for (size_t t = 0; st == JF_OK && t < found; t++) h[nh++] = bids[idx[t]];
        }
        jf_index_free(ix);
        /* keep the list short as it grows: sort, drop repeats */
        if (st == JF_OK && nh) {
            qsort(h, nh, sizeof *h, cmp_u32);
            size_t u = 1;
            for (size_t t = 1; t < nh; t++)
                if (h[t] != h[u - 1]) h[u++] = h[t];
            nh = u;
        }
    }
    free(rq);
    free(ord);
    free(idx);
    free(d2);
    free(bids);
    free(bxyz);
    if (st != JF_OK) {
        free(h);
        return st;
    }
    *halo = h;
    *nhalo = nh;
    return JF_OK;
}

jf_status jf_estimate_parts(const jf_cloud *c, const jf_estimate_opts *o, int nparts,
                            jf_block_fn sink, void *user, jf_error *err)
{
    if (err) err->msg[0] = '\0';
    if (!c || !o || !sink || (c->n && !c->xyz) || nparts < 1 || nparts > JF_PARTS_MAX) {
        set_err(err, "jf_estimate_parts: NULL argument or nparts out of 1..65536");
        return JF_ERR_INVALID;
    }
    jf_part_query q;
    jf_status st = jf__part_query_init(o, &q);
    if (st == JF_ERR_UNSUPPORTED || o->orient == JF_ORIENT_MST) {
        set_err(err, "parts need a k-d tree neighbourhood (knn, radius) and a per-point "
                     "orientation (not mst)");
        return JF_ERR_UNSUPPORTED;
    }
    if (st != JF_OK || nparts == 1 || c->n == 0)
        return jf_estimate_blocks(c, o, sink, user, err); /* its own checks */
    /* the whole cloud's checks first (a bad option fails before any work);
     * the parts then share one resolved orientation */
    jf_estimate_opts use;
    if ((st = jf__estimate_check(c, o, &use, err)) != JF_OK) return st;
    o = &use;
    const size_t n = c->n;
    const int P = nparts, nt = o->threads > 0 ? o->threads : jf_default_threads(NULL);
    int32_t *part = malloc(n * sizeof *part);
    size_t *count = calloc((size_t)P, sizeof *count), cmax = 0;
    double *box = malloc((size_t)P * 6 * sizeof *box);
    uint32_t *ids = NULL, *halo = NULL;
    double *sxyz = NULL, *snrm = NULL;
    uint32_t *sscan = NULL;
    uint8_t *mask = NULL;
    if (!part || !count || !box) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    if ((st = jf__parts_split(c->xyz, n, P, part)) != JF_OK) goto out;
    for (int b = 0; b < P; b++)
        for (int k = 0; k < 3; k++) box[6 * b + k] = INFINITY, box[6 * b + 3 + k] = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        if (part[i] < 0) continue;
        double *bx = box + 6 * part[i];
        for (int k = 0; k < 3; k++) {
            const double v = c->xyz[3 * i + (size_t)k];
            bx[k] = v < bx[k] ? v : bx[k];
            bx[3 + k] = v > bx[3 + k] ? v : bx[3 + k];
        }
        count[part[i]]++;
    }
    /* the non-finite points' rows */
    {
        jf_result blk[64];
        uint32_t id[64];
        size_t mm = 0;
        for (size_t i = 0; st == JF_OK && i <= n; i++) {
            if (i < n && part[i] >= 0) continue;
            if (i < n) {
                jf_result *r = &blk[mm];
                memset(r, 0, sizeof *r);
                r->status = JF_PT_NONFINITE;
                r->cond = r->residual = NAN;
                for (int j = 0; j < 3; j++) r->pca_eval[j] = NAN;
                jf__result_nan(r);
                id[mm++] = (uint32_t)i;
            }
            if (mm && (mm == 64 || i == n)) {
                st = sink(user, id, blk, mm);
                mm = 0;
            }
        }
        if (st != JF_OK) goto out;
    }
    for (int b = 0; b < P; b++) cmax = count[b] > cmax ? count[b] : cmax;
    ids = malloc((cmax ? cmax : 1) * sizeof *ids);
    sxyz = malloc(3 * (cmax ? cmax : 1) * sizeof *sxyz);
    if (!ids || !sxyz) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    jf_estimate_opts po = *o;
    po.progress = NULL; /* per part: the totals would restart */
    for (int a = 0; a < P && st == JF_OK; a++) {
        if (!count[a]) continue;
        if (o->cancel && o->cancel(o->cancel_user)) {
            st = JF_ERR_CANCELLED;
            set_err(err, "cancelled");
            goto out;
        }
        /* step 2: own index, requests, halo */
        size_t m = gather(c, part, a, ids, sxyz), nh = 0;
        jf_index *own = NULL;
        if ((st = jf__index_build_threads(sxyz, m, nt, &own)) != JF_OK) break;
        st = halo_of(c, part, count, box, P, a, own, sxyz, m, &q, nt, &halo, &nh);
        jf_index_free(own);
        if (st != JF_OK) break;
        /* step 3: own + halo in input order */
        size_t ms = m + nh, u = 0, v = 0, k = 0;
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
        while (u < m || v < nh) {
            int own_next = v == nh || (u < m && ids[u] < halo[v]);
            uint32_t g = own_next ? ids[u++] : halo[v++];
            sid[k] = g;
            mask[k] = (uint8_t)own_next;
            memcpy(sxyz + 3 * k, c->xyz + 3 * (size_t)g, sizeof(double[3]));
            k++;
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
        relay rl = {sid, sink, user};
        st = jf__estimate_blocks_masked(&sc, &po, mask, relay_block, &rl, err);
        free(sid);
        free(snrm);
        free(sscan);
        free(mask);
        snrm = NULL;
        sscan = NULL;
        mask = NULL;
        if (st != JF_OK) goto out;
    }
    if (st == JF_OK && o->progress) o->progress(o->progress_user, n, n);
out:
    if (st != JF_OK && err && !err->msg[0])
        set_err(err, st == JF_ERR_NOMEM ? "out of memory (parts)" : jf_strerror(st));
    free(part);
    free(count);
    free(box);
    free(ids);
    free(halo);
    free(sxyz);
    free(snrm);
    free(sscan);
    free(mask);
    return st;
}
