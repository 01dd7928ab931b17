/* scale.c -- jf_fit_point_full: the per-point fit of the command, with
 * scale selection (params.scales) over the plain, reweighted
 * (robust.c) or degree-selected (select.c) fit. */
#include <math.h>
#include <string.h>

#include "robust_internal.h"

/* A normal whose standard deviation exceeds this (radians) is noise. */
#define SD_MEANINGFUL 0.3

/* Margin, in standard deviations of the difference, below which two
 * scales' normals count as agreeing (2: a 2-d Gaussian difference exceeds
 * it with probability e^-4 ~ 2%; 3 and 4 were worse on PCPNet's low-noise
 * cells and no better elsewhere). */
#define XS_TAU 2.0

/* Squared bias of fit r's normal, estimated from the fit `ref` one degree
 * higher on the same points (Theorem 3: its truncation error is an order
 * of h smaller).  Without bias the two differ by noise only, and as the
 * lower degree's estimate is the efficient one under the smaller model,
 * that difference has variance sd_ref^2 - sd_r^2 (Hausman); subtracting it
 * leaves an unbiased estimate of |bias|^2, clipped at 0. */
static double bias2(const jf_result *r, double sd_r, const jf_result *ref, double sd_ref)
{
    double a = jf__angle(r->normal, ref->normal);
    double b = a * a - (sd_ref * sd_ref - sd_r * sd_r);
    return b > 0.0 ? b : 0.0;
}

/* Scale selection by estimated mean squared error of the normal: at each
 * candidate K, the fit (plain, reweighted or degree-selected, as pr asks)
 * and a fit one degree higher on the same points.  The squared bias is the
 * larger of bias2() against the higher degree and, for a bias no
 * polynomial sees (a crease, a neighbourhood across a thin part), the
 * normal's excess move against each smaller K; the cost is that plus
 * varw * sd^2 (scale_varw = 2: the bias estimates are noisy and
 * clipped at 0, so the minimum favours lucky draws; weighting the variance
 * up counters it).  The least cost wins.  Noise makes sd fall with K
 * (large K on flat, noisy regions); curvature makes the bias grow as h^2
 * (a quadric's normal, Theorem 3), so curved regions keep a smaller K. */
jf_status jf_fit_point_full(jf_fitter *f, const double p[3], const double *nbr,
                            size_t n, jf_result *out)
{
    if (!f || !p || !out || (n && !nbr)) return JF_ERR_INVALID;
    const jf_params *pr = jf_fitter_params(f);
    if (pr->auto_select) return jf__fit_auto(f, pr, p, nbr, n, out);
    if (pr->robust == JF_ROBUST_NONE && pr->nscales <= 0 && pr->degree_select <= 0 &&
        !(pr->dist_weight > 0.0))
        return jf_fit_point(f, p, nbr, n, out);

    double stackbuf[4 * JF_STACK_N];
    double *buf = stackbuf;
    if (n > JF_STACK_N && (pr->robust != JF_ROBUST_NONE || pr->dist_weight > 0.0) &&
        !(buf = jf__ws_buf(f, 4 * n)))
        return JF_ERR_NOMEM;

    double sigma;
    if (pr->nscales <= 0) return jf__fit_select(f, pr, p, nbr, n, buf, out, &sigma);
    const jf__knobs *kn = jf__knobs_of(f);

    /* Candidate sizes: scales[] clamped to n, ascending, distinct. */
    size_t ks[8];
    int nk = 0;
    for (int i = 0; i < pr->nscales && i < 8; i++) {
        size_t k = pr->scales[i] < n ? pr->scales[i] : n;
        if (k > 0 && (nk == 0 || k > ks[nk - 1])) ks[nk++] = k;
    }
    if (nk == 0) return jf_fit_point(f, p, nbr, n, out);

    double nrm[8][3], sdv[8];
    int nacc = 0;
    int best = -1;
    double best_cost = INFINITY, s2n = NAN; /* s2n: noise variance, see below */
    for (int i = 0; i < nk; i++) {
        jf_result r, ref;
        double sg_ref, neff;
        jf_status st = jf__fit_select(f, pr, p, nbr, ks[i], buf, &r, &sigma);
        if (st != JF_OK) return st;
        if (!jf__usable(&r)) {
            if (best < 0) *out = r; /* nothing better yet: report this one */
            continue;
        }
        double b2 = 0.0;
        jf_fitter *g = r.degree < JF_MAX_DEGREE ? jf__ws_fitter(f, pr, r.degree + 1) : NULL;
        if (r.degree < JF_MAX_DEGREE && !g) return JF_ERR_NOMEM;
        if (g) {
            st = jf__fit_robust(g, pr, p, nbr, ks[i], buf, 0.0, &ref, &sg_ref, &neff);
            if (st != JF_OK) return st;
        }
        /* No usable higher-degree fit (too few points for it, or degree
         * 9): the bias is unknown and counted as 0. */
        int have_ref = g && jf__usable(&ref) && ref.degree == r.degree + 1;
        /* One noise variance for all K: the residual of the smallest K
         * (its higher-degree fit when that has >= 8 degrees of freedom),
         * the least inflated by truncation error, which larger K would
         * count as noise and so hide their own bias. */
        double s2 = s2n;
        if (!isfinite(s2)) {
            size_t nref = jf_jet_size(r.degree + 1);
            s2 = have_ref && ks[i] >= nref + 8 ? jf__unbiased_var(&ref, sg_ref, ks[i])
                                               : jf__unbiased_var(&r, sigma, ks[i]);
        }
        double sd = jf__normal_sd(kn, &r, s2, p, nbr, ks[i]);
        /* ...from the smallest K whose normal is not noise: a blob's
         * residual underestimates the noise (its frame follows it) */
        if (!isfinite(s2n) && sd < SD_MEANINGFUL) s2n = s2;
        if (have_ref) b2 = bias2(&r, sd, &ref, jf__normal_sd(kn, &ref, s2, p, nbr, ks[i]));
        /* Bias that a polynomial of any degree misses (a crease, a
         * neighbourhood reaching across a thin part) moves the normal with
         * K instead: the same estimate against each smaller K, whose
         * normal differs from this one by noise of variance sd_j^2 - sd^2
         * when neither is biased (Goldenshluger-Lepski). */
        for (int j = 0; j < nacc; j++) {
            if (!(sdv[j] < SD_MEANINGFUL)) continue; /* noise: shows no bias */
            double v = sdv[j] * sdv[j] - sd * sd;
            double b = jf__angle(nrm[j], r.normal) - XS_TAU * sqrt(v > 0.0 ? v : 0.0);
            if (b > 0.0 && b * b > b2) b2 = b * b;
        }
        memcpy(nrm[nacc], r.normal, sizeof nrm[nacc]);
        sdv[nacc++] = sd;
        /* A noise-dominated normal's sd (a linearisation) understates its
         * error: such K win only when no K is better than noise, and
         * then the largest does. */
        double cost = sd < SD_MEANINGFUL ? b2 + kn->scale_varw * sd * sd : INFINITY;
        if (best < 0 || cost < best_cost || (!isfinite(best_cost) && !isfinite(cost))) {
            best_cost = cost;
            *out = r;
            best = i;
        }
        if (sd <= kn->scale_target) break; /* precise enough: stop growing */
    }
    if (best >= 0 && best != nk - 1) out->status |= JF_PT_SCALE_SELECTED;
    return JF_OK;
}
