/* bench_index.cpp -- jf_index (src/spatial/kdtree.c) against CGAL's kd-tree
 * (Orthogonal_k_neighbor_search, Search_traits_3) and nanoflann
 * (KDTreeSingleIndexAdaptor), in the same run, one thread each.
 *
 * Data: N points (default 1M) of (a) uniform random in the unit cube and
 * (b) the paper's §6.1 surface z = 0.1 exp(2u + v - v^2) on a randomly
 * perturbed sqrt(N) x sqrt(N) grid over [-0.5, 0.5]^2, shuffled so that the
 * file order is random.  For each: build time, then the K nearest of every
 * data point (K = 16 and 32), queried in input (random) order and in Morton
 * order (jf_spatial_order).  Each library runs in its own forked child so
 * its peak memory (ru_maxrss after resetting the high-water mark) is its
 * own; "extra" is the peak above the input already in memory.  The sum of
 * all returned squared distances must agree between the three (ties may
 * pick different points, never different distances).
 *
 * usage: bench_index [--n N] [--no-cgal] [--no-nanoflann]
 *                    [--data uniform|surface|mesh|both]
 */
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#if __has_include(<nanoflann.hpp>)
#include <nanoflann.hpp>
#define HAVE_NANOFLANN 1
#else
#define HAVE_NANOFLANN 0
#endif

#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "jetfit.h"

namespace {

const size_t Ks[2] = {16, 32};

double now()
{
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts); /* CPU time: robust on a shared machine */
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

uint64_t rng = 0x2545F4914F6CDD1DULL;
double urand()
{
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return (double)((rng * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

struct Result {
    int ok;
    double build_s;
    double query_s[2][2]; /* [K][0 = input order, 1 = Morton order] */
    double sum[2];        /* sum of squared distances, per K          */
    double peak_mb;       /* ru_maxrss of the child                   */
    double extra_mb;      /* peak above the RSS at the child's start  */
};

long vm_kb(const char *field)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return 0;
    char line[256];
    long kb = 0;
    size_t len = strlen(field);
    while (fgets(line, sizeof line, f))
        if (strncmp(line, field, len) == 0) kb = atol(line + len + 1);
    fclose(f);
    return kb;
}

/* Runs fn in a child process and returns its Result. */
template <class F> Result in_child(F fn)
{
    Result r;
    memset(&r, 0, sizeof r);
    int fd[2];
    if (pipe(fd) != 0) return r;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        /* reset the peak RSS to the current RSS (Linux clear_refs "5") */
        if (FILE *c = fopen("/proc/self/clear_refs", "w")) {
            fputs("5", c);
            fclose(c);
        }
        long base = vm_kb("VmRSS:");
        Result out;
        memset(&out, 0, sizeof out);
        fn(out);
        rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        long hwm = vm_kb("VmHWM:");
        long peak = ru.ru_maxrss;
        if (hwm > 0 && hwm < peak) peak = hwm; /* maxrss may keep the parent's */
        out.peak_mb = (double)peak / 1024.0;
        out.extra_mb = (double)(peak - base) / 1024.0;
        out.ok = 1;
        ssize_t w = write(fd[1], &out, sizeof out);
        (void)w;
        _exit(0);
    }
    close(fd[1]);
    ssize_t got = read(fd[0], &r, sizeof r);
    close(fd[0]);
    int status;
    waitpid(pid, &status, 0);
    if (got != (ssize_t)sizeof r) r.ok = 0;
    return r;
}

struct Data {
    std::string name;
    std::vector<double> xyz;
    std::vector<uint32_t> morton;
    size_t n;
};

void run_ours(const Data &d, Result &out)
{
    double t0 = now();
    jf_index *ix = nullptr;
    if (jf_index_build(d.xyz.data(), d.n, &ix) != JF_OK) return;
    out.build_s = now() - t0;
    std::vector<uint32_t> idx(64);
    std::vector<double> d2(64);
    for (int k = 0; k < 2; k++)
        for (int o = 0; o < 2; o++) {
            double sum = 0;
            t0 = now();
            for (size_t i = 0; i < d.n; i++) {
                size_t q = o ? d.morton[i] : i, found;
                jf_index_knn(ix, &d.xyz[3 * q], Ks[k], idx.data(), d2.data(),
                             &found);
                for (size_t j = 0; j < found; j++) sum += d2[j];
            }
            out.query_s[k][o] = now() - t0;
            out.sum[k] = sum;
        }
    jf_index_free(ix);
}

typedef CGAL::Simple_cartesian<double> Kernel;
typedef Kernel::Point_3 Point;
typedef CGAL::Search_traits_3<Kernel> Traits;
typedef CGAL::Orthogonal_k_neighbor_search<Traits> Search;
typedef Search::Tree Tree;

void run_cgal(const Data &d, Result &out)
{
    std::vector<Point> pts;
    pts.reserve(d.n);
    for (size_t i = 0; i < d.n; i++)
        pts.emplace_back(d.xyz[3 * i], d.xyz[3 * i + 1], d.xyz[3 * i + 2]);
    double t0 = now();
    Tree tree(pts.begin(), pts.end());
    tree.build();
    out.build_s = now() - t0;
    for (int k = 0; k < 2; k++)
        for (int o = 0; o < 2; o++) {
            double sum = 0;
            t0 = now();
            for (size_t i = 0; i < d.n; i++) {
                size_t q = o ? d.morton[i] : i;
                Search search(tree, pts[q], (unsigned)Ks[k]);
                for (auto it = search.begin(); it != search.end(); ++it)
                    sum += it->second;
            }
            out.query_s[k][o] = now() - t0;
            out.sum[k] = sum;
        }
}

#if HAVE_NANOFLANN
struct Cloud {
    const double *xyz;
    size_t n;
    size_t kdtree_get_point_count() const { return n; }
    double kdtree_get_pt(size_t i, size_t dim) const { return xyz[3 * i + dim]; }
    template <class B> bool kdtree_get_bbox(B &) const { return false; }
};
typedef nanoflann::KDTreeSingleIndexAdaptor<
    nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3, uint32_t>
    NanoTree;

void run_nanoflann(const Data &d, Result &out)
{
    Cloud cloud{d.xyz.data(), d.n};
    double t0 = now();
    NanoTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    out.build_s = now() - t0;
    std::vector<uint32_t> idx(64);
    std::vector<double> d2(64);
    for (int k = 0; k < 2; k++)
        for (int o = 0; o < 2; o++) {
            double sum = 0;
            t0 = now();
            for (size_t i = 0; i < d.n; i++) {
                size_t q = o ? d.morton[i] : i;
                size_t found = tree.knnSearch(&d.xyz[3 * q], Ks[k], idx.data(),
                                              d2.data());
                for (size_t j = 0; j < found; j++) sum += d2[j];
            }
            out.query_s[k][o] = now() - t0;
            out.sum[k] = sum;
        }
}
#endif

void make_uniform(Data &d, size_t n)
{
    d.name = "uniform cube";
    d.n = n;
    d.xyz.resize(3 * n);
    for (auto &v : d.xyz) v = urand();
}

/* §6.1: f(u,v) = 0.1 exp(2u + v - v^2), (u,v) on a grid of step h
 * perturbed by (delta h, delta' h), delta, delta' in [0, 0.9]. */
void make_surface(Data &d, size_t n)
{
    size_t g = (size_t)std::ceil(std::sqrt((double)n));
    double h = 1.0 / (double)g;
    d.name = "6.1 surface";
    d.n = n;
    d.xyz.resize(3 * n);
    for (size_t i = 0; i < n; i++) {
        double u = -0.5 + h * ((double)(i % g) + 0.9 * urand());
        double v = -0.5 + h * ((double)(i / g) + 0.9 * urand());
        d.xyz[3 * i] = u;
        d.xyz[3 * i + 1] = v;
        d.xyz[3 * i + 2] = 0.1 * std::exp(2 * u + v - v * v);
    }
    for (size_t i = n - 1; i > 0; i--) { /* Fisher-Yates: random file order */
        size_t j = (size_t)(urand() * (double)(i + 1));
        for (int c = 0; c < 3; c++) std::swap(d.xyz[3 * i + c], d.xyz[3 * j + c]);
    }
}

/* Mesh side (§5.1 mesh case): the §6.1 surface on a g x g perturbed grid,
 * two triangles per cell; adjacency build, then the default approximation
 * neighbourhood of degree 2 (whole rings, >= 2 N_2 = 12 points) of every
 * vertex, in vertex order.  No peer: CGAL has no ring query. */
void run_mesh(size_t n, Result &out)
{
    size_t g = (size_t)std::ceil(std::sqrt((double)n));
    size_t nv = g * g, nf = 2 * (g - 1) * (g - 1);
    std::vector<double> xyz(3 * nv);
    double h = 1.0 / (double)g;
    for (size_t i = 0; i < nv; i++) {
        double u = -0.5 + h * ((double)(i % g) + 0.9 * urand());
        double v = -0.5 + h * ((double)(i / g) + 0.9 * urand());
        xyz[3 * i] = u;
        xyz[3 * i + 1] = v;
        xyz[3 * i + 2] = 0.1 * std::exp(2 * u + v - v * v);
    }
    std::vector<size_t> off(nf + 1);
    std::vector<uint32_t> fi(3 * nf);
    size_t f = 0;
    for (size_t j = 0; j + 1 < g; j++)
        for (size_t i = 0; i + 1 < g; i++) {
            uint32_t a = (uint32_t)(i + g * j), b = a + 1,
                     c = (uint32_t)(a + g + 1), d = (uint32_t)(a + g);
            uint32_t t[6] = {a, b, c, a, c, d};
            for (int k = 0; k < 6; k++) fi[3 * f + k] = t[k];
            off[f + 1] = 3 * (f + 1);
            off[f + 2] = 3 * (f + 2);
            f += 2;
        }
    double t0 = now();
    jf_mesh *m = nullptr;
    if (jf_mesh_build(nv, nf, off.data(), fi.data(), &m, nullptr) != JF_OK) return;
    out.build_s = now() - t0;
    uint32_t idx[64];
    double sum = 0;
    t0 = now();
    for (size_t v = 0; v < nv; v++) {
        size_t found;
        jf_mesh_rings_full(m, xyz.data(), (uint32_t)v, 12, idx, 64, &found);
        sum += (double)found;
    }
    out.query_s[0][0] = now() - t0;
    out.sum[0] = sum / (double)nv;
    jf_mesh_free(m);
}

void report(const char *who, const Result &r, const Result &ours, size_t n)
{
    if (!r.ok) {
        printf("  %-10s FAILED\n", who);
        return;
    }
    printf("  %-10s build %6.3f s", who, r.build_s);
    for (int k = 0; k < 2; k++)
        printf(" | K%zu %6.3f s (%5.2fM q/s) Z %6.3f s (%5.2fM q/s)", Ks[k],
               r.query_s[k][0], (double)n / r.query_s[k][0] * 1e-6,
               r.query_s[k][1], (double)n / r.query_s[k][1] * 1e-6);
    printf(" | peak %7.1f MB, extra %6.1f MB = %5.1f B/pt\n", r.peak_mb,
           r.extra_mb, r.extra_mb * 1048576.0 / (double)n);
    if (&r != &ours) {
        printf("  %-10s time / jetfit: build %.2fx", "", r.build_s / ours.build_s);
        for (int k = 0; k < 2; k++)
            printf(", K%zu %.2fx (Z %.2fx)", Ks[k],
                   r.query_s[k][0] / ours.query_s[k][0],
                   r.query_s[k][1] / ours.query_s[k][1]);
        printf(", extra memory %.2fx", r.extra_mb / ours.extra_mb);
        int agree = 1;
        for (int k = 0; k < 2; k++)
            agree &= std::fabs(r.sum[k] - ours.sum[k]) <=
                     1e-9 * std::fabs(ours.sum[k]);
        printf("; distances %s\n", agree ? "agree" : "DISAGREE");
    }
}

} // namespace

int main(int argc, char **argv)
{
    size_t n = 1000000;
    bool cgal = true, nano = true;
    std::string which = "both";
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--n") && i + 1 < argc) n = strtoul(argv[++i], 0, 10);
        else if (!strcmp(argv[i], "--no-cgal")) cgal = false;
        else if (!strcmp(argv[i], "--no-nanoflann")) nano = false;
        else if (!strcmp(argv[i], "--data") && i + 1 < argc) which = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--n N] [--no-cgal] [--no-nanoflann] "
                            "[--data uniform|surface|mesh|both]\n", argv[0]);
            return 2;
        }
    }
    if (n < 100) n = 100;
    /* fixed thresholds: big blocks always mmap'ed and returned on free, so
     * a child's peak is not hidden by heap pages the parent freed */
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
    mallopt(M_TRIM_THRESHOLD, 128 * 1024);
    printf("bench_index: %zu points, one thread, K nearest of every point "
           "(input order, and Z = Morton order)\n", n);
#if !HAVE_NANOFLANN
    printf("nanoflann: not available (install libnanoflann-dev)\n");
    nano = false;
#endif
    for (int ds = 0; ds < 2; ds++) {
        if (which != "both" && which != (ds ? "surface" : "uniform")) continue;
        Data d;
        if (ds) make_surface(d, n);
        else make_uniform(d, n);
        d.morton.resize(n);
        double t0 = now();
        jf_spatial_order(d.xyz.data(), n, d.morton.data());
        printf("%s: Morton order %.3f s\n", d.name.c_str(), now() - t0);
        Result ours = in_child([&](Result &r) { run_ours(d, r); });
        report("jetfit", ours, ours, n);
#if HAVE_NANOFLANN
        if (nano) {
            Result nf = in_child([&](Result &r) { run_nanoflann(d, r); });
            report("nanoflann", nf, ours, n);
        }
#endif
        if (cgal) {
            Result cg = in_child([&](Result &r) { run_cgal(d, r); });
            report("CGAL", cg, ours, n);
        }
    }
    if (which == "both" || which == "mesh") {
        Result m = in_child([&](Result &r) { run_mesh(n, r); });
        if (m.ok)
            printf("mesh (%zu vertices, 6.1 surface grid): adjacency %.3f s, "
                   "rings (whole, >= 12 points, mean %.1f) %.3f s = %.2fM "
                   "vertices/s | peak %.1f MB, extra %.1f MB\n", n,
                   m.build_s, m.sum[0], m.query_s[0][0],
                   (double)n / m.query_s[0][0] * 1e-6, m.peak_mb, m.extra_mb);
    }
    return 0;
}
