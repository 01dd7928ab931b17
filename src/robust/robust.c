/* robust.c -- robust reweighting (params.robust) of one jet fit, and the
 * fitter's state shared by the selection rules (select.c, scale.c).
 *
 * Iteratively reweighted least squares on the height residuals of the
 * fit.  Scale s = 1.4826 * median|r| (the MAD, consistent for Gaussian
 * noise); Huber weights (c = 1.345 s) or Tukey's biweight (c = 4.685 s),
 * the usual 95% efficiency constants.  Tukey starts with Huber steps: the
 * biweight is not convex and needs a good start.  p stays the origin, but
 * the jet's constant term A_00 (approximation mode) lets the fitted
 * surface pass away from a corrupted p, so p's own equation is
 * downweighted like any other; the quantities are those of the jet at
 * (0, 0, A_00).  Distance weights (params.dist_weight): Gaussian weights
 * on the distance to p, combined with the IRLS weights.
 *
 * No allocation per point: buffers live on the caller's stack up to
 * JF_STACK_N neighbours; above that, one heap buffer per fitter (the
 * caller's workspace: a fitter per thread) grown only when a larger n is
 * first seen, freed with the fitter. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fitter_internal.h"
#include "order_stat.h"
#include "robust_internal.h"

#define NORMAL_TOL 1e-6 /* rad: IRLS stops when the normal moves less... */
#define CURV_TOL 1e-6   /* ...and |dk| * h does: both scale invariant     */
#define REL_TOL 0.1     /* or both move less than 10% of the noise scale  */

/* Tuning constants of the selection rules (select.c, scale.c), one place
 * so that the bench-only setter below reaches them all. */
/* Scale selection's weight of the variance in its MSE estimate (scale.c:
 * 2, by measurement on the §6.1 surface; docs/robustness.md). */
#ifndef JF_SCALE_VARW
#define JF_SCALE_VARW 2.0
#endif
#ifndef JF_SCALE_TARGET
#define JF_SCALE_TARGET 0.0
#endif
/* Degree selection: interval width in standard deviations, the normal sd
 * (radians) below which the top degree is kept without trying lower ones,
 * and the size above which the blob floor of the sd (select.c) shrinks
 * like 1/sqrt(n).  Chosen together with --robust-normals' distance weight
 * (0.55) on PCPNet's armadillo, the one set of the sweep below CGAL's jet
 * in all 24 cells with the widest margin (1.5 / 0.2 / 50; the earlier
 * 1 / 0.15 / no shrink lost 2 cells by up to 0.44 deg; bench_pcpnet
 * --same-points --dtau --dsdmin --dfloorn, docs/robustness.md). */
#ifndef JF_DEGREE_TAU
#define JF_DEGREE_TAU 1.5
#endif
#ifndef JF_DEGREE_SDMIN
#define JF_DEGREE_SDMIN 0.2
#endif
#ifndef JF_DEGREE_FLOOR_N
#define JF_DEGREE_FLOOR_N 50.0
#endif

/* neighbors auto (auto.c): Lepski's threshold in sd (chosen on
 * tests/bench/study_auto.sh's data); a residual above auto_blob x the
 * radius is a blob of noise whose cubic follows the noise (the noise is
 * then read at a larger K); a normal whose sd exceeds auto_sdmax (rad) is
 * noise and stops no K; noise below auto_clean x the radius allows cubics
 * on 16-24 points; auto_gl 1 = Goldenshluger-Lepski over every (K, degree);
 * auto_nest T > 0: Lepski against T sqrt(sd_j^2 - sd_K^2), the sd of the
 * difference of nested least-squares normals (both worse on PCPNet:
 * docs/robustness.md "Neighbourhood auto"); auto_lof z > 0: a K whose
 * residual variance stays within 1 + z sqrt(2 / (K - 6)) of the noise's
 * passes Lepski's test; auto_s2floor c > 0: the noise variance at least
 * the cubic's at K = 48 where it exceeds (c x radius)^2 (auto_rule.c;
 * both off: docs/robustness.md); auto_flat z: the noise variance is the
 * cubic's at the largest K where that stays within 1 + z sqrt(2 / 38) of
 * the cubic's at K = 48 (auto.c step 2; 0: off); auto_dw C > 0: the
 * reported fit with Gaussian weights of width C x the K-th distance
 * (--dist-weight's; off: better at noise 0 and 0.125%, worse at 1.2%,
 * and still above the best fixed K at 0.125%: docs/robustness.md). */
const jf__knobs jf__knob_defaults = {
    JF_SCALE_VARW, JF_SCALE_TARGET, 0.3, JF_DEGREE_TAU, JF_DEGREE_SDMIN, JF_DEGREE_FLOOR_N,
    2.0, 0.2, 0.3, 0.05, 1.0, 0, 0.0, 0.0, 0.0, 2.0, 0.0, NULL};

/* ---- the fitter's robust state: fallback buffer for n > JF_STACK_N, and
 * the fitters of the lower degrees tried by degree selection (created on
 * first use, kept with the fitter; recreated only if the caller's
 * parameters other than the degree change) ---- */
typedef struct {
    double *buf;
    size_t cap;
    jf_fitter *fit[JF_MAX_DEGREE + 1]; /* fit[d]: a fitter of degree d */
    jf_params key;                     /* the parameters they were made from */
    jf__knobs knob;                    /* the selection rules' tuning */
} ws_state;

static void ws_free(void *p)
{
    ws_state *b = p;
    if (b) {
        free(b->buf);
        for (int d = 0; d <= JF_MAX_DEGREE; d++) jf_fitter_free(b->fit[d]);
    }
    free(b);
}

static ws_state *ws_get(jf_fitter *f)
{
    if (!f->ext) {
        ws_state *b = calloc(1, sizeof *b);
        if (!b) return NULL;
        b->knob = jf__knob_defaults;
        f->ext = b;
        f->ext_free = ws_free;
    }
    return f->ext;
}

const jf__knobs *jf__knobs_of(jf_fitter *f)
{
    ws_state *b = ws_get(f);
    return b ? &b->knob : &jf__knob_defaults;
}

/* Bench- and test-only (tests/bench/bench_pcpnet.cpp measures them): not
 * in jetfit.h. */
int jf__robust_tune(jf_fitter *f, const char *name, double v)
{
    ws_state *b = ws_get(f);
    if (!b) return -1;
    jf__knobs *k = &b->knob;
    if (!strcmp(name, "scale_varw")) k->scale_varw = v;
    else if (!strcmp(name, "scale_target")) k->scale_target = v;
    else if (!strcmp(name, "scale_floor")) k->scale_floor = v;
    else if (!strcmp(name, "degree_tau")) k->degree_tau = v;
    else if (!strcmp(name, "degree_sdmin")) k->degree_sdmin = v;
    else if (!strcmp(name, "degree_floor_n")) k->degree_floor_n = v;
    else if (!strcmp(name, "auto_tau")) k->auto_tau = v;
    else if (!strcmp(name, "auto_blob")) k->auto_blob = v;
    else if (!strcmp(name, "auto_sdmax")) k->auto_sdmax = v;
    else if (!strcmp(name, "auto_varw")) k->auto_varw = v;
    else if (!strcmp(name, "auto_clean")) k->auto_clean = v;
    else if (!strcmp(name, "auto_gl")) k->auto_gl = (int)v;
    else if (!strcmp(name, "auto_nest")) k->auto_nest = v;
    else if (!strcmp(name, "auto_lof")) k->auto_lof = v;
    else if (!strcmp(name, "auto_s2floor")) k->auto_s2floor = v;
    else if (!strcmp(name, "auto_flat")) k->auto_flat = v;
    else if (!strcmp(name, "auto_dw")) k->auto_dw = v;
    else return -1;
    return 0;
}

/* Bench-only: auto's candidates out (robust_internal.h). */
int jf__auto_diag_attach(jf_fitter *f, jf__auto_diag *dg)
{
    ws_state *b = ws_get(f);
    if (!b) return -1;
    b->knob.auto_diag = dg;
    return 0;
}

double *jf__ws_buf(jf_fitter *f, size_t need)
{
    ws_state *b = ws_get(f);
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
jf_fitter *jf__ws_fitter(jf_fitter *f, const jf_params *pr, int d)
{
    ws_state *b = ws_get(f);
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
static double mad_scale(const double *r, double *tmp, size_t nr)
{
    size_t n = 0; /* non-finite input points have NaN residuals: left out */
    for (size_t i = 0; i < nr; i++)
        if (isfinite(r[i])) tmp[n++] = fabs(r[i]);
    if (n == 0) return 0.0;
    jf__select_kth(tmp, n, n / 2);
    double m = tmp[n / 2];
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

int jf__usable(const jf_result *r) { return !(r->status & (JF_PT_FAILED | JF_PT_NONFINITE)); }

/* One fit of the first n neighbours, reweighted when params ask for it.
 * buf holds 4n doubles.  *sigma: the noise scale of the final fit (robust:
 * the MAD of the residuals; else the RMS residual). */
jf_status jf__fit_robust(jf_fitter *f, const jf_params *pr, const double p[3],
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
    if (st != JF_OK || pr->robust == JF_ROBUST_NONE || !jf__usable(out)) return st;

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
        if (!jf__usable(out)) { /* the reweighted system degenerated */
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
