# fos-jobs: concurrent trials (factor_of_safety.jobs) find the same factor of safety, and a
# search leaves its mechanism and its plots.  workflows/slope_2d_fos.yaml at 0.5 m cells (its
# factor is 1.37) from the bracket [1.3, 1.45] to 0.06, once with one trial at a time
# (bisection: 1.3, 1.45, 1.375, 1.3375) and once with two (1.3 and 1.45 together, then 1.35
# and 1.4).  Checked: the two factors within the tolerance of each other and their brackets
# overlapping; the trials at the factors both runs share (1.3 and 1.45) the same to the last
# digit of fos_trials.csv, wall seconds apart (a trial in a child process is the same trial);
# fos_mechanism.csv, and fos_trials.png and fos_mechanism.png where gnuplot is installed;
# `mpmc resume` after the search keeps its factor and runs the next stage.
# Included by tests/CMakeLists.txt; script mode runs one.
if(CMAKE_SCRIPT_MODE_FILE)
  set(tol 0.06)
  set(common --set grid.cell_size=0.5 --set stages.fos.factor_of_safety.lo=1.3
      --set stages.fos.factor_of_safety.hi=1.45 --set stages.fos.factor_of_safety.tolerance=${tol})
  foreach(jobs 1 2)
    set(out ${OUT}/jobs${jobs})
    execute_process(COMMAND ${MPMC} fos ${SCENE} --out ${out} --force --quiet ${common}
                            --set stages.fos.factor_of_safety.jobs=${jobs}
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "jobs = ${jobs}: mpmc fos failed (${rc}): ${err}")
    endif()
    file(READ ${out}/summary.json summary)
    string(JSON fos${jobs} GET "${summary}" factor_of_safety)
    string(JSON lo${jobs} GET "${summary}" fos_bracket 0)
    string(JSON hi${jobs} GET "${summary}" fos_bracket 1)
    # the rows by factor, without the trial number and the wall seconds
    file(STRINGS ${out}/fos_trials.csv rows)
    list(POP_FRONT rows)
    foreach(row IN LISTS rows)
      string(REGEX REPLACE "^[0-9]+,([^,]+),(.*),[^,]+$" "\\2" rest "${row}")
      string(REGEX REPLACE "^[0-9]+,([^,]+),.*$" "\\1" factor "${row}")
      set(row${jobs}_${factor} "${rest}")
      list(APPEND factors${jobs} ${factor})
    endforeach()
    foreach(f fos_mechanism.csv)
      if(NOT EXISTS ${out}/${f})
        message(FATAL_ERROR "jobs = ${jobs}: no ${f} after the search")
      endif()
    endforeach()
    if(GNUPLOT)
      foreach(f fos_trials.png fos_mechanism.png)
        if(NOT EXISTS ${out}/${f})
          message(FATAL_ERROR "jobs = ${jobs}: no ${f} after the search (gnuplot is ${GNUPLOT})")
        endif()
      endforeach()
    endif()
    if(jobs EQUAL 1)
      # `mpmc resume` after the search runs the stage after it, not the search again, and the
      # summary keeps the search's answer
      execute_process(COMMAND ${MPMC} resume ${out} --quiet --set stages.runout.end.time=0.02
                      RESULT_VARIABLE rc ERROR_VARIABLE err)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "resume after the search failed (${rc}): ${err}")
      endif()
      file(READ ${out}/summary.json resumed)
      string(JSON fos_resumed ERROR_VARIABLE no_fos GET "${resumed}" factor_of_safety)
      string(JSON last_stage GET "${resumed}" stages 2 name)
      file(STRINGS ${out}/fos_trials.csv rows_resumed)
      list(LENGTH rows_resumed n_resumed)
      list(LENGTH factors1 n_first)
      math(EXPR n_first "${n_first} + 1")
      if(no_fos OR NOT fos_resumed STREQUAL fos1 OR NOT last_stage STREQUAL "runout"
         OR NOT n_resumed EQUAL n_first)
        message(FATAL_ERROR "after resume: factor of safety '${fos_resumed}' (search: ${fos1}), last stage "
                            "'${last_stage}', ${n_resumed} rows in fos_trials.csv (search: ${n_first})")
      endif()
    endif()
    message(STATUS "jobs = ${jobs}: factor of safety ${fos${jobs}} [${lo${jobs}}, ${hi${jobs}}], "
                   "factors ${factors${jobs}}")
  endforeach()
  list(LENGTH factors2 n2)
  if(n2 LESS 4)
    message(FATAL_ERROR "jobs = 2: expected two rounds of two trials, got the factors ${factors2}")
  endif()
  # overlapping brackets, each at most tol wide (the search found them): the factors, their
  # midpoints, are within tol of each other
  if(NOT lo1 LESS hi2 OR NOT lo2 LESS hi1)
    message(FATAL_ERROR "jobs = 2 found ${fos2} [${lo2}, ${hi2}], jobs = 1 ${fos1} [${lo1}, ${hi1}]: "
                        "brackets apart, not the same factor within ${tol}")
  endif()
  set(shared 0)
  foreach(factor IN LISTS factors1)
    if(DEFINED row2_${factor})
      math(EXPR shared "${shared} + 1")
      if(NOT row1_${factor} STREQUAL row2_${factor})
        message(FATAL_ERROR "the trial at F = ${factor} differs with jobs = 2:\n"
                            "jobs = 1: ${row1_${factor}}\njobs = 2: ${row2_${factor}}")
      endif()
    endif()
  endforeach()
  if(shared LESS 2)
    message(FATAL_ERROR "expected the trials at 1.3 and 1.45 in both runs, got ${factors1} and ${factors2}")
  endif()
  return()
endif()
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  find_program(MPMC_GNUPLOT gnuplot)
  set(gp)
  if(MPMC_GNUPLOT)
    set(gp -DGNUPLOT=${MPMC_GNUPLOT})
  endif()
  add_test(NAME fos-jobs
           COMMAND ${CMAKE_COMMAND} -DMPMC=$<TARGET_FILE:mpmc_cli>
                   -DSCENE=${PROJECT_SOURCE_DIR}/workflows/slope_2d_fos.yaml ${gp}
                   -DOUT=${CMAKE_CURRENT_BINARY_DIR}/fos-jobs -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(fos-jobs PROPERTIES LABELS workflow
                       ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
