/* parts_run.c -- jf_estimate_parts: the cloud cut into parts processed one
 * at a time, each with an exact halo, so that only one part's index is
 * held at once (`jetfit estimate --memory`, issues 12.1, 28).  The same
 * results as jf_estimate_blocks, bit for bit.
 *
 * design (the requests are parts.c's, shared with jetfit-mpi):
 *  1. Parts: the finite points cut along the (Morton key, index) order at
 *     the quantiles of a sample (jf__parts_split_sampled: no sort of the
 *     cloud, 16 bytes per sampled point).
 *  2. For part a, knn with dense cells (halo_by_cells): the own points
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
 *     k-th distance over the other parts (halo_of).  A superset of the
 *     exact halo; no other part is indexed.  A knn's bounds come from
 *     the cloud, not the part (wide_index): a first such pass with every
 *     ball capped at twice the median radius, then the requests again
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
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <omp.h>

#include "fitter_internal.h"
#include "index_internal.h"
#include "jetfit.h"
#include "parts.h"

static void set_err(jf_error *err, const char *msg)
{
    if (err) snprintf(err->msg, sizeof err->msg, "%s", msg);
}

/* The query of the parts from o (jf__part_query_init), the one check both
 * entry points make: JF_ERR_UNSUPPORTED with its message where parts
 * cannot serve (not a k-d tree query; mst, which orients along the whole
 * cloud's graph); JF_ERR_INVALID without one (each caller says it). */
static jf_status parts_query(const jf_estimate_opts *o, jf_part_query *q, jf_error *err)
{
    jf_status st = jf__part_query_init(o, q);
    if (st == JF_ERR_UNSUPPORTED || o->orient == JF_ORIENT_MST) {
        set_err(err, "parts need a k-d tree neighbourhood (knn, radius) and a per-point "
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

/* The coordinates' reader (jf_xyz_src): every scan walks the cloud in
 * chunks of JF_SRC_CHUNK points on the threads, each thread reading its
 * chunk into its own buffers (in memory: a pointer, no copy).  The first
 * failed read is kept; the scans then skip, and the caller returns it. */
typedef struct {
    const jf_xyz_src *s;
    size_t n, nch;         /* points, chunks                            */
    double **xyz;          /* per thread: JF_SRC_CHUNK x 3              */
    unsigned char **raw;   /* per thread: JF_SRC_CHUNK rows             */
    int nt;
    int plain;             /* rows are x y z doubles (no raw buffers)   */
    int fail;              /* a read failed: io_row, io_errno           */
    size_t io_row;
    int io_errno;
} reader;

static size_t chunk_len(const reader *rd, size_t ch)
{
    const size_t first = ch * JF_SRC_CHUNK;
    return rd->n - first < JF_SRC_CHUNK ? rd->n - first : JF_SRC_CHUNK;
}

/* Chunk ch's coordinates (chunk_len points), or NULL after a failure. */
static const double *chunk_xyz(reader *rd, size_t ch)
{
    const size_t first = ch * JF_SRC_CHUNK, m = chunk_len(rd, ch);
    if (rd->s->xyz) return rd->s->xyz + 3 * first;
    if (__atomic_load_n(&rd->fail, __ATOMIC_RELAXED)) return NULL;
    const int t = omp_get_thread_num();
    const jf_row_layout *l = rd->s->l;
    /* rows of three doubles: read straight into the coordinates */
    unsigned char *p = rd->plain ? (unsigned char *)rd->xyz[t] : rd->raw[t];
    size_t left = m * l->row;
    uint64_t at = l->vertex_off + (uint64_t)first * l->row;
    while (left) {
        ssize_t k = pread(rd->s->fd, p, left, (off_t)at);
        if (k < 0 && errno == EINTR) continue;
        if (k <= 0) {
#pragma omp critical(jf_parts_reader)
            if (!rd->fail) {
                rd->fail = 1;
                rd->io_row = first + (size_t)(at - l->vertex_off - (uint64_t)first * l->row) / l->row;
                rd->io_errno = k < 0 ? errno : 0;
            }
            return NULL;
        }
        p += k, left -= (size_t)k, at += (uint64_t)k;
    }
    if (!rd->plain) jf__layout_rows(rd->raw[t], m, l, rd->xyz[t], NULL);
    return rd->xyz[t];
}

static jf_status reader_open(reader *rd, const jf_xyz_src *s, size_t n, int nt)
{
    memset(rd, 0, sizeof *rd);
    rd->s = s, rd->n = n, rd->nt = nt;
    rd->nch = (n + JF_SRC_CHUNK - 1) / JF_SRC_CHUNK;
    if (s->xyz) return JF_OK;
    rd->xyz = calloc((size_t)nt, sizeof *rd->xyz);
    rd->raw = calloc((size_t)nt, sizeof *rd->raw);
    rd->plain = jf__layout_plain_xyz(s->l);
    if (!rd->xyz || !rd->raw) return JF_ERR_NOMEM;
    for (int t = 0; t < nt; t++) {
        rd->xyz[t] = malloc(JF_SRC_CHUNK * 3 * sizeof(double));
        rd->raw[t] = rd->plain ? NULL : malloc(JF_SRC_CHUNK * s->l->row);
        if (!rd->xyz[t] || (!rd->plain && !rd->raw[t])) return JF_ERR_NOMEM;
    }
    return JF_OK;
}

static void reader_close(reader *rd)
{
    for (int t = 0; rd->xyz && t < rd->nt; t++) free(rd->xyz[t]);
    for (int t = 0; rd->raw && t < rd->nt; t++) free(rd->raw[t]);
    free(rd->xyz);
    free(rd->raw);
}

/* JF_ERR_IO with the file, the vertex and the reason after a failed read. */
static jf_status reader_status(const reader *rd, jf_error *err)
{
    if (!rd->fail) return JF_OK;
    if (err)
        snprintf(err->msg, sizeof err->msg, "read failed at vertex %zu: %s", rd->io_row,
                 rd->io_errno ? strerror(rd->io_errno) : "the file shrank while it was read");
    return JF_ERR_IO;
}

/* The points of part a (input order) and their coordinates. */
static size_t gather(reader *rd, const int32_t *part, int32_t a, uint32_t *ids, double *xyz,
                     size_t *cnt)
{
    /* on the threads, in input order: count per chunk, then fill from
     * each chunk's offset (cnt: nch + 1 entries) */
    const size_t nch = rd->nch;
    cnt[0] = 0;
#pragma omp parallel for num_threads(rd->nt) schedule(dynamic, 16)
    for (size_t ch = 0; ch < nch; ch++) {
        size_t k = 0, beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
        for (size_t i = beg; i < end; i++) k += part[i] == a;
        cnt[ch + 1] = k;
    }
    for (size_t ch = 0; ch < nch; ch++) cnt[ch + 1] += cnt[ch];
#pragma omp parallel for num_threads(rd->nt) schedule(dynamic, 1)
    for (size_t ch = 0; ch < nch; ch++) {
        if (cnt[ch + 1] == cnt[ch]) continue; /* none of a's: not read */
        const double *x = chunk_xyz(rd, ch);
        if (!x) continue;
        size_t m = cnt[ch], beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
        for (size_t i = beg; i < end; i++)
            if (part[i] == a) {
                ids[m] = (uint32_t)i;
                memcpy(xyz + 3 * m, x + 3 * (i - beg), sizeof(double[3]));
                m++;
            }
    }
    return cnt[nch];
}

typedef struct {
    uint32_t pt;      /* own point (local index)                        */
    jf_halo_req req;
} request;

/* A growable array of requests or of input indices (one per thread). */
typedef struct {
    request *r;
    size_t n, cap;
} rvec;

static int rvec_push(rvec *v, request x)
{
    if (v->n == v->cap) {
        size_t nc = v->cap ? 2 * v->cap : 1024;
        request *nr = realloc(v->r, nc * sizeof *nr);
        if (!nr) return 0;
        v->r = nr;
        v->cap = nc;
    }
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

/* Who owns each cell of a grid over the cloud's box (built once, in
 * split's part pass): OCC_EMPTY, the one part (+1) whose points it holds,
 * or OCC_MIXED.  A ball over no cell owned by another part (empty, or a's
 * only) holds no foreign point, so its point needs no halo (boxes of
 * Z-curve runs overlap too much to tell).  cell(v) = floor((v - lo) / s),
 * clamped (a product by 1/s), is monotone in v, so a point inside a box
 * is in one of the box's cells.  A byte a cell: the cells are jf__parts_grid_bits / 8, the
 * bytes of the bit grid rebuilt per part by a scan before. */
typedef struct {
    double lo[3], s;
    size_t dim[3];
    uint8_t *own;
    int P;
    double inv;        /* 1 / s: a product per axis, not a division     */
} occgrid;

#define OCC_EMPTY 0
#define OCC_MIXED 255              /* also every cell when P > 254      */
#define OCC_PROBE 4096             /* more cells in a ball: just ask   */
/* (skipping a query: at most 64 cells probed, a query costs less) */

static inline size_t cell1(double v, double lo, double inv, size_t dim)
{
    double t = floor((v - lo) * inv);
    if (!(t > 0)) return 0;
    return t >= (double)dim ? dim - 1 : (size_t)t;
}

/* A grid over box widened by pad cells on every side, of at most
 * maxcells cells: the finest of ext / 4096 times powers of 2^(1/3). */
static void occ_setup(occgrid *g, const double box[6], size_t maxcells, size_t pad)
{
    double ext = 0;
    for (int d = 0; d < 3; d++) ext = box[3 + d] - box[d] > ext ? box[3 + d] - box[d] : ext;
    g->s = ext > 0 && isfinite(ext) ? ext / 4096 : 1;
    for (;;) {
        double cells = 1;
        for (int d = 0; d < 3; d++) cells *= floor((box[3 + d] - box[d]) / g->s) + 1 + 2 * (double)pad;
        if (cells <= (double)maxcells) break;
        g->s *= 1.25992104989487316; /* cube root of 2: half the cells */
    }
    for (int d = 0; d < 3; d++) {
        g->lo[d] = box[d] - (double)pad * g->s;
        g->dim[d] = (size_t)floor((box[3 + d] - box[d]) / g->s) + 1 + 2 * pad;
    }
    g->inv = 1 / g->s;
}

static size_t occ_cells(const occgrid *g) { return g->dim[0] * g->dim[1] * g->dim[2]; }

static inline size_t occ_cell(const occgrid *g, const double *x)
{
    return (cell1(x[2], g->lo[2], g->inv, g->dim[2]) * g->dim[1] +
            cell1(x[1], g->lo[1], g->inv, g->dim[1])) * g->dim[0] +
           cell1(x[0], g->lo[0], g->inv, g->dim[0]);
}

/* Part a (-1: none) holds x: its cell goes empty -> a + 1 -> mixed, on
 * any thread (values only move forward, so a lost race retries once). */
static void occ_set(occgrid *g, const double *x, int32_t a)
{
    uint8_t *c = g->own + occ_cell(g, x);
    const uint8_t mine = g->P <= 254 ? (uint8_t)(a + 1) : OCC_MIXED;
    uint8_t v = __atomic_load_n(c, __ATOMIC_RELAXED);
    if (v == mine || v == OCC_MIXED) return;
    if (v == OCC_EMPTY &&
        __atomic_compare_exchange_n(c, &v, mine, 0, __ATOMIC_RELAXED, __ATOMIC_RELAXED))
        return;
    if (v != mine) __atomic_store_n(c, (uint8_t)OCC_MIXED, __ATOMIC_RELAXED);
}

/* 1 when no cell meeting the box p +- r holds a point of a part other
 * than a. */
static int occ_free(const occgrid *g, const double p[3], double r, double probe, int32_t a)
{
    size_t lo[3], hi[3];
    double cells = 1;
    for (int d = 0; d < 3; d++) {
        lo[d] = cell1(p[d] - r, g->lo[d], g->inv, g->dim[d]);
        hi[d] = cell1(p[d] + r, g->lo[d], g->inv, g->dim[d]);
        cells *= (double)(hi[d] - lo[d] + 1);
    }
    if (!(r < INFINITY) || cells > probe) return 0;
    const uint8_t mine = g->P <= 254 ? (uint8_t)(a + 1) : OCC_EMPTY;
    for (size_t z = lo[2]; z <= hi[2]; z++)
        for (size_t y = lo[1]; y <= hi[1]; y++) {
            const uint8_t *row = g->own + (z * g->dim[1] + y) * g->dim[0];
            for (size_t x = lo[0]; x <= hi[0]; x++)
                if (row[x] != OCC_EMPTY && row[x] != mine) return 0;
        }
    return 1;
}

/* A halo point: input index and coordinates, as the scan read them. */
typedef struct {
    uint32_t id;
    double x[3];
} hpoint;

typedef struct {
    hpoint *v;
    size_t n, cap;
} hvec;

static int hvec_push(hvec *a, uint32_t id, const double *x)
{
    if (a->n == a->cap) {
        size_t nc = a->cap ? 2 * a->cap : 1024;
        hpoint *nv = realloc(a->v, nc * sizeof *nv);
        if (!nv) return 0;
        a->v = nv;
        a->cap = nc;
    }
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
static jf_status halo_of(reader *rd, const int32_t *part, const double *box, int P,
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
                const size_t beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
                const double *xc = chunk_xyz(rd, ch);
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
              const size_t beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
              size_t i0 = beg;
              while (i0 < end && (part[i0] < 0 || !scan[part[i0]])) i0++;
              const double *xc = ok && i0 < end ? chunk_xyz(rd, ch) : NULL;
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
static jf_status wide_index(reader *rd, const int32_t *part, const double *box, int P,
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
        halo_of(rd, part, box, P, occ, a, own, own, WIDE_CAP, &capped, xyz, m, &qk, nt, &h, &nh);
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
static jf_status halo_by_cells(reader *rd, const int32_t *part, const double *boxa, int32_t a,
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
                const size_t beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
                size_t i0 = beg;
                while (i0 < end && (part[i0] < 0 || part[i0] == a)) i0++;
                const double *xc = i0 < end ? chunk_xyz(rd, ch) : NULL;
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
        set_err(err, "jf_estimate_parts: NULL argument or nparts out of 1..65536");
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
            const double *x = chunk_xyz(rd, ch);
            const size_t m = chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
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
            const double *x = chunk_xyz(rd, ch);
            const size_t m = chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
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
            const double *x = chunk_xyz(rd, ch);
            const size_t m = chunk_len(rd, ch), beg = ch * JF_SRC_CHUNK;
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
        const size_t beg = ch * JF_SRC_CHUNK, end = beg + chunk_len(rd, ch);
        size_t i = beg;
        while (i < end && part[i] >= 0) i++;
        if (i == end) continue;
        const double *x = chunk_xyz(rd, ch);
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
        set_err(err, "jf__estimate_parts_src: NULL argument or nparts out of 2..65536");
        return JF_ERR_INVALID;
    }
    jf_part_query q;
    jf_status st = parts_query(o, &q, err);
    if (st == JF_ERR_UNSUPPORTED) return st;
    if (st != JF_OK) {
        set_err(err, "invalid parameters");
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
    size_t *ccnt = NULL;
    occgrid occ = {{0, 0, 0}, 1, {1, 1, 1}, NULL, 0, 1};
    reader rd;
    double gb[6];
    if ((st = reader_open(&rd, src, n, nt)) != JF_OK) goto out;
    if (!part || !count || !box || !(ccnt = malloc((rd.nch + 1) * sizeof *ccnt))) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    if ((st = split(&rd, P, part, box, count, gb, &nf, &occ)) != JF_OK) goto out;
    if ((st = reader_status(&rd, err)) != JF_OK) goto out;
    if (nf < n && (st = nonfinite_rows(&rd, part, sink, user)) != JF_OK) {
        if (rd.fail) st = reader_status(&rd, err);
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
    for (int a = 0; a < P && st == JF_OK; a++) {
        if (!count[a]) continue;
        if (o->cancel && o->cancel(o->cancel_user)) {
            st = JF_ERR_CANCELLED;
            set_err(err, "cancelled");
            goto out;
        }
        /* step 2: own index, requests, halo */
        size_t m = gather(&rd, part, a, ids, sxyz, ccnt), nh = 0;
        if ((st = reader_status(&rd, err)) != JF_OK) goto out;
        int served = 0;
        /* auto's step 6 needs a wider halo than the cells' rings: requests */
        if (q.nb.kind == JF_NB_KNN && !q.nj &&
            (st = halo_by_cells(&rd, part, box + 6 * a, a, sxyz, m, q.nb.k, hcap > m ? hcap - m : 0,
                                jf__parts_grid_bits(n) / 8, nt, &halo, &nh, &served)) != JF_OK)
            break;
        if (!served && !rd.fail) { /* the exact requests (any kind, any cloud) */
            jf_index *own = NULL, *wide = NULL;
            if ((st = jf__index_build_threads(sxyz, m, nt, &own)) != JF_OK) break;
            if (q.nb.kind == JF_NB_KNN) /* the balls from the cloud's distances */
                st = wide_index(&rd, part, box, P, &occ, a, own, sxyz, m, &q, nt, &halo, &nh,
                                &wide);
            if (st == JF_OK && !halo)
                st = rd.fail ? JF_ERR_IO
                             : halo_of(&rd, part, box, P, &occ, a, own, wide ? wide : own, 0.0,
                                       NULL, sxyz, m, &q, nt, &halo, &nh);
            jf_index_free(wide);
            jf_index_free(own);
        }
        if (rd.fail) st = reader_status(&rd, err);
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
        relay rl = {sid, sink, user};
        st = jf__estimate_blocks_masked_xyz(&sc, &po, mask, relay_block, &rl, err);
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
    reader_close(&rd);
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
    free(occ.own);
    return st;
}
