/* curve.c -- jets of plane curves (§4): y = f(x) = B0 + B1 x + ... + Bn x^n
 * fitted at p from 2D samples; normal, tangent, curvature and its
 * derivative along the arc.
 *
 * design: the surface pipeline one dimension down.  Translate to p; PCA of
 * the samples (two-pass centred covariance) gives the x axis (largest
 * variance: the tangent estimate, sign pinned to its largest-|component|
 * positive), y = x turned by +90 degrees; precondition with h = mean |x_i|
 * (§2.3); QR + SVD (solve.c); adaptive degree as for surfaces.  With
 * f' = B1, f'' = 2 B2, f''' = 6 B3 at x = 0:
 *   k     = f'' / (1 + f'^2)^(3/2)                        (§4)
 *   dk/ds = [f''' (1 + f'^2) - 3 f' f''^2] / (1 + f'^2)^3
 * (dk/dx divided by ds/dx = (1 + f'^2)^(1/2)), s increasing along the
 * reported tangent, k signed w.r.t. the reported normal (tangent turned by
 * +90 degrees: the fitting frame's +y side). */
#include <float.h>
#include <math.h>
#include <string.h>

#include "fitter_internal.h"

static void curve_nan(jf_curve_result *out)
{
    out->degree = 0;
    for (int k = 0; k <= JF_MAX_DEGREE; k++) out->coef[k] = NAN;
    out->normal[0] = out->normal[1] = out->tangent[0] = out->tangent[1] = NAN;
    out->k = out->dk = NAN;
}

jf_status jf_fit_curve(jf_fitter *f, const double p[2], const double *xy, size_t n,
                       int degree, jf_fit_mode mode, jf_curve_result *out)
{
    if (!f || !p || !out || (n > 0 && !xy)) return JF_ERR_INVALID;
    if (degree < 1 || degree > JF_MAX_DEGREE) return JF_ERR_INVALID;
    if (mode != JF_FIT_APPROX && mode != JF_FIT_INTERP) return JF_ERR_INVALID;
    if (n > f->maxn) return JF_ERR_TOO_LARGE;
    memset(out, 0, sizeof *out);
    out->cond = NAN;
    f->have_last = 0; /* the surface residuals are no longer the last fit */
    if (!isfinite(p[0]) || !isfinite(p[1])) {
        out->status = JF_PT_NONFINITE;
        curve_nan(out);
        return JF_OK;
    }
    /* translate; centroid and covariance in two passes */
    size_t usable = 0;
    double cx = 0, cy = 0;
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i] - p[0], y = xy[2 * i + 1] - p[1];
        if (!isfinite(x) || !isfinite(y)) continue;
        f->loc[2 * usable] = x;
        f->loc[2 * usable + 1] = y;
        cx += x;
        cy += y;
        usable++;
    }
    if (usable < 2) {
        out->status = JF_PT_LOWERED_FEW | JF_PT_FAILED;
        curve_nan(out);
        return JF_OK;
    }
    cx /= (double)usable;
    cy /= (double)usable;
    double sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < usable; i++) {
        double dx = f->loc[2 * i] - cx, dy = f->loc[2 * i + 1] - cy;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    /* major axis of [[sxx, sxy], [sxy, syy]] */
    const double th = 0.5 * atan2(2.0 * sxy, sxx - syy);
    double ex[2] = {cos(th), sin(th)};
    if (fabs(ex[1]) > fabs(ex[0]) ? ex[1] < 0 : ex[0] < 0) {
        ex[0] = -ex[0];
        ex[1] = -ex[1];
    }
    const double ey[2] = {-ex[1], ex[0]};
    for (size_t i = 0; i < usable; i++) {
        double x = f->loc[2 * i], y = f->loc[2 * i + 1];
        f->loc[2 * i] = ex[0] * x + ex[1] * y;
        f->loc[2 * i + 1] = ey[0] * x + ey[1] * y;
        f->dist[i] = x * x + y * y;
        f->order[i] = (uint32_t)i;
    }
    if (mode == JF_FIT_INTERP) /* nearest first, ties by index */
        for (size_t i = 1; i < usable; i++) {
            uint32_t o = f->order[i];
            size_t j = i;
            while (j > 0 && f->dist[f->order[j - 1]] > f->dist[o]) {
                f->order[j] = f->order[j - 1];
                j--;
            }
            f->order[j] = o;
        }

    int deg = 0;
    double h = 0;
    for (int d = degree; d >= 1; d--) {
        size_t cols = (size_t)d + 1;
        if (usable < cols) {
            out->status |= JF_PT_LOWERED_FEW;
            continue;
        }
        size_t rows = mode == JF_FIT_INTERP ? cols : usable;
        h = 0;
        for (size_t t = 0; t < rows; t++) h += fabs(f->loc[2 * f->order[t]]);
        h /= (double)rows;
        if (!(h > 0) || !isfinite(h)) {
            out->status |= JF_PT_LOWERED_RANK;
            out->cond = INFINITY;
            continue;
        }
        for (size_t t = 0; t < rows; t++) {
            const double xs = f->loc[2 * f->order[t]] / h;
            double pw = 1.0;
            for (size_t c = 0; c < cols; c++, pw *= xs) f->m[c * rows + t] = pw;
            f->rhs[t] = f->loc[2 * f->order[t] + 1];
        }
        int rc = jf__svd_solve(f, rows, cols, &out->cond);
        if (rc != 0) {
            out->status |= JF_PT_LOWERED_RANK;
            continue;
        }
        if (out->cond > f->p.max_cond) {
            out->status |= JF_PT_LOWERED_COND;
            continue;
        }
        deg = d;
        break;
    }
    if (deg == 0) {
        out->status |= JF_PT_FAILED;
        curve_nan(out);
        return JF_OK;
    }
    double hk = 1.0;
    for (int k = 0; k <= deg; k++, hk *= h) out->coef[k] = f->sol[k] / hk;
    out->degree = deg;
    const double b1 = out->coef[1], f2 = deg >= 2 ? 2.0 * out->coef[2] : NAN;
    const double f3 = deg >= 3 ? 6.0 * out->coef[3] : NAN;
    const double q = 1.0 + b1 * b1, sq = sqrt(q);
    const double tl[2] = {1.0 / sq, b1 / sq}, nl[2] = {-b1 / sq, 1.0 / sq};
    for (int i = 0; i < 2; i++) {
        out->tangent[i] = tl[0] * ex[i] + tl[1] * ey[i];
        out->normal[i] = nl[0] * ex[i] + nl[1] * ey[i];
    }
    out->k = f2 / (q * sq);
    out->dk = degree < 3 ? 0.0 : (f3 * q - 3.0 * b1 * f2 * f2) / (q * q * q);
    return JF_OK;
}
