/* parts_halo.c -- step 2 of the bounded-memory estimate (parts_run.c's
 * design): a part's halo, every point of the other parts its own points'
 * neighbourhoods may reach, from scans of the cloud; no other part
 * indexed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "parts_run.h"

typedef struct {
    uint32_t pt;      /* own point (local index)                        */
    jf_halo_req req;
} request;

/* A growable array of requests (one per thread). */
typedef struct {
    request *r;
    size_t n, cap;
} rvec;

static int rvec_push(rvec *v, request x)
{
    void *nv = jf__grow(v->r, &v->cap, v->n, sizeof *v->r);
    if (!nv) return 0;
    v->r = nv;
    v->r[v->n++] = x;
    return 1;
}

static int cmp_f64(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Max-heap of the k smallest squared distances (a far request's). */
static void heap_push(double *h, size_t *n, size_t k, double d)
{
    if (*n < k) {
        size_t i = (*n)++;
        while (i && h[(i - 1) / 2] < d) {
            h[i] = h[(i - 1) / 2];
            i = (i - 1) / 2;
        }
        h[i] = d;
        return;
    }
    if (!(d < h[0])) return;
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, b = i;
        double vb = d;
        if (l < *n && h[l] > vb) b = l, vb = h[l];
        if (r < *n && h[r] > vb) b = r;
        if (b == i) break;
        h[i] = h[b];
        i = b;
    }
    h[i] = d;
}

/* A ball's half side, inflated so that every point the k-d tree finds
 * within squared distance b (its rounded sum) lies inside the box: the
 * relative margin covers the roundings, the absolute one squares that
 * underflow to 0. */
static double ball_r(double b) { return sqrt(b) * (1 + 1e-9) + 1e-140; }

static int hvec_push(hvec *a, uint32_t id, const double *x)
{
    void *nv = jf__grow(a->v, &a->cap, a->n, sizeof *a->v);
    if (!nv) return 0;
    a->v = nv;
    a->v[a->n].id = id;
    memcpy(a->v[a->n].x, x, sizeof(double[3]));
    a->n++;
    return 1;
}

static int cmp_hpoint(const void *a, const void *b)
{
    uint32_t x = ((const hpoint *)a)->id, y = ((const hpoint *)b)->id;
    return (x > y) - (x < y);
}

#define FAR_FINITE 16           /* finite-bound requests answered by a scan */
#define FAR_RATIO 64.0          /* ... when their bound exceeds 64 x median */
#define REQ_CHUNK 4096          /* own points per task of the request pass */

/* Step 2 for part a: the halo (input indices, ascending, distinct) of
 * its m own points (xyz, indexed by own).
 * design: each own point's requests (k, bound) that reach another part's
 * box (in space order, chunks of REQ_CHUNK on the threads) describe balls;
 * a remote point within a ball's bound may be a neighbour, and one outside
 * every ball is none (parts.c: the own k-th distance bounds the cloud's).
 * So the balls' bounding boxes mark the cells of a grid (cell side the
 * median ball radius), and one parallel scan of the cloud keeps the points
 * of other parts in a marked cell: a superset of the halo, which the fit
 * then narrows exactly.  Balls too large for the grid (an isolated point,
 * a part with fewer than k points: bound up to inf) are few; each keeps
 * the k smallest distances in the scan, and a second scan takes the
 * points within its k-th: a superset too.  Cost: two index-free passes
 * over the cloud's coordinates, no other part indexed. */
jf_status jf__halo_of(reader *rd, const int32_t *part, const double *box, int P,
                         const occgrid *occ, int32_t a,
                         const jf_index *own, const jf_index *qix, double cap, int *capped,
                         const double *xyz, size_t m, const jf_part_query *q, int nt,
                         hpoint **halo, size_t *nhalo)
{
    const size_t scratch = (q->cap > q->min_count ? q->cap : q->min_count) + 1;
    const size_t n = rd->n;
    const int knn = q->nb.kind == JF_NB_KNN;
    rvec *trq = calloc((size_t)nt, sizeof *trq);
    hvec *th = calloc((size_t)nt, sizeof *th);
    request *rq = NULL, *far = NULL;
    double *bs = NULL, *heaps = NULL;
    size_t *hn = NULL;
    uint64_t *bits = NULL;
    size_t nrq = 0, nfar = 0, kmax = 0;
    jf_status st = trq && th ? JF_OK : JF_ERR_NOMEM;
    /* the own index's leaf order: spatially coherent, as a Morton order */
    const double *lp = NULL;
    const uint32_t *lid = NULL;
    if (jf__index_points(own, &lp, &lid) != m) st = JF_ERR_INVALID;
    /* 1. the requests that reach another part's box */
    if (st == JF_OK) {
        const size_t nchunk = (m + REQ_CHUNK - 1) / REQ_CHUNK;
        int fail = 0;
#pragma omp parallel num_threads(nt)
        {
            rvec *mine = &trq[omp_get_thread_num()];
            uint32_t *idx = malloc(scratch * sizeof *idx);
            double *d2 = malloc(scratch * sizeof *d2);
            int ok = idx && d2;
#pragma omp for schedule(dynamic, 1)
            for (size_t ch = 0; ch < nchunk; ch++) {
                double last[4] = {0, 0, 0, INFINITY};
                const size_t end = (ch + 1) * REQ_CHUNK < m ? (ch + 1) * REQ_CHUNK : m;
                for (size_t jj = ch * REQ_CHUNK; ok && jj < end; jj++) {
                    const size_t j = lid[jj];
                    const double *p = lp + 3 * jj;
                    if (q->only && !q->only[j]) continue;
                    jf_halo_req r[2];
                    if (knn && last[3] < INFINITY) {
                        /* own k-th distance <= last's + |p - last|
                         * (triangle inequality): no foreign cell within
                         * it, no request, no query */
                        double dd = 0;
                        for (int k = 0; k < 3; k++) dd += (p[k] - last[k]) * (p[k] - last[k]);
                        const double step = (q->nj ? 3.0 : 1.0) * sqrt(dd); /* parts.c */
                        if (occ_free(occ, p, (step + last[3]) * (1 + 1e-9) + 1e-140, 64, a))
                            continue;
                    }
                    int nr = jf__halo_requests(qix, q, p, idx, d2, r);
                    if (knn && nr == 1) {
                        memcpy(last, p, sizeof(double[3]));
                        last[3] = sqrt(r[0].bound);
                    }
                    for (int t = 0; t < nr && ok; t++)
                        if (!occ_free(occ, p, ball_r(r[t].bound), OCC_PROBE, a))
                            ok = rvec_push(mine, (request){(uint32_t)j, r[t]});
                }
            }
            if (!ok) {
#pragma omp atomic write
                fail = 1;
            }
            free(idx);
            free(d2);
        }
        if (fail) st = JF_ERR_NOMEM;
    }
    for (int t = 0; st == JF_OK && t < nt; t++) nrq += trq[t].n;
    if (st == JF_OK && nrq) {
        rq = malloc(nrq * sizeof *rq);
        bs = malloc(nrq * sizeof *bs);
        if (!rq || !bs) st = JF_ERR_NOMEM;
    }
    if (st == JF_OK && nrq) {
        size_t w = 0;
        for (int t = 0; t < nt; t++) {
            if (trq[t].n) /* a thread with none may hold no array */
                memcpy(rq + w, trq[t].r, trq[t].n * sizeof *rq);
            w += trq[t].n;
        }
    }
    for (int t = 0; t < nt; t++) free(trq[t].r);
    free(trq);
    trq = NULL;
    /* 2. the balls too large for the grid: infinite bounds, and the
     * largest finite ones beyond FAR_RATIO x the median (FAR_FINITE at
     * most) */
    double cutb = INFINITY, h = 0;
    if (st == JF_OK && nrq) {
        size_t nfin = 0;
        for (size_t r = 0; r < nrq; r++)
            if (rq[r].req.bound < INFINITY) bs[nfin++] = rq[r].req.bound;
        qsort(bs, nfin, sizeof *bs, cmp_f64);
        if (nfin && cap > 0) { /* a first stage (wide_index): no ball past cap x the median */
            const double cb = bs[nfin / 2] * cap;
            for (size_t r = 0; r < nrq; r++)
                if (!(rq[r].req.bound <= cb)) {
                    rq[r].req.bound = cb;
                    *capped = 1;
                }
            for (size_t r = 0; r < nfin; r++)
                if (bs[r] > cb) bs[r] = cb;
        }
        if (nfin) {
            const double med = bs[nfin / 2];
            cutb = med * FAR_RATIO;
            if (nfin > FAR_FINITE && bs[nfin - 1 - FAR_FINITE] > cutb) cutb = bs[nfin - 1 - FAR_FINITE];
            h = sqrt(med);
        }
        /* far requests move to the end of rq */
        size_t w = 0;
        far = malloc(nrq * sizeof *far);
        if (!far) st = JF_ERR_NOMEM;
        for (size_t r = 0; st == JF_OK && r < nrq; r++) {
            if (rq[r].req.bound > cutb) far[nfar++] = rq[r];
            else rq[w++] = rq[r];
        }
        nrq = w;
    }
    free(bs);
    bs = NULL;
    /* 3. the grid over the near balls' boxes */
    double glo[3] = {INFINITY, INFINITY, INFINITY}, ghi[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t dim[3] = {0, 0, 0};
    if (st == JF_OK && nrq) {
        for (size_t r = 0; r < nrq; r++) {
            const double *p = xyz + 3 * (size_t)rq[r].pt, rr = ball_r(rq[r].req.bound);
            for (int d = 0; d < 3; d++) {
                if (p[d] - rr < glo[d]) glo[d] = p[d] - rr;
                if (p[d] + rr > ghi[d]) ghi[d] = p[d] + rr;
            }
        }
        double ext = 0;
        for (int d = 0; d < 3; d++) ext = ghi[d] - glo[d] > ext ? ghi[d] - glo[d] : ext;
        if (!isfinite(ext)) { /* coordinates near the overflow: all scanned */
            if (nrq) memcpy(far + nfar, rq, nrq * sizeof *rq);
            nfar += nrq;
            nrq = 0;
        }
    }
    if (st == JF_OK && nrq) {
        double ext = 0;
        for (int d = 0; d < 3; d++) ext = ghi[d] - glo[d] > ext ? ghi[d] - glo[d] : ext;
        if (!(h > 0) || !isfinite(h)) h = ext > 0 ? ext / 256 : 1;
        for (;;) {
            double cells = 1;
            for (int d = 0; d < 3; d++) cells *= floor((ghi[d] - glo[d]) / h) + 1;
            if (cells <= (double)jf__parts_grid_bits(n)) break;
            h *= 1.25992104989487316; /* cube root of 2: half the cells */
        }
        for (int d = 0; d < 3; d++) dim[d] = (size_t)floor((ghi[d] - glo[d]) / h) + 1;
        bits = calloc((dim[0] * dim[1] * dim[2] + 63) / 64, sizeof *bits);
        if (!bits) st = JF_ERR_NOMEM;
        for (size_t r = 0; st == JF_OK && r < nrq; r++) {
            const double *p = xyz + 3 * (size_t)rq[r].pt, rr = ball_r(rq[r].req.bound);
            size_t lo[3], hi[3];
            for (int d = 0; d < 3; d++) {
                /* floor((v - glo) / h) is monotone in v: every point of
                 * the ball's box falls in [lo, hi] */
                lo[d] = (size_t)floor((p[d] - rr - glo[d]) / h);
                hi[d] = (size_t)floor((p[d] + rr - glo[d]) / h);
                if (hi[d] >= dim[d]) hi[d] = dim[d] - 1;
                if (lo[d] > hi[d]) lo[d] = hi[d];
            }
            for (size_t z = lo[2]; z <= hi[2]; z++)
                for (size_t y = lo[1]; y <= hi[1]; y++)
                    for (size_t x = lo[0]; x <= hi[0]; x++) {
                        size_t cix = (z * dim[1] + y) * dim[0] + x;
                        bits[cix / 64] |= (uint64_t)1 << (cix % 64);
                    }
        }
    }
    free(rq);
    rq = NULL;
    /* 4. the far balls' k-th distance over the other parts (first scan;
     * not for auto's step 6, whose balls are kept whole: parts.c) */
    for (size_t f = 0; f < nfar; f++) kmax = far[f].req.k > kmax ? far[f].req.k : kmax;
    const int tighten = nfar && !q->nj;
    if (st == JF_OK && tighten) {
        heaps = malloc((size_t)nt * nfar * kmax * sizeof *heaps);
        hn = calloc((size_t)nt * nfar, sizeof *hn);
        if (!heaps || !hn) st = JF_ERR_NOMEM;
    }
    if (st == JF_OK && tighten) {
#pragma omp parallel num_threads(nt)
        {
            const size_t t = (size_t)omp_get_thread_num();
            double *hp = heaps + t * nfar * kmax;
            size_t *hc = hn + t * nfar;
#pragma omp for schedule(dynamic, 4)
            for (size_t ch = 0; ch < rd->nch; ch++) {
                const size_t beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
                const double *xc = jf__chunk_xyz(rd, ch);
                for (size_t i = beg; xc && i < end; i++) {
                    if (part[i] < 0 || part[i] == a) continue;
                    const double *x = xc + 3 * (i - beg);
                    for (size_t f = 0; f < nfar; f++) {
                        const double *p = xyz + 3 * (size_t)far[f].pt;
                        const double dx = x[0] - p[0], dy = x[1] - p[1], dz = x[2] - p[2];
                        const double d = dx * dx + dy * dy + dz * dz;
                        if (d <= far[f].req.bound) heap_push(hp + f * kmax, &hc[f], far[f].req.k, d);
                    }
                }
            }
        }
        /* threshold: the k-th smallest over the threads */
        double *all = malloc((size_t)nt * kmax * sizeof *all);
        if (!all) st = JF_ERR_NOMEM;
        for (size_t f = 0; st == JF_OK && f < nfar; f++) {
            size_t na = 0;
            for (int t = 0; t < nt; t++) {
                memcpy(all + na, heaps + ((size_t)t * nfar + f) * kmax, hn[(size_t)t * nfar + f] * sizeof *all);
                na += hn[(size_t)t * nfar + f];
            }
            qsort(all, na, sizeof *all, cmp_f64);
            if (na >= far[f].req.k) {
                const double th2 = all[far[f].req.k - 1] * (1 + 1e-9) + 1e-280;
                if (th2 < far[f].req.bound) far[f].req.bound = th2;
            }
        }
        free(all);
    }
    for (size_t f = 0; f < nfar; f++) /* room for the roundings */
        far[f].req.bound = far[f].req.bound * (1 + 1e-9) + 1e-280;
    free(heaps);
    free(hn);
    heaps = NULL;
    hn = NULL;
    /* 5. the scan: points of other parts in a marked cell or a far ball
     * (without far balls, only parts whose box meets the grid's) */
    uint8_t *scan = NULL;
    if (st == JF_OK && (nrq || nfar) && !(scan = malloc((size_t)P))) st = JF_ERR_NOMEM;
    for (int b = 0; st == JF_OK && scan && b < P; b++) {
        const double *bb = box + 6 * b;
        int in = b != a && bb[0] <= bb[3];
        for (int d = 0; in && !nfar && d < 3; d++) in = bb[d] <= ghi[d] && bb[3 + d] >= glo[d];
        scan[b] = (uint8_t)in;
    }
    if (st == JF_OK && (nrq || nfar)) {
        int fail = 0;
#pragma omp parallel num_threads(nt)
        {
            hvec *mine = &th[omp_get_thread_num()];
            int ok = 1;
#pragma omp for schedule(dynamic, 4)
            for (size_t ch = 0; ch < rd->nch; ch++) {
              const size_t beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
              size_t i0 = beg;
              while (i0 < end && (part[i0] < 0 || !scan[part[i0]])) i0++;
              const double *xc = ok && i0 < end ? jf__chunk_xyz(rd, ch) : NULL;
              for (size_t i = i0; xc && i < end; i++) {
                if (!ok || part[i] < 0 || !scan[part[i]]) continue;
                const double *x = xc + 3 * (i - beg);
                int keep = 0;
                if (nrq && x[0] >= glo[0] && x[0] <= ghi[0] && x[1] >= glo[1] && x[1] <= ghi[1] &&
                    x[2] >= glo[2] && x[2] <= ghi[2]) {
                    size_t cx = (size_t)floor((x[0] - glo[0]) / h),
                           cy = (size_t)floor((x[1] - glo[1]) / h),
                           cz = (size_t)floor((x[2] - glo[2]) / h);
                    cx = cx < dim[0] ? cx : dim[0] - 1;
                    cy = cy < dim[1] ? cy : dim[1] - 1;
                    cz = cz < dim[2] ? cz : dim[2] - 1;
                    size_t cix = (cz * dim[1] + cy) * dim[0] + cx;
                    keep = (int)((bits[cix / 64] >> (cix % 64)) & 1);
                }
                for (size_t f = 0; !keep && f < nfar; f++) {
                    const double *p = xyz + 3 * (size_t)far[f].pt;
                    const double dx = x[0] - p[0], dy = x[1] - p[1], dz = x[2] - p[2];
                    keep = dx * dx + dy * dy + dz * dz <= far[f].req.bound;
                }
                if (keep) ok = hvec_push(mine, (uint32_t)i, x);
              }
            }
            if (!ok) {
#pragma omp atomic write
                fail = 1;
            }
        }
        if (fail) st = JF_ERR_NOMEM;
    }
    free(bits);
    free(far);
    free(scan);
    /* the threads' lists, each ascending: one array in input order */
    hpoint *hv = NULL;
    size_t nh = 0;
    for (int t = 0; st == JF_OK && t < nt; t++) nh += th[t].n;
    if (st == JF_OK && !(hv = malloc((nh ? nh : 1) * sizeof *hv))) st = JF_ERR_NOMEM;
    if (st == JF_OK) {
        size_t w = 0;
        for (int t = 0; t < nt; t++) {
            if (th[t].n) memcpy(hv + w, th[t].v, th[t].n * sizeof *hv);
            w += th[t].n;
        }
        qsort(hv, nh, sizeof *hv, cmp_hpoint);
    }
    for (int t = 0; t < nt; t++) free(th[t].v);
    free(th);
    if (st != JF_OK) {
        free(hv);
        return st;
    }
    *halo = hv;
    *nhalo = nh;
    return JF_OK;
}

/* A knn halo's balls from the cloud's distances, not the part's: the
 * part's K-th distance is one-sided at its border and unbounded on an
 * island of it (a Morton range is not connected); such balls made up to
 * 94% of a 10^6 cloud one part's halo under auto (r_K + 2 r_nj, parts.c),
 * and 20 times a part's points under knn:256.  So first the halo of balls
 * capped at WIDE_CAP x the median: if none was capped (and no step 6)
 * that is the halo; else the index over own + it, a subset of the cloud
 * over which a point's K-th distance bounds the cloud's (and equals it
 * wherever the capped ball held the K nearest), for the requests again. */
#define WIDE_CAP 16.0 /* squared: 4 x the median radius (a border point's own reach 2 x) */
jf_status jf__wide_index(reader *rd, const int32_t *part, const double *box, int P,
                            const occgrid *occ, int32_t a, const jf_index *own,
                            const double *xyz, size_t m, const jf_part_query *q, int nt,
                            hpoint **halo, size_t *nhalo, jf_index **wide)
{
    jf_part_query qk = *q;
    qk.nj = 0;
    hpoint *h = NULL;
    size_t nh = 0;
    int capped = 0;
    *wide = NULL;
    jf_status st =
        jf__halo_of(rd, part, box, P, occ, a, own, own, WIDE_CAP, &capped, xyz, m, &qk, nt, &h, &nh);
    if (st == JF_OK && !capped && !q->nj) { /* the exact requests' halo already */
        *halo = h;
        *nhalo = nh;
        return JF_OK;
    }
    double *w = st == JF_OK ? malloc(3 * (m + nh) * sizeof *w) : NULL;
    if (st == JF_OK && !w) st = JF_ERR_NOMEM;
    if (st == JF_OK) {
        memcpy(w, xyz, 3 * m * sizeof *w);
        for (size_t i = 0; i < nh; i++) memcpy(w + 3 * (m + i), h[i].x, sizeof(double[3]));
        free(h);
        h = NULL;
        st = jf__index_build_threads(w, m + nh, nt, wide);
    }
    free(h);
    free(w); /* the index holds its own copy */
    return st;
}

/* Step 2 without the own index (knn:K, K < CNT_MAX): part a's halo as
 * every point of another part in a cell near one of a's, on a grid over
 * a's box (widened by GRID_PAD cells; as fine as the plan's second grid
 * allows).  Why it holds the halo: an own point p in cell c that holds
 * K + 1 own points has its own K-th distance t <= the cell's diagonal
 * (sqrt 3 s), else, if the 3 x 3 x 3 cells around c hold K + 1, t <=
 * 2 sqrt 3 s; every point of the whole cloud nearer p than t (the cloud's
 * K-th distance is no larger) lies within R = 2 (or 4) cells of c (cell =
 * floor((v - lo) / s), as a product by 1 / s, is monotone; the margins cover the roundings; 6
 * cells for the 5 x 5 x 5 around c, t <= 3 sqrt 3 s), so
 * the points of other parts in those cells are a superset of p's remote
 * neighbours.  Cost: one scan of the cloud (the own points were gathered
 * by another), no index, no query.  *served = 0 (nothing allocated) when
 * a cell's 27 hold too few own points (sparse regions: the requests
 * decide there), when the cells are too small for the coordinates'
 * roundings, or when the halo would pass cap points (the memory plan's):
 * the caller then takes halo_of. */
#define CNT_MAX 63   /* counts in a byte's low 6 bits; bit 6: done, bit 7: near */
#define GRID_PAD 7   /* cells around a's box: more than R = 6 */
jf_status jf__halo_by_cells(reader *rd, const int32_t *part, const double *boxa, int32_t a,
                               const double *xyz, size_t m, size_t K, size_t cap, size_t maxcells,
                               int nt, hpoint **halo, size_t *nhalo, int *served)
{
    *served = 0;
    if (K + 1 > CNT_MAX || !m) return JF_OK;
    occgrid gg, *g = &gg;
    double ext = 0, big = 0;
    for (int d = 0; d < 3; d++) {
        ext = boxa[3 + d] - boxa[d] > ext ? boxa[3 + d] - boxa[d] : ext;
        big = fabs(boxa[d]) > big ? fabs(boxa[d]) : big;
        big = fabs(boxa[3 + d]) > big ? fabs(boxa[3 + d]) : big;
    }
    /* the padding alone must fit (a small cloud's grid is small) */
    const double pad = 2 * GRID_PAD + 2;
    if (!(ext > 0) || !isfinite(ext) || pad * pad * pad > (double)maxcells) return JF_OK;
    occ_setup(g, boxa, maxcells, GRID_PAD);
    if (!(g->s > 1e-6 * (big + ext))) return JF_OK; /* cells of a few ulps: the margins fail */
    double ghi[3];
    for (int d = 0; d < 3; d++) ghi[d] = g->lo[d] + (double)g->dim[d] * g->s;
    const size_t dx = g->dim[0], dy = g->dim[1], dz = g->dim[2];
    /* the plan's second grid (its bytes: jf__parts_grid_bits / 8), freed
     * before halo_of takes its own */
    uint8_t *cnt = calloc(occ_cells(g), 1);
    if (!cnt) return JF_ERR_NOMEM;
    for (size_t j = 0; j < m; j++) {
        uint8_t *c = cnt + occ_cell(g, xyz + 3 * j);
        if (*c < CNT_MAX) (*c)++;
    }
    for (size_t j = 0; j < m; j++) {
        const size_t c = occ_cell(g, xyz + 3 * j);
        if (cnt[c] & 0x40) continue;
        cnt[c] |= 0x40;
        const size_t cx = c % dx, cy = c / dx % dy, cz = c / dx / dy;
        /* the least block of (2L + 1)^3 cells around c holding K + 1 own
         * points bounds t by sqrt 3 (L + 1) s: R = its ceiling */
        static const size_t RL[3] = {2, 4, 6};
        size_t R = 0;
        for (size_t L = 0; L < 3 && !R; L++) {
            size_t sum = 0;
            for (size_t z = cz > L ? cz - L : 0; z <= cz + L && z < dz; z++)
                for (size_t y = cy > L ? cy - L : 0; y <= cy + L && y < dy; y++)
                    for (size_t x = cx > L ? cx - L : 0; x <= cx + L && x < dx; x++)
                        sum += cnt[(z * dy + y) * dx + x] & 0x3f;
            if (sum >= K + 1) R = RL[L];
        }
        if (!R) {
            free(cnt);
            return JF_OK;
        }
        for (size_t z = cz > R ? cz - R : 0; z <= cz + R && z < dz; z++)
            for (size_t y = cy > R ? cy - R : 0; y <= cy + R && y < dy; y++) {
                uint8_t *row = cnt + (z * dy + y) * dx;
                for (size_t x = cx > R ? cx - R : 0; x <= cx + R && x < dx; x++) row[x] |= 0x80;
            }
    }
    /* the scan: other parts' points in a marked cell, at most cap */
    hvec *th = calloc((size_t)nt, sizeof *th);
    size_t total = 0;
    int fail = !th, over = 0;
    if (th) {
#pragma omp parallel num_threads(nt)
        {
            hvec *mine_v = &th[omp_get_thread_num()];
            int ok = 1;
#pragma omp for schedule(dynamic, 4)
            for (size_t ch = 0; ch < rd->nch; ch++) {
                if (!ok || __atomic_load_n(&over, __ATOMIC_RELAXED)) continue;
                const size_t beg = ch * JF_SRC_CHUNK, end = beg + jf__chunk_len(rd, ch);
                size_t i0 = beg;
                while (i0 < end && (part[i0] < 0 || part[i0] == a)) i0++;
                const double *xc = i0 < end ? jf__chunk_xyz(rd, ch) : NULL;
                const size_t had = mine_v->n;
                for (size_t i = i0; xc && ok && i < end; i++) {
                    if (part[i] < 0 || part[i] == a) continue;
                    const double *x = xc + 3 * (i - beg);
                    if (!(x[0] >= g->lo[0] && x[0] <= ghi[0] && x[1] >= g->lo[1] &&
                          x[1] <= ghi[1] && x[2] >= g->lo[2] && x[2] <= ghi[2]))
                        continue; /* farther than GRID_PAD cells from a's box */
                    if (cnt[occ_cell(g, x)] & 0x80) ok = hvec_push(mine_v, (uint32_t)i, x);
                }
                if (__atomic_add_fetch(&total, mine_v->n - had, __ATOMIC_RELAXED) > cap)
                    __atomic_store_n(&over, 1, __ATOMIC_RELAXED);
            }
            if (!ok) {
#pragma omp atomic write
                fail = 1;
            }
        }
    }
    hpoint *hv = NULL;
    size_t nh = 0;
    if (!fail && !over && !rd->fail) {
        for (int t = 0; t < nt; t++) nh += th[t].n;
        if (!(hv = malloc((nh ? nh : 1) * sizeof *hv))) fail = 1;
    }
    if (hv) {
        size_t w = 0;
        for (int t = 0; t < nt; t++) {
            if (th[t].n) memcpy(hv + w, th[t].v, th[t].n * sizeof *hv);
            w += th[t].n;
        }
        qsort(hv, nh, sizeof *hv, cmp_hpoint);
    }
    for (int t = 0; th && t < nt; t++) free(th[t].v);
    free(th);
    free(cnt);
    if (fail) return JF_ERR_NOMEM;
    if (!hv) return JF_OK; /* over the cap, or a failed read (the caller's) */
    *halo = hv;
    *nhalo = nh;
    *served = 1;
    return JF_OK;
}

