/* auto_internal.h -- what the files of neighbors auto share: the power
 * sums of one candidate K and the monomials' order (auto.c: steps 1-2 and
 * the candidates' jets; auto_sums.c: the sums; auto_direct.c: step 5,
 * the reported fit).  Internal to src/robust. */
#ifndef JF_AUTO_INTERNAL_H
#define JF_AUTO_INTERNAL_H

#include <emmintrin.h>
#include <stddef.h>

#include "fitter_internal.h"
#include "robust_internal.h"

#define NMON 10        /* monomials of a cubic                         */
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4l __attribute__((vector_size(32)));

/* total degree of monomial j (order 1, x, y, x^2, xy, y^2, x^3, ...) */
static const int mdeg[NMON] = {0, 1, 1, 2, 2, 2, 3, 3, 3, 3};

/* Exponents of monomial j (order 1, x, y, x^2, xy, y^2, x^3, ...). */
static const int mex[NMON] = {0, 1, 0, 2, 1, 0, 3, 2, 1, 0};
static const int mey[NMON] = {0, 0, 1, 0, 1, 2, 0, 1, 2, 3};

/* Position of the power sum x^i y^j (i + j <= 6) in the moment vector:
 * by degree t = i + j, then j. */
#define NPOW 28
#define PIDX(i, j) (((i) + (j)) * ((i) + (j) + 1) / 2 + (j))

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

/* The power sums of one candidate K (step 1) and what its fit needs. */
typedef struct {
    double S[28], T[NMON], zz;
    size_t m;     /* finite points among the K                      */
    double hmean; /* their mean planar distance (the jet's h, §2.3)  */
} mom;

/* *r = sqrt(x) lane by lane, IEEE: correctly rounded (by pointer: a v4d
 * return value's ABI differs with and without AVX) */
static inline __attribute__((always_inline)) void sqrt4(v4d *r, const v4d *x)
{
    const __m128d lo = _mm_sqrt_pd((__m128d){(*x)[0], (*x)[1]});
    const __m128d hi = _mm_sqrt_pd((__m128d){(*x)[2], (*x)[3]});
    *r = (v4d){lo[0], lo[1], hi[0], hi[1]};
}

/* auto_sums.c: the power sums of the first k neighbours in the frame fr
 * (x, y in units of H; up to degree 2 deg), their count and mean planar
 * distance (length units); and step 1's (degree 6 and 3) of the first
 * ks[c] neighbours for every candidate c < nc into mo[c], their radius
 * (largest planar distance) into hk[c]. */
void jf__auto_moments(const double p[3], const double *nbr, size_t k, const double fr[9], double H, int deg,
                      mom *mo);
void jf__auto_first_pass(const double p[3], const double *nbr, size_t nmax, const double fr[9], double H,
                         const size_t *ks, int nc, mom *mo, double *hk);

/* The chosen jet straight from its power sums (mo) in the frame fr: the
 * least-squares jet of degree d on those K points, as jf_fit_point would
 * fit it but in the frame of the 32 nearest (no second fit: step 5).
 * Its steps mirror the jet's (§2, §5.2; jet.c): monomials of x / h with h
 * the mean planar distance (§2.3), the condition number of that scaled
 * Vandermonde matrix sqrt(lambda_max / lambda_min) of G', the degree
 * lowered while G' is singular or too ill-conditioned (params.max_cond,
 * flags LOWERED_RANK / LOWERED_COND), A_ij = Y_ij / h^(i+j), then the
 * quantities (monge.c).  Interpolation, or no degree left: jf_fit_point
 * on the same points (jf__auto_final_fit).  In two halves
 * (jf__auto_direct_begin, then jf__auto_direct_end), so that up to four
 * points' first G' have their extremes side by side
 * (jf__gram_extremes_x4: the bits of one at a time). */
typedef struct {
    mom mk;             /* the K points' sums in their own frame       */
    double fk[9], pca_ev[3], sp[4], sigma;
    double E[NMON * NMON]; /* G' of degree deg (nd x nd), row-major    */
    int d, deg, nd;     /* asked, first tried (its G' in E), its size  */
    unsigned flags;     /* the degrees lowered before deg              */
} jf__auto_dfit;

/* auto_direct.c, step 5.  The jet of degree d on the first k points by the
 * fitter itself (dw > 0: Gaussian distance weights of width dw, the
 * bench-only knob auto_dw), flagged JF_PT_AUTO with the noise assumed;
 * jf__auto_final_fit: the same without weights. */
jf_status jf__auto_fit_by_fitter(jf_fitter *f, const jf_params *pr, int d, const double p[3],
                                 const double *nbr, size_t k, double sigma, double dw, jf_result *out);
jf_status jf__auto_final_fit(jf_fitter *f, const jf_params *pr, int d, const double p[3], const double *nbr,
                             size_t k, double sigma, jf_result *out);
/* The frame of the K points of step 1's sums mo0 (their PCA, §5.2). */
void jf__auto_own_frame(const mom *mo0, double H, const double fr0[9], jf_frame_mode mode, double pca_ev[3],
                        double fk[9]);
/* The direct fit in two halves: begin up to its first G' (1; 0 when
 * jf__auto_final_fit did the whole fit, its status in *st), the G's
 * extremes (jf__auto_gram_first, or four side by side), then end. */
int jf__auto_direct_begin(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                          size_t k, const mom *mo0, double H, const double fr0[9], int d, double sigma,
                          jf__auto_dfit *D, jf_result *out, jf_status *st);
int jf__auto_gram_first(const jf__auto_dfit *D, double *hi, double *lo);
jf_status jf__auto_direct_end(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                              size_t k, const jf__auto_dfit *D, double hi0, double lo0, int ok0,
                              jf_result *out);
jf_status jf__auto_direct_fit(jf_fitter *f, const jf_params *pr, const double p[3], const double *nbr,
                              size_t k, const mom *mo0, double H, const double fr0[9], int d, double sigma,
                              jf_result *out);

#endif
