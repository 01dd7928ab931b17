// delaunay.cpp -- jfb_delaunay_build: CGAL's 3D Delaunay triangulation of a
// cloud, flattened into plain arrays (vertex map, CSR adjacency, poles).
//
// design:
//  1. the finite points are spatially sorted (CGAL's Hilbert sort, as the
//     range insert does) and inserted one by one with the previous vertex
//     as hint, so each location walks a few cells; insert() returns the
//     vertex of every input, identical points included (CGAL merges them),
//     which gives the input -> vertex map without any lookup.
//  2. vertices get dense ids in the triangulation's order (close to the
//     insertion order, so spatially coherent); rep = smallest input index.
//  3. adjacency, poles, hull directions (star.cpp), then the triangulation
//     is destroyed: the C core keeps only the arrays.
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

#include "dt3.hpp"

namespace {
constexpr std::uint32_t kNone = UINT32_MAX;

template <class T> T *alloc(size_t n) {
    T *p = static_cast<T *>(std::malloc((n ? n : 1) * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

void build(const double *xyz, size_t n, jfb_delaunay *d) {
    using namespace jfb;
    d->n = n;
    d->vertex_of = alloc<std::uint32_t>(n);
    std::vector<Point> pts(n);
    std::vector<std::size_t> order;  // size_t: the key type of the adapter
    order.reserve(n);
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        d->vertex_of[i] = kNone;
        if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) {
            pts[i] = Point(p[0], p[1], p[2]);
            order.push_back(i);
        } else {
            d->nnonfinite++;
        }
    }
    size_t nfinite = order.size();
    using Pmap = CGAL::Pointer_property_map<Point>::type;
    using Traits = CGAL::Spatial_sort_traits_adapter_3<K, Pmap>;
    CGAL::spatial_sort(order.begin(), order.end(), Traits(CGAL::make_property_map(pts)));

    DT3 t;
    std::vector<DT3::Vertex_handle> of(n);
    DT3::Vertex_handle hint;
    for (std::size_t i : order) hint = of[i] = t.insert(pts[i], hint);
    std::vector<Point>().swap(pts);
    std::vector<std::size_t>().swap(order);

    d->dimension = t.dimension();
    d->nv = t.number_of_vertices();
    d->nduplicates = nfinite - d->nv;
    std::vector<DT3::Vertex_handle> vh(d->nv);
    std::uint32_t id = 0;
    for (auto v = t.finite_vertices_begin(); v != t.finite_vertices_end(); ++v) {
        v->info() = id;
        vh[id++] = v;
    }
    d->rep = alloc<std::uint32_t>(d->nv);
    for (size_t v = 0; v < d->nv; v++) d->rep[v] = kNone;
    for (size_t i = 0; i < n; i++)
        if (of[i] != DT3::Vertex_handle()) {
            std::uint32_t v = of[i]->info();
            d->vertex_of[i] = v;
            if (d->rep[v] == kNone) d->rep[v] = (std::uint32_t)i;  // i ascending: the smallest
        }
    std::vector<DT3::Vertex_handle>().swap(of);
    extract_stars(t, vh, d);
}
}  // namespace

extern "C" int jfb_delaunay_build(const double *xyz, size_t n, jfb_delaunay *out) {
    if (!out) return 1;
    std::memset(out, 0, sizeof *out);
    if (!xyz && n > 0) return 1;
    if (n >= (size_t)UINT32_MAX) return 5;
    try {
        build(xyz, n, out);
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
