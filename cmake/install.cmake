# install.cmake -- what `cmake --install build --prefix P` puts under P:
# bin/jetfit, lib/libjetfit.so.0 (+ the dev symlink), include/jetfit.h,
# lib/pkgconfig/jetfit.pc, lib/cmake/jetfit/ (find_package(jetfit) with the
# imported target jetfit::jetfit) and share/man/man1/jetfit.1.
include(CMakePackageConfigHelpers)
install(TARGETS jetfit RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS jetfit_shared EXPORT jetfitTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES ${PROJECT_SOURCE_DIR}/src/jetfit.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})

# libjetfit.a (JF_STATIC_LIB): the library and the CGAL bridge in one
# archive; a program links it with `pkg-config --libs jetfit-static` (the
# archive by path, then GSL, expat, OpenMP, the C++ runtime and CGAL's GMP/MPFR:
# `pkg-config --static --libs jetfit` says -ljetfit, which the linker
# resolves to the shared library when both are installed) or
# jetfit::jetfit_static.
if(JF_STATIC_LIB)
  add_library(jetfit_static STATIC $<TARGET_OBJECTS:jetfit_obj> $<TARGET_OBJECTS:jetfit_cgal_obj>)
  set_target_properties(jetfit_static PROPERTIES OUTPUT_NAME jetfit EXPORT_NAME jetfit_static)
  target_include_directories(jetfit_static PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(JF_CGAL)
    target_link_libraries(jetfit_static INTERFACE gsl gslcblas gomp expat stdc++ gmp mpfr m)
  else()
    target_link_libraries(jetfit_static INTERFACE gsl gslcblas gomp expat m)
  endif()
  install(TARGETS jetfit_static EXPORT jetfitTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  set(JF_PC_STATIC ON)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/docs/jetfit.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)

install(EXPORT jetfitTargets NAMESPACE jetfit:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jetfit)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/jetfitConfig.cmake.in
  ${PROJECT_BINARY_DIR}/jetfitConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jetfit)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/jetfitConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/jetfitConfig.cmake ${PROJECT_BINARY_DIR}/jetfitConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/jetfit)

# pkg-config: paths relative to the .pc file, so `--prefix P` at install
# time (not the configure-time prefix) is what the file describes
if(JF_CGAL)
  set(JF_PC_PRIVATE "-lgsl -lgslcblas -lgomp -lexpat -lstdc++ -lgmp -lmpfr -lm")
else()
  set(JF_PC_PRIVATE "-lgsl -lgslcblas -lgomp -lexpat -lm")
endif()
file(RELATIVE_PATH JF_PC_UP /r/${CMAKE_INSTALL_LIBDIR}/pkgconfig /r)
configure_file(${PROJECT_SOURCE_DIR}/cmake/jetfit.pc.in ${PROJECT_BINARY_DIR}/jetfit.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/jetfit.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(JF_PC_STATIC)
  configure_file(${PROJECT_SOURCE_DIR}/cmake/jetfit-static.pc.in ${PROJECT_BINARY_DIR}/jetfit-static.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/jetfit-static.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()
