/* scale.c -- jf_fit_point_full: the per-point fit of the command, with
 * scale selection (params.scales) over the plain, reweighted
 * (robust.c) or degree-selected (select.c) fit. */
#include <math.h>
#include <string.h>

#include "robust_internal.h"

/* A normal whose standard deviation exceeds this (radians) is noise: it
 * cannot reveal a bias, so it takes no part in the interval test. */
#define SD_MEANINGFUL 0.3

/* Scale selection by the intersection of confidence intervals (Lepski's
 * method, as in Katkovnik's ICI rule): walk the candidates from the
 * smallest K up; K_i is accepted while its normal lies within
 * tau (sd_i + sd_j) of the normal of every smaller accepted K_j.  Noise
 * alone keeps the normals within their intervals, so the walk goes on to
 * large K (less variance); once the truncation error (bias, growing with
 * the radius) moves the normal out, the walk stops at the last K whose
 * normal agreed with all smaller ones.  The first failure ends the walk, so
 * clean, curved regions never pay for the large fits. */
jf_status jf_fit_point_full(jf_fitter *f, const double p[3], const double *nbr,
                            size_t n, jf_result *out)
{
    if (!f || !p || !out || (n && !nbr)) return JF_ERR_INVALID;
    const jf_params *pr = jf_fitter_params(f);
    if (pr->robust == JF_ROBUST_NONE && pr->nscales <= 0 && pr->degree_select <= 0 &&
        !(pr->dist_weight > 0.0))
        return jf_fit_point(f, p, nbr, n, out);

    double stackbuf[4 * JF_STACK_N];
    double *buf = stackbuf;
    if (n > JF_STACK_N && (pr->robust != JF_ROBUST_NONE || pr->dist_weight > 0.0) &&
        !(buf = jf__tl_buf(4 * n)))
        return JF_ERR_NOMEM;

    double sigma;
    if (pr->nscales <= 0) return jf__fit_select(f, pr, p, nbr, n, buf, out, &sigma);

    /* Candidate sizes: scales[] clamped to n, ascending, distinct. */
    size_t ks[8];
    int nk = 0;
    for (int i = 0; i < pr->nscales && i < 8; i++) {
        size_t k = pr->scales[i] < n ? pr->scales[i] : n;
        if (k > 0 && (nk == 0 || k > ks[nk - 1])) ks[nk++] = k;
    }
    if (nk == 0) return jf_fit_point(f, p, nbr, n, out);

    double nrm[8][3], sd[8];
    int acc = 0, best = -1;
    for (int i = 0; i < nk; i++) {
        jf_result r;
        jf_status st = jf__fit_select(f, pr, p, nbr, ks[i], buf, &r, &sigma);
        if (st != JF_OK) return st;
        if (!jf__usable(&r)) {
            if (best < 0) *out = r; /* nothing better yet: report this one */
            continue;
        }
        size_t used = r.n_used > 0 ? (size_t)r.n_used : ks[i];
        (void)used;
        double s = jf__normal_sd(&r, jf__unbiased_var(&r, sigma, ks[i]), p, nbr, ks[i]);
        int ok = 1;
        for (int j = 0; j < acc && ok; j++)
            ok = !(sd[j] < SD_MEANINGFUL) || jf__angle(r.normal, nrm[j]) <= jf__knob.scale_tau * (s + sd[j]);
        if (!ok) break;
        memcpy(nrm[acc], r.normal, sizeof nrm[acc]);
        sd[acc++] = s;
        *out = r;
        best = i;
        if (s <= jf__knob.scale_target) break; /* precise enough: stop growing */
    }
    if (best >= 0 && best != nk - 1) out->status |= JF_PT_SCALE_SELECTED;
    return JF_OK;
}
