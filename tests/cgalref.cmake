# cgalref: CGAL's Monge_via_jet_fitting defaults to Eigen's JacobiSVD
# (CGAL::Eigen_svd), which needs CGAL_EIGEN3_ENABLED and the Eigen headers
# (Debian: libeigen3-dev).  Without Eigen, tests/core/cgalref_svd.hpp falls back
# to a GSL SVD, so the build never depends on Eigen being there.
find_package(Eigen3 3.1.0 QUIET)
include(CGAL_Eigen3_support OPTIONAL)
foreach(t test_cgal_reference bench_fit)
  if(TARGET ${t} AND TARGET CGAL::Eigen3_support)
    target_link_libraries(${t} PRIVATE CGAL::Eigen3_support)
  endif()
endforeach()
