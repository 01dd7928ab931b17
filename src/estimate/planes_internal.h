/* planes_internal.h -- tangent planes for natural neighbourhoods on noisy
 * clouds (planes.c; not part of the public API). */
#ifndef JF_PLANES_INTERNAL_H
#define JF_PLANES_INTERNAL_H

#include "jetfit.h"

/* For every point i of xyz[3n]: the plain jet fit (prm's degree, frame
 * and conditioning; no robust weights, no scale selection) of its k
 * nearest points in ix (built over xyz); nrm[3i] = its unit normal,
 * proj[3i] = the jet's point above xyz[3i], ok[i] = 1.  Where it fails
 * (non-finite point, too few points): ok[i] = 0, NaN normal, proj[3i] =
 * xyz[3i].  OpenMP on nt threads; output independent of nt.  Returns
 * JF_OK, JF_ERR_INVALID (NULL, k = 0), JF_ERR_NOMEM (a thread's
 * workspace). */
jf_status jf__planes_knn_jet(const jf_index *ix, const double *xyz, size_t n, size_t k,
                             const jf_params *prm, int nt, double *nrm, double *proj,
                             unsigned *ok);

/* The unit eigenvector of the smallest eigenvalue of a (3x3 symmetric
 * positive semi-definite, row-major) by power iteration on its
 * adjugate; 0 when that is not settled (zero or non-finite a, collinear
 * points, two smallest eigenvalues close): use jf__eig3 then. */
int jf__pca_smallest(const double a[9], double nrm[3]);

/* PCA planes (the default on a clean cloud; --normal pca): the smallest
 * eigenvector of the centred covariance of the 16 nearest points.
 * jf__planes_pca_one: point i's from a k-NN query in ix (over xyz);
 * returns 0 if there is none (non-finite point, fewer than 3 points, all
 * collinear).  jf__planes_pca_knn: every point's, from the k-NN form's
 * candidates of nt (the point and its 15 nearest others), by
 * jf__pca_smallest (jf__eig3 where it refuses, two in SIMD lanes when
 * both of a pair do); nrm[3i] = the normal or NaN, flags[i] |=
 * JF_PT_NORMAL_PCA or JF_PT_FAILED; and, from the same candidates, nt's
 * own-plane rows (jf__natural_own_row).  OpenMP on nt threads; returns
 * JF_ERR_NOMEM (rows, a thread's workspace) or JF_ERR_INTERNAL (a
 * failed query), as jf__natural_own_rows. */
int jf__planes_pca_one(const jf_index *ix, const double *xyz, size_t i, double nrm[3]);
jf_status jf__planes_pca_knn(jf_natural *ntl, size_t n, int nt, double *nrm, unsigned *flags);

#endif
