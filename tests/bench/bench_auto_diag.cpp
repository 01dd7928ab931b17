// bench_auto_diag.cpp -- per-point diagnosis of `--neighbors auto` (issue
// 27; docs/robustness.md "Neighbourhood auto"): for every evaluated point,
// every candidate (K, degree) auto considered -- its step-1 normal, sd per
// unit noise, radius, and the error of its reported fit (the fit of
// knn:K --degree d) against the truth -- beside auto's choice, so that a
// script can find the oracle K and test selection rules offline
// (tests/bench/auto_diag.py).
//
// usage: bench_auto_diag CLOUD TRUTH OUT [--pidx FILE] [--every M]
//          [--noise L] [--knob NAME=V ...]
//   CLOUD  the points (any jf_cloud_read format; PCPNet .xyz)
//   TRUTH  a table with nx ny nz [k1 k2] per point (generate's --truth,
//          PCPNet .normals)
//   --pidx the evaluated points (PCPNet .pidx), else every M-th point
//   --noise Gaussian noise of L x the bounding-box diagonal per axis,
//          bench_pcpnet's draws (mt19937_64, seed 20031), the truth kept
// OUT, one line per evaluated point:
//   index nc ci d sigma2 auto_err tnx tny tnz (the true normal), then per
//   candidate c, per degree 2, 3: K ok tr h nx ny nz (step 1's normal)
//   err_deg dk1 dk2 rnx rny rnz k1 k2 (the reported fit's) s2 (the
//   candidate's unbiased residual variance)
// (dk: |k - k_true| after jf_curv_compare's orientation; nan without
// curvature truth).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "jetfit.h"
extern "C" {
#include "robust_internal.h"
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        std::fprintf(stderr, "usage: bench_auto_diag CLOUD TRUTH OUT [--pidx F] [--every M] [--noise L]\n");
        return 2;
    }
    const char *pidx = nullptr;
    size_t every = 1;
    double noise = 0;
    std::vector<std::pair<std::string, double>> knobs;
    for (int i = 4; i < argc; i++) {
        if (!std::strcmp(argv[i], "--pidx") && i + 1 < argc) pidx = argv[++i];
        else if (!std::strcmp(argv[i], "--every") && i + 1 < argc) every = std::strtoul(argv[++i], nullptr, 10);
        else if (!std::strcmp(argv[i], "--noise") && i + 1 < argc) noise = std::atof(argv[++i]);
        else if (!std::strcmp(argv[i], "--knob") && i + 1 < argc) {
            std::string a = argv[++i];
            size_t e = a.find('=');
            if (e == std::string::npos) return 2;
            knobs.emplace_back(a.substr(0, e), std::atof(a.c_str() + e + 1));
        } else {
            std::fprintf(stderr, "bench_auto_diag: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    jf_cloud c;
    jf_error err;
    if (jf_cloud_read(argv[1], nullptr, &c, &err) != JF_OK) {
        std::fprintf(stderr, "bench_auto_diag: %s\n", err.msg);
        return 1;
    }
    jf_eval_table tt;
    if (jf_eval_table_read(argv[2], &tt, &err) != JF_OK) {
        std::fprintf(stderr, "bench_auto_diag: %s\n", err.msg);
        return 1;
    }
    int cn[5];
    const char *nm[5] = {"nx", "ny", "nz", "k1", "k2"};
    for (int j = 0; j < 5; j++) cn[j] = jf_eval_table_col(&tt, nm[j]);
    if (cn[0] < 0 || cn[1] < 0 || cn[2] < 0 || tt.nrows != c.n) {
        std::fprintf(stderr, "bench_auto_diag: %s: no nx ny nz, or not one row per point\n", argv[2]);
        return 1;
    }
    std::vector<size_t> eval;
    if (pidx) {
        jf_eval_table ti;
        if (jf_eval_table_read(pidx, &ti, &err) != JF_OK) return 1;
        for (size_t j = 0; j < ti.nrows; j++) eval.push_back((size_t)ti.v[j * ti.ncols]);
        jf_eval_table_free(&ti);
    } else
        for (size_t i = 0; i < c.n; i += every) eval.push_back(i);
    std::vector<double> xyz(c.xyz, c.xyz + 3 * c.n);
    if (noise > 0) { // bench_pcpnet's draws
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < c.n; i++)
            for (int d = 0; d < 3; d++) {
                lo[d] = std::fmin(lo[d], xyz[3 * i + d]);
                hi[d] = std::fmax(hi[d], xyz[3 * i + d]);
            }
        double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                (hi[2] - lo[2]) * (hi[2] - lo[2]));
        std::mt19937_64 rng(20031);
        std::normal_distribution<double> g(0.0, noise * diag);
        for (double &x : xyz) x += g(rng);
    }
    jf_index *ix = nullptr;
    if (jf_index_build(xyz.data(), c.n, &ix) != JF_OK) return 1;
    jf_params p;
    jf_params_init(&p);
    p.max_neighbors = JF_NB_AUTO_KMAX;
    p.auto_select = 1;
    jf_fitter *f = nullptr;
    if (jf_fitter_create(&p, &f) != JF_OK) return 1;
    for (auto &k : knobs)
        if (jf__robust_tune(f, k.first.c_str(), k.second) != 0) {
            std::fprintf(stderr, "bench_auto_diag: unknown knob %s\n", k.first.c_str());
            return 2;
        }
    static jf__auto_diag dg;
    jf__auto_diag_attach(f, &dg);
    FILE *o = std::fopen(argv[3], "w");
    if (!o) return 1;
    const size_t K = JF_NB_AUTO_KMAX;
    std::vector<uint32_t> idx(K);
    std::vector<double> nbr(3 * K);
    for (size_t i : eval) {
        const double *q = &xyz[3 * i];
        size_t found = 0;
        jf_index_knn(ix, q, K, idx.data(), nullptr, &found);
        for (size_t t = 0; t < found; t++) std::memcpy(&nbr[3 * t], &xyz[3 * idx[t]], 3 * sizeof(double));
        std::memset(&dg, 0, sizeof dg);
        dg.ci = -2; // untouched: auto did not reach its rule (too few points)
        jf_result r;
        jf_fit_point_full(f, q, nbr.data(), found, &r);
        const double *row = &tt.v[i * tt.ncols];
        double tn[3] = {row[cn[0]], row[cn[1]], row[cn[2]]};
        double tk1 = cn[3] >= 0 ? row[cn[3]] : NAN, tk2 = cn[4] >= 0 ? row[cn[4]] : NAN;
        std::fprintf(o, "%zu %d %d %d %.6g %.6g %.9f %.9f %.9f", i, dg.c.nc, dg.ci, dg.d, dg.c.s2,
                     jf_normal_angle_deg(r.normal, tn), tn[0], tn[1], tn[2]);
        for (int k = 0; k < dg.c.nc; k++)
            for (int e = 0; e < 2; e++) {
                const jf__auto_cand *a = &dg.c.cf[e][k];
                const jf_result *rr = &dg.res[e][k];
                double ea = jf_normal_angle_deg(rr->normal, tn), dk[2] = {NAN, NAN};
                if (std::isfinite(tk1)) jf_curv_compare(rr->normal, rr->k1, rr->k2, tn, tk1, tk2, dk, nullptr);
                std::fprintf(o, " %zu %d %.6g %.6g %.9f %.9f %.9f %.6g %.6g %.6g %.9f %.9f %.9f %.6g %.6g %.6g",
                             dg.c.ks[k], a->ok, a->tr, a->h, a->nrm[0], a->nrm[1], a->nrm[2], ea, dk[0], dk[1],
                             rr->normal[0], rr->normal[1], rr->normal[2], rr->k1, rr->k2, a->s2);
            }
        std::fputc('\n', o);
    }
    std::fclose(o);
    jf_fitter_free(f);
    jf_index_free(ix);
    jf_eval_table_free(&tt);
    jf_cloud_free(&c);
    return 0;
}
