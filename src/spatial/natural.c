/*
 * natural.c -- natural neighbourhoods of a point cloud (§5.1): tangent-plane
 * normals from Voronoi poles or minimum-circumradius triangles, then the
 * natural neighbours of p in the power diagram of the samples restricted to
 * p's tangent plane (Boissonnat & Flototto, ref. 3), grown ring by ring.
 *
 * design:
 *  - The CGAL bridge builds the 3D Delaunay triangulation once and hands
 *    back plain arrays (cgal_bridge.h): vertex map, CSR adjacency, poles.
 *    Everything per point happens here, in C, without allocation.
 *  - Why the planar cells are exact: project the samples on the plane H
 *    through p with weight w_q = -h_q^2 (h_q the distance of q to H).  For
 *    x in H the power distance |x - q'|^2 - w_q = |x - q'|^2 + h_q^2 is the
 *    3D squared distance |x - q|^2, so the planar power cell of q is
 *    H ∩ Vor3(q), and Vor3(q) is the intersection of the half-spaces of
 *    q's 3D Delaunay neighbours only.  Clipping a polygon of H by those
 *    half-planes therefore gives q's planar cell exactly (up to rounding),
 *    and the labels of its edges are q's planar natural neighbours.
 *    Planar ring r+1 = the planar neighbours of ring r, each found from
 *    its own 3D adjacency: no candidate set can be too small.
 *  - Unbounded planar cells (at the rim of an open scan) are clipped by a
 *    box twice the reach of the vertex's 3D neighbours.  The far ends of
 *    neighbouring rim cells touch each other: with a box 1e3 times the
 *    reach the rings ran along the rim, and natural:128's normals on the
 *    clean §6.1 patch were 9.75 deg off at the rim (0.10 with 2x; knn:128
 *    0.02; docs/natural.md).
 *  - The same cells without a triangulation (the k-NN form, the default
 *    of jf_estimate): natural_knn.c; the cells of both forms and their
 *    clip: natural_cell.c; the rings below serve both.  With
 *    the k-NN form's own-plane rows (jf_estimate), ring r+1 is the union
 *    of ring r's rows: each vertex's cell in its own plane, made once,
 *    instead of again in every p's plane that reaches it.
 */
#include <math.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "natural_internal.h"

#define HULL_AGREE 0.7     /* cos 45 deg: hull direction vs -pole       */

int jf__natural_threads(int threads) {
#ifdef _OPENMP
    return threads > 0 ? threads : omp_get_num_procs();
#else
    (void)threads;
    return 1;
#endif
}

static jf_status from_bridge(int rc) {
    switch (rc) {
    case 0: return JF_OK;
    case 1: return JF_ERR_INVALID;
    case 2: return JF_ERR_NOMEM;
    case 5: return JF_ERR_TOO_LARGE;
    case 7: return JF_ERR_UNSUPPORTED; /* built without CGAL */
    default: return JF_ERR_INTERNAL;
    }
}

jf_status jf_natural_create(const double *xyz, size_t n, jf_natural **out) {
    return jf_natural_create_threads(xyz, n, 0, out);
}

jf_status jf_natural_create_threads(const double *xyz, size_t n, int threads, jf_natural **out) {
    if (!out || (!xyz && n > 0)) return JF_ERR_INVALID;
    *out = NULL;
    int nthr = jf__natural_threads(threads);
    jf_natural *nt = calloc(1, sizeof *nt);
    if (!nt) return JF_ERR_NOMEM;
    jf_status st = from_bridge(jfb_delaunay_build(xyz, n, nthr, &nt->d));
    if (st != JF_OK) {
        free(nt);
        return st;
    }
    size_t nv = nt->d.nv, max_deg = 0;
    nt->vxyz = malloc((3 * nv + 1) * sizeof(double));
    nt->nn = malloc((nv + 1) * sizeof(double));
    if (!nt->vxyz || !nt->nn) {
        jf_natural_free(nt);
        return JF_ERR_NOMEM;
    }
    long nvl = (long)nv;
#ifdef _OPENMP
#pragma omp parallel for schedule(static) num_threads(nthr)
#endif
    for (long v = 0; v < nvl; v++) {
        const double *p = xyz + 3 * (size_t)nt->d.rep[v];
        memcpy(nt->vxyz + 3 * v, p, 3 * sizeof(double));
    }
    /* the nearest neighbour is always a Delaunay neighbour */
#ifdef _OPENMP
#pragma omp parallel for schedule(static) num_threads(nthr) reduction(max : max_deg)
#endif
    for (long v = 0; v < nvl; v++) {
        const double *p = nt->vxyz + 3 * v;
        double best = INFINITY;
        size_t b = nt->d.adj_off[v], e = nt->d.adj_off[v + 1];
        if (e - b > max_deg) max_deg = e - b;
        for (size_t k = b; k < e; k++) {
            const double *q = nt->vxyz + 3 * (size_t)nt->d.adj[k];
            double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
            double d2 = dx * dx + dy * dy + dz * dz;
            if (d2 < best) best = d2;
        }
        nt->nn[v] = sqrt(best);
    }
    nt->max_deg = max_deg;
    *out = nt;
    return JF_OK;
}

void jf_natural_free(jf_natural *nt) {
    if (!nt) return;
    jfb_delaunay_release(&nt->d);
    if (!nt->ix) free(nt->vxyz);
    free(nt->nn);
    jf_index_free(nt->ix_own);
    free(nt->row);
    free(nt);
}

void jf_natural_get_stats(const jf_natural *nt, jf_natural_stats *st) {
    if (!st) return;
    memset(st, 0, sizeof *st);
    st->dimension = -1;
    if (!nt) return;
    st->dimension = nt->d.dimension;
    st->nvertices = nt->d.nv;
    st->nduplicates = nt->d.nduplicates;
    st->nnonfinite = nt->d.nnonfinite;
    memcpy(st->seconds, nt->d.seconds, sizeof st->seconds);
    memcpy(st->cpu_seconds, nt->d.cpu_seconds, sizeof st->cpu_seconds);
}

size_t jf_natural_kept(const jf_natural *nt, size_t i) {
    if (!nt || i >= nt->d.n || nt->d.vertex_of[i] == NONE) return SIZE_MAX;
    return nt->d.rep[nt->d.vertex_of[i]];
}

/* ---- normals ------------------------------------------------------- */

/* §5.1: q = nearest neighbour of p, r = the sample minimising the
 * circumradius of pqr, normal of pqr.  The minimiser is a Delaunay
 * neighbour of p: pq is a Gabriel edge (q nearest), so the smallest sphere
 * through p, q, r is empty (a point inside it on the far side of pq would
 * give a smaller circle), i.e. pqr is a Delaunay face.  Returns 0 when
 * every candidate is collinear with p and q. */
static int mincirc_normal(const jf_natural *nt, size_t v, double n[3]) {
    const double *p = nt->vxyz + 3 * v;
    size_t b = nt->d.adj_off[v], e = nt->d.adj_off[v + 1];
    double a[3] = {0, 0, 0}, best = INFINITY;
    for (size_t k = b; k < e; k++) {
        const double *q = nt->vxyz + 3 * (size_t)nt->d.adj[k];
        double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        if (d2 < best) {
            best = d2;
            memcpy(a, d, sizeof a);
        }
    }
    if (!(best < INFINITY)) return 0;
    double la = best, bestr = INFINITY;
    for (size_t k = b; k < e; k++) {
        const double *r = nt->vxyz + 3 * (size_t)nt->d.adj[k];
        double c[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        double x[3] = {a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2],
                       a[0] * c[1] - a[1] * c[0]};
        double lx = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        /* collinear (or q itself): no triangle.  The relative bound keeps
         * nearly collinear triples, whose circle is huge, from winning by
         * rounding. */
        double lc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        if (!(lx > 1e-24 * la * lc)) continue;
        double ac[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        /* R^2 = |a|^2 |c|^2 |c - a|^2 / (4 |a x c|^2) */
        double r2 = la * lc * (ac[0] * ac[0] + ac[1] * ac[1] + ac[2] * ac[2]) / (4 * lx);
        if (r2 < bestr) {
            bestr = r2;
            double l = sqrt(lx);
            n[0] = x[0] / l;
            n[1] = x[1] / l;
            n[2] = x[2] / l;
        }
    }
    return bestr < INFINITY;
}

/* Amenta & Bern pole normal of vertex v and its reliability (pole
 * distance / nearest-neighbour distance; 0 when there is no usable pole).
 * A hull sample's pole must lie opposite its hull direction, and the two
 * must roughly agree, else the cell is open in an unknown direction (rim
 * of an open scan). */
static double pole_normal(const jf_natural *nt, size_t v, double n[3]) {
    const double *pl = nt->d.pole + 3 * v, *h = nt->d.hull + 3 * v;
    double lp = sqrt(pl[0] * pl[0] + pl[1] * pl[1] + pl[2] * pl[2]);
    if (!(lp > 0) || !isfinite(lp)) return 0.0;
    for (int k = 0; k < 3; k++) n[k] = pl[k] / lp;
    double lh = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    if (lh > 0 && -(n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) < HULL_AGREE * lh) return 0.0;
    double nn = nt->nn[v];
    return nn > 0 ? lp / nn : 0.0;
}

jf_status jf_natural_normals(const jf_natural *nt, jf_normal_source src, int threads,
                             double *nrm, unsigned *flags, double *reliability) {
    if (!nt || !nrm || !flags || nt->ix) return JF_ERR_INVALID; /* k-NN form: no poles */
    if (src != JF_NORMAL_POLES && src != JF_NORMAL_MINCIRC) return JF_ERR_INVALID;
    long n = (long)nt->d.n;
    int nthr = jf__natural_threads(threads);
#pragma omp parallel for schedule(static) num_threads(nthr)
    for (long i = 0; i < n; i++) {
        uint32_t v = nt->d.vertex_of[i];
        double *o = nrm + 3 * i;
        if (v == NONE) {
            o[0] = o[1] = o[2] = NAN;
            flags[i] |= JF_PT_FAILED | JF_PT_NONFINITE;
            if (reliability) reliability[i] = 0.0;
            continue;
        }
        double pn[3], rel = pole_normal(nt, v, pn);
        if (reliability) reliability[i] = rel;
        if (src == JF_NORMAL_POLES && rel >= JF_NATURAL_MIN_RELIABILITY) {
            memcpy(o, pn, sizeof pn);
            flags[i] |= JF_PT_NORMAL_POLES;
        } else if (mincirc_normal(nt, v, o)) {
            flags[i] |= JF_PT_NORMAL_MINCIRC |
                        (src == JF_NORMAL_POLES ? JF_PT_NORMAL_FALLBACK : 0u);
        } else {
            o[0] = o[1] = o[2] = NAN;
            flags[i] |= JF_PT_FAILED;
        }
    }
    return JF_OK;
}

/* ---- neighbourhoods ---------------------------------------------- */

jf_status jf_natural_ws_create(const jf_natural *nt, jf_natural_ws **out) {
    if (!nt || !out) return JF_ERR_INVALID;
    *out = NULL;
    jf_natural_ws *ws = calloc(1, sizeof *ws);
    if (!ws) return JF_ERR_NOMEM;
    size_t m = nt->max_deg + 8;
    ws->nt = nt;
    ws->stamp = calloc(nt->d.nv + 1, sizeof *ws->stamp);
    ws->listcap = 256;
    ws->list = malloc(ws->listcap * sizeof *ws->list);
    ws->dist = malloc(ws->listcap * sizeof *ws->dist);
    double **bufs[] = {&ws->px, &ws->py, &ws->qx, &ws->qy, &ws->sx, &ws->sy, &ws->sr};
    int ok = ws->stamp && ws->list && ws->dist;
    for (size_t k = 0; k < sizeof bufs / sizeof *bufs; k++) ok &= (*bufs[k] = malloc(m * sizeof(double))) != NULL;
    ok &= (ws->pl = malloc(m * sizeof(uint32_t))) != NULL;
    ok &= (ws->ql = malloc(m * sizeof(uint32_t))) != NULL;
    ok &= (ws->cpos = malloc(m * sizeof(uint32_t))) != NULL;
    ok &= (ws->cd2 = malloc(m * sizeof(double))) != NULL;
    if (!ok) {
        jf_natural_ws_free(ws);
        return JF_ERR_NOMEM;
    }
    *out = ws;
    return JF_OK;
}

void jf_natural_ws_free(jf_natural_ws *ws) {
    if (!ws) return;
    free(ws->stamp);
    free(ws->list);
    free(ws->dist);
    free(ws->px), free(ws->py), free(ws->qx), free(ws->qy);
    free(ws->sx), free(ws->sy), free(ws->sr);
    free(ws->pl), free(ws->ql);
    free(ws->cpos), free(ws->cd2);
    free(ws);
}

void jf__natural_collect(jf_natural_ws *ws, uint32_t v) {
    if (++ws->gen == 0) { /* wrapped: clear the stamps once */
        memset(ws->stamp, 0, ws->nt->d.nv * sizeof *ws->stamp);
        ws->gen = 1;
    }
    ws->stamp[v] = ws->gen;
}

int jf__natural_reserve(jf_natural_ws *ws, size_t len, size_t more) {
    while (len + more > ws->listcap) {
        size_t c = 2 * ws->listcap;
        uint32_t *l = realloc(ws->list, c * sizeof *l);
        if (!l) return 0;
        ws->list = l;
        double *d = realloc(ws->dist, c * sizeof *d);
        if (!d) return 0;
        ws->dist = d;
        ws->listcap = c;
    }
    return 1;
}

/* Lexicographic (x, y, z) order of two distinct vertices: the tie-break
 * of equal distances (grids), a function of the points alone, so the
 * cut ring does not depend on vertex ids (the spatial sort's order). */
static int lex_greater(const jf_natural *nt, uint32_t a, uint32_t b) {
    const double *p = nt->vxyz + 3 * (size_t)a, *q = nt->vxyz + 3 * (size_t)b;
    if (p[0] != q[0]) return p[0] > q[0];
    if (p[1] != q[1]) return p[1] > q[1];
    return p[2] > q[2];
}

/* Puts the `keep` first of list[a..b) by (distance, coordinates) in
 * order at its front (keep >= b - a: all of it): insertion on the
 * distance alone (rings are short), an entry past a full front costing
 * one comparison; then the rare runs of equal distances (grids) by
 * coordinates.  The rest, beyond the front, in no order (the last ring
 * is cut there). */
static void sort_ring(jf_natural_ws *ws, size_t a, size_t b, size_t keep) {
    uint32_t *restrict list = ws->list;
    double *restrict dist = ws->dist;
    const size_t m = keep < b - a ? keep : b - a;
    int ties = 0;
    for (size_t k = a + 1; k < b; k++) {
        const uint32_t v = list[k];
        const double d = dist[k];
        size_t j = k;
        if (k - a >= m) { /* the front is full: v enters only before its last */
            const size_t last = a + m - 1;
            if (m == 0 || d > dist[last] ||
                (d == dist[last] && !lex_greater(ws->nt, list[last], v)))
                continue;
            list[k] = list[last], dist[k] = dist[last];
            j = last;
        }
        for (; j > a && dist[j - 1] > d; j--) list[j] = list[j - 1], dist[j] = dist[j - 1];
        list[j] = v, dist[j] = d;
        ties |= j > a && dist[j - 1] == d;
    }
    for (size_t k = a + 1; ties && k < a + m; k++) {
        const uint32_t v = list[k];
        size_t j = k;
        for (; j > a && dist[j - 1] == dist[k] && lex_greater(ws->nt, list[j - 1], v); j--)
            list[j] = list[j - 1];
        list[j] = v;
    }
}

/* p's tangent plane, made when first needed (own rows need it only for
 * a LIVE row). */
typedef struct {
    const double *o, *nrm;
    plane h;
    int made;
} lazy_plane;

static const plane *plane_of(lazy_plane *lp) {
    if (!lp->made) lp->made = jf__natural_plane(lp->o, lp->nrm, &lp->h) ? 1 : -1;
    return lp->made > 0 ? &lp->h : NULL;
}

/* Appends ring vertex u's neighbours: its cell in p's plane; own (a LIVE
 * row): in u's own plane when it has one. */
static int ring_step(jf_natural_ws *ws, lazy_plane *lp, uint32_t u, int own, size_t *len) {
    const jf_natural *nt = ws->nt;
    plane hu;
    if (own && jf__natural_plane(nt->vxyz + 3 * (size_t)u, nt->row_nrm + 3 * (size_t)nt->d.rep[u], &hu))
        return jf__natural_knn_cell(ws, &hu, u, NULL, 0, NULL, lp->o, len);
    const plane *h = plane_of(lp);
    if (!h) return 1; /* checked by grow: not reached */
    return nt->ix ? jf__natural_knn_cell(ws, h, u, NULL, 0, NULL, h->o, len)
                  : jf__natural_tri_cell(ws, h, u, len);
}

/* The next ring from the own-plane rows of ring list[a..b) (a LIVE row:
 * ring_step's).  Locals: the stores to list and dist would otherwise
 * reload every pointer. */
static int own_ring(jf_natural_ws *ws, lazy_plane *lp, size_t a, size_t b, size_t *len) {
    const jf_natural *nt = ws->nt;
    if (!jf__natural_reserve(ws, *len, (b - a) * ROW_W)) return 0;
    const double *V = nt->vxyz, *p = lp->o;
    const uint32_t gen = ws->gen, v0 = ws->list[0]; /* p: always collected */
    uint32_t *restrict stamp = ws->stamp, *restrict list = ws->list;
    double *restrict dist = ws->dist;
    const size_t n0 = *len;
    size_t n = n0;
    for (size_t k = a; k < b; k++) {
        const uint32_t *row = nt->row + (size_t)list[k] * ROW_W;
        if (row[0] == ROW_LIVE) { /* rare: may grow the list */
            *len = n;
            if (!ring_step(ws, lp, list[k], 1, len) || !jf__natural_reserve(ws, *len, (b - k) * ROW_W)) return 0;
            n = *len, list = ws->list, dist = ws->dist;
            continue;
        }
        /* every slot, no branch: whether a label is new, or the row has
         * ended (NONE: p itself, collected), is a coin toss for the
         * branch predictor; an old one is written and not counted */
        for (size_t j = 0; j < ROW_W; j++) {
            const uint32_t s = row[j] == NONE ? v0 : row[j];
            const size_t fresh = stamp[s] != gen;
            stamp[s] = gen;
            list[n] = s;
            n += fresh;
        }
    }
    /* the distances of the new ones only (a LIVE row's: the same again) */
    for (size_t k = n0; k < n; k++) dist[k] = dist2(V + 3 * (size_t)list[k], p);
    *len = n;
    return 1;
}

/* Grows rings from input point i until `want` vertices (with i) or
 * `maxrings` rings are collected.  ring_end[r] = end of ring r.  own:
 * from the own-plane rows (jf__natural_neighbors_own). */
static jf_status grow(const jf_natural *nt, jf_natural_ws *ws, size_t i, const double nrm[3],
                      size_t want, int maxrings, int own, size_t *len, size_t *ring_end) {
    *len = 0;
    if (!nt || !ws || ws->nt != nt || !nrm || i >= nt->d.n) return JF_ERR_INVALID;
    uint32_t v0 = nt->d.vertex_of[i];
    if (v0 == NONE) return JF_OK;
    /* the plane itself: when needed; own: nrm is the caller's to check
     * (not read unless i's row is LIVE) */
    if (!own && !plane_len2(nrm)) return JF_ERR_INVALID;
    lazy_plane lp = {.o = nt->vxyz + 3 * (size_t)v0, .nrm = nrm};
    jf__natural_collect(ws, v0);
    jf__natural_push(ws, len, v0, 0.0);
    size_t a = 0, b = 1;
    if (ring_end) ring_end[0] = 1;
    for (int r = 1; r <= maxrings && *len < want; r++) {
        if (own) {
            if (!own_ring(ws, &lp, a, b, len)) return JF_ERR_NOMEM;
        } else {
            for (size_t k = a; k < b; k++)
                if (!ring_step(ws, &lp, ws->list[k], 0, len)) return JF_ERR_NOMEM;
        }
        if (*len == b) break; /* the cloud ran out */
        /* want > b: the loop goes on.  own: a ring kept whole stays in
         * row order (a fit does not care; the cut one is sorted) */
        if (!own || *len > want) sort_ring(ws, b, *len, want - b);
        a = b, b = *len;
        if (ring_end) ring_end[r] = b;
    }
    return JF_OK;
}

static jf_status neighbors(const jf_natural *nt, jf_natural_ws *ws, size_t i, const double nrm[3],
                           size_t N, int own, uint32_t *idx, size_t cap, size_t *found) {
    if (!found) return JF_ERR_INVALID;
    *found = 0;
    size_t len, want = N < cap ? N : cap;
    jf_status st = grow(nt, ws, i, nrm, want, INT32_MAX, own, &len, NULL);
    if (st != JF_OK || len == 0) return st;
    if (len > want) len = want;
    *found = len;
    if (!idx) return JF_OK; /* the caller reads ws->list only */
    idx[0] = (uint32_t)i;
    for (size_t k = 1; k < len; k++) idx[k] = nt->d.rep[ws->list[k]];
    *found = len;
    return JF_OK;
}

void jf__natural_prefetch(const jf_natural *nt, size_t i) {
    if (i < nt->d.n) __builtin_prefetch(nt->d.vertex_of + i);
}

jf_status jf__natural_neighbors_own(const jf_natural *nt, jf_natural_ws *ws, size_t i,
                                    const double nrm[3], size_t N, uint32_t *idx, size_t cap,
                                    size_t *found) {
    return neighbors(nt, ws, i, nrm, N, nt && nt->row, idx, cap, found);
}

jf_status jf_natural_neighbors(const jf_natural *nt, jf_natural_ws *ws, size_t i,
                               const double nrm[3], size_t N, uint32_t *idx, size_t cap,
                               size_t *found) {
    if (!idx) return JF_ERR_INVALID;
    return neighbors(nt, ws, i, nrm, N, 0, idx, cap, found);
}

jf_status jf_natural_rings(const jf_natural *nt, jf_natural_ws *ws, size_t i,
                           const double nrm[3], int nrings, uint32_t *idx, size_t cap,
                           size_t *found, size_t *ring_end) {
    if (!found || !idx || nrings < 0) return JF_ERR_INVALID;
    *found = 0;
    size_t len;
    if (ring_end)
        for (int r = 0; r <= nrings; r++) ring_end[r] = 0;
    jf_status st = grow(nt, ws, i, nrm, SIZE_MAX, nrings, 0, &len, ring_end);
    if (st != JF_OK || len == 0) return st;
    if (ring_end) /* rings past the end of the cloud are empty */
        for (int r = 1; r <= nrings; r++)
            if (ring_end[r] < ring_end[r - 1]) ring_end[r] = ring_end[r - 1];
    if (len > cap) return JF_ERR_TOO_LARGE;
    idx[0] = (uint32_t)i;
    for (size_t k = 1; k < len; k++) idx[k] = nt->d.rep[ws->list[k]];
    *found = len;
    return JF_OK;
}
