/* fitter_internal.h -- the jf_fitter workspace and the helpers shared by
 * frame.c, jet.c, solve.c, monge.c and curve.c (not part of the public API). */
#ifndef JF_FITTER_INTERNAL_H
#define JF_FITTER_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "jetfit.h"

/* Columns the workspace holds: the surface jet N_n, and at least the
 * JF_MAX_DEGREE + 1 coefficients of a curve jet. */
#define JF_CURVE_COLS (JF_MAX_DEGREE + 1)

/* Bivariate polynomials truncated at order 4, coefficient of x^(k-j) y^j
 * at index k(k+1)/2 + j (the jet's column order, eq. 4). */
#define JF_TP_ORDER 4
#define JF_TP_SIZE 15

struct jf_fitter {
    jf_params p;
    size_t maxn;      /* largest n accepted                            */
    size_t maxc;      /* largest number of columns                     */
    /* per-fit buffers, all sized at create time */
    double *loc;      /* 3*maxn local coordinates (fitting frame)      */
    double *w;        /* maxn equation weights (0 = not usable)        */
    double *dist;     /* maxn squared distances to p                   */
    uint32_t *order;  /* maxn indices of usable points, nearest first  */
    double *m;        /* maxn*maxc scaled Vandermonde M', column-major  */
    double *v;        /* maxc*maxc right singular vectors              */
    double *x;        /* maxc*maxc R^T R, or R (R^T) then its SVD      */
    double *s;        /* maxc singular values (or their squares)       */
    double *work;     /* maxc scratch (QR norms, eigen, GSL)           */
    double *rhs;      /* maxn right-hand side, then Q^T of it          */
    double *sol;      /* maxc scaled solution Y                        */
    double coef[JF_CURVE_COLS > 55 ? JF_CURVE_COLS : 55]; /* jet A_ij  */
    int perm[55];     /* column pivoting of the QR                     */
    double tmp[55];   /* solution in pivoted order                     */
    double frame[9];  /* last fitting frame: rows ex, ey, ez (world)   */
    int last_deg;     /* degree of coef (0 when the last fit failed)   */
    double last_h;    /* its preconditioning scale h                   */
    size_t last_n;    /* n of the last surface fit (residuals)         */
    int have_last;
    double last_p[3]; /* its origin (the point fitted)                 */
    /* the robust layer's state of this fitter (robust.c: scratch, the
     * lower-degree fitters, tuning), made on its first use and freed with
     * the fitter; core never looks inside, so it calls nothing up */
    void *ext;
    void (*ext_free)(void *);
};

/* RMS of z - J(x, y) of n other points (world coordinates) in the last
 * surface fit's frame: how far the jet fitted to moved points lies from
 * the raw ones (natural neighbourhoods on a noisy cloud).  NaN when the
 * last fit failed or no point is finite. */
double jf__fitter_rms(const jf_fitter *f, const double *pts, size_t n);

/* ldexp(x, e) as one multiplication by the exact double 2^e when that
 * is a normal number: a product is rounded once, as ldexp's result is
 * (subnormal and overflowing results included), so the bits are the
 * same; a library call per coefficient cost ~1.5% of a k-NN run. */
static inline double jf__ldexp(double x, int e)
{
    if (e < -1022 || e > 1023) return ldexp(x, e);
    union {
        uint64_t u;
        double d;
    } p = {(uint64_t)(e + 1023) << 52};
    return x * p.d;
}

#include "avx_path.h" /* JF_AVX_PATH, JF_AVX_FN, JF_HAVE_AVX */

/* frame.c */
/* Eigen-decomposition of the symmetric 3x3 matrix a (row-major) by cyclic
 * Jacobi: eval ascending, evec[3*k..] the unit eigenvector of eval[k]
 * with its largest-|component| positive.  Deterministic. */
void jf__eig3(const double a[9], double eval[3], double evec[9]);
/* jf__eig3 to rounding (a sweep sooner; not jf__eig3's bits) of a matrix
 * a given in the axes rot (rows: unit vectors in the world; NULL: the
 * world's), its eigenvectors in the world's coordinates.  Fewer sweeps
 * still when rot is near a's eigenvectors. */
void jf__eig3_in(const double a[9], const double rot[9], double eval[3], double evec[9]);

/* A tangent frame of a covariance a in the layout of jf__eig3's evec: the
 * least eigenvalue's eigenvector (evec[0..2], in closed form: a fifth of
 * the Jacobi solver's time, to about eps x l3 / (l2 - l1)) and two unit
 * vectors perpendicular to it (evec[6..8], evec[3..5]), not a's.  Returns
 * 0 (evec untouched) when l1 is not clearly apart from l2 or a is not
 * finite: jf__eig3 decides there. */
int jf__normal3(const double a[9], double evec[9]);
/* jf__eig3_in's results (to rounding; their tangent axes may differ
 * where two eigenvalues nearly meet) from jf__normal3's least eigenvector
 * and the 2 x 2 block of a in the plane normal to it; jf__eig3_in where
 * normal3 finds no clear normal. */
void jf__eig3_near(const double a[9], const double rot[9], double eval[3], double evec[9]);

/* Fitting frame (§5.2) of the local points q[3*i] (already translated to
 * p) with weights w[i] (> 0 used): two-pass weighted centred covariance,
 * PCA, then the axes ex, ey, ez (rows of r, right-handed) of the PCA or
 * world-axis frame.  Returns 0 on success, -1 if the covariance is not
 * finite or no weight is positive. */
int jf__frame(const double *q, const double *w, size_t n, jf_frame_mode mode,
              double r[9], double eval[3]);

/* jf__frame in steps: the covariance (0, or -1 as jf__frame), then the
 * axes r from the eigenvectors of jf__eig3 (or jf__eig3_x2). */
int jf__frame_cov(const double *q, const double *w, size_t n, double cov[9]);
void jf__frame_axes(const double evec[9], jf_frame_mode mode, double r[9]);

/* jf__eig3 of a0 and of a1 at once (SIMD lanes), bit for bit the same. */
void jf__eig3_x2(const double a0[9], const double a1[9], double eval0[3], double evec0[9],
                 double eval1[3], double evec1[9]);

/* jf__eig3 of a[0..3] at once (SIMD lanes), bit for bit the same. */
void jf__eig3_x4(const double *const a[4], double *const eval[4], double *const evec[4]);

/* monge.c */
/* Differential quantities of the jet A (fitting frame, degree deg, rows of
 * r = frame axes in world coordinates) into out: normal, k1, k2, d1, d2,
 * b, c (up to monge_degree), and JF_PT_UMBILIC.  Orders above deg are
 * NaN. */
void jf__quantities(const double *a, int deg, int monge_degree,
                    const double r[9], double h, jf_result *out);

/* Sets every quantity of out to NaN (FAILED / NONFINITE rows). */
void jf__result_nan(jf_result *out);

/* jet.c */
/* jf_fit_point on two neighbourhoods with two distinct fitters at once:
 * the same results (and fitter state), bit for bit, as the two calls;
 * their eigen-solvers share SIMD lanes (frame.c, solve.c). */
jf_status jf__fit_point_x2(jf_fitter *f0, const double p0[3], const double *nbr0, size_t n0,
                           jf_result *out0, jf_fitter *f1, const double p1[3],
                           const double *nbr1, size_t n1, jf_result *out1);

/* jf__fit_point_x2 for four (distinct fitters f[k]): the same results,
 * bit for bit, as the four calls. */
jf_status jf__fit_point_x4(jf_fitter *const f[4], const double *const p[4],
                           const double *const nbr[4], const size_t n[4], jf_result *const out[4]);

/* solve.c */
/* Solves the weighted least-squares system rows x cols in f->m / f->rhs
 * by pivoted QR, then (kappa <= 1e3) the eigenvalues of R^T R and a
 * back-substitution, or an SVD of the cols x cols R; fills f->sol, *cond,
 * and leaves Q^T rhs in f->rhs (its rows cols.. are the residual, jet.c);
 * f->m, f->x, f->v, f->s, f->work, f->perm, f->tmp are scratch.  Returns
 * 0, 1 if the matrix is rank deficient (sigma_min <= sigma_max * rows *
 * DBL_EPSILON), -1 when no SVD was had (GSL failure, or a singular value
 * not finite). */
int jf__svd_solve(jf_fitter *f, size_t rows, size_t cols, double *cond);

/* jf__svd_solve in steps, for two fits side by side (jet.c):
 * jf__qr_gram: the QR, then G = R^T R into f->x; returns 1, or 0 when
 * the fast path does not apply (no eigenvalues wanted).
 * jf__eigvals (gram_eig.c): G's extreme eigenvalues into f->s (s[0] the
 * largest, the rest the smallest; all of them for cols > 10); 1 ok, 0
 * failed.
 * jf__eigvals_x2: the same for f0 and f1 (same cols) at once, bit for
 * bit; ok[i] as jf__eigvals' return.
 * jf__sym_eigvals: all eigenvalues d of the symmetric n x n a (destroyed)
 * by Householder and QL (n <= 55; e: n scratch); 0, or -1 when the QL did
 * not converge.
 * jf__solve_after_eig: the rest (have_eig: the eigenvalues are in f->s);
 * returns as jf__svd_solve. */
int jf__qr_gram(jf_fitter *f, size_t rows, size_t cols);
/* jf__qr_gram of four fitters (distinct, the same rows and cols) at
 * once, the same bits; returns as jf__qr_gram (the same for all four). */
int jf__qr_gram_x4(jf_fitter *const f[4], size_t rows, size_t cols);
/* The QR, G's extremes and M' run the code of the common sizes (16 or 32
 * rows, 6 or 10 columns) with those sizes as constants, which the
 * compiler unrolls: the same operations, the same bits.  0 runs the
 * general code for every size (tests compare the two; not thread-safe to
 * change while fitting). */
extern int jf__fixed_sizes;
int jf__eigvals(jf_fitter *f, size_t cols);
void jf__eigvals_x2(jf_fitter *f0, jf_fitter *f1, size_t cols, int ok[2]);
/* jf__eigvals_x4: the same for four fitters (same cols) at once. */
void jf__eigvals_x4(jf_fitter *const f[4], size_t cols, int ok[4]);
int jf__sym_eigvals(double *a, size_t n, double *d, double *e);
/* jf__gram_extremes (gram_eig.c): the largest and least eigenvalues of
 * the symmetric cols x cols g (2 <= cols <= 10), as jf__eigvals; 1 ok. */
int jf__gram_extremes(const double *g, size_t cols, double *hi, double *lo);
/* the same of four matrices g[0..3] (may repeat), ok[L] 1 where found:
 * each lane's bits are jf__gram_extremes' */
void jf__gram_extremes_x4(const double *const g[4], size_t cols, double hi[4], double lo[4],
                          int ok[4]);
int jf__solve_after_eig(jf_fitter *f, size_t rows, size_t cols, int have_eig, double *cond);

/* jet.c */
/* Makes GSL return error codes instead of aborting (once per process). */
void jf__gsl_init(void);

#endif /* JF_FITTER_INTERNAL_H */
