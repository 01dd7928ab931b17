// bench_estimate.cpp -- end-to-end speed and peak memory of
// `jetfit estimate` (read, index, fit, write) beside CGAL's peers, in the
// same run, on N points (default 1,000,000) of the paper's §6.1 surface
// z = 0.1 exp(2x + y - y^2) in random order, stored twice: as binary PLY
// and as .xyz text (%.17g, as scanners' exports and our own writer).
//
//   bench_estimate [N] [--normals] [--keep DIR] [--also JETFIT] [--reps R]
//       (needs the built jetfit next to it: JF_BUILD_DIR/jetfit)
//   --normals      also run CGAL's jet_estimate_normals (binary PLY only)
//   --keep DIR     write the inputs into DIR and keep them (for profiling)
//   --also JETFIT  also run another jetfit binary (e.g. an older build) on
//                  one thread: before and after in the same run
//   --reps R       run each contender R times (default 1) and report the
//                  least wall time and the least CPU time of its R runs
//                  (and the largest peak memory): on a shared, noisy
//                  machine the best of a few runs is the fairer ratio
//
// Every contender runs in its own child process (fork), so its peak
// memory (wait4's ru_maxrss) is its own, and starts with no output file
// from an earlier contender (deleting one costs ~0.1 s in the kernel):
//  - jetfit estimate --threads 1 / 2 (exec of the built binary);
//  - CGAL end to end: read_PLY (or read_XYZ), k-d tree (Orthogonal_k_neighbor_search),
//    Monge_via_jet_fitting per point (query point first), binary PLY out
//    of the same quantities (x y z n k1 k2 d1 d2);
//  - CGAL jet_estimate_normals<Sequential_tag> (normals only), read and
//    write included.
// Configurations: knn:16 degree 2 and knn:32 degree 3 (monge 3).
#include <CGAL/Monge_via_jet_fitting.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/IO/read_ply_points.h>
#include <CGAL/IO/read_xyz_points.h>
#include <CGAL/IO/write_ply_points.h>
#include <CGAL/jet_estimate_normals.h>
#include <CGAL/property_map.h>

#include "cgalref_svd.hpp" // CGAL's default SVD (Eigen) or a GSL stand-in

#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

extern "C" {
#include "jetfit.h"
}

typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 Point;
typedef Kernel::Vector_3 Vector;

static std::string g_dir;

// ---- the input ----------------------------------------------------------

static void make_input(size_t n, const std::string &path, const std::string &text)
{
    std::vector<double> xyz(3 * n);
    unsigned long long s = 2003;
    auto rnd = [&s]() {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        return (double)(s >> 11) / 9007199254740992.0;
    };
    for (size_t i = 0; i < n; i++) { // uniform random samples: random order
        double x = rnd() - 0.5, y = rnd() - 0.5;
        xyz[3 * i] = x;
        xyz[3 * i + 1] = y;
        xyz[3 * i + 2] = 0.1 * std::exp(2 * x + y - y * y);
    }
    jf_cloud c = {};
    c.n = n;
    c.xyz = xyz.data();
    jf_error e;
    for (const std::string *p : {&path, &text})
        if (jf_cloud_write(p->c_str(), &c, 0, &e) != JF_OK) {
            std::fprintf(stderr, "cannot write %s: %s\n", p->c_str(), e.msg);
            std::exit(1);
        }
}

// ---- running a contender in a child -----------------------------------------

struct Run {
    double secs, cpu;
    long maxrss_kb;
    int ok;
};

template <class F> static Run in_child(F f)
{
    // every contender writes a new file: replacing the previous run's
    // 100+ MB output would charge its deletion to whoever comes next
    for (const char *o : {"jetfit_out.ply", "cgal_out.ply", "cgal_normals.ply"})
        std::remove((g_dir + "/" + o).c_str());
    std::fflush(nullptr);
    auto t0 = std::chrono::steady_clock::now();
    pid_t pid = fork();
    if (pid == 0) _exit(f());
    int status = 0;
    struct rusage ru;
    wait4(pid, &status, 0, &ru);
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                 (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    return {secs, cpu, ru.ru_maxrss, WIFEXITED(status) && WEXITSTATUS(status) == 0};
}

static int g_reps = 1;

// in_child g_reps times: the least wall and the least CPU time (each its
// own best run), the largest peak memory; ok only if every run was
template <class F> static Run best_of(F f)
{
    Run b = in_child(f);
    for (int r = 1; r < g_reps; r++) {
        Run t = in_child(f);
        if (t.secs < b.secs) b.secs = t.secs;
        if (t.cpu < b.cpu) b.cpu = t.cpu;
        if (t.maxrss_kb > b.maxrss_kb) b.maxrss_kb = t.maxrss_kb;
        b.ok = b.ok && t.ok;
    }
    return b;
}

static const char *g_jetfit = JF_BUILD_DIR "/jetfit";

static int run_jetfit(const std::string &in, int k, int degree, int threads)
{
    std::string out = g_dir + "/jetfit_out.ply", nb = "knn:" + std::to_string(k);
    std::string deg = std::to_string(degree), th = std::to_string(threads);
    const char *argv[] = {g_jetfit, "estimate", in.c_str(), "-o", out.c_str(),
                          "--neighbors", nb.c_str(), "--degree", deg.c_str(), "--threads",
                          th.c_str(), "--quiet", nullptr};
    execv(argv[0], (char *const *)argv);
    return 127;
}

static int run_cgal_monge(const std::string &in, int k, int degree)
{
    typedef CGAL::Search_traits_3<Kernel> Traits;
    typedef CGAL::Orthogonal_k_neighbor_search<Traits> Search;
    typedef jf_cgalref::Monge_fitting Monge;
    std::vector<Point> pts;
    std::ifstream is(in, std::ios::binary);
    const bool text = in.size() > 4 && in.compare(in.size() - 4, 4, ".xyz") == 0;
    if (text ? !CGAL::IO::read_XYZ(is, std::back_inserter(pts))
             : !CGAL::IO::read_PLY(is, std::back_inserter(pts)))
        return 1;
    Search::Tree tree(pts.begin(), pts.end());
    std::string out = g_dir + "/cgal_out.ply";
    FILE *f = std::fopen(out.c_str(), "wb");
    if (!f) return 1;
    std::fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\n", pts.size());
    const char *names[] = {"x", "y", "z", "nx", "ny", "nz", "k1", "k2",
                           "d1x", "d1y", "d1z", "d2x", "d2y", "d2z"};
    for (const char *nm : names) std::fprintf(f, "property double %s\n", nm);
    std::fprintf(f, "end_header\n");
    std::vector<Point> nb;
    nb.reserve(k);
    Monge fit;
    int monge = degree < 3 ? degree : 3;
    for (const Point &p : pts) {
        Search search(tree, p, k); // sorted: p itself first (distance 0)
        nb.clear();
        for (auto it = search.begin(); it != search.end(); ++it) nb.push_back(it->first);
        Monge::Monge_form m = fit(nb.begin(), nb.end(), degree, monge);
        Vector n = m.normal_direction(), d1 = m.maximal_principal_direction(),
               d2 = m.minimal_principal_direction();
        double row[14] = {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(),
                          m.principal_curvatures(0), m.principal_curvatures(1),
                          d1.x(), d1.y(), d1.z(), d2.x(), d2.y(), d2.z()};
        std::fwrite(row, sizeof row, 1, f);
    }
    return std::fclose(f) == 0 ? 0 : 1;
}

static int run_cgal_jet_normals(const std::string &in, int k, int degree)
{
    typedef std::pair<Point, Vector> PN;
    std::vector<PN> pts;
    auto pm = CGAL::First_of_pair_property_map<PN>();
    auto nm = CGAL::Second_of_pair_property_map<PN>();
    std::ifstream is(in, std::ios::binary);
    if (!CGAL::IO::read_PLY(is, std::back_inserter(pts), CGAL::parameters::point_map(pm)))
        return 1;
#ifdef CGAL_EIGEN3_ENABLED
    CGAL::jet_estimate_normals<CGAL::Sequential_tag>(
        pts, k, CGAL::parameters::point_map(pm).normal_map(nm).degree_fitting(degree));
#else
    CGAL::jet_estimate_normals<CGAL::Sequential_tag>(
        pts, k,
        CGAL::parameters::point_map(pm).normal_map(nm).degree_fitting(degree).svd_traits(
            jf_cgalref::Gsl_svd()));
#endif
    std::ofstream os(g_dir + "/cgal_normals.ply", std::ios::binary);
    CGAL::IO::set_binary_mode(os);
    return CGAL::IO::write_PLY(os, pts, CGAL::parameters::point_map(pm).normal_map(nm)) ? 0 : 1;
}

// Wall time gives points/s; CPU time (user + sys of the child) is shown
// too, since the machine may be shared: on one thread CPU ~ wall when idle.
static void report(const char *what, size_t n, const Run &r, const Run *ref)
{
    double pps = r.ok ? (double)n / r.secs : 0;
    double bpp = 1024.0 * (double)r.maxrss_kb / (double)n;
    std::printf("%-40s %7.2f s wall %7.2f s cpu %9.0f points/s %7.1f MB %5.0f B/point", what,
                r.secs, r.cpu, pps, (double)r.maxrss_kb / 1024.0, bpp);
    if (ref && ref->ok && r.ok)
        std::printf("  x%.2f wall, x%.2f cpu vs CGAL", ref->secs / r.secs, ref->cpu / r.cpu);
    std::printf("%s\n", r.ok ? "" : "   FAILED");
    std::fflush(stdout);
}

static void loadavg(const char *when)
{
    double l[3] = {0, 0, 0};
    FILE *f = std::fopen("/proc/loadavg", "r");
    if (f && std::fscanf(f, "%lf %lf %lf", &l[0], &l[1], &l[2]) == 3)
        std::printf("load average %s: %.2f %.2f %.2f (%ld cores)\n", when, l[0], l[1], l[2],
                    sysconf(_SC_NPROCESSORS_ONLN));
    if (f) std::fclose(f);
}

int main(int argc, char **argv)
{
    size_t n = 1000000;
    bool normals = false;
    const char *keep = nullptr, *also = nullptr;
    for (int a = 1; a < argc; a++) {
        if (!std::strcmp(argv[a], "--normals")) normals = true;
        else if (!std::strcmp(argv[a], "--keep") && a + 1 < argc) keep = argv[++a];
        else if (!std::strcmp(argv[a], "--also") && a + 1 < argc) also = argv[++a];
        else if (!std::strcmp(argv[a], "--reps") && a + 1 < argc) {
            g_reps = std::atoi(argv[++a]);
            if (g_reps < 1) g_reps = 1;
        }
        else n = std::strtoul(argv[a], nullptr, 10);
    }
    char tmpl[] = "/tmp/jf_bench_XXXXXX";
    if (!mkdtemp(tmpl)) return 1;
    g_dir = tmpl;
    std::string in_dir = keep ? std::string(keep) : g_dir;
    std::string ply = in_dir + "/surface61.ply", xyz = in_dir + "/surface61.xyz";
    make_input(n, ply, xyz);
    std::string reps_text = g_reps == 1 ? std::string("one run")
                                        : "best of " + std::to_string(g_reps) +
                                              " runs (least wall, least cpu)";
    std::printf("bench_estimate: %zu points of the §6.1 surface, random order, binary PLY\n"
                "and .xyz text (%%.17g); end to end (read, index, fit, write binary PLY),\n"
                "each in a child process, %s; CGAL's SVD: %s\n\n",
                n, reps_text.c_str(), jf_cgalref::cgal_svd_name);
    loadavg("before");
    const int cfg[2][2] = {{16, 2}, {32, 3}};
    double ratio[2][2] = {{0, 0}, {0, 0}}, cratio[2][2] = {{0, 0}, {0, 0}};
    for (int ci = 0; ci < 2; ci++)
        for (int fi = 0; fi < 2; fi++) {
            int k = cfg[ci][0], d = cfg[ci][1];
            const std::string &in = fi ? xyz : ply;
            std::printf("knn:%d degree %d, %s input\n", k, d, fi ? ".xyz text" : "binary PLY");
            Run cg = best_of([&] { return run_cgal_monge(in, k, d); });
            report("  CGAL kd-tree + Monge_via_jet_fitting", n, cg, nullptr);
            if (normals && !fi) {
                Run jn = best_of([&] { return run_cgal_jet_normals(in, k, d); });
                report("  CGAL jet_estimate_normals (seq)", n, jn, &cg);
            }
            if (also) {
                const char *own = g_jetfit;
                g_jetfit = also;
                Run ja = best_of([&] { return run_jetfit(in, k, d, 1); });
                g_jetfit = own;
                std::string what = std::string("  ") + also + " --threads 1";
                report(what.c_str(), n, ja, &cg);
            }
            Run j1 = best_of([&] { return run_jetfit(in, k, d, 1); });
            report("  jetfit estimate --threads 1", n, j1, &cg);
            Run j2 = best_of([&] { return run_jetfit(in, k, d, 2); });
            report("  jetfit estimate --threads 2", n, j2, &cg);
            if (j1.ok && j2.ok)
                std::printf("  jetfit speed-up 1 -> 2 threads: x%.2f\n", j1.secs / j2.secs);
            if (cg.ok && j1.ok) ratio[ci][fi] = cg.secs / j1.secs;
            if (cg.ok && j1.ok) cratio[ci][fi] = cg.cpu / j1.cpu;
            std::printf("\n");
        }
    loadavg("after");
    std::printf("one thread, wall, jetfit vs CGAL: knn:16 d2 PLY x%.2f, xyz x%.2f; "
                "knn:32 d3 PLY x%.2f, xyz x%.2f\n",
                ratio[0][0], ratio[0][1], ratio[1][0], ratio[1][1]);
    std::printf("one thread, cpu,  jetfit vs CGAL: knn:16 d2 PLY x%.2f, xyz x%.2f; "
                "knn:32 d3 PLY x%.2f, xyz x%.2f\n",
                cratio[0][0], cratio[0][1], cratio[1][0], cratio[1][1]);
    for (const char *f : {"jetfit_out.ply", "cgal_out.ply", "cgal_normals.ply"})
        std::remove((g_dir + "/" + f).c_str());
    if (!keep) {
        std::remove(ply.c_str());
        std::remove(xyz.c_str());
    }
    rmdir(g_dir.c_str());
    return 0;
}
