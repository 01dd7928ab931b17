/* natural_internal.h -- what natural.c (the triangulation's form, the
 * rings) and natural_knn.c (the k-NN form's cells) share; not public. */
#ifndef JF_NATURAL_INTERNAL_H
#define JF_NATURAL_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "cgal_bridge.h"
#include "index_internal.h"
#include "jetfit.h"

#define NONE UINT32_MAX
#define BOX_SCALE 2.0      /* box half-size / farthest 3D neighbour     */
#define EDGE_EPS 1e-9      /* edges shorter than this x reach: no edge */

#define CAND_K JF_NATURAL_CAND /* k-NN cells: candidates queried first */
#define CAND_MID 47        /* widened: at most (47 + itself: the tree's
                              sorted path)                              */
#define CAND_MAX 144       /* then at most                              */
#define ROW_W 10           /* own-plane rows: labels kept per vertex    */
#define ROW_LIVE (NONE - 1) /* row[0]: no row, the cell made when asked */

/* Two sources of the cells' cutting neighbours: the 3D Delaunay
 * neighbours (exact by construction), or the k-NN candidates of the k-d
 * tree, nearest first, with a certificate (knn_cell).  In the k-NN form
 * vertices are the tree's positions, the candidates are queried when a
 * cell is made, d.adj, d.adj_off, d.pole, d.hull are NULL; row (when
 * made) holds each vertex's cell labels in its own tangent plane. */
struct jf_natural {
    jfb_delaunay d;
    double *vxyz; /* [3nv] coordinates of each vertex                  */
    double *nn;   /* [nv] distance to the nearest Delaunay neighbour    */
    size_t max_deg;
    const jf_index *ix; /* k-NN form: the tree (owned if ix_own)        */
    jf_index *ix_own;
    uint32_t *row; /* k-NN form: [nv * ROW_W] own-plane labels, NONE-
                      padded; row[0] == ROW_LIVE: made when asked    */
    const double *row_nrm; /* the rows' normals, by input index (borrowed) */
};

struct jf_natural_ws {
    const jf_natural *nt;
    uint32_t *stamp; /* [nv] == gen: vertex already collected          */
    uint32_t gen;
    uint32_t *list;  /* collected vertices, in ring order              */
    double *dist;    /* their squared distance to p                    */
    size_t listcap;
    double *px, *py, *qx, *qy; /* polygon buffers (max_deg + 8)        */
    uint32_t *pl, *ql;         /* edge labels (vertex id, NONE = box)   */
    double r2;                 /* after a clip: max px^2 + py^2         */
    double *sx, *sy, *sr;      /* projected neighbours of the cell     */
    uint32_t *cpos;            /* k-NN form: a candidate query         */
    double *cd2;
};

/* The tangent plane: orthonormal e1, e2 spanning it, n its unit normal. */
typedef struct {
    double o[3], e1[3], e2[3], n[3];
} plane;

static inline void project(const plane *h, const double *q, double *x, double *y, double *z) {
    double d[3] = {q[0] - h->o[0], q[1] - h->o[1], q[2] - h->o[2]};
    *x = d[0] * h->e1[0] + d[1] * h->e1[1] + d[2] * h->e1[2];
    *y = d[0] * h->e2[0] + d[1] * h->e2[1] + d[2] * h->e2[2];
    *z = d[0] * h->n[0] + d[1] * h->n[1] + d[2] * h->n[2];
}

/* |a - b|^2 (the one expression: rings and cells compare these bit for
 * bit). */
static inline double dist2(const double *a, const double *b) {
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
           (a[2] - b[2]) * (a[2] - b[2]);
}

/* |nrm|^2, 0 when nrm gives no plane (zero, or not finite) */
static inline double plane_len2(const double nrm[3]) {
    double l2 = nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2];
    return l2 > 0 && isfinite(l2) ? l2 : 0;
}

/* h through o with unit normal along nrm; 0 if nrm is zero or not
 * finite. */
int jf__natural_plane(const double *o, const double nrm[3], plane *h);

/* A new collection on ws: its stamp generation (stamps cleared when it
 * wraps), v stamped as collected. */
void jf__natural_collect(jf_natural_ws *ws, uint32_t v);

/* OpenMP thread count of a call: threads, or every core when <= 0. */
int jf__natural_threads(int threads);

/* Room for `more` list entries after len (amortised growth, not per
 * point); 0 when out of memory. */
int jf__natural_reserve(jf_natural_ws *ws, size_t len, size_t more);

/* Appends v (squared distance d2 to p) to the list; 0 when out of memory. */
static inline int jf__natural_push(jf_natural_ws *ws, size_t *len, uint32_t v, double d2) {
    if (*len == ws->listcap && !jf__natural_reserve(ws, *len, 1)) return 0;
    ws->list[*len] = v;
    ws->dist[(*len)++] = d2;
    return 1;
}

/* natural_cell.c: vertex u's cell in the plane h clipped by its 3D
 * Delaunay neighbours (the triangulation's form): the labels of its
 * edges not yet collected appended to the list with their squared
 * distance to h->o (edges shorter than EDGE_EPS x reach: no adjacency).
 * 0: no memory. */
int jf__natural_tri_cell(jf_natural_ws *ws, const plane *h, uint32_t u, size_t *len);

/* natural_cell.c: vertex u's cell in the plane h from its k-NN candidates
 * c[0..cnt) (nearest first, all of the CAND_K nearest, scan what their
 * search read or NULL; c NULL: queried here), made exact by the
 * certificate; its labels appended as
 * jf__natural_tri_cell does (distances from `from`; from NULL: every
 * label, no stamps or distances -- a row).  Returns 0 on a failed query
 * or no memory. */
int jf__natural_knn_cell(jf_natural_ws *ws, const plane *h, uint32_t u, const uint32_t *c,
                         size_t cnt, const jf__kd_scan *scan, const double *from, size_t *len);

#endif /* JF_NATURAL_INTERNAL_H */
