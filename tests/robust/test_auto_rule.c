/* test_auto_rule.c -- neighbors auto's diagnosis hook and rule knobs
 * (src/robust/auto_rule.c, robust_internal.h; docs/robustness.md
 * "Neighbourhood auto"): every candidate fit the hook reports
 * (bench_auto_diag's per-point errors) is jf_fit_point's jet of that
 * degree on that many nearest; the row auto reports is the hook's chosen
 * candidate, bit for bit; jf__auto_rule on the hook's candidates makes the
 * same choice; the auto_lof knob, set so that every K passes Lepski's
 * test, lets K grow (the knob is live); and step 2's flat test reads the
 * noise at the largest K where the residual variance is flat, not where
 * it grows. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "robust_internal.h"
#include "synth/surfaces.h"
#include "jf_test.h"

#define NPTS 1500

static jf_sample cloud(void)
{
    jf_sample s;
    jf_rng rng;
    jf_rng_seed(&rng, 11);
    ck_assert_int_eq(jf_sample_random(JF_SURF_TORUS, NPTS, JF_DENSITY_GRADIENT, &rng, &s), JF_OK);
    jf_noise_gauss(&s, 0.003, &rng);
    return s;
}

static jf_fitter *fitter(int degree, int autosel)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = degree;
    p.max_neighbors = JF_NB_AUTO_KMAX;
    p.auto_select = autosel;
    jf_fitter *f = NULL;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    return f;
}

/* the K nearest of point i into nb; returns how many */
static size_t nearest(const jf_index *ix, const jf_sample *s, size_t i, size_t k, double *nb)
{
    uint32_t idx[JF_NB_AUTO_KMAX];
    size_t got = 0;
    ck_assert_int_eq(jf_index_knn(ix, s->xyz + 3 * i, k, idx, NULL, &got), JF_OK);
    for (size_t j = 0; j < got; j++) memcpy(nb + 3 * j, s->xyz + 3 * (size_t)idx[j], 3 * sizeof(double));
    return got;
}

START_TEST(test_diag_candidates_are_the_jets)
{
    jf_sample s = cloud();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(s.xyz, s.n, &ix), JF_OK);
    jf_fitter *fa = fitter(2, 1), *fd[2] = {fitter(2, 0), fitter(3, 0)};
    static jf__auto_diag dg;
    ck_assert_int_eq(jf__auto_diag_attach(fa, &dg), 0);
    double nb[3 * JF_NB_AUTO_KMAX], nk[3 * JF_NB_AUTO_KMAX];
    for (size_t i = 0; i < s.n; i += 7) {
        size_t n = nearest(ix, &s, i, JF_NB_AUTO_KMAX, nb);
        memset(&dg, 0, sizeof dg);
        jf_result ra;
        ck_assert_int_eq(jf_fit_point_full(fa, s.xyz + 3 * i, nb, n, &ra), JF_OK);
        ck_assert_int_eq(dg.c.nc, JF_AUTO_NCAND);
        ck_assert(dg.ci >= 0 && dg.ci < dg.c.nc && (dg.d == 2 || dg.d == 3));
        /* the row is the chosen candidate's fit, bit for bit */
        const jf_result *rc = &dg.res[dg.d - 2][dg.ci];
        ck_assert_int_eq(memcmp(ra.normal, rc->normal, sizeof ra.normal), 0);
        ck_assert(ra.k1 == rc->k1 && ra.k2 == rc->k2);
        ck_assert_uint_eq((size_t)ra.n_used, dg.c.ks[dg.ci]);
        /* the rule on the reported candidates makes the same choice */
        int d = 0;
        ck_assert_int_eq(jf__auto_rule(jf__knobs_of(fa), &dg.c, &d), dg.ci);
        ck_assert_int_eq(d, dg.d);
        /* every candidate's fit is the jet of its degree on its K nearest */
        for (int c = 0; c < dg.c.nc; c++) {
            if (c > 0) ck_assert_uint_gt(dg.c.ks[c], dg.c.ks[c - 1]);
            size_t k = nearest(ix, &s, i, dg.c.ks[c], nk);
            for (int e = 0; e < 2; e++) {
                const jf_result *a = &dg.res[e][c];
                jf_result r;
                ck_assert_int_eq(jf_fit_point(fd[e], s.xyz + 3 * i, nk, k, &r), JF_OK);
                ck_assert_int_eq(r.degree, a->degree);
                double dot = fabs(r.normal[0] * a->normal[0] + r.normal[1] * a->normal[1] +
                                  r.normal[2] * a->normal[2]);
                ck_assert_msg(dot > 1.0 - 1e-12, "point %zu K %zu degree %d: dot %.17g", i, dg.c.ks[c],
                              e + 2, dot);
                double ks = fabs(r.k1) + fabs(r.k2) + 1e-300;
                ck_assert_msg(fabs(r.k1 - a->k1) <= 1e-7 * ks && fabs(r.k2 - a->k2) <= 1e-7 * ks,
                              "point %zu K %zu degree %d: k1 %.17g / %.17g", i, dg.c.ks[c], e + 2, a->k1,
                              r.k1);
            }
        }
    }
    jf_fitter_free(fa);
    jf_fitter_free(fd[0]);
    jf_fitter_free(fd[1]);
    jf_index_free(ix);
    jf_sample_free(&s);
}
END_TEST

/* auto_lof z: a K whose residual variance is below s2 (1 + z sqrt(2 /
 * (K - 6))) passes; with z huge every K passes, so the cubic's Lepski
 * chain runs to the largest K and the mean chosen K must grow. */
/* jf__angle_le answers as jf__angle(a, b) <= thr does: unit vectors at
 * angles from 1e-7 to pi/2, thresholds at, one ulp around, and 1e-9 /
 * 1e-3 relative around the angle jf__angle computes (where the shortcut's
 * margin is thin), and far from it, zero, negative, NaN, huge. */
START_TEST(test_angle_le_is_the_acos_test)
{
    uint64_t st = 27;
    long n = 0;
    for (int it = 0; it < 20000; it++) {
        double u = (double)(jf_splitmix64(&st) >> 11) / 9007199254740992.0;
        double th = 1e-7 * pow(1.5707963e7, u); /* log-uniform in [1e-7, pi/2] */
        double ph = 6.283185307179586 * (double)(jf_splitmix64(&st) >> 11) / 9007199254740992.0;
        double a[3] = {0, 0, 1}, b[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
        if (it & 1) b[2] = -b[2]; /* unoriented */
        const double g = jf__angle(a, b);
        const double thr[] = {g, nextafter(g, 0), nextafter(g, INFINITY), g * (1 + 1e-9), g * (1 - 1e-9),
                              g * 1.001, g * 0.999, g * 2, g / 2, 0.0, -g, NAN, 1e300, INFINITY};
        for (size_t t = 0; t < sizeof thr / sizeof thr[0]; t++, n++)
            ck_assert_int_eq(jf__angle_le(a, b, thr[t]), jf__angle(a, b) <= thr[t]);
    }
    ck_assert_int_eq(n, 20000 * 14);
}
END_TEST

START_TEST(test_lof_knob_is_live)
{
    jf_sample s = cloud();
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(s.xyz, s.n, &ix), JF_OK);
    jf_fitter *f0 = fitter(2, 1), *f1 = fitter(2, 1);
    ck_assert_int_eq(jf__robust_tune(f1, "auto_lof", 1e12), 0);
    ck_assert_int_eq(jf__robust_tune(f1, "auto_no_such_knob", 1.0), -1);
    double nb[3 * JF_NB_AUTO_KMAX], k0 = 0, k1 = 0;
    size_t top = 0;
    for (size_t i = 0; i < s.n; i += 5) {
        size_t n = nearest(ix, &s, i, JF_NB_AUTO_KMAX, nb);
        jf_result r0, r1;
        ck_assert_int_eq(jf_fit_point_full(f0, s.xyz + 3 * i, nb, n, &r0), JF_OK);
        ck_assert_int_eq(jf_fit_point_full(f1, s.xyz + 3 * i, nb, n, &r1), JF_OK);
        k0 += r0.n_used;
        k1 += r1.n_used;
        if (r1.degree == 3) {
            ck_assert_int_eq(r1.n_used, JF_NB_AUTO_KMAX);
            top++;
        }
    }
    ck_assert_msg(k1 > k0, "mean K with every K passing %g, default %g", k1, k0);
    ck_assert_uint_gt(top, 0);
    jf_fitter_free(f0);
    jf_fitter_free(f1);
    jf_index_free(ix);
    jf_sample_free(&s);
}
END_TEST

/* 256 neighbours of p = 0 (a sunflower, nearest first): on the plane
 * z = 0 with noise of sd 0.01 along z, or on the sphere of radius 3
 * through p with noise 1e-4 (the cubic's truncation dominates there). */
static size_t patch(int curved, jf_rng *rng, double *nb)
{
    for (size_t i = 0; i < JF_NB_AUTO_KMAX; i++) {
        double r = sqrt((double)i / JF_NB_AUTO_KMAX), t = 2.399963229728653 * (double)i;
        double x = r * cos(t), y = r * sin(t), g = jf_rng_gauss(rng);
        nb[3 * i] = x;
        nb[3 * i + 1] = y;
        nb[3 * i + 2] = curved ? 3.0 - sqrt(9.0 - x * x - y * y) + 1e-4 * g : 0.01 * g;
    }
    return JF_NB_AUTO_KMAX;
}

/* Step 2's flat test.  On 8000 noisy planes the K = 32 estimate alone
 * (22 dof) puts sigma under 0.7 x the noise at about 2% of them (a
 * chi-square's tail), and the test, reading the noise at K = 256 where
 * the residual variance is flat, at half as many (asserted: at most
 * 0.7x); where the variance grows with K (curvature) sigma stays the
 * K = 32 estimate. */
START_TEST(test_flat_noise)
{
    const double p[3] = {0, 0, 0};
    static double nb[3 * JF_NB_AUTO_KMAX];
    jf_fitter *on = fitter(2, 1), *off = fitter(2, 1);
    ck_assert_int_eq(jf__robust_tune(off, "auto_flat", 0.0), 0);
    jf_rng rng;
    jf_rng_seed(&rng, 5);
    int low_on = 0, low_off = 0;
    for (int t = 0; t < 8000; t++) {
        jf_result a, b;
        size_t n = patch(0, &rng, nb);
        ck_assert_int_eq(jf_fit_point_full(on, p, nb, n, &a), JF_OK);
        ck_assert_int_eq(jf_fit_point_full(off, p, nb, n, &b), JF_OK);
        ck_assert(a.sigma >= b.sigma); /* the test only raises it */
        low_on += a.sigma < 0.7 * 0.01;
        low_off += b.sigma < 0.7 * 0.01;
    }
    ck_assert_msg(low_off >= 80 && 10 * low_on <= 7 * low_off,
                  "sigma < 0.7 noise: %d with the test, %d without", low_on, low_off);
    for (int t = 0; t < 20; t++) {
        jf_result a, b;
        size_t n = patch(1, &rng, nb);
        ck_assert_int_eq(jf_fit_point_full(on, p, nb, n, &a), JF_OK);
        ck_assert_int_eq(jf_fit_point_full(off, p, nb, n, &b), JF_OK);
        ck_assert(isfinite(a.sigma) && a.sigma > 0.0);
        ck_assert_msg(a.sigma == b.sigma, "curved: sigma %g, without the test %g", a.sigma,
                      b.sigma);
    }
    jf_fitter_free(on);
    jf_fitter_free(off);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("auto_rule");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_diag_candidates_are_the_jets);
    tcase_add_test(tc, test_lof_knob_is_live);
    tcase_add_test(tc, test_angle_le_is_the_acos_test);
    tcase_add_test(tc, test_flat_noise);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) { return jf_test_run(suite()); }
