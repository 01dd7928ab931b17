// star.cpp -- what the C core needs from the star of each vertex of a 3D
// Delaunay triangulation: the Delaunay neighbours, the Amenta & Bern pole
// (paper ref. 1, used by §5.1) and the hull direction.
//
// design:
//  1. neighbours: CGAL's finite_adjacent_vertices per vertex, into CSR.
//     (A hand-written per-vertex star walk, parallel on 2 threads, measured
//     1.7x slower at 1M points than this serial pass: CGAL marks visited
//     cells in place, a thread-safe walk must hash them.)
//  2. hull: each infinite cell has one finite facet, a convex-hull facet;
//     its outer unit normal is added to its three vertices; the mean is
//     the direction of the vertex's unbounded Voronoi cell (the pole "at
//     infinity").
//  3. poles: one pass over the finite cells in memory order; a cell's
//     circumcentre is a Voronoi vertex of its four vertices, each keeps the
//     farthest one -- for a hull vertex the farthest opposite its hull
//     direction (Amenta & Bern's negative pole: the accurate one on a
//     closed surface).  Slivers have far circumcentres, which is what
//     makes poles work; exactly flat cells give none and are skipped.
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <limits>
#include <new>

#include "dt3.hpp"

namespace {
using jfb::DT3;
using jfb::Point;

struct V3 {
    double x, y, z;
};
V3 sub(const Point &a, const Point &b) { return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()}; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

template <class T> T *alloc(size_t n) {
    T *p = static_cast<T *>(std::malloc((n ? n : 1) * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

void adjacency(const DT3 &t, const std::vector<DT3::Vertex_handle> &vh, jfb_delaunay *d) {
    size_t nv = d->nv, cap = 18 * nv + 16, len = 0;
    d->adj_off = alloc<size_t>(nv + 1);
    d->adj = alloc<std::uint32_t>(cap);
    d->adj_off[0] = 0;
    std::vector<DT3::Vertex_handle> nb;
    for (size_t id = 0; id < nv; id++) {
        nb.clear();
        if (t.dimension() >= 1) t.finite_adjacent_vertices(vh[id], std::back_inserter(nb));
        if (len + nb.size() > cap) {  // rare: grow geometrically
            cap = 2 * cap + nb.size();
            auto *p = static_cast<std::uint32_t *>(std::realloc(d->adj, cap * sizeof(std::uint32_t)));
            if (!p) throw std::bad_alloc();
            d->adj = p;
        }
        for (auto u : nb) d->adj[len++] = u->info();
        d->adj_off[id + 1] = len;
    }
}

void poles(const DT3 &t, jfb_delaunay *d) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    size_t nv = d->nv;
    d->pole = alloc<double>(3 * nv);
    d->hull = alloc<double>(3 * nv);
    for (size_t i = 0; i < 3 * nv; i++) d->pole[i] = nan, d->hull[i] = 0.0;
    if (t.dimension() < 3) return;  // flat or collinear: no bounded cells

    std::vector<int> nfacets(nv, 0);
    std::vector<DT3::Cell_handle> inf;
    t.incident_cells(t.infinite_vertex(), std::back_inserter(inf));
    for (auto c : inf) {
        int i = c->index(t.infinite_vertex());
        const Point &a = c->vertex((i + 1) & 3)->point();
        V3 nrm = cross(sub(c->vertex((i + 2) & 3)->point(), a), sub(c->vertex((i + 3) & 3)->point(), a));
        double len = std::sqrt(dot(nrm, nrm));
        if (!(len > 0)) continue;
        // outward: away from the finite cell across the facet
        if (dot(nrm, sub(t.mirror_vertex(c, i)->point(), a)) > 0) len = -len;
        for (int k = 1; k <= 3; k++) {
            std::uint32_t v = c->vertex((i + k) & 3)->info();
            d->hull[3 * v] += nrm.x / len, d->hull[3 * v + 1] += nrm.y / len, d->hull[3 * v + 2] += nrm.z / len;
            nfacets[v]++;
        }
    }
    for (size_t v = 0; v < nv; v++)
        if (nfacets[v] > 0)
            for (int k = 0; k < 3; k++) d->hull[3 * v + k] /= nfacets[v];
    std::vector<int>().swap(nfacets);

    std::vector<double> best(nv, -1.0);
    for (auto c = t.finite_cells_begin(); c != t.finite_cells_end(); ++c) {
        const Point &p0 = c->vertex(0)->point();
        V3 a = sub(c->vertex(1)->point(), p0), b = sub(c->vertex(2)->point(), p0),
           e = sub(c->vertex(3)->point(), p0);
        V3 be = cross(b, e), ea = cross(e, a), ab = cross(a, b);
        double det = 2.0 * dot(a, be);
        if (det == 0.0) continue;
        double la = dot(a, a), lb = dot(b, b), le = dot(e, e);
        // circumcentre - p0 = (|a|^2 b x e + |b|^2 e x a + |e|^2 a x b) / (2 a.(b x e))
        V3 o = {(la * be.x + lb * ea.x + le * ab.x) / det, (la * be.y + lb * ea.y + le * ab.y) / det,
                (la * be.z + lb * ea.z + le * ab.z) / det};
        if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) continue;
        for (int k = 0; k < 4; k++) {
            std::uint32_t v = c->vertex(k)->info();
            V3 off = sub(c->vertex(k)->point(), p0);
            V3 dv = {o.x - off.x, o.y - off.y, o.z - off.z};
            const double *h = d->hull + 3 * v;
            if ((h[0] != 0 || h[1] != 0 || h[2] != 0) && dv.x * h[0] + dv.y * h[1] + dv.z * h[2] >= 0)
                continue;  // the unbounded side of a hull vertex
            double d2 = dot(dv, dv);
            if (d2 > best[v]) best[v] = d2, d->pole[3 * v] = dv.x, d->pole[3 * v + 1] = dv.y, d->pole[3 * v + 2] = dv.z;
        }
    }
}
}  // namespace

void jfb::extract_stars(const DT3 &t, const std::vector<DT3::Vertex_handle> &vh, jfb_delaunay *d) {
    adjacency(t, vh, d);
    poles(t, d);
}
