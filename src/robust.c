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
 *  - scale selection (params.scales): intersection of confidence intervals
 *    (Lepski / Katkovnik's ICI rule) over the candidate K, smallest first:
 *    each fit's normal has a standard deviation computed from the noise
 *    estimate and the jet's normal matrix (normal_sd()); K grows while its
 *    normal agrees with every smaller K's within tau (sd_i + sd_j).  Noise
 *    alone keeps the normals within their intervals (large K wins); the
 *    truncation error of a too-large neighbourhood moves the normal out.
 *    tau = 1 chosen on PCPNet's armadillo (tests/bench_pcpnet.cpp).
 *
 *  - degree selection (params.degree_select): the same interval rule over
 *    the degree (fit_select()); lower-degree fitters live per thread.
 *
 *  - distance weights (params.dist_weight): Gaussian weights on the
 *    distance to p, combined with the IRLS weights; with degree selection
 *    the weighted fit heads the chain of candidates.
 *
 * No allocation per point: the residual/weight buffers live on the stack
 * up to STACK_N neighbours; above that, one heap buffer per thread (C11
 * tss, freed at thread exit) grown only when a larger n is first seen. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>

#include "jetfit.h"

#define STACK_N 512
#define NORMAL_TOL 1e-6 /* rad: IRLS stops when the normal moves less... */
#define CURV_TOL 1e-6   /* ...and |dk| * h does: both scale invariant     */
#define REL_TOL 0.1     /* or both move less than 10% of the noise scale  */

/* Width of the scale-selection confidence intervals, in standard
 * deviations (see jf_fit_point_full); chosen by measurement
 * (tests/bench_pcpnet.cpp, README). */
#ifndef JF_SCALE_TAU
#define JF_SCALE_TAU 1.0
#endif
#ifndef JF_SCALE_TARGET
#define JF_SCALE_TARGET 0.0
#endif
/* Degree selection: interval width in standard deviations (1; 0.5 and 2
 * were worse on PCPNet's armadillo overall), and the normal sd (radians)
 * below which the top degree is kept without trying lower ones (0.15:
 * clean K=18 d3 6.22 -> 6.17 deg, noise 0.00125 K=112 d3 15.05 -> 14.81,
 * other cells within 0.07; bench_pcpnet --same-points --dsdmin). */
#ifndef JF_DEGREE_TAU
#define JF_DEGREE_TAU 1.0
#endif
#ifndef JF_DEGREE_SDMIN
#define JF_DEGREE_SDMIN 0.15
#endif

static double degree_tau = JF_DEGREE_TAU;
static double degree_sdmin = JF_DEGREE_SDMIN;

/* ---- per-thread state: fallback buffer for n > STACK_N, and the fitters
 * of the lower degrees tried by degree selection (created on first use,
 * kept for the thread's life; recreated only if the caller's parameters
 * other than the degree change) ---- */
typedef struct {
    double *buf;
    size_t cap;
    jf_fitter *fit[JF_MAX_DEGREE + 1]; /* fit[d]: a fitter of degree d */
    jf_params key;                     /* the parameters they were made from */
} tl_state;

static tss_t tl_key;
static once_flag tl_once = ONCE_FLAG_INIT;
static int tl_ok;

static void tl_free(void *p)
{
    tl_state *b = p;
    if (b) {
        free(b->buf);
        for (int d = 0; d <= JF_MAX_DEGREE; d++) jf_fitter_free(b->fit[d]);
    }
    free(b);
}

static void tl_init(void) { tl_ok = tss_create(&tl_key, tl_free) == thrd_success; }

static tl_state *tl_state_get(void)
{
    call_once(&tl_once, tl_init);
    if (!tl_ok) return NULL;
    tl_state *b = tss_get(tl_key);
    if (!b) {
        if (!(b = calloc(1, sizeof *b))) return NULL;
        if (tss_set(tl_key, b) != thrd_success) {
            free(b);
            return NULL;
        }
    }
    return b;
}

static double *tl_get(size_t need)
{
    tl_state *b = tl_state_get();
    if (!b) return NULL;
    if (b->cap < need) {
        double *nb = realloc(b->buf, need * sizeof *nb);
        if (!nb) return NULL;
        b->buf = nb;
        b->cap = need;
    }
    return b->buf;
}

/* A fitter of degree d with pr's other fitting parameters (frame, mode,
 * max_cond, max_neighbors; monge_degree clamped to what d allows). */
static jf_fitter *tl_fitter(const jf_params *pr, int d)
{
    tl_state *b = tl_state_get();
    if (!b) return NULL;
    const jf_params *k = &b->key;
    if (k->fit != pr->fit || k->frame != pr->frame || k->max_cond != pr->max_cond ||
        k->max_neighbors != pr->max_neighbors || k->monge_degree != pr->monge_degree) {
        for (int i = 0; i <= JF_MAX_DEGREE; i++) {
            jf_fitter_free(b->fit[i]);
            b->fit[i] = NULL;
        }
        b->key = *pr;
    }
    if (!b->fit[d]) {
        jf_params q = *pr;
        q.degree = d;
        if (q.monge_degree > (d < 2 ? 2 : d)) q.monge_degree = d < 2 ? 2 : d;
        q.robust = JF_ROBUST_NONE;
        q.nscales = 0;
        q.degree_select = 0;
        if (jf_fitter_create(&q, &b->fit[d]) != JF_OK) b->fit[d] = NULL;
    }
    return b->fit[d];
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
 * buf holds 4n doubles.  *sigma: the noise scale of the final fit (robust:
 * the MAD of the residuals; else the RMS residual). */
static jf_status fit_robust(jf_fitter *f, const jf_params *pr, const double p[3],
                            const double *nbr, size_t n, double *buf, double dist_c,
                            jf_result *out, double *sigma, double *neff)
{
    double *res = buf, *tmp = buf + n, *w = buf + 2 * n, *wd = NULL;
    jf_status st;
    *neff = (double)n;
    if (dist_c > 0.0 && n > 0) { /* Gaussian weights on the distance to p */
        wd = buf + 3 * n;
        double r2max = 0.0;
        for (size_t i = 0; i < n; i++) {
            const double *q = nbr + 3 * i;
            double d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                        (q[2] - p[2]) * (q[2] - p[2]);
            wd[i] = isfinite(d2) ? d2 : 0.0;
            if (wd[i] > r2max) r2max = wd[i];
        }
        double s2 = dist_c * dist_c * r2max;
        double sw = 0.0, sww = 0.0;
        for (size_t i = 0; i < n; i++) {
            wd[i] = s2 > 0.0 ? exp(-0.5 * wd[i] / s2) : 1.0;
            w[i] = sqrt(wd[i]);
            sw += wd[i];
            sww += wd[i] * wd[i];
        }
        *neff = sww > 0.0 ? sw * sw / sww : (double)n; /* Kish's effective size */
        st = jf_fit_point_weighted(f, p, nbr, w, n, out);
    } else
        st = jf_fit_point(f, p, nbr, n, out);
    *sigma = out->residual;
    if (st != JF_OK || pr->robust == JF_ROBUST_NONE || !usable(out)) return st;

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
            w[i] = sqrt(wd ? wi * wd[i] : wi);
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

/* Standard deviation (radians) of the normal of a least-squares jet fit of
 * degree d to n points with noise sigma along the normal: the slope
 * (A_10, A_01) has covariance sigma^2 [(M^T M)^-1] restricted to the two
 * linear columns (M: the Vandermonde matrix of §2, eq. 7).  M^T M is built
 * in the result's tangent frame (the fit's frame up to a rotation about
 * the normal, which leaves the trace used here unchanged), preconditioned
 * by h (§2.3), and inverted by Cholesky.  s2: the noise variance, e.g. the
 * unbiased residual variance (unbiased_var()).  INFINITY when undefined. */
static double scale_floor = 0.3; /* sqrt(s2)/h above which sd >= sqrt(s2)/h */
#define SD_MAXN 15 /* degree <= 4: N_4 = 15; higher degrees use degree 4 */
static double normal_sd(const jf_result *r, double s2, const double p[3],
                        const double *nbr, size_t n)
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
     * by about sigma / h whatever n is. */
    double sd = sqrt(s2 * var) / h, fl = sqrt(s2) / h;
    return fl > scale_floor && fl > sd ? fl : sd;
}

/* Unbiased residual variance of a fit of r->degree to n points whose RMS
 * (or MAD) residual is sigma: n residuals, N_d coefficients. */
static double unbiased_var(const jf_result *r, double sigma, size_t n)
{
    size_t nfit = jf_jet_size(r->degree);
    return n > nfit ? sigma * sigma * (double)n / (double)(n - nfit) : INFINITY;
}

static double angle(const double a[3], const double b[3])
{
    double d = fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
    return acos(d > 1.0 ? 1.0 : d);
}

static double scale_tau = JF_SCALE_TAU;
static double scale_target = JF_SCALE_TARGET;

/* Bench-only setter of the tuning constants above (tests/bench_pcpnet.cpp
 * measures them); not in jetfit.h, not thread-safe: call before fitting.
 * name: "scale_tau", "scale_target", "scale_floor" or "degree_tau".
 * Returns 0, or -1 for an unknown name. */
int jf__robust_tune(const char *name, double v);
int jf__robust_tune(const char *name, double v)
{
    if (!strcmp(name, "scale_tau")) scale_tau = v;
    else if (!strcmp(name, "scale_target")) scale_target = v;
    else if (!strcmp(name, "scale_floor")) scale_floor = v;
    else if (!strcmp(name, "degree_tau")) degree_tau = v;
    else if (!strcmp(name, "degree_sdmin")) degree_sdmin = v;
    else return -1;
    return 0;
}
/* A normal whose standard deviation exceeds this (radians) is noise: it
 * cannot reveal a bias, so it takes no part in the interval test. */
#define SD_MEANINGFUL 0.3

/* Degree selection (params.degree_select = dmin): the same interval logic
 * over the degree instead of K.  The top degree D has the least bias and
 * the most variance; degree d < D is accepted while its normal lies within
 * tau (sd_d + sd_j) of the normal of every higher accepted degree j, and
 * the lowest accepted degree is kept.  All sd use the noise variance of
 * the degree-D fit (its residual is the least inflated by truncation
 * error).  Noise on a small neighbourhood makes sd_D large, so the plane
 * or quadric wins; on clean data sd_D is tiny and any bias of a lower
 * degree rejects it.  *sigma: the noise scale of the returned fit. */
static jf_status fit_select(jf_fitter *f, const jf_params *pr, const double p[3],
                            const double *nbr, size_t n, double *buf, jf_result *out,
                            double *sigma)
{
    double neff, dw = pr->dist_weight;
    if (pr->degree_select <= 0 || pr->fit != JF_FIT_APPROX)
        return fit_robust(f, pr, p, nbr, n, buf, dw, out, sigma, &neff);
    /* The chain, least bias first: [distance-weighted degree D,] degree D,
     * D - 1, ..., degree_select. */
    jf_result top;
    double sg;
    jf_status st = fit_robust(f, pr, p, nbr, n, buf, 0.0, &top, &sg, &neff);
    if (st != JF_OK || !usable(&top)) {
        *out = top;
        *sigma = sg;
        return st;
    }
    double s2 = unbiased_var(&top, sg, n);
    double nrm[JF_MAX_DEGREE + 2][3], sd[JF_MAX_DEGREE + 2];
    int acc = 0;
    double sd_top = normal_sd(&top, s2, p, nbr, n);
    if (dw > 0.0) {
        jf_result rw;
        double sgw;
        if ((st = fit_robust(f, pr, p, nbr, n, buf, dw, &rw, &sgw, &neff)) != JF_OK) return st;
        if (usable(&rw) && rw.degree == top.degree) {
            memcpy(nrm[acc], rw.normal, sizeof nrm[acc]);
            /* weighted least squares: the variance grows by n / n_eff */
            sd[acc++] = sd_top * sqrt((double)n / (neff > 1.0 ? neff : 1.0));
            *out = rw;
            *sigma = sgw;
            if (!(sd_top >= degree_sdmin)) return JF_OK; /* precise enough */
            if (!isfinite(s2) || !(angle(top.normal, rw.normal) <= degree_tau * (sd[0] + sd_top)))
                return JF_OK;
        }
    }
    memcpy(nrm[acc], top.normal, sizeof nrm[acc]);
    sd[acc++] = sd_top;
    *out = top;
    *sigma = sg;
    if (!isfinite(s2) || top.degree <= pr->degree_select) return JF_OK;
    if (!(sd_top >= degree_sdmin)) return JF_OK; /* precise enough: keep D */
    for (int d = top.degree - 1; d >= pr->degree_select; d--) {
        jf_fitter *g = tl_fitter(pr, d);
        if (!g) return JF_ERR_NOMEM;
        jf_result r;
        if ((st = fit_robust(g, pr, p, nbr, n, buf, 0.0, &r, &sg, &neff)) != JF_OK) return st;
        if (!usable(&r)) break;
        double s = normal_sd(&r, s2, p, nbr, n);
        int ok = 1;
        for (int j = 0; j < acc && ok; j++) ok = angle(r.normal, nrm[j]) <= degree_tau * (s + sd[j]);
        if (!ok) break;
        memcpy(nrm[acc], r.normal, sizeof nrm[acc]);
        sd[acc++] = s;
        r.status |= top.status & JF_PT_FEW_NEIGHBORS;
        *out = r;
        *sigma = sg;
    }
    return JF_OK;
}

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

    double stackbuf[4 * STACK_N];
    double *buf = stackbuf;
    if (n > STACK_N && (pr->robust != JF_ROBUST_NONE || pr->dist_weight > 0.0) &&
        !(buf = tl_get(4 * n)))
        return JF_ERR_NOMEM;

    double sigma;
    if (pr->nscales <= 0) return fit_select(f, pr, p, nbr, n, buf, out, &sigma);

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
        jf_status st = fit_select(f, pr, p, nbr, ks[i], buf, &r, &sigma);
        if (st != JF_OK) return st;
        if (!usable(&r)) {
            if (best < 0) *out = r; /* nothing better yet: report this one */
            continue;
        }
        size_t used = r.n_used > 0 ? (size_t)r.n_used : ks[i];
        (void)used;
        double s = normal_sd(&r, unbiased_var(&r, sigma, ks[i]), p, nbr, ks[i]);
        int ok = 1;
        for (int j = 0; j < acc && ok; j++)
            ok = !(sd[j] < SD_MEANINGFUL) || angle(r.normal, nrm[j]) <= scale_tau * (s + sd[j]);
        if (!ok) break;
        memcpy(nrm[acc], r.normal, sizeof nrm[acc]);
        sd[acc++] = s;
        *out = r;
        best = i;
        if (s <= scale_target) break; /* precise enough: stop growing */
    }
    if (best >= 0 && best != nk - 1) out->status |= JF_PT_SCALE_SELECTED;
    return JF_OK;
}
