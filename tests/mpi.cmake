# mpi.cmake -- tests/mpi/test_mpi.sh: `mpirun -np 1|2|3 jetfit-mpi estimate`
# against `jetfit estimate`, byte for byte, and its error cases.  Only when
# jetfit-mpi is built (MPI found); the script exits 77 (skipped) without
# mpirun.  Not under the sanitizers: OpenMPI's own allocations make ASan's
# leak report noisy (the MPI code paths run in the Release suite).
if(TARGET jetfit-mpi AND NOT JF_SANITIZE)
  foreach(mode equal-knn equal-more errors full-disk)
    add_test(NAME test_mpi_${mode}
             COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/mpi/test_mpi.sh $<TARGET_FILE:jetfit>
                     $<TARGET_FILE:jetfit-mpi> ${CMAKE_CURRENT_BINARY_DIR} ${mode})
    set_tests_properties(test_mpi_${mode} PROPERTIES SKIP_RETURN_CODE 77 LABELS "mpi;e2e"
                         TIMEOUT 300)
  endforeach()
endif()
