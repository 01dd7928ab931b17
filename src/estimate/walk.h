/* walk.h -- the estimate's walk (walk.c): every point of a cloud fitted
 * once, by the threads, in the k-d tree's leaf order (or Z-order), the
 * rows going to out[] or to a sink; pipeline.c builds what it reads and
 * orients after it.  Internal to src/estimate. */
#ifndef JF_WALK_H
#define JF_WALK_H

#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"
#include "nbctx.h"
#include "parts.h" /* jf__block_xyz_fn */

/* Where results go: out[i] (jf_estimate), or blocks to a sink
 * (jf_estimate_blocks).  mst in block mode runs two passes: the first
 * keeps only the normals and statuses (vn, vs) and the graph, Prim
 * decides a flip per point (vf), the second fits again (the same bits:
 * each result depends only on its neighbourhood) and flips per block. */
typedef struct {
    const jf_cloud *c;
    const jf_estimate_opts *o;
    nbctx *x;
    const uint8_t *fit;   /* fit only where fit[i] (NULL: all; parts.h) */
    jf_result *out;
    jf_block_fn sink;
    jf__block_xyz_fn sinkx; /* instead of sink: the coordinates too  */
    void *user;
    int collect;          /* mst pass 1: fill vn, vs (and x->graph)    */
    double *vn;
    unsigned *vs;
    unsigned char *vf;    /* mst pass 2: flip flags (NULL otherwise)   */
    size_t done0, total;  /* progress: points done before this pass    */
} jf__runctx;

/* The caller's cancel hook (jetfit.h): polled on the calling thread only. */
static inline int jf__cancelled(const jf_estimate_opts *o)
{
    return o->cancel && o->cancel(o->cancel_user);
}

static inline jf_status jf__cancel_status(jf_error *err)
{
    jf__set_err(err, "cancelled");
    return JF_ERR_CANCELLED;
}

/* The rows of the non-finite points (not in the k-d tree, so not in its
 * walk), on the calling thread: to out, or in blocks to the sink. */
jf_status jf__walk_nonfinite(const jf__runctx *R, size_t n);

/* One pass of the fit over walk[0..nwalk-1] (coordinates from walk_xyz,
 * the tree's copy, when not NULL) on nt threads, auto's step 6 where
 * R->x->nj is set; a failure's line in err. */
jf_status jf__walk_pass(const jf__runctx *R, const uint32_t *walk, const double *walk_xyz, size_t nwalk,
                        int nt, jf_error *err);

#endif
