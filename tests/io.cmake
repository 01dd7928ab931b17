# The file readers and writers: label their suites "io" (ctest -L io).
foreach(t test_io_read test_io_write test_io_bad)
  if(TEST ${t})
    set_tests_properties(${t} PROPERTIES LABELS io)
  endif()
endforeach()
foreach(t test_io_las test_io_hostile test_io_attrs)
  if(TEST ${t})
    set_tests_properties(${t} PROPERTIES LABELS io)
  endif()
endforeach()
# test_las_numpy: a second LAS reader (numpy, tests/io/las_numpy_check.py)
# reads jetfit's LAS output; Debian's python3 (where python3-numpy is), else
# any; skipped (77) without numpy.
find_program(JF_NUMPY_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT JF_NUMPY_PYTHON)
  find_program(JF_NUMPY_PYTHON NAMES python3)
endif()
# Three inputs: a LAS 1.3 format 1 and a LAS 1.2 format 3 (the output keeps
# their records, issue 13.2) and an x y z listing (format 0 output).
if(JF_NUMPY_PYTHON AND TARGET jetfit)
  foreach(pair "test_las_numpy;vegetation_1_3.las" "test_las_numpy_simple;simple.las"
               "test_las_numpy_xyz;simple.xyz")
    list(GET pair 0 name)
    list(GET pair 1 input)
    add_test(NAME ${name}
             COMMAND ${CMAKE_COMMAND} -E env ${JF_NUMPY_PYTHON}
                     ${CMAKE_CURRENT_SOURCE_DIR}/io/las_numpy_check.py $<TARGET_FILE:jetfit>
                     ${PROJECT_SOURCE_DIR}/tests/data/las/${input}
                     ${CMAKE_CURRENT_BINARY_DIR}/${name})
    set_tests_properties(${name} PROPERTIES LABELS io SKIP_RETURN_CODE 77)
  endforeach()
endif()
