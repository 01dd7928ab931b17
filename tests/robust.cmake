# robust.cmake -- test_eval runs the `jetfit eval` command end to end, so it
# needs the executable built first.
if(TARGET test_eval AND TARGET jetfit)
  add_dependencies(test_eval jetfit)
endif()

# bench_pcpnet: the PCPNet study (data folder as its argument or $JF_DATA/pcpnet) runs CGAL's
# jet_estimate_normals, whose default SVD is Eigen's (CGAL::Eigen3_support).
if(TARGET bench_pcpnet)
  find_package(Eigen3 3.1.0 QUIET)
  include(CGAL_Eigen3_support OPTIONAL)
  if(TARGET CGAL::Eigen3_support)
    target_link_libraries(bench_pcpnet PRIVATE CGAL::Eigen3_support)
  endif()
endif()
