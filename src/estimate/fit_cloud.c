/* fit_cloud.c -- jf_fit_cloud: every point of a cloud from CSR neighbour
 * lists, OpenMP over points with one fitter per thread.
 *
 * design: each point is independent and a fitter keeps no state between
 * fits, so results do not depend on the thread count or the schedule.
 * The neighbour coordinates are gathered into a per-thread buffer sized
 * once for the longest list.  Each point goes through jf_fit_point_full
 * (robust.c), so params.robust and params.scales are honoured; with
 * neither set it is jf_fit_point. */
#include <math.h>
#include <stdlib.h>

#include <omp.h>

#include "jetfit.h"

jf_status jf_fit_cloud(const jf_params *p, const double *xyz, size_t n,
                       const size_t *off, const uint32_t *idx, int threads,
                       jf_result *out)
{
    if (!p || (n > 0 && (!xyz || !off || !out))) return JF_ERR_INVALID;
    jf_status st = jf_params_validate(p, NULL);
    if (st != JF_OK) return st;
    if (n == 0) return JF_OK;
    if (off[0] != 0) return JF_ERR_INVALID;
    size_t longest = 0;
    for (size_t i = 0; i < n; i++) {
        if (off[i + 1] < off[i]) return JF_ERR_INVALID;
        size_t len = off[i + 1] - off[i];
        if (len > longest) longest = len;
    }
    if (off[n] > 0 && !idx) return JF_ERR_INVALID;
    for (size_t t = 0; t < off[n]; t++)
        if (idx[t] >= n) return JF_ERR_INVALID;
    /* the workspace must hold the longest list */
    jf_params q = *p;
    if (longest > q.max_neighbors) q.max_neighbors = longest;
    if (jf_params_validate(&q, NULL) != JF_OK) return JF_ERR_TOO_LARGE;
    int nth = threads > 0 ? threads : jf_default_threads(NULL);
    if ((size_t)nth > n) nth = (int)n;

    jf_status err = JF_OK;
#pragma omp parallel num_threads(nth)
    {
        jf_fitter *f = NULL;
        double *buf = malloc(3 * (longest ? longest : 1) * sizeof *buf);
        jf_status mine = buf ? jf_fitter_create(&q, &f) : JF_ERR_NOMEM;
        if (mine != JF_OK) {
#pragma omp critical(jf_fit_cloud_err)
            if (err == JF_OK) err = mine;
        }
        /* every thread must reach the barrier of the loop below */
#pragma omp barrier
        int ok = err == JF_OK;
#pragma omp for schedule(dynamic, 256)
        for (size_t i = 0; i < n; i++) {
            if (!ok) continue;
            const double *pi = xyz + 3 * i;
            size_t k = 0;
            for (size_t t = off[i]; t < off[i + 1]; t++) {
                const double *q = xyz + 3 * (size_t)idx[t];
                buf[3 * k] = q[0];
                buf[3 * k + 1] = q[1];
                buf[3 * k + 2] = q[2];
                k++;
            }
            jf_status s = jf_fit_point_full(f, pi, buf, k, out + i);
            if (s != JF_OK) {
#pragma omp critical(jf_fit_cloud_err)
                if (err == JF_OK) err = s;
            }
        }
        jf_fitter_free(f);
        free(buf);
    }
    return err;
}
