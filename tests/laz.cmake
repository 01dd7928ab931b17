# LAZ (issue 25): the reader's records, and the writer's .laz files, against
# laz-perf (npm, WASM, under node), an independent LASzip decoder; skipped
# (77) with the reason where
# node or the laz-perf package (.ci/install-deps puts it in
# tests/node_modules) is missing.
if(TEST test_io_laz)
  set_tests_properties(test_io_laz PROPERTIES LABELS io)
endif()
add_executable(laz_dump ${CMAKE_CURRENT_SOURCE_DIR}/io/laz_dump.c)
target_link_libraries(laz_dump PRIVATE jetfit_lib OpenMP::OpenMP_C)
target_include_directories(laz_dump PRIVATE ${JF_INTERNAL_INCLUDES} ${CMAKE_CURRENT_SOURCE_DIR}/io)
add_test(NAME test_laz_perf
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/io/laz_perf_check.sh $<TARGET_FILE:laz_dump>
                 ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/test_laz_perf
                 $<TARGET_FILE:jetfit>)
# slow: jetfit estimate on every real file and 7 generated files of 100,001
# points, each decoded by laz-perf (half a minute in Release; the
# writer's ASan coverage is test_io_laz_write's)
set_tests_properties(test_laz_perf PROPERTIES LABELS "io;slow" SKIP_RETURN_CODE 77 TIMEOUT 600)
