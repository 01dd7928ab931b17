# The repository's own consistency (issue 24): every path or section a
# comment or document names exists (check_refs.py), and the library's
# folders call only down (check_layers.py, over the built objects).
find_program(JF_PY3 NAMES python3)
if(JF_PY3)
  add_test(NAME check_refs COMMAND ${JF_PY3} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_refs.py
           ${PROJECT_SOURCE_DIR})
  add_test(NAME check_layers COMMAND ${JF_PY3} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_layers.py
           ${PROJECT_SOURCE_DIR}/src ${PROJECT_BINARY_DIR}/CMakeFiles/jetfit_obj.dir/src)
  set_tests_properties(check_refs check_layers PROPERTIES LABELS docs)
endif()
if(JF_PY3 AND TARGET jetfit_shared)
  add_test(NAME check_abi COMMAND ${JF_PY3} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_abi.py
           ${PROJECT_SOURCE_DIR}/src/jetfit.h $<TARGET_FILE:jetfit_shared>)
  set_tests_properties(check_abi PROPERTIES LABELS docs)
endif()
add_test(NAME check_man COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_man.sh
         ${PROJECT_SOURCE_DIR}/docs/jetfit.1)
set_tests_properties(check_man PROPERTIES LABELS docs SKIP_RETURN_CODE 77)
# the Python that imports the module, when it is built (python blocks,
# the docstring); else python3
set(JF_DOC_PY ${JF_PY3})
if(Python3_EXECUTABLE)
  set(JF_DOC_PY ${Python3_EXECUTABLE})
endif()
# Every default quoted in the documents is the code's (issue 31):
# print_defaults prints them from the code, check_defaults.py compares.
add_executable(print_defaults ${CMAKE_CURRENT_SOURCE_DIR}/docs/print_defaults.c)
target_link_libraries(print_defaults PRIVATE jetfit_cmdline jetfit_lib)
set_target_properties(print_defaults PROPERTIES LINKER_LANGUAGE CXX)
if(JF_PY3)
  add_test(NAME check_defaults COMMAND ${JF_DOC_PY} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_defaults.py
           ${PROJECT_SOURCE_DIR} $<TARGET_FILE:print_defaults> $<TARGET_FILE:jetfit>
           ${PROJECT_BINARY_DIR}/python)
  set_tests_properties(check_defaults PROPERTIES LABELS docs)
endif()
# The doc-test (issue 31): README's and docs/' sh and python blocks run as
# written against this build (installing and building steps skipped, listed);
# not in a sanitizer build (Release runs them; an ASan library cannot be
# linked into the docs' own programs, and ASan's leak check fails MPI's exit)
if(JF_PY3 AND NOT JF_SANITIZE)
  add_test(NAME check_commands COMMAND ${JF_DOC_PY} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_commands.py
           ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
  set_tests_properties(check_commands PROPERTIES LABELS docs TIMEOUT 1800)
endif()
# Every command's options come from its option table (issue 31): --help,
# the man page and docs/cli.md name each of them and nothing else, and
# state the same defaults; _planted plants three discrepancies and passes
# only if exactly they are reported (the check can fail).  Release only.
if(JF_PY3 AND NOT JF_SANITIZE)
  set(JF_OPT_MPI "")
  if(TARGET jetfit-mpi)
    set(JF_OPT_MPI $<TARGET_FILE:jetfit-mpi>)
  endif()
  add_test(NAME check_options COMMAND ${JF_PY3} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_options.py
           ${PROJECT_SOURCE_DIR} $<TARGET_FILE:jetfit> ${JF_OPT_MPI})
  add_test(NAME check_options_planted COMMAND ${JF_PY3} ${CMAKE_CURRENT_SOURCE_DIR}/docs/check_options.py
           ${PROJECT_SOURCE_DIR} $<TARGET_FILE:jetfit> ${JF_OPT_MPI} --plant)
  set_tests_properties(check_options check_options_planted PROPERTIES LABELS docs)
endif()
