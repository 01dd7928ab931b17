/* auto.c -- neighbors auto (params.auto_select): per point, the number of
 * neighbours K and the degree (2 or 3) of the jet, chosen from the data
 * alone, and the noise the choice assumed (jf_result.sigma).
 *
 * design:
 *  1. One frame per point: the PCA of its 32 nearest (§5.2).  In it every
 *     neighbour, nearest first, adds its monomials x^i y^j (i + j <= 3) to
 *     a Gram matrix G = M^T M and to M^T z, so that the least-squares jets
 *     of degree 2 and 3 at every candidate K (nested: the first K of the
 *     list) cost one small Cholesky solve each, not a fit (the normal
 *     equations of §2; each K's matrix is rescaled by its own radius, the
 *     preconditioning of §2.3, before the solve).
 *  2. Noise: the unbiased residual variance of the cubic at K = 32 (22
 *     degrees of freedom), where truncation error (O(h^4), Theorem 3) is
 *     least and the noise is still well sampled; the next larger K where
 *     that exceeds jf__auto_blob x the radius (a blob of noise, whose cubic
 *     follows it).  It is what `sigma` reports.
 *  3. Per degree, Lepski's rule (Lepski, Mammen & Spokoiny 1997; the
 *     intersection of confidence intervals of Katkovnik 1999; the K that
 *     balances noise and curvature for normals: Mitra, Nguyen & Guibas
 *     2004): grow K while the
 *     normal at K stays within tau (sd_j + sd_K) of the normal at every
 *     smaller accepted K j, sd from sigma^2 (M^T M)^-1 (the slope's
 *     covariance).  Noise makes sd fall like 1/(h sqrt K), so a noisy flat
 *     region grows K; curvature makes the quadric's normal drift like h^2
 *     (its bias), which stops the growth.
 *  4. Degree (cubics from K = 32, or smaller K when the noise is under 5%
 *     of their radius): the cubic's choice, unless the quadric at the largest K of
 *     its chain where it agrees with the cubic at the same K (within tau
 *     sd of the cubic) has the smaller sd.
 *  5. The reported fit is the ordinary jet (jf_fit_point) of the chosen
 *     degree on the chosen K points: the same numbers as knn:K --degree d,
 *     flagged JF_PT_AUTO.
 */
#include <math.h>
#include <string.h>

#include "fitter_internal.h"
#include "robust_internal.h"

#define NMON 10        /* monomials of a cubic                         */
#define FRAME_K 32     /* points of the PCA frame                      */
#define NOISE_K 32     /* K of the noise estimate                      */
#define NCAND 10
#define CUBIC_MINK 32  /* smallest K of a cubic candidate              */

/* Candidate K (nested, nearest first); the last is JF_NB_AUTO_KMAX. */
static const size_t cand[NCAND] = {16, 24, 32, 48, 64, 96, 128, 160, 200, 256};

/* Lepski's threshold, in sd (chosen on tests/bench/study_auto.sh's data) */
double jf__auto_tau = 2.0;
/* A residual above this fraction of the radius is a blob of noise whose
 * cubic follows the noise (and whose residual understates it): the noise
 * is then read at a larger K. */
double jf__auto_blob = 0.2;
/* A normal whose sd exceeds this (rad) is noise: it does not stop K. */
double jf__auto_sdmax = 0.3;
/* Noise below this fraction of the radius: cubics on 16-24 points allowed. */
double jf__auto_clean = 0.05;
/* 1: Goldenshluger-Lepski over every (K, degree) instead (bench --auto-gl
 * 1; worse, docs/robustness.md "Neighbourhood auto") */
int jf__auto_gl = 0;
double jf__auto_varw = 1.0;

/* total degree of monomial j (order 1, x, y, x^2, xy, y^2, x^3, ...) */
static const int mdeg[NMON] = {0, 1, 1, 2, 2, 2, 3, 3, 3, 3};

typedef struct {
    int ok;
    double nrm[3]; /* world normal                                  */
    double tr;     /* sd^2 of the normal's angle per unit noise var  */
    double s2;     /* unbiased residual variance                     */
    double h;      /* radius (farthest planar distance)              */
} cand_fit;

/* Solves the leading nd x nd block of the rescaled normal equations at one
 * K: G'_ab = G_ab D_a D_b, D_a = (H / hK)^deg(a) (monomials of x / hK).
 * Returns 0 when G' is (near) singular. */
static int solve_k(const double *G, const double *bz, double zz, size_t m, int nd, double H,
                   double hK, const double fr[9], cand_fit *out)
{
    double D[NMON], L[NMON * NMON], y[NMON], a[NMON];
    double s = H / hK;
    D[0] = 1.0;
    for (int j = 1; j < nd; j++) D[j] = pow(s, mdeg[j]);
    for (int i = 0; i < nd; i++)
        for (int j = 0; j <= i; j++) L[i * NMON + j] = G[i * NMON + j] * D[i] * D[j];
    /* Cholesky, lower triangle in place */
    for (int j = 0; j < nd; j++) {
        double sum = L[j * NMON + j];
        for (int k = 0; k < j; k++) sum -= L[j * NMON + k] * L[j * NMON + k];
        if (!(sum > 1e-12 * G[0])) return 0;
        L[j * NMON + j] = sqrt(sum);
        for (int i = j + 1; i < nd; i++) {
            double t = L[i * NMON + j];
            for (int k = 0; k < j; k++) t -= L[i * NMON + k] * L[j * NMON + k];
            L[i * NMON + j] = t / L[j * NMON + j];
        }
    }
    for (int i = 0; i < nd; i++) { /* L y = D bz */
        double t = bz[i] * D[i];
        for (int k = 0; k < i; k++) t -= L[i * NMON + k] * y[k];
        y[i] = t / L[i * NMON + i];
    }
    double rss = zz;
    for (int i = 0; i < nd; i++) rss -= y[i] * y[i]; /* z'z - b'G^-1 b */
    for (int i = nd - 1; i >= 0; i--) { /* L^T a = y */
        double t = y[i];
        for (int k = i + 1; k < nd; k++) t -= L[k * NMON + i] * a[k];
        a[i] = t / L[i * NMON + i];
    }
    /* [G'^-1]_cc = |L^-1 e_c|^2 for the slope columns c = 1, 2 */
    double var = 0.0;
    for (int c = 1; c <= 2; c++) {
        double zc[NMON] = {0};
        for (int i = c; i < nd; i++) {
            double t = i == c ? 1.0 : 0.0;
            for (int k = c; k < i; k++) t -= L[i * NMON + k] * zc[k];
            zc[i] = t / L[i * NMON + i];
            var += zc[i] * zc[i];
        }
    }
    double gx = a[1] / hK, gy = a[2] / hK, g2 = 1.0 + gx * gx + gy * gy;
    double v[3];
    for (int k = 0; k < 3; k++) v[k] = fr[6 + k] - gx * fr[k] - gy * fr[3 + k];
    double nv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(nv > 0.0) || !isfinite(nv)) return 0;
    for (int k = 0; k < 3; k++) out->nrm[k] = v[k] / nv;
    /* d(angle) = d|grad| / (1 + |grad|^2) */
    out->tr = var / (hK * hK) / (g2 * g2);
    out->s2 = (rss > 0.0 ? rss : 0.0) / (double)(m - (size_t)nd);
    out->h = hK;
    out->ok = isfinite(out->tr) && isfinite(out->s2);
    return out->ok;
}

/* Lepski / ICI over the candidates of one degree: the last K whose normal
 * agrees with every smaller accepted K's.  Returns its index or -1. */
static int lepski(const cand_fit *c, int nc, double s2, double tau)
{
    int acc[NCAND], na = 0, best = -1;
    for (int i = 0; i < nc; i++) {
        if (!c[i].ok) continue;
        double sdi = sqrt(s2 * c[i].tr);
        int okk = 1;
        for (int j = 0; j < na && okk; j++) {
            double sdj = sqrt(s2 * c[acc[j]].tr);
            if (!(sdj < jf__auto_sdmax)) continue; /* a normal of noise bounds nothing */
            okk = jf__angle(c[i].nrm, c[acc[j]].nrm) <= tau * (sdi + sdj);
        }
        if (!okk) break;
        acc[na++] = i;
        best = i;
    }
    return best;
}

static jf_status final_fit(jf_fitter *f, const jf_params *pr, int d, const double p[3], const double *nbr,
                           size_t k, double sigma, jf_result *out)
{
    jf_fitter *g = jf__ws_fitter(f, pr, d);
    if (!g) return JF_ERR_NOMEM;
    jf_status st = jf_fit_point(g, p, nbr, k, out);
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

jf_status jf__fit_auto(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                       size_t n, jf_result *out)
{
    (void)f;
    size_t nmax = n < JF_NB_AUTO_KMAX ? n : JF_NB_AUTO_KMAX;
    /* step 1: the frame, PCA of the FRAME_K nearest finite points */
    double mean[3] = {0, 0, 0}, cov[9] = {0};
    size_t kf = 0;
    for (size_t i = 0; i < nmax && kf < FRAME_K; i++) {
        const double *q = nbr + 3 * i;
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
        for (int k = 0; k < 3; k++) mean[k] += q[k] - p[k];
        kf++;
    }
    if (kf < 16) return final_fit(f, pr, 2, p, nbr, nmax, NAN, out); /* too few to choose */
    for (int k = 0; k < 3; k++) mean[k] /= (double)kf;
    size_t seen = 0;
    for (size_t i = 0; i < nmax && seen < kf; i++) {
        const double *q = nbr + 3 * i;
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
        double v[3] = {q[0] - p[0] - mean[0], q[1] - p[1] - mean[1], q[2] - p[2] - mean[2]};
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) cov[3 * a + b] += v[a] * v[b];
        seen++;
    }
    double ev[3], evec[9], fr[9];
    jf__eig3(cov, ev, evec);
    /* rows t1 (largest variance), t2 = nf x t1, nf (smallest) */
    memcpy(fr, evec + 6, 3 * sizeof(double));
    memcpy(fr + 6, evec, 3 * sizeof(double));
    fr[3] = fr[7] * fr[2] - fr[8] * fr[1];
    fr[4] = fr[8] * fr[0] - fr[6] * fr[2];
    fr[5] = fr[6] * fr[1] - fr[7] * fr[0];

    double H = 0.0;
    for (size_t i = 0; i < nmax; i++) {
        const double *q = nbr + 3 * i;
        double v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double x = v[0] * fr[0] + v[1] * fr[1] + v[2] * fr[2];
        double y = v[0] * fr[3] + v[1] * fr[4] + v[2] * fr[5];
        double r = hypot(x, y);
        if (isfinite(r) && r > H) H = r;
    }
    if (!(H > 0.0)) return final_fit(f, pr, 2, p, nbr, nmax, NAN, out);

    /* the candidates (the last one: the whole list when it is shorter) */
    size_t ks[NCAND];
    int nc = 0;
    for (int c = 0; c < NCAND && cand[c] <= nmax; c++) ks[nc++] = cand[c];
    if (nc < NCAND && (nc == 0 || ks[nc - 1] < nmax) && nmax >= cand[0]) ks[nc++] = nmax;

    double G[NMON * NMON] = {0}, bz[NMON] = {0}, zz = 0.0, hK = 0.0;
    size_t m = 0;
    cand_fit cf[2][NCAND];
    memset(cf, 0, sizeof cf);
    int c = 0;
    for (size_t i = 0; i < nmax && c < nc; i++) {
        const double *q = nbr + 3 * i;
        double v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
        double x = v[0] * fr[0] + v[1] * fr[1] + v[2] * fr[2];
        double y = v[0] * fr[3] + v[1] * fr[4] + v[2] * fr[5];
        double z = v[0] * fr[6] + v[1] * fr[7] + v[2] * fr[8];
        if (isfinite(x) && isfinite(y) && isfinite(z)) {
            double r = hypot(x, y);
            if (r > hK) hK = r;
            x /= H;
            y /= H;
            double mon[NMON] = {1, x, y, x * x, x * y, y * y, x * x * x, x * x * y, x * y * y,
                                y * y * y};
            for (int a = 0; a < NMON; a++) {
                for (int b = 0; b <= a; b++) G[a * NMON + b] += mon[a] * mon[b];
                bz[a] += mon[a] * z;
            }
            zz += z * z;
            m++;
        }
        if (i + 1 != ks[c]) continue;
        for (int d = 0; d < 2; d++) {
            int nd = d ? 10 : 6;
            if (m >= (size_t)nd + 4 && hK > 0.0)
                solve_k(G, bz, zz, m, nd, H, hK, fr, &cf[d][c]);
        }
        c++;
    }

    /* step 2: the noise, from the cubic at NOISE_K (else the nearest K) */
    double s2 = NAN;
    for (int i = 0; i < nc; i++)
        if (cf[1][i].ok) {
            double hb = jf__auto_blob * cf[1][i].h;
            s2 = cf[1][i].s2;
            if (ks[i] >= NOISE_K && s2 <= hb * hb) break;
        }
    if (!isfinite(s2)) return final_fit(f, pr, 2, p, nbr, nmax, NAN, out);
    double sigma = sqrt(s2);
    /* a cubic on fewer than 32 points follows the noise, unless the noise
     * is a small fraction of its radius (clean data, where the small
     * cubic is the least biased choice) */
    for (int i = 0; i < nc; i++) {
        double hc = jf__auto_clean * cf[1][i].h;
        if (ks[i] < CUBIC_MINK && ks[i] < nmax && !(s2 <= hc * hc)) cf[1][i].ok = 0;
    }

    if (jf__auto_gl) {
        /* Goldenshluger-Lepski over every (K, degree): the squared bias of a
         * candidate is its largest excess move against each less biased
         * one (smaller K, or the cubic at the same K), less what noise of
         * variance |sd_a^2 - sd_b^2| explains; cost = bias^2 + varw sd^2 */
        int bd = -1, bc = -1;
        double bcost = INFINITY;
        for (int i = 0; i < nc; i++)
            for (int d = 0; d < 2; d++) {
                const cand_fit *a = &cf[d][i];
                if (!a->ok) continue;
                double va = s2 * a->tr, b2 = 0.0;
                for (int j = 0; j <= i; j++)
                    for (int e = 0; e < 2; e++) {
                        const cand_fit *b = &cf[e][j];
                        if (!b->ok || (j == i && e <= d)) continue;
                        double vb = s2 * b->tr;
                        if (!(vb < jf__auto_sdmax * jf__auto_sdmax)) continue;
                        double x = jf__angle(a->nrm, b->nrm) - jf__auto_tau * sqrt(fabs(vb - va));
                        if (x > 0.0 && x * x > b2) b2 = x * x;
                    }
                double cost = b2 + jf__auto_varw * va;
                if (cost < bcost) {
                    bcost = cost;
                    bd = d;
                    bc = i;
                }
            }
        if (bc < 0) return final_fit(f, pr, 2, p, nbr, nmax, sigma, out);
        return final_fit(f, pr, bd ? 3 : 2, p, nbr, ks[bc], sigma, out);
    }
    /* step 3: Lepski per degree */
    double tau = jf__auto_tau;
    int c2 = lepski(cf[0], nc, s2, tau), c3 = lepski(cf[1], nc, s2, tau);
    /* step 4: the degree */
    int d = 3, ci = c3;
    if (c3 < 0) {
        d = 2;
        ci = c2;
    } else {
        /* the quadric at the largest K of its chain that agrees with the
         * cubic at the same K, if its sd is below the cubic's choice */
        double sd3 = sqrt(s2 * cf[1][c3].tr);
        for (int i = c2; i >= 0; i--) {
            if (!cf[0][i].ok || !cf[1][i].ok) continue;
            if (jf__angle(cf[0][i].nrm, cf[1][i].nrm) > tau * sqrt(s2 * cf[1][i].tr)) continue;
            if (sqrt(s2 * cf[0][i].tr) < sd3) {
                d = 2;
                ci = i;
            }
            break;
        }
    }
    if (ci < 0) return final_fit(f, pr, 2, p, nbr, nmax, sigma, out);
    return final_fit(f, pr, d, p, nbr, ks[ci], sigma, out);
}
