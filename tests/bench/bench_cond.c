/* bench_cond.c -- a measurement to choose the default --max-cond (§5.2,
 * last paragraph: lower the degree where kappa(M') is too large).
 *
 * For degrees 2..4 and knn 16/32/64 it prints the distribution
 * (percentiles) of kappa = sigma_max/sigma_min of the preconditioned
 * Vandermonde matrix (§2.3, jf_result.cond) on
 *   - the §6.1 graph f(u,v) = 0.1 exp(2u + v - v^2), (u,v) in [-0.5,0.5]^2:
 *     A. the paper's perturbed grid (x = u + δh, y = v + δ'h, δ in [0,0.9]),
 *     B. uniform random samples, C. the same with Gaussian noise of
 *     sigma 1e-5 and 1e-4 on z (0.13% and 1.3% of the spacing ~1/128);
 *   - a raw range scan: argv[1], or $JF_DATA/scans/stanford_bunny/data/bun000.ply,
 *     or the bundled data/bun090.ply.
 * Where the truth is known (§6.1) it also fits every neighbourhood at the
 * degree below, and tabulates, per decade of kappa, the curvature error at
 * degree d and at d-1: a threshold is worth having where, above it, the
 * lower degree is more accurate; on the scan (no truth) the same for the
 * deviation of the normal from a K64 degree-2 fit.  Every fit here uses
 * max_cond = 1e300 so
 * nothing is lowered for conditioning (rank-deficient fits are counted).
 *
 * Usage: bench_cond [bun000.ply] [queries=4000]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "jetfit.h"

static uint64_t rng_s = 0x6a09e667f3bcc908ull;
static uint64_t rng_next(void) /* splitmix64 */
{
    uint64_t z = (rng_s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static double rng_uni(void) { return (double)(rng_next() >> 11) * 0x1.0p-53; }
static double rng_gauss(void)
{
    double u = rng_uni(), v = rng_uni();
    return sqrt(-2.0 * log(u + 1e-300)) * cos(6.283185307179586 * v);
}

/* §6.1 graph and its exact normal and principal curvatures (first and
 * second fundamental forms of a graph; upward normal). */
static double f61(double u, double v) { return 0.1 * exp(2 * u + v - v * v); }
static void truth61(double x, double y, double n[3], double *k1, double *k2)
{
    double f = f61(x, y), g = 1 - 2 * y;
    double fx = 2 * f, fy = g * f, fxx = 4 * f, fxy = 2 * g * f,
           fyy = (g * g - 2) * f;
    double w2 = 1 + fx * fx + fy * fy, w = sqrt(w2);
    n[0] = -fx / w; n[1] = -fy / w; n[2] = 1 / w;
    double K = (fxx * fyy - fxy * fxy) / (w2 * w2);
    double H = ((1 + fx * fx) * fyy - 2 * fx * fy * fxy + (1 + fy * fy) * fxx) /
               (2 * w2 * w);
    double disc = sqrt(fmax(H * H - K, 0));
    *k1 = H + disc;
    *k2 = H - disc;
}

typedef struct {
    const char *name;
    double *xyz;
    size_t n;
    int truth;  /* 1: points are (x, y, f61(x, y) + noise) */
} dataset;

static dataset make61(const char *name, int grid, size_t nrand, double noise)
{
    dataset d = {name, NULL, 0, 1};
    d.n = grid ? (size_t)grid * grid : nrand;
    d.xyz = malloc(3 * d.n * sizeof(double));
    for (size_t i = 0; i < d.n; i++) {
        double x, y;
        if (grid) {
            double h = 1.0 / (grid - 1);
            x = -0.5 + (double)(i % grid) * h + 0.9 * h * rng_uni();
            y = -0.5 + (double)(i / grid) * h + 0.9 * h * rng_uni();
        } else {
            x = rng_uni() - 0.5;
            y = rng_uni() - 0.5;
        }
        d.xyz[3 * i] = x;
        d.xyz[3 * i + 1] = y;
        d.xyz[3 * i + 2] = f61(x, y) + noise * rng_gauss();
    }
    return d;
}

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double pct(const double *sorted, size_t n, double p)
{
    if (n == 0) return NAN;
    size_t i = (size_t)(p / 100.0 * (double)(n - 1) + 0.5);
    return sorted[i < n ? i : n - 1];
}

enum { NBINS = 9 };  /* kappa decades [1,10) ... [1e8, inf) */
typedef struct {
    double *err_d[NBINS], *err_lo[NBINS];
    size_t cnt[NBINS], lower_wins[NBINS];
    double *kap, *e, *el;  /* every fit: kappa, error at d, error at d-1 */
    size_t n;
} bins;

/* Sine of the angle between two unit normals (orientation ignored). */
static double normal_dev(const double *a, const double *b)
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    double s = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    return isfinite(s) ? s : 1.0;  /* a failed fit: worst possible */
}

/* Error of a fit at data point p of the 6.1 graph: for degree >= 2 the
 * curvature error max(|dk1|, |dk2|) / max(|k1|, |k2|); with normal != 0
 * (degree 2 against degree 1, which has no curvature) the sine of the
 * normal's angle. */
static double err61(const jf_result *r, const double *p, int normal)
{
    double n[3], k1, k2;
    truth61(p[0], p[1], n, &k1, &k2);
    jf_result o = *r;
    jf_result_orient(&o, n);
    if (normal) return normal_dev(o.normal, n);
    double s = fmax(fabs(k1), fabs(k2));
    double e = fmax(fabs(o.k1 - k1), fabs(o.k2 - k2)) / s;
    return isfinite(e) ? e : INFINITY;  /* a failed fit sorts last */
}

/* The adaptive rule with threshold T on these fits: the degree-d error
 * where kappa <= T, the degree-(d-1) error elsewhere. */
static void print_policy(int d, const bins *B, double *tmp)
{
    static const double T[7] = {1e2, 1e3, 1e4, 1e5, 1e6, 1e8, INFINITY};
    printf("    max_cond    lowered   err p50   err p90   err p99 "
           "(the rule: d%d where kappa <= max_cond, else d%d)\n", d, d - 1);
    for (int t = 0; t < 7; t++) {
        size_t low = 0;
        for (size_t i = 0; i < B->n; i++) {
            int lo = B->kap[i] > T[t];
            low += lo;
            tmp[i] = lo ? B->el[i] : B->e[i];
        }
        qsort(tmp, B->n, sizeof *tmp, cmp_dbl);
        printf("    %8.0e %9.2f%% %9.3g %9.3g %9.3g\n", T[t],
               100.0 * (double)low / (double)(B->n ? B->n : 1),
               pct(tmp, B->n, 50), pct(tmp, B->n, 90), pct(tmp, B->n, 99));
    }
}

static void print_bins(const char *name, int d, int truth, bins *B)
{
    printf("  %s, degree %d: %s by kappa decade, d%d vs d%d on the "
           "same points (median, p90), share where d%d is better\n", name, d,
           !truth ? "normal deviation (sine) from a K64 2-jet (no truth)"
           : d == 2 ? "normal error (sine)" : "curvature error max|dk|/max|k|",
           d, d - 1, d - 1);
    for (int b = 0; b < NBINS; b++) {
        size_t n = B->cnt[b];
        if (!n) continue;
        qsort(B->err_d[b], n, sizeof(double), cmp_dbl);
        qsort(B->err_lo[b], n, sizeof(double), cmp_dbl);
        char hi[16];
        if (b == NBINS - 1) snprintf(hi, sizeof hi, "inf");
        else snprintf(hi, sizeof hi, "1e%d", b + 1);
        printf("    kappa [1e%d,%-4s) %6zu  d%d %9.3g %9.3g   d%d %9.3g %9.3g"
               "   %5.1f%%\n", b, hi, n, d, pct(B->err_d[b], n, 50),
               pct(B->err_d[b], n, 90), d - 1, pct(B->err_lo[b], n, 50),
               pct(B->err_lo[b], n, 90),
               100.0 * (double)B->lower_wins[b] / (double)n);
    }
}

/* One dataset, degree d, K neighbours, Q random queries. */
static void run(const dataset *ds, const jf_index *ix, int d, size_t K,
                size_t Q, jf_fit_mode mode, bins *B)
{
    jf_params p;
    jf_params_init(&p);
    p.fit = mode;
    p.degree = d;
    p.monge_degree = 2;
    p.max_cond = 1e300;
    if (p.max_neighbors < K) p.max_neighbors = K;
    jf_params plo = p;
    plo.degree = d - 1;
    if (plo.degree < 2) plo.monge_degree = plo.degree < 1 ? 1 : 2;
    /* no truth (raw scan): the normal of a degree-2 fit on the 64 nearest
     * points is the reference (a proxy, smooth and well conditioned) */
    jf_params pref;
    jf_params_init(&pref);
    pref.degree = 2;
    pref.max_cond = 1e300;
    if (pref.max_neighbors < 64) pref.max_neighbors = 64;
    jf_fitter *f = NULL, *flo = NULL, *fref = NULL;
    if (jf_fitter_create(&p, &f) != JF_OK ||
        jf_fitter_create(&plo, &flo) != JF_OK ||
        (!ds->truth && jf_fitter_create(&pref, &fref) != JF_OK)) {
        fprintf(stderr, "bench_cond: fitter_create failed\n");
        exit(2);
    }
    size_t cap = K > 64 ? K : 64;
    uint32_t *idx = malloc(cap * sizeof *idx);
    double *nb = malloc(3 * cap * sizeof(double));
    double *kap = malloc(Q * sizeof(double));
    size_t nk = 0, rank = 0;
    for (size_t q = 0; q < Q; q++) {
        const double *pt = ds->xyz + 3 * (rng_next() % ds->n);
        size_t found = 0;
        jf_index_knn(ix, pt, K, idx, NULL, &found);
        for (size_t i = 0; i < found; i++)
            memcpy(nb + 3 * i, ds->xyz + 3 * (size_t)idx[i], 3 * sizeof(double));
        jf_result r;
        jf_fit_point(f, pt, nb, found, &r);
        if (r.degree != d) { rank++; continue; }
        kap[nk++] = r.cond;
        jf_result rl;
        jf_fit_point(flo, pt, nb, found, &rl);
        int b = r.cond < 1 ? 0 : (int)floor(log10(r.cond));
        if (b >= NBINS) b = NBINS - 1;
        double e, el;
        if (ds->truth) {
            e = err61(&r, pt, d == 2);
            el = err61(&rl, pt, d == 2);
        } else {
            jf_result rr;
            jf_index_knn(ix, pt, 64, idx, NULL, &found);
            for (size_t i = 0; i < found; i++)
                memcpy(nb + 3 * i, ds->xyz + 3 * (size_t)idx[i],
                       3 * sizeof(double));
            jf_fit_point(fref, pt, nb, found, &rr);
            e = normal_dev(r.normal, rr.normal);
            el = normal_dev(rl.normal, rr.normal);
        }
        B->err_d[b][B->cnt[b]] = e;
        B->err_lo[b][B->cnt[b]] = el;
        B->cnt[b]++;
        B->lower_wins[b] += el < e;
        B->kap[B->n] = r.cond;
        B->e[B->n] = e;
        B->el[B->n] = el;
        B->n++;
    }
    qsort(kap, nk, sizeof *kap, cmp_dbl);
    size_t over[3] = {0, 0, 0};  /* kappa > 1e3, 1e4, 1e6 */
    for (size_t i = 0; i < nk; i++) {
        over[0] += kap[i] > 1e3;
        over[1] += kap[i] > 1e4;
        over[2] += kap[i] > 1e6;
    }
    double pc = 100.0 / (double)(nk ? nk : 1);
    printf("%-22s %cd%d K%-3zu %6zu %9.3g %9.3g %9.3g %9.3g %9.3g %6zu "
           "%6.2f%% %6.2f%% %6.2f%%\n", ds->name,
           mode == JF_FIT_INTERP ? 'i' : ' ', d, K, nk, pct(kap, nk, 50),
           pct(kap, nk, 90), pct(kap, nk, 99), pct(kap, nk, 99.9),
           nk ? kap[nk - 1] : NAN, rank, over[0] * pc, over[1] * pc,
           over[2] * pc);
    free(kap);
    free(nb);
    free(idx);
    jf_fitter_free(f);
    jf_fitter_free(flo);
    jf_fitter_free(fref);
}

int main(int argc, char **argv)
{
    char envpath[4096];
    const char *env = getenv("JF_DATA");
    if (env)
        snprintf(envpath, sizeof envpath, "%s/scans/stanford_bunny/data/bun000.ply", env);
    const char *bunny = argc > 1 ? argv[1] : env ? envpath : JF_TEST_DATA "/bun090.ply";
    size_t Q = argc > 2 ? strtoul(argv[2], NULL, 10) : 4000;
    if (Q < 1) return 2;

    dataset sets[5];
    int nsets = 0;
    sets[nsets++] = make61("6.1 perturbed grid", 128, 0, 0);
    sets[nsets++] = make61("6.1 uniform random", 0, 16384, 0);
    sets[nsets++] = make61("6.1 random +1e-5 noise", 0, 16384, 1e-5);
    sets[nsets++] = make61("6.1 random +1e-4 noise", 0, 16384, 1e-4);
    const int ntruth = nsets;
    jf_cloud c;
    memset(&c, 0, sizeof c);
    jf_error err;
    if (jf_cloud_read(bunny, NULL, &c, &err) == JF_OK) {
        dataset b = {"bunny bun000 (raw)", c.xyz, c.n, 0};
        sets[nsets++] = b;
    } else {
        fprintf(stderr, "bench_cond: %s (bunny skipped)\n", err.msg);
    }
    jf_index *ix[5] = {NULL};
    for (int s = 0; s < nsets; s++)
        if (jf_index_build(sets[s].xyz, sets[s].n, &ix[s]) != JF_OK) {
            fprintf(stderr, "bench_cond: index build failed\n");
            return 2;
        }

    printf("bench_cond: kappa(M') of jf_fit_point (PCA frame, approximation"
           " and interpolation (i), max_cond off), %zu random queries per row; 6.1 sets: 16384 "
           "points (grid 128^2), spacing ~1/128\n", Q);
    const size_t Ks[3] = {16, 32, 64};
    for (int d = 2; d <= 4; d++) {
        printf("%-22s %-7s %6s %9s %9s %9s %9s %9s %6s %7s %7s %7s\n", "data",
               "fit", "fits", "p50", "p90", "p99", "p99.9", "max", "rank-",
               ">1e3", ">1e4", ">1e6");
        /* B[s]: approximation, K = 16, 32, 64 pooled; B[5 + s]:
         * interpolation (K = N_d, the N_d nearest) */
        bins B[10];
        memset(B, 0, sizeof B);
        for (int s = 0; s < 2 * nsets; s++) {
            int bi = s < nsets ? s : 5 + s - nsets;
            for (int b = 0; b < NBINS; b++) {
                B[bi].err_d[b] = malloc(3 * Q * sizeof(double));
                B[bi].err_lo[b] = malloc(3 * Q * sizeof(double));
            }
            B[bi].kap = malloc(3 * Q * sizeof(double));
            B[bi].e = malloc(3 * Q * sizeof(double));
            B[bi].el = malloc(3 * Q * sizeof(double));
        }
        for (int s = 0; s < nsets; s++) {
            for (int k = 0; k < 3; k++) {
                if (jf_jet_size(d) > Ks[k]) continue;
                run(&sets[s], ix[s], d, Ks[k], Q, JF_FIT_APPROX, &B[s]);
            }
        }
        for (int s = 0; s < nsets; s++)
            run(&sets[s], ix[s], d, jf_jet_size(d), Q, JF_FIT_INTERP,
                &B[5 + s]);
        double *tmp = malloc(3 * Q * sizeof(double));
        for (int s = 0; s < 2 * nsets; s++) {
            int bi = s < nsets ? s : 5 + s - nsets, ds = s % nsets;
            printf("  -- %s\n", s < nsets ? "approximation, K 16/32/64"
                                          : "interpolation, K = N_d");
            print_bins(sets[ds].name, d, ds < ntruth, &B[bi]);
            print_policy(d, &B[bi], tmp);
            for (int b = 0; b < NBINS; b++) {
                free(B[bi].err_d[b]);
                free(B[bi].err_lo[b]);
            }
            free(B[bi].kap);
            free(B[bi].e);
            free(B[bi].el);
        }
        free(tmp);
    }
    for (int s = 0; s < nsets; s++) jf_index_free(ix[s]);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("peak RSS %.1f MB\n", ru.ru_maxrss / 1024.0);
    for (int s = 0; s < ntruth; s++) free(sets[s].xyz);
    jf_cloud_free(&c);
    return 0;
}
