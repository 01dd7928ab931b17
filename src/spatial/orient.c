/* orient.c -- a consistent side for the normals of a cloud of results.
 *
 * Three rules (docs/design.md "Data flow of an estimate"), each flipping whole results with
 * jf_result_flip so that curvature signs, k1/k2, d1/d2 and the Monge
 * coefficients follow the normal:
 *  - input:     agree with the normals read from the file;
 *  - viewpoint: point towards a scanner position;
 *  - mst:       Hoppe et al. (SIGGRAPH 1992, §3.3): propagate along a minimum
 *               spanning tree of the k-NN graph with weights 1 - |ni.nj|, so
 *               the orientation travels first across nearly parallel normals.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "orient_internal.h"

/* A result whose normal can be oriented (and can orient others). */
static int orientable(const jf_result *r)
{
    return !(r->status & (JF_PT_FAILED | JF_PT_NONFINITE)) && isfinite(r->normal[0]) &&
           isfinite(r->normal[1]) && isfinite(r->normal[2]);
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Flip r if n.dir < 0; a zero or non-finite product cannot decide. */
static void orient_along(jf_result *r, const double dir[3])
{
    double d = dot3(r->normal, dir);
    if (d < 0)
        jf_result_flip(r);
    else if (!(d > 0))
        r->status |= JF_PT_ORIENT_UNKNOWN;
}

jf_status jf_orient_input(jf_result *res, size_t n, const double *nrm)
{
    if (n && (!res || !nrm)) return JF_ERR_INVALID;
    for (size_t i = 0; i < n; i++)
        if (orientable(&res[i])) orient_along(&res[i], nrm + 3 * i);
    return JF_OK;
}

jf_status jf_orient_viewpoint(jf_result *res, const double *xyz, size_t n,
                              const double vp[3])
{
    if (n && (!res || !xyz || !vp)) return JF_ERR_INVALID;
    for (size_t i = 0; i < n; i++) {
        if (!orientable(&res[i])) continue;
        const double *p = xyz + 3 * i;
        double dir[3] = {vp[0] - p[0], vp[1] - p[1], vp[2] - p[2]};
        orient_along(&res[i], dir);
    }
    return JF_OK;
}

jf_status jf_orient_scanner(jf_result *res, const double *xyz, size_t n,
                            const uint32_t *scan, const double *scanner, size_t nscans)
{
    if (n && (!res || !xyz || !scan || !scanner)) return JF_ERR_INVALID;
    for (size_t i = 0; i < n; i++)
        if (scan[i] >= nscans) return JF_ERR_INVALID; /* before any flip */
    for (size_t i = 0; i < n; i++) {
        if (!orientable(&res[i])) continue;
        const double *p = xyz + 3 * i, *s = scanner + 3 * (size_t)scan[i];
        double dir[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
        orient_along(&res[i], dir);
    }
    return JF_OK;
}

/* ---- mst: Prim's algorithm with an indexed binary min-heap -------------- */

#define NOT_SEEN UINT32_MAX        /* never reached                  */
#define DONE (UINT32_MAX - 1)      /* popped (oriented) or invalid   */

typedef struct {
    uint32_t *heap;  /* heap of point indices                        */
    uint32_t *pos;   /* pos[i]: slot of i in heap, NOT_SEEN or DONE  */
    double *key;     /* key[i]: lightest edge weight reaching i      */
    uint32_t len;
} mheap;

/* Strict order: key, then index (deterministic ties). */
static int before(const mheap *h, uint32_t a, uint32_t b)
{
    return h->key[a] < h->key[b] || (h->key[a] == h->key[b] && a < b);
}

static void sift_up(mheap *h, uint32_t s)
{
    uint32_t v = h->heap[s];
    while (s > 0) {
        uint32_t up = (s - 1) / 2;
        if (!before(h, v, h->heap[up])) break;
        h->heap[s] = h->heap[up];
        h->pos[h->heap[s]] = s;
        s = up;
    }
    h->heap[s] = v;
    h->pos[v] = s;
}

static void sift_down(mheap *h, uint32_t s)
{
    uint32_t v = h->heap[s];
    for (;;) {
        uint32_t c = 2 * s + 1;
        if (c >= h->len) break;
        if (c + 1 < h->len && before(h, h->heap[c + 1], h->heap[c])) c++;
        if (!before(h, h->heap[c], v)) break;
        h->heap[s] = h->heap[c];
        h->pos[h->heap[s]] = s;
        s = c;
    }
    h->heap[s] = v;
    h->pos[v] = s;
}

static uint32_t heap_pop(mheap *h)
{
    uint32_t top = h->heap[0];
    h->len--;
    if (h->len) {
        h->heap[0] = h->heap[h->len];
        sift_down(h, 0);
    }
    h->pos[top] = DONE;
    return top;
}

/* Seeds are taken by decreasing z (ties: smaller index): heapsort of the
 * indices, in place, no extra memory. */
static int seed_less(const double *xyz, uint32_t a, uint32_t b)
{
    double za = xyz[3 * (size_t)a + 2], zb = xyz[3 * (size_t)b + 2];
    return za > zb || (za == zb && a < b);
}

static void seed_sift(const double *xyz, uint32_t *o, size_t s, size_t len)
{
    for (;;) {
        size_t c = 2 * s + 1;
        if (c >= len) return;
        /* a max-heap under seed_less's reverse puts the last seed on top */
        if (c + 1 < len && seed_less(xyz, o[c], o[c + 1])) c++;
        if (!seed_less(xyz, o[s], o[c])) return;
        uint32_t t = o[s];
        o[s] = o[c];
        o[c] = t;
        s = c;
    }
}

static void seed_sort(const double *xyz, uint32_t *o, size_t len)
{
    for (size_t s = len / 2; s-- > 0;) seed_sift(xyz, o, s, len);
    for (size_t end = len; end > 1; end--) {
        uint32_t t = o[0];
        o[0] = o[end - 1];
        o[end - 1] = t;
        seed_sift(xyz, o, 0, end - 1);
    }
}

/* What prim reads and changes: the normals (3n), the statuses (n) and a
 * flip flag per point (n, toggled with each negation), so that the
 * streaming pipeline can orient from 29 bytes per point instead of whole
 * results (orient_internal.h). */
typedef struct {
    double *nrm;
    unsigned *status;
    unsigned char *flip;
} oview;

static int v_orientable(const oview *o, size_t i)
{
    const double *m = o->nrm + 3 * i;
    return !(o->status[i] & (JF_PT_FAILED | JF_PT_NONFINITE)) && isfinite(m[0]) &&
           isfinite(m[1]) && isfinite(m[2]);
}

static void v_flip(const oview *o, size_t i)
{
    for (int j = 0; j < 3; j++) o->nrm[3 * i + j] = -o->nrm[3 * i + j];
    o->flip[i] ^= 1;
}

/* orient_along on the view. */
static void v_along(const oview *o, size_t i, const double dir[3])
{
    double d = dot3(o->nrm + 3 * i, dir);
    if (d < 0)
        v_flip(o, i);
    else if (!(d > 0))
        o->status[i] |= JF_PT_ORIENT_UNKNOWN;
}

/* Where the graph's edges come from: k-NN queries, or stored lists. */
typedef struct {
    const jf_index *ix;   /* query k+1 nearest (the point itself drops out) */
    const uint32_t *g;    /* or: g[i*k .. i*k+k-1], UINT32_MAX = none      */
    const double *xyz;
    size_t k;
} nbsrc;

static jf_status get_neighbours(const nbsrc *src, uint32_t u, uint32_t *nb, size_t *found)
{
    if (src->ix)
        return jf_index_knn(src->ix, src->xyz + 3 * (size_t)u, src->k + 1, nb, NULL, found);
    const uint32_t *row = src->g + (size_t)u * src->k;
    size_t m = 0;
    for (size_t j = 0; j < src->k; j++)
        if (row[j] != UINT32_MAX) nb[m++] = row[j];
    *found = m;
    return JF_OK;
}

/* design: Prim over the k-NN graph, neighbours queried again (or read
 * from the caller's lists) when a point is popped (memory O(n): no
 * adjacency is stored here).
 *  1. Seeds in order of decreasing z.  A seed is oriented by its lightest
 *     already-oriented k-NN neighbour if it has one (k-NN is not symmetric:
 *     this recovers the edges only the other end lists), else it starts a
 *     component and is oriented +z (the top of a closed surface faces up).
 *  2. Pop the lightest reached point, flip it to agree with its parent,
 *     relax its k nearest neighbours with w = 1 - |ni.nj|.
 *  A seed with no orientable neighbour gets JF_PT_ORIENT_UNKNOWN. */
static jf_status prim(const oview *res, const double *xyz, size_t n, const nbsrc *src)
{
    if (n && (!res->nrm || !xyz || !(src->ix || src->g))) return JF_ERR_INVALID;
    if (src->k < 1 || src->k > 1024) return JF_ERR_INVALID;
    if (n >= DONE) return JF_ERR_TOO_LARGE;
    size_t k = src->k;
    mheap h = {0};
    uint32_t *parent = malloc((n ? n : 1) * sizeof *parent);
    uint32_t *seeds = malloc((n ? n : 1) * sizeof *seeds);
    uint32_t *nb = malloc((k + 1) * sizeof *nb);
    h.heap = malloc((n ? n : 1) * sizeof *h.heap);
    h.pos = malloc((n ? n : 1) * sizeof *h.pos);
    h.key = malloc((n ? n : 1) * sizeof *h.key);
    jf_status st = JF_OK;
    if (!parent || !seeds || !nb || !h.heap || !h.pos || !h.key) {
        st = JF_ERR_NOMEM;
        goto out;
    }
    size_t nseeds = 0;
    for (size_t i = 0; i < n; i++) {
        int ok = v_orientable(res, i);
        h.pos[i] = ok ? NOT_SEEN : DONE;
        if (ok) seeds[nseeds++] = (uint32_t)i;
    }
    seed_sort(xyz, seeds, nseeds);

    for (size_t si = 0; si < nseeds; si++) {
        uint32_t s = seeds[si];
        if (h.pos[s] != NOT_SEEN) continue;
        /* step 1: orient the seed */
        size_t found = 0;
        st = get_neighbours(src, s, nb, &found);
        if (st != JF_OK) goto out;
        uint32_t best = NOT_SEEN;
        double bestw = INFINITY;
        int neighbours = 0;
        for (size_t j = 0; j < found; j++) {
            uint32_t v = nb[j];
            if (v >= n || v == s || !v_orientable(res, v)) continue;
            neighbours = 1;
            double w = 1.0 - fabs(dot3(res->nrm + 3 * (size_t)s, res->nrm + 3 * (size_t)v));
            if (h.pos[v] == DONE && w < bestw) {
                bestw = w;
                best = v;
            }
        }
        if (best != NOT_SEEN) {
            v_along(res, s, res->nrm + 3 * (size_t)best);
        } else if (res->nrm[3 * (size_t)s + 2] < 0) {
            v_flip(res, s); /* a new component: face +z */
        }
        if (!neighbours) res->status[s] |= JF_PT_ORIENT_UNKNOWN;
        h.key[s] = 0;
        h.heap[0] = s;
        h.pos[s] = 0;
        h.len = 1;
        parent[s] = s;
        /* step 2: grow the tree */
        while (h.len) {
            uint32_t u = heap_pop(&h);
            if (parent[u] != u) v_along(res, u, res->nrm + 3 * (size_t)parent[u]);
            st = get_neighbours(src, u, nb, &found);
            if (st != JF_OK) goto out;
            for (size_t j = 0; j < found; j++) {
                uint32_t v = nb[j];
                if (v >= n || h.pos[v] == DONE) continue;
                double w = 1.0 - fabs(dot3(res->nrm + 3 * (size_t)u, res->nrm + 3 * (size_t)v));
                if (h.pos[v] == NOT_SEEN) {
                    h.key[v] = w;
                    parent[v] = u;
                    h.heap[h.len] = v;
                    h.pos[v] = h.len;
                    h.len++;
                    sift_up(&h, h.pos[v]);
                } else if (w < h.key[v]) {
                    h.key[v] = w;
                    parent[v] = u;
                    sift_up(&h, h.pos[v]);
                }
            }
        }
    }
out:
    free(parent);
    free(seeds);
    free(nb);
    free(h.heap);
    free(h.pos);
    free(h.key);
    return st;
}

/* prim on whole results: their normals and statuses copied to a view,
 * the flips and flags applied back (29 bytes per point for the call). */
static jf_status prim_results(jf_result *res, const double *xyz, size_t n, const nbsrc *src)
{
    if (n && !res) return JF_ERR_INVALID;
    oview v = {malloc((n ? n : 1) * 3 * sizeof *v.nrm), malloc((n ? n : 1) * sizeof *v.status),
               calloc(n ? n : 1, 1)};
    jf_status st = JF_ERR_NOMEM;
    if (v.nrm && v.status && v.flip) {
        for (size_t i = 0; i < n; i++) {
            memcpy(v.nrm + 3 * i, res[i].normal, sizeof(double[3]));
            v.status[i] = res[i].status;
        }
        st = prim(&v, xyz, n, src);
        for (size_t i = 0; st == JF_OK && i < n; i++) {
            if (v.flip[i]) jf_result_flip(&res[i]);
            res[i].status = v.status[i];
        }
    }
    free(v.nrm);
    free(v.status);
    free(v.flip);
    return st;
}

jf_status jf__orient_mst_view(double *nrm, unsigned *status, unsigned char *flip,
                              const double *xyz, size_t n, const uint32_t *nbr, size_t k)
{
    oview v = {nrm, status, flip};
    nbsrc src = {NULL, nbr, xyz, k};
    return prim(&v, xyz, n, &src);
}

void jf__orient_point(jf_result *r, const double dir[3])
{
    if (orientable(r)) orient_along(r, dir);
}

jf_status jf_orient_mst(jf_result *res, const double *xyz, size_t n,
                        const jf_index *ix, size_t k)
{
    nbsrc src = {ix, NULL, xyz, k};
    return prim_results(res, xyz, n, &src);
}

jf_status jf_orient_mst_graph(jf_result *res, const double *xyz, size_t n,
                              const uint32_t *nbr, size_t k)
{
    nbsrc src = {NULL, nbr, xyz, k};
    return prim_results(res, xyz, n, &src);
}
