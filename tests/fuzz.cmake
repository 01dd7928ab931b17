# libFuzzer harnesses for the file readers (tests/fuzz/README.md).  Built
# only with -DJF_FUZZ=ON and clang; the reader sources are compiled into
# each harness so they carry the fuzzer's coverage instrumentation.
if(JF_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "JF_FUZZ=ON needs clang: configure with "
            "-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++")
  endif()
  # every file of src/io (the readers and what they call, e.g. the writers'
  # helpers): a new reader file cannot break the fuzz build's link again
  file(GLOB JF_FUZZ_READER_SOURCES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/io/*.c)
  # the writers' default thread count (jf_default_threads), the readers'
  # huge-page buffers (jf__big_alloc)
  list(APPEND JF_FUZZ_READER_SOURCES ${PROJECT_SOURCE_DIR}/src/core/threads.c
       ${PROJECT_SOURCE_DIR}/src/core/bigalloc.c)
  set(JF_FUZZ_FLAGS -fsanitize=fuzzer,address,undefined
      -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g)
  foreach(reader ply xyz off las ptx ply_layout e57 laz laz_rt)
    add_executable(fuzz_${reader} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_${reader}.c
                   ${JF_FUZZ_READER_SOURCES})
    target_include_directories(fuzz_${reader} PRIVATE ${PROJECT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR}/src/io)
    target_compile_options(fuzz_${reader} PRIVATE ${JF_FUZZ_FLAGS})
    target_link_options(fuzz_${reader} PRIVATE ${JF_FUZZ_FLAGS})
    target_link_libraries(fuzz_${reader} PRIVATE OpenMP::OpenMP_C m EXPAT::EXPAT)
  endforeach()
endif()
