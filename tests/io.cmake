# The file readers and writers: label their suites "io" (ctest -L io).
foreach(t test_io_read test_io_write test_io_bad)
  if(TEST ${t})
    set_tests_properties(${t} PROPERTIES LABELS io)
  endif()
endforeach()
