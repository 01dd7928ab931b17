// bench_natural.cpp -- natural neighbourhoods at scale (issue 4).
//
//   bench_natural [n=1000000] [threads=2] [seed=1]
//
// n random samples of the paper's §6.1 surface z = 0.1 exp(2u + v - v^2),
// (u, v) uniform in [-0.5, 0.5]^2, in random order.  Each measurement runs
// in its own forked process, so its peak memory (wait4's ru_maxrss) is its
// own; every process starts from the same parent holding the points.
//   plain-dt3   CGAL Delaunay_triangulation_3, t.insert(begin, end) (the
//               peer of the build: spatially sorted range insertion)
//   jf-build    jf_natural_create (the same triangulation + vertex map,
//               adjacency, poles, then the triangulation freed)
//   natural:16  jf_estimate end to end, --neighbors natural:16 (build,
//               pole normals, natural neighbours, degree-2 fits)
//   knn:16      jf_estimate end to end, --neighbors knn:16 (the peer)
//
//   bench_natural reliability
//
// The measurement behind JF_NATURAL_MIN_RELIABILITY: 20k samples of a unit
// sphere and of the §6.1 surface with normal noise of 0, 0.1, 0.3, 1 x
// the sample spacing; per bin of the pole reliability (pole distance /
// nearest-neighbour distance), the mean angle error of the pole normal
// (taken from the bridge, whatever its reliability) and of mincirc.
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "cgal_bridge.h"
#include "jetfit.h"

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;

static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

static std::vector<double> g_xyz;
static int g_threads = 2;

static int run_plain() {
    std::vector<K::Point_3> p;
    p.reserve(g_xyz.size() / 3);
    for (size_t i = 0; i < g_xyz.size(); i += 3) p.emplace_back(g_xyz[i], g_xyz[i + 1], g_xyz[i + 2]);
    CGAL::Delaunay_triangulation_3<K> t;
    t.insert(p.begin(), p.end());
    return t.number_of_vertices() == p.size() ? 0 : 1;
}

static int run_build() {
    jf_natural *nt;
    if (jf_natural_create(g_xyz.data(), g_xyz.size() / 3, &nt) != JF_OK) return 1;
    jf_natural_free(nt);
    return 0;
}

static int run_estimate(bool natural) {
    jf_cloud c = {};
    c.n = g_xyz.size() / 3;
    c.xyz = g_xyz.data();
    jf_estimate_opts o;
    jf_estimate_opts_init(&o);
    o.nb.kind = natural ? JF_NB_NATURAL : JF_NB_KNN;
    o.nb.k = 16;
    o.nb.n = 16;
    o.threads = g_threads;
    std::vector<jf_result> out(c.n);
    jf_error err;
    if (jf_estimate(&c, &o, out.data(), &err) != JF_OK) {
        std::fprintf(stderr, "jf_estimate: %s\n", err.msg);
        return 1;
    }
    size_t failed = 0;
    for (auto &r : out) failed += (r.status & JF_PT_FAILED) != 0;
    return failed * 100 > c.n ? 2 : 0;  // more than 1% failed: a bug
}

struct Meas {
    double secs, mib;
    int rc;
};

static Meas measure(int (*fn)(void), int (*fnb)(bool), bool arg) {
    int fd[2];
    if (pipe(fd) != 0) std::exit(1);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        double t0 = now();
        int rc = fn ? fn() : fnb(arg);
        double dt = now() - t0;
        if (write(fd[1], &dt, sizeof dt) != (ssize_t)sizeof dt) _exit(3);
        _exit(rc);
    }
    close(fd[1]);
    Meas m = {NAN, NAN, -1};
    if (read(fd[0], &m.secs, sizeof m.secs) != (ssize_t)sizeof m.secs) m.secs = NAN;
    close(fd[0]);
    int status;
    struct rusage ru;
    wait4(pid, &status, 0, &ru);
    m.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    m.mib = ru.ru_maxrss / 1024.0;
    return m;
}

static double angle_deg(const double *a, const double *b) {
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return std::atan2(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                      std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])) *
           57.29577951308232;
}

static int reliability_table() {
    const size_t n = 20000;
    std::mt19937_64 g(5);
    std::normal_distribution<double> nd(0.0, 1.0);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    const double edges[] = {0, 1, 2, 3, 4, 6, 8, 12, 20, 50, 1e300};
    for (int surf = 0; surf < 2; surf++)
        for (double noise : {0.0, 0.1, 0.3, 1.0}) {
            std::vector<double> p(3 * n), t(3 * n);
            double sp = surf ? 1.0 / std::sqrt((double)n) : std::sqrt(4 * 3.141592653589793 / n);
            for (size_t i = 0; i < n; i++) {
                double *q = &p[3 * i], *tn = &t[3 * i];
                if (surf) {
                    double x = u(g), y = u(g), z = 0.1 * std::exp(2 * x + y - y * y);
                    double fx = 2 * z, fy = (1 - 2 * y) * z, l = std::sqrt(fx * fx + fy * fy + 1);
                    tn[0] = -fx / l, tn[1] = -fy / l, tn[2] = 1 / l;
                    q[0] = x, q[1] = y, q[2] = z;
                } else {
                    double v[3] = {nd(g), nd(g), nd(g)}, l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
                    for (int k = 0; k < 3; k++) tn[k] = q[k] = v[k] / l;
                }
                double e = noise * sp * nd(g);
                for (int k = 0; k < 3; k++) q[k] += e * tn[k];
            }
            jfb_delaunay d;
            jf_natural *nt;
            if (jfb_delaunay_build(p.data(), n, &d) != 0 || jf_natural_create(p.data(), n, &nt) != JF_OK) return 1;
            std::vector<double> mc(3 * n), rel(n);
            std::vector<unsigned> fl(n, 0);
            jf_natural_normals(nt, JF_NORMAL_MINCIRC, 1, mc.data(), fl.data(), rel.data());
            std::printf("%s, noise %.1f x spacing\n", surf ? "surface 6.1" : "sphere", noise);
            for (int b = 0; b < 10; b++) {
                double ep = 0, em = 0;
                size_t c = 0, cp = 0;
                for (size_t i = 0; i < n; i++) {
                    if (rel[i] < edges[b] || rel[i] >= edges[b + 1]) continue;
                    c++;
                    em += angle_deg(&mc[3 * i], &t[3 * i]);
                    const double *pl = d.pole + 3 * (size_t)d.vertex_of[i];
                    if (std::isfinite(pl[0])) cp++, ep += angle_deg(pl, &t[3 * i]);
                }
                if (c)
                    std::printf("  reliability [%g, %g): %5zu pts  mincirc %6.2f deg  pole %6.2f deg (%zu with a pole)\n",
                                edges[b], edges[b + 1], c, em / c, cp ? ep / cp : NAN, cp);
            }
            jf_natural_free(nt);
            jfb_delaunay_release(&d);
        }
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && std::string(argv[1]) == "reliability") return reliability_table();
    size_t n = argc > 1 ? (size_t)std::atof(argv[1]) : 1000000;
    g_threads = argc > 2 ? std::atoi(argv[2]) : 2;
    unsigned seed = argc > 3 ? (unsigned)std::atoi(argv[3]) : 1;
    std::mt19937_64 g(seed);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    g_xyz.resize(3 * n);
    for (size_t i = 0; i < n; i++) {
        double x = u(g), y = u(g);
        g_xyz[3 * i] = x;
        g_xyz[3 * i + 1] = y;
        g_xyz[3 * i + 2] = 0.1 * std::exp(2 * x + y - y * y);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    std::printf("bench_natural: %zu random points of the §6.1 surface, %d threads for the estimates\n", n,
                g_threads);
    std::printf("baseline process (points generated): %.0f MiB\n", ru.ru_maxrss / 1024.0);
    Meas plain = measure(run_plain, nullptr, false);
    Meas build = measure(run_build, nullptr, false);
    Meas nat = measure(nullptr, run_estimate, true);
    Meas knn = measure(nullptr, run_estimate, false);
    auto row = [&](const char *name, const Meas &m) {
        std::printf("%-12s %8.2f s %10.0f pts/s %8.0f MiB peak  rc=%d\n", name, m.secs, n / m.secs, m.mib, m.rc);
    };
    row("plain-dt3", plain);
    row("jf-build", build);
    row("natural:16", nat);
    row("knn:16", knn);
    std::printf("ratios: build/plain-dt3 time %.2f memory %.2f; natural/knn time %.2f memory %.2f\n",
                build.secs / plain.secs, build.mib / plain.mib, nat.secs / knn.secs, nat.mib / knn.mib);
    return plain.rc || build.rc || nat.rc || knn.rc;
}
