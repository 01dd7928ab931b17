// dt3.hpp -- the 3D Delaunay triangulation type shared by the bridge's
// .cpp files (internal: never included from C).  CGAL's 3D Delaunay is
// unique, degenerate (cospherical) inputs included, by its symbolic
// perturbation, which depends on the points only, not on the insertion
// order.
#ifndef JF_CGAL_BRIDGE_DT3_HPP
#define JF_CGAL_BRIDGE_DT3_HPP
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <cstdint>
#include <vector>

#include "cgal_bridge.h"

namespace jfb {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// info(): the dense vertex id (0 .. nv-1: the order of the spatial sort,
// so ids do not depend on where CGAL stored the vertex)
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K>;
using Cb = CGAL::Delaunay_triangulation_cell_base_3<K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using DT3 = CGAL::Delaunay_triangulation_3<K, Tds>;
using Point = K::Point_3;

// Allocates and fills d->adj_off, d->adj, d->pole, d->hull from the star
// of every vertex (vh[id] is the vertex of id), on `threads` threads;
// frees the triangulation (t.clear()) as soon as it is no longer needed
// (star.cpp).
void extract_stars(DT3 &t, std::vector<DT3::Vertex_handle> &vh, int threads, jfb_delaunay *d);
}  // namespace jfb
#endif
