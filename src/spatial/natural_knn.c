/*
 * natural_knn.c -- natural neighbourhoods without a triangulation (issue
 * 15.2): each planar power cell clipped by the sample's nearest samples
 * from the k-d tree, nearest first, until a certificate proves it exact
 * (knn_cell below; natural.c says why clipping by any superset of the
 * cutting samples gives the cell).  Vertices are the tree's positions;
 * d.adj holds CAND_K candidates per vertex (NONE-padded); no poles, no
 * merged duplicates.  docs/natural.md, "The k-NN cells".
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "index_internal.h"
#include "natural_internal.h"

/* The k-NN form over the tree ix: vertex v = tree position v; its
 * CAND_K nearest other vertices by (distance, input index). */
jf_status jf__natural_from_index(const jf_index *ix, int threads, jf_natural **out) {
    if (!ix || !out) return JF_ERR_INVALID;
    *out = NULL;
    int nthr = jf__natural_threads(threads);
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
    nt->d.adj = malloc((m * CAND_K + 1) * sizeof *nt->d.adj);
    if (!nt->d.vertex_of || !nt->d.rep || !nt->d.adj) {
        jf_natural_free(nt);
        return JF_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++) nt->d.vertex_of[i] = NONE;
    for (size_t v = 0; v < m; v++) nt->d.rep[v] = id[v], nt->d.vertex_of[id[v]] = (uint32_t)v;
    long ml = (long)m;
    int bad = 0;
#ifdef _OPENMP
#pragma omp parallel for schedule(static, 1024) num_threads(nthr) reduction(| : bad)
#endif
    for (long v = 0; v < ml; v++) {
        uint32_t pos[CAND_K + 1], *a = nt->d.adj + (size_t)v * CAND_K;
        double d2[CAND_K + 1];
        size_t f = 0, c = 0;
        bad |= jf__index_knn_pos(ix, pts + 3 * v, CAND_K + 1, INFINITY, pos, d2, &f) != JF_OK;
        for (size_t j = 0; j < f && c < CAND_K; j++)
            if (pos[j] != (uint32_t)v) a[c++] = pos[j];
        while (c < CAND_K) a[c++] = NONE;
    }
    if (bad) {
        jf_natural_free(nt);
        return JF_ERR_INTERNAL;
    }
    *out = nt;
    return JF_OK;
}

size_t jf__natural_candidates(const jf_natural *nt, size_t v, const uint32_t **pos) {
    if (!nt || !nt->ix || v >= nt->d.nv) return 0;
    size_t c = 0;
    *pos = nt->d.adj + v * CAND_K;
    while (c < CAND_K && (*pos)[c] != NONE) c++;
    return c;
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

/* k-NN form of cell_neighbors: u's planar cell clipped by its
 * candidates, nearest first.  Certificate: a sample s at 3D distance
 * d_s from u cannot cut the cell at a vertex x (in H) with
 * |x - u| <= d_s / 2, since |x - s| >= d_s - |x - u| >= |x - u|.  So
 * once the next candidate is at least twice as far as every vertex of
 * the polygon, no sample further out cuts it either and the cell is
 * exact.  The candidates run out before that only where the cell is
 * large (rim of an open scan, sparse or far-off-plane u): the query
 * widens to CAND_MAX, then the cell is taken as clipped by the box. */
int jf__natural_knn_cell(jf_natural_ws *ws, const plane *h, uint32_t u, size_t *len) {
    const jf_natural *nt = ws->nt;
    const double *U = nt->vxyz + 3 * (size_t)u;
    const uint32_t *c;
    size_t cnt = jf__natural_candidates(nt, u, &c), K = CAND_K, np, j = 0;
    if (!cnt) return 1;
    double ux, uy, uz;
    project(h, U, &ux, &uy, &uz);
    const double *L = nt->vxyz + 3 * (size_t)c[cnt - 1];
    double reach = sqrt((L[0] - U[0]) * (L[0] - U[0]) + (L[1] - U[1]) * (L[1] - U[1]) +
                        (L[2] - U[2]) * (L[2] - U[2]));
    const double B = BOX_SCALE * reach;
    np = jf__natural_box(ws, B);
    double r2 = 2 * B * B + uz * uz; /* largest |x - u|^2 over the polygon */
    for (;;) {
        for (; j < cnt && np > 0; j++) {
            const double *S = nt->vxyz + 3 * (size_t)c[j];
            double dx = S[0] - U[0], dy = S[1] - U[1], dz = S[2] - U[2];
            if (dx * dx + dy * dy + dz * dz >= 4 * r2) goto exact;
            double x, y, z;
            project(h, S, &x, &y, &z);
            double sx = x - ux, sy = y - uy, sr = sx * sx + sy * sy + (z - uz) * (z + uz);
            if (!jf__natural_cut(ws, &np, sx, sy, sr, c[j])) continue;
            r2 = 0;
            for (size_t k = 0; k < np; k++) {
                double q = ws->px[k] * ws->px[k] + ws->py[k] * ws->py[k];
                if (q > r2) r2 = q;
            }
            r2 += uz * uz;
        }
        if (np == 0 || cnt < K || K >= CAND_MAX) break;
        const double *S = nt->vxyz + 3 * (size_t)c[cnt - 1];
        double dx = S[0] - U[0], dy = S[1] - U[1], dz = S[2] - U[2];
        if (dx * dx + dy * dy + dz * dz >= 4 * r2) break; /* the last cut shrank it enough */
        /* widen: the first j of a wider list are the same candidates.
         * First the CAND_MID nearest, from the thread's cache (fewer: the
         * whole cloud); then the samples within 2 |x - u| (at most
         * CAND_MAX; fewer found: all of them) */
        size_t f = 0, m = 0;
        if (K == CAND_K) {
            K = CAND_MID;
            size_t slot = u & (WCACHE - 1);
            uint32_t *w = ws->wlist + slot * CAND_MID;
            if (ws->wkey[slot] != u) {
                if (jf__index_knn_pos(nt->ix, U, CAND_MID + 1, INFINITY, ws->cpos, ws->cd2, &f) != JF_OK)
                    return 0;
                for (size_t k = 0; k < f && m < CAND_MID; k++)
                    if (ws->cpos[k] != u) w[m++] = ws->cpos[k];
                ws->wkey[slot] = u;
                ws->wcnt[slot] = (uint8_t)m;
            }
            c = w;
            cnt = ws->wcnt[slot];
            continue;
        }
        K = CAND_MAX;
        if (jf__index_knn_pos(nt->ix, U, K + 1, 4 * r2, ws->cpos, ws->cd2, &f) != JF_OK) return 0;
        for (size_t k = 0; k < f; k++)
            if (ws->cpos[k] != u) ws->cpos[m++] = ws->cpos[k];
        c = ws->cpos;
        cnt = m;
    }
exact:
    return jf__natural_labels(ws, h, np, reach, len);
}
