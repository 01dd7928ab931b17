/* planes.c -- tangent planes and denoised positions for natural
 * neighbourhoods on noisy clouds (issue 15.1, docs/natural.md).
 *
 * design:
 *  - The natural neighbourhood of p is built in a plane H through p with
 *    power weights -h^2 (§5.1, natural.c): of the samples around p it
 *    prefers those nearest H.  On a noisy cloud that choice follows the
 *    noise: the ring favours samples on the side of H's tilt and flatter
 *    than the surface, so the fitted jet reproduces H's error instead of
 *    correcting it (measured: with the exact plane natural:N is as good as
 *    knn:N, with the pole plane 2-3.5x worse, with the jet plane of knn:N
 *    still 1.14x worse in the normal and 1.7x in k1 at N = 256).
 *  - So both the plane and the positions the rings are built on come from
 *    the jet of the N nearest points: the normal of that jet, and each
 *    sample moved to the jet's point above it (0, 0, A00 in the fitting
 *    frame).  The triangulation of the moved samples is that of a nearly
 *    clean surface, where natural neighbourhoods work as designed; the fit
 *    then uses the original samples of that ring.
 *  - One fitter and buffers per thread, made once; each result depends
 *    only on its own neighbourhood: any thread count gives the same bits.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "fitter_internal.h"
#include "jetfit.h"
#include "planes_internal.h"

jf_status jf__planes_knn_jet(const jf_index *ix, const double *xyz, size_t n, size_t k,
                             const jf_params *prm, int nt, double *nrm, double *proj,
                             unsigned *ok)
{
    if (!ix || !xyz || !nrm || !proj || !ok || !prm || k < 1) return JF_ERR_INVALID;
    jf_params p = *prm;
    if (p.max_neighbors < k) p.max_neighbors = k;
    jf_status failed = JF_OK;
#pragma omp parallel num_threads(nt)
    {
        jf_fitter *f = NULL;
        uint32_t *idx = malloc(k * sizeof *idx);
        double *pts = malloc(3 * k * sizeof *pts), *d2 = malloc(k * sizeof *d2);
        jf_status wst = jf_fitter_create(&p, &f);
        if (wst == JF_OK && (!idx || !pts || !d2)) wst = JF_ERR_NOMEM;
        if (wst != JF_OK) {
#pragma omp atomic write
            failed = wst;
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const double *q = xyz + 3 * i;
            double *o = nrm + 3 * i;
            size_t found = 0;
            jf_result r;
            ok[i] = 0;
            o[0] = o[1] = o[2] = NAN;
            memcpy(proj + 3 * i, q, sizeof(double[3]));
            if (wst != JF_OK || !isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
            if (jf_index_knn(ix, q, k, idx, d2, &found) != JF_OK) continue;
            for (size_t j = 0; j < found; j++)
                memcpy(pts + 3 * j, xyz + 3 * (size_t)idx[j], sizeof(double[3]));
            /* plain fit (no robust weights, no scale choice): only the
             * plane and the jet's point above q are used */
            if (jf_fit_point(f, q, pts, found, &r) != JF_OK || (r.status & JF_PT_FAILED)) continue;
            memcpy(o, r.normal, sizeof r.normal);
            /* the jet's point above q: frame row 3 is ez (world) */
            for (int c = 0; c < 3; c++) proj[3 * i + c] = q[c] + f->coef[0] * f->frame[6 + c];
            ok[i] = 1;
        }
        jf_fitter_free(f);
        free(idx);
        free(pts);
        free(d2);
    }
    return failed;
}
