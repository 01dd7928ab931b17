/* auto.c -- neighbors auto (params.auto_select): per point, the number of
 * neighbours K and the degree (2 or 3) of the jet, chosen from the data
 * alone, and the noise the choice assumed (jf_result.sigma).
 *
 * design:
 *  0. (auto_cloud.c, the estimate's) The cloud's cap on K from its
 *     cross-validation, params.auto_select > 1: no candidate above it;
 *     JF_AUTO_CUBIC_MIN48 in it: no cubic below K = 48 (jf__auto_cv_point
 *     gives a sampled point's values).
 *  1. One frame per point: the PCA of its 32 nearest (§5.2).  In it every
 *     neighbour, nearest first, adds its power sums x^i y^j (i + j <= 6)
 *     and x^i y^j z (i + j <= 3), two at a time (SIMD lanes): the Gram
 *     matrix M^T M of the cubic on the first K points is read from their
 *     sums, so every candidate K (nested: the first K of the list) costs
 *     one small Cholesky solve, not a fit (the normal equations of §2,
 *     rescaled by K's own radius as in §2.3), and serves both degrees
 *     (the quadric's M^T M is the cubic's leading block).
 *  2. Noise: the unbiased residual variance of the cubic at K = 32 (22
 *     degrees of freedom), where truncation error (O(h^4), Theorem 3) is
 *     least and the noise is still well sampled; the next larger K where
 *     that exceeds auto_blob x the radius (a blob of noise, whose cubic
 *     follows it); the cubic's at the largest K instead where its
 *     residual variance stays flat from K = 48 on (no bias: the K = 32
 *     estimate's chi-square tail).  It is what `sigma` reports.
 *  3. (Steps 3-4: auto_rule.c.) Per degree, Lepski's rule (Lepski, Mammen & Spokoiny 1997; the
 *     intersection of confidence intervals of Katkovnik 1999; the K that
 *     balances noise and curvature for normals: Mitra, Nguyen & Guibas
 *     2004): grow K while the
 *     normal at K stays within tau (sd_j + sd_K) of the normal at every
 *     smaller accepted K j, sd from sigma^2 (M^T M)^-1 (the slope's
 *     covariance).  Noise makes sd fall like 1/(h sqrt K), so a noisy flat
 *     region grows K; curvature makes the quadric's normal drift like h^2
 *     (its bias), which stops the growth.
 *  4. Degree (cubics from K = 32, or smaller K when the noise is under 5%
 *     of their radius; from K = 48 where step 0 found the cubic on 16
 *     points predicts worse than the quadric): the cubic's choice, unless
 *     the quadric at the largest K of
 *     its chain where it agrees with the cubic at the same K (within tau
 *     sd of the cubic) has the smaller sd.
 *  5. The reported fit: the least-squares jet of the chosen degree on the
 *     chosen K points in their own PCA frame (the jet's, §5.2), from a
 *     second pass of power sums (direct_fit) -- the numbers of knn:K
 *     --degree d up to rounding (test_auto), without a second fit;
 *     flagged JF_PT_AUTO.  The walk's points come four at a time
 *     (jf__fit_auto_lanes): their Gram extremes side by side.
 * The power sums are auto_sums.c's, step 5's fit auto_direct.c's.
 */
#include <math.h>
#include <string.h>

#include "auto_internal.h"

#define FRAME_K 32     /* points of the PCA frame                      */
#define NOISE_K 32     /* K of the noise estimate                      */
#define NCAND JF_AUTO_NCAND
#define CUBIC_MINK 32    /* smallest K of a cubic, but on clean data     */
#define CUBIC_MINK_CV 48 /* ... where step 0 finds the noise outweighs it */
#define FLAT_K 48      /* the flat test's first K (step 2)             */
#define FLAT_I 3       /* its index: jf__auto_ks[FLAT_I] == FLAT_K     */

/* Candidate K (nested, nearest first); the last is JF_NB_AUTO_KMAX. */
const size_t jf__auto_ks[JF_AUTO_NCAND] = {16, 24, 32, 48, 64, 96, 128, 160, 200, 256};

/* The thresholds (Lepski's tau, blob, sdmax, clean, varw, gl) are the
 * fitter's knobs: jf__knob_defaults in robust.c says what each means. */

typedef jf__auto_cand cand_fit; /* robust_internal.h */

/* The normals of four jets (lane e where use[e]) whose slopes, in units
 * of x / hK, are (a1, a2), and the sd^2 of their angles per unit noise
 * variance from the slopes' variances var (same units), into out[e]
 * (left as it is where the normal is not finite); each lane's operations
 * those of one jet alone (put_fit), so its bits. */
static inline __attribute__((always_inline)) void put_fit4(v4d a1, v4d a2, v4d var, v4d rss,
                                                           const v4d hK, const v4d dof, const int use[4],
                                                           const double fr[9], cand_fit *out)
{
    const v4d one = {1.0, 1.0, 1.0, 1.0}, zero = {0.0, 0.0, 0.0, 0.0};
    const v4d gx = a1 / hK, gy = a2 / hK, g2 = one + gx * gx + gy * gy;
    v4d v[3];
    for (int k = 0; k < 3; k++) v[k] = fr[6 + k] - gx * fr[k] - gy * fr[3 + k];
    const v4d n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    v4d nv;
    sqrt4(&nv, &n2);
    v4d nrm[3];
    for (int k = 0; k < 3; k++) nrm[k] = v[k] / nv;
    const v4d tr = var / (hK * hK) / (g2 * g2);
    const v4d rp = (v4d)((v4l)rss & (v4l)(rss > zero));
    const v4d s2 = rp / dof;
    for (int e = 0; e < 4; e++) {
        if (!use[e] || !(nv[e] > 0.0) || !isfinite(nv[e])) continue;
        cand_fit *o = &out[e];
        for (int k = 0; k < 3; k++) o->nrm[k] = nrm[k][e];
        o->tr = tr[e];
        o->s2 = s2[e];
        o->h = hK[e];
        o->ok = isfinite(o->tr) && isfinite(o->s2);
    }
}

/* put_fit4 of one jet of nd monomials on m points (lane 0). */
static void put_fit(double a1, double a2, double var, double rss, size_t m, int nd, double hK,
                    const double fr[9], cand_fit *out)
{
    const int use[4] = {1, 0, 0, 0};
    const double dof = (double)(m - (size_t)nd);
    put_fit4((v4d){a1, a1, a1, a1}, (v4d){a2, a2, a2, a2}, (v4d){var, var, var, var},
             (v4d){rss, rss, rss, rss}, (v4d){hK, hK, hK, hK}, (v4d){dof, dof, dof, dof}, use, fr, out);
}

/* Cholesky in place of the leading nd x nd lower triangle of L (rows
 * NMON apart), idg its inverse diagonal; the columns factored: nd, or the
 * first whose pivot is not above 1e-12 s0 (s0: the point count). */
static int chol(double *L, int nd, double s0, double *idg)
{
    for (int j = 0; j < nd; j++) {
        double sum = L[j * NMON + j];
        for (int k = 0; k < j; k++) sum -= L[j * NMON + k] * L[j * NMON + k];
        if (!(sum > 1e-12 * s0)) return j;
        L[j * NMON + j] = sqrt(sum);
        double inv = idg[j] = 1.0 / L[j * NMON + j];
        for (int i = j + 1; i < nd; i++) {
            double t = L[i * NMON + j];
            for (int k = 0; k < j; k++) t -= L[i * NMON + k] * L[j * NMON + k];
            L[i * NMON + j] = t * inv;
        }
    }
    return nd;
}

/* The quadric (out[0]) and the cubic (out[1]) least-squares jets at one
 * K, from the power sums S = sum x^i y^j (i + j <= 6) and T = sum x^i y^j z
 * (i + j <= 3) of its points: G_ab = S(a + b), (M^T z)_a = T(a), rescaled
 * G'_ab = G_ab D_a D_b, D_a = (H / hK)^deg(a) (monomials of x / hK, §2.3).
 * The monomials are ordered by degree, so the quadric's G' is the leading
 * 6 x 6 block of the cubic's and one Cholesky factor L serves both: with
 * y = L^-1 D M^T z and u_c = L^-1 e_c (c = 1, 2: the slope columns), the
 * slope is a_c = u_c . y, its variance per unit noise |u_c|^2, and the
 * residual z'z - |y|^2 -- over the first 6 entries for the quadric, all 10
 * for the cubic (L^-1 is lower triangular: its leading block inverts G'
 * of the quadric).  A degree whose block is (near) singular, or with
 * fewer than its size + 4 points, is left out (ok = 0). */
static void solve_k(const double *S, const double *T, double zz, size_t m, double H, double hK,
                    const double fr[9], cand_fit out[2])
{
    double D[NMON], L[NMON * NMON], y[NMON], u[2][NMON], idg[NMON];
    double s = H / hK, sp[4] = {1.0, s, s * s, s * s * s};
    int nd = m >= NMON + 4 ? NMON : m >= 6 + 4 ? 6 : 0;
    for (int j = 0; j < nd; j++) D[j] = sp[mdeg[j]];
    for (int i = 0; i < nd; i++)
        for (int j = 0; j <= i; j++)
            L[i * NMON + j] = S[gpos[i][j]] * D[i] * D[j];
    /* nd drops to 6 if the cubic's trailing block is singular */
    const int nf = chol(L, nd, S[0], idg);
    if (nf < nd) nd = nf >= 6 ? 6 : 0;
    for (int i = 0; i < nd; i++) { /* L y = D M^T z */
        double t = T[PIDX(mex[i], mey[i])] * D[i];
        for (int k = 0; k < i; k++) t -= L[i * NMON + k] * y[k];
        y[i] = t * idg[i];
    }
    for (int c = 1; c <= 2; c++) { /* L u = e_c */
        double *z = u[c - 1];
        z[0] = 0.0;
        if (c == 2) z[1] = 0.0;
        for (int i = c; i < nd; i++) {
            double t = i == c ? 1.0 : 0.0;
            for (int k = c; k < i; k++) t -= L[i * NMON + k] * z[k];
            z[i] = t * idg[i];
        }
    }
    double a1 = 0.0, a2 = 0.0, var = 0.0, rss = zz;
    for (int i = 0; i < nd; i++) {
        a1 += u[0][i] * y[i];
        a2 += u[1][i] * y[i];
        var += u[0][i] * u[0][i] + u[1][i] * u[1][i];
        rss -= y[i] * y[i];
        if (i == 5) put_fit(a1, a2, var, rss, m, 6, hK, fr, &out[0]);
    }
    if (nd == NMON) put_fit(a1, a2, var, rss, m, NMON, hK, fr, &out[1]);
}

/* solve_k for every candidate at once: candidate l in lane l % 4 of quad
 * l / 4 (AVX: one register a quad, no FMA; default: two SSE2 registers),
 * the quads' chains of dependent square roots and divisions (the
 * Cholesky's) side by side, each lane with solve_k's operations, so its
 * bits.  A lane that would leave the common path (fewer than NMON + 4
 * points, a singular block: solve_k lowers the degree) runs solve_k on
 * its own; a candidate with no radius (hk <= 0) is left out (ok = 0). */
#define NQUAD ((NCAND + 3) / 4)
JF_CLONES static void solve_all(const mom *mo, const double *hk, int nc, double H, const double fr[9],
                                cand_fit cf[2][NCAND])
{
    v4d L[NMON * NMON][NQUAD], y[NMON][NQUAD], u[2][NMON][NQUAD], idg[NMON][NQUAD], D[NMON][NQUAD];
    v4d zz[NQUAD], floor[NQUAD], sv[NQUAD];
    int use[4 * NQUAD], any = 0;
    v4l bad[NQUAD];
    const v4d one = {1.0, 1.0, 1.0, 1.0}, zero = {0.0, 0.0, 0.0, 0.0};
    for (int l = 0; l < 4 * NQUAD; l++) {
        use[l] = l < nc && hk[l] > 0.0 && mo[l].m >= NMON + 4;
        any |= use[l];
    }
    if (any) {
        /* a lane not used holds a used one's numbers (no NaN, no denormal) */
        int src[4 * NQUAD], first = 0;
        while (!use[first]) first++;
        for (int l = 0; l < 4 * NQUAD; l++) src[l] = use[l] ? l : first;
        const mom *ml[NQUAD][4];
        for (int g = 0; g < NQUAD; g++) {
            for (int e = 0; e < 4; e++) {
                ml[g][e] = &mo[src[4 * g + e]];
                sv[g][e] = H / hk[src[4 * g + e]];
                zz[g][e] = ml[g][e]->zz;
                floor[g][e] = ml[g][e]->S[0];
            }
            floor[g] *= 1e-12;
            bad[g] = (v4l){0, 0, 0, 0};
        }
        for (int j = 0; j < NMON; j++)
            for (int g = 0; g < NQUAD; g++) {
                const v4d s = sv[g];
                D[j][g] = mdeg[j] == 0 ? one : mdeg[j] == 1 ? s : mdeg[j] == 2 ? s * s : s * s * s;
            }
        for (int i = 0; i < NMON; i++)
            for (int j = 0; j <= i; j++)
                for (int g = 0; g < NQUAD; g++) {
                    const int at = gpos[i][j];
                    const v4d S = {ml[g][0]->S[at], ml[g][1]->S[at], ml[g][2]->S[at], ml[g][3]->S[at]};
                    L[i * NMON + j][g] = S * D[i][g] * D[j][g];
                }
        for (int j = 0; j < NMON; j++) {
            for (int g = 0; g < NQUAD; g++) {
                v4d sum = L[j * NMON + j][g];
                for (int k = 0; k < j; k++) sum -= L[j * NMON + k][g] * L[j * NMON + k][g];
                bad[g] |= ~(v4l)(sum > floor[g]); /* the lane's result is not used */
                sqrt4(&L[j * NMON + j][g], &sum);
                idg[j][g] = one / L[j * NMON + j][g];
            }
            for (int i = j + 1; i < NMON; i++)
                for (int g = 0; g < NQUAD; g++) {
                    v4d t = L[i * NMON + j][g];
                    for (int k = 0; k < j; k++) t -= L[i * NMON + k][g] * L[j * NMON + k][g];
                    L[i * NMON + j][g] = t * idg[j][g];
                }
        }
        for (int i = 0; i < NMON; i++) /* L y = D M^T z */
            for (int g = 0; g < NQUAD; g++) {
                const int at = PIDX(mex[i], mey[i]);
                v4d t = (v4d){ml[g][0]->T[at], ml[g][1]->T[at], ml[g][2]->T[at], ml[g][3]->T[at]} * D[i][g];
                for (int k = 0; k < i; k++) t -= L[i * NMON + k][g] * y[k][g];
                y[i][g] = t * idg[i][g];
            }
        for (int c = 1; c <= 2; c++) /* L u = e_c */
            for (int g = 0; g < NQUAD; g++) {
                u[c - 1][0][g] = zero;
                if (c == 2) u[c - 1][1][g] = zero;
                for (int i = c; i < NMON; i++) {
                    v4d t = i == c ? one : zero;
                    for (int k = c; k < i; k++) t -= L[i * NMON + k][g] * u[c - 1][k][g];
                    u[c - 1][i][g] = t * idg[i][g];
                }
            }
        for (int g = 0; g < NQUAD; g++) {
            v4d a1 = zero, a2 = zero, var = zero, rss = zz[g], hK, m, dof[2];
            int ug[4];
            for (int e = 0; e < 4; e++) {
                const int l = 4 * g + e;
                ug[e] = use[l] && !bad[g][e];
                hK[e] = hk[src[l]];
                m[e] = (double)mo[src[l]].m;
            }
            dof[0] = m - 6.0; /* (double)(m - nd): exact, m < 2^53 */
            dof[1] = m - (double)NMON;
            for (int i = 0; i < NMON; i++) {
                a1 += u[0][i][g] * y[i][g];
                a2 += u[1][i][g] * y[i][g];
                var += u[0][i][g] * u[0][i][g] + u[1][i][g] * u[1][i][g];
                rss -= y[i][g] * y[i][g];
                if (i == 5) put_fit4(a1, a2, var, rss, hK, dof[0], ug, fr, &cf[0][4 * g]);
            }
            put_fit4(a1, a2, var, rss, hK, dof[1], ug, fr, &cf[1][4 * g]);
        }
    }
    for (int l = 0; l < nc; l++)
        if (hk[l] > 0.0 && (!use[l] || bad[l / 4][l % 4])) {
            cand_fit two[2] = {{0}, {0}};
            solve_k(mo[l].S, mo[l].T, mo[l].zz, mo[l].m, H, hk[l], fr, two);
            cf[0][l] = two[0];
            cf[1][l] = two[1];
        }
}

/* Steps 1-2 of one point: what the rule and the reported fit read. */
typedef struct {
    size_t nmax;
    double fr[9], H, s2, sigma;
    size_t ks[NCAND];
    int nc;
    cand_fit cf[2][NCAND];
    mom mo[NCAND];
    double hks[NCAND];
} stage;

/* Steps 1 and 2 into g; 0 when no candidate can be weighed (too few
 * points, no radius, no noise estimate: jf__auto_final_fit on the whole list). */
static int steps12(const jf__knobs *kn, const jf_params *pr, const double p[3], const double *nbr,
                   size_t n, stage *g)
{
    const size_t nmax = g->nmax = n < JF_NB_AUTO_KMAX ? n : JF_NB_AUTO_KMAX;
    g->sigma = NAN;
    /* step 1: the frame, PCA of the FRAME_K nearest finite points */
    double mean[3] = {0, 0, 0}, cov[9] = {0};
    size_t kf = 0;
    for (size_t i = 0; i < nmax && kf < FRAME_K; i++) {
        const double *q = nbr + 3 * i;
        if (!isfinite(q[0]) || !isfinite(q[1]) || !isfinite(q[2])) continue;
        for (int k = 0; k < 3; k++) mean[k] += q[k] - p[k];
        kf++;
    }
    if (kf < 16) return 0; /* too few to choose */
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
    double ev[3], evec[9];
    /* the candidates' fits do not depend on the tangent axes (a rotation
     * about the normal maps the polynomials of degree d onto themselves) */
    if (!jf__normal3(cov, evec)) jf__eig3_in(cov, NULL, ev, evec);
    /* rows t1 (largest variance), t2 = nf x t1, nf (smallest), as the
     * jet's own frame (or the world axis nearest nf: params.frame) */
    jf__frame_axes(evec, pr->frame, g->fr);

    /* H: a scale for the power sums, the distance of the last finite
     * neighbour (the farthest, nearest first), so that |x| / H, |y| / H
     * <= 1 (only a scale: any order of the list stays exact) */
    double H2 = 0.0;
    for (size_t i = nmax; i-- > 0;) {
        const double *q = nbr + 3 * i;
        double v0 = q[0] - p[0], v1 = q[1] - p[1], v2 = q[2] - p[2];
        double r2 = v0 * v0 + v1 * v1 + v2 * v2;
        if (isfinite(r2)) {
            H2 = r2;
            break;
        }
    }
    const double H = g->H = sqrt(H2), iH = 1.0 / H;
    if (!(H > 0.0) || !isfinite(iH)) return 0;

    /* the candidates (the last one: the whole list when it is shorter) */
    size_t *ks = g->ks;
    int nc = 0;
    for (int c = 0; c < NCAND && jf__auto_ks[c] <= nmax; c++) ks[nc++] = jf__auto_ks[c];
    if (nc < NCAND && (nc == 0 || ks[nc - 1] < nmax) && nmax >= jf__auto_ks[0]) ks[nc++] = nmax;
    g->nc = nc;

    /* power sums of x^i y^j (i + j <= 6: the Gram matrix of the cubic)
     * and x^i y^j z (i + j <= 3, with z'z), four neighbours at a time */
    cand_fit(*cf)[NCAND] = g->cf;
    memset(g->cf, 0, sizeof g->cf);
    jf__auto_first_pass(p, nbr, nmax, g->fr, H, ks, nc, g->mo, g->hks);
    solve_all(g->mo, g->hks, nc, H, g->fr, cf);

    /* step 2: the noise, from the cubic at NOISE_K (else the nearest K) */
    double s2 = NAN;
    for (int i = 0; i < nc; i++)
        if (cf[1][i].ok) {
            double hb = kn->auto_blob * cf[1][i].h;
            s2 = cf[1][i].s2;
            if (ks[i] >= NOISE_K && s2 <= hb * hb) break;
        }
    if (!isfinite(s2)) return 0;
    /* On 22 dof the estimate at K = 32 falls, at a few points in a
     * thousand, to a third of the noise's variance, and Lepski then stops
     * on wild small-K normals.  Where the cubic's residual variance stays
     * flat from K = 48 to the largest K there is no bias to fear (a
     * cubic's grows like h^8, Theorem 3): the largest K's, on the most
     * points, is the noise's. */
    const int b = nc - 1; /* ks[i] == jf__auto_ks[i] below the last */
    if (kn->auto_flat > 0.0 && FLAT_I < b && cf[1][FLAT_I].ok && cf[1][b].ok && cf[1][b].s2 > s2 &&
        cf[1][b].s2 <= cf[1][FLAT_I].s2 * (1.0 + kn->auto_flat * sqrt(2.0 / (FLAT_K - NMON))))
        s2 = cf[1][b].s2;
    g->s2 = s2;
    g->sigma = sqrt(s2);
    return 1;
}

/* A point's direct fit waiting for its first G's extremes (jf__auto_direct_end). */
typedef struct {
    jf__auto_dfit D;
    size_t k;   /* its K                       */
    int capped; /* step 0's cap left candidates out */
} pend;

/* jf__fit_auto up to the direct fit's first G' (then 1, *P to finish),
 * or the whole fit (0, its status in *st). */
static int auto_begin(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr, size_t n,
                      pend *P, jf_result *out, jf_status *st)
{
    const jf__knobs *kn = jf__knobs_of(f);
    stage g;
    if (!steps12(kn, pr, p, nbr, n, &g)) {
        *st = jf__auto_final_fit(f, pr, 2, p, nbr, g.nmax, g.sigma, out);
        return 0;
    }
    const size_t nmax = g.nmax, *ks = g.ks;
    const int nc = g.nc;
    const double s2 = g.s2, sigma = g.sigma;
    cand_fit(*cf)[NCAND] = g.cf;
    /* a cubic on fewer than 32 points follows the noise, unless the noise
     * is a small fraction of its radius (clean data, where the small
     * cubic is the least biased choice); where the cloud's cross-validation
     * (step 0) finds the noise outweighs the smallest cubic's detail, on
     * fewer than 48 (the range scans' cubics at 32: item 8) */
    const int min48 = (pr->auto_select & JF_AUTO_CUBIC_MIN48) != 0;
    const size_t cap = (size_t)(pr->auto_select & ~JF_AUTO_FLAGS);
    for (int i = 0; i < nc; i++) {
        double hc = kn->auto_clean * cf[1][i].h;
        if (ks[i] < (min48 ? CUBIC_MINK_CV : CUBIC_MINK) && ks[i] < nmax && (min48 || !(s2 <= hc * hc)))
            cf[1][i].ok = 0;
    }
    /* step 0's cap (the cloud's cross-validation, jf__auto_cv_point): no
     * candidate above it (ks ascend); where step 0 found the cloud's small
     * fits mildly biased, none below JF_AUTO_CAPW_KMIN either, nor below a
     * smaller cap (the range scans' rows at K = 16 and 24 were 2.6 and 1.5
     * times knn:32's mean error on the same points: a wild small fit stops
     * Lepski's rule; item 8) */
    const int capped = cap > 1 && ks[nc - 1] > cap;
    const size_t least = capped && (pr->auto_select & JF_AUTO_CAPPED_WEIGHTED)
                             ? (cap < JF_AUTO_CAPW_KMIN ? cap : JF_AUTO_CAPW_KMIN)
                             : 0;
    for (int i = 0; i < nc; i++)
        if ((capped && ks[i] > cap) || ks[i] < least) cf[0][i].ok = cf[1][i].ok = 0;

    /* steps 3-4 (auto_rule.c): the candidate and the degree */
    jf__auto_cands C;
    C.nc = nc;
    C.s2 = s2;
    memcpy(C.ks, ks, sizeof g.ks);
    memcpy(C.cf, cf, sizeof g.cf);
    int d = 2, ci = jf__auto_rule(kn, &C, &d);
    if (kn->auto_diag) { /* bench-only: every candidate's own fit */
        jf__auto_diag *dg = kn->auto_diag;
        dg->c = C;
        dg->ci = ci;
        dg->d = d;
        for (int i = 0; i < nc; i++)
            for (int e = 0; e < 2; e++)
                if (jf__auto_direct_fit(f, pr, p, nbr, ks[i], &g.mo[i], g.H, g.fr, e + 2, sigma,
                                        &dg->res[e][i]) != JF_OK)
                    dg->res[e][i].status = JF_PT_FAILED;
    }
    if (ci >= 0 && !(kn->auto_dw > 0.0)) {
        P->k = ks[ci];
        P->capped = capped;
        if (jf__auto_direct_begin(f, pr, p, nbr, ks[ci], &g.mo[ci], g.H, g.fr, d, sigma, &P->D, out, st))
            return 1;
    } else if (ci < 0) /* no candidate: the plain quadric on the list (up to the cap) */
        *st = jf__auto_final_fit(f, pr, 2, p, nbr, capped ? cap : nmax, sigma, out);
    else /* bench-only knob, off: a distance-weighted row */
        *st = jf__auto_fit_by_fitter(f, pr, d, p, nbr, ks[ci], sigma, kn->auto_dw, out);
    if (*st == JF_OK && capped && (out->status & JF_PT_AUTO)) out->status |= JF_PT_AUTO_CAPPED;
    return 0;
}

/* The direct fit of P, its first G's extremes given (hi, lo, ok). */
static jf_status auto_end(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                          const pend *P, double hi, double lo, int ok, jf_result *out)
{
    jf_status st = jf__auto_direct_end(f, pr, p, nbr, P->k, &P->D, hi, lo, ok, out);
    if (st == JF_OK && P->capped && (out->status & JF_PT_AUTO)) out->status |= JF_PT_AUTO_CAPPED;
    return st;
}

jf_status jf__fit_auto(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                       size_t n, jf_result *out)
{
    const double *const pp[1] = {p}, *const nn[1] = {nbr};
    jf_result *const oo[1] = {out};
    return jf__fit_auto_lanes(f, pr, 1, pp, nn, &n, oo);
}

jf_status jf__fit_auto_lanes(jf_fitter *f, const jf_params *pr, int L, const double *const p[],
                             const double *const nbr[], const size_t n[], jf_result *const out[])
{
    if (L < 1 || L > 4) return JF_ERR_INVALID;
    pend P[4];
    int wait[4] = {0};
    jf_status st = JF_OK;
    for (int l = 0; l < L && st == JF_OK; l++)
        wait[l] = auto_begin(f, pr, p[l], nbr[l], n[l], &P[l], out[l], &st);
    if (st != JF_OK) return st;
    /* the waiting lanes' first G' side by side, those of one size together
     * (a lane's extremes do not depend on the others': the same bits) */
    double hi[4] = {0}, lo[4] = {0};
    int ok[4] = {0}, done[4] = {0};
    for (int l = 0; l < L; l++) {
        if (!wait[l] || done[l]) continue;
        const int nd = P[l].D.nd;
        const double *g[4];
        int lane[4], c = 0;
        for (int e = l; e < L; e++)
            if (wait[e] && !done[e] && P[e].D.nd == nd) lane[c] = e, g[c++] = P[e].D.E, done[e] = 1;
        if (c > 1 && nd > 0) {
            double h4[4], l4[4];
            int o4[4];
            for (int e = c; e < 4; e++) g[e] = g[0];
            jf__gram_extremes_x4(g, (size_t)nd, h4, l4, o4);
            for (int e = 0; e < c; e++) hi[lane[e]] = h4[e], lo[lane[e]] = l4[e], ok[lane[e]] = o4[e];
        } else
            ok[l] = jf__auto_gram_first(&P[l].D, &hi[l], &lo[l]);
    }
    for (int l = 0; l < L && st == JF_OK; l++)
        if (wait[l]) st = auto_end(f, pr, p[l], nbr[l], &P[l], hi[l], lo[l], ok[l], out[l]);
    return st;
}

/* The squared leave-one-out residual at p of the jet of nd monomials (6:
 * the quadric, NMON: the cubic) on one candidate's points (p among them,
 * at the origin): a0 / (1 - h00), a0 the jet's height at p and h00 =
 * (M^T M)^-1 [0, 0] the hat matrix's diagonal there, u0 = L^-1 e0 giving
 * both (a0 = u0 . y, h00 = |u0|^2; the monomials' scale D leaves the
 * constant's row alone). */
static double loo2(const mom *mo, double H, double hK, int nd)
{
    if (mo->m < (size_t)nd + 4 || !(hK > 0.0)) return NAN;
    const double s = H / hK, sp[4] = {1.0, s, s * s, s * s * s};
    double L[NMON * NMON], idg[NMON], y[NMON], u[NMON];
    for (int i = 0; i < nd; i++)
        for (int j = 0; j <= i; j++) L[i * NMON + j] = mo->S[gpos[i][j]] * sp[mdeg[i]] * sp[mdeg[j]];
    if (chol(L, nd, mo->S[0], idg) < nd) return NAN;
    double a0 = 0.0, h = 0.0;
    for (int i = 0; i < nd; i++) { /* L y = D M^T z, L u = e0 */
        double t = mo->T[PIDX(mex[i], mey[i])] * sp[mdeg[i]], v = i == 0 ? 1.0 : 0.0;
        for (int k = 0; k < i; k++) t -= L[i * NMON + k] * y[k], v -= L[i * NMON + k] * u[k];
        y[i] = t * idg[i];
        u[i] = v * idg[i];
        a0 += u[i] * y[i];
        h += u[i] * u[i];
    }
    if (!(h < 1.0)) return NAN;
    const double r = a0 / (1.0 - h);
    return r * r;
}

/* Candidate c's quadric normal against its cubic's: the squared angle
 * over the variance the noise alone gives it.  The cubic's slope is
 * unbiased where the 4th-order terms are small (§3) and the two differ by
 * noise of variance tr3 - tr2 (nested least squares), so a quadric's
 * slope bias adds to about chi2_2 / 2.  +inf: a bias and no noise. */
static double bias_stat(const stage *g, int c)
{
    const cand_fit *q2 = &g->cf[0][c], *q3 = &g->cf[1][c];
    if (!q2->ok || !q3->ok || !(q3->tr > q2->tr)) return NAN;
    double d2 = 0.0;
    for (int k = 0; k < 3; k++) d2 += (q3->nrm[k] - q2->nrm[k]) * (q3->nrm[k] - q2->nrm[k]);
    const double den = (q3->tr - q2->tr) * q3->s2; /* 0: no noise left */
    return den > 0.0 ? d2 / den : d2 > 0.0 ? INFINITY : NAN;
}

void jf__auto_cv_point(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                       size_t n, double out[JF_AUTO_CV_N])
{
    for (int c = 0; c < JF_AUTO_CV_N; c++) out[c] = NAN;
    stage g;
    if (!steps12(jf__knobs_of(f), pr, p, nbr, n, &g)) return;
    for (int c = 0; c < g.nc; c++)
        if (g.ks[c] == jf__auto_ks[c]) out[c] = loo2(&g.mo[c], g.H, g.hks[c], 6);
    if (g.ks[0] == jf__auto_ks[0] && g.mo[0].m > 0) {
        /* the smallest K's quadric and cubic in their own frame (as the
         * reported fit's): a small cubic's CV hangs on the tilt of step
         * 1's frame (the clean armadillo's: 1.9x the quadric's there,
         * 0.74x in its own) */
        double ev[3], fk[9];
        mom mk;
        jf__auto_own_frame(&g.mo[0], g.H, g.fr, pr->frame, ev, fk);
        jf__auto_moments(p, nbr, g.ks[0], fk, g.H, 3, &mk);
        out[JF_AUTO_CV_SMALL] = loo2(&mk, g.H, g.hks[0], 6);
        out[JF_AUTO_CV_SMALL + 1] = loo2(&mk, g.H, g.hks[0], NMON);
    }
    if (g.ks[g.nc - 1] == JF_NB_AUTO_KMAX) out[JF_AUTO_CV_BIAS] = bias_stat(&g, g.nc - 1);
    if (g.nc > JF_AUTO_CV_K32 && g.ks[JF_AUTO_CV_K32] == jf__auto_ks[JF_AUTO_CV_K32])
        out[JF_AUTO_CV_BIAS32] = bias_stat(&g, JF_AUTO_CV_K32);
    if (g.nmax > 16) {
        const double *q = nbr + 3 * 16;
        const double r = sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                              (q[2] - p[2]) * (q[2] - p[2]));
        out[NCAND] = g.sigma / r;
    }
}
