/* nbctx.h -- the neighbourhood of a point, whatever its kind (k-NN,
 * radius, rings, natural), as the estimate's walk asks for it
 * (src/estimate/nbctx.c; not part of the public API). */
#ifndef JF_NBCTX_H
#define JF_NBCTX_H

#include <math.h>
#include <stdint.h>

#include "index_internal.h"
#include "jetfit.h"
#include "neigh_jets.h"
#include "set_err.h" /* jf__set_err */

typedef struct {
    const jf_nb_spec *nb;
    const double *xyz;
    const jf_index *ix;
    jf_mesh *mesh;        /* rings                                     */
    jf_natural *nt;       /* natural                                   */
    double *nrm_own;      /* natural: normals we computed (3n)         */
    const double *nrm;    /* natural: the tangent-plane normals        */
    unsigned *nflags;     /* natural: JF_PT_NORMAL_* per point         */
    int fit_moved;        /* natural, noisy: fit the ring's points moved
                             onto their jets (nt's own coordinates)     */
    size_t min_count;     /* N_n of the asked degree                   */
    size_t want;          /* fewer found than this: FEW_NEIGHBORS      */
    size_t cap;           /* buffer size (largest neighbourhood)       */
    uint32_t *graph;      /* mst: the first gk neighbours of each point */
    size_t gk;
    jf_fit_mode fit;
    int plain;            /* jf_fit_point_full is jf_fit_point: pairs   */
    jf__njs *nj;          /* auto's step 6: each point's fit, compact,
                             by tree position (the walk's order: a unit's
                             records are neighbours in memory too)      */
    const double *pts;    /* the tree's copy of the points, by position */
} nbctx;

static inline int jf__finite3(const double *p)
{
    return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]);
}

/* Step 1 for natural[:N]: the cells' structure and the tangent-plane
 * normals into x (x->nt, nrm, nflags, fit_moved); the message in err. */
jf_status jf__nb_natural_setup(nbctx *x, const jf_cloud *c, jf_normal_source src, int nt,
                               const jf_params *prm, jf_error *err);

/* Neighbourhood of point i (at p) into idx[0..cap-1] and, for the k-d
 * tree's kinds (knn, radius), their coordinates from its own storage into
 * xyz (other kinds leave that to the caller); *flags gets per-point flags
 * (few neighbours, the natural normal's source, failure).  sh: auto's
 * shared search (pos: the tree positions); hint: knn's last neighbours. */
jf_status jf__nb_point(const nbctx *x, jf_natural_ws *ws, jf__knn_share *sh, size_t i,
                       const double *p, uint32_t *idx, uint32_t *pos, double *d2, double *xyz,
                       size_t *found, unsigned *flags, const double *hint, size_t hint_n);

#endif /* JF_NBCTX_H */
