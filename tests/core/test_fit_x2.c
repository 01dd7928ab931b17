/* test_fit_x2.c -- two or four fits side by side (jf__fit_point_x2 and
 * _x4, the SIMD lanes of jf__eig3_x2/_x4 and of the Gram extremes; the
 * AVX and the default builds of the kernels) give the bits of the
 * one-at-a-time path, and jf_estimate on the k-NN path (pairs, streamed
 * rows) gives the bits of the plain per-point loop this test keeps:
 * jf_index_knn then jf_fit_point, point by point; and jf__ldexp is
 * ldexp.  Cases: the §6.1
 * surface, noisy and exact paraboloids, planes (umbilics), offsets of
 * 1e6, clusters (kappa > 1e3: the SVD path), collinear and duplicated
 * points, too few points (lowered degrees), non-finite neighbours, and
 * pairs whose two lanes take different paths. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fitter_internal.h"
#include "jetfit.h"
#include "jf_test.h"

static uint64_t rng_state;
static double urand(void) /* splitmix64, deterministic */
{
    return jf_unit(jf_splitmix64(&rng_state));
}

static int same_bits(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

/* Every field, bit for bit (NaN payloads included; padding ignored). */
static int same_result(const jf_result *a, const jf_result *b)
{
    return a->status == b->status && a->degree == b->degree && a->n_used == b->n_used &&
           same_bits(&a->cond, &b->cond, 1) && same_bits(&a->residual, &b->residual, 1) &&
           same_bits(a->pca_eval, b->pca_eval, 3) && same_bits(a->normal, b->normal, 3) &&
           same_bits(&a->k1, &b->k1, 1) && same_bits(&a->k2, &b->k2, 1) &&
           same_bits(a->d1, b->d1, 3) && same_bits(a->d2, b->d2, 3) &&
           same_bits(a->b, b->b, 4) && same_bits(a->c, b->c, 5);
}

#define MAXN 64

/* Neighbourhood of kind `kind` around the origin sample (p = nbr[0]). */
static size_t make_nbhd(int kind, double *nbr)
{
    size_t n = 6 + (size_t)(urand() * 40); /* 6..45 */
    double off = kind == 3 ? 1e6 : 0.0, s = 0.05 + 0.2 * urand();
    for (size_t i = 0; i < n; i++) {
        double x = i ? s * (2 * urand() - 1) : 0, y = i ? s * (2 * urand() - 1) : 0, z;
        switch (kind) {
        case 0: z = 0.1 * exp(2 * x + y - y * y); break;            /* §6.1 */
        case 1: z = 0.7 * x * x - 0.3 * y * y + 1e-4 * urand(); break; /* noisy */
        case 2: z = 0.0; break;                                      /* plane */
        case 3: z = 0.5 * (x * x + y * y); break;                    /* offset */
        case 4: /* a cluster and a far point: kappa > 1e3 */
            x = i + 1 < n ? 1e-4 * x : s;
            y = i + 1 < n ? 1e-4 * y : s;
            z = x * x;
            break;
        case 5: z = 2 * x; y = 3 * x; break;                         /* collinear */
        case 6: /* duplicates */
            if (i > 2) {
                memcpy(nbr + 3 * i, nbr + 3 * (i % 3), sizeof(double[3]));
                continue;
            }
            z = x * y;
            break;
        case 7: z = x * y; n = n > 8 ? 8 : n; break;                 /* few points */
        default: /* non-finite neighbours */
            z = x * x - y * y;
            if (i % 5 == 3) x = NAN;
            if (i % 7 == 4) z = INFINITY;
        }
        if (i >= n) break;
        nbr[3 * i] = x + off;
        nbr[3 * i + 1] = y - off;
        nbr[3 * i + 2] = z + off;
    }
    return n;
}

START_TEST(test_eig3_x2_bits)
{
    rng_state = 15;
    for (int t = 0; t < 20000; t++) {
        double a[2][9], ev[2][3], vec[2][9], ev1[3], vec1[9];
        for (int k = 0; k < 2; k++) {
            int kind = (t + k) % 5;
            for (int i = 0; i < 3; i++)
                for (int j = i; j < 3; j++) {
                    double v = 2 * urand() - 1;
                    if (kind == 1 && i != j) v = 0;                /* diagonal */
                    if (kind == 2) v = i == j ? 1.0 : (j == 2 ? 1e-9 * v : 0); /* repeated */
                    if (kind == 3) v = 0;                          /* zero */
                    if (kind == 4 && i != j) v *= 1e-13;           /* nearly diagonal */
                    a[k][3 * i + j] = a[k][3 * j + i] = v;
                }
        }
        jf__eig3_x2(a[0], a[1], ev[0], vec[0], ev[1], vec[1]);
        for (int k = 0; k < 2; k++) {
            jf__eig3(a[k], ev1, vec1);
            ck_assert_msg(same_bits(ev[k], ev1, 3) && same_bits(vec[k], vec1, 9),
                          "eig3 lane %d differs at %d", k, t);
        }
    }
}
END_TEST

/* jf__eig3_x4's four lanes (each its own kind of matrix, or repeats of
 * one) against jf__eig3, in the AVX build and in the default one. */
START_TEST(test_eig3_x4_bits)
{
    rng_state = 16;
    for (int avx = 0; avx < 2; avx++) {
        jf__no_avx = !avx;
        for (int t = 0; t < 10000; t++) {
            double a[4][9], ev[4][3], vec[4][9], ev1[3], vec1[9];
            for (int k = 0; k < 4; k++) {
                int kind = (t + k * (t / 5 + 1)) % 5;
                for (int i = 0; i < 3; i++)
                    for (int j = i; j < 3; j++) {
                        double v = 2 * urand() - 1;
                        if (kind == 1 && i != j) v = 0;
                        if (kind == 2) v = i == j ? 1.0 : (j == 2 ? 1e-9 * v : 0);
                        if (kind == 3) v = 0;
                        if (kind == 4 && i != j) v *= 1e-13;
                        a[k][3 * i + j] = a[k][3 * j + i] = v;
                    }
            }
            const double *in[4] = {a[0], a[1], a[2], a[t % 7 == 0 ? 0 : 3]};
            double *const e[4] = {ev[0], ev[1], ev[2], ev[3]}, *const v[4] = {vec[0], vec[1], vec[2], vec[3]};
            jf__eig3_x4(in, e, v);
            for (int k = 0; k < 4; k++) {
                jf__eig3(in[k], ev1, vec1);
                ck_assert_msg(same_bits(ev[k], ev1, 3) && same_bits(vec[k], vec1, 9),
                              "eig3_x4 lane %d differs at %d (avx %d)", k, t, avx);
            }
        }
    }
    jf__no_avx = 0;
}
END_TEST

/* jf__fit_point_x2 (L = 2) or _x4 (L = 4) against L jf_fit_point calls
 * on another fitter, for degrees 1..4, both fits and frames: lanes of
 * mixed kinds (some finished early, some lowered, some on the SVD path);
 * the four-lane kernels in the AVX and the default build.  The fitters'
 * state too: the residuals of the last fit.  At least 1/min_frac of the
 * groups, and not all, keep every lane on the fast path. */
static void lanes_vs_one(int L, int cases, size_t min_frac)
{
    static const jf_fit_mode fits[2] = {JF_FIT_APPROX, JF_FIT_INTERP};
    static const jf_frame_mode frames[2] = {JF_FRAME_PCA, JF_FRAME_AXIS};
    size_t groups = 0, all_fast = 0;
    for (int deg = 1; deg <= 4; deg++)
        for (int fm = 0; fm < 2; fm++)
            for (int fr = 0; fr < 2; fr++) {
                jf_params p;
                jf_params_init(&p);
                p.degree = deg;
                p.monge_degree = deg < 2 ? 2 : (deg < 4 ? deg : 4);
                p.fit = fits[fm];
                p.frame = frames[fr];
                p.max_neighbors = MAXN;
                jf_fitter *f[4], *s0;
                for (int k = 0; k < L; k++) ck_assert_int_eq(jf_fitter_create(&p, &f[k]), JF_OK);
                ck_assert_int_eq(jf_fitter_create(&p, &s0), JF_OK);
                for (int t = 0; t < cases; t++) {
                    double nb[4][3 * MAXN], res[MAXN], ref_res[MAXN];
                    size_t n[4];
                    int kind[4];
                    for (int k = 0; k < L; k++) {
                        kind[k] = L == 2 ? (k ? (t / 9 + t) % 9 : t % 9)
                                         : (t / 4 + k * (t % 4 + 1)) % 9;
                        if (t % 3) kind[k] = t % 2 ? 0 : 1; /* mostly the usual case */
                        n[k] = make_nbhd(kind[k], nb[k]);
                    }
                    jf_result r[4], ref;
                    if (L == 2) {
                        ck_assert_int_eq(jf__fit_point_x2(f[0], nb[0], nb[0], n[0], &r[0], f[1],
                                                          nb[1], nb[1], n[1], &r[1]),
                                         JF_OK);
                    } else {
                        const double *pp[4] = {nb[0], nb[1], nb[2], nb[3]};
                        jf_result *const rr[4] = {&r[0], &r[1], &r[2], &r[3]};
                        jf__no_avx = t % 2;
                        ck_assert_int_eq(jf__fit_point_x4(f, pp, pp, n, rr), JF_OK);
                        jf__no_avx = 0;
                    }
                    int fast = 1;
                    for (int k = 0; k < L; k++) {
                        ck_assert_int_eq(jf_fit_point(s0, nb[k], nb[k], n[k], &ref), JF_OK);
                        ck_assert_msg(same_result(&r[k], &ref),
                                      "x%d deg %d fit %d frame %d case %d lane %d (kind %d): "
                                      "k1 %.17g vs %.17g, cond %.17g vs %.17g",
                                      L, deg, fm, fr, t, k, kind[k], r[k].k1, ref.k1, r[k].cond,
                                      ref.cond);
                        ck_assert_int_eq(jf_fitter_residuals(f[k], res, n[k]), JF_OK);
                        ck_assert_int_eq(jf_fitter_residuals(s0, ref_res, n[k]), JF_OK);
                        ck_assert(same_bits(res, ref_res, n[k]));
                        fast &= r[k].degree == deg && r[k].cond <= 1e3;
                    }
                    groups++;
                    all_fast += fast;
                }
                for (int k = 0; k < L; k++) jf_fitter_free(f[k]);
                jf_fitter_free(s0);
            }
    /* the lanes were exercised, and the other paths too */
    ck_assert_uint_gt(all_fast, groups / min_frac);
    ck_assert_uint_lt(all_fast, groups);
}

START_TEST(test_fit_x2_bits)
{
    rng_state = 2003;
    lanes_vs_one(2, 300, 2);
}
END_TEST

START_TEST(test_fit_x4_bits)
{
    rng_state = 4004;
    lanes_vs_one(4, 200, 3);
}
END_TEST

/* jf__ldexp (one multiplication) against ldexp, bit for bit, over the
 * whole range: subnormal, overflowing, zero, infinite and NaN results. */
START_TEST(test_ldexp_bits)
{
    rng_state = 7;
    static const double special[] = {0.0, -0.0, INFINITY, -INFINITY, NAN, 0x1p-1074, 0x1p-1022,
                                     0x1.fffffffffffffp+1023, 1.0, -3.0, 0x1.8p-1060};
    for (int t = 0; t < 2000000; t++) {
        double x;
        if (t < 11 * 64) {
            x = special[t % 11];
        } else {
            uint64_t u = (uint64_t)(urand() * 0x1p53) << 11 ^ (uint64_t)(urand() * 2048);
            memcpy(&x, &u, sizeof x);
        }
        int e = (int)(urand() * 2300) - 1150;
        double a = jf__ldexp(x, e), b = ldexp(x, e);
        ck_assert_msg(memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b)),
                      "ldexp(%a, %d): %a vs %a", x, e, a, b);
    }
}
END_TEST

/* The code for the common sizes (16 or 32 rows at degree 2, 32 at degree
 * 3: constant sizes, unrolled) gives the general code's bits
 * (jf__fixed_sizes = 0), one fit at a time and in pairs, on every kind
 * of neighbourhood that keeps K usable points. */
START_TEST(test_fixed_sizes_bits)
{
    static const size_t ks[3] = {16, 32, 32};
    static const int degs[3] = {2, 2, 3};
    size_t fast = 0, total = 0;
    rng_state = 1615;
    for (int c = 0; c < 3; c++) {
        jf_params p;
        jf_params_init(&p);
        p.degree = degs[c];
        p.monge_degree = degs[c];
        p.max_neighbors = MAXN;
        jf_fitter *f0, *f1, *g0, *g1;
        ck_assert_int_eq(jf_fitter_create(&p, &f0), JF_OK);
        ck_assert_int_eq(jf_fitter_create(&p, &f1), JF_OK);
        ck_assert_int_eq(jf_fitter_create(&p, &g0), JF_OK);
        ck_assert_int_eq(jf_fitter_create(&p, &g1), JF_OK);
        for (int t = 0; t < 400; t++) {
            const int kind = t % 9 == 7 ? 0 : t % 9; /* 7: too few points */
            double nb[2][3 * MAXN], res[2][MAXN];
            for (int k = 0; k < 2; k++)
                while (make_nbhd(kind, nb[k]) < ks[c]) {
                }
            jf_result r[2][2], one[2];
            for (int fixed = 1; fixed >= 0; fixed--) {
                jf__fixed_sizes = fixed;
                ck_assert_int_eq(jf__fit_point_x2(f0, nb[0], nb[0], ks[c], &r[fixed][0], f1, nb[1],
                                                  nb[1], ks[c], &r[fixed][1]),
                                 JF_OK);
                ck_assert_int_eq(jf_fit_point(g0, nb[0], nb[0], ks[c], &one[fixed]), JF_OK);
                ck_assert_int_eq(jf_fitter_residuals(f0, res[fixed], ks[c]), JF_OK);
            }
            jf__fixed_sizes = 1;
            ck_assert_msg(same_result(&r[1][0], &r[0][0]) && same_result(&r[1][1], &r[0][1]) &&
                              same_result(&one[1], &one[0]) && same_result(&one[1], &r[1][0]),
                          "K %zu d%d case %d (kind %d): k1 %.17g vs %.17g, cond %.17g vs %.17g",
                          ks[c], degs[c], t, kind, r[1][0].k1, r[0][0].k1, r[1][0].cond,
                          r[0][0].cond);
            ck_assert(same_bits(res[1], res[0], ks[c]));
            total++;
            fast += r[1][0].degree == degs[c] && r[1][0].cond <= 1e3;
        }
        jf_fitter_free(f0);
        jf_fitter_free(f1);
        jf_fitter_free(g0);
        jf_fitter_free(g1);
    }
    /* the unrolled fast path ran, and the other paths too */
    ck_assert_uint_gt(fast, total / 2);
    ck_assert_uint_lt(fast, total);
}
END_TEST

/* jf_estimate (k-NN: pairs, streamed rows, 1 and 2 threads) against the
 * per-point loop of before: the same bits in every row. */
static void estimate_vs_loop(size_t k, int degree)
{
    const size_t n = 3000;
    double *xyz = malloc(3 * n * sizeof *xyz);
    jf_result *out = malloc(n * sizeof *out), ref;
    uint32_t idx[64];
    double d2[64], nb[3 * 64];
    ck_assert(xyz && out);
    rng_state = 61;
    for (size_t i = 0; i < n; i++) { /* §6.1 surface, random order */
        double x = urand() - 0.5, y = urand() - 0.5;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = 0.1 * exp(2 * x + y - y * y);
    }
    xyz[3 * 17] = NAN; /* a non-finite point: its own row, nobody's neighbour */
    jf_cloud c = {0};
    c.n = n;
    c.xyz = xyz;
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = JF_NB_KNN;
    o.nb.k = k;
    o.params.degree = degree;
    o.params.monge_degree = degree < 3 ? degree : 3;
    jf_index *ix;
    ck_assert_int_eq(jf_index_build(xyz, n, &ix), JF_OK);
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&o.params, &f), JF_OK);
    for (int threads = 1; threads <= 3; threads++) {
        o.threads = threads < 3 ? threads : 1;
        jf__no_avx = threads == 3; /* the default (SSE2) kernels too */
        jf_error err;
        ck_assert_int_eq(jf_estimate(&c, &o, out, &err), JF_OK);
        for (size_t i = 0; i < n; i++) {
            if (i == 17) {
                ck_assert(out[i].status & JF_PT_NONFINITE);
                continue;
            }
            size_t found;
            ck_assert_int_eq(jf_index_knn(ix, xyz + 3 * i, k, idx, d2, &found), JF_OK);
            for (size_t j = 0; j < found; j++) memcpy(nb + 3 * j, xyz + 3 * idx[j], sizeof(double[3]));
            ck_assert_int_eq(jf_fit_point(f, xyz + 3 * i, nb, found, &ref), JF_OK);
            ck_assert_msg(same_result(&out[i], &ref), "knn:%zu d%d, %d threads: row %zu differs",
                          k, degree, threads, i);
        }
    }
    jf__no_avx = 0;
    jf_fitter_free(f);
    jf_index_free(ix);
    free(out);
    free(xyz);
}

START_TEST(test_estimate_vs_loop)
{
    estimate_vs_loop(16, 2);
    estimate_vs_loop(32, 3);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("fit_x2");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_ldexp_bits);
    tcase_add_test(tc, test_eig3_x2_bits);
    tcase_add_test(tc, test_fit_x2_bits);
    tcase_add_test(tc, test_eig3_x4_bits);
    tcase_add_test(tc, test_fit_x4_bits);
    tcase_add_test(tc, test_fixed_sizes_bits);
    tcase_add_test(tc, test_estimate_vs_loop);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
