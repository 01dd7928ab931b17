/* auto_direct.c -- neighbors auto, step 5 (auto.c's design block): the
 * reported jet of the chosen K and degree straight from its power sums in
 * the frame of its own points (§5.2), the numbers of knn:K --degree d up
 * to rounding (test_auto), without a second fit; the fitter's own jet
 * where those sums cannot serve. */
#include <math.h>
#include <string.h>

#include "auto_internal.h"

/* The jet of degree d on the first k points by the fitter itself (dw > 0:
 * with --dist-weight's Gaussian weights of width dw, the bench-only knob
 * auto_dw), flagged JF_PT_AUTO with the noise auto assumed. */
jf_status jf__auto_fit_by_fitter(jf_fitter *f, const jf_params *pr, int d, const double p[3],
                                 const double *nbr, size_t k, double sigma, double dw, jf_result *out)
{
    jf_fitter *g = jf__ws_fitter(f, pr, d);
    if (!g) return JF_ERR_NOMEM;
    jf_status st;
    if (dw > 0.0) {
        double *buf = jf__ws_buf(f, 4 * k), sg, ne;
        if (!buf) return JF_ERR_NOMEM;
        st = jf__fit_robust(g, pr, p, nbr, k, buf, dw, out, &sg, &ne);
    } else
        st = jf_fit_point(g, p, nbr, k, out);
    if (st != JF_OK) return st;
    /* b asked for but a quadric chosen: unknown, not 0 (jetfit.h) */
    if (pr->monge_degree >= 3 && out->degree < 3)
        for (int j = 0; j < 4; j++) out->b[j] = NAN;
    if (pr->monge_degree >= 4 && out->degree < 4)
        for (int j = 0; j < 5; j++) out->c[j] = NAN;
    out->status |= JF_PT_AUTO;
    out->sigma = sigma;
    return JF_OK;
}

jf_status jf__auto_final_fit(jf_fitter *f, const jf_params *pr, int d, const double p[3], const double *nbr,
                             size_t k, double sigma, jf_result *out)
{
    return jf__auto_fit_by_fitter(f, pr, d, p, nbr, k, sigma, 0.0, out);
}

/* The frame of the K points of step 1's sums mo0 (the jet's, §5.2): their
 * covariance from those sums, turned from fr0's axes to the world's. */
void jf__auto_own_frame(const mom *mo0, double H, const double fr0[9], jf_frame_mode mode, double pca_ev[3],
                        double fk[9])
{
    const double *S = mo0->S, *T = mo0->T, n1 = (double)mo0->m;
    double mx = S[PIDX(1, 0)] * H / n1, my = S[PIDX(0, 1)] * H / n1, mz = T[0] / n1;
    double c[9], evec[9];
    c[0] = S[PIDX(2, 0)] * H * H / n1 - mx * mx;
    c[1] = c[3] = S[PIDX(1, 1)] * H * H / n1 - mx * my;
    c[2] = c[6] = T[PIDX(1, 0)] * H / n1 - mx * mz;
    c[4] = S[PIDX(0, 2)] * H * H / n1 - my * my;
    c[5] = c[7] = T[PIDX(0, 1)] * H / n1 - my * mz;
    c[8] = mo0->zz / n1 - mz * mz;
    jf__eig3_near(c, fr0, pca_ev, evec);
    jf__frame_axes(evec, mode, fk);
}

/* G' of degree deg from the sums: nd x nd into E */
static int gram_of(const jf__auto_dfit *D, int deg, double *E)
{
    const int nd = (deg + 1) * (deg + 2) / 2;
    for (int i = 0; i < nd; i++)
        for (int j = 0; j < nd; j++) E[i * nd + j] = D->mk.S[gpos[i][j]] * D->sp[mdeg[i]] * D->sp[mdeg[j]];
    return nd;
}

/* The extremes of the first G' (jf__auto_direct_begin's) alone: 1 where found. */
int jf__auto_gram_first(const jf__auto_dfit *D, double *hi, double *lo)
{
    return D->nd > 0 && jf__gram_extremes(D->E, (size_t)D->nd, hi, lo);
}

/* Up to the first G' to weigh: 1 with it in D->E, 0 when the jet is to
 * be fitted by jf__auto_final_fit (its call made, its status in *st). */
int jf__auto_direct_begin(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                          size_t k, const mom *mo0, double H, const double fr0[9], int d, double sigma,
                          jf__auto_dfit *D, jf_result *out, jf_status *st)
{
    if (pr->fit != JF_FIT_APPROX || !(mo0->m > 0)) {
        *st = jf__auto_final_fit(f, pr, d, p, nbr, k, sigma, out);
        return 0;
    }
    jf__auto_own_frame(mo0, H, fr0, pr->frame, D->pca_ev, D->fk);
    jf__auto_moments(p, nbr, k, D->fk, H, d, &D->mk);
    if (!(D->mk.hmean > 0.0)) {
        *st = jf__auto_final_fit(f, pr, d, p, nbr, k, sigma, out);
        return 0;
    }
    const double sc = H / D->mk.hmean;
    D->sp[0] = 1.0, D->sp[1] = sc, D->sp[2] = sc * sc, D->sp[3] = sc * sc * sc;
    D->sigma = sigma;
    D->d = d;
    D->flags = 0;
    int deg = d;
    while (deg >= 1 && D->mk.m < (size_t)((deg + 1) * (deg + 2) / 2)) {
        D->flags |= JF_PT_LOWERED_FEW;
        deg--;
    }
    D->deg = deg;
    D->nd = deg >= 1 ? gram_of(D, deg, D->E) : 0;
    return 1;
}

/* The rest of jf__auto_direct_fit: with the extremes of D->E (hi0, lo0; ok0 0:
 * singular) for the first degree, lower ones by jf__gram_extremes. */
jf_status jf__auto_direct_end(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                              size_t k, const jf__auto_dfit *D, double hi0, double lo0, int ok0,
                              jf_result *out)
{
    const mom *mo = &D->mk;
    const double h = mo->hmean, *sp = D->sp;
    const size_t m = mo->m;
    unsigned flags = D->flags;
    double L[NMON * NMON], Y[NMON], cond = NAN, rss = mo->zz;
    int deg = D->deg;
    for (; deg >= 1; deg--) {
        const int nd = (deg + 1) * (deg + 2) / 2;
        if (m < (size_t)nd) {
            flags |= JF_PT_LOWERED_FEW;
            continue;
        }
        double E[NMON * NMON], lo = lo0, hi = hi0;
        const double *G = deg == D->deg ? D->E : E; /* the first's: jf__auto_direct_begin's */
        if (deg != D->deg) gram_of(D, deg, E);
        for (int i = 0; i < nd; i++)
            for (int j = 0; j < nd; j++) L[i * NMON + j] = G[i * nd + j];
        /* the extremes only, as the jet's own (gram_eig.c) */
        if (deg == D->deg ? !ok0 : !jf__gram_extremes(E, (size_t)nd, &hi, &lo)) {
            flags |= JF_PT_LOWERED_RANK;
            continue;
        }
        cond = lo > 0.0 ? sqrt(hi / lo) : INFINITY;
        int okc = 1;
        for (int j = 0; j < nd && okc; j++) { /* Cholesky of G' */
            double sum = L[j * NMON + j];
            for (int q = 0; q < j; q++) sum -= L[j * NMON + q] * L[j * NMON + q];
            if (!(sum > 0.0)) {
                okc = 0;
                break;
            }
            L[j * NMON + j] = sqrt(sum);
            for (int i = j + 1; i < nd; i++) {
                double t = L[i * NMON + j];
                for (int q = 0; q < j; q++) t -= L[i * NMON + q] * L[j * NMON + q];
                L[i * NMON + j] = t / L[j * NMON + j];
            }
        }
        if (!okc || !isfinite(cond)) {
            flags |= JF_PT_LOWERED_RANK;
            continue;
        }
        if (cond > pr->max_cond) {
            flags |= JF_PT_LOWERED_COND;
            continue;
        }
        double y[NMON];
        rss = mo->zz;
        for (int i = 0; i < nd; i++) { /* L y = D M^T z */
            double t = mo->T[PIDX(mex[i], mey[i])] * sp[mdeg[i]];
            for (int q = 0; q < i; q++) t -= L[i * NMON + q] * y[q];
            y[i] = t / L[i * NMON + i];
            rss -= y[i] * y[i];
        }
        for (int i = nd - 1; i >= 0; i--) { /* L^T Y = y */
            double t = y[i];
            for (int q = i + 1; q < nd; q++) t -= L[q * NMON + i] * Y[q];
            Y[i] = t / L[i * NMON + i];
        }
        break;
    }
    if (deg < 1) return jf__auto_final_fit(f, pr, D->d, p, nbr, k, D->sigma, out);
    memset(out, 0, sizeof *out);
    out->status = flags | JF_PT_AUTO;
    out->degree = deg;
    out->n_used = (int)m;
    out->cond = cond;
    out->residual = sqrt((rss > 0.0 ? rss : 0.0) / (double)m);
    out->sigma = D->sigma;
    memcpy(out->pca_eval, D->pca_ev, sizeof D->pca_ev);
    double A[NMON], hk = 1.0;
    for (int t = 0, j = 0; t <= deg; t++, hk *= h)
        for (int q = 0; q <= t; q++, j++) A[j] = Y[j] / hk;
    jf__quantities(A, deg, pr->monge_degree, D->fk, h, out);
    return JF_OK;
}

jf_status jf__auto_direct_fit(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                              size_t k, const mom *mo0, double H, const double fr0[9], int d, double sigma,
                              jf_result *out)
{
    jf__auto_dfit D;
    jf_status st = JF_OK;
    if (!jf__auto_direct_begin(f, pr, p, nbr, k, mo0, H, fr0, d, sigma, &D, out, &st)) return st;
    double hi = 0.0, lo = 0.0;
    const int ok = jf__auto_gram_first(&D, &hi, &lo);
    return jf__auto_direct_end(f, pr, p, nbr, k, &D, hi, lo, ok, out);
}
