// dt3.hpp -- the 3D Delaunay triangulation type shared by the bridge's
// .cpp files (internal: never included from C).
#ifndef JF_CGAL_BRIDGE_DT3_HPP
#define JF_CGAL_BRIDGE_DT3_HPP
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <cstdint>

#include "cgal_bridge.h"

namespace jfb {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
// info(): the input index while inserting, then the dense vertex id
using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb>;
using DT3 = CGAL::Delaunay_triangulation_3<K, Tds>;
using Point = K::Point_3;

// Fills d->pole and d->hull (arrays already allocated, vertex infos are
// dense ids).  poles.cpp.
void compute_poles(const DT3 &t, jfb_delaunay *d);
}  // namespace jfb
#endif
