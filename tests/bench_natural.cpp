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
#include <vector>

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

int main(int argc, char **argv) {
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
