/* robust.c -- jf_fit_point_full: the per-point fit of the command, adding
 * to the plain jet fit (§2-§3) two options the paper leaves open:
 *
 *  - robust reweighting (params.robust): iteratively reweighted least
 *    squares on the height residuals of the fit.  Scale s = 1.4826 *
 *    median|r| (the MAD, consistent for Gaussian noise); Huber weights
 *    (c = 1.345 s) or Tukey's biweight (c = 4.685 s), the usual 95%
 *    efficiency constants.  Tukey starts with Huber steps: the biweight
 *    is not convex and needs a good start.  p stays the origin, but the
 *    jet's constant term A_00 (approximation mode) lets the fitted surface
 *    pass away from a corrupted p, so p's own equation is downweighted like
 *    any other; the quantities are those of the jet at (0, 0, A_00).
 *
 *  - scale selection (params.scales): for each candidate K (the first K
 *    neighbours, sorted nearest first) fit and estimate the normal error as
 *    variance + bias (see score()); keep the K of least estimated error.
 *
 * No allocation per point: the residual/weight buffers live on the stack
 * up to STACK_N neighbours; above that, one heap buffer per thread (C11
 * tss, freed at thread exit) grown only when a larger n is first seen. */
#include <math.h>
#ifdef JF_ROBUST_DEBUG
#include <stdio.h>
#endif
#include <stdlib.h>
#include <string.h>
#include <threads.h>

#include "jetfit.h"

#define STACK_N 512
#define NORMAL_TOL 1e-6 /* rad: IRLS stops when the normal moves less... */
#define CURV_TOL 1e-6   /* ...and |dk| * h does: both scale invariant     */
#define REL_TOL 0.01    /* or both move less than 1% of the noise scale   */

/* Weight of the scale-selection variance term against the bias term
 * (score()); chosen by measurement (tests/bench_pcpnet.cpp, README). */
#ifndef JF_SCALE_VAR_WEIGHT
#define JF_SCALE_VAR_WEIGHT 1.0
#endif

/* ---- per-thread fallback buffer for n > STACK_N ---- */
typedef struct {
    double *buf;
    size_t cap;
} tl_buffer;

static tss_t tl_key;
static once_flag tl_once = ONCE_FLAG_INIT;
static int tl_ok;

static void tl_free(void *p)
{
    tl_buffer *b = p;
    if (b) free(b->buf);
    free(b);
}

static void tl_init(void) { tl_ok = tss_create(&tl_key, tl_free) == thrd_success; }

static double *tl_get(size_t need)
{
    call_once(&tl_once, tl_init);
    if (!tl_ok) return NULL;
    tl_buffer *b = tss_get(tl_key);
    if (!b) {
        if (!(b = calloc(1, sizeof *b))) return NULL;
        if (tss_set(tl_key, b) != thrd_success) {
            free(b);
            return NULL;
        }
    }
    if (b->cap < need) {
        double *nb = realloc(b->buf, need * sizeof *nb);
        if (!nb) return NULL;
        b->buf = nb;
        b->cap = need;
    }
    return b->buf;
}

/* ---- median of |r| by quickselect on a scratch copy ---- */
static double select_kth(double *a, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = a[lo + (hi - lo) / 2];
        size_t i = lo, j = hi;
        while (i <= j) {
            while (a[i] < pivot) i++;
            while (a[j] > pivot) j--;
            if (i <= j) {
                double t = a[i];
                a[i] = a[j];
                a[j] = t;
                i++;
                if (j == 0) break;
                j--;
            }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else return a[k];
    }
    return a[k];
}

static double mad_scale(const double *r, double *tmp, size_t nr)
{
    size_t n = 0; /* non-finite input points have NaN residuals: left out */
    for (size_t i = 0; i < nr; i++)
        if (isfinite(r[i])) tmp[n++] = fabs(r[i]);
    if (n == 0) return 0.0;
    double m = select_kth(tmp, n, n / 2);
    if (n % 2 == 0) { /* the lower middle is the max of the lower half */
        double lo = tmp[0];
        for (size_t i = 1; i < n / 2; i++)
            if (tmp[i] > lo) lo = tmp[i];
        m = 0.5 * (m + lo);
    }
    return 1.4826 * m;
}

/* Mean tangential distance of the first n neighbours from p: the paper's
 * preconditioning radius h (§2.3), recomputed from the result's normal. */
static double tangential_radius(const double p[3], const double *nbr, size_t n,
                                const double nrm[3])
{
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d[3] = {nbr[3 * i] - p[0], nbr[3 * i + 1] - p[1], nbr[3 * i + 2] - p[2]};
        double dn = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
        double t2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - dn * dn;
        sum += sqrt(t2 > 0.0 ? t2 : 0.0);
    }
    return n ? sum / (double)n : 0.0;
}

static int usable(const jf_result *r) { return !(r->status & (JF_PT_FAILED | JF_PT_NONFINITE)); }

/* One fit of the first n neighbours, reweighted when params ask for it.
 * buf holds 3n doubles.  *sigma: the noise scale of the final fit (robust:
 * the MAD of the residuals; else the RMS residual). */
static jf_status fit_robust(jf_fitter *f, const jf_params *pr, const double p[3],
                            const double *nbr, size_t n, double *buf,
                            jf_result *out, double *sigma)
{
    jf_status st = jf_fit_point(f, p, nbr, n, out);
    *sigma = out->residual;
    if (st != JF_OK || pr->robust == JF_ROBUST_NONE || !usable(out)) return st;

    double *res = buf, *tmp = buf + n, *w = buf + 2 * n;
    size_t need = jf_jet_size(out->degree) + 1;
    double h = tangential_radius(p, nbr, n, out->normal);
    int converged = 0;
    for (int it = 0; it < pr->robust_iters; it++) {
        if ((st = jf_fitter_residuals(f, res, n)) != JF_OK) return st;
        double s = mad_scale(res, tmp, n);
        *sigma = s;
        /* An exact fit of most points: nothing left to downweight. */
        if (!(s > 1e-12 * (h > 0.0 ? h : 1.0))) {
            converged = 1;
            break;
        }
        int tukey = pr->robust == JF_ROBUST_TUKEY && it >= 2;
        double c = (tukey ? 4.685 : 1.345) * s;
        size_t live = 0;
        for (size_t i = 0; i < n; i++) {
            double a = fabs(res[i]) / c, wi;
            if (!isfinite(a)) wi = 0.0; /* a non-finite input point */
            else if (tukey) wi = a < 1.0 ? (1.0 - a * a) * (1.0 - a * a) : 0.0;
            else wi = a <= 1.0 ? 1.0 : 1.0 / a;
            live += wi > 0.0;
            /* jf_fit_point_weighted multiplies each equation by its weight:
             * IRLS minimises sum w r^2, so the row factor is sqrt(w). */
            w[i] = sqrt(wi);
        }
        if (live < need) break; /* too few inliers left: keep the last fit */
        jf_result prev = *out;
        if ((st = jf_fit_point_weighted(f, p, nbr, w, n, out)) != JF_OK) return st;
        if (!usable(out)) { /* the reweighted system degenerated */
            *out = prev;
            break;
        }
        double dot = fabs(prev.normal[0] * out->normal[0] + prev.normal[1] * out->normal[1] +
                          prev.normal[2] * out->normal[2]);
        double ang = acos(dot > 1.0 ? 1.0 : dot);
        double dk = fabs(prev.k1 - out->k1) + fabs(prev.k2 - out->k2);
        int pt = pr->robust == JF_ROBUST_TUKEY && it < 2; /* Huber warm-up */
#ifdef JF_ROBUST_DEBUG
        fprintf(stderr, "it %d s %g ang %g dk*h %g live %zu/%zu\n", it, s, ang, dk * h, live, n);
#endif
        /* converged: the jet moved by a small fraction of the noise scale
         * over the neighbourhood (tilt ang * h, curvature dk h^2), or by a
         * negligible amount outright */
        if (!pt && ((ang * h <= REL_TOL * s && dk * h * h <= REL_TOL * s) ||
                    (ang < NORMAL_TOL && dk * h < CURV_TOL))) {
            converged = 1;
            break;
        }
    }
    if (!converged) out->status |= JF_PT_ROBUST_NOCONV;
    return JF_OK;
}

/* Estimated squared normal error of a fit of n points at radius h, from
 * the noise variance sigma0^2 (the least unbiased residual variance over
 * the candidates) and this fit's residual variance s2:
 *   variance: the slope of a least-squares jet has variance about
 *     sigma^2 / (sigma_min(M')^2 h^2) and sigma_max(M') ~ sqrt(n), so
 *     sigma0^2 kappa^2 / (n h^2)  (§2.3: kappa = sigma_max / sigma_min);
 *   bias: the residual variance above the noise is the truncation error
 *     of the jet, O(h^(n+1)), whose slope error is that over h. */
static double score(double sigma0_2, double s2, double cond, size_t n, double h)
{
    if (!(h > 0.0)) return INFINITY;
    double var = sigma0_2 * cond * cond / ((double)n * h * h);
    double bias = s2 > sigma0_2 ? (s2 - sigma0_2) / (h * h) : 0.0;
    return JF_SCALE_VAR_WEIGHT * var + bias;
}

jf_status jf_fit_point_full(jf_fitter *f, const double p[3], const double *nbr,
                            size_t n, jf_result *out)
{
    if (!f || !p || !out || (n && !nbr)) return JF_ERR_INVALID;
    const jf_params *pr = jf_fitter_params(f);
    if (pr->robust == JF_ROBUST_NONE && pr->nscales <= 0)
        return jf_fit_point(f, p, nbr, n, out);

    double stackbuf[3 * STACK_N];
    double *buf = stackbuf;
    if (n > STACK_N && pr->robust != JF_ROBUST_NONE && !(buf = tl_get(3 * n)))
        return JF_ERR_NOMEM;

    double sigma;
    if (pr->nscales <= 0) return fit_robust(f, pr, p, nbr, n, buf, out, &sigma);

    /* Candidate sizes: scales[] clamped to n, ascending, distinct. */
    size_t ks[8];
    int nk = 0;
    for (int i = 0; i < pr->nscales && i < 8; i++) {
        size_t k = pr->scales[i] < n ? pr->scales[i] : n;
        if (k > 0 && (nk == 0 || k > ks[nk - 1])) ks[nk++] = k;
    }
    if (nk == 0) return jf_fit_point(f, p, nbr, n, out);
    if (nk == 1) return fit_robust(f, pr, p, nbr, ks[0], buf, out, &sigma);

    jf_result res[8];
    double s2[8], h[8];
    double sigma0_2 = INFINITY;
    for (int i = 0; i < nk; i++) {
        jf_status st = fit_robust(f, pr, p, nbr, ks[i], buf, &res[i], &sigma);
        if (st != JF_OK) return st;
        h[i] = NAN;
        s2[i] = INFINITY;
        if (!usable(&res[i])) continue;
        size_t nn = jf_jet_size(res[i].degree);
        size_t used = res[i].n_used > 0 ? (size_t)res[i].n_used : ks[i];
        if (used <= nn) continue; /* interpolation: no residual to learn from */
        /* unbiased variance: n residuals, N_n coefficients */
        s2[i] = sigma * sigma * (double)used / (double)(used - nn);
        h[i] = tangential_radius(p, nbr, ks[i], res[i].normal);
        if (s2[i] < sigma0_2) sigma0_2 = s2[i];
    }
    int best = nk - 1;
    if (isfinite(sigma0_2)) {
        double bs = INFINITY;
        for (int i = 0; i < nk; i++) {
            if (!isfinite(s2[i])) continue;
            size_t used = res[i].n_used > 0 ? (size_t)res[i].n_used : ks[i];
            double sc = score(sigma0_2, s2[i], res[i].cond, used, h[i]);
            if (sc < bs) {
                bs = sc;
                best = i;
            }
        }
    } else {
        /* nothing scored: the largest candidate that fitted at all */
        while (best > 0 && !usable(&res[best])) best--;
    }
    *out = res[best];
    if (best != nk - 1) out->status |= JF_PT_SCALE_SELECTED;
    return JF_OK;
}
