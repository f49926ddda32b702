# MPI tests (tests/mpi/t7xx-mpi-*.c), only in a build with -DMPMC_WITH_MPI=ON: each runs under
# mpiexec on 2 and on 3 ranks, oversubscribed (more ranks than cores is fine for a test).
# OpenMPI refuses to run as root unless told; the two variables tell it, and are ignored for
# other users, so the tests run for both (MPMC_MPIEXEC_ENV: the environment of the runs).
if(NOT MPMC_WITH_MPI)
  return()
endif()
set(MPMC_MPIEXEC_ENV "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1"
  CACHE STRING "Environment of the MPI tests' mpiexec runs")
set(MPMC_MPIEXEC_FLAGS "--oversubscribe" CACHE STRING
  "mpiexec options of the MPI tests (before the program; OpenMPI's --oversubscribe by default)")
file(GLOB MPMC_MPI_TESTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/mpi/t7[0-9][0-9]-mpi-*.c)
foreach(src ${MPMC_MPI_TESTS})
  get_filename_component(name ${src} NAME_WE)
  add_executable(${name} ${src})
  target_link_libraries(${name} PRIVATE mpmc MPI::MPI_C m)
  foreach(np 2 3)
    add_test(NAME ${name}-np${np}
      COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} ${np} ${MPMC_MPIEXEC_FLAGS}
        ${MPIEXEC_PREFLAGS} $<TARGET_FILE:${name}> ${MPIEXEC_POSTFLAGS})
    set_tests_properties(${name}-np${np} PROPERTIES LABELS "mpi" PROCESSORS ${np}
      ENVIRONMENT "${MPMC_MPIEXEC_ENV}" TIMEOUT 600)
  endforeach()
endforeach()
