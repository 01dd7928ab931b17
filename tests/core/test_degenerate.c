/* test_degenerate.c -- degenerate neighbourhoods: collinear points, the
 * Kite (all neighbours on two lines through p, Fig. 3), duplicates,
 * N < N_n, points all equal, NaN input, a condition threshold, and
 * coordinates offset by 1e6.  Never a crash, always a named status, a
 * lower degree where one fits, and NaN (never garbage) where none does. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static uint64_t rng_state;
static double urand(void)
{
    return jf_unit(jf_splitmix64(&rng_state));
}

static jf_fitter *make(int degree, jf_fit_mode mode, double max_cond)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = degree;
    p.monge_degree = degree >= 4 ? 4 : (degree < 2 ? 2 : degree);
    p.fit = mode;
    p.max_cond = max_cond;
    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    return f;
}

static double surf(double x, double y) { return 0.3 * x * x - 0.2 * x * y + 0.5 * y * y + 0.1 * x; }

static void all_nan(const jf_result *r)
{
    ck_assert_int_eq(r->degree, 0);
    ck_assert(isnan(r->normal[0]) && isnan(r->k1) && isnan(r->k2) && isnan(r->d1[0]));
}

START_TEST(test_collinear)
{
    double xyz[3 * 20];
    for (int i = 0; i < 20; i++) {
        xyz[3 * i] = 0.1 * i;
        xyz[3 * i + 1] = -0.05 * i;
        xyz[3 * i + 2] = 0.02 * i;
    }
    for (int mode = 0; mode < 2; mode++) {
        jf_fitter *f = make(3, (jf_fit_mode)mode, 1e6);
        jf_result r;
        ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 20, &r), JF_OK);
        ck_assert(r.status & JF_PT_FAILED);
        ck_assert(r.status & (JF_PT_LOWERED_RANK | JF_PT_LOWERED_COND));
        all_nan(&r);
        jf_fitter_free(f);
    }
}
END_TEST

/* The Kite (Fig. 3): every neighbour on the lines y = 0 and x = 0 of the
 * tangent plane, alternately, nearest first; xy vanishes on both, so no
 * 2-jet is determined: degree 1 (LOWERED_RANK) with the exact tangent
 * plane at p, curvatures NaN, in both modes (interpolation keeps the 3
 * nearest, on both lines). */
START_TEST(test_kite)
{
    double xyz[3 * 17];
    xyz[0] = xyz[1] = xyz[2] = 0;
    for (int i = 1; i < 17; i++) {
        double t = (0.04 + 0.01 * i) * (i % 4 < 2 ? 1 : -1);
        double x = i % 2 ? t : 0, y = i % 2 ? 0 : t;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = 0.1 * x + 0.2 * y; /* a plane: the 1-jet is exact */
    }
    for (int mode = 0; mode < 2; mode++) {
        jf_fitter *f = make(2, (jf_fit_mode)mode, INFINITY);
        jf_result r;
        ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 17, &r), JF_OK);
        ck_assert_int_eq(r.degree, 1);
        ck_assert(r.status & JF_PT_LOWERED_RANK);
        ck_assert(!(r.status & JF_PT_FAILED));
        const double w = sqrt(1 + 0.01 + 0.04);
        ck_assert_double_eq_tol(fabs(r.normal[0]), 0.1 / w, 1e-12);
        ck_assert_double_eq_tol(fabs(r.normal[1]), 0.2 / w, 1e-12);
        ck_assert_double_eq_tol(fabs(r.normal[2]), 1 / w, 1e-12);
        ck_assert(isnan(r.k1) && isnan(r.k2));
        ck_assert(isfinite(r.d1[0]) && isfinite(r.d2[0]));
        ck_assert_int_eq(r.n_used, mode ? 3 : 17);
        jf_fitter_free(f);
    }
}
END_TEST

/* Duplicates: approximation with every point twice solves the same least
 * squares problem; interpolation on duplicates is rank deficient and
 * lowers the degree, keeping the N_{n-1} nearest points. */
START_TEST(test_duplicates)
{
    double xyz[3 * 40];
    rng_state = 77;
    for (int i = 0; i < 20; i++) {
        double x = i ? 0.3 * (2 * urand() - 1) : 0, y = i ? 0.3 * (2 * urand() - 1) : 0;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = surf(x, y);
    }
    memcpy(xyz + 60, xyz, 60 * sizeof(double));
    jf_fitter *f = make(2, JF_FIT_APPROX, 1e6);
    jf_result r1, r2;
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 20, &r1), JF_OK);
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 40, &r2), JF_OK);
    ck_assert_int_eq(r2.degree, 2);
    ck_assert_double_eq_tol(r1.k1, r2.k1, 1e-12);
    ck_assert_double_eq_tol(r1.k2, r2.k2, 1e-12);
    ck_assert_double_eq_tol(r1.normal[2], r2.normal[2], 1e-12);
    jf_fitter_free(f);
    /* interpolation: points 0..5 each twice (N_2 = 6): duplicates are
     * skipped, the 6 distinct points give the same 2-jet as without them */
    double dup[3 * 12];
    for (int i = 0; i < 6; i++) {
        memcpy(dup + 6 * i, xyz + 3 * i, 3 * sizeof(double));
        memcpy(dup + 6 * i + 3, xyz + 3 * i, 3 * sizeof(double));
    }
    f = make(2, JF_FIT_INTERP, 1e6);
    ck_assert_int_eq(jf_fit_point(f, xyz, dup, 12, &r1), JF_OK);
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 6, &r2), JF_OK);
    ck_assert_int_eq(r1.degree, 2);
    ck_assert_int_eq(r1.n_used, 6);
    ck_assert_uint_eq(r1.status, 0);
    ck_assert_double_eq_tol(r1.k1, r2.k1, 1e-10);
    ck_assert_double_eq_tol(r1.k2, r2.k2, 1e-10);
    /* but 6 points of which only 2 are distinct: no fit at all */
    for (int i = 0; i < 6; i++) memcpy(dup + 3 * i, xyz + 3 * (i % 2), 3 * sizeof(double));
    ck_assert_int_eq(jf_fit_point(f, xyz, dup, 6, &r1), JF_OK);
    ck_assert(r1.status & JF_PT_FAILED);
    ck_assert(r1.status & JF_PT_LOWERED_FEW);
    jf_fitter_free(f);
}
END_TEST

START_TEST(test_too_few)
{
    double xyz[3 * 8];
    rng_state = 5;
    for (int i = 0; i < 8; i++) {
        double x = i ? 2 * urand() - 1 : 0, y = i ? 2 * urand() - 1 : 0;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = surf(x, y);
    }
    jf_fitter *f = make(3, JF_FIT_APPROX, 1e6); /* N_3 = 10 > 8 */
    jf_result r;
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 8, &r), JF_OK);
    ck_assert_int_eq(r.degree, 2);
    ck_assert_uint_eq(r.status & ~(unsigned)JF_PT_UMBILIC, JF_PT_LOWERED_FEW);
    ck_assert(isnan(r.b[0])); /* asked for b: a 2-jet has none */
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 2, &r), JF_OK);
    ck_assert(r.status & JF_PT_FAILED);
    ck_assert(r.status & JF_PT_LOWERED_FEW);
    all_nan(&r);
    ck_assert_int_eq(jf_fit_point(f, xyz, NULL, 0, &r), JF_OK);
    ck_assert(r.status & JF_PT_FAILED);
    /* all points equal */
    double same[3 * 12];
    for (int i = 0; i < 36; i++) same[i] = 1.5;
    ck_assert_int_eq(jf_fit_point(f, same, same, 12, &r), JF_OK);
    ck_assert(r.status & JF_PT_FAILED);
    all_nan(&r);
    jf_fitter_free(f);
}
END_TEST

/* NaN: a NaN p is NONFINITE; NaN neighbours are left out (bit-identical to
 * the fit without them); huge coordinates do not crash. */
START_TEST(test_nonfinite)
{
    double xyz[3 * 30], clean[3 * 30];
    rng_state = 8;
    int m = 0;
    for (int i = 0; i < 30; i++) {
        double x = i ? 0.2 * (2 * urand() - 1) : 0, y = i ? 0.2 * (2 * urand() - 1) : 0;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = surf(x, y);
        if (i % 7 == 3) xyz[3 * i + (i % 3)] = i % 2 ? NAN : INFINITY;
        else {
            memcpy(clean + 3 * m, xyz + 3 * i, 3 * sizeof(double));
            m++;
        }
    }
    jf_fitter *f = make(2, JF_FIT_APPROX, 1e6);
    jf_result r1, r2;
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 30, &r1), JF_OK);
    ck_assert_int_eq(jf_fit_point(f, clean, clean, (size_t)m, &r2), JF_OK);
    ck_assert(memcmp(&r1, &r2, sizeof r1) == 0);
    double res[30];
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 30, &r1), JF_OK);
    ck_assert_int_eq(jf_fitter_residuals(f, res, 30), JF_OK);
    ck_assert(isnan(res[3]) && isfinite(res[4]));
    double pn[3] = {0, NAN, 0};
    ck_assert_int_eq(jf_fit_point(f, pn, xyz, 30, &r1), JF_OK);
    ck_assert_uint_eq(r1.status, JF_PT_NONFINITE);
    all_nan(&r1);
    xyz[3 * 5] = 1e300;
    xyz[3 * 6 + 2] = -1e300;
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 30, &r1), JF_OK);
    ck_assert(r1.status != 0);
    jf_fitter_free(f);
}
END_TEST

/* A condition threshold below kappa of the 4-jet lowers the degree; the
 * reported kappa is that of the degree used, within the threshold. */
START_TEST(test_max_cond)
{
    double xyz[3 * 40];
    rng_state = 12;
    for (int i = 0; i < 40; i++) {
        double x = i ? 0.2 * (2 * urand() - 1) : 0, y = i ? 0.2 * (2 * urand() - 1) : 0;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = surf(x, y);
    }
    jf_fitter *f = make(4, JF_FIT_APPROX, INFINITY);
    jf_result r;
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 40, &r), JF_OK);
    ck_assert_int_eq(r.degree, 4);
    double k4 = r.cond;
    jf_fitter_free(f);
    f = make(4, JF_FIT_APPROX, k4 * 0.999);
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 40, &r), JF_OK);
    ck_assert_int_lt(r.degree, 4);
    ck_assert(r.status & JF_PT_LOWERED_COND);
    ck_assert(r.cond <= k4 * 0.999);
    jf_fitter_free(f);
    f = make(4, JF_FIT_APPROX, 1.0); /* nothing but kappa = 1 passes */
    ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 40, &r), JF_OK);
    ck_assert(r.status & JF_PT_FAILED);
    ck_assert(r.status & JF_PT_LOWERED_COND);
    jf_fitter_free(f);
}
END_TEST

/* Offset 1e6: translating to p before anything else keeps full precision.
 * The same local patch, near the origin and offset (exactly representable
 * offsets; the offset coordinates round to ~1e-10), gives the same result
 * to 1e-7 in both frames, and in the axis frame the analytic curvatures of
 * the graph (its 2-jet is exact); one-pass world-coordinate covariance
 * sums lose everything here (docs/design.md "CGAL 5.5.1"). */
START_TEST(test_offset_1e6)
{
    const double off[3] = {1e6, -2e6, 5e5};
    double loc[3 * 30], xyz[3 * 30];
    rng_state = 99;
    for (int i = 0; i < 30; i++) {
        double x = i ? 0.05 * (2 * urand() - 1) : 0, y = i ? 0.05 * (2 * urand() - 1) : 0;
        loc[3 * i] = x;
        loc[3 * i + 1] = y;
        loc[3 * i + 2] = 0.3 * x * x - 0.2 * x * y + 0.5 * y * y;
        for (int k = 0; k < 3; k++) xyz[3 * i + k] = off[k] + loc[3 * i + k];
    }
    /* analytic: Hessian [[0.6, -0.2], [-0.2, 1.0]], gradient 0 at p */
    const double mean = 0.8, rad = sqrt(0.2 * 0.2 + 0.2 * 0.2);
    for (int fr = 0; fr < 2; fr++) {
        jf_params p;
        jf_params_init(&p);
        p.frame = (jf_frame_mode)fr;
        jf_fitter *f;
        ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
        jf_result r, r0;
        ck_assert_int_eq(jf_fit_point(f, xyz, xyz, 30, &r), JF_OK);
        ck_assert_int_eq(jf_fit_point(f, loc, loc, 30, &r0), JF_OK);
        ck_assert_uint_eq(r.status, 0);
        ck_assert_double_eq_tol(r.k1, r0.k1, 1e-7);
        ck_assert_double_eq_tol(r.k2, r0.k2, 1e-7);
        for (int k = 0; k < 3; k++) ck_assert_double_eq_tol(r.normal[k], r0.normal[k], 1e-9);
        if (fr == JF_FRAME_AXIS) {
            ck_assert_double_eq_tol(r.k1, mean + rad, 1e-6);
            ck_assert_double_eq_tol(r.k2, mean - rad, 1e-6);
            ck_assert_double_eq_tol(r.normal[2], 1, 1e-9);
        }
        jf_fitter_free(f);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("degenerate");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_collinear);
    tcase_add_test(tc, test_kite);
    tcase_add_test(tc, test_duplicates);
    tcase_add_test(tc, test_too_few);
    tcase_add_test(tc, test_nonfinite);
    tcase_add_test(tc, test_max_cond);
    tcase_add_test(tc, test_offset_1e6);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
