/* select.c -- the uncertainty of a fitted normal, and degree selection
 * (params.degree_select): per point, the lowest degree whose normal agrees
 * with every higher degree's within their confidence intervals. */
#include <math.h>
#include <string.h>

#include "robust_internal.h"

/* Standard deviation (radians) of the normal of a least-squares jet fit of
 * degree d to n points with noise sigma along the normal: the slope
 * (A_10, A_01) has covariance sigma^2 [(M^T M)^-1] restricted to the two
 * linear columns (M: the Vandermonde matrix of §2, eq. 7).  M^T M is built
 * in the result's tangent frame (the fit's frame up to a rotation about
 * the normal, which leaves the trace used here unchanged), preconditioned
 * by h (§2.3), and inverted by Cholesky.  s2: the noise variance, e.g. the
 * unbiased residual variance (unbiased_var()).  INFINITY when undefined. */
#define SD_MAXN 15 /* degree <= 4: N_4 = 15; higher degrees use degree 4 */
static double normal_sd(const jf__knobs *kn, const jf_result *r, double s2, const double p[3], const double *nbr,
                        size_t n, double floor_n)
{
    int d = r->degree < 4 ? r->degree : 4;
    size_t nn = jf_jet_size(d), nfit = jf_jet_size(r->degree);
    if (n <= nfit || !isfinite(s2)) return INFINITY;
    double h = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *q = nbr + 3 * i;
        double v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        h += hypot(v[0] * r->d1[0] + v[1] * r->d1[1] + v[2] * r->d1[2],
                   v[0] * r->d2[0] + v[1] * r->d2[1] + v[2] * r->d2[2]);
    }
    h /= (double)n;
    if (!(h > 0.0) || !isfinite(h)) return INFINITY;
    double g[SD_MAXN * SD_MAXN] = {0}, mon[SD_MAXN];
    for (size_t i = 0; i < n; i++) {
        const double *q = nbr + 3 * i;
        double v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double x = (v[0] * r->d1[0] + v[1] * r->d1[1] + v[2] * r->d1[2]) / h;
        double y = (v[0] * r->d2[0] + v[1] * r->d2[1] + v[2] * r->d2[2]) / h;
        if (!isfinite(x) || !isfinite(y)) continue;
        size_t c = 0; /* monomials x^(k-j) y^j, k = 0..d, as the core orders them */
        for (int k = 0; k <= d; k++)
            for (int j = 0; j <= k; j++) mon[c++] = pow(x, k - j) * pow(y, j);
        for (size_t a = 0; a < nn; a++)
            for (size_t b = 0; b <= a; b++) g[a * nn + b] += mon[a] * mon[b];
    }
    /* Cholesky G = L L^T in the lower triangle */
    for (size_t j = 0; j < nn; j++) {
        double sum = g[j * nn + j];
        for (size_t k = 0; k < j; k++) sum -= g[j * nn + k] * g[j * nn + k];
        if (!(sum > 1e-14 * (double)n)) return INFINITY; /* (near) singular */
        g[j * nn + j] = sqrt(sum);
        for (size_t i = j + 1; i < nn; i++) {
            double t = g[i * nn + j];
            for (size_t k = 0; k < j; k++) t -= g[i * nn + k] * g[j * nn + k];
            g[i * nn + j] = t / g[j * nn + j];
        }
    }
    /* [G^-1]_cc = |L^-1 e_c|^2 for the linear columns c = 1 (x), 2 (y) */
    double var = 0.0;
    for (size_t c = 1; c <= 2; c++) {
        double z[SD_MAXN] = {0};
        for (size_t i = c; i < nn; i++) { /* forward substitution, L z = e_c */
            double t = i == c ? 1.0 : 0.0;
            for (size_t k = c; k < i; k++) t -= g[i * nn + k] * z[k];
            z[i] = t / g[i * nn + i];
        }
        for (size_t i = c; i < nn; i++) var += z[i] * z[i];
    }
    /* Floor: when the residual is a sizeable fraction of the radius the
     * neighbourhood is a blob of noise whose PCA frame follows the noise
     * and whose residual underestimates it; its normal is then uncertain
     * by about sigma / h whatever n is.  floor_n > 0 (degree selection)
     * shrinks that floor like 1/sqrt(n) above floor_n points: with
     * hundreds of points the frame's wobble averages out, and a floor
     * equal for every degree would always hand large noisy neighbourhoods
     * to the plane, whose bias there exceeds the quadric's. */
    double sd = sqrt(s2 * var) / h, fl = sqrt(s2) / h, f2 = fl;
    if (floor_n > 0.0 && (double)n > floor_n) f2 = fl * sqrt(floor_n / (double)n);
    return fl > kn->scale_floor && f2 > sd ? f2 : sd;
}

double jf__normal_sd(const jf__knobs *kn, const jf_result *r, double s2, const double p[3], const double *nbr,
                     size_t n)
{
    return normal_sd(kn, r, s2, p, nbr, n, 0.0);
}

/* The sd used by degree selection: the floor shrinks with n. */
static double select_sd(const jf__knobs *kn, const jf_result *r, double s2, const double p[3], const double *nbr,
                        size_t n)
{
    return normal_sd(kn, r, s2, p, nbr, n, kn->degree_floor_n);
}

/* Unbiased residual variance of a fit of r->degree to n points whose RMS
 * (or MAD) residual is sigma: n residuals, N_d coefficients. */
double jf__unbiased_var(const jf_result *r, double sigma, size_t n)
{
    size_t nfit = jf_jet_size(r->degree);
    return n > nfit ? sigma * sigma * (double)n / (double)(n - nfit) : INFINITY;
}

double jf__angle(const double a[3], const double b[3])
{
    double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
    return acos(d > 1.0 ? 1.0 : d);
}

/* Degree selection (params.degree_select = dmin): an interval rule
 * over the degree.  The top degree D has the least bias and
 * the most variance; degree d < D is accepted while its normal lies within
 * tau (sd_d + sd_j) of the normal of every higher accepted degree j, and
 * the lowest accepted degree is kept.  All sd use the noise variance of
 * the degree-D fit (its residual is the least inflated by truncation
 * error).  Noise on a small neighbourhood makes sd_D large, so the plane
 * or quadric wins; on clean data sd_D is tiny and any bias of a lower
 * degree rejects it.  The sd here (select_sd) shrinks the blob floor with
 * n, so that a large noisy neighbourhood, whose normal is precise, keeps
 * its (weighted) top degree instead of the plane, whose bias there
 * (creases, thin parts) exceeds the top degree's variance: PCPNet's
 * armadillo at K = 450 with noise 0.006, 26.33 -> 25.58 deg at degree 3.
 * *sigma: the noise scale of the returned fit. */
jf_status jf__fit_select(jf_fitter *f, const jf_params *pr, const double p[3],
                         const double *nbr, size_t n, double *buf, jf_result *out,
                         double *sigma)
{
    double neff, dw = pr->dist_weight;
    if (pr->degree_select <= 0 || pr->fit != JF_FIT_APPROX)
        return jf__fit_robust(f, pr, p, nbr, n, buf, dw, out, sigma, &neff);
    /* The chain, least bias first: [distance-weighted degree D,] degree D,
     * D - 1, ..., degree_select. */
    const jf__knobs *kn = jf__knobs_of(f);
    jf_result top;
    double sg;
    jf_status st = jf__fit_robust(f, pr, p, nbr, n, buf, 0.0, &top, &sg, &neff);
    if (st != JF_OK || !jf__usable(&top)) {
        *out = top;
        *sigma = sg;
        return st;
    }
    double s2 = jf__unbiased_var(&top, sg, n);
    double nrm[JF_MAX_DEGREE + 2][3], sd[JF_MAX_DEGREE + 2];
    int acc = 0;
    double sd_top = select_sd(kn, &top, s2, p, nbr, n);
    if (dw > 0.0) {
        jf_result rw;
        double sgw;
        if ((st = jf__fit_robust(f, pr, p, nbr, n, buf, dw, &rw, &sgw, &neff)) != JF_OK) return st;
        if (jf__usable(&rw) && rw.degree == top.degree) {
            memcpy(nrm[acc], rw.normal, sizeof nrm[acc]);
            /* weighted least squares: the variance grows by n / n_eff */
            sd[acc++] = sd_top * sqrt((double)n / (neff > 1.0 ? neff : 1.0));
            *out = rw;
            *sigma = sgw;
            if (!(sd_top >= kn->degree_sdmin)) return JF_OK; /* precise enough */
            if (!isfinite(s2) || !(jf__angle(top.normal, rw.normal) <= kn->degree_tau * (sd[0] + sd_top)))
                return JF_OK;
        }
    }
    memcpy(nrm[acc], top.normal, sizeof nrm[acc]);
    sd[acc++] = sd_top;
    *out = top;
    *sigma = sg;
    if (!isfinite(s2) || top.degree <= pr->degree_select) return JF_OK;
    if (!(sd_top >= kn->degree_sdmin)) return JF_OK; /* precise enough: keep D */
    for (int d = top.degree - 1; d >= pr->degree_select; d--) {
        jf_fitter *g = jf__ws_fitter(f, pr, d);
        if (!g) return JF_ERR_NOMEM;
        jf_result r;
        if ((st = jf__fit_robust(g, pr, p, nbr, n, buf, 0.0, &r, &sg, &neff)) != JF_OK) return st;
        if (!jf__usable(&r)) break;
        double s = select_sd(kn, &r, s2, p, nbr, n);
        int ok = 1;
        for (int j = 0; j < acc && ok; j++) ok = jf__angle(r.normal, nrm[j]) <= kn->degree_tau * (s + sd[j]);
        if (!ok) break;
        memcpy(nrm[acc], r.normal, sizeof nrm[acc]);
        sd[acc++] = s;
        r.status |= top.status & JF_PT_FEW_NEIGHBORS;
        *out = r;
        *sigma = sg;
    }
    return JF_OK;
}
