// poles.cpp -- Amenta & Bern poles (paper ref. 1, used by §5.1) from a 3D
// Delaunay triangulation: the pole of a sample p is the vertex of p's
// Voronoi cell farthest from p, and p->pole approximates the normal line.
//
// design:
//  1. hull facets (the finite facets of infinite cells): each adds its outer
//     unit normal to its three vertices; the mean is the direction of p's
//     unbounded Voronoi cell (the pole "at infinity").
//  2. every finite cell's circumcentre is a Voronoi vertex of its four
//     vertices; each vertex keeps the farthest one.  A hull sample keeps the
//     farthest one opposite its hull direction (Amenta & Bern's negative
//     pole), which is the accurate one on a closed surface.
//  Nearly flat cells (slivers) have far circumcentres: that is what makes
//  poles work; exactly flat ones give no centre and are skipped.
#include <cmath>
#include <limits>
#include <vector>

#include "dt3.hpp"

namespace {
struct V3 {
    double x, y, z;
};
V3 sub(const jfb::Point &a, const jfb::Point &b) { return {a.x() - b.x(), a.y() - b.y(), a.z() - b.z()}; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
}  // namespace

void jfb::compute_poles(const DT3 &t, jfb_delaunay *d) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (size_t i = 0; i < 3 * d->nv; i++) {
        d->pole[i] = nan;
        d->hull[i] = 0.0;
    }
    if (t.dimension() < 3) return;  // flat or collinear: no bounded cells

    // 1. hull directions
    std::vector<int> nfacets(d->nv, 0);
    std::vector<DT3::Cell_handle> inf;
    t.incident_cells(t.infinite_vertex(), std::back_inserter(inf));
    for (auto c : inf) {
        int i = c->index(t.infinite_vertex());
        const auto &a = c->vertex((i + 1) & 3)->point();
        const auto &b = c->vertex((i + 2) & 3)->point();
        const auto &e = c->vertex((i + 3) & 3)->point();
        V3 nrm = cross(sub(b, a), sub(e, a));
        double len = std::sqrt(dot(nrm, nrm));
        if (!(len > 0)) continue;
        // outward: away from the finite cell on the other side of the facet
        const auto &m = t.mirror_vertex(c, i)->point();
        if (dot(nrm, sub(m, a)) > 0) len = -len;
        for (int k = 1; k <= 3; k++) {
            std::uint32_t v = c->vertex((i + k) & 3)->info();
            d->hull[3 * v] += nrm.x / len;
            d->hull[3 * v + 1] += nrm.y / len;
            d->hull[3 * v + 2] += nrm.z / len;
            nfacets[v]++;
        }
    }
    for (size_t v = 0; v < d->nv; v++)
        if (nfacets[v] > 0)
            for (int k = 0; k < 3; k++) d->hull[3 * v + k] /= nfacets[v];
    std::vector<int>().swap(nfacets);

    // 2. farthest circumcentre per vertex
    std::vector<double> best(d->nv, -1.0);
    for (auto c = t.finite_cells_begin(); c != t.finite_cells_end(); ++c) {
        const auto &p0 = c->vertex(0)->point();
        V3 a = sub(c->vertex(1)->point(), p0), b = sub(c->vertex(2)->point(), p0),
           e = sub(c->vertex(3)->point(), p0);
        V3 bc = cross(b, e), ca = cross(e, a), ab = cross(a, b);
        double det = 2.0 * dot(a, bc);
        if (det == 0.0) continue;
        double la = dot(a, a), lb = dot(b, b), le = dot(e, e);
        // circumcentre relative to p0: (|a|^2 b x e + |b|^2 e x a + |e|^2 a x b) / (2 a.(b x e))
        V3 o = {(la * bc.x + lb * ca.x + le * ab.x) / det, (la * bc.y + lb * ca.y + le * ab.y) / det,
                (la * bc.z + lb * ca.z + le * ab.z) / det};
        if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z)) continue;
        for (int k = 0; k < 4; k++) {
            auto vh = c->vertex(k);
            std::uint32_t v = vh->info();
            V3 off = sub(vh->point(), p0);
            V3 dv = {o.x - off.x, o.y - off.y, o.z - off.z};
            const double *h = d->hull + 3 * v;
            if ((h[0] != 0 || h[1] != 0 || h[2] != 0) && dv.x * h[0] + dv.y * h[1] + dv.z * h[2] >= 0)
                continue;  // on the unbounded side of a hull sample
            double d2 = dot(dv, dv);
            if (d2 > best[v]) {
                best[v] = d2;
                d->pole[3 * v] = dv.x;
                d->pole[3 * v + 1] = dv.y;
                d->pole[3 * v + 2] = dv.z;
            }
        }
    }
}
