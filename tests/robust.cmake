# robust.cmake -- test_eval runs the `jetfit eval` command end to end, so it
# needs the executable built first.
if(TARGET test_eval AND TARGET jetfit)
  add_dependencies(test_eval jetfit)
endif()
