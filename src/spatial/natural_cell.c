/*
 * natural_cell.c -- one planar power cell (§5.1; natural.c says why the
 * clipped cell is exact): the tangent plane, the convex clip, and the
 * cell from either source of cutting samples -- the 3D Delaunay
 * neighbours (the triangulation's form) or the k-d tree's nearest
 * samples with a certificate (the k-NN form).  One file so the clip is
 * inlined where the cells are made (docs/natural.md, "Speed").
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "index_internal.h"
#include "natural_internal.h"

int jf__natural_plane(const double *o, const double nrm[3], plane *h) {
    const double l2 = plane_len2(nrm);
    if (!l2) return 0;
    /* e1: the world axis least aligned with nrm, made orthogonal:
     * t = l2 e_ax - a nrm (a = nrm_ax), |t|^2 = l2 (l2 - a^2) with
     * a^2 <= l2 / 3 -- both square roots at once, not one waiting on the
     * other (the plane is on the path of every cell) */
    const int ax = fabs(nrm[0]) < fabs(nrm[1]) ? (fabs(nrm[0]) < fabs(nrm[2]) ? 0 : 2)
                                                : (fabs(nrm[1]) < fabs(nrm[2]) ? 1 : 2);
    const double a = nrm[ax], l = sqrt(l2), s = sqrt(l2 - a * a), il = 1 / l, it = 1 / (l * s);
    /* in locals, no indexed store (read back as a vector, it stalls) */
    double n[3], e[3];
    for (int k = 0; k < 3; k++) n[k] = nrm[k] * il, e[k] = ((k == ax ? l2 : 0) - a * nrm[k]) * it;
    for (int k = 0; k < 3; k++) h->o[k] = o[k], h->n[k] = n[k], h->e1[k] = e[k];
    h->e2[0] = n[1] * e[2] - n[2] * e[1];
    h->e2[1] = n[2] * e[0] - n[0] * e[2];
    h->e2[2] = n[0] * e[1] - n[1] * e[0];
    return 1;
}

/* Clips the convex polygon (px, py, pl)[0..*m) by a.x <= b; pl[k] labels
 * the edge from vertex k to k+1.  Sutherland-Hodgman; the new edge along
 * the clip line gets label s; ws->r2 = the largest px^2 + py^2 of the
 * result (what the k-NN cells' certificate needs, without a second
 * pass over vertices just stored). */
static int clip(jf_natural_ws *ws, size_t *m, double ax, double ay, double b, uint32_t s) {
    const double *restrict px = ws->px, *restrict py = ws->py;
    const uint32_t *restrict pl = ws->pl;
    double *restrict qx = ws->qx, *restrict qy = ws->qy;
    uint32_t *restrict ql = ws->ql;
    size_t n = *m, o = 0, k0;
    for (k0 = 0; k0 < n; k0++) /* most 3D neighbours cut nothing: no copy */
        if (ax * px[k0] + ay * py[k0] > b) break;
    if (k0 == n) return 0;
    const double f0 = ax * px[0] + ay * py[0] - b;
    double fu = f0, r2 = 0;
    for (size_t k = 0; k < n; k++) {
        const size_t k1 = k + 1 == n ? 0 : k + 1;
        const double fw = k1 ? ax * px[k1] + ay * py[k1] - b : f0;
        if (fu <= 0) {
            qx[o] = px[k], qy[o] = py[k], ql[o++] = pl[k];
            const double q = px[k] * px[k] + py[k] * py[k];
            r2 = q > r2 ? q : r2;
            if (fw > 0) {
                const double t = fu / (fu - fw), x = px[k] + t * (px[k1] - px[k]),
                             y = py[k] + t * (py[k1] - py[k]);
                qx[o] = x, qy[o] = y, ql[o++] = s;
                r2 = x * x + y * y > r2 ? x * x + y * y : r2;
            }
        } else if (fw <= 0) {
            const double t = fu / (fu - fw), x = px[k] + t * (px[k1] - px[k]),
                         y = py[k] + t * (py[k1] - py[k]);
            qx[o] = x, qy[o] = y, ql[o++] = pl[k];
            r2 = x * x + y * y > r2 ? x * x + y * y : r2;
        }
        fu = fw;
    }
    ws->qx = ws->px, ws->qy = ws->py, ws->ql = ws->pl;
    ws->px = qx, ws->py = qy, ws->pl = ql;
    ws->r2 = r2;
    *m = o;
    return 1;
}

static size_t box(jf_natural_ws *ws, double B) {
    const double bx[4] = {-B, B, B, -B}, by[4] = {-B, -B, B, B};
    for (int k = 0; k < 4; k++) ws->px[k] = bx[k], ws->py[k] = by[k], ws->pl[k] = NONE;
    return 4;
}

static int cut(jf_natural_ws *ws, size_t *np, double sx, double sy, double sr, uint32_t s) {
    if (sx == 0 && sy == 0) {
        if (sr < 0) *np = 0; /* s straight above u, nearer H: u has no cell */
        return 0;
    }
    return clip(ws, np, 2 * sx, 2 * sy, sr, s);
}

/* Appends the labels of the clipped cell's edges (np vertices) not yet
 * collected, with their squared distance to p; edges shorter than
 * EDGE_EPS x reach are no adjacency.  p NULL (a row): every label, no
 * stamps or distances (a convex cell's labels are distinct; the rings
 * check them again anyway).  Returns 0 when out of memory. */
static int labels(jf_natural_ws *ws, const double *p, size_t np, double reach, size_t *len) {
    const jf_natural *nt = ws->nt;
    for (size_t k = 0; k < np; k++) {
        uint32_t s = ws->pl[k];
        if (s == NONE || (p && ws->stamp[s] == ws->gen)) continue;
        size_t k1 = k + 1 == np ? 0 : k + 1;
        double ex = ws->px[k1] - ws->px[k], ey = ws->py[k1] - ws->py[k];
        if (ex * ex + ey * ey <= EDGE_EPS * EDGE_EPS * reach * reach) continue;
        if (p) ws->stamp[s] = ws->gen;
        if (!jf__natural_push(ws, len, s, p ? dist2(nt->vxyz + 3 * (size_t)s, p) : 0)) return 0;
    }
    return 1;
}

/* Appends to the list the planar natural neighbours of vertex u not yet
 * collected (the edge labels of u's clipped power cell). */
int jf__natural_tri_cell(jf_natural_ws *ws, const plane *h, uint32_t u, size_t *len) {
    const jf_natural *nt = ws->nt;
    size_t b = nt->d.adj_off[u], e = nt->d.adj_off[u + 1], m = 0;
    double ux, uy, uz, reach = 0;
    project(h, nt->vxyz + 3 * (size_t)u, &ux, &uy, &uz);
    for (size_t k = b; k < e; k++, m++) {
        double x, y, z;
        project(h, nt->vxyz + 3 * (size_t)nt->d.adj[k], &x, &y, &z);
        /* relative to u': the half-plane 2 d.X <= |d|^2 + h_s^2 - h_u^2 */
        ws->sx[m] = x - ux, ws->sy[m] = y - uy;
        ws->sr[m] = ws->sx[m] * ws->sx[m] + ws->sy[m] * ws->sy[m] + (z - uz) * (z + uz);
        double r = ws->sx[m] * ws->sx[m] + ws->sy[m] * ws->sy[m] + (z - uz) * (z - uz);
        if (r > reach) reach = r;
    }
    reach = sqrt(reach);
    size_t np = box(ws, BOX_SCALE * reach);
    for (size_t k = 0; k < m && np > 0; k++)
        cut(ws, &np, ws->sx[k], ws->sy[k], ws->sr[k], nt->d.adj[b + k]);
    return labels(ws, h->o, np, reach, len);
}

/* Cuts the cell (u' at (ux, uy) in h, u at height uz) by sample s:
 * cut's return. */
static int cut_by(jf_natural_ws *ws, const plane *h, double ux, double uy, double uz, uint32_t s,
                  size_t *np) {
    double x, y, z;
    project(h, ws->nt->vxyz + 3 * (size_t)s, &x, &y, &z);
    double sx = x - ux, sy = y - uy;
    return cut(ws, np, sx, sy, sx * sx + sy * sy + (z - uz) * (z + uz), s);
}

/* The cell u' clipped by every sample nearer u than dl = sqrt(dl2) (the
 * candidates, the last at dl; or those of the leaves their search read)
 * is exact iff no vertex x has a sample strictly nearer than u (a
 * half-plane that cuts a convex polygon holds one of its vertices).
 * Vertices with |x - u| <= dl / 2 are certified by those samples.  The balls B(x, |x - u|) of the others all pass through u,
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
    /* those nearer u than dl have cut it already */
    const double *U = nt->vxyz + 3 * (size_t)u;
    for (size_t j = 0; j < f && *np > 0; j++) {
        const uint32_t s = ws->cpos[j];
        if (s != u && !(dist2(nt->vxyz + 3 * (size_t)s, U) < dl2)) cut_by(ws, h, ux, uy, uz, s, np);
    }
    return 1;
}

/* Before a second query: the candidates' search read every sample
 * nearer u than sqrt(scan->rc2) (median 1.22 times the last candidate's
 * distance), in at most JF_KD_SCAN_LEAVES leaves.  The cell cut by those
 * of them beyond the candidates (d2 >= dl2) that can still cut (d2 < 4
 * r2) is exact out to |x - u| <= sqrt(rc2) / 2.  Returns the new r2. */
static double from_leaves(jf_natural_ws *ws, const plane *h, uint32_t u, double ux, double uy,
                          double uz, double dl2, double r2, const jf__kd_scan *scan,
                          size_t *np) {
    const double *V = ws->nt->vxyz, *U = V + 3 * (size_t)u;
    double *restrict d = ws->cd2; /* >= 32 entries (CAND_MAX) */
    for (size_t l = 0; l < scan->n; l++)
        for (uint32_t off = 0; off < scan->cnt[l] && *np > 0; off += 32) {
            /* a run of up to 32 points of the leaf (12..24): one bit each,
             * set where the point may cut (most: a candidate, or too far) */
            const uint32_t s0 = scan->first[l] + off,
                           m = scan->cnt[l] - off < 32 ? scan->cnt[l] - off : 32;
            const double *restrict P = V + 3 * (size_t)s0;
            uint32_t k = 0, in = 0;
#ifdef __SSE2__
            /* two points a step (the scalar dist2's operations, in lanes) */
            const __m128d u0 = _mm_set1_pd(U[0]), u1 = _mm_set1_pd(U[1]), u2 = _mm_set1_pd(U[2]),
                          lo = _mm_set1_pd(dl2), hi = _mm_set1_pd(4 * r2);
            for (; k + 1 < m; k += 2) {
                const __m128d a = _mm_loadu_pd(P + 3 * k), b = _mm_loadu_pd(P + 3 * k + 2),
                              c = _mm_loadu_pd(P + 3 * k + 4);
                const __m128d dx = _mm_sub_pd(_mm_shuffle_pd(a, b, 2), u0),
                              dy = _mm_sub_pd(_mm_shuffle_pd(a, c, 1), u1),
                              dz = _mm_sub_pd(_mm_shuffle_pd(b, c, 2), u2);
                const __m128d e = _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)),
                                             _mm_mul_pd(dz, dz));
                _mm_storeu_pd(d + k, e);
                in |= (uint32_t)_mm_movemask_pd(_mm_and_pd(_mm_cmpge_pd(e, lo), _mm_cmplt_pd(e, hi)))
                      << k;
            }
#endif
            for (; k < m; k++) {
                d[k] = dist2(P + 3 * k, U);
                in |= (uint32_t)(d[k] >= dl2 && d[k] < 4 * r2) << k;
            }
            for (; in && *np > 0; in &= in - 1) {
                k = (uint32_t)__builtin_ctz(in);
                if (d[k] >= 4 * r2 || s0 + k == u) continue; /* r2 shrinks as it is cut */
                if (cut_by(ws, h, ux, uy, uz, s0 + k, np)) r2 = ws->r2 + uz * uz;
            }
        }
    return r2;
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
                         size_t cnt, const jf__kd_scan *scan, const double *from, size_t *len) {
    const jf_natural *nt = ws->nt;
    const double *U = nt->vxyz + 3 * (size_t)u;
    size_t K = CAND_K, np, j = 0;
    jf__kd_scan own;
    if (!c) { /* widening below may overwrite cpos: it then reads its own list */
        cnt = jf__natural_query(nt, u, ws->cpos, &own);
        if (cnt == SIZE_MAX) return 0;
        c = ws->cpos;
        scan = &own;
    }
    if (!cnt) return 1;
    double ux, uy, uz;
    project(h, U, &ux, &uy, &uz);
    double reach = sqrt(dist2(nt->vxyz + 3 * (size_t)c[cnt - 1], U));
    const double B = BOX_SCALE * reach;
    np = box(ws, B);
    double r2 = 2 * B * B + uz * uz; /* largest |x - u|^2 over the polygon */
    for (;;) {
        for (; j < cnt && np > 0; j++) {
            /* s - u in the plane's frame: its length is the certificate's,
             * its half-plane the cut (one read of s) */
            double x, y, z;
            project(h, nt->vxyz + 3 * (size_t)c[j], &x, &y, &z);
            const double sx = x - ux, sy = y - uy, dz = z - uz, s2 = sx * sx + sy * sy;
            if (s2 + dz * dz >= 4 * r2) goto exact;
            if (cut(ws, &np, sx, sy, s2 + dz * (z + uz), c[j])) r2 = ws->r2 + uz * uz;
        }
        if (np == 0 || cnt < K || K >= CAND_MAX) break;
        double dl2 = dist2(nt->vxyz + 3 * (size_t)c[cnt - 1], U);
        if (dl2 >= 4 * r2) break; /* the last cut shrank it enough */
        if (K == CAND_K) {
            if (scan && scan->rc2 > dl2) { /* the leaves already read */
                r2 = from_leaves(ws, h, u, ux, uy, uz, dl2, r2, scan, &np);
                dl2 = scan->rc2;
                if (np == 0 || dl2 >= 4 * r2) break;
            }
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
    return labels(ws, from, np, reach, len);
}
