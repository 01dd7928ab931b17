/* test_natural_convergence.c -- the §6.1 convergence slopes with natural
 * neighbourhoods (§5.1): Theorem 3 says the error on a k-th order quantity
 * from a degree-n jet is O(h^(n-k+1)).  Samples: the paper's perturbed
 * grid of side h on f(u,v) = 0.1 exp(2u + v - v^2) over [-0.5,0.5]^2
 * (x = u + δh, y = v + δ'h, δ, δ' uniform in [0, 0.9)); tangent planes
 * from poles; natural neighbours grown to N = 2 N_n; approximation fits
 * (jf_fit_point).  Errors at the samples within 0.15 of the origin,
 * against the exact normal and principal curvatures of the graph; slopes
 * of log(mean error) over h = 2^-3 .. 2^-6, each within 0.5 of n-k+1. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "jetfit.h"
#include "jf_test.h"

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static double urand(void) {
    rng_state ^= rng_state >> 12, rng_state ^= rng_state << 25, rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* Exact normal (upward) and principal curvatures k1 >= k2 of the graph z =
 * f(x, y) w.r.t. it: eigenvalues of I^-1 II. */
static void truth(double x, double y, double n[3], double *k1, double *k2) {
    double f = 0.1 * exp(2 * x + y - y * y), g = 1 - 2 * y;
    double fx = 2 * f, fy = g * f, fxx = 4 * f, fxy = 2 * g * f, fyy = (g * g - 2) * f;
    double W = sqrt(1 + fx * fx + fy * fy);
    n[0] = -fx / W, n[1] = -fy / W, n[2] = 1 / W;
    double E = 1 + fx * fx, F = fx * fy, G = 1 + fy * fy;
    double L = fxx / W, M = fxy / W, N = fyy / W;
    /* det(II - k I) = 0: (EG - F^2) k^2 - (EN - 2FM + GL) k + (LN - M^2) = 0 */
    double a = E * G - F * F, b = -(E * N - 2 * F * M + G * L), c = L * N - M * M;
    double disc = sqrt(fmax(b * b - 4 * a * c, 0.0));
    *k1 = (-b + disc) / (2 * a), *k2 = (-b - disc) / (2 * a);
}

typedef struct {
    double normal, k1, k2; /* mean errors: sin angle, |k - k_true| / |k_true| */
} errs;

static errs run(double h, int degree) {
    int m = (int)floor(1.0 / h + 0.5) + 1;
    size_t n = (size_t)m * (size_t)m;
    double *p = malloc(3 * n * sizeof *p), *nrm = malloc(3 * n * sizeof *nrm);
    unsigned *fl = calloc(n, sizeof *fl);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double *q = p + 3 * ((size_t)i * m + j);
            q[0] = -0.5 + i * h + 0.9 * urand() * h;
            q[1] = -0.5 + j * h + 0.9 * urand() * h;
            q[2] = 0.1 * exp(2 * q[0] + q[1] - q[1] * q[1]);
        }
    jf_natural *nt;
    ck_assert_int_eq(jf_natural_create(p, n, &nt), JF_OK);
    ck_assert_int_eq(jf_natural_normals(nt, JF_NORMAL_POLES, 1, nrm, fl, NULL), JF_OK);
    jf_natural_ws *ws;
    ck_assert_int_eq(jf_natural_ws_create(nt, &ws), JF_OK);
    jf_params prm;
    jf_params_init(&prm);
    prm.degree = degree;
    prm.fit = JF_FIT_APPROX;
    size_t N = 2 * jf_jet_size(degree);
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&prm, &f), JF_OK);
    uint32_t idx[128];
    double nb[3 * 128];
    errs e = {0, 0, 0};
    int count = 0;
    for (size_t i = 0; i < n; i++) {
        const double *q = p + 3 * i;
        if (fabs(q[0]) > 0.15 || fabs(q[1]) > 0.15) continue;
        ck_assert_uint_eq(fl[i], JF_PT_NORMAL_POLES);
        size_t found;
        ck_assert_int_eq(jf_natural_neighbors(nt, ws, i, nrm + 3 * i, N, idx, 128, &found), JF_OK);
        ck_assert_uint_eq(found, N);
        for (size_t k = 0; k < found; k++)
            for (int c = 0; c < 3; c++) nb[3 * k + c] = p[3 * (size_t)idx[k] + c];
        jf_result r;
        ck_assert_int_eq(jf_fit_point(f, q, nb, found, &r), JF_OK);
        ck_assert_int_eq(r.degree, degree);
        double tn[3], k1, k2;
        truth(q[0], q[1], tn, &k1, &k2);
        jf_result_orient(&r, tn);
        double c[3] = {r.normal[1] * tn[2] - r.normal[2] * tn[1], r.normal[2] * tn[0] - r.normal[0] * tn[2],
                       r.normal[0] * tn[1] - r.normal[1] * tn[0]};
        e.normal += sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        e.k1 += fabs(r.k1 - k1) / fabs(k1);
        e.k2 += fabs(r.k2 - k2) / fabs(k2);
        count++;
    }
    ck_assert_int_gt(count, 0);
    e.normal /= count, e.k1 /= count, e.k2 /= count;
    jf_fitter_free(f);
    jf_natural_ws_free(ws);
    jf_natural_free(nt);
    free(p), free(nrm), free(fl);
    return e;
}

/* least-squares slope of log(1/err) against log(1/h) */
static double slope(const double *h, const double *err, int k) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < k; i++) {
        double x = -log(h[i]), y = -log(err[i]);
        sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

START_TEST(approximation_slopes_natural) {
    const double h[4] = {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64};
    for (int deg = 2; deg <= 4; deg++) {
        double en[4], e1[4], e2[4];
        for (int k = 0; k < 4; k++) {
            errs e = run(h[k], deg);
            en[k] = e.normal, e1[k] = e.k1, e2[k] = e.k2;
        }
        double sn = slope(h, en, 4), s1 = slope(h, e1, 4), s2 = slope(h, e2, 4);
        printf("degree %d: slopes normal %.2f (expect %d), k1 %.2f, k2 %.2f (expect %d); "
               "errors at h=1/64: %.2e %.2e %.2e\n",
               deg, sn, deg, s1, s2, deg - 1, en[3], e1[3], e2[3]);
        ck_assert_double_lt(fabs(sn - deg), 0.5);
        ck_assert_double_lt(fabs(s1 - (deg - 1)), 0.5);
        ck_assert_double_lt(fabs(s2 - (deg - 1)), 0.5);
    }
}
END_TEST

static Suite *suite(void) {
    Suite *s = suite_create("natural_convergence");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, approximation_slopes_natural);
    suite_add_tcase(s, tc);
    return s;
}

int main(void) {
    return jf_test_run(suite());
}
