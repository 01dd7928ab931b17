/* cgal_bridge.h -- the C ABI of the CGAL bridge (C++17 inside).  Opaque
 * handles, plain arrays, integer status codes (jf_status values); every
 * entry point catches every exception.  No C++ type crosses. */
#ifndef JF_CGAL_BRIDGE_H
#define JF_CGAL_BRIDGE_H
#include <stddef.h>
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif

/* CGAL version the bridge was built with, e.g. "5.5.1". */
const char *jfb_cgal_version(void);

/* ---- 3D Delaunay triangulation of a cloud, flattened to plain arrays ----
 * (delaunay.cpp, star.cpp).  The bridge builds CGAL's
 * Delaunay_triangulation_3 (spatially sorted range insertion), copies out
 * what the C core needs and destroys the triangulation before returning,
 * so nothing C++ outlives the call.  Every array is malloc'd by the bridge
 * and released by jfb_delaunay_release(). */
typedef struct {
    int dimension;      /* of the triangulation: -1 (empty) .. 3; 2 means
                           every point is coplanar (flat), < 2 collinear */
    size_t n;           /* input points                                   */
    size_t nv;          /* vertices = distinct finite points              */
    size_t nduplicates; /* finite inputs merged into an identical point   */
    size_t nnonfinite;  /* inputs with a NaN/Inf coordinate (left out)    */
    uint32_t *vertex_of;/* [n] vertex of input i; UINT32_MAX: non-finite  */
    uint32_t *rep;      /* [nv] input index of the vertex (the smallest
                           index among identical points)                 */
    size_t *adj_off;    /* [nv+1] CSR offsets into adj                     */
    uint32_t *adj;      /* Delaunay neighbours (vertex ids) of each vertex,
                           nearest first (ties: lexicographic (x, y, z)
                           order of the points); dimension < 3: lexico-
                           graphic                                         */
    double *pole;       /* [3nv] vector from the sample to its pole (the
                           farthest Voronoi vertex of its cell; for a hull
                           sample the farthest one opposite `hull`); NaN
                           when there is none (dimension < 3)            */
    double *hull;       /* [3nv] hull samples: mean outer unit normal of the
                           incident hull facets (not normalised: its length
                           says how well they agree); 0 0 0 inside        */
    double seconds[3];  /* wall time of the spatial sort, the insertion and
                           the extraction (bench_natural's profile)      */
    double cpu_seconds[3]; /* the same in CPU time (process, all threads) */
} jfb_delaunay;

/* Builds the triangulation of the finite points of xyz[3n] and fills *out
 * (zeroed first).  Identical points are merged into one vertex.  The
 * insertion is sequential; the extraction of the arrays runs on `threads`
 * threads (< 1: one).  The triangulation is unique (CGAL's symbolic
 * perturbation) and every value is computed in the lexicographic order
 * of the points involved (star.cpp), so adjacency sets, their order,
 * poles and hull directions depend on the point set only: the same bit
 * for bit whatever the thread count or insertion order.  Vertex ids
 * follow the spatial sort (the same for any thread count).  Returns 0 or a
 * jf_status value (2 = no memory, 8 = CGAL threw); on failure *out holds
 * nothing to release.  Thread-safe (no shared state). */
int jfb_delaunay_build(const double *xyz, size_t n, int threads, jfb_delaunay *out);

/* Frees the arrays of a filled jfb_delaunay and zeroes it; NULL-safe. */
void jfb_delaunay_release(jfb_delaunay *d);

#ifdef __cplusplus
}
#endif
#endif
