# bench_natural's "plain-dt3-par" row: CGAL's concurrent 3D Delaunay
# insertion (Parallel_tag, TBB), measured against the sequential one that
# the library uses.  Only when TBB is found (Debian: libtbb-dev).
if(JF_BENCH AND TARGET bench_natural AND TARGET CGAL::TBB_support)
  target_link_libraries(bench_natural PRIVATE CGAL::TBB_support)
endif()
