/* parts.c -- partition of a cloud into P parts and the exact halo of each
 * (parts.h says how the distributed run and the bounded-memory estimate
 * use it).
 *
 * design:
 *  - partition: Morton keys of the finite points (the cube over their
 *    bounding box, 21 bits per axis, as order.c), sorted with the input
 *    index as tie (jf_spatial_order), cut into P equal runs.  A run of the
 *    Z curve is spatially compact; its bounding box is the part's region
 *    for the halo test.  Equal points may fall in two parts (duplicates
 *    straddling a cut): the halo handles them as any other point.
 *  - halo (why one round is exact): q's neighbourhood over the whole cloud
 *    is the top k in the (d2, index) order within a bound b.  If q's own
 *    part holds k points within b, the k-th of them, t, bounds the whole
 *    cloud's k-th: every remote neighbour x has d2(x) <= t and is in its
 *    own part's top k within t.  So each point asks (k, min(t, b)) of the
 *    parts whose box is within that bound, once; there is nothing to
 *    iterate.  knn+radius's fallback (fewer than the floor within R: the
 *    floor nearest at any distance) is a second request, sent only when
 *    the own part has fewer than the floor within R (if the whole cloud
 *    has, so does any part answering).
 *  - rounding: box distances use the k-d tree's lower-bound arithmetic
 *    (kdtree.c), so a box is never skipped when a point inside qualifies;
 *    bounds are inclusive (a remote point at exactly the k-th distance and
 *    a smaller index wins the tie, so it must be fetched).
 */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include <omp.h>

#include "index_internal.h"
#include "io_internal.h"
#include "parts.h"
#include "robust/neigh_jets.h"

static int finite3(const double *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

static size_t max_sz(size_t a, size_t b) { return a > b ? a : b; }

jf_status jf__part_query_init(const jf_estimate_opts *o, jf_part_query *q)
{
    if (!o || !q) return JF_ERR_INVALID;
    jf_estimate_opts oa = *o;
    jf__nb_auto_opts(&oa); /* auto is knn:JF_NB_AUTO_KMAX, as in jf_estimate */
    if (oa.params.monge_degree == 0) oa.params.monge_degree = jf_monge_degree_of(oa.params.degree);
    o = &oa;
    if (jf_params_validate(&o->params, NULL) != JF_OK) return JF_ERR_INVALID;
    if (o->nb.kind > JF_NB_KNN_RADIUS) return JF_ERR_UNSUPPORTED;
    const jf_params *p = &o->params;
    /* the same sizes as jf_estimate's (pipeline.c) */
    memset(q, 0, sizeof *q);
    q->nb = o->nb;
    if (q->nb.kind == JF_NB_KNN)
        for (int j = 0; j < p->nscales; j++) q->nb.k = max_sz(q->nb.k, p->scales[j]);
    q->min_count = jf_jet_size(p->degree);
    q->cap = p->max_neighbors;
    if (q->nb.kind == JF_NB_KNN) q->cap = q->nb.k;
    if (q->nb.kind == JF_NB_KNN_RADIUS) q->cap = o->nb.k;
    q->cap = max_sz(q->cap, 1);
    if (q->cap > p->max_neighbors) return JF_ERR_INVALID;
    if (q->nb.kind != JF_NB_KNN && !(q->nb.r >= 0 && isfinite(q->nb.r))) return JF_ERR_INVALID;
    if (q->nb.kind != JF_NB_RADIUS && !q->nb.k) return JF_ERR_INVALID;
    q->nj = jf__nj_on(p, &q->nb) ? jf__nj_reach(p) : 0;
    return JF_OK;
}

/* ---------------------------------------------------------- partition */

jf_status jf__parts_split(const double *xyz, size_t n, int nparts, int32_t *part)
{
    if ((n && (!xyz || !part)) || nparts < 1 || nparts > JF_PARTS_MAX) return JF_ERR_INVALID;
    if (n >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    if (!n) return JF_OK;
    uint32_t *order = malloc(n * sizeof *order);
    if (!order) return JF_ERR_NOMEM;
    /* (key, index) order, non-finite points last: the same keys as
     * jf__morton_key over jf__parts_bbox (order.c) */
    jf_status st = jf_spatial_order(xyz, n, order);
    if (st != JF_OK) {
        free(order);
        return st;
    }
    size_t nf = 0;
    for (size_t i = 0; i < n; i++) nf += finite3(xyz + 3 * i);
    for (size_t j = 0; j < n; j++)
        part[order[j]] = j < nf ? (int32_t)(((uint64_t)j * (uint64_t)nparts) / nf) : -1;
    free(order);
    return JF_OK;
}

/* ---------------------------------------------------------------- halo */

double jf__box_dist2(const double box[6], const double q[3])
{
    if (!(box[0] <= box[3])) return INFINITY; /* empty */
    double g[3];
    for (int d = 0; d < 3; d++) {
        /* as kdtree.c: g <= |q - p| for every p in the box, rounded alike */
        double a = box[d] - q[d], b = q[d] - box[3 + d];
        g[d] = a > 0 ? a : (b > 0 ? b : 0);
    }
    return g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
}

/* The own part's answer to (k, bound): tightened to its k-th distance. */
static double tighten(const jf_index *own, const double p[3], size_t k, double bound,
                      uint32_t *idx, double *d2, size_t *found)
{
    *found = 0;
    if (jf__index_query(own, p, k, bound, idx, d2, NULL, found) != JF_OK) return bound;
    return *found == k && k ? d2[k - 1] : bound;
}

int jf__halo_requests(const jf_index *own, const jf_part_query *q, const double p[3],
                      uint32_t *idx, double *d2, jf_halo_req req[2])
{
    if (!finite3(p)) return 0;
    size_t found = 0;
    switch (q->nb.kind) {
    case JF_NB_KNN: {
        size_t k = q->nb.k < q->cap ? q->nb.k : q->cap;
        req[0].k = k;
        req[0].bound = tighten(own, p, k, INFINITY, idx, d2, &found);
        if (q->nj && found == k && req[0].bound < INFINITY) {
            /* auto's step 6: p's row reads the fits of its nj nearest j,
             * each on its own k nearest x; |p - x| <= r_nj + r_k(j) <=
             * r_k(p) + 2 r_nj (r_k(j) <= r_k(p) + |p - j|), the own part's
             * distances bounding the cloud's: every point a row needs is
             * in that ball (a superset: users keep all of it, not the k) */
            const double r = sqrt(req[0].bound) + 2.0 * sqrt(d2[(q->nj < k ? q->nj : k) - 1]);
            req[0].bound = r * r * (1 + 1e-9) + 1e-280;
        }
        return 1;
    }
    case JF_NB_RADIUS:
        req[0].k = q->cap;
        req[0].bound = tighten(own, p, q->cap, q->nb.r * q->nb.r, idx, d2, &found);
        return 1;
    case JF_NB_KNN_RADIUS: {
        size_t want = q->nb.k < q->cap ? q->nb.k : q->cap;
        size_t floor = q->min_count < want ? q->min_count : want;
        req[0].k = want;
        req[0].bound = tighten(own, p, want, q->nb.r * q->nb.r, idx, d2, &found);
        if (found >= floor) return 1;
        req[1].k = floor;
        req[1].bound = tighten(own, p, floor, INFINITY, idx, d2, &found);
        return 2;
    }
    default: return 0;
    }
}

int jf__halo_requests_near(const jf_index *own, const jf_part_query *q, const double *boxes,
                           int nboxes, int self, const double p[3], double last[4],
                           uint32_t *idx, double *d2, jf_halo_req req[2])
{
    const int knn = q->nb.kind == JF_NB_KNN;
    if (knn && last[3] < INFINITY && finite3(p)) {
        double dd = 0, near2 = INFINITY;
        for (int k = 0; k < 3; k++) dd += (p[k] - last[k]) * (p[k] - last[k]);
        /* own k-th distance <= last's + |p - last| (triangle inequality;
         * step 6's ball, three such distances: 3 |p - last|) */
        const double u = (q->nj ? 3.0 : 1.0) * sqrt(dd) + last[3];
        for (int b = 0; b < nboxes; b++) {
            const double bd = b == self ? INFINITY : jf__box_dist2(boxes + 6 * b, p);
            if (bd < near2) near2 = bd;
        }
        /* strictly beyond, with room for the roundings: no tie either */
        if (u * u * (1 + 1e-9) < near2) return 0;
    }
    const int nr = jf__halo_requests(own, q, p, idx, d2, req);
    if (knn && nr == 1) {
        memcpy(last, p, sizeof(double[3]));
        last[3] = sqrt(req[0].bound);
    }
    return nr;
}

void *jf__grow(void *v, size_t *cap, size_t n, size_t elem)
{
    if (n < *cap) return v;
    size_t nc = *cap ? 2 * *cap : 1024;
    void *nv = realloc(v, nc * elem);
    if (nv) *cap = nc;
    return nv;
}

/* Growable list of input indices (one per thread). */
typedef struct {
    uint32_t *v;
    size_t n, cap;
} ivec;

static int ivec_push(ivec *a, uint32_t x)
{
    void *nv = jf__grow(a->v, &a->cap, a->n, sizeof *a->v);
    if (!nv) return 0;
    a->v = nv;
    a->v[a->n++] = x;
    return 1;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Sorts [start, a->n) and drops repeats. */
static void sort_unique(ivec *a, size_t start)
{
    if (a->n <= start) return; /* an empty tail may have no array at all */
    qsort(a->v + start, a->n - start, sizeof *a->v, cmp_u32);
    size_t w = start;
    for (size_t j = start; j < a->n; j++)
        if (j == start || a->v[j] != a->v[w - 1]) a->v[w++] = a->v[j];
    a->n = w;
}

int jf__halo_cmp(const void *a, const void *b)
{
    const jf_halo_cand *x = a, *y = b;
    if (x->d2 != y->d2) return x->d2 < y->d2 ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

/* One thread's buffers. */
typedef struct {
    ivec cand, need;
    jf_halo_cand *m;  /* one request's candidates, own and remote        */
    size_t mn, mcap;
    uint32_t *idx;
    double *d2;
} hworker;

static int cand_push(hworker *w, double d2, uint32_t id, int remote)
{
    void *nv = jf__grow(w->m, &w->mcap, w->mn, sizeof *w->m);
    if (!nv) return 0;
    w->m = nv;
    w->m[w->mn++] = (jf_halo_cand){d2, id, (uint32_t)remote};
    return 1;
}

jf_status jf__parts_halos(const double *xyz, size_t n, const int32_t *part, int nparts,
                          const jf_part_query *q, int threads, size_t *halo_off,
                          uint32_t **halo, jf_halo_stats *stats)
{
    if (!halo || !halo_off || !q || (n && (!xyz || !part)) || nparts < 1 ||
        nparts > JF_PARTS_MAX)
        return JF_ERR_INVALID;
    *halo = NULL;
    if (stats) memset(stats, 0, sizeof *stats);
    if (n >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    const int nt = threads > 0 ? threads : jf_default_threads(NULL);
    const size_t P = (size_t)nparts, scratch = max_sz(q->cap, q->min_count) + 1;
    jf_status st = JF_OK;
    /* members of each part (CSR, ascending input index), their coordinates,
     * boxes and indexes */
    size_t *moff = calloc(P + 1, sizeof *moff);
    uint32_t *mem = malloc((n ? n : 1) * sizeof *mem);
    double *mxyz = malloc((n ? n : 1) * 3 * sizeof *mxyz);
    double *box = malloc(P * 6 * sizeof *box);
    jf_index **ix = calloc(P, sizeof *ix);
    hworker *tw = calloc((size_t)nt, sizeof *tw);
    ivec all = {0};
    size_t nreq = 0, nfetched = 0;
    if (!moff || !mem || !mxyz || !box || !ix || !tw) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    for (int t = 0; t < nt; t++) {
        tw[t].idx = malloc(scratch * sizeof *tw[t].idx);
        tw[t].d2 = malloc(scratch * sizeof *tw[t].d2);
        if (!tw[t].idx || !tw[t].d2) {
            st = JF_ERR_NOMEM;
            goto out;
        }
    }
    for (size_t i = 0; i < n; i++) {
        if (part[i] >= nparts) {
            st = JF_ERR_INVALID;
            goto out;
        }
        if (part[i] >= 0 && finite3(xyz + 3 * i)) moff[part[i] + 1]++;
    }
    for (size_t a = 0; a < P; a++) moff[a + 1] += moff[a];
    {
        size_t *fill = malloc(P * sizeof *fill);
        if (!fill) {
            st = JF_ERR_NOMEM;
            goto out;
        }
        memcpy(fill, moff, P * sizeof *fill);
        for (size_t i = 0; i < n; i++) {
            if (part[i] < 0 || !finite3(xyz + 3 * i)) continue;
            size_t at = fill[part[i]]++;
            mem[at] = (uint32_t)i;
            memcpy(mxyz + 3 * at, xyz + 3 * i, sizeof(double[3]));
        }
        free(fill);
    }
    for (size_t a = 0; a < P && st == JF_OK; a++) {
        size_t m = moff[a + 1] - moff[a];
        jf__parts_bbox(mxyz + 3 * moff[a], m, box + 6 * a);
        st = jf__index_build_threads(mxyz + 3 * moff[a], m, nt, &ix[a]);
    }
    if (st != JF_OK) goto out;

    halo_off[0] = 0;
    for (size_t a = 0; a < P; a++) {
        const size_t beg = moff[a], m = moff[a + 1] - beg;
        jf_status fail = JF_OK;
#pragma omp parallel num_threads(nt) reduction(+ : nreq)
        {
            hworker *w = &tw[omp_get_thread_num()];
            int ok = 1;
#pragma omp for schedule(dynamic, 256)
            for (size_t j = 0; j < m; j++) {
                if (!ok) continue;
                const double *p = mxyz + 3 * (beg + j);
                jf_halo_req req[2];
                int nr = jf__halo_requests(ix[a], q, p, w->idx, w->d2, req);
                for (int r = 0; r < nr && ok; r++) {
                    /* the request's candidates: own top k, then each
                     * answering part's; the merged top k is the
                     * neighbourhood, its remote points the halo */
                    size_t found = 0;
                    w->mn = 0;
                    ok = jf__index_query(ix[a], p, req[r].k, req[r].bound, w->idx, w->d2, NULL,
                                         &found) == JF_OK;
                    for (size_t t = 0; t < found && ok; t++)
                        ok = cand_push(w, w->d2[t], mem[beg + w->idx[t]], 0);
                    for (size_t b = 0; b < P && ok; b++) {
                        if (b == a || !(jf__box_dist2(box + 6 * b, p) <= req[r].bound)) continue;
                        nreq++;
                        ok = jf__index_query(ix[b], p, req[r].k, req[r].bound, w->idx, w->d2,
                                             NULL, &found) == JF_OK;
                        for (size_t t = 0; t < found && ok; t++) {
                            uint32_t g = mem[moff[b] + w->idx[t]];
                            ok = cand_push(w, w->d2[t], g, 1) && ivec_push(&w->cand, g);
                        }
                    }
                    if (!ok) break;
                    size_t keep = w->mn < req[r].k ? w->mn : req[r].k;
                    if (w->mn > 1) qsort(w->m, w->mn, sizeof *w->m, jf__halo_cmp);
                    for (size_t t = 0; t < keep && ok; t++)
                        if (w->m[t].remote) ok = ivec_push(&w->need, w->m[t].id);
                }
            }
            if (!ok) {
#pragma omp atomic write
                fail = JF_ERR_NOMEM;
            }
        }
        if (fail != JF_OK) {
            st = fail;
            goto out;
        }
        /* gather the threads' lists, sort, drop repeats */
        size_t start = all.n;
        for (int t = 0; t < nt && st == JF_OK; t++) {
            for (size_t j = 0; j < tw[t].need.n; j++)
                if (!ivec_push(&all, tw[t].need.v[j])) st = JF_ERR_NOMEM;
            tw[t].need.n = 0;
            if (t && st == JF_OK) /* candidates: counted, distinct per part */
                for (size_t j = 0; j < tw[t].cand.n; j++)
                    if (!ivec_push(&tw[0].cand, tw[t].cand.v[j])) st = JF_ERR_NOMEM;
            if (t) tw[t].cand.n = 0;
        }
        if (st != JF_OK) goto out;
        sort_unique(&all, start);
        sort_unique(&tw[0].cand, 0);
        nfetched += tw[0].cand.n;
        tw[0].cand.n = 0;
        halo_off[a + 1] = all.n;
    }
    *halo = all.v ? all.v : malloc(1);
    all.v = NULL;
    if (!*halo) st = JF_ERR_NOMEM;
    if (stats) {
        stats->requests = nreq;
        stats->fetched = nfetched;
    }
out:
    if (ix)
        for (size_t a = 0; a < P; a++) jf_index_free(ix[a]);
    if (tw)
        for (int t = 0; t < nt; t++) {
            free(tw[t].cand.v);
            free(tw[t].need.v);
            free(tw[t].m);
            free(tw[t].idx);
            free(tw[t].d2);
        }
    free(tw);
    free(all.v);
    free(ix);
    free(box);
    free(mxyz);
    free(mem);
    free(moff);
    return st;
}

/* ------------------------------------------- partition from a sample */

int jf__keyed_cmp(const void *a, const void *b)
{
    const jf__keyed *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

size_t jf__parts_sample_size(size_t nf)
{
    size_t s = nf / 16 > 256 ? nf / 16 : 256;
    return s < JF_PARTS_SAMPLE ? s : JF_PARTS_SAMPLE;
}

int32_t jf__keyed_rank(const jf__keyed *cut, int ncut, uint64_t key, uint32_t id)
{
    int lo = 0, hi = ncut;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (cut[mid].key < key || (cut[mid].key == key && cut[mid].id <= id)) lo = mid + 1;
        else hi = mid;
    }
    return (int32_t)lo;
}

jf_status jf__parts_split_sampled(const double *xyz, size_t n, int nparts, int threads,
                                  int32_t *part)
{
    if ((n && (!xyz || !part)) || nparts < 1 || nparts > JF_PARTS_MAX) return JF_ERR_INVALID;
    if (n >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    if (!n) return JF_OK;
    double box[6];
    const size_t nf = jf__parts_bbox(xyz, n, box);
    const double scale = jf__morton_scale(box);
    /* every stride-th finite point, in input order: about JF_PARTS_SAMPLE */
    const size_t want = jf__parts_sample_size(nf), stride = nf > want ? nf / want : 1;
    size_t ns = nf ? (nf + stride - 1) / stride : 0, got = 0, seen = 0;
    jf__keyed *s = malloc((ns ? ns : 1) * sizeof *s);
    jf__keyed *cut = malloc((size_t)nparts * sizeof *cut);
    if (!s || !cut) {
        free(s);
        free(cut);
        return JF_ERR_NOMEM;
    }
    for (size_t i = 0; i < n && got < ns; i++) {
        if (!finite3(xyz + 3 * i)) continue;
        if (seen++ % stride == 0)
            s[got++] = (jf__keyed){jf__morton_key(xyz + 3 * i, box, scale), (uint32_t)i};
    }
    qsort(s, got, sizeof *s, jf__keyed_cmp);
    /* cut r (1..P-1) is the sample's r/P quantile: part r starts there */
    int ncut = 0;
    for (int r = 1; r < nparts && got; r++) cut[ncut++] = s[(size_t)r * got / (size_t)nparts];
    free(s);
    const int nt = threads > 0 ? threads : jf_default_threads(NULL);
#pragma omp parallel for num_threads(nt) schedule(static, 65536)
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        part[i] = finite3(p) ? jf__keyed_rank(cut, ncut, jf__morton_key(p, box, scale), (uint32_t)i)
                             : -1;
    }
    free(cut);
    return JF_OK;
}

/* --------------------------------------------------------- memory plan */

size_t jf__parts_grid_bits(size_t n)
{
    size_t b = n < ((size_t)1 << 22) ? 16 * n : (size_t)1 << 26;
    return b < 4096 ? 4096 : b;
}

void jf__plan_nb(const jf_estimate_opts *o, jf_plan_nb *nb)
{
    jf_part_query q;
    memset(nb, 0, sizeof *nb);
    if (jf__part_query_init(o, &q) != JF_OK || q.nb.kind != JF_NB_KNN) return;
    const double r = sqrt((double)q.nb.k) + 2.0 * sqrt((double)q.nj); /* step 6's ball */
    nb->ball = q.nj ? r * r : (double)q.nb.k;
    nb->fit_pt = q.nj ? JF_PLAN_NJ_PT : 0;
    nb->fit_thread = q.nj ? JF_PLAN_NJ_THREAD : 0;
}

double jf__plan_part_points(size_t n, int P, const jf_plan_nb *nb)
{
    const double m = ceil((double)n / P) * JF_PLAN_IMBALANCE;
    /* knn:32's ring when not told (the default) */
    const double ball = nb && nb->ball > 0.0 ? nb->ball : 32.0;
    double h = JF_PLAN_RING * sqrt(ball / m);
    h = h > JF_PLAN_HALO ? h : JF_PLAN_HALO;
    const double pts = m * (1.0 + h);
    return (pts < (double)n ? pts : (double)n) + 64;
}

/* What one of P parts holds at its peak: own + halo points at
 * JF_PLAN_PART_PT (+ fit_pt) each, the halo's lists while it is taken. */
static double part_bytes(size_t n, int P, const jf_plan_nb *nb)
{
    const double pts = jf__plan_part_points(n, P, nb), own = ceil((double)n / P);
    const double halo = pts > own ? pts - own : 0.0;
    return pts * (double)(JF_PLAN_PART_PT + (nb ? nb->fit_pt : 0)) + halo * JF_PLAN_HALO_PT;
}

/* The plan's figures: *whole, *least (the most parts) and, for a budget,
 * the fewest parts that fit (2..pmax) or 0. */
static int plan_figures(size_t n, size_t held, size_t ncols, int nt, const jf_plan_nb *nb, size_t budget,
                        double *whole, double *least)
{
    /* the writer: its file buffer (1 MiB), the sink's rows (a block per
     * thread) and jf_writer_rows' formatting (4096 rows of up to 32
     * bytes a column per thread) */
    const double writer = (double)(1 << 20) + (double)nt * 256.0 * 8.0 * (double)ncols +
                          (double)nt * 4096.0 * 32.0 * (double)ncols;
    const double base = (double)held + (double)jf__spool_bytes(n, ncols) + writer;
    /* auto's walk holds rows per thread (a part's run holds them too,
     * within the parts' per-point figures: measured 20.5 MB at the least
     * plan of a 2 * 10^5 torus, 23.8 MB planned) */
    const double threads = nb ? (double)(nt > 0 ? nt : 1) * (double)nb->fit_thread : 0.0;
    *whole = base + threads + (double)(JF_PLAN_WHOLE_PT + (nb ? nb->fit_pt : 0)) * (double)n;
    const double fixed = base + (double)JF_PLAN_SPLIT_PT * (double)n +
                         2.0 * (double)(jf__parts_grid_bits(n) / 8) +
                         (double)sizeof(uint64_t[2]) * (double)jf__parts_sample_size(n);
    /* parts of JF_PLAN_PART_MIN points at least: each has fixed costs */
    size_t pmax = n / JF_PLAN_PART_MIN;
    pmax = pmax < 2 ? 2 : pmax > JF_PLAN_PARTS_MAX ? JF_PLAN_PARTS_MAX : pmax;
    *least = fixed + part_bytes(n, (int)pmax, nb);
    if ((double)budget < *least) return 0;
    /* the fewest parts that fit: each costs a scan of the cloud */
    int lo = 2, hi = (int)pmax;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (fixed + part_bytes(n, mid, nb) <= (double)budget) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

int jf__parts_plan(size_t n, size_t held, size_t ncols, int nt, const jf_plan_nb *nb,
                   size_t budget, size_t *need_whole, size_t *need_min)
{
    double whole, least;
    const int p = plan_figures(n, held, ncols, nt, nb, budget, &whole, &least);
    if (need_whole) *need_whole = (size_t)ceil(whole);
    if (need_min) *need_min = (size_t)ceil(least < whole ? least : whole);
    if ((double)budget >= whole || n < 2) return 1;
    return p;
}

int jf__parts_plan_ooc(size_t n, size_t held, size_t ncols, int nt, const jf_plan_nb *nb, size_t row,
                       size_t budget, size_t *need_min)
{
    /* the read buffers: raw rows and their coordinates, per thread; never
     * the whole cloud (its tree would hold the coordinates) */
    held += (size_t)(nt > 0 ? nt : 1) * JF_SRC_CHUNK * (24 + row);
    double whole, least;
    const int p = plan_figures(n, held, ncols, nt, nb, budget, &whole, &least);
    if (need_min) *need_min = (size_t)ceil(least);
    return n < 2 ? 0 : p;
}

static int ends_with(const char *s, const char *ext)
{
    size_t n = strlen(s), e = strlen(ext);
    return n >= e && !strcasecmp(s + n - e, ext);
}

int jf__memory_precheck(const char *in, const char *in_fmt, size_t budget, int cond_held,
                        size_t ncols, int threads, int kd, const jf_plan_nb *nb, int keep, const char *out,
                        const char *out_fmt, jf_row_layout *l, jf_memchk *r)
{
    memset(r, 0, sizeof *r);
    const int ply = ends_with(in, ".ply"), las = ends_with(in, ".las");
    const int las_out = out_fmt ? !strcasecmp(out_fmt, "las") || !strcasecmp(out_fmt, "laz")
                                : ends_with(out, ".las") || ends_with(out, ".laz");
    if (!budget || in_fmt || !kd || !(ply || las)) return JF_MEMCHK_OK;
    FILE *f = fopen(in, "rb");
    if (!f) return JF_MEMCHK_OK; /* the reader says why */
    const size_t cap = 1 << 16;
    char *buf = malloc(cap);
    size_t got = buf ? fread(buf, 1, cap, f) : 0;
    long long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    fclose(f);
    jf_error e = {{0}};
    jf_status st = !buf || size < 0 ? JF_ERR_IO
                   : ply ? jf__ply_layout(buf, got, (uint64_t)size, in, l, &e)
                         : jf__las_layout(buf, got, (uint64_t)size, in, l, &e);
    free(buf);
    if (st != JF_OK) return JF_MEMCHK_OK;
    const size_t n = (size_t)l->count, coords = n * 24;
    size_t need_min = 0, need_ooc = 0;
    const size_t held = coords + n * ((l->has_normals ? 24 : 0) + (cond_held ? 8 : 0));
    r->n = n;
    if (ply && !las_out && !l->laz) {
        /* the kept attributes are at most a row a point: if the cloud
         * fits in memory with that, it is read whole; else their size is
         * known once read (then: in memory if it fits, else from the
         * file); --keep none: exact now */
        if (jf__parts_plan(n, held + (keep ? n * l->row : 0), ncols, threads, nb, budget, NULL,
                           NULL))
            return JF_MEMCHK_OK;
        if (keep) return JF_MEMCHK_OOC;
        if (jf__parts_plan(n, held, ncols, threads, nb, budget, NULL, &need_min))
            return JF_MEMCHK_OK;
        if (jf__parts_plan_ooc(n, held - coords, ncols, threads, nb, l->row, budget, &need_ooc))
            return JF_MEMCHK_OOC;
        r->ooc = need_ooc < need_min;
        r->need_min = r->ooc ? need_ooc : need_min;
        r->held = r->ooc ? held - coords : held;
        return JF_MEMCHK_REFUSED;
    }
    if (jf__parts_plan(n, held, ncols, threads, nb, budget, NULL, &need_min)) return JF_MEMCHK_OK;
    r->need_min = need_min, r->held = held;
    return JF_MEMCHK_REFUSED;
}
