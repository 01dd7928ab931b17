/*
 * natural_knn.c -- natural neighbourhoods without a triangulation (issue
 * 15.2): each planar power cell clipped by the sample's nearest samples
 * from the k-d tree, nearest first, until a certificate proves it exact
 * (knn_cell below; natural.c says why clipping by any superset of the
 * cutting samples gives the cell); and the own-plane rows: every
 * sample's cell made once in its own tangent plane, the rings grown from
 * them (natural.c own_ring).  Vertices are the tree's positions; no
 * poles, no merged duplicates.  docs/natural.md, "Own-plane rings" and
 * "The k-NN cells".
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "natural_internal.h"

/* The k-NN form over the tree ix: vertex v = tree position v; its
 * candidates are queried when its cell is made (nothing per vertex is
 * kept but the vertex maps). */
jf_status jf__natural_from_index(const jf_index *ix, int threads, jf_natural **out) {
    if (!ix || !out) return JF_ERR_INVALID;
    *out = NULL;
    jf_natural *nt = calloc(1, sizeof *nt);
    if (!nt) return JF_ERR_NOMEM;
    const double *pts;
    const uint32_t *id;
    size_t m = jf__index_points(ix, &pts, &id), n = jf__index_input_size(ix);
    nt->ix = ix;
    nt->vxyz = (double *)pts; /* borrowed: never freed in this form */
    nt->max_deg = CAND_MAX;
    nt->d.dimension = 3;
    nt->d.n = n;
    nt->d.nv = m;
    nt->d.vertex_of = malloc((n + 1) * sizeof *nt->d.vertex_of);
    nt->d.rep = malloc((m + 1) * sizeof *nt->d.rep);
    if (!nt->d.vertex_of || !nt->d.rep) {
        jf_natural_free(nt);
        return JF_ERR_NOMEM;
    }
    long nl = (long)n, ml = (long)m;
#ifdef _OPENMP
#pragma omp parallel num_threads(jf__natural_threads(threads))
#endif
    { /* first touch on every thread; the ids are distinct */
#ifdef _OPENMP
#pragma omp for schedule(static)
#endif
        for (long i = 0; i < nl; i++) nt->d.vertex_of[i] = NONE;
#ifdef _OPENMP
#pragma omp for schedule(static)
#endif
        for (long v = 0; v < ml; v++) nt->d.rep[v] = id[v], nt->d.vertex_of[id[v]] = (uint32_t)v;
    }
    *out = nt;
    return JF_OK;
}

size_t jf__natural_query(const jf_natural *nt, size_t v, uint32_t pos[CAND_K]) {
    uint32_t p[CAND_K + 1];
    double d2[CAND_K + 1];
    size_t f = 0, c = 0;
    if (!nt || !nt->ix || v >= nt->d.nv) return SIZE_MAX;
    if (jf__index_knn_pos(nt->ix, nt->vxyz + 3 * v, CAND_K + 1, INFINITY, p, d2, &f) != JF_OK)
        return SIZE_MAX;
    for (size_t j = 0; j < f && c < CAND_K; j++)
        if (p[j] != (uint32_t)v) pos[c++] = p[j];
    return c;
}

jf_status jf__natural_rows_alloc(jf_natural *nt, const double *nrm) {
    if (!nt || !nt->ix || !nrm) return JF_ERR_INVALID;
    nt->row_nrm = nrm;
    if (!nt->row && !(nt->row = malloc((nt->d.nv * ROW_W + 1) * sizeof *nt->row)))
        return JF_ERR_NOMEM;
    return JF_OK; /* filled (and first touched) by the threads' passes */
}

int jf__natural_own_row(jf_natural_ws *ws, size_t v, const double nrm[3], const uint32_t *c,
                        size_t cnt) {
    const jf_natural *nt = ws->nt;
    uint32_t *row = nt->row + v * ROW_W;
    plane h;
    size_t len = 0;
    row[0] = ROW_LIVE;
    if (!jf__natural_plane(nt->vxyz + 3 * v, nrm, &h)) return 1;
    jf__natural_collect(ws, (uint32_t)v);
    if (!jf__natural_knn_cell(ws, &h, (uint32_t)v, c, cnt, h.o, &len)) return 0;
    if (len > ROW_W) return 1; /* rare: made again when asked */
    for (size_t k = 0; k < ROW_W; k++) row[k] = k < len ? ws->list[k] : NONE;
    return 1;
}

jf_status jf__natural_own_rows(jf_natural *nt, int threads, const double *nrm) {
    if (!nt || !nt->ix || !nrm) return JF_ERR_INVALID;
    jf_status st = jf__natural_rows_alloc(nt, nrm);
    if (st != JF_OK) return st;
    long nv = (long)nt->d.nv;
    int bad = 0; /* 1: no memory, 2: a failed query */
#ifdef _OPENMP
#pragma omp parallel num_threads(jf__natural_threads(threads)) reduction(| : bad)
#endif
    {
        jf_natural_ws *ws = NULL;
        bad |= jf_natural_ws_create(nt, &ws) != JF_OK;
#ifdef _OPENMP
#pragma omp for schedule(static, 1024)
#endif
        for (long v = 0; v < nv; v++) {
            uint32_t c[CAND_K];
            if (bad) continue;
            size_t cnt = jf__natural_query(nt, (size_t)v, c);
            if (cnt == SIZE_MAX) {
                bad |= 2;
                continue;
            }
            bad |= !jf__natural_own_row(ws, (size_t)v, nrm + 3 * (size_t)nt->d.rep[v], c, cnt);
        }
        jf_natural_ws_free(ws);
    }
    return bad & 1 ? JF_ERR_NOMEM : bad ? JF_ERR_INTERNAL : JF_OK;
}

const jf_index *jf__natural_index(const jf_natural *nt) { return nt ? nt->ix : NULL; }

void jf__natural_coords(const jf_natural_ws *ws, size_t found, double *xyz) {
    for (size_t k = 0; k < found; k++)
        memcpy(xyz + 3 * k, ws->nt->vxyz + 3 * (size_t)ws->list[k], sizeof(double[3]));
}

jf_status jf_natural_create_knn(const double *xyz, size_t n, int threads, jf_natural **out) {
    if (!out || (!xyz && n > 0)) return JF_ERR_INVALID;
    *out = NULL;
    if (n >= UINT32_MAX) return JF_ERR_TOO_LARGE;
    jf_index *ix = NULL;
    jf_status st = jf__index_build_threads(xyz, n, threads, &ix);
    if (st == JF_OK && (st = jf__natural_from_index(ix, threads, out)) == JF_OK)
        (*out)->ix_own = ix;
    else
        jf_index_free(ix);
    return st;
}

/* Cuts the cell (u' at (ux, uy) in h, u at height uz) by sample s:
 * jf__natural_cut's return. */
static int cut_by(jf_natural_ws *ws, const plane *h, double ux, double uy, double uz, uint32_t s,
                  size_t *np) {
    double x, y, z;
    project(h, ws->nt->vxyz + 3 * (size_t)s, &x, &y, &z);
    double sx = x - ux, sy = y - uy;
    return jf__natural_cut(ws, np, sx, sy, sx * sx + sy * sy + (z - uz) * (z + uz), s);
}

/* The cell u' clipped by all samples of the candidate list (the last at
 * squared distance dl2 from u) is exact iff no vertex x has a sample
 * strictly nearer than u (a half-plane that cuts a convex polygon holds
 * one of its vertices).  Vertices with |x - u| <= dl / 2 are certified by
 * the list.  The balls B(x, |x - u|) of the others all pass through u,
 * and z in B(c, |c - u|) is linear in c, so the ball of any point of the
 * polygon lies in the union of its vertices' balls: one query for every
 * sample in a ball enclosing the uncertified vertices' balls, and the
 * cell clipped by them, is exact -- the clips only shrink the polygon.
 * Cheaper than the samples within 2 max |x - u| of u.  Returns 1 when
 * exact, -1 when that ball holds CAND_MID samples or more (the caller
 * widens), 0 on a failed query. */
static int verify(jf_natural_ws *ws, const plane *h, uint32_t u, double ux, double uy, double uz,
                  double dl2, size_t *np) {
    const jf_natural *nt = ws->nt;
    double cx = 0, cy = 0, m = 0;
    for (size_t k = 0; k < *np; k++) {
        double px = ws->px[k], py = ws->py[k];
        if (4 * (px * px + py * py + uz * uz) > dl2) cx += px, cy += py, m++;
    }
    if (m == 0) return 1;
    cx /= m, cy /= m;
    double rho = 0;
    for (size_t k = 0; k < *np; k++) {
        double px = ws->px[k], py = ws->py[k], rx2 = px * px + py * py + uz * uz;
        if (4 * rx2 <= dl2) continue;
        double e = sqrt((px - cx) * (px - cx) + (py - cy) * (py - cy)) + sqrt(rx2);
        rho = e > rho ? e : rho;
    }
    rho *= 1 + 1e-12; /* the rounding of the sums above, outwards */
    double X[3];
    for (int d = 0; d < 3; d++) X[d] = h->o[d] + (ux + cx) * h->e1[d] + (uy + cy) * h->e2[d];
    size_t f = 0;
    if (jf__index_knn_pos(nt->ix, X, CAND_MID, rho * rho, ws->cpos, ws->cd2, &f) != JF_OK) return 0;
    if (f == CAND_MID) return -1;
    for (size_t j = 0; j < f && *np > 0; j++) {
        if (ws->cpos[j] != u) cut_by(ws, h, ux, uy, uz, ws->cpos[j], np);
    }
    return 1;
}

/* k-NN form of cell_neighbors: u's planar cell clipped by its
 * candidates, nearest first.  Certificate: a sample s at 3D distance
 * d_s from u cannot cut the cell at a vertex x (in H) with
 * |x - u| <= d_s / 2, since |x - s| >= d_s - |x - u| >= |x - u|.  So
 * once the next candidate is at least twice as far as every vertex of
 * the polygon, no sample further out cuts it either and the cell is
 * exact.  The candidates run out before that only where the cell is
 * large (rim of an open scan, sparse or far-off-plane u): the query
 * widens to the samples within twice the polygon's radius (at most
 * CAND_MID, then CAND_MAX), then the cell is taken as clipped by the box. */
int jf__natural_knn_cell(jf_natural_ws *ws, const plane *h, uint32_t u, const uint32_t *c,
                         size_t cnt, const double *from, size_t *len) {
    const jf_natural *nt = ws->nt;
    const double *U = nt->vxyz + 3 * (size_t)u;
    size_t K = CAND_K, np, j = 0;
    if (!c) { /* widening below may overwrite cpos: it then reads its own list */
        cnt = jf__natural_query(nt, u, ws->cpos);
        if (cnt == SIZE_MAX) return 0;
        c = ws->cpos;
    }
    if (!cnt) return 1;
    double ux, uy, uz;
    project(h, U, &ux, &uy, &uz);
    double reach = sqrt(dist2(nt->vxyz + 3 * (size_t)c[cnt - 1], U));
    const double B = BOX_SCALE * reach;
    np = jf__natural_box(ws, B);
    double r2 = 2 * B * B + uz * uz; /* largest |x - u|^2 over the polygon */
    for (;;) {
        for (; j < cnt && np > 0; j++) {
            if (dist2(nt->vxyz + 3 * (size_t)c[j], U) >= 4 * r2) goto exact;
            if (cut_by(ws, h, ux, uy, uz, c[j], &np)) r2 = ws->r2 + uz * uz;
        }
        if (np == 0 || cnt < K || K >= CAND_MAX) break;
        double dl2 = dist2(nt->vxyz + 3 * (size_t)c[cnt - 1], U);
        if (dl2 >= 4 * r2) break; /* the last cut shrank it enough */
        if (K == CAND_K) {
            int v = verify(ws, h, u, ux, uy, uz, dl2, &np);
            if (v == 0) return 0;
            if (v > 0) break;
        }
        /* widen: the samples within 2 |x - u| (the first j of them are
         * the same candidates), at most CAND_MID, then CAND_MAX; fewer
         * found: all of them */
        size_t f = 0, m = 0;
        K = K < CAND_MID ? CAND_MID : CAND_MAX;
        if (jf__index_knn_pos(nt->ix, U, K + 1, 4 * r2, ws->cpos, ws->cd2, &f) != JF_OK) return 0;
        for (size_t k = 0; k < f; k++)
            if (ws->cpos[k] != u) ws->cpos[m++] = ws->cpos[k];
        c = ws->cpos;
        cnt = m;
    }
exact:
    return jf__natural_labels(ws, from, np, reach, len);
}
