/* test_curve.c -- plane-curve jets (§4): exact recovery, circle (dk = 0),
 * curvature and dk/ds of y = x^3 + x^2/2 against analytic values (dk/ds
 * also by finite differences of the analytic k), degenerate inputs. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static jf_fitter *make(double max_cond)
{
    jf_params p;
    jf_params_init(&p);
    p.max_cond = max_cond;
    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    return f;
}

/* symmetric samples of y = 0.3 x^2: the PCA x axis is the world x axis,
 * so the 2-jet is the parabola itself */
START_TEST(test_curve_exact)
{
    jf_fitter *f = make(INFINITY);
    const double xs[7] = {0, -0.5, 0.5, -0.25, 0.25, -1, 1};
    double xy[14], p[2] = {0, 0};
    for (int i = 0; i < 7; i++) {
        xy[2 * i] = xs[i];
        xy[2 * i + 1] = 0.3 * xs[i] * xs[i];
    }
    for (int mode = 0; mode < 2; mode++) {
        jf_curve_result r;
        size_t n = mode ? 3 : 7;
        ck_assert_int_eq(jf_fit_curve(f, p, xy, n, 2, (jf_fit_mode)mode, &r), JF_OK);
        ck_assert_uint_eq(r.status, 0);
        ck_assert_int_eq(r.degree, 2);
        ck_assert_double_eq_tol(r.coef[0], 0, 1e-14);
        ck_assert_double_eq_tol(r.coef[1], 0, 1e-14);
        ck_assert_double_eq_tol(r.coef[2], 0.3, 1e-13);
        ck_assert_double_eq_tol(r.k, 0.6, 1e-13);
        ck_assert_double_eq_tol(r.tangent[0], 1, 1e-14);
        ck_assert_double_eq_tol(r.normal[1], 1, 1e-14);
        ck_assert(r.dk == 0.0); /* degree 2 asked: dk not computed */
    }
    /* degree 3 on a parabola: dk/ds = -3 f' f''^2 / (1+f'^2)^3 = 0 at x=0 */
    jf_curve_result r;
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 7, 3, JF_FIT_APPROX, &r), JF_OK);
    ck_assert_double_eq_tol(r.coef[3], 0, 1e-13);
    ck_assert_double_eq_tol(r.dk, 0, 1e-12);
    jf_fitter_free(f);
}
END_TEST

/* circle of radius R through p: |k| = 1/R, positive when the normal points
 * to the centre, dk/ds = 0 */
START_TEST(test_curve_circle)
{
    jf_fitter *f = make(INFINITY);
    const double R = 2.0, c[2] = {0.3, -0.7};
    for (int t = 0; t < 8; t++) {
        double phi = 0.4 + t * 0.8, xy[2 * 21], p[2];
        p[0] = c[0] + R * cos(phi);
        p[1] = c[1] + R * sin(phi);
        for (int i = 0; i < 21; i++) {
            double a = phi + 0.005 * (i - 10) * (1 + 0.1 * (i % 3));
            xy[2 * i] = c[0] + R * cos(a);
            xy[2 * i + 1] = c[1] + R * sin(a);
        }
        jf_curve_result r;
        ck_assert_int_eq(jf_fit_curve(f, p, xy, 21, 7, JF_FIT_APPROX, &r), JF_OK);
        ck_assert_int_eq(r.degree, 7);
        double toc = r.normal[0] * (c[0] - p[0]) + r.normal[1] * (c[1] - p[1]);
        double k = toc > 0 ? r.k : -r.k;
        ck_assert_double_eq_tol(k, 1 / R, 1e-7);
        ck_assert_double_eq_tol(fabs(toc), R, 1e-7); /* normal radial */
        ck_assert_double_eq_tol(r.dk, 0, 1e-5);
        ck_assert_double_eq_tol(r.tangent[0] * r.normal[0] + r.tangent[1] * r.normal[1], 0,
                                1e-15);
        /* (tangent, normal) is direct */
        ck_assert_double_eq_tol(r.tangent[0] * r.normal[1] - r.tangent[1] * r.normal[0], 1,
                                1e-15);
    }
    jf_fitter_free(f);
}
END_TEST

static double kcub(double x) /* curvature of y = x^3 + x^2/2 */
{
    double f1 = 3 * x * x + x, f2 = 6 * x + 1;
    return f2 / pow(1 + f1 * f1, 1.5);
}

/* y = x^3 + x^2/2 at x0: k and dk/ds (along +x) analytic; dk/ds is also
 * checked against a central difference of k(x) divided by ds/dx. */
START_TEST(test_curve_cubic_dk)
{
    jf_fitter *f = make(INFINITY);
    const double x0s[3] = {-0.4, 0.1, 0.3};
    for (int t = 0; t < 3; t++) {
        double x0 = x0s[t], p[2] = {x0, x0 * x0 * x0 + 0.5 * x0 * x0}, xy[2 * 25];
        for (int i = 0; i < 25; i++) {
            double x = x0 + 0.0025 * (i - 12) + 0.0005 * ((i * 7) % 5);
            xy[2 * i] = x;
            xy[2 * i + 1] = x * x * x + 0.5 * x * x;
        }
        jf_curve_result r;
        ck_assert_int_eq(jf_fit_curve(f, p, xy, 25, 6, JF_FIT_APPROX, &r), JF_OK);
        ck_assert_int_eq(r.degree, 6);
        double f1 = 3 * x0 * x0 + x0, f2 = 6 * x0 + 1, f3 = 6, q = 1 + f1 * f1;
        double k = f2 / pow(q, 1.5);
        double dk = (f3 * q - 3 * f1 * f2 * f2) / (q * q * q);
        double e = 1e-5, dkfd = (kcub(x0 + e) - kcub(x0 - e)) / (2 * e) / sqrt(q);
        ck_assert_double_eq_tol(dk, dkfd, 1e-6 * fmax(1, fabs(dk)));
        /* orient as the graph: tangent along +x, normal to +y */
        double sgn = r.tangent[0] > 0 ? 1 : -1;
        ck_assert_double_eq_tol(r.tangent[0] * sgn, 1 / sqrt(q), 1e-8);
        ck_assert_double_eq_tol(r.tangent[1] * sgn, f1 / sqrt(q), 1e-8);
        if (getenv("JF_VERBOSE")) printf("x0 %g: k err %.3g dk err %.3g t err %.3g\n", x0, r.k * sgn - k, r.dk - dk, r.tangent[1] * sgn - f1 / sqrt(q));
        ck_assert_double_eq_tol(r.k * sgn, k, 1e-7 * fabs(k));
        /* reversing s and the normal together: dk/ds keeps its sign */
        ck_assert_double_eq_tol(r.dk, dk, 1e-5 * fmax(1, fabs(dk)));
    }
    jf_fitter_free(f);
}
END_TEST

START_TEST(test_curve_degenerate)
{
    jf_fitter *f = make(1e6);
    double xy[2 * 300], p[2] = {1, 1};
    jf_curve_result r;
    for (int i = 0; i < 300; i++) xy[i] = 1;
    /* all samples equal: no fit, NaN, named */
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 10, 2, JF_FIT_APPROX, &r), JF_OK);
    ck_assert(r.status & JF_PT_FAILED);
    ck_assert(isnan(r.k) && isnan(r.normal[0]));
    /* two distinct points: degree 1 (a line), lowered for lack of points */
    xy[2] = 2;
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 2, 3, JF_FIT_APPROX, &r), JF_OK);
    ck_assert_int_eq(r.degree, 1);
    ck_assert(r.status & JF_PT_LOWERED_FEW);
    ck_assert(isnan(r.k));
    ck_assert_double_eq_tol(fabs(r.tangent[0]), 1, 1e-15);
    /* NaN samples are skipped; a NaN p is NONFINITE */
    xy[4] = NAN;
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 3, 1, JF_FIT_APPROX, &r), JF_OK);
    ck_assert_int_eq(r.degree, 1);
    double pn[2] = {NAN, 0};
    ck_assert_int_eq(jf_fit_curve(f, pn, xy, 3, 1, JF_FIT_APPROX, &r), JF_OK);
    ck_assert_uint_eq(r.status, JF_PT_NONFINITE);
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 300, 2, JF_FIT_APPROX, &r), JF_ERR_TOO_LARGE);
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 3, 0, JF_FIT_APPROX, &r), JF_ERR_INVALID);
    ck_assert_int_eq(jf_fit_curve(f, p, xy, 3, 10, JF_FIT_APPROX, &r), JF_ERR_INVALID);
    ck_assert_int_eq(jf_fit_curve(f, p, NULL, 3, 2, JF_FIT_APPROX, &r), JF_ERR_INVALID);
    jf_fitter_free(f);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("curve");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_curve_exact);
    tcase_add_test(tc, test_curve_circle);
    tcase_add_test(tc, test_curve_cubic_dk);
    tcase_add_test(tc, test_curve_degenerate);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
