/* test_convergence.c -- Theorem 3 on the paper's §6.1 surface
 * f(u,v) = 0.1 exp(2u + v - v^2): with approximation of degree n over
 * N = 2 N_n samples of a randomly perturbed grid of side h (x = u + δh,
 * y = v + δ'h, δ, δ' uniform in [0, 0.9], fixed seed), the normal error
 * (sine of the angle) is O(h^n) and the k1, k2 relative errors O(h^(n-1)).
 * The log-log least-squares slope over h = 2^-2 .. 2^-6 must be within 0.5
 * of n (normal, n = 1..4) and of n-1 (curvatures, n = 2..4).  Errors are
 * averaged over 6 query points; an error below 1e-12 (the double
 * precision floor) would drop its h from the slope (none does: the
 * smallest, the 4-jet normal at h = 2^-6, is ~2e-8; measured slopes:
 * normal 0.94 2.06 2.99 4.04, k1 0.99 1.92 2.63, k2 1.05 2.01 2.96).  Exact values from
 * the graph's fundamental forms.  JF_VERBOSE=1 prints the table. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

static double f61(double u, double v) { return 0.1 * exp(2 * u + v - v * v); }

/* exact unit normal (+z side) and k1 >= k2 of the graph at (u, v) */
static void exact61(double u, double v, double n[3], double *k1, double *k2)
{
    const double e = f61(u, v), gv = 1 - 2 * v;
    const double fu = 2 * e, fv = gv * e, fuu = 4 * e, fuv = 2 * gv * e, fvv = (gv * gv - 2) * e;
    const double w2 = 1 + fu * fu + fv * fv, w = sqrt(w2);
    n[0] = -fu / w;
    n[1] = -fv / w;
    n[2] = 1 / w;
    const double K = (fuu * fvv - fuv * fuv) / (w2 * w2);
    const double H = ((1 + fu * fu) * fvv - 2 * fu * fv * fuv + (1 + fv * fv) * fuu) / (2 * w2 * w);
    const double d = sqrt(fmax(H * H - K, 0));
    *k1 = H + d;
    *k2 = H - d;
}

/* perturbation of grid node (i, j): a hash, so any window is reproducible */
static double jitter(int64_t i, int64_t j, int c)
{
    uint64_t z = (uint64_t)(i * 73856093) ^ ((uint64_t)(j * 19349663) << 1) ^ ((uint64_t)c << 40);
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return 0.9 * (double)(z >> 11) * 0x1.0p-53;
}

enum { WIN = 9, MAXN = 64 };

/* The N samples nearest (3D) to the sample of node (i0, j0), nearest
 * first; p = that sample. */
static void neighbourhood(int64_t i0, int64_t j0, double h, size_t N, double *p, double *nb)
{
    static double cand[3 * (2 * WIN + 1) * (2 * WIN + 1)], dist[(2 * WIN + 1) * (2 * WIN + 1)];
    size_t m = 0;
    for (int64_t i = i0 - WIN; i <= i0 + WIN; i++)
        for (int64_t j = j0 - WIN; j <= j0 + WIN; j++) {
            double x = i * h + jitter(i, j, 0) * h, y = j * h + jitter(i, j, 1) * h;
            cand[3 * m] = x;
            cand[3 * m + 1] = y;
            cand[3 * m + 2] = f61(x, y);
            if (i == i0 && j == j0) memcpy(p, cand + 3 * m, 3 * sizeof(double));
            m++;
        }
    for (size_t t = 0; t < m; t++) {
        double dx = cand[3 * t] - p[0], dy = cand[3 * t + 1] - p[1], dz = cand[3 * t + 2] - p[2];
        dist[t] = dx * dx + dy * dy + dz * dz;
    }
    for (size_t k = 0; k < N; k++) {
        size_t best = 0;
        for (size_t t = 1; t < m; t++)
            if (dist[t] < dist[best]) best = t;
        memcpy(nb + 3 * k, cand + 3 * best, 3 * sizeof(double));
        dist[best] = INFINITY;
    }
}

static double slope(const double *h, const double *err, int cnt)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int m = 0;
    for (int t = 0; t < cnt; t++) {
        if (!(err[t] > 1e-12)) continue; /* double-precision floor */
        double x = log(h[t]), y = log(err[t]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        m++;
    }
    ck_assert_int_ge(m, 3);
    return (m * sxy - sx * sy) / (m * sxx - sx * sx);
}

START_TEST(test_theorem3)
{
    const double qs[6][2] = {{0, 0}, {0.2, -0.1}, {-0.3, 0.25}, {0.1, 0.3}, {-0.15, -0.35}, {0.35, 0.1}};
    const int verbose = getenv("JF_VERBOSE") != NULL;
    for (int n = 1; n <= 4; n++) {
        jf_params prm;
        jf_params_init(&prm);
        prm.degree = n;
        prm.max_cond = INFINITY; /* measure the degree asked for */
        jf_fitter *f;
        ck_assert_int_eq(jf_fitter_create(&prm, &f), JF_OK);
        const size_t N = 2 * jf_jet_size(n);
        double hs[5], en[5], ek1[5], ek2[5];
        for (int e = 2; e <= 6; e++) {
            const double h = ldexp(1.0, -e);
            double sn = 0, s1 = 0, s2 = 0;
            for (int q = 0; q < 6; q++) {
                double p[3], nb[3 * MAXN], nx[3], k1, k2;
                neighbourhood((int64_t)floor(qs[q][0] / h), (int64_t)floor(qs[q][1] / h), h, N, p, nb);
                exact61(p[0], p[1], nx, &k1, &k2);
                jf_result r;
                ck_assert_int_eq(jf_fit_point(f, p, nb, N, &r), JF_OK);
                ck_assert_int_eq(r.degree, n);
                if (r.normal[0] * nx[0] + r.normal[1] * nx[1] + r.normal[2] * nx[2] < 0)
                    jf_result_flip(&r);
                double c[3] = {r.normal[1] * nx[2] - r.normal[2] * nx[1],
                               r.normal[2] * nx[0] - r.normal[0] * nx[2],
                               r.normal[0] * nx[1] - r.normal[1] * nx[0]};
                sn += sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / 6;
                if (n >= 2) {
                    s1 += fabs(r.k1 - k1) / fabs(k1) / 6;
                    s2 += fabs(r.k2 - k2) / fabs(k2) / 6;
                }
            }
            hs[e - 2] = h;
            en[e - 2] = sn;
            ek1[e - 2] = s1;
            ek2[e - 2] = s2;
            if (verbose)
                printf("degree %d N %2zu h 2^-%d: normal %.3e k1 %.3e k2 %.3e\n", n, N, e, sn, s1,
                       s2);
        }
        double sl = slope(hs, en, 5);
        if (verbose) printf("degree %d slopes: normal %.2f", n, sl);
        ck_assert_msg(fabs(sl - n) <= 0.5, "degree %d normal slope %.2f", n, sl);
        if (n >= 2) {
            double s1 = slope(hs, ek1, 5), s2 = slope(hs, ek2, 5);
            if (verbose) printf(" k1 %.2f k2 %.2f", s1, s2);
            ck_assert_msg(fabs(s1 - (n - 1)) <= 0.5, "degree %d k1 slope %.2f", n, s1);
            ck_assert_msg(fabs(s2 - (n - 1)) <= 0.5, "degree %d k2 slope %.2f", n, s2);
        }
        if (verbose) printf("\n");
        jf_fitter_free(f);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("convergence");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_theorem3);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
