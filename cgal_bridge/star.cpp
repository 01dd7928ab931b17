// star.cpp -- what the C core needs from the star of each vertex of a 3D
// Delaunay triangulation: the Delaunay neighbours, the Amenta & Bern pole
// (paper ref. 1, used by §5.1) and the hull direction.
//
// design:
//  1. one walk per vertex over its incident cells (from v->cell(), across
//     the facets through v), in parallel over blocks of vertex ids; the
//     walk only reads the triangulation (visited cells go in a small
//     per-thread hash set, not in CGAL's in-cell flags), so threads need
//     no lock.  Every result is computed in the lexicographic (x, y, z)
//     order of the points involved, never in the order CGAL stores or
//     walks cells nor in id order, so it is a function of the point set
//     alone: the same bit for bit for any thread count, any insertion
//     order, any memory layout.
//  2. neighbours: the finite vertices of the incident cells, nearest
//     first (ties: lexicographic order of their points).
//  3. hull: each incident infinite cell has one finite facet, a convex-hull
//     facet; the mean of their outer unit normals (summed in the facets'
//     lexicographic order) is the direction of the vertex's unbounded
//     Voronoi cell (the pole "at infinity").
//  4. pole: each finite incident cell's circumcentre (computed from its
//     lexicographically smallest vertex, the others in that order) is a
//     Voronoi vertex of v;
//     v keeps the farthest -- for a hull vertex the farthest opposite its
//     hull direction (Amenta & Bern's negative pole: the accurate one on a
//     closed surface).  Slivers have far circumcentres, which is what
//     makes poles work; exactly flat cells give none and are skipped.
//     Each cell is evaluated by its four vertices (4x the arithmetic of a
//     pass over cells, but no shared writes).
//  5. the triangulation is cleared before the per-block adjacency lists
//     are joined, so the peak holds CGAL's structure or the joined copy,
//     not both.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <tuple>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "dt3.hpp"

namespace {
using jfb::DT3;
using jfb::Point;
using Cell = DT3::Cell_handle;
using Vertex = DT3::Vertex_handle;

struct V3 {
    double x, y, z;
};
V3 sub(const Point &a, const Point &b) { return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()}; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

bool lex_less(const Point &a, const Point &b) {
    if (a.x() != b.x()) return a.x() < b.x();
    if (a.y() != b.y()) return a.y() < b.y();
    return a.z() < b.z();
}
bool vlex_less(Vertex a, Vertex b) { return lex_less(a->point(), b->point()); }

template <class T> T *alloc(size_t n) {
    T *p = static_cast<T *>(std::malloc((n ? n : 1) * sizeof(T)));
    if (!p) throw std::bad_alloc();
    return p;
}

// Per-thread workspace: allocated once per thread, reused for every vertex.
struct Ws {
    std::vector<Cell> cells;                  // incident cells of the vertex
    std::vector<std::pair<const void *, std::uint32_t>> slot;  // hash set, generation-stamped
    std::uint32_t gen = 0;
    std::vector<std::uint32_t> stamp;         // [nv] == mark: neighbour already listed
    std::uint32_t mark = 0;
    std::vector<Vertex> nb;
    std::vector<std::pair<double, Vertex>> nbd;  // (squared distance, vertex)
    const std::uint32_t *rank = nullptr;      // [nv] lexicographic rank of each vertex
    struct Facet {  // a hull facet through the vertex
        std::uint32_t r[3];  // ranks of the corners, ascending
        const Point *p[3];   // corners in that order
        Vertex mirror;       // the finite vertex across it
        bool operator<(const Facet &o) const {
            return r[0] != o.r[0] ? r[0] < o.r[0] : r[1] != o.r[1] ? r[1] < o.r[1] : r[2] < o.r[2];
        }
    };
    std::vector<Facet> facets;
};

bool visit(Ws &w, Cell c) {  // true the first time c is seen for this vertex
    size_t mask = w.slot.size() - 1;
    size_t h = (size_t)(((std::uint64_t)reinterpret_cast<std::uintptr_t>(&*c) * 0x9E3779B97F4A7C15ull) >> 40);
    for (;; h++) {
        auto &s = w.slot[h & mask];
        if (s.second != w.gen) {
            s = {&*c, w.gen};
            return true;
        }
        if (s.first == &*c) return false;
    }
}

void incident_cells(Ws &w, Vertex v) {
    w.cells.clear();
    if (++w.gen == 0) {  // wrapped: clear the stamps once
        for (auto &s : w.slot) s.second = 0;
        w.gen = 1;
    }
    Cell c0 = v->cell();
    visit(w, c0);
    w.cells.push_back(c0);
    for (size_t k = 0; k < w.cells.size(); k++) {
        Cell c = w.cells[k];
        int iv = c->index(v);
        for (int j = 0; j < 4; j++) {
            if (j == iv) continue;  // facet j contains v
            Cell nbc = c->neighbor(j);
            if (visit(w, nbc)) w.cells.push_back(nbc);
        }
        if (4 * w.cells.size() > w.slot.size()) {  // rare: grow the hash set
            std::vector<std::pair<const void *, std::uint32_t>>(2 * w.slot.size(), {nullptr, 0}).swap(w.slot);
            w.gen = 1;
            for (Cell x : w.cells) visit(w, x);
        }
    }
}

// one vertex: neighbours into w.nb (ascending), hull direction, pole
void star(const DT3 &t, Ws &w, Vertex v, jfb_delaunay *d) {
    const std::uint32_t id = v->info();
    incident_cells(w, v);
    w.nb.clear();
    w.facets.clear();
    if (++w.mark == 0) {
        std::fill(w.stamp.begin(), w.stamp.end(), 0);
        w.mark = 1;
    }
    const Vertex inf = t.infinite_vertex();
    for (Cell c : w.cells) {
        for (int k = 0; k < 4; k++) {
            Vertex u = c->vertex(k);
            if (u == v || u == inf) continue;
            std::uint32_t ui = u->info();
            if (w.stamp[ui] != w.mark) w.stamp[ui] = w.mark, w.nb.push_back(u);
        }
        int ii;
        if (c->has_vertex(inf, ii)) {
            Vertex u[3] = {c->vertex((ii + 1) & 3), c->vertex((ii + 2) & 3), c->vertex((ii + 3) & 3)};
            const std::uint32_t *rk = w.rank;
            std::sort(u, u + 3, [rk](Vertex a, Vertex b) { return rk[a->info()] < rk[b->info()]; });
            Ws::Facet f;
            for (int k = 0; k < 3; k++) f.p[k] = &u[k]->point(), f.r[k] = rk[u[k]->info()];
            f.mirror = t.mirror_vertex(c, ii);
            w.facets.push_back(f);
        }
    }
    // nearest first (ties lexicographic): the C core clips v's planar cell
    // by these half-planes in this order, and the near ones make the cell,
    // so the far ones then mostly cut nothing (clip's early exit)
    const Point &pv0 = v->point();
    w.nbd.clear();
    for (Vertex u : w.nb) w.nbd.push_back({CGAL::squared_distance(pv0, u->point()), u});
    const std::uint32_t *rk = w.rank;
    std::sort(w.nbd.begin(), w.nbd.end(), [rk](const std::pair<double, Vertex> &a, const std::pair<double, Vertex> &b) {
        return a.first != b.first ? a.first < b.first : rk[a.second->info()] < rk[b.second->info()];
    });
    for (size_t k = 0; k < w.nb.size(); k++) w.nb[k] = w.nbd[k].second;

    // hull direction: facets in lexicographic order, normal from the smallest corner
    double *hd = d->hull + 3 * (size_t)id;
    if (!w.facets.empty()) {
        std::sort(w.facets.begin(), w.facets.end());
        int nf = 0;
        double s[3] = {0, 0, 0};
        for (const auto &f : w.facets) {
            const Point *const *P = f.p;
            V3 nrm = cross(sub(*P[1], *P[0]), sub(*P[2], *P[0]));
            double len = std::sqrt(dot(nrm, nrm));
            if (!(len > 0)) continue;
            // outward: away from the finite cell across the facet
            if (dot(nrm, sub(f.mirror->point(), *P[0])) > 0) len = -len;
            s[0] += nrm.x / len, s[1] += nrm.y / len, s[2] += nrm.z / len;
            nf++;
        }
        if (nf > 0)
            for (int k = 0; k < 3; k++) hd[k] = s[k] / nf;
    }

    // pole: farthest circumcentre, each from the cell's vertices in lexicographic order
    double *pd = d->pole + 3 * (size_t)id;
    double best = -1.0;
    const bool hull = hd[0] != 0 || hd[1] != 0 || hd[2] != 0;
    const Point &pv = v->point();
    for (Cell c : w.cells) {
        if (t.is_infinite(c)) continue;
        Vertex q[4] = {c->vertex(0), c->vertex(1), c->vertex(2), c->vertex(3)};
        std::uint32_t r[4] = {rk[q[0]->info()], rk[q[1]->info()], rk[q[2]->info()], rk[q[3]->info()]};
        for (int i = 1; i < 4; i++)  // insertion sort by rank (4 elements)
            for (int j = i; j > 0 && r[j] < r[j - 1]; j--) std::swap(r[j], r[j - 1]), std::swap(q[j], q[j - 1]);
        const Point &p0 = q[0]->point();
        V3 a = sub(q[1]->point(), p0), b = sub(q[2]->point(), p0), e = sub(q[3]->point(), p0);
        V3 be = cross(b, e), ea = cross(e, a), ab = cross(a, b);
        double det = 2.0 * dot(a, be);
        if (det == 0.0) continue;
        double la = dot(a, a), lb = dot(b, b), le = dot(e, e);
        // circumcentre - p0 = (|a|^2 b x e + |b|^2 e x a + |e|^2 a x b) / (2 a.(b x e))
        V3 o = {(la * be.x + lb * ea.x + le * ab.x) / det, (la * be.y + lb * ea.y + le * ab.y) / det,
                (la * be.z + lb * ea.z + le * ab.z) / det};
        if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) continue;
        V3 off = sub(pv, p0);
        // + 0.0: -0 -> +0, so that equal candidates are equal bit for bit
        V3 dv = {o.x - off.x + 0.0, o.y - off.y + 0.0, o.z - off.z + 0.0};
        if (hull && dv.x * hd[0] + dv.y * hd[1] + dv.z * hd[2] >= 0) continue;  // the unbounded side
        double d2 = dot(dv, dv);
        // ties (cospherical cells share a circumcentre up to rounding): the
        // lexicographically smaller vector, so the walk order cannot matter
        if (d2 > best || (d2 == best && std::make_tuple(dv.x, dv.y, dv.z) < std::make_tuple(pd[0], pd[1], pd[2])))
            best = d2, pd[0] = dv.x, pd[1] = dv.y, pd[2] = dv.z;
    }
}

// dimension < 3 (coplanar or collinear input): CGAL's own adjacency,
// sequential (rare; flat clouds), in lexicographic order; no poles, no hull
void flat_adjacency(DT3 &t, std::vector<Vertex> &vh, jfb_delaunay *d) {
    size_t nv = d->nv, len = 0, cap = 8 * nv + 16;
    d->adj = alloc<std::uint32_t>(cap);
    std::vector<Vertex> nb;
    std::vector<std::pair<double, Vertex>> nbd;  // (squared distance, vertex)
    for (size_t id = 0; id < nv; id++) {
        nb.clear();
        if (t.dimension() >= 1) t.finite_adjacent_vertices(vh[id], std::back_inserter(nb));
        if (len + nb.size() > cap) {
            cap = 2 * cap + nb.size();
            auto *p = static_cast<std::uint32_t *>(std::realloc(d->adj, cap * sizeof(std::uint32_t)));
            if (!p) throw std::bad_alloc();
            d->adj = p;
        }
        std::sort(nb.begin(), nb.end(), vlex_less);
        for (auto u : nb) d->adj[len++] = u->info();
        d->adj_off[id + 1] = len;
    }
}
}  // namespace

void jfb::extract_stars(DT3 &t, std::vector<Vertex> &vh, int threads, jfb_delaunay *d) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const size_t nv = d->nv;
    d->adj_off = alloc<size_t>(nv + 1);
    d->adj_off[0] = 0;
    d->pole = alloc<double>(3 * nv);
    d->hull = alloc<double>(3 * nv);
    for (size_t i = 0; i < 3 * nv; i++) d->pole[i] = nan, d->hull[i] = 0.0;
    if (t.dimension() < 3) {
        flat_adjacency(t, vh, d);
        return;
    }
    // lexicographic rank of every vertex: every "in lexicographic order"
    // above compares ranks (integers) instead of points
    std::vector<std::uint32_t> rank(nv);
    {
        std::vector<std::uint32_t> ids(nv);
        for (size_t id = 0; id < nv; id++) ids[id] = (std::uint32_t)id;
        std::sort(ids.begin(), ids.end(),
                  [&vh](std::uint32_t a, std::uint32_t b) { return lex_less(vh[a]->point(), vh[b]->point()); });
        for (size_t k = 0; k < nv; k++) rank[ids[k]] = (std::uint32_t)k;
    }
    // blocks of ids, each with its own adjacency buffer, joined in order
    const size_t nblocks = std::max<size_t>(1, std::min<size_t>(nv / 4096 + 1, 16 * (size_t)std::max(1, threads)));
    std::vector<std::uint32_t *> buf(nblocks, nullptr);
    bool failed = false;
#ifdef _OPENMP
#pragma omp parallel num_threads(threads > 0 ? threads : 1)
#endif
    {
        Ws w;
        try {
            w.rank = rank.data();
            w.slot.assign(256, {nullptr, 0});
            w.stamp.assign(nv, 0);
            w.cells.reserve(256);
        } catch (...) {
#ifdef _OPENMP
#pragma omp atomic write
#endif
            failed = true;
        }
#ifdef _OPENMP
#pragma omp for schedule(dynamic, 1)
#endif
        for (long blk = 0; blk < (long)nblocks; blk++) {
            bool bad;
#ifdef _OPENMP
#pragma omp atomic read
#endif
            bad = failed;
            if (bad) continue;
            size_t a = nv * blk / nblocks, b = nv * (blk + 1) / nblocks;
            try {
                size_t cap = 20 * (b - a) + 64, len = 0;
                std::uint32_t *out = alloc<std::uint32_t>(cap);
                buf[blk] = out;
                for (size_t id = a; id < b; id++) {
                    star(t, w, vh[id], d);
                    if (len + w.nb.size() > cap) {  // rare: grow geometrically
                        cap = 2 * cap + w.nb.size();
                        auto *p = static_cast<std::uint32_t *>(std::realloc(out, cap * sizeof *out));
                        if (!p) throw std::bad_alloc();
                        buf[blk] = out = p;
                    }
                    for (Vertex u : w.nb) out[len++] = u->info();
                    d->adj_off[id + 1] = w.nb.size();  // degree for now
                }
            } catch (...) {
#ifdef _OPENMP
#pragma omp atomic write
#endif
                failed = true;
            }
        }
    }
    // the triangulation is no longer needed: free it before joining
    std::vector<Vertex>().swap(vh);
    t.clear();
    if (failed) {
        for (auto *p : buf) std::free(p);
        throw std::bad_alloc();
    }
    for (size_t id = 0; id < nv; id++) d->adj_off[id + 1] += d->adj_off[id];
    d->adj = static_cast<std::uint32_t *>(std::malloc((d->adj_off[nv] ? d->adj_off[nv] : 1) * sizeof(std::uint32_t)));
    if (!d->adj) {
        for (auto *p : buf) std::free(p);
        throw std::bad_alloc();
    }
    for (size_t blk = 0; blk < nblocks; blk++) {
        size_t a = nv * blk / nblocks, b = nv * (blk + 1) / nblocks;
        std::memcpy(d->adj + d->adj_off[a], buf[blk], (d->adj_off[b] - d->adj_off[a]) * sizeof(std::uint32_t));
        std::free(buf[blk]);
    }
}
