// bench_pcpnet.cpp -- the PCPNet normal study on armadillo100k (issue 6).
//
// For the clean shape and Gaussian-noise copies (sigma = level x bbox
// diagonal per axis, levels 0.00125 / 0.006 / 0.012, fixed seed; the GT
// normals are those of the clean point of the same index), the RMS of the
// unoriented normal angle on the 5000 .pidx points, for:
//   jetfit  jf_index k-NN + jf_fit_point_full, K = 18 / 112 / 450,
//           degree 2 and 3, and robust / scale-selection configurations;
//   CGAL    jet_estimate_normals (degree 2 and 3) and pca_estimate_normals,
//           Sequential_tag, on the same points in the same run.
// CGAL computes every one of the 100k points (its API has no query subset);
// jetfit fits only the 5000 evaluated points, so times are reported per
// fit.  CGAL's k counts the neighbours besides the query point (k + 1
// points, Point_set_processing_3/internal/Neighbor_query.h); jetfit's K
// counts the point itself (K points).
// Usage: bench_pcpnet [DATA_DIR] [--quick] [--no-cgal] [--no-fixed]
//   [--sweep "K,deg,robust[,dsel] ..."] [--varw X] [--floor X] [--target X]
//   [--dtau X] [--dsdmin X] [--dfloorn X] [--distw X] [--same-points]
//   [--levels L1,L2,..] [--cgal-k K] [--seed S]
// --same-points: jetfit fits K + 1 points like CGAL (default: K, the query
// included); --distw X: dist_weight of the --sweep configurations;
// --dtau, --dsdmin, --dfloorn: the degree-selection knobs of robust.c
// (interval width, sd below which the top degree is kept, size above
// which the blob floor shrinks); --levels: only these noise
// levels; --seed: the noise draws' seed (default 20031: another seed,
// another draw of the same levels); --cgal-k: CGAL at this K only (its
// K = 450 runs take minutes);
// --quick: clean shape and the largest noise only, K = 18 and 112;
// --sweep adds configurations (K may be a scale set "12/18/36"; robust
// 0/1/2 = none/huber/tukey; with --no-fixed only those run); --varw,
// --floor, --target override the scale-selection constants of robust.c;
// --auto adds neighbors auto (jf_estimate on the whole cloud: the rows the
// command writes), --auto-tau/-blob/-sdmax/-varw/-clean/-gl/-nest/-lof/
// -s2floor/-flat/-dw X set robust.c's auto_* knob of that name (then each
// .pidx point's own fit, without step 6: the knobs are a fitter's).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/property_map.h>

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "jetfit.h"

// src/robust/robust.c's bench-only setter of its tuning constants (scale_varw,
// scale_target, scale_floor, degree_tau, degree_sdmin, degree_floor_n).
extern "C" int jf__robust_tune(jf_fitter *f, const char *name, double v);
// the knobs given on the command line, applied to every fitter made
static std::vector<std::pair<std::string, double>> tunes;
static void tune(const char *name, double v) { tunes.emplace_back(name, v); }

typedef CGAL::Exact_predicates_inexact_constructions_kernel Kernel;
typedef Kernel::Point_3 Point;
typedef Kernel::Vector_3 Vector;
typedef std::pair<Point, Vector> PN;

static double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static long peak_kb()
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

static bool load(const std::string &path, jf_eval_table &t)
{
    jf_error e;
    if (jf_eval_table_read(path.c_str(), &t, &e) != JF_OK) {
        std::fprintf(stderr, "bench_pcpnet: %s\n", e.msg);
        return false;
    }
    return true;
}

struct Study {
    std::vector<double> xyz;          // current (noisy) cloud
    std::vector<double> gt;           // GT normals, 3 per point
    std::vector<uint32_t> pidx;       // evaluated points
};

static double g_median, g_p95; // of the last rms_angle call
static double rms_angle(const Study &s, const std::vector<double> &nrm)
{
    std::vector<double> all;
    double sum = 0;
    for (size_t j = 0; j < s.pidx.size(); j++) {
        uint32_t i = s.pidx[j];
        double a = jf_normal_angle_deg(&nrm[3 * j], &s.gt[3 * i]);
        if (!std::isfinite(a)) a = 90.0; // an unfitted point counts as the worst angle
        sum += a * a;
        all.push_back(a);
    }
    jf_err_stats st;
    jf_err_stats_compute(all.data(), all.size(), &st);
    g_median = st.median;
    g_p95 = st.p95;
    return std::sqrt(sum / (double)all.size());
}

struct Config {
    const char *name;
    int degree;
    size_t k;                  // neighbours fetched (largest scale)
    jf_robust_mode robust;
    int nscales;
    size_t scales[8];
    int dsel; // jf_params.degree_select (0 = off)
    double distw; // jf_params.dist_weight (0 = off)
};

// --same-points: jetfit fits K + 1 points (the query and K neighbours), the
// neighbourhood CGAL uses for its k = K; every scale likewise + 1.
static size_t g_extra = 0;
static double g_distw = 0; // --distw: jf_params.dist_weight of the sweep configs

// jetfit on the .pidx points; returns the RMS angle, fills secs.
static double run_jetfit(const Study &s, const jf_index *ix, const Config &c0, double *secs,
                         size_t *flagged)
{
    Config c = c0;
    c.k += g_extra;
    for (int i = 0; i < c.nscales; i++) c.scales[i] += g_extra;
    *secs = 0;
    *flagged = 0;
    jf_params p;
    jf_params_init(&p);
    p.degree = c.degree;
    p.max_neighbors = c.k;
    p.robust = c.robust;
    p.nscales = c.nscales;
    for (int i = 0; i < c.nscales; i++) p.scales[i] = c.scales[i];
    p.degree_select = c.dsel;
    p.dist_weight = c.distw;
    p.auto_select = !std::strcmp(c.name, "jetfit auto"); // neighbors auto
    jf_fitter *f = nullptr;
    const char *bad = nullptr;
    if (jf_params_validate(&p, &bad) != JF_OK || jf_fitter_create(&p, &f) != JF_OK) {
        std::fprintf(stderr, "bench_pcpnet: bad params (%s)\n", bad ? bad : "?");
        return NAN;
    }
    for (auto &t : tunes) jf__robust_tune(f, t.first.c_str(), t.second);
    std::vector<uint32_t> idx(c.k);
    std::vector<double> nbr(3 * c.k), nrm(3 * s.pidx.size());
    std::map<std::pair<int, int>, size_t> chosen;
    double sig = 0;
    double t0 = now();
    // auto without knobs: jf_estimate on the whole cloud, the product's
    // rows (steps 1-6: step 6 reads the neighbours' fits); with a knob,
    // each .pidx point's own fit (steps 1-5), the knobs being a fitter's
    std::vector<jf_result> rows;
    if (p.auto_select && tunes.empty()) {
        jf_estimate_opts o;
        jf_estimate_opts_init(&o);
        o.nb.kind = JF_NB_AUTO;
        o.orient = JF_ORIENT_NONE;
        o.threads = 1;
        jf_cloud cl = {};
        cl.n = s.xyz.size() / 3;
        cl.xyz = const_cast<double *>(s.xyz.data()); // read only
        rows.resize(cl.n);
        jf_error e;
        if (jf_estimate(&cl, &o, rows.data(), &e) != JF_OK) {
            std::fprintf(stderr, "bench_pcpnet: jf_estimate: %s\n", e.msg);
            jf_fitter_free(f);
            return NAN;
        }
    } else if (p.auto_select)
        std::printf("# auto with knobs: each point's own fit (steps 1-5, no step 6)\n");
    for (size_t j = 0; j < s.pidx.size(); j++) {
        if (!rows.empty()) {
            const jf_result &r = rows[s.pidx[j]];
            std::memcpy(&nrm[3 * j], r.normal, 3 * sizeof(double));
            if (r.status & JF_PT_FAILED) (*flagged)++;
            chosen[std::make_pair(r.n_used, r.degree)]++;
            sig += r.sigma;
            continue;
        }
        const double *q = &s.xyz[3 * s.pidx[j]];
        size_t found = 0;
        jf_index_knn(ix, q, c.k, idx.data(), nullptr, &found);
        for (size_t t = 0; t < found; t++)
            std::memcpy(&nbr[3 * t], &s.xyz[3 * idx[t]], 3 * sizeof(double));
        jf_result r;
        jf_fit_point_full(f, q, nbr.data(), found, &r);
        std::memcpy(&nrm[3 * j], r.normal, 3 * sizeof(double));
        if (r.status & (JF_PT_ROBUST_NOCONV | JF_PT_FAILED)) (*flagged)++;
        if (p.auto_select) {
            chosen[std::make_pair(r.n_used, r.degree)]++;
            sig += r.sigma;
        }
    }
    if (p.auto_select) { // what auto chose: K x degree histogram, mean sigma
        std::printf("# auto chose (K/degree: points):");
        for (auto &e : chosen) std::printf(" %d/%d:%zu", e.first.first, e.first.second, e.second);
        std::printf("; mean sigma %.4g\n", sig / (double)s.pidx.size());
    }
    *secs = now() - t0; // auto without knobs: the whole cloud's time
    jf_fitter_free(f);
    return rms_angle(s, nrm);
}

// CGAL on the whole cloud; the RMS on the .pidx points.
static double run_cgal(const Study &s, bool jet, int degree, size_t k, double *secs)
{
    size_t n = s.xyz.size() / 3;
    std::vector<PN> pts(n);
    for (size_t i = 0; i < n; i++)
        pts[i] = PN(Point(s.xyz[3 * i], s.xyz[3 * i + 1], s.xyz[3 * i + 2]), Vector(0, 0, 0));
    auto np = CGAL::parameters::point_map(CGAL::First_of_pair_property_map<PN>())
                  .normal_map(CGAL::Second_of_pair_property_map<PN>());
    double t0 = now();
    if (jet)
        CGAL::jet_estimate_normals<CGAL::Sequential_tag>(pts, (unsigned)k, np.degree_fitting(degree));
    else
        CGAL::pca_estimate_normals<CGAL::Sequential_tag>(pts, (unsigned)k, np);
    *secs = now() - t0;
    std::vector<double> nrm(3 * s.pidx.size());
    for (size_t j = 0; j < s.pidx.size(); j++) {
        const Vector &v = pts[s.pidx[j]].second;
        nrm[3 * j] = v.x();
        nrm[3 * j + 1] = v.y();
        nrm[3 * j + 2] = v.z();
    }
    return rms_angle(s, nrm);
}

int main(int argc, char **argv)
{
    // the PCPNet folder: argv (any non-option argument), else $JF_DATA/pcpnet
    const char *env = std::getenv("JF_DATA");
    std::string dir = env ? std::string(env) + "/pcpnet" : std::string();
    bool quick = false, no_cgal = false, no_fixed = false, with_auto = false,
         cgal_jet2 = false; // CGAL: jet degree 2 only (issue 27's peer)
    const char *cgal_ks = nullptr; // "18,32,64": CGAL's K list (default: the jetfit Ks)
    const char *sweep = nullptr; // "K,deg,robust[,dsel] ...": extra fixed configs
    const char *only_levels = nullptr; // "0,0.012": a subset of the noise levels
    bool same_points = false;    // jetfit fits K + 1 points, CGAL's neighbourhood
    size_t cgal_k = 0;           // run CGAL at this K only (0 = every K)
    unsigned long seed = 20031;  // the noise draws' (--seed: another draw of the same levels)
    for (int i = 1; i < argc; i++) {
        if (!std::strcmp(argv[i], "--quick")) quick = true;
        else if (!std::strcmp(argv[i], "--no-cgal")) no_cgal = true;
        else if (!std::strcmp(argv[i], "--no-fixed")) no_fixed = true;
        else if (!std::strcmp(argv[i], "--varw") && i + 1 < argc) tune("scale_varw", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--target") && i + 1 < argc) tune("scale_target", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--floor") && i + 1 < argc) tune("scale_floor", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--dtau") && i + 1 < argc) tune("degree_tau", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--dsdmin") && i + 1 < argc) tune("degree_sdmin", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--dfloorn") && i + 1 < argc) tune("degree_floor_n", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--distw") && i + 1 < argc) g_distw = std::atof(argv[++i]);
        else if (!std::strcmp(argv[i], "--same-points")) same_points = true;
        else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) seed = std::strtoul(argv[++i], nullptr, 10);
        else if (!std::strcmp(argv[i], "--auto")) with_auto = true;
        else if (!std::strcmp(argv[i], "--cgal-jet2")) cgal_jet2 = true;
        else if (!std::strcmp(argv[i], "--auto-tau") && i + 1 < argc) tune("auto_tau", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-blob") && i + 1 < argc) tune("auto_blob", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-sdmax") && i + 1 < argc) tune("auto_sdmax", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-varw") && i + 1 < argc) tune("auto_varw", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-clean") && i + 1 < argc) tune("auto_clean", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-gl") && i + 1 < argc) tune("auto_gl", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-nest") && i + 1 < argc) tune("auto_nest", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-lof") && i + 1 < argc) tune("auto_lof", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-s2floor") && i + 1 < argc)
            tune("auto_s2floor", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-dw") && i + 1 < argc)
            tune("auto_dw", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--auto-flat") && i + 1 < argc)
            tune("auto_flat", std::atof(argv[++i]));
        else if (!std::strcmp(argv[i], "--cgal-ks") && i + 1 < argc) cgal_ks = argv[++i];
        else if (!std::strcmp(argv[i], "--cgal-k") && i + 1 < argc) cgal_k = std::strtoul(argv[++i], nullptr, 10);
        else if (!std::strcmp(argv[i], "--levels") && i + 1 < argc) only_levels = argv[++i];
        else if (!std::strcmp(argv[i], "--sweep") && i + 1 < argc) sweep = argv[++i];
        else dir = argv[i];
    }
    if (dir.empty()) {
        std::fprintf(stderr, "bench_pcpnet: give the PCPNet folder (or set JF_DATA to a folder "
                             "holding pcpnet/): it must contain armadillo100k.xyz, "
                             "armadillo100k.normals and armadillo100k.pidx\n");
        return 2;
    }
    if (same_points) g_extra = 1;
    jf_eval_table tx, tn, ti;
    if (!load(dir + "/armadillo100k.xyz", tx) || !load(dir + "/armadillo100k.normals", tn) ||
        !load(dir + "/armadillo100k.pidx", ti))
        return 1;
    Study s;
    std::vector<double> clean(tx.v, tx.v + 3 * tx.nrows);
    s.gt.assign(tn.v, tn.v + 3 * tn.nrows);
    for (size_t j = 0; j < ti.nrows; j++) s.pidx.push_back((uint32_t)ti.v[j]);
    size_t n = tx.nrows;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; i++)
        for (int d = 0; d < 3; d++) {
            lo[d] = std::fmin(lo[d], clean[3 * i + d]);
            hi[d] = std::fmax(hi[d], clean[3 * i + d]);
        }
    double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                            (hi[2] - lo[2]) * (hi[2] - lo[2]));
    std::printf("# armadillo100k: %zu points, %zu evaluated (.pidx), bbox diagonal %.3f\n", n,
                s.pidx.size(), diag);
    std::printf("# RMS unoriented normal angle (degrees) on the .pidx points; time: seconds for\n"
                "# the 5000 jetfit fits (k-NN included) / for CGAL's 100k points\n");

    std::vector<double> levels = {0.0, 0.00125, 0.006, 0.012};
    std::vector<size_t> ks = {18, 112, 450};
    if (quick) {
        levels = {0.0, 0.012};
        ks = {18, 112};
    }
    if (only_levels) {
        levels.clear();
        for (const char *q = only_levels; *q;) {
            char *e;
            levels.push_back(std::strtod(q, &e));
            if (e == q) break;
            q = *e == ',' ? e + 1 : e;
        }
    }
    std::printf("%-8s %-34s %5s %4s %9s %9s %s\n", "noise", "method", "K", "deg", "rms_deg",
                "time_s", "flagged");
    for (double lv : levels) {
        s.xyz = clean;
        std::mt19937_64 rng(seed);
        std::normal_distribution<double> g(0.0, lv * diag);
        if (lv > 0)
            for (double &x : s.xyz) x += g(rng);
        jf_index *ix = nullptr;
        if (jf_index_build(s.xyz.data(), n, &ix) != JF_OK) return 1;
        std::vector<Config> cfg;
        for (size_t k : ks)
            for (int d = 2; d <= 3 && !no_fixed; d++)
                cfg.push_back({"jetfit", d, k, JF_ROBUST_NONE, 0, {0}, 0, 0});
        for (size_t k : ks)
            for (int d = 2; d <= 3 && !no_fixed; d++)
                cfg.push_back({"jetfit degree-select", d, k, JF_ROBUST_NONE, 0, {0}, 1, 0});
        size_t kmax = ks.back();
        if (with_auto) cfg.push_back({"jetfit auto", 2, JF_NB_AUTO_KMAX, JF_ROBUST_NONE, 0, {0}, 0, 0});
        // --sweep "K,deg,robust ..." (robust 0/1/2 = none/huber/tukey);
        // K may be a scale set "12/18/36" (scale selection, the last the largest)
        for (const char *q = sweep; q && *q;) {
            Config c = {"jetfit sweep", 2, 0, JF_ROBUST_NONE, 0, {0}, 0, 0};
            int d, rb, used = 0;
            unsigned long k;
            while (std::sscanf(q, "%lu%n", &k, &used) == 1) {
                c.scales[c.nscales++] = k;
                c.k = k;
                q += used;
                if (*q != '/' || c.nscales == 8) break;
                q++;
            }
            if (std::sscanf(q, ",%d,%d%n", &d, &rb, &used) != 2) break;
            c.degree = d;
            c.robust = (jf_robust_mode)rb;
            q += used;
            int ds = 0;
            if (std::sscanf(q, ",%d%n", &ds, &used) == 1) q += used;
            c.dsel = ds;
            c.distw = g_distw;
            if (c.nscales == 1) c.nscales = 0;
            cfg.push_back(c);
            while (*q == ' ') q++;
        }
        for (size_t k : ks)
            for (int d = 2; d <= 3 && !no_fixed; d++)
                cfg.push_back({"jetfit", d, k, JF_ROBUST_HUBER, 0, {0}, 0, 0});
        for (int d = 2; d <= 3 && !(no_fixed && sweep); d++) {
            cfg.push_back({"jetfit scales 18/36/112/225/450", d, kmax, JF_ROBUST_NONE, 5,
                           {18, 36, 112, 225, 450}, 0, 0});
            cfg.push_back({"jetfit scales 18/36/112/225/450", d, kmax, JF_ROBUST_HUBER, 5,
                           {18, 36, 112, 225, 450}, 0, 0});
            cfg.push_back({"jetfit scales 18/36/112/225/450", d, kmax, JF_ROBUST_TUKEY, 5,
                           {18, 36, 112, 225, 450}, 0, 0});
        }
        for (const Config &c : cfg) {
            Config cc = c;
            if (cc.nscales) { // clamp scales to kmax in --quick
                int m = 0;
                for (int i = 0; i < cc.nscales; i++)
                    if (cc.scales[i] <= kmax) cc.scales[m++] = cc.scales[i];
                cc.nscales = m;
            }
            double secs;
            size_t fl;
            double r = run_jetfit(s, ix, cc, &secs, &fl);
            char name[128];
            std::snprintf(name, sizeof name, "%s%s", cc.name,
                          cc.robust == JF_ROBUST_TUKEY ? " tukey" : cc.robust == JF_ROBUST_HUBER ? " huber" : "");
            if (cc.nscales && !std::strcmp(cc.name, "jetfit sweep")) {
                std::snprintf(name, sizeof name, "jetfit scales");
                for (int i = 0; i < cc.nscales; i++)
                    std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), "%s%zu",
                                  i ? "/" : " ", cc.scales[i]);
                if (cc.robust)
                    std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), " %s",
                                  cc.robust == JF_ROBUST_TUKEY ? "tukey" : "huber");
            }
            if (cc.dsel && !std::strstr(name, "degree-select"))
                std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), " dsel%d", cc.dsel);
            if (cc.distw > 0)
                std::snprintf(name + std::strlen(name), sizeof name - std::strlen(name), " dw%g", cc.distw);
            std::printf("%-8g %-34s %5zu %4d %9.3f %9.3f %zu  (median %.2f p95 %.2f)\n", lv, name,
                        cc.k, cc.degree, r, secs, fl, g_median, g_p95);
            std::fflush(stdout);
        }
        std::vector<size_t> cks = ks;
        if (cgal_ks) {
            cks.clear();
            for (const char *q = cgal_ks; *q;) {
                char *e;
                cks.push_back(std::strtoul(q, &e, 10));
                if (e == q) break;
                q = *e == ',' ? e + 1 : e;
            }
        }
        for (size_t k : cks) {
            if (no_cgal) break;
            if (cgal_k && k != cgal_k) continue;
            for (int d = 2; d <= (cgal_jet2 ? 2 : 3); d++) {
                double secs, r = run_cgal(s, true, d, k, &secs);
                std::printf("%-8g %-34s %5zu %4d %9.3f %9.3f -\n", lv, "CGAL jet_estimate_normals", k,
                            d, r, secs);
                std::fflush(stdout);
            }
            if (cgal_jet2) continue;
            double secs, r = run_cgal(s, false, 0, k, &secs);
            std::printf("%-8g %-34s %5zu %4s %9.3f %9.3f -\n", lv, "CGAL pca_estimate_normals", k, "-",
                        r, secs);
            std::fflush(stdout);
        }
        jf_index_free(ix);
    }
    std::printf("# peak RSS %ld kB\n", peak_kb());
    jf_eval_table_free(&tx);
    jf_eval_table_free(&tn);
    jf_eval_table_free(&ti);
    return 0;
}
