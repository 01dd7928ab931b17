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
 */
#include <emmintrin.h>
#include <math.h>
#include <string.h>

#include "fitter_internal.h"
#include "robust_internal.h"

#define NMON 10        /* monomials of a cubic                         */
typedef double v2d __attribute__((vector_size(16)));
typedef long long v2l __attribute__((vector_size(16)));
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));
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

/* total degree of monomial j (order 1, x, y, x^2, xy, y^2, x^3, ...) */
static const int mdeg[NMON] = {0, 1, 1, 2, 2, 2, 3, 3, 3, 3};

typedef jf__auto_cand cand_fit; /* robust_internal.h */

/* The power sums of one candidate K (step 1) and what its fit needs. */
typedef struct {
    double S[28], T[NMON], zz;
    size_t m;     /* finite points among the K                      */
    double hmean; /* their mean planar distance (the jet's h, §2.3)  */
} mom;

/* Exponents of monomial j (order 1, x, y, x^2, xy, y^2, x^3, ...). */
static const int mex[NMON] = {0, 1, 0, 2, 1, 0, 3, 2, 1, 0};
static const int mey[NMON] = {0, 0, 1, 0, 1, 2, 0, 1, 2, 3};

/* Position of the power sum x^i y^j (i + j <= 6) in the moment vector:
 * by degree t = i + j, then j. */
#define NPOW 28
_Static_assert(NPOW % 4 == 0 && NMON >= 8, "first_pass sums four power sums a step");
#define PIDX(i, j) (((i) + (j)) * ((i) + (j) + 1) / 2 + (j))

/* *r = sqrt(x) lane by lane, IEEE: correctly rounded (by pointer: a v4d
 * return value's ABI differs with and without AVX) */
static inline __attribute__((always_inline)) void sqrt4(v4d *r, const v4d *x)
{
    const __m128d lo = _mm_sqrt_pd((__m128d){(*x)[0], (*x)[1]}), hi = _mm_sqrt_pd((__m128d){(*x)[2], (*x)[3]});
    *r = (v4d){lo[0], lo[1], hi[0], hi[1]};
}

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
/* gpos[a][b]: PIDX of x^(mex a + mex b) y^(mey a + mey b) */
static const unsigned char gpos[NMON][NMON] = {
    {0, 1, 2, 3, 4, 5, 6, 7, 8, 9},
    {1, 3, 4, 6, 7, 8, 10, 11, 12, 13},
    {2, 4, 5, 7, 8, 9, 11, 12, 13, 14},
    {3, 6, 7, 10, 11, 12, 15, 16, 17, 18},
    {4, 7, 8, 11, 12, 13, 16, 17, 18, 19},
    {5, 8, 9, 12, 13, 14, 17, 18, 19, 20},
    {6, 10, 11, 15, 16, 17, 21, 22, 23, 24},
    {7, 11, 12, 16, 17, 18, 22, 23, 24, 25},
    {8, 12, 13, 17, 18, 19, 23, 24, 25, 26},
    {9, 13, 14, 18, 19, 20, 24, 25, 26, 27}};

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

/* The jet of degree d on the first k points by the fitter itself (dw > 0:
 * with --dist-weight's Gaussian weights of width dw, the bench-only knob
 * auto_dw), flagged JF_PT_AUTO with the noise auto assumed. */
static jf_status fit_by_fitter(jf_fitter *f, const jf_params *pr, int d, const double p[3],
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

static jf_status final_fit(jf_fitter *f, const jf_params *pr, int d, const double p[3], const double *nbr,
                           size_t k, double sigma, jf_result *out)
{
    return fit_by_fitter(f, pr, d, p, nbr, k, sigma, 0.0, out);
}

/* Power sums in four SIMD lanes (four neighbours a step, lane l the
 * neighbours l, l + 4, ...; summed (l0 + l1) + (l2 + l3) at the end).  The
 * loops are built twice (target_clones): AVX (four lanes a register, no
 * FMA, so no contraction) and the default (two SSE2 registers) -- the same
 * operations on every lane, so the same bits on every machine. */
typedef struct {
    v4d S[NPOW], T[NMON], zz, m, rmax2, rsum;
} acc4;

static inline double sum4(v4d v) { return (v[0] + v[1]) + (v[2] + v[3]); }

/* out[i] = sum4(v[i]), i < 4: the same additions, four sums a step
 * (pairs of lanes side by side, then the pairs' sums) */
#if defined(__clang__) /* GCC's __builtin_shuffle is clang's shufflevector */
#define SHUF4(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define SHUF4(a, b, i, j, k, l) __builtin_shuffle(a, b, (v4l){i, j, k, l})
#endif
static inline __attribute__((always_inline)) void sum4x4(const v4d *v, double *out)
{
    const v4d ab = SHUF4(v[0], v[1], 0, 4, 2, 6) + SHUF4(v[0], v[1], 1, 5, 3, 7); /* a01 b01 a23 b23 */
    const v4d cd = SHUF4(v[2], v[3], 0, 4, 2, 6) + SHUF4(v[2], v[3], 1, 5, 3, 7);
    const v4d r = SHUF4(ab, cd, 0, 1, 4, 5) + SHUF4(ab, cd, 2, 3, 6, 7);
    memcpy(out, &r, sizeof r);
}

/* One quad of neighbours q[0..3] (NULL: none) in the frame: x, y (units
 * of H: scaled by iH), z, and w = 1 (0: none or not finite). */
typedef struct {
    v4d x, y, z, w;
} quad4;

static inline __attribute__((always_inline)) void quad_load(quad4 *Q, const double *const q[4],
                                                            const double p[3], const double fr[9],
                                                            double iH)
{
    const v4d zero = {0.0, 0.0, 0.0, 0.0}, one = {1.0, 1.0, 1.0, 1.0};
    v4d v0, v1, v2;
    v4l live;
    if (q[3]) { /* four in a row (quad_of): one transpose of 12 doubles */
        const double *a = q[0];
        v4d r0, r1, r2;
        memcpy(&r0, a, sizeof r0); /* x0 y0 z0 x1 */
        memcpy(&r1, a + 4, sizeof r1); /* y1 z1 x2 y2 */
        memcpy(&r2, a + 8, sizeof r2); /* z2 x3 y3 z3 */
        const v4d pp = {p[0], p[1], p[2], p[0]};
        v0 = (v4d){r0[0], r0[3], r1[2], r2[1]} - pp[0];
        v1 = (v4d){r0[1], r1[0], r1[3], r2[2]} - pp[1];
        v2 = (v4d){r0[2], r1[1], r2[0], r2[3]} - pp[2];
        live = (v4l){-1, -1, -1, -1};
    } else
        for (int l = 0; l < 4; l++) {
            v0[l] = q[l] ? q[l][0] - p[0] : 0.0;
            v1[l] = q[l] ? q[l][1] - p[1] : 0.0;
            v2[l] = q[l] ? q[l][2] - p[2] : 0.0;
            live[l] = q[l] ? -1 : 0;
        }
    v4d x = (v0 * fr[0] + v1 * fr[1] + v2 * fr[2]) * iH;
    v4d y = (v0 * fr[3] + v1 * fr[4] + v2 * fr[5]) * iH;
    v4d z = v0 * fr[6] + v1 * fr[7] + v2 * fr[8];
    /* finite: t - t == 0 (NaN for an infinity or a NaN) */
    v4l ok = ((x - x) == zero) & ((y - y) == zero) & ((z - z) == zero) & live;
    Q->x = (v4d)((v4l)x & ok);
    Q->y = (v4d)((v4l)y & ok);
    Q->z = (v4d)((v4l)z & ok);
    Q->w = (v4d)((v4l)one & ok);
}

/* Adds nq (1 or 2) quads Q[0..nq) to A, in that order: x^i y^j for
 * i + j <= top, x^i y^j z for i + j <= deg, z^2, the count, the largest
 * x^2 + y^2 and (rs) the sum of sqrt(x^2 + y^2).  Two quads add to each
 * sum one after the other in a register, (A + a) + b, the bits of two
 * calls with one quad, with half the loads and stores of the ~40 sums
 * (which do not fit in registers: the stores bounded the loop). */
static inline __attribute__((always_inline)) void acc_quads(acc4 *A, const quad4 *Q, int nq, int top,
                                                            int deg, int rs)
{
    const v4d one = {1.0, 1.0, 1.0, 1.0};
    v4d xp[2][7], yp[2][7];
    for (int u = 0; u < nq; u++) {
        xp[u][0] = Q[u].w;
        yp[u][0] = one;
        for (int e = 1; e <= top; e++) {
            xp[u][e] = xp[u][e - 1] * Q[u].x;
            yp[u][e] = yp[u][e - 1] * Q[u].y;
        }
    }
    int at = 0; /* PIDX order: degree t, then j = 0..t */
    for (int t = 0; t <= top; t++)
        for (int j = 0; j <= t; j++, at++) {
            v4d a = A->S[at];
            for (int u = 0; u < nq; u++) a += xp[u][t - j] * yp[u][j];
            A->S[at] = a;
        }
    at = 0;
    for (int t = 0; t <= deg; t++)
        for (int j = 0; j <= t; j++, at++) {
            v4d a = A->T[at];
            for (int u = 0; u < nq; u++) a += xp[u][t - j] * yp[u][j] * Q[u].z;
            A->T[at] = a;
        }
    for (int u = 0; u < nq; u++) {
        const v4d x = Q[u].x, y = Q[u].y, z = Q[u].z;
        A->zz += Q[u].w * z * z;
        A->m += Q[u].w;
        v4d r2 = x * x + y * y;
        v4l gt = (v4l)(r2 > A->rmax2);
        A->rmax2 = (v4d)(((v4l)r2 & gt) | ((v4l)A->rmax2 & ~gt));
        if (rs) { /* four lanes a step (sqrt is correctly rounded: the bits of one at a time) */
            v4d r;
            sqrt4(&r, &r2);
            A->rsum += r;
        }
    }
}

/* Adds neighbours q[0..3] (NULL: none) to A (acc_quads). */
static inline __attribute__((always_inline)) void acc_quad(acc4 *A, const double *const q[4],
                                                           const double p[3], const double fr[9],
                                                           double iH, int top, int deg, int rs)
{
    quad4 Q;
    quad_load(&Q, q, p, fr, iH);
    acc_quads(A, &Q, 1, top, deg, rs);
}

/* Adds the eight neighbours nbr[i..i + 8) to A, as two acc_quad calls. */
static inline __attribute__((always_inline)) void acc_eight(acc4 *A, const double *nbr, size_t i,
                                                            const double p[3], const double fr[9],
                                                            double iH, int top, int deg, int rs)
{
    quad4 Q[2];
    const double *q0[4] = {nbr + 3 * i, nbr + 3 * i + 3, nbr + 3 * i + 6, nbr + 3 * i + 9};
    const double *q1[4] = {nbr + 3 * i + 12, nbr + 3 * i + 15, nbr + 3 * i + 18, nbr + 3 * i + 21};
    quad_load(&Q[0], q0, p, fr, iH);
    quad_load(&Q[1], q1, p, fr, iH);
    acc_quads(A, Q, 2, top, deg, rs);
}

/* The four neighbours from i (NULL past k). */
static inline void quad_of(const double *nbr, size_t i, size_t k, const double *q[4])
{
    for (int l = 0; l < 4; l++) q[l] = i + (size_t)l < k ? nbr + 3 * (i + (size_t)l) : NULL;
}

/* The power sums of the first k neighbours in the frame fr (as step 1's,
 * x, y in units of H; up to degree 2 deg), their count and mean planar
 * distance (length units). */
JF_CLONES static void moments(const double p[3], const double *nbr, size_t k, const double fr[9],
                              double H, int deg, mom *mo)
{
    const double iH = 1.0 / H;
    const int top = 2 * deg, ntop = (top + 1) * (top + 2) / 2, nt = (deg + 1) * (deg + 2) / 2;
    acc4 A;
    memset(&A, 0, sizeof A);
    const double *q[4];
    size_t i = 0;
    if (deg == 2) {
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, 4, 2, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, 4, 2, 1);
    } else if (deg == 3) { /* constants: the sums' loops unrolled (the same operations) */
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, 6, 3, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, 6, 3, 1);
    } else {
        for (; i + 8 <= k; i += 8) acc_eight(&A, nbr, i, p, fr, iH, top, deg, 1);
        for (; i < k; i += 4) quad_of(nbr, i, k, q), acc_quad(&A, q, p, fr, iH, top, deg, 1);
    }
    for (int j = 0; j < ntop; j++) mo->S[j] = sum4(A.S[j]);
    for (int j = 0; j < nt; j++) mo->T[j] = sum4(A.T[j]);
    mo->zz = sum4(A.zz);
    mo->m = (size_t)sum4(A.m);
    mo->hmean = mo->m ? sum4(A.rsum) / (double)mo->m * H : 0.0;
}

/* Step 1's power sums (degree 6 and 3, in the frame fr) of the first ks[c]
 * neighbours for every candidate c < nc into mo[c], and their radius
 * (largest planar distance, length units) into hk[c].  Every candidate K
 * but a short list's last (nmax) is a multiple of 4. */
JF_CLONES static void first_pass(const double p[3], const double *nbr, size_t nmax, const double fr[9],
                                 double H, const size_t *ks, int nc, mom *mo, double *hk)
{
    const double iH = 1.0 / H;
    acc4 A;
    memset(&A, 0, sizeof A);
    const double *q[4];
    int c = 0;
    for (size_t i = 0; i < nmax && c < nc;) {
        if (i + 8 <= nmax && ks[c] > i + 4) { /* no sums are read between the two quads */
            acc_eight(&A, nbr, i, p, fr, iH, 6, 3, 0);
            i += 8;
        } else {
            quad_of(nbr, i, nmax, q);
            acc_quad(&A, q, p, fr, iH, 6, 3, 0);
            i += 4;
        }
        if ((i < nmax ? i : nmax) < ks[c]) continue;
        mom *mc = &mo[c];
        mc->zz = sum4(A.zz);
        for (int j = 0; j < NPOW; j += 4) sum4x4(A.S + j, mc->S + j);
        sum4x4(A.T, mc->T);
        sum4x4(A.T + 4, mc->T + 4);
        for (int j = 8; j < NMON; j++) mc->T[j] = sum4(A.T[j]);
        mc->m = (size_t)sum4(A.m);
        mc->hmean = 0.0; /* unused: the reported jet has its own sums */
        v4d r = A.rmax2;
        double a = r[0] > r[1] ? r[0] : r[1], b = r[2] > r[3] ? r[2] : r[3];
        hk[c] = sqrt(a > b ? a : b) * H;
        c++;
    }
}

/* The frame of the K points of step 1's sums mo0 (the jet's, §5.2): their
 * covariance from those sums, turned from fr0's axes to the world's. */
static void own_frame(const mom *mo0, double H, const double fr0[9], jf_frame_mode mode, double pca_ev[3],
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

/* The chosen jet straight from its power sums (mo) in the frame fr: the
 * least-squares jet of degree d on those K points, as jf_fit_point would
 * fit it but in the frame of the 32 nearest (no second fit: step 5).
 * Its steps mirror the jet's (§2, §5.2; jet.c): monomials of x / h with h
 * the mean planar distance (§2.3), the condition number of that scaled
 * Vandermonde matrix sqrt(lambda_max / lambda_min) of G', the degree
 * lowered while G' is singular or too ill-conditioned (params.max_cond,
 * flags LOWERED_RANK / LOWERED_COND), A_ij = Y_ij / h^(i+j), then the
 * quantities (monge.c).  Interpolation, or no degree left: jf_fit_point
 * on the same points (final_fit).  In two halves (direct_begin, then
 * direct_end), so that up to four points' first G' have their extremes
 * side by side (jf__gram_extremes_x4: the bits of one at a time). */
typedef struct {
    mom mk;             /* the K points' sums in their own frame       */
    double fk[9], pca_ev[3], sp[4], sigma;
    double E[NMON * NMON]; /* G' of degree deg (nd x nd), row-major    */
    int d, deg, nd;     /* asked, first tried (its G' in E), its size  */
    unsigned flags;     /* the degrees lowered before deg              */
} dfit;

/* G' of degree deg from the sums: nd x nd into E */
static int gram_of(const dfit *D, int deg, double *E)
{
    const int nd = (deg + 1) * (deg + 2) / 2;
    for (int i = 0; i < nd; i++)
        for (int j = 0; j < nd; j++) E[i * nd + j] = D->mk.S[gpos[i][j]] * D->sp[mdeg[i]] * D->sp[mdeg[j]];
    return nd;
}

/* The extremes of the first G' (direct_begin's) alone: 1 where found. */
static int gram_first(const dfit *D, double *hi, double *lo)
{
    return D->nd > 0 && jf__gram_extremes(D->E, (size_t)D->nd, hi, lo);
}

/* Up to the first G' to weigh: 1 with it in D->E, 0 when the jet is to
 * be fitted by final_fit (its call made, its status in *st). */
static int direct_begin(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                        size_t k, const mom *mo0, double H, const double fr0[9], int d, double sigma,
                        dfit *D, jf_result *out, jf_status *st)
{
    if (pr->fit != JF_FIT_APPROX || !(mo0->m > 0)) {
        *st = final_fit(f, pr, d, p, nbr, k, sigma, out);
        return 0;
    }
    own_frame(mo0, H, fr0, pr->frame, D->pca_ev, D->fk);
    moments(p, nbr, k, D->fk, H, d, &D->mk);
    if (!(D->mk.hmean > 0.0)) {
        *st = final_fit(f, pr, d, p, nbr, k, sigma, out);
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

/* The rest of direct_fit: with the extremes of D->E (hi0, lo0; ok0 0:
 * singular) for the first degree, lower ones by jf__gram_extremes. */
static jf_status direct_end(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                            size_t k, const dfit *D, double hi0, double lo0, int ok0, jf_result *out)
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
        const double *G = deg == D->deg ? D->E : E; /* the first's: direct_begin's */
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
    if (deg < 1) return final_fit(f, pr, D->d, p, nbr, k, D->sigma, out);
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

static jf_status direct_fit(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr, size_t k,
                            const mom *mo0, double H, const double fr0[9], int d, double sigma,
                            jf_result *out)
{
    dfit D;
    jf_status st = JF_OK;
    if (!direct_begin(f, pr, p, nbr, k, mo0, H, fr0, d, sigma, &D, out, &st)) return st;
    double hi = 0.0, lo = 0.0;
    const int ok = gram_first(&D, &hi, &lo);
    return direct_end(f, pr, p, nbr, k, &D, hi, lo, ok, out);
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
 * points, no radius, no noise estimate: final_fit on the whole list). */
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
    first_pass(p, nbr, nmax, g->fr, H, ks, nc, g->mo, g->hks);
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

/* A point's direct fit waiting for its first G's extremes (direct_end). */
typedef struct {
    dfit D;
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
        *st = final_fit(f, pr, 2, p, nbr, g.nmax, g.sigma, out);
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
                if (direct_fit(f, pr, p, nbr, ks[i], &g.mo[i], g.H, g.fr, e + 2, sigma,
                               &dg->res[e][i]) != JF_OK)
                    dg->res[e][i].status = JF_PT_FAILED;
    }
    if (ci >= 0 && !(kn->auto_dw > 0.0)) {
        P->k = ks[ci];
        P->capped = capped;
        if (direct_begin(f, pr, p, nbr, ks[ci], &g.mo[ci], g.H, g.fr, d, sigma, &P->D, out, st)) return 1;
    } else if (ci < 0) /* no candidate: the plain quadric on the list (up to the cap) */
        *st = final_fit(f, pr, 2, p, nbr, capped ? cap : nmax, sigma, out);
    else /* bench-only knob, off: a distance-weighted row */
        *st = fit_by_fitter(f, pr, d, p, nbr, ks[ci], sigma, kn->auto_dw, out);
    if (*st == JF_OK && capped && (out->status & JF_PT_AUTO)) out->status |= JF_PT_AUTO_CAPPED;
    return 0;
}

/* The direct fit of P, its first G's extremes given (hi, lo, ok). */
static jf_status auto_end(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                          const pend *P, double hi, double lo, int ok, jf_result *out)
{
    jf_status st = direct_end(f, pr, p, nbr, P->k, &P->D, hi, lo, ok, out);
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
            ok[l] = gram_first(&P[l].D, &hi[l], &lo[l]);
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
        own_frame(&g.mo[0], g.H, g.fr, pr->frame, ev, fk);
        moments(p, nbr, g.ks[0], fk, g.H, 3, &mk);
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
