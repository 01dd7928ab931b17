/* test_jet.c -- the jet fit on polynomial height functions: exact recovery
 * of the coefficients (interpolation and approximation, axis and PCA
 * frames), the paraboloid of the paper's Fig. 1, parameters, residuals,
 * and "no hidden state". */
#include <check.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_linalg.h>

#include "fitter_internal.h"
#include "jetfit.h"
#include "jf_test.h"

/* splitmix64: a small deterministic PRNG (no libc rand state) */
static uint64_t rng_state;
static double urand(void)
{
    return jf_unit(jf_splitmix64(&rng_state));
}

#define IDX(i, j) (((i) + (j)) * ((i) + (j) + 1) / 2 + (j))

static double poly_eval(const double *a, int deg, double x, double y)
{
    double z = 0;
    for (int k = 0; k <= deg; k++)
        for (int j = 0; j <= k; j++) z += a[IDX(k - j, j)] * pow(x, k - j) * pow(y, j);
    return z;
}

/* n samples (x,y) uniform in [-s,s]^2, z = poly; p = the origin sample */
static void sample_poly(const double *a, int deg, size_t n, double s, double *xyz)
{
    xyz[0] = 0;
    xyz[1] = 0;
    xyz[2] = a[0];
    for (size_t i = 1; i < n; i++) {
        double x = s * (2 * urand() - 1), y = s * (2 * urand() - 1);
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = poly_eval(a, deg, x, y);
    }
}

static const double origin[3] = {0, 0, 0};

static jf_fitter *make_fitter(int degree, int monge, jf_fit_mode fit, jf_frame_mode frame)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = degree;
    p.monge_degree = monge;
    p.fit = fit;
    p.frame = frame;
    p.max_cond = INFINITY;
    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    return f;
}

/* The paper's Fig. 1 surface z = 2x^2 + y^2: k1 = 4, k2 = 2 at the origin,
 * d1 = +-x, d2 = +-y, normal +z (the fitting frame's +z side). */
START_TEST(test_paraboloid)
{
    static const jf_fit_mode fits[2] = {JF_FIT_APPROX, JF_FIT_INTERP};
    static const jf_frame_mode frames[2] = {JF_FRAME_AXIS, JF_FRAME_PCA};
    const double a[6] = {0, 0, 0, 2, 0, 1};
    double xyz[3 * 40];
    rng_state = 1;
    sample_poly(a, 2, 40, 0.1, xyz);
    for (int deg = 2; deg <= 4; deg++)
        for (int fi = 0; fi < 2; fi++)
            for (int fr = 0; fr < 2; fr++) {
                /* the PCA frame tilts away from z: a 2-jet in the PCA frame
                 * is only approximate, so test it with degree 4 only */
                if (frames[fr] == JF_FRAME_PCA) continue;
                jf_fitter *f = make_fitter(deg, 2, fits[fi], frames[fr]);
                jf_result r;
                size_t n = fits[fi] == JF_FIT_INTERP ? jf_jet_size(deg) + 5 : 40;
                ck_assert_int_eq(jf_fit_point(f, xyz, xyz, n, &r), JF_OK);
                ck_assert_uint_eq(r.status, 0);
                ck_assert_int_eq(r.degree, deg);
                ck_assert_double_eq_tol(r.k1, 4.0, 1e-9);
                ck_assert_double_eq_tol(r.k2, 2.0, 1e-9);
                ck_assert_double_eq_tol(fabs(r.d1[0]), 1.0, 1e-9);
                ck_assert_double_eq_tol(fabs(r.d2[1]), 1.0, 1e-9);
                ck_assert_double_eq_tol(r.normal[2], 1.0, 1e-12);
                /* d1 x d2 = n */
                double c2 = r.d1[0] * r.d2[1] - r.d1[1] * r.d2[0];
                ck_assert_double_eq_tol(c2, 1.0, 1e-12);
                ck_assert(r.residual < 1e-12);
                jf_fitter_free(f);
            }
}
END_TEST


/* coefficients of P(a x + b y, c x + d y) (independent of monge.c) */
static void compose_linear(const double *pa, int deg, double a, double b, double c,
                           double d, double *out)
{
    static const double binom[10][10] = {
        {1}, {1, 1}, {1, 2, 1}, {1, 3, 3, 1}, {1, 4, 6, 4, 1}, {1, 5, 10, 10, 5, 1},
        {1, 6, 15, 20, 15, 6, 1}, {1, 7, 21, 35, 35, 21, 7, 1},
        {1, 8, 28, 56, 70, 56, 28, 8, 1}, {1, 9, 36, 84, 126, 126, 84, 36, 9, 1}};
    memset(out, 0, jf_jet_size(deg) * sizeof *out);
    for (int k = 0; k <= deg; k++)
        for (int j = 0; j <= k; j++) {
            int i = k - j; /* (a x + b y)^i (c x + d y)^j */
            for (int p = 0; p <= i; p++)
                for (int q = 0; q <= j; q++) {
                    double t = pa[IDX(i, j)] * binom[i][p] * pow(a, i - p) * pow(b, p) *
                               binom[j][q] * pow(c, j - q) * pow(d, q);
                    out[IDX(i - p + j - q, p + q)] += t;
                }
        }
}

static void random_poly(int deg, double scale, double *a)
{
    for (size_t c = 0; c < jf_jet_size(deg); c++) a[c] = scale * (2 * urand() - 1);
    a[0] = 0.05 * (2 * urand() - 1);
}

static void check_coef(const jf_fitter *f, const double *want, int deg)
{
    double big = 0;
    for (size_t c = 0; c < jf_jet_size(deg); c++) big = fmax(big, fabs(want[c]));
    ck_assert_int_eq(f->last_deg, deg);
    for (size_t c = 0; c < jf_jet_size(deg); c++)
        ck_assert_msg(fabs(f->coef[c] - want[c]) <= 1e-9 * big,
                      "deg %d coef %zu: got %.17g want %.17g", deg, c, f->coef[c], want[c]);
}

/* Exact recovery, axis frame: z = P(x,y) of degree <= n over the world xy
 * plane is fitted exactly by an n-jet (interpolation with N_n points,
 * approximation with 3 N_n); the frame is the identity. */
START_TEST(test_exact_axis)
{
    rng_state = 42;
    for (int n = 1; n <= JF_MAX_DEGREE; n++)
        for (int pd = (n > 1 ? n - 1 : n); pd <= n; pd++)
            for (int fi = 0; fi < 2; fi++) {
                double a[55] = {0}, xyz[3 * 165];
                random_poly(pd, 0.1, a);
                size_t nn = fi ? jf_jet_size(n) : 3 * jf_jet_size(n);
                sample_poly(a, pd, nn, 1.0, xyz);
                jf_fitter *f = make_fitter(n, n >= 4 ? 4 : (n < 2 ? 2 : n),
                                           fi ? JF_FIT_INTERP : JF_FIT_APPROX, JF_FRAME_AXIS);
                jf_result r;
                ck_assert_int_eq(jf_fit_point(f, origin, xyz, nn, &r), JF_OK);
                ck_assert_msg((r.status & ~(unsigned)JF_PT_UMBILIC) == 0, "n %d status %u cond %g", n, r.status, r.cond);
                ck_assert_int_eq(r.n_used, (int)nn);
                static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
                for (int k = 0; k < 9; k++) ck_assert(f->frame[k] == id[k]);
                check_coef(f, a, n);
                jf_fitter_free(f);
            }
}
END_TEST

/* Exact recovery, PCA frame: the samples of z = P(x,y) are made to have
 * cov(x,z) = cov(y,z) = 0 (by choosing A10, A01), so the PCA normal is the
 * local z axis; the cloud is then rotated by a known Q and translated.  The
 * reported frame R must be Q up to a rotation S about z (and a pinned sign),
 * and the coefficients those of S33 P(S2^T (x,y)). */
START_TEST(test_exact_pca)
{
    rng_state = 7;
    const double ang[3] = {0.7, -0.4, 1.1};
    double q[9]; /* Q = Rz(ang2) Ry(ang1) Rx(ang0): rows = local axes */
    {
        double cx = cos(ang[0]), sx = sin(ang[0]), cy = cos(ang[1]), sy = sin(ang[1]);
        double cz = cos(ang[2]), sz = sin(ang[2]);
        double m[9] = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                       sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                       -sy,     cy * sx,                cy * cx};
        memcpy(q, m, sizeof m);
    }
    const double off[3] = {0.3, -0.2, 0.1};
    for (int n = 2; n <= 7; n++)
        for (int fi = 0; fi < 2; fi++) {
            double a[55] = {0}, loc[3 * 108], xyz[3 * 108];
            random_poly(n, 0.05, a);
            size_t nn = fi ? jf_jet_size(n) : 3 * jf_jet_size(n);
            sample_poly(a, n, nn, 1.0, loc);
            /* choose A10, A01 so that the sample covariances (x,z), (y,z)
             * vanish: a 2x2 linear system in (A10, A01) */
            double mx = 0, my = 0;
            for (size_t i = 0; i < nn; i++) {
                mx += loc[3 * i] / nn;
                my += loc[3 * i + 1] / nn;
            }
            double sxx = 0, sxy = 0, syy = 0, rx = 0, ry = 0;
            a[1] = a[2] = 0;
            for (size_t i = 0; i < nn; i++) {
                double dx = loc[3 * i] - mx, dy = loc[3 * i + 1] - my;
                double z = poly_eval(a, n, loc[3 * i], loc[3 * i + 1]);
                sxx += dx * dx;
                sxy += dx * dy;
                syy += dy * dy;
                rx -= dx * z;
                ry -= dy * z;
            }
            double det = sxx * syy - sxy * sxy;
            a[1] = (rx * syy - ry * sxy) / det;
            a[2] = (sxx * ry - sxy * rx) / det;
            for (size_t i = 0; i < nn; i++) {
                loc[3 * i + 2] = poly_eval(a, n, loc[3 * i], loc[3 * i + 1]);
                for (int k = 0; k < 3; k++) /* world = Q^T local + off */
                    xyz[3 * i + k] = off[k] + q[k] * loc[3 * i] + q[3 + k] * loc[3 * i + 1] +
                                     q[6 + k] * loc[3 * i + 2];
            }
            jf_fitter *f = make_fitter(n, n >= 4 ? 4 : n, fi ? JF_FIT_INTERP : JF_FIT_APPROX,
                                       JF_FRAME_PCA);
            jf_result r;
            ck_assert_int_eq(jf_fit_point(f, off, xyz, nn, &r), JF_OK);
            ck_assert_uint_eq(r.status, 0);
            double s[9]; /* S = R Q^T */
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    s[3 * i + j] = f->frame[3 * i] * q[3 * j] + f->frame[3 * i + 1] * q[3 * j + 1] +
                                   f->frame[3 * i + 2] * q[3 * j + 2];
            ck_assert_double_eq_tol(s[2], 0, 1e-12);
            ck_assert_double_eq_tol(s[5], 0, 1e-12);
            ck_assert_double_eq_tol(fabs(s[8]), 1, 1e-12);
            /* (x, y) = S2^T (X, Y): x = s0 X + s3 Y, y = s1 X + s4 Y */
            double want[55];
            compose_linear(a, n, s[0], s[3], s[1], s[4], want);
            for (size_t c = 0; c < jf_jet_size(n); c++) want[c] *= s[8];
            check_coef(f, want, n);
            jf_fitter_free(f);
        }
}
END_TEST

/* Residuals: z_i - J(x_i, y_i) in the fitting frame; least squares makes
 * them orthogonal to every monomial column; the result's residual is their
 * RMS.  An outlier of weight 0 does not disturb an exact fit. */
START_TEST(test_residuals_weights)
{
    rng_state = 3;
    double a[10] = {0.01, 0.02, -0.03, 0.4, 0.1, -0.2, 0.05, 0.02, -0.01, 0.03};
    double xyz[3 * 30], w[30], res[30];
    sample_poly(a, 3, 30, 0.5, xyz);
    xyz[3 * 7 + 2] += 0.01; /* one perturbed sample */
    jf_fitter *f = make_fitter(3, 3, JF_FIT_APPROX, JF_FRAME_AXIS);
    jf_result r;
    ck_assert_int_eq(jf_fit_point(f, origin, xyz, 30, &r), JF_OK);
    ck_assert_int_eq(jf_fitter_residuals(f, res, 29), JF_ERR_INVALID);
    ck_assert_int_eq(jf_fitter_residuals(f, res, 30), JF_OK);
    double ss = 0;
    for (int k = 0; k <= 3; k++)
        for (int j = 0; j <= k; j++) {
            double dot = 0;
            for (int i = 0; i < 30; i++)
                dot += res[i] * pow(xyz[3 * i], k - j) * pow(xyz[3 * i + 1], j);
            ck_assert_double_eq_tol(dot, 0, 1e-13); /* ~ kappa eps |r| |m| */
        }
    for (int i = 0; i < 30; i++) {
        double z = poly_eval(f->coef, 3, xyz[3 * i], xyz[3 * i + 1]);
        ck_assert_double_eq_tol(res[i], xyz[3 * i + 2] - z, 1e-15);
        ss += res[i] * res[i];
    }
    ck_assert(res[7] > 1e-3);
    ck_assert_double_eq_tol(r.residual, sqrt(ss / 30), 1e-15);
    for (int i = 0; i < 30; i++) w[i] = i == 7 ? 0.0 : 1.0;
    ck_assert_int_eq(jf_fit_point_weighted(f, origin, xyz, w, 30, &r), JF_OK);
    ck_assert_int_eq(r.n_used, 29);
    check_coef(f, a, 3);
    ck_assert(r.residual < 1e-15);
    ck_assert_int_eq(jf_fitter_residuals(f, res, 30), JF_OK);
    ck_assert_double_eq_tol(res[7], 0.01, 1e-12);
    w[3] = -1;
    ck_assert_int_eq(jf_fit_point_weighted(f, origin, xyz, w, 30, &r), JF_ERR_INVALID);
    w[3] = NAN;
    ck_assert_int_eq(jf_fit_point_weighted(f, origin, xyz, w, 30, &r), JF_ERR_INVALID);
    jf_fitter_free(f);
}
END_TEST

/* No hidden state: a fitter reused on other (and failing) neighbourhoods
 * gives bit-identical results to a fresh one. */
START_TEST(test_no_hidden_state)
{
    static const jf_fit_mode fits[2] = {JF_FIT_APPROX, JF_FIT_INTERP};
    rng_state = 11;
    double a[15], xyz[3 * 60], other[3 * 60];
    random_poly(4, 0.3, a);
    sample_poly(a, 4, 60, 0.3, xyz);
    for (int fi = 0; fi < 2; fi++)
        for (int fr = 0; fr < 2; fr++) {
            jf_fitter *fresh = make_fitter(4, 4, fits[fi], (jf_frame_mode)fr);
            jf_fitter *used = make_fitter(4, 4, fits[fi], (jf_frame_mode)fr);
            jf_result r0, r1, junk;
            double res0[60], res1[60];
            for (int t = 0; t < 20; t++) {
                for (int i = 0; i < 3 * 60; i++) other[i] = 2 * urand() - 1;
                if (t % 3 == 0) other[5] = NAN;
                if (t % 4 == 0)
                    for (int i = 1; i < 60; i++) /* collinear: fails */
                        other[3 * i] = other[3 * i + 1] = other[3 * i + 2] = i * 0.1;
                jf_fit_point(used, other, other, 10 + (size_t)t * 2, &junk);
            }
            ck_assert_int_eq(jf_fit_point(fresh, xyz, xyz, 60, &r0), JF_OK);
            ck_assert_int_eq(jf_fit_point(used, xyz, xyz, 60, &r1), JF_OK);
            ck_assert(memcmp(&r0, &r1, sizeof r0) == 0);
            jf_fitter_residuals(fresh, res0, 60);
            jf_fitter_residuals(used, res1, 60);
            ck_assert(memcmp(res0, res1, sizeof res0) == 0);
            jf_fitter_free(fresh);
            jf_fitter_free(used);
        }
}
END_TEST

/* A random rows x cols least-squares problem and GSL's answer: column j of
 * A scaled by grade^(j / (cols-1)), entries of A (column by column) then
 * of b uniform in [-1, 1) from urand(), stored column-major in a (leading
 * dimension rows) and in b; GSL's Golub-Reinsch SVD solution into x.
 * Returns GSL's kappa; *xn = max |x_j|. */
static double gsl_graded_lsq(size_t rows, size_t cols, double grade, double *a, double *b,
                             double *x, double *xn)
{
    gsl_matrix *ga = gsl_matrix_alloc(rows, cols), *v = gsl_matrix_alloc(cols, cols);
    gsl_vector *sv = gsl_vector_alloc(cols), *w = gsl_vector_alloc(cols);
    gsl_vector *gb = gsl_vector_alloc(rows), *gx = gsl_vector_alloc(cols);
    for (size_t j = 0; j < cols; j++) {
        double sc = pow(grade, (double)j / (double)(cols - 1));
        for (size_t i = 0; i < rows; i++) {
            a[j * rows + i] = sc * (2 * urand() - 1);
            gsl_matrix_set(ga, i, j, a[j * rows + i]);
        }
    }
    for (size_t i = 0; i < rows; i++) gsl_vector_set(gb, i, b[i] = 2 * urand() - 1);
    ck_assert_int_eq(gsl_linalg_SV_decomp(ga, v, sv, w), 0);
    ck_assert_int_eq(gsl_linalg_SV_solve(ga, v, sv, gb, gx), 0);
    double gcond = gsl_vector_get(sv, 0) / gsl_vector_get(sv, cols - 1);
    *xn = 0;
    for (size_t j = 0; j < cols; j++) {
        x[j] = gsl_vector_get(gx, j);
        *xn = fmax(*xn, fabs(x[j]));
    }
    gsl_matrix_free(ga);
    gsl_matrix_free(v);
    gsl_vector_free(sv);
    gsl_vector_free(w);
    gsl_vector_free(gb);
    gsl_vector_free(gx);
    return gcond;
}

/* The solver's solution f->sol agrees with GSL's x to ~ kappa eps. */
static void check_sol(const jf_fitter *f, const double *x, size_t cols, double gcond, double xn,
                      int t)
{
    for (size_t j = 0; j < cols; j++)
        ck_assert_msg(fabs(f->sol[j] - x[j]) <= 1e-14 * gcond * xn,
                      "t %d sol %zu: %.17g gsl %.17g (cond %g)", t, j, f->sol[j], x[j], gcond);
}

/* The solver (pivoted Householder QR + one-sided Jacobi SVD of R) against
 * GSL's Golub-Reinsch SVD of the whole matrix: kappa and the least-squares
 * solution on random tall matrices with graded columns (kappa up to
 * ~1e10), and the rank-deficiency verdict on a matrix with two equal
 * columns. */
START_TEST(test_solver_vs_gsl)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = 4;
    p.max_neighbors = 64;
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    rng_state = 1234;
    const size_t shapes[4][2] = {{6, 6}, {16, 6}, {32, 10}, {64, 15}};
    for (int t = 0; t < 40; t++) {
        size_t rows = shapes[t % 4][0], cols = shapes[t % 4][1];
        double grade = pow(10.0, -(double)(t % 11)); /* column scales 1 .. grade */
        double x[15], xn;
        double gcond = gsl_graded_lsq(rows, cols, grade, f->m, f->rhs, x, &xn);
        double cond;
        int rc = jf__svd_solve(f, rows, cols, &cond);
        ck_assert_int_eq(rc, 0);
        ck_assert_msg(fabs(cond - gcond) <= 1e-8 * gcond, "cond %g gsl %g", cond, gcond);
        check_sol(f, x, cols, gcond, xn, t);
    }
    /* rank deficient: column 3 = column 1 */
    for (size_t i = 0; i < 16; i++) {
        for (size_t j = 0; j < 6; j++) f->m[j * 16 + i] = 2 * urand() - 1;
        f->m[3 * 16 + i] = f->m[1 * 16 + i];
        f->rhs[i] = 1;
    }
    double cond;
    ck_assert_int_eq(jf__svd_solve(f, 16, 6, &cond), 1);
    ck_assert(cond > 1e14);
    jf_fitter_free(f);
}
END_TEST

/* The solver's fast path (kappa from the eigenvalues of R^T R, solution
 * by back-substitution; taken for kappa <= 1e3 away from max_cond) against
 * GSL's SVD: kappa to 1e-9 and the solution to ~kappa eps on matrices with
 * kappa from ~3 to ~3e3 (both sides of the switch to the Jacobi SVD);
 * and the adaptive degree's verdict (cond > max_cond) the same as the
 * SVD's when max_cond is within 1e-12 of kappa on either side (the fast
 * path's kappa is off by up to ~1e-11 there: it must not decide). */
START_TEST(test_solver_fast_path)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = 3;
    p.max_neighbors = 64;
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    rng_state = 99;
    const size_t shapes[3][2] = {{16, 6}, {32, 10}, {10, 10}};
    double a0[64 * 10], b0[64];
    for (int t = 0; t < 60; t++) {
        size_t rows = shapes[t % 3][0], cols = shapes[t % 3][1];
        double grade = pow(10.0, -0.1 * (double)(t % 30)); /* column scales 1 .. grade */
        double x[10], xn;
        double gcond = gsl_graded_lsq(rows, cols, grade, a0, b0, x, &xn);
        /* max_cond: off, just above kappa, just below kappa */
        const double maxc[3] = {INFINITY, gcond * (1 + 1e-12), gcond * (1 - 1e-12)};
        for (int u = 0; u < 3; u++) {
            memcpy(f->m, a0, rows * cols * sizeof *a0);
            memcpy(f->rhs, b0, rows * sizeof *b0);
            f->p.max_cond = maxc[u];
            double cond;
            ck_assert_int_eq(jf__svd_solve(f, rows, cols, &cond), 0);
            ck_assert_msg(fabs(cond - gcond) <= 1e-9 * gcond, "t %d cond %.17g gsl %.17g", t,
                          cond, gcond);
            if (u == 1) ck_assert_msg(cond <= maxc[u], "t %d: %.17g > %.17g", t, cond, maxc[u]);
            if (u == 2) ck_assert_msg(cond > maxc[u], "t %d: %.17g <= %.17g", t, cond, maxc[u]);
            check_sol(f, x, cols, gcond, xn, t);
        }
    }
    jf_fitter_free(f);
}
END_TEST

/* The fast path's kappa comes from the extreme eigenvalues of G = R^T R
 * by Laguerre's iteration (gram_eig.c).  Against GSL's SVD of M' on
 * graded matrices (kappa ~1 .. ~4e3): kappa to 1e-12 relative (measured
 * <= 2.2e-13; the QL of all eigenvalues it replaced was off by up to
 * 2.2e-9 there); against that QL (solve.c) on these and on matrices
 * with (nearly) multiple eigenvalues, where Laguerre converges slowest:
 * both extremes to 8 cols eps lambda_max; and two or four at once
 * (jf__eigvals_x2, jf__gram_extremes_x4) bit for bit as one at a time. */
START_TEST(test_gram_extremes)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = 3;
    p.max_neighbors = 64;
    jf_fitter *f, *g;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    ck_assert_int_eq(jf_fitter_create(&p, &g), JF_OK);
    rng_state = 7;
    double a0[64 * 10], b0[64], x[10], xn, gq[100], ev[10], sc[10], gx[100];
    int graded = 0;
    for (int t = 0; t < 400; t++) {
        size_t rows = t % 2 ? 32 : 16, cols = t % 2 ? 10 : 6;
        double gk = 0; /* GSL's kappa of M' */
        if (t % 4 < 2) { /* graded columns: kappa ~1 .. ~4e3 */
            gk = gsl_graded_lsq(rows, cols, pow(10.0, -0.1 * (double)(t % 35)), a0, b0, x, &xn);
        } else { /* H diag(c): G = diag(c^2) up to rounding, c with repeats */
            double v[32], vv = 0;
            for (size_t i = 0; i < rows; i++) {
                v[i] = 2 * urand() - 1;
                vv += v[i] * v[i];
            }
            for (size_t j = 0; j < cols; j++) {
                double c = 1.0 + (double)((j * (size_t)t) % 3);
                for (size_t i = 0; i < rows; i++)
                    a0[j * rows + i] = c * ((i == j) - 2 * v[i] * v[j] / vv);
                b0[j] = 0;
            }
        }
        for (int k = 0; k < 2; k++) {
            jf_fitter *h = k ? g : f;
            memcpy(h->m, a0, rows * cols * sizeof *a0);
            memcpy(h->rhs, b0, rows * sizeof *b0);
            ck_assert_int_eq(jf__qr_gram(h, rows, cols), 1);
        }
        memcpy(gq, f->x, cols * cols * sizeof *gq);
        memcpy(gx, f->x, cols * cols * sizeof *gx);
        ck_assert_int_eq(jf__sym_eigvals(gq, cols, ev, sc), 0);
        double lmax = 0, lmin = INFINITY;
        for (size_t j = 0; j < cols; j++) {
            lmax = fmax(lmax, ev[j]);
            lmin = fmin(lmin, ev[j]);
        }
        ck_assert_int_eq(jf__eigvals(f, cols), 1);
        const double tol = 8.0 * (double)cols * DBL_EPSILON * lmax;
        ck_assert_msg(fabs(f->s[0] - lmax) <= tol, "t %d max %.17g ql %.17g", t, f->s[0], lmax);
        ck_assert_msg(fabs(f->s[1] - lmin) <= tol, "t %d min %.17g ql %.17g", t, f->s[1], lmin);
        const double kl = sqrt(f->s[0] / f->s[1]);
        if (gk > 0) {
            graded++;
            ck_assert_msg(fabs(kl - gk) <= 1e-12 * gk, "t %d kappa %.17g gsl %.17g", t, kl, gk);
        }
        /* side by side: each lane as alone (g holds the same G) */
        memcpy(f->x, gx, cols * cols * sizeof *gx);
        const double s0 = f->s[0], s1 = f->s[1];
        int ok[2];
        jf__eigvals_x2(f, g, cols, ok);
        ck_assert(ok[0] && ok[1]);
        ck_assert(f->s[0] == s0 && f->s[1] == s1 && g->s[0] == s0 && g->s[1] == s1);
        /* four matrices (auto's lanes), this G in lane t % 4 beside others:
         * its lane as alone, AVX and default builds */
        double hi = 0, lo = 0, h4[4], l4[4];
        ck_assert_int_eq(jf__gram_extremes(gx, cols, &hi, &lo), 1);
        ck_assert(hi == s0 && lo == s1);
        double other[100];
        for (size_t j = 0; j < cols * cols; j++) other[j] = gx[j] * (1.0 + (j % (cols + 1) == 0));
        const double *g4[4] = {other, other, other, other};
        g4[t % 4] = gx;
        for (int avx = 0; avx < 2; avx++) {
            jf__no_avx = !avx;
            int o4[4];
            jf__gram_extremes_x4(g4, cols, h4, l4, o4);
            ck_assert(o4[t % 4] && h4[t % 4] == s0 && l4[t % 4] == s1);
        }
        jf__no_avx = 0;
    }
    ck_assert_int_eq(graded, 200);
    jf_fitter_free(f);
    jf_fitter_free(g);
}
END_TEST

START_TEST(test_params)
{
    jf_params p;
    const char *bad = "x";
    jf_params_init(&p);
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_OK);
    ck_assert_ptr_null(bad);
    ck_assert_int_eq(jf_jet_size(2), 6);
    ck_assert_int_eq(jf_jet_size(9), 55);
    p.degree = 0;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "degree");
    p.degree = 10;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    jf_params_init(&p);
    p.monge_degree = 3; /* > degree 2 */
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "monge_degree");
    jf_params_init(&p);
    p.degree = 1; /* degree 1 with the default monge_degree is valid */
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_OK);
    jf_params_init(&p);
    p.max_cond = NAN;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "max_cond");
    p.max_cond = 0.5;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    jf_params_init(&p);
    p.max_neighbors = 0;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "max_neighbors");
    jf_params_init(&p);
    p.nscales = 2;
    p.scales[0] = 32;
    p.scales[1] = 16;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "scales");
    ck_assert_int_eq(jf_params_validate(NULL, &bad), JF_ERR_INVALID);

    jf_fitter *f = (jf_fitter *)&p; /* must be reset to NULL on failure */
    p.nscales = 0;
    p.degree = 0;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_ERR_INVALID);
    ck_assert_ptr_null(f);
    jf_fitter_free(NULL);
    jf_params_init(&p);
    p.max_neighbors = 8;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    ck_assert_int_eq(jf_fitter_params(f)->max_neighbors, 8);
    double pts[3 * 9] = {0};
    jf_result r;
    ck_assert_int_eq(jf_fit_point(f, pts, pts, 9, &r), JF_ERR_TOO_LARGE);
    ck_assert_int_eq(jf_fit_point(f, pts, NULL, 3, &r), JF_ERR_INVALID);
    ck_assert_int_eq(jf_fit_point(f, NULL, pts, 3, &r), JF_ERR_INVALID);
    jf_fitter_free(f);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("jet");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_paraboloid);
    tcase_add_test(tc, test_exact_axis);
    tcase_add_test(tc, test_exact_pca);
    tcase_add_test(tc, test_residuals_weights);
    tcase_add_test(tc, test_no_hidden_state);
    tcase_add_test(tc, test_params);
    tcase_add_test(tc, test_solver_vs_gsl);
    tcase_add_test(tc, test_solver_fast_path);
    tcase_add_test(tc, test_gram_extremes);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
