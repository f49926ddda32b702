# fos-verdict: the factor-of-safety search's verdict does not depend on the time step or on
# the trial's length.  workflows/slope_2d_fos.yaml at 0.5 m cells (its factor is 1.44),
# trials at F = 1.2 (must stand) and F = 1.7 (must fail) only (a bracket wider than the
# tolerance stops there), three times: as the scene says, with dt_factor halved (0.15), and
# with the trial time doubled (4 s).  Included by tests/CMakeLists.txt; script mode runs one.
if(CMAKE_SCRIPT_MODE_FILE)
  set(common --set grid.cell_size=0.5 --set stages.fos.factor_of_safety.lo=1.2
      --set stages.fos.factor_of_safety.hi=1.7 --set stages.fos.factor_of_safety.tolerance=1)
  foreach(variant base half_dt double_time)
    set(extra)
    if(variant STREQUAL half_dt)
      set(extra --set stages.fos.dt_factor=0.15)
    elseif(variant STREQUAL double_time)
      set(extra --set stages.fos.end.time=4)
    endif()
    set(out ${OUT}/${variant})
    execute_process(COMMAND ${MPMC} fos ${SCENE} --out ${out} --force --quiet ${common} ${extra}
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${variant}: mpmc fos failed (${rc}): ${err}")
    endif()
    file(STRINGS ${out}/fos_trials.csv rows)
    list(LENGTH rows n)
    if(NOT n EQUAL 3)
      message(FATAL_ERROR "${variant}: expected two trials in fos_trials.csv, got: ${rows}")
    endif()
    list(GET rows 1 first)
    list(GET rows 2 second)
    if(NOT first MATCHES "^1,1\\.2,stands," OR NOT second MATCHES "^2,1\\.7,fails,")
      message(FATAL_ERROR "${variant}: expected F = 1.2 to stand and F = 1.7 to fail, got\n"
                          "${first}\n${second}")
    endif()
    message(STATUS "${variant}: ${first} | ${second}")
  endforeach()
  return()
endif()
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  add_test(NAME fos-verdict
           COMMAND ${CMAKE_COMMAND} -DMPMC=$<TARGET_FILE:mpmc_cli>
                   -DSCENE=${PROJECT_SOURCE_DIR}/workflows/slope_2d_fos.yaml
                   -DOUT=${CMAKE_CURRENT_BINARY_DIR}/fos-verdict -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(fos-verdict PROPERTIES LABELS workflow
                       ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
