/* orient_internal.h -- orientation pieces for the streaming pipeline
 * (walk.c, for jf_estimate_blocks), not part of the public API. */
#ifndef JF_ORIENT_INTERNAL_H
#define JF_ORIENT_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

/* One result oriented along dir exactly as jf_orient_input / _viewpoint /
 * _scanner orient it: left alone if FAILED, NONFINITE or a non-finite
 * normal; flipped if n.dir < 0; JF_PT_ORIENT_UNKNOWN if n.dir is 0 or
 * NaN. */
void jf__orient_point(jf_result *r, const double dir[3]);

/* jf_orient_mst_graph on the normals (3n) and statuses (n) alone:
 * normals are negated in place, flip[i] (n, zeroed by the caller) toggles
 * with each negation of point i, and status[i] may gain
 * JF_PT_ORIENT_UNKNOWN.  Applying jf_result_flip to the results whose
 * flip[i] is 1 and OR-ing the new status bits gives what
 * jf_orient_mst_graph gives on the whole results. */
jf_status jf__orient_mst_view(double *nrm, unsigned *status, unsigned char *flip,
                              const double *xyz, size_t n, const uint32_t *nbr, size_t k);

#endif /* JF_ORIENT_INTERNAL_H */
