/* fitter_internal.h -- the jf_fitter workspace and the helpers shared by
 * frame.c, jet.c, solve.c, monge.c and curve.c (not part of the public API). */
#ifndef JF_FITTER_INTERNAL_H
#define JF_FITTER_INTERNAL_H

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
};

/* frame.c */
/* Eigen-decomposition of the symmetric 3x3 matrix a (row-major) by cyclic
 * Jacobi: eval ascending, evec[3*k..] the unit eigenvector of eval[k]
 * with its largest-|component| positive.  Deterministic. */
void jf__eig3(const double a[9], double eval[3], double evec[9]);

/* Fitting frame (§5.2) of the local points q[3*i] (already translated to
 * p) with weights w[i] (> 0 used): two-pass weighted centred covariance,
 * PCA, then the axes ex, ey, ez (rows of r, right-handed) of the PCA or
 * world-axis frame.  Returns 0 on success, -1 if the covariance is not
 * finite or no weight is positive. */
int jf__frame(const double *q, const double *w, size_t n, jf_frame_mode mode,
              double r[9], double eval[3]);

/* monge.c */
/* Differential quantities of the jet A (fitting frame, degree deg, rows of
 * r = frame axes in world coordinates) into out: normal, k1, k2, d1, d2,
 * b, c (up to monge_degree), and JF_PT_UMBILIC.  Orders above deg are
 * NaN. */
void jf__quantities(const double *a, int deg, int monge_degree,
                    const double r[9], double h, jf_result *out);

/* Sets every quantity of out to NaN (FAILED / NONFINITE rows). */
void jf__result_nan(jf_result *out);

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

/* jet.c */
/* Makes GSL return error codes instead of aborting (once per process). */
void jf__gsl_init(void);

#endif /* JF_FITTER_INTERNAL_H */
