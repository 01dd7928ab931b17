/* test_scale.c -- issue 11.8: the fit is scale-invariant.  Coordinates
 * scaled by s = 2^e (exact in floating point) from 2^-498 (~1e-150) to
 * 2^498 (~1e150) give the same normal, directions and status bit for bit,
 * curvatures k/s and Monge coefficients b/s^2 bit for bit (degree 4 to
 * 2^+-332: its coefficients, ~1/length^3, overflow beyond); and a
 * non-finite curvature is never reported with status 0 or only umbilic.
 * Before: the umbilic test was absolute (k1 - k2 <= 1e-10 max(1, |k|)):
 * at 1e10 most points became umbilic with arbitrary directions. */
#include <check.h>
#include <math.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

#define N 40

/* A patch of z = f(x, y) around 0 with mild anisotropy `an` (an = 0: a
 * sphere-like umbilic point), deterministic pseudo-random samples. */
static void patch(double an, double *p)
{
    unsigned long long r = 12345;
    for (int i = 0; i < N; i++) {
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        double x = ((double)(r >> 11) / 9007199254740992.0 - 0.5) * 0.2;
        r = r * 6364136223846793005ULL + 1442695040888963407ULL;
        double y = ((double)(r >> 11) / 9007199254740992.0 - 0.5) * 0.2;
        if (i == 0) x = y = 0;
        p[3 * i] = x;
        p[3 * i + 1] = y;
        p[3 * i + 2] = 0.5 * ((1 + an) * x * x + y * y) + 0.3 * x * x * y + 0.1 * x * y * y * y;
    }
}

static void fit(double an, double s, int degree, jf_result *out)
{
    double p[3 * N];
    patch(an, p);
    for (int i = 0; i < 3 * N; i++) p[i] *= s;
    jf_params prm;
    jf_params_init(&prm);
    prm.degree = degree;
    prm.monge_degree = degree < 4 ? degree : 4;
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&prm, &f), JF_OK);
    ck_assert_int_eq(jf_fit_point(f, p, p, N, out), JF_OK);
    jf_fitter_free(f);
}

static int same(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

START_TEST(scale_exact)
{
    const double aniso[] = {0.0, 1e-13, 1e-6, 0.5};
    const int degrees[] = {2, 3, 4};
    for (int ai = 0; ai < 4; ai++)
        for (int di = 0; di < 3; di++) {
            jf_result ref;
            fit(aniso[ai], 1.0, degrees[di], &ref);
            ck_assert(isfinite(ref.k1) && isfinite(ref.k2));
            /* degree 4: c ~ 1/length^3 overflows a double beyond 2^+-340 */
            int lim = degrees[di] < 4 ? 498 : 332;
            for (int e = -lim; e <= lim; e += 83) {
                double s = ldexp(1.0, e);
                jf_result r;
                fit(aniso[ai], s, degrees[di], &r);
                ck_assert_msg(r.status == ref.status, "aniso %g deg %d 2^%d: status %u, want %u",
                              aniso[ai], degrees[di], e, r.status, ref.status);
                for (int k = 0; k < 3; k++) {
                    ck_assert_msg(same(r.normal[k], ref.normal[k]), "normal 2^%d", e);
                    ck_assert_msg(same(r.d1[k], ref.d1[k]) && same(r.d2[k], ref.d2[k]),
                                  "aniso %g deg %d 2^%d: directions", aniso[ai], degrees[di], e);
                }
                ck_assert_msg(same(r.k1 * s, ref.k1) && same(r.k2 * s, ref.k2),
                              "aniso %g deg %d 2^%d: k1 %.17g k2 %.17g, want %.17g %.17g",
                              aniso[ai], degrees[di], e, r.k1 * s, r.k2 * s, ref.k1, ref.k2);
                if (degrees[di] >= 3)
                    for (int k = 0; k < 4; k++)
                        ck_assert_msg(same(r.b[k] * s * s, ref.b[k]), "b%d 2^%d", k, e);
                ck_assert(same(r.cond, ref.cond));
            }
        }
}
END_TEST

/* A power of ten is not exact in binary: 1e10 and 1e-10 agree to a few
 * ulps, and the umbilic verdict must not change (it did at 1e10). */
START_TEST(scale_decimal)
{
    /* the umbilic verdict too, at degree 4 (to 1e+-90: its coefficients
     * overflow beyond): nearly umbilic points (k1 - k2 ~ 6e-7 and 2e-6
     * here, from the fit) never become umbilic at any decimal scale, as
     * they did from 1e10 with the absolute test */
    for (int e = -90; e <= 90; e += 10) /* degree 4: c ~ 1/length^3 */
        for (int ai = 0; ai < 2; ai++) {
            const double an = ai ? 1e-6 : 0.0;
            jf_result ref, r;
            fit(an, 1.0, 4, &ref);
            fit(an, pow(10.0, e), 4, &r);
            ck_assert_msg(r.status == ref.status, "aniso %g 1e%d: status %u, want %u", an, e,
                          r.status, ref.status);
            ck_assert_msg(!(r.status & JF_PT_UMBILIC), "aniso %g 1e%d: umbilic", an, e);
        }
    for (int e = -150; e <= 150; e += 10) {
        double s = pow(10.0, e);
        jf_result ref, r;
        fit(0.5, 1.0, 2, &ref);
        fit(0.5, s, 2, &r);
        ck_assert_uint_eq(r.status, ref.status);
        ck_assert(fabs(r.k1 * s - ref.k1) <= 1e-9 * fabs(ref.k1));
        ck_assert(fabs(r.k2 * s - ref.k2) <= 1e-9 * fabs(ref.k2));
        ck_assert(fabs(r.d1[0] * ref.d1[0] + r.d1[1] * ref.d1[1] + r.d1[2] * ref.d1[2]) >
                  1 - 1e-12);
    }
}
END_TEST

/* Coordinates so large that the fit overflows: whatever comes out, a
 * non-finite curvature is flagged as a failure, never as status 0 or only
 * umbilic. */
START_TEST(nonfinite_never_ok)
{
    for (int e = 500; e <= 1020; e += 20) {
        jf_result r;
        fit(0.5, ldexp(1.0, e), 2, &r);
        if (!isfinite(r.k1) || !isfinite(r.k2) || !isfinite(r.normal[0]))
            ck_assert_msg(r.status & (JF_PT_FAILED | JF_PT_NONFINITE),
                          "2^%d: k1 %g with status %u", e, r.k1, r.status);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("scale");
    TCase *tc = tcase_create("scale");
    tcase_add_test(tc, scale_exact);
    tcase_add_test(tc, scale_decimal);
    tcase_add_test(tc, nonfinite_never_ok);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
