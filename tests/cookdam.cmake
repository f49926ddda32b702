# bench/error_vs_runtime at the small end of its sweeps (issue 9): Cook's membrane at 4 and
# 2 m cells, the dam break's hydrostatic stage at 0.5 m cells, the strip footing at 0.2 m
# (B/5, 4 m domain) and the reduced landslide at 0.8 and 0.4 m, standard and F-bar, uGIMP.
# --check fails unless every run completes, each benchmark has its CSV and PNG, and F-bar's
# error is below the standard formulation's at every size (locking).  Included by
# tests/CMakeLists.txt; the scenes' own CTests come from tests/workflows.cmake.
if(NOT TARGET mpmc_cli AND NOT EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  return()
endif()
find_program(MPMC_BASH bash)
if(MPMC_BASH AND MPMC_WITH_GMSH)
  add_test(NAME t661-error-vs-runtime-small
    COMMAND ${MPMC_BASH} ${PROJECT_SOURCE_DIR}/bench/error_vs_runtime --small --check --bench cook,dam,footing,landslide
            --mpmc $<TARGET_FILE:mpmc_cli> --out ${CMAKE_CURRENT_BINARY_DIR}/evr-small)
  set_tests_properties(t661-error-vs-runtime-small PROPERTIES LABELS workflow TIMEOUT 600
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1" FIXTURES_SETUP evr_small)
  # --report redraws the table and PNG from the CSV as it stands: a row appended to the
  # small sweep's Cook CSV (as when runs made elsewhere are merged) must appear in the table
  set(_evr ${CMAKE_CURRENT_BINARY_DIR}/evr-small)
  add_test(NAME t662-error-vs-runtime-report
    COMMAND ${MPMC_BASH} -c "set -e; d=${_evr}/report; rm -rf \"$d\"; mkdir -p \"$d\"; \
cp ${_evr}/evr_cook.csv \"$d\"/; \
echo 'cook,ugimp_total_h0.125,ugimp,total,0.125,completed,quasi_static,368000,900000,5000,0.2762,0.2765,0.0010850,4999.5' >> \"$d\"/evr_cook.csv; \
${PROJECT_SOURCE_DIR}/bench/error_vs_runtime --report --bench cook --figures \"$d\" --out \"$d\"/out; \
grep -q '| ugimp | total | 0.125 | 368000 | 900000 | 4999.5 | 5000.0 | 0.2762 | 0.11 % |' \"$d\"/evr_cook.md; \
test $(grep -c '^| ugimp' \"$d\"/evr_cook.md) -eq 5; \
if command -v gnuplot >/dev/null; then test -s \"$d\"/evr_cook.png; fi")
  set_tests_properties(t662-error-vs-runtime-report PROPERTIES LABELS workflow FIXTURES_REQUIRED evr_small)
endif()
