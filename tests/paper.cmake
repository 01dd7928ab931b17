# paper.cmake -- the paper's experiments (engineer "paper"): the end-to-end
# test of `jetfit generate` / `jetfit convergence` runs the built binary,
# so building the test builds the command; labels group the suites.
if(TARGET test_generate_cli AND TARGET jetfit)
  add_dependencies(test_generate_cli jetfit)
endif()
foreach(t test_surfaces test_convergence_mesh test_generate_cli)
  if(TARGET ${t})
    set_property(TEST ${t} APPEND PROPERTY LABELS paper)
  endif()
endforeach()
