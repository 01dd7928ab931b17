# view.cmake -- `jetfit view`: the page in headless Chromium (node drives
# it over the DevTools pipe: tests/view/view_check.js), skipped (77) with a
# visible reason when node, Chromium or three.js (libjs-three) is missing;
# test_cli_view (a Check suite) covers the command and its packing without
# a browser.
find_program(JF_NODE NAMES node nodejs)
foreach(mode colours hostile large)
  if(JF_NODE)
    add_test(NAME view_browser_${mode}
             COMMAND ${JF_NODE} ${CMAKE_CURRENT_SOURCE_DIR}/view/view_check.js
                     $<TARGET_FILE:jetfit> ${mode})
  else()
    add_test(NAME view_browser_${mode}
             COMMAND sh -c "echo 'SKIP: node not found (Debian: nodejs)'; exit 77")
  endif()
  set_tests_properties(view_browser_${mode} PROPERTIES SKIP_RETURN_CODE 77
                       LABELS "cli;browser" TIMEOUT 300)
endforeach()
set_property(TEST view_browser_large APPEND PROPERTY LABELS slow)
if(TARGET test_cli_view)
  add_dependencies(test_cli_view jetfit)
  target_sources(test_cli_view PRIVATE ${PROJECT_SOURCE_DIR}/src/cli/view_pack.c
                 ${PROJECT_SOURCE_DIR}/src/cli/view_page.c ${PROJECT_SOURCE_DIR}/src/cli/view_sample.c)
  target_include_directories(test_cli_view PRIVATE ${PROJECT_SOURCE_DIR}/src/cli)
  set_tests_properties(test_cli_view PROPERTIES LABELS "cli;e2e")
  jf_tool_case(test_cli_view three)
endif()
