# bench/error_vs_runtime at the small end of its sweeps (issue 9): Cook's membrane at 4 and
# 2 m cells, the dam break's hydrostatic stage at 0.5 m cells and the strip footing at
# 0.2 m (B/5, 4 m domain), standard and F-bar, uGIMP.
# --check fails unless every run completes, each benchmark has its CSV and PNG, and F-bar's
# error is below the standard formulation's at every size (locking).  Included by
# tests/CMakeLists.txt; the scenes' own CTests come from tests/workflows.cmake.
if(NOT TARGET mpmc_cli AND NOT EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  return()
endif()
find_program(MPMC_BASH bash)
if(MPMC_BASH AND MPMC_WITH_GMSH)
  add_test(NAME t661-error-vs-runtime-small
    COMMAND ${MPMC_BASH} ${PROJECT_SOURCE_DIR}/bench/error_vs_runtime --small --check --bench cook,dam,footing
            --mpmc $<TARGET_FILE:mpmc_cli> --out ${CMAKE_CURRENT_BINARY_DIR}/evr-small)
  set_tests_properties(t661-error-vs-runtime-small PROPERTIES LABELS workflow TIMEOUT 300
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
