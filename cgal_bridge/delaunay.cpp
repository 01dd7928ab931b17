// delaunay.cpp -- jfb_delaunay_build: CGAL's 3D Delaunay triangulation of a
// cloud, flattened into plain arrays (vertex map, CSR adjacency, poles).
//
// design:
//  1. the finite points are spatially sorted (CGAL's Hilbert sort with
//     its fixed-seed shuffle, as the range insert does: deterministic,
//     the same for any thread count).
//  2. inserted one by one with the previous vertex as hint, so each
//     location walks a few cells; insert() returns the vertex of every
//     input, identical points included (CGAL merges them): the input ->
//     vertex map without any lookup.  Sequential: CGAL's concurrent
//     insertion (Parallel_tag + TBB) was measured 2.5-10x SLOWER on
//     2 threads on surface samples (docs/natural.md, "Speed").
//  3. vertex ids: order of first appearance in the spatial sort, so they
//     do not depend on which thread inserted what, nor on where CGAL
//     stored a vertex; rep = smallest input index.  The triangulation
//     itself is unique (symbolic perturbation), so every array extracted
//     from it in id order is the same whatever the thread count or the
//     triangulation's memory layout.
//  4. adjacency, poles, hull directions (star.cpp, parallel per vertex),
//     then the triangulation is destroyed: the C core keeps only arrays.
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "dt3.hpp"

namespace {
constexpr std::uint32_t kNone = UINT32_MAX;

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double cpu_now() {  // the process's CPU time, every thread
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

template <class T> T *alloc(size_t n) {
    T *p = static_cast<T *>(std::malloc((n ? n : 1) * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

// input index -> CGAL point, read straight from the caller's array (no copy)
struct XyzMap {
    const double *xyz;
    using key_type = std::uint32_t;
    using value_type = jfb::Point;
    using reference = jfb::Point;
    using category = boost::readable_property_map_tag;
    friend jfb::Point get(const XyzMap &m, std::uint32_t i) {
        const double *p = m.xyz + 3 * (size_t)i;
        return jfb::Point(p[0], p[1], p[2]);
    }
};

void build(const double *xyz, size_t n, int threads, jfb_delaunay *d) {
    using namespace jfb;
    d->n = n;
    d->vertex_of = alloc<std::uint32_t>(n);
    std::vector<std::uint32_t> order;
    order.reserve(n);
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        d->vertex_of[i] = kNone;
        if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) {
            order.push_back((std::uint32_t)i);
        } else {
            d->nnonfinite++;
        }
    }
    const size_t nf = order.size();
    double t0 = now(), c0 = cpu_now();
    XyzMap pm{xyz};
    using Traits = CGAL::Spatial_sort_traits_adapter_3<K, XyzMap>;
    CGAL::spatial_sort(order.begin(), order.end(), Traits(pm));

    double t1 = now(), c1 = cpu_now();
    std::vector<DT3::Vertex_handle> of(n);
    DT3 t;
    DT3::Vertex_handle hint;
    for (std::uint32_t i : order) hint = of[i] = t.insert(get(pm, i), hint);

    double t2 = now(), c2 = cpu_now();
    d->dimension = t.dimension();
    d->nv = t.number_of_vertices();
    d->nduplicates = nf - d->nv;
    for (auto v = t.finite_vertices_begin(); v != t.finite_vertices_end(); ++v) v->info() = kNone;
    std::vector<DT3::Vertex_handle> vh(d->nv);
    std::uint32_t id = 0;
    for (size_t j = 0; j < nf; j++) {
        DT3::Vertex_handle v = of[order[j]];
        if (v->info() == kNone) v->info() = id, vh[id++] = v;
    }
    std::vector<std::uint32_t>().swap(order);
    d->rep = alloc<std::uint32_t>(d->nv);
    for (size_t v = 0; v < d->nv; v++) d->rep[v] = kNone;
    for (size_t i = 0; i < n; i++)
        if (of[i] != DT3::Vertex_handle()) {
            std::uint32_t v = of[i]->info();
            d->vertex_of[i] = v;
            if (d->rep[v] == kNone) d->rep[v] = (std::uint32_t)i;  // i ascending: the smallest
        }
    std::vector<DT3::Vertex_handle>().swap(of);
    extract_stars(t, vh, threads, d);
    d->seconds[0] = t1 - t0, d->seconds[1] = t2 - t1, d->seconds[2] = now() - t2;
    d->cpu_seconds[0] = c1 - c0, d->cpu_seconds[1] = c2 - c1, d->cpu_seconds[2] = cpu_now() - c2;
}
}  // namespace

extern "C" int jfb_delaunay_build(const double *xyz, size_t n, int threads, jfb_delaunay *out) {
    if (!out) return 1;
    std::memset(out, 0, sizeof *out);
    if (!xyz && n > 0) return 1;
    if (n >= (size_t)UINT32_MAX) return 5;
    if (threads < 1) threads = 1;
    try {
        build(xyz, n, threads, out);
        return 0;
    } catch (const std::bad_alloc &) {
        jfb_delaunay_release(out);
        return 2;
    } catch (...) {
        jfb_delaunay_release(out);
        return 8;
    }
}

extern "C" void jfb_delaunay_release(jfb_delaunay *d) {
    if (!d) return;
    std::free(d->vertex_of);
    std::free(d->rep);
    std::free(d->adj_off);
    std::free(d->adj);
    std::free(d->pole);
    std::free(d->hull);
    std::memset(d, 0, sizeof *d);
}
