/* test_robust.c -- jf_fit_point_full: IRLS reweighting and scale selection
 * against the analytic truth of the paper's §6.1 surface
 * f(u, v) = 0.1 exp(2u + v - v^2), sampled on a perturbed grid with noise
 * and outliers.  Neighbours by brute force (nearest first). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jetfit.h"
#include "jf_test.h"

/* src/robust/robust.c's bench-only setter of the selection constants */
int jf__robust_tune(jf_fitter *f, const char *name, double v);
/* degree_floor_n of roof_err's fitters (the library's default: 50) */
static double roof_floor_n = 50.0;

/* ---- the surface and its exact quantities ---- */
static double fz(double u, double v) { return 0.1 * exp(2 * u + v - v * v); }

/* Unit normal (-fu, -fv, 1)/|.| and principal curvatures k1 >= k2 w.r.t.
 * it, from the Weingarten map of a graph (Table 1's formulas). */
static void truth(double u, double v, double n[3], double *k1, double *k2)
{
    double f = fz(u, v), gu = 2.0, gv = 1.0 - 2.0 * v;
    double fu = f * gu, fv = f * gv, fuu = f * gu * gu, fuv = f * gu * gv,
           fvv = f * (gv * gv - 2.0);
    double w = sqrt(1 + fu * fu + fv * fv);
    n[0] = -fu / w;
    n[1] = -fv / w;
    n[2] = 1 / w;
    double E = 1 + fu * fu, F = fu * fv, G = 1 + fv * fv;
    double e = fuu / w, ff = fuv / w, g = fvv / w;
    /* jetfit's sign: z = (k1 x^2 + k2 y^2)/2 along n, so k = +II/I */
    double K = (e * g - ff * ff) / (E * G - F * F);
    double H = (e * G - 2 * ff * F + g * E) / (2 * (E * G - F * F));
    double d = sqrt(fmax(H * H - K, 0.0));
    *k1 = H + d;
    *k2 = H - d;
}

/* ---- deterministic RNG (splitmix64) ---- */
static uint64_t rng_state;
static double urand(void)
{
    return jf_unit(jf_splitmix64(&rng_state));
}
static double grand(void)
{
    double a = urand(), b = urand();
    return sqrt(-2.0 * log(a + 1e-300)) * cos(6.283185307179586 * b);
}

static int quadric; /* make_cloud samples z = 0.4u^2 - 0.2v^2 + 0.1uv */
static double quiet_half = 1.0; /* noise factor on the half u > 0 */

typedef struct {
    size_t n;
    double *xyz;   /* noisy / corrupted samples */
    double *uv;    /* parameters of the clean samples */
} cloud;

/* Grid of side m over [-0.5,0.5]^2 perturbed by [0,0.9]h (§6.1), Gaussian
 * noise sigma (absolute, per axis), a fraction `outl` of the points moved
 * off the surface by +-[5,10] sigma_o along z. */
static cloud make_cloud(int m, double sigma, double outl, double sigma_o, uint64_t seed)
{
    cloud c;
    rng_state = seed;
    c.n = (size_t)m * (size_t)m;
    c.xyz = malloc(3 * c.n * sizeof *c.xyz);
    c.uv = malloc(2 * c.n * sizeof *c.uv);
    double h = 1.0 / (m - 1);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            size_t k = (size_t)i * m + j;
            double u = -0.5 + i * h + 0.9 * h * urand() - 0.45 * h;
            double v = -0.5 + j * h + 0.9 * h * urand() - 0.45 * h;
            c.uv[2 * k] = u;
            c.uv[2 * k + 1] = v;
            double sg = u > 0 ? sigma * quiet_half : sigma;
            c.xyz[3 * k] = u + sg * grand();
            c.xyz[3 * k + 1] = v + sg * grand();
            c.xyz[3 * k + 2] = fz(u, v) + sg * grand();
            /* always draw, so that clouds with and without outliers share
             * their samples */
            double a = urand(), b = urand(), t = urand();
            if (outl > 0 && a < outl) c.xyz[3 * k + 2] += (b < 0.5 ? -1 : 1) * sigma_o * (5 + 5 * t);
            if (quadric) c.xyz[3 * k + 2] = 0.4 * u * u - 0.2 * v * v + 0.1 * u * v;
        }
    return c;
}

/* Brute-force k nearest of point q (nearest first, ties by index). */
static void knn(const cloud *c, size_t q, size_t k, double *nbr, size_t *d_idx, double *d2)
{
    /* partial insertion sort: k is small */
    size_t cnt = 0;
    for (size_t i = 0; i < c->n; i++) {
        double dx = c->xyz[3 * i] - c->xyz[3 * q], dy = c->xyz[3 * i + 1] - c->xyz[3 * q + 1],
               dz = c->xyz[3 * i + 2] - c->xyz[3 * q + 2];
        double d = dx * dx + dy * dy + dz * dz;
        if (cnt == k && d >= d2[k - 1]) continue;
        size_t pos = cnt < k ? cnt++ : k - 1;
        while (pos > 0 && d2[pos - 1] > d) {
            d2[pos] = d2[pos - 1];
            d_idx[pos] = d_idx[pos - 1];
            pos--;
        }
        d2[pos] = d;
        d_idx[pos] = i;
    }
    for (size_t t = 0; t < k; t++)
        memcpy(nbr + 3 * t, c->xyz + 3 * d_idx[t], 3 * sizeof *nbr);
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmpd);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

typedef struct {
    double med_normal;  /* median normal angle, degrees */
    double med_curv;    /* median of |dk1| and |dk2| relative errors */
    size_t nflag;       /* rows with the given flag */
} errs;

/* Fits every 7th point of the inner region |u|,|v| <= region (jet fits are
 * one-sided at the border) with params p from their kmax nearest; nflag:
 * the rows with `flag`. */
static double region = 0.3;
static size_t n_lowered; /* fits of run() at a degree below p->degree */
static errs run(const cloud *c, const jf_params *p, size_t kmax, unsigned flag)
{
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(p, &f), JF_OK);
    double *nbr = malloc(3 * kmax * sizeof *nbr), *d2 = malloc(kmax * sizeof *d2);
    size_t *idx = malloc(kmax * sizeof *idx);
    double *en = malloc(c->n * sizeof *en), *ek = malloc(2 * c->n * sizeof *ek);
    size_t m = 0;
    errs e = {0, 0, 0};
    for (size_t q = 0; q < c->n; q += 7) {
        double u = c->uv[2 * q], v = c->uv[2 * q + 1];
        if (fabs(u) > region || fabs(v) > region) continue;
        knn(c, q, kmax, nbr, idx, d2);
        jf_result r;
        ck_assert_int_eq(jf_fit_point_full(f, c->xyz + 3 * q, nbr, kmax, &r), JF_OK);
        double nt[3], k1, k2, ea[2], er[2];
        truth(u, v, nt, &k1, &k2);
        en[m] = jf_normal_angle_deg(r.normal, nt);
        jf_curv_compare(r.normal, r.k1, r.k2, nt, k1, k2, ea, er);
        ek[2 * m] = ea[0] / fmax(fabs(k1), 1e-3); /* relative: k ~ 0.1..1 here */
        ek[2 * m + 1] = ea[1] / fmax(fabs(k1), 1e-3);
        if (r.status & flag) e.nflag++;
        if (r.degree < p->degree) n_lowered++;
        m++;
    }
    e.med_normal = median(en, m);
    e.med_curv = median(ek, 2 * m);
    free(nbr);
    free(d2);
    free(idx);
    free(en);
    free(ek);
    jf_fitter_free(f);
    return e;
}

static int verbose(void) { return getenv("JF_TEST_VERBOSE") != NULL; }

/* With neither option set, jf_fit_point_full is jf_fit_point bit for bit. */
START_TEST(plain_is_jf_fit_point)
{
    cloud c = make_cloud(30, 0.002, 0, 0, 1);
    jf_params p;
    jf_params_init(&p);
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    double nbr[3 * 40], d2[40];
    size_t idx[40];
    for (size_t q = 0; q < c.n; q += 37) {
        knn(&c, q, 40, nbr, idx, d2);
        jf_result a, b;
        ck_assert_int_eq(jf_fit_point(f, c.xyz + 3 * q, nbr, 40, &a), JF_OK);
        ck_assert_int_eq(jf_fit_point_full(f, c.xyz + 3 * q, nbr, 40, &b), JF_OK);
        ck_assert_int_eq(memcmp(&a, &b, sizeof a), 0);
    }
    jf_fitter_free(f);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* Fits c with every fixed K of ks[0..nk) at `degree`, then with scale
 * selection among them; *best and *second: the two lowest median normal
 * errors of the fixed K.  Returns the selection's errors (nflag: points
 * with JF_PT_SCALE_SELECTED). */
static errs fixed_and_selected(const cloud *c, int degree, const size_t *ks, int nk,
                               const char *tag, double *best, double *second)
{
    jf_params p;
    jf_params_init(&p);
    p.degree = degree;
    p.max_neighbors = ks[nk - 1];
    *best = *second = INFINITY;
    for (int i = 0; i < nk; i++) {
        errs e = run(c, &p, ks[i], 0);
        if (verbose()) printf("%s, fixed K=%zu: median normal %.4f deg\n", tag, ks[i], e.med_normal);
        if (e.med_normal < *best) {
            *second = *best;
            *best = e.med_normal;
        } else if (e.med_normal < *second)
            *second = e.med_normal;
    }
    p.nscales = nk;
    for (int i = 0; i < nk; i++) p.scales[i] = ks[i];
    errs s = run(c, &p, ks[nk - 1], JF_PT_SCALE_SELECTED);
    if (verbose())
        printf("%s, selected: median normal %.4f deg (best fixed %.4f, second %.4f), %zu below "
               "the largest K\n",
               tag, s.med_normal, *best, *second, s.nflag);
    return s;
}

#define DIAG61 sqrt(2.0 + 0.3 * 0.3) /* the bounding-box diagonal */

/* §6.1 surface, 0.5% Gaussian noise (of the bbox diagonal, per axis) on
 * the half u < 0 and 50x less on u > 0: the best K differs between the
 * halves (it grows with noise), so per-point scale selection among
 * K in {32, 64, 128, 256, 512} has a lower median normal error than every
 * fixed K of the set. */
START_TEST(scale_selection_beats_best_fixed_k)
{
    quiet_half = 0.02;
    cloud c = make_cloud(50, 0.005 * DIAG61, 0, 0, 2);
    quiet_half = 1.0;
    region = 0.45;
    const size_t ks[] = {32, 64, 128, 256, 512};
    double best, second;
    errs s = fixed_and_selected(&c, 2, ks, 5, "half noisy", &best, &second);
    ck_assert(s.nflag > 0);
    ck_assert_double_lt(s.med_normal, best);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* §6.1 surface, the same 0.5% Gaussian noise everywhere, quadrics: the
 * best K is nearly the same at every point (measured: choosing the best K
 * per region of the surface gains at most 1-8% over the best fixed K), so
 * selection cannot be expected to beat it; it must not lose much either,
 * nor pick small K on noise alone: within 1.15x of the best fixed K of
 * {32, ..., 1024} and below every other fixed K.  (The former interval
 * rule gave 1.96x here.) */
START_TEST(scale_selection_uniform_noise_near_best)
{
    cloud c = make_cloud(50, 0.005 * DIAG61, 0, 0, 2);
    region = 0.45;
    const size_t ks[] = {32, 64, 128, 256, 512, 1024};
    double best, second;
    errs s = fixed_and_selected(&c, 2, ks, 6, "uniform", &best, &second);
    ck_assert_double_lt(s.med_normal, 1.15 * best);
    ck_assert_double_lt(s.med_normal, second);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* Issue 6's case: §6.1 surface, 0.5% Gaussian noise everywhere, jets of
 * degree 1 (the plane; its bias is first order in h wherever the
 * neighbourhood is one-sided and second order elsewhere, so the best K
 * varies over the surface): per-point selection among {32, ..., 512} has
 * a lower median normal error than every fixed K of the set (measured
 * 0.85x; 0.87-0.93x at 4,900 and 10,000 points with the set one or two
 * doublings larger).  At degree 2 the best K hardly varies and selection
 * only comes near the best fixed K (the test above). */
START_TEST(scale_selection_plane_uniform_noise_beats_best_fixed_k)
{
    cloud c = make_cloud(50, 0.005 * DIAG61, 0, 0, 2);
    region = 0.45;
    const size_t ks[] = {32, 64, 128, 256, 512};
    double best, second;
    errs s = fixed_and_selected(&c, 1, ks, 5, "plane", &best, &second);
    ck_assert(s.nflag > 0);
    ck_assert_double_lt(s.med_normal, best);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* Scale selection at the top degree (no higher degree to estimate the
 * bias from: only the comparison across K is left) and combined with
 * degree selection, on the exact §6.1 surface: no fit fails and the
 * normals keep the accuracy of exact data (a degree-9 jet on 64+ exact
 * points: error far below 1e-3 deg; degree 3: below the 0.01 deg of the
 * plain K = 64 cubic's order). */
START_TEST(scale_selection_top_degree_and_degree_select)
{
    cloud c = make_cloud(40, 0.0, 0, 0, 5);
    region = 0.3;
    jf_params p;
    jf_params_init(&p);
    p.degree = JF_MAX_DEGREE;
    p.monge_degree = 4;
    p.max_neighbors = 256;
    p.nscales = 3;
    p.scales[0] = 64;
    p.scales[1] = 128;
    p.scales[2] = 256;
    errs e = run(&c, &p, 256, JF_PT_FAILED);
    if (verbose()) printf("degree 9 + scales: median normal %.3g deg\n", e.med_normal);
    ck_assert_uint_eq(e.nflag, 0);
    ck_assert_double_lt(e.med_normal, 1e-3);
    p.degree = 3;
    p.monge_degree = 3;
    p.degree_select = 1;
    e = run(&c, &p, 256, JF_PT_FAILED);
    if (verbose()) printf("degree 3 + dsel + scales: median normal %.3g deg\n", e.med_normal);
    ck_assert_uint_eq(e.nflag, 0);
    ck_assert_double_lt(e.med_normal, 0.01);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* Degree selection on the §6.1 surface with 0.5% noise (of the bbox
 * diagonal, per axis) and K = 18: a cubic on 18 noisy points is dominated
 * by noise, a lower degree is not, so selecting per point among degrees
 * 1..3 has a lower median normal error than the fixed cubic (and lowers
 * the degree at most points); on the exact surface every fit keeps the
 * cubic, whose normal is the most accurate there. */
START_TEST(degree_selection_noise_and_clean)
{
    region = 0.4;
    cloud c = make_cloud(50, 0.005 * DIAG61, 0, 0, 3);
    jf_params p;
    jf_params_init(&p);
    p.degree = 3;
    n_lowered = 0;
    errs fixed = run(&c, &p, 18, 0);
    ck_assert_uint_eq(n_lowered, 0);
    p.degree_select = 1;
    n_lowered = 0;
    errs sel = run(&c, &p, 18, 0);
    size_t lowered = n_lowered;
    /* the count of fits: run() visits every 7th point of the region */
    n_lowered = 0;
    p.degree_select = 0;
    p.degree = 1;
    errs plane = run(&c, &p, 18, 0);
    if (verbose())
        printf("noise K=18: cubic %.3f deg, selected %.3f (lowered %zu), plane %.3f\n",
               fixed.med_normal, sel.med_normal, lowered, plane.med_normal);
    ck_assert_double_lt(sel.med_normal, 0.8 * fixed.med_normal);
    ck_assert_uint_gt(lowered, n_lowered); /* n_lowered is 0 here */
    ck_assert_uint_gt(lowered, 10);
    free(c.xyz);
    free(c.uv);

    cloud e = make_cloud(50, 0.0, 0, 0, 3);
    p.degree = 3;
    p.degree_select = 0;
    errs efix = run(&e, &p, 18, 0);
    p.degree_select = 1;
    n_lowered = 0;
    errs esel = run(&e, &p, 18, 0);
    p.degree_select = 0;
    p.degree = 1;
    errs eplane = run(&e, &p, 18, 0);
    if (verbose())
        printf("exact K=18: cubic %.2e deg, selected %.2e (lowered %zu), plane %.2e\n",
               efix.med_normal, esel.med_normal, n_lowered, eplane.med_normal);
    ck_assert_uint_eq(n_lowered, 0);
    ck_assert_double_eq(esel.med_normal, efix.med_normal);
    ck_assert_double_lt(efix.med_normal, 0.1 * eplane.med_normal);
    free(e.xyz);
    free(e.uv);
    region = 0.3;
}
END_TEST

/* Distance weighting on the exact §6.1 surface with K = 64 at degree 2:
 * the error is truncation (the cubic terms), which grows with the
 * distance, so Gaussian weights (sigma = 0.4 x the farthest neighbour)
 * lower the median normal error; with noise and K = 18 the weights only
 * shrink the effective sample and the error does not drop as much. */
START_TEST(distance_weighting_lowers_truncation_error)
{
    cloud e = make_cloud(50, 0.0, 0, 0, 4);
    jf_params p;
    jf_params_init(&p);
    p.degree = 2;
    errs plain = run(&e, &p, 64, 0);
    p.dist_weight = 0.4;
    errs w = run(&e, &p, 64, 0);
    if (verbose()) printf("exact K=64 d2: plain %.4f deg, weighted %.4f\n", plain.med_normal, w.med_normal);
    ck_assert_double_lt(w.med_normal, 0.7 * plain.med_normal);
    free(e.xyz);
    free(e.uv);
}
END_TEST

START_TEST(new_params_validated)
{
    jf_params p;
    jf_params_init(&p);
    ck_assert_int_eq(p.degree_select, 0);
    ck_assert(p.dist_weight == 0.0);
    const char *bad = NULL;
    p.degree = 2;
    p.degree_select = 3;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "degree_select");
    p.degree_select = 2;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_OK);
    p.dist_weight = -0.1;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    ck_assert_str_eq(bad, "dist_weight");
    p.dist_weight = NAN;
    ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
    p.dist_weight = 0.0;
    /* auto_select: 0, 1 or a cap 16..256, either with JF_AUTO_FLAGS */
    static const int good[] = {0, 1, 16, 24, 256, 1 | JF_AUTO_CUBIC_MIN48, 48 | JF_AUTO_CUBIC_MIN48,
                               1 | JF_AUTO_WEIGHTED_MEAN, 32 | JF_AUTO_CAPPED_WEIGHTED, 24 | JF_AUTO_FLAGS};
    static const int wrong[] = {-1, 2, 15, 257, JF_AUTO_CUBIC_MIN48, 8 | JF_AUTO_CUBIC_MIN48,
                                JF_AUTO_WEIGHTED_MEAN, JF_AUTO_CAPPED_WEIGHTED, JF_AUTO_FLAGS, 16384 | 24};
    for (size_t i = 0; i < sizeof good / sizeof *good; i++) {
        p.auto_select = good[i];
        ck_assert_int_eq(jf_params_validate(&p, &bad), JF_OK);
    }
    for (size_t i = 0; i < sizeof wrong / sizeof *wrong; i++) {
        p.auto_select = wrong[i];
        ck_assert_int_eq(jf_params_validate(&p, &bad), JF_ERR_INVALID);
        ck_assert_str_eq(bad, "auto_select");
    }
}
END_TEST

/* 5% outliers: Tukey reweighting keeps the median curvature error within
 * 1.5x of the plain fit of the outlier-free cloud; the plain fit with the
 * outliers does not (so the test can fail). */
START_TEST(reweighting_suppresses_outliers)
{
    const double sigma = 0.0002;
    cloud clean = make_cloud(60, sigma, 0, 0, 3);
    cloud dirty = make_cloud(60, sigma, 0.05, 0.003, 3); /* same samples + outliers */
    jf_params p;
    jf_params_init(&p);
    p.max_neighbors = 64;
    errs e0 = run(&clean, &p, 64, 0);
    errs e1 = run(&dirty, &p, 64, 0);
    p.robust = JF_ROBUST_TUKEY;
    errs e2 = run(&dirty, &p, 64, JF_PT_ROBUST_NOCONV);
    p.robust = JF_ROBUST_HUBER;
    errs e3 = run(&dirty, &p, 64, JF_PT_ROBUST_NOCONV);
    if (verbose())
        printf("median curvature error: clean %.4f, outliers plain %.4f, tukey %.4f (%zu noconv), "
               "huber %.4f\nmedian normal: clean %.4f, plain %.4f, tukey %.4f, huber %.4f\n",
               e0.med_curv, e1.med_curv, e2.med_curv, e2.nflag, e3.med_curv, e0.med_normal,
               e1.med_normal, e2.med_normal, e3.med_normal);
    ck_assert_double_gt(e1.med_curv, 1.5 * e0.med_curv);
    ck_assert_double_le(e2.med_curv, 1.5 * e0.med_curv);
    ck_assert_double_lt(e3.med_curv, e1.med_curv);
    free(clean.xyz);
    free(clean.uv);
    free(dirty.xyz);
    free(dirty.uv);
}
END_TEST

/* A noiseless quadric: residuals vanish, IRLS stops at once (converged),
 * the result equals the plain fit's quantities. */
START_TEST(exact_surface_converges)
{
    quadric = 1;
    cloud c = make_cloud(30, 0, 0, 0, 4);
    quadric = 0;
    jf_params p;
    jf_params_init(&p);
    p.robust = JF_ROBUST_TUKEY;
    p.frame = JF_FRAME_AXIS; /* z: the quadric is exactly a height function */
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    double nbr[3 * 30], d2[30];
    size_t idx[30];
    size_t q = 15 * 30 + 15;
    knn(&c, q, 30, nbr, idx, d2);
    jf_result a, b;
    ck_assert_int_eq(jf_fit_point(f, c.xyz + 3 * q, nbr, 30, &a), JF_OK);
    ck_assert_int_eq(jf_fit_point_full(f, c.xyz + 3 * q, nbr, 30, &b), JF_OK);
    if (verbose()) printf("exact: a.k1 %g b.k1 %g status %u\n", a.k1, b.k1, b.status);
    ck_assert_uint_eq(b.status & JF_PT_ROBUST_NOCONV, 0);
    ck_assert_double_eq_tol(a.k1, b.k1, 1e-6 * fabs(a.k1));
    ck_assert_double_eq_tol(a.k2, b.k2, 1e-6 * fabs(a.k1));
    /* a corrupted neighbour among few points and NaN neighbours: no crash,
     * finite result */
    nbr[3 * 5 + 2] += 0.05;
    nbr[3 * 7] = NAN;
    ck_assert_int_eq(jf_fit_point_full(f, c.xyz + 3 * q, nbr, 30, &b), JF_OK);
    ck_assert(isfinite(b.k1) && isfinite(b.normal[2]));
    /* the exact normal of the quadric at (u, v) */
    double u = c.uv[2 * q], v = c.uv[2 * q + 1];
    double nt[3] = {-(0.8 * u + 0.1 * v), -(-0.4 * v + 0.1 * u), 1.0};
    ck_assert_double_lt(jf_normal_angle_deg(b.normal, nt), 1e-6);
    jf_fitter_free(f);
    free(c.xyz);
    free(c.uv);
}
END_TEST

/* More neighbours than the stack buffer holds (the per-thread buffer):
 * same answer as the plain fit on exact data, no NOCONV. */
START_TEST(large_neighbourhood)
{
    quadric = 1;
    cloud c = make_cloud(30, 0, 0, 0, 5);
    quadric = 0;
    jf_params p;
    jf_params_init(&p);
    p.robust = JF_ROBUST_HUBER;
    p.frame = JF_FRAME_AXIS;
    p.max_neighbors = 700;
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(&p, &f), JF_OK);
    double *nbr = malloc(3 * 700 * sizeof *nbr), *d2 = malloc(700 * sizeof *d2);
    size_t *idx = malloc(700 * sizeof *idx);
    size_t q = 15 * 30 + 15;
    knn(&c, q, 700, nbr, idx, d2);
    jf_result a, b;
    ck_assert_int_eq(jf_fit_point(f, c.xyz + 3 * q, nbr, 700, &a), JF_OK);
    ck_assert_int_eq(jf_fit_point_full(f, c.xyz + 3 * q, nbr, 700, &b), JF_OK);
    ck_assert_uint_eq(b.status & JF_PT_ROBUST_NOCONV, 0);
    ck_assert_double_eq_tol(a.k1, b.k1, 1e-9);
    ck_assert_double_eq_tol(b.k1, 0.8 + 0.0, 0.05); /* z = 0.4u^2 ...: k ~ 0.8 near 0 */
    free(nbr);
    free(d2);
    free(idx);
    jf_fitter_free(f);
    free(c.xyz);
    free(c.uv);
}
END_TEST


/* A roof z = a|u| (dihedral crease along v) sampled like make_cloud, with
 * Gaussian noise sigma (per axis); median normal error (degrees) of the
 * *npts points at 0.05 <= |u| <= 0.15, |v| <= 0.3 (their K-neighbourhoods
 * straddle the crease), fitted from their K nearest with p; *lowered:
 * fits below p->degree. */
static double roof_err(double a, double sigma, size_t K, const jf_params *p, size_t *lowered,
                       size_t *npts)
{
    int m = 50;
    cloud c;
    rng_state = 11;
    c.n = (size_t)m * m;
    c.xyz = malloc(3 * c.n * sizeof *c.xyz);
    c.uv = malloc(2 * c.n * sizeof *c.uv);
    double h = 1.0 / (m - 1);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            size_t k = (size_t)i * m + j;
            double u = -0.5 + i * h + 0.9 * h * urand() - 0.45 * h;
            double v = -0.5 + j * h + 0.9 * h * urand() - 0.45 * h;
            c.uv[2 * k] = u;
            c.uv[2 * k + 1] = v;
            c.xyz[3 * k] = u + sigma * grand();
            c.xyz[3 * k + 1] = v + sigma * grand();
            c.xyz[3 * k + 2] = a * fabs(u) + sigma * grand();
        }
    jf_fitter *f;
    ck_assert_int_eq(jf_fitter_create(p, &f), JF_OK);
    ck_assert_int_eq(jf__robust_tune(f, "degree_floor_n", roof_floor_n), 0);
    double *nbr = malloc(3 * K * sizeof *nbr), *d2 = malloc(K * sizeof *d2);
    size_t *idx = malloc(K * sizeof *idx);
    double *e = malloc(c.n * sizeof *e);
    size_t ne = 0;
    *lowered = 0;
    for (size_t q = 0; q < c.n; q++) {
        double u = c.uv[2 * q], v = c.uv[2 * q + 1];
        if (fabs(u) < 0.05 || fabs(u) > 0.15 || fabs(v) > 0.3) continue;
        knn(&c, q, K, nbr, idx, d2);
        jf_result r;
        ck_assert_int_eq(jf_fit_point_full(f, c.xyz + 3 * q, nbr, K, &r), JF_OK);
        double w = sqrt(1 + a * a), nt[3] = {-(u > 0 ? a : -a) / w, 0, 1 / w};
        e[ne++] = jf_normal_angle_deg(r.normal, nt);
        if (r.degree < p->degree) (*lowered)++;
    }
    double med = median(e, ne);
    *npts = ne;
    free(e);
    free(nbr);
    free(d2);
    free(idx);
    free(c.xyz);
    free(c.uv);
    jf_fitter_free(f);
    return med;
}

/* --robust-normals' parameters (degree_select 1, dist_weight 0.55)
 * against analytic normals.  §6.1 surface: exact with K = 64 degree 2,
 * the weighted top degree is kept everywhere and beats the plain fit;
 * 0.5% noise with K = 18 degree 3, the plane or quadric takes over and
 * beats the plain cubic.  Roof z = |u| near its crease with K = 256 and
 * noise 0.05 (noise / radius ~ 0.4, above the 0.3 blob floor): the floor
 * shrunk like sqrt(50 / n) keeps the weighted quadric, which sees mostly
 * the point's own face, where the unshrunk floor (degree_floor_n = 0, the
 * rule before) hands nearly every point to the plane, which averages both
 * faces. */
START_TEST(robust_normals_preset)
{
    jf_params p;
    jf_params_init(&p);
    p.max_neighbors = 512;
    cloud e = make_cloud(50, 0.0, 0, 0, 4);
    errs plain = run(&e, &p, 64, 0);
    p.degree_select = 1;
    p.dist_weight = 0.55;
    n_lowered = 0;
    errs pre = run(&e, &p, 64, 0);
    if (verbose()) printf("exact K=64 d2: plain %.4f deg, preset %.4f (lowered %zu)\n", plain.med_normal,
                          pre.med_normal, n_lowered);
    ck_assert_uint_eq(n_lowered, 0);
    ck_assert_double_lt(pre.med_normal, 0.9 * plain.med_normal);
    free(e.xyz);
    free(e.uv);

    cloud c = make_cloud(50, 0.005 * DIAG61, 0, 0, 3);
    p.degree = 3;
    p.degree_select = 0;
    p.dist_weight = 0.0;
    errs cub = run(&c, &p, 18, 0);
    p.degree_select = 1;
    p.dist_weight = 0.55;
    n_lowered = 0;
    errs pn = run(&c, &p, 18, 0);
    if (verbose()) printf("noise K=18 d3: cubic %.3f deg, preset %.3f (lowered %zu)\n", cub.med_normal,
                          pn.med_normal, n_lowered);
    ck_assert_uint_gt(n_lowered, 10);
    ck_assert_double_lt(pn.med_normal, 0.5 * cub.med_normal);
    free(c.xyz);
    free(c.uv);

    size_t low_new, low_old, npts, l;
    p.degree = 2;
    double en = roof_err(1.0, 0.05, 256, &p, &low_new, &npts);
    roof_floor_n = 0.0;
    double eo = roof_err(1.0, 0.05, 256, &p, &low_old, &npts);
    roof_floor_n = 50.0;
    p.degree_select = 0;
    p.dist_weight = 0.0;
    double eq = roof_err(1.0, 0.05, 256, &p, &l, &npts);
    p.degree = 1;
    double ep = roof_err(1.0, 0.05, 256, &p, &l, &npts);
    if (verbose())
        printf("roof K=256 noise 0.05: plane %.3f quadric %.3f preset %.3f (lowered %zu/%zu), "
               "unshrunk floor %.3f (lowered %zu)\n", ep, eq, en, low_new, npts, eo, low_old);
    ck_assert_uint_gt(low_old, 9 * npts / 10);
    ck_assert_uint_lt(low_new, npts / 5);
    ck_assert_double_lt(en, 0.9 * eo);
    ck_assert_double_lt(en, 0.95 * fmin(ep, eq));
}
END_TEST

int main(void)
{
    Suite *s = suite_create("robust");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, plain_is_jf_fit_point);
    tcase_add_test(tc, exact_surface_converges);
    tcase_add_test(tc, large_neighbourhood);
    tcase_add_test(tc, scale_selection_beats_best_fixed_k);
    tcase_add_test(tc, scale_selection_uniform_noise_near_best);
    tcase_add_test(tc, scale_selection_plane_uniform_noise_beats_best_fixed_k);
    tcase_add_test(tc, scale_selection_top_degree_and_degree_select);
    tcase_add_test(tc, reweighting_suppresses_outliers);
    tcase_add_test(tc, degree_selection_noise_and_clean);
    tcase_add_test(tc, distance_weighting_lowers_truncation_error);
    tcase_add_test(tc, new_params_validated);
    tcase_add_test(tc, robust_normals_preset);
    suite_add_tcase(s, tc);
    return jf_test_run(s);
}
