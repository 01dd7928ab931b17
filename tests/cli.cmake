# cli.cmake -- the end-to-end tests of `jetfit estimate` run the built
# binary (JF_BUILD_DIR/jetfit): build it before them, label them.
foreach(t test_cli_errors test_cli_formats test_cli_orient)
  if(TARGET ${t})
    add_dependencies(${t} jetfit)
    set_tests_properties(${t} PROPERTIES LABELS "cli;e2e")
  endif()
endforeach()
if(TARGET test_pipeline)
  set_tests_properties(test_pipeline PROPERTIES LABELS "cli")
endif()
if(TARGET test_orient)
  set_tests_properties(test_orient PROPERTIES LABELS "cli")
endif()
