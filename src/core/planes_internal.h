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

#endif
