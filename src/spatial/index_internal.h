/* index_internal.h -- the k-d tree's own point storage, for the pipeline
 * (not part of the public API).  The tree keeps a contiguous copy of the
 * finite points in leaf order; walking the cloud in that order and taking
 * neighbour coordinates from that copy keeps a neighbourhood's reads in a
 * few adjacent leaves instead of scattered over the input array. */
#ifndef JF_INDEX_INTERNAL_H
#define JF_INDEX_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

/* jf_index_build on `threads` OpenMP threads (<= 0: the OpenMP default,
 * as jf_index_build), so that jf_estimate's thread count holds for the
 * tree's build too.  The tree is the same for any count. */
jf_status jf__index_build_threads(const double *xyz, size_t n, int threads, jf_index **out);

/* The m = jf_index_size(ix) indexed points in the tree's leaf order (a
 * spatially coherent order, as the Morton order): *pts their 3m
 * coordinates, *id their indices in the input.  Owned by the index.
 * Returns m. */
size_t jf__index_points(const jf_index *ix, const double **pts, const uint32_t **id);

/* jf_index_knn (bound = INFINITY) or jf_index_radius (bound = r*r, r >= 0)
 * with the same results, and also the coordinates of the found points,
 * nearest first, to xyz (3 per point, caller-owned) unless NULL. */
jf_status jf__index_query(const jf_index *ix, const double q[3], size_t k, double bound,
                          uint32_t *idx, double *d2, double *xyz, size_t *found);

/* knn_share.c: jf__index_query's k nearest (bound INFINITY) of a run of
 * nearby query points from one search per few points (neighbors auto).
 * The same lists, bit for bit; a jf__knn_share is one thread's.  A query
 * writes what is not NULL of idx, d2, xyz (k each) and pos (only the
 * first npos: step 6 reads q's nearest 32). */
typedef struct jf__knn_share jf__knn_share;
jf_status jf__knn_share_create(size_t k, size_t npos, jf__knn_share **out);
void jf__knn_share_free(jf__knn_share *s);
/* The walk's next n points, xyz[0..2] the next query's (a hint for where
 * to search: any hint gives the same lists). */
void jf__knn_share_ahead(jf__knn_share *s, const double *xyz, size_t n);
jf_status jf__knn_share_query(jf__knn_share *s, const jf_index *ix, const double q[3],
                              uint32_t *idx, uint32_t *pos, double *d2, double *xyz,
                              size_t *found);

/* n given to the build (jf_index_size counts the finite ones only). */
size_t jf__index_input_size(const jf_index *ix);

/* jf__index_query (no coordinates) leaving positions in the tree's order
 * (indices into *pts of jf__index_points) in pos instead of input
 * indices. */
jf_status jf__index_knn_pos(const jf_index *ix, const double q[3], size_t k, double bound,
                            uint32_t *pos, double *d2, size_t *found);

/* What a k-NN search read: the leaves it scanned (tree positions
 * first[j] .. first[j] + cnt[j] - 1) and rc2, the least squared distance
 * a point it did not read can have (every point nearer is in those
 * leaves; 0 when more than JF_KD_SCAN_LEAVES leaves were read).  The
 * k-NN cells use it to certify their rim without a second query. */
#define JF_KD_SCAN_LEAVES 16
typedef struct {
    uint32_t first[JF_KD_SCAN_LEAVES], cnt[JF_KD_SCAN_LEAVES];
    size_t n;
    double rc2;
} jf__kd_scan;

/* jf__index_knn_pos (no bound) recording what it read in *scan. */
jf_status jf__index_knn_scan(const jf_index *ix, const double q[3], size_t k, uint32_t *pos,
                             double *d2, size_t *found, jf__kd_scan *scan);

/* natural.c: natural neighbourhoods over k-NN candidates of the tree's
 * points (borrowed: ix must outlive *out); see jf_natural_create_knn. */
jf_status jf__natural_from_index(const jf_index *ix, int threads, jf_natural **out);

/* The k-NN form's candidates of vertex v (tree position v of the tree it
 * was made from): its JF_NATURAL_CAND nearest other vertices by
 * (distance, input index) into pos; their count (fewer: the whole
 * cloud), or SIZE_MAX if the query failed.  scan (may be NULL): what
 * the search read, for the cell's rim. */
#define JF_NATURAL_CAND 16
size_t jf__natural_query(const jf_natural *nt, size_t v, uint32_t pos[JF_NATURAL_CAND],
                         jf__kd_scan *scan);

/* Own-plane rows of the k-NN form (docs/natural.md, "Own-plane rings"):
 * each vertex's planar cell in its own tangent plane, made once, so that
 * a ring grows from stored rows instead of one clipped cell per ring
 * vertex.  jf__natural_rows_alloc makes the table for the normals nrm
 * (by input index, borrowed: they must outlive the rows' use; rows
 * undefined: a pass must fill every one before a ring reads them);
 * jf__natural_own_row fills vertex v's from its plane normal nrm (of its
 * input point) and its candidates c[0..cnt) (jf__natural_query's, with
 * its scan or NULL; a zero or non-finite normal or more than the row's
 * room leaves it LIVE: that cell is made when a ring asks for it, in its
 * own plane, or in the asking point's if it has none);
 * jf__natural_own_rows does both for every vertex, normals nrm[3n] by
 * input index. */
jf_status jf__natural_rows_alloc(jf_natural *nt, const double *nrm);
int jf__natural_own_row(jf_natural_ws *ws, size_t v, const double nrm[3], const uint32_t *c,
                        size_t cnt, const jf__kd_scan *scan);
jf_status jf__natural_own_rows(jf_natural *nt, int threads, const double *nrm);

/* jf_natural_neighbors of input point i over the own-plane rows where
 * they are made (every ring from its vertices' rows: the plane is each
 * vertex's own, i's normal nrm for its own cell when its row is LIVE;
 * a ring kept whole comes in row order -- a fit does not care -- the cut
 * one by (distance, coordinates); nrm is not checked: the caller's
 * planes are valid, and a LIVE row of i without one gets no
 * neighbours); without rows (the triangulation's form, no rows pass
 * yet), the same as jf_natural_neighbors.
 * idx may be NULL: the neighbours are then only ws's list (vertices;
 * jf__natural_coords reads them). */
jf_status jf__natural_neighbors_own(const jf_natural *nt, jf_natural_ws *ws, size_t i,
                                    const double nrm[3], size_t N, uint32_t *idx, size_t cap,
                                    size_t *found);

/* The k-d tree the k-NN form's vertices are positions of (NULL for the
 * triangulation form). */
const jf_index *jf__natural_index(const jf_natural *nt);

/* Asks the cache for what jf_natural_neighbors first reads of point i. */
void jf__natural_prefetch(const jf_natural *nt, size_t i);

/* After jf_natural_neighbors on ws (found points): their coordinates in
 * the structure's own copy (for the jet form, the points moved onto their
 * jets) to xyz[3 found]. */
void jf__natural_coords(const jf_natural_ws *ws, size_t found, double *xyz);

/* neighbors.c: jf_nb_query, and the coordinates of the neighbours to xyz
 * (3 * cap entries, caller-owned) unless NULL. */
jf_status jf__nb_query_xyz(const jf_index *ix, const jf_nb_spec *s, size_t min_count,
                           const double q[3], uint32_t *idx, double *d2, double *xyz,
                           size_t cap, size_t *found);

#endif /* JF_INDEX_INTERNAL_H */
