// delaunay.cpp -- jfb_delaunay_build: CGAL's 3D Delaunay triangulation of a
// cloud, flattened into plain arrays (vertex map, CSR adjacency, poles).
//
// design:
//  1. finite points -> (point, input index) pairs; the range insertion
//     spatially sorts them (Hilbert order), so each location starts next to
//     the previous point instead of at a random cell.
//  2. vertices get dense ids; identical inputs were merged by CGAL, so the
//     inputs that own no vertex are matched to theirs by exact coordinates.
//  3. CSR adjacency from finite_adjacent_vertices, poles (poles.cpp), then
//     the triangulation is destroyed: the C core keeps only the arrays.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include "dt3.hpp"

namespace {
constexpr std::uint32_t kNone = UINT32_MAX;

struct Key {
    double x, y, z;
    bool operator==(const Key &o) const { return x == o.x && y == o.y && z == o.z; }
};
struct KeyHash {
    size_t operator()(const Key &k) const {
        std::uint64_t h = 1469598103934665603ull, b[3];
        std::memcpy(&b[0], &k.x, 8);
        std::memcpy(&b[1], &k.y, 8);
        std::memcpy(&b[2], &k.z, 8);
        for (std::uint64_t v : b) h = (h ^ v) * 1099511628211ull ^ (v >> 29);
        return (size_t)h;
    }
};
// +0.0 turns -0.0 into 0.0: CGAL calls them equal, the hash must too
Key key_of(const double *p) { return Key{p[0] + 0.0, p[1] + 0.0, p[2] + 0.0}; }

template <class T> T *alloc(size_t n) {
    T *p = static_cast<T *>(std::malloc((n ? n : 1) * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

void build(const double *xyz, size_t n, jfb_delaunay *d) {
    using namespace jfb;
    d->n = n;
    d->vertex_of = alloc<std::uint32_t>(n);
    std::vector<std::pair<Point, std::uint32_t>> pts;
    pts.reserve(n);
    for (size_t i = 0; i < n; i++) {
        const double *p = xyz + 3 * i;
        d->vertex_of[i] = kNone;
        if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))
            pts.emplace_back(Point(p[0], p[1], p[2]), (std::uint32_t)i);
        else
            d->nnonfinite++;
    }
    size_t nfinite = pts.size();
    DT3 t;
    t.insert(pts.begin(), pts.end());
    std::vector<std::pair<Point, std::uint32_t>>().swap(pts);

    d->dimension = t.dimension();
    d->nv = t.number_of_vertices();
    d->nduplicates = nfinite - d->nv;
    d->rep = alloc<std::uint32_t>(d->nv);
    d->adj_off = alloc<size_t>(d->nv + 1);
    d->pole = alloc<double>(3 * d->nv);
    d->hull = alloc<double>(3 * d->nv);
    std::vector<DT3::Vertex_handle> vh(d->nv);
    std::uint32_t id = 0;
    for (auto v = t.finite_vertices_begin(); v != t.finite_vertices_end(); ++v) {
        d->rep[id] = v->info();
        d->vertex_of[v->info()] = id;
        v->info() = id;
        vh[id++] = v;
    }
    if (d->nduplicates > 0) {
        // only here does a hash of every vertex cost anything
        std::unordered_map<Key, std::uint32_t, KeyHash> at;
        at.reserve(d->nv);
        for (size_t v = 0; v < d->nv; v++) at.emplace(key_of(xyz + 3 * (size_t)d->rep[v]), (std::uint32_t)v);
        for (size_t i = 0; i < n; i++) {
            const double *p = xyz + 3 * i;
            if (d->vertex_of[i] != kNone || !std::isfinite(p[0]) || !std::isfinite(p[1]) ||
                !std::isfinite(p[2]))
                continue;
            auto it = at.find(key_of(p));
            if (it == at.end()) throw std::runtime_error("duplicate without a vertex");
            d->vertex_of[i] = it->second;
            if (i < d->rep[it->second]) d->rep[it->second] = (std::uint32_t)i;
        }
    }

    std::vector<std::uint32_t> adj;
    adj.reserve(d->nv * 16);
    std::vector<DT3::Vertex_handle> nb;
    d->adj_off[0] = 0;
    for (size_t v = 0; v < d->nv; v++) {
        nb.clear();
        if (d->dimension >= 1) t.finite_adjacent_vertices(vh[v], std::back_inserter(nb));
        for (auto w : nb) adj.push_back(w->info());
        d->adj_off[v + 1] = adj.size();
    }
    d->adj = alloc<std::uint32_t>(adj.size());
    if (!adj.empty()) std::memcpy(d->adj, adj.data(), adj.size() * sizeof(std::uint32_t));
    std::vector<std::uint32_t>().swap(adj);
    compute_poles(t, d);
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
