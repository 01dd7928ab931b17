/*
 * natural_knn.c -- natural neighbourhoods without a triangulation (issue
 * 15.2): the form's vertices and candidates (each planar power cell is
 * clipped by the sample's nearest samples from the k-d tree until a
 * certificate proves it exact: natural_cell.c; natural.c says why
 * clipping by any superset of the cutting samples gives the cell); and
 * the own-plane rows: every sample's cell made once in its own tangent
 * plane, the rings grown from them (natural.c own_ring).  Vertices are the tree's positions; no
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

size_t jf__natural_query(const jf_natural *nt, size_t v, uint32_t pos[CAND_K], jf__kd_scan *scan) {
    uint32_t p[CAND_K + 1];
    double d2[CAND_K + 1];
    size_t f = 0, c = 0;
    if (!nt || !nt->ix || v >= nt->d.nv) return SIZE_MAX;
    if ((scan ? jf__index_knn_scan(nt->ix, nt->vxyz + 3 * v, CAND_K + 1, p, d2, &f, scan)
              : jf__index_knn_pos(nt->ix, nt->vxyz + 3 * v, CAND_K + 1, INFINITY, p, d2, &f)) != JF_OK)
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
                        size_t cnt, const jf__kd_scan *scan) {
    const jf_natural *nt = ws->nt;
    uint32_t *row = nt->row + v * ROW_W;
    plane h;
    size_t len = 0;
    row[0] = ROW_LIVE;
    if (!jf__natural_plane(nt->vxyz + 3 * v, nrm, &h)) return 1;
    if (!jf__natural_knn_cell(ws, &h, (uint32_t)v, c, cnt, scan, NULL, &len)) return 0;
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
            jf__kd_scan scan;
            if (bad) continue;
            size_t cnt = jf__natural_query(nt, (size_t)v, c, &scan);
            if (cnt == SIZE_MAX) {
                bad |= 2;
                continue;
            }
            bad |= !jf__natural_own_row(ws, (size_t)v, nrm + 3 * (size_t)nt->d.rep[v], c, cnt, &scan);
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

