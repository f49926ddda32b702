# The mpmc front end over MPI (docs/mpi.md): `mpiexec -n N mpmc run SCENE.yaml` against the
# same scene in one process (the same program, started without a launcher: no MPI at all).
# Checked: both complete; summary.json's metrics agree to RTOL (relative, or ATOL absolute
# for values near zero) and the stages end alike (reason and steps); summary.json records the
# ranks; snapshots.h5, its XDMF and checkpoint.h5 are written once.  With RESUME_NP the run
# on N ranks is then continued (`mpmc resume --set stages.<last>.end.time=T2`) on RESUME_NP
# ranks and compared with the one-process run continued alike (a restart N -> M; a finished
# run continued is not the uninterrupted run to T2: its last step was cut to land on T1).
# Only in a build with -DMPMC_WITH_MPI=ON (label mpi); script mode runs one case.
if(CMAKE_SCRIPT_MODE_FILE)
  function(run_or_die what)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
    endif()
  endfunction()
  function(compare what a b)
    file(READ ${a}/summary.json sa)
    file(READ ${b}/summary.json sb)
    foreach(s sa sb)
      string(JSON status GET "${${s}}" status)
      if(NOT status STREQUAL "completed")
        message(FATAL_ERROR "${what}: a run did not complete: ${${s}}")
      endif()
    endforeach()
    string(JSON n GET "${sa}" particles)
    string(JSON m GET "${sb}" particles)
    if(NOT n EQUAL m)
      message(FATAL_ERROR "${what}: ${n} points in one process, ${m} over MPI")
    endif()
    string(JSON ns LENGTH "${sa}" stages)
    math(EXPR last "${ns} - 1")
    foreach(i RANGE ${last})
      foreach(key end steps)
        string(JSON va GET "${sa}" stages ${i} ${key})
        string(JSON vb GET "${sb}" stages ${i} ${key})
        if(NOT va STREQUAL vb)
          message(FATAL_ERROR "${what}: stage ${i}: ${key} ${va} in one process, ${vb} over MPI")
        endif()
      endforeach()
    endforeach()
    foreach(key IN LISTS KEYS)
      string(JSON va GET "${sa}" ${key})
      string(JSON vb GET "${sb}" ${key})
      # |a - b| <= RTOL |a| + ATOL, in CMake's integer-free arithmetic: through math(EXPR)
      # cannot take reals, so compare with a tiny Python-free check by scaled strings
      execute_process(COMMAND awk "BEGIN { a = ${va}; b = ${vb}; d = a - b; if (d < 0) d = -d;
                                           s = a < 0 ? -a : a; exit !(d <= ${RTOL} * s + ${ATOL}) }"
                      RESULT_VARIABLE close)
      if(NOT close EQUAL 0)
        message(FATAL_ERROR "${what}: ${key} = ${va} in one process, ${vb} over MPI (rtol ${RTOL}, atol ${ATOL})")
      endif()
      message(STATUS "${what}: ${key}: ${va} | ${vb}")
    endforeach()
  endfunction()
  # The point-by-point CSVs rank 0 writes from the points it gathers (final_state.csv, the
  # factor of safety's mechanism, the snapshot plots' data): present alike, the same header
  # and rows, and each column's sum within RTOL (1e-6 at least) of the sum of its magnitudes
  # (the rows' order differs: storage order in one process, global ids over MPI).
  function(compare_csvs what a b)
    file(GLOB names RELATIVE ${a} ${a}/final_state.csv ${a}/fos_mechanism.csv ${a}/snap_*.csv)
    set(tol ${RTOL})
    if(tol LESS 1e-6)
      set(tol 1e-6)
    endif()
    foreach(f IN LISTS names)
      if(NOT EXISTS ${b}/${f})
        message(FATAL_ERROR "${what}: ${f} written in one process, not over MPI")
      endif()
      execute_process(COMMAND awk -F, -v tol=${tol} "
          /^#/ { next }
          !(FILENAME in head) { head[FILENAME] = \$0; next }
          { rows[FILENAME]++; for (i = 1; i <= NF; ++i) { s[FILENAME, i] += \$i; m[FILENAME, i] += \$i < 0 ? -\$i : \$i }
            nf = NF }
          END { if (head[ARGV[1]] != head[ARGV[2]]) { print \"header: \" head[ARGV[1]] \" | \" head[ARGV[2]]; exit 1 }
                if (rows[ARGV[1]] != rows[ARGV[2]]) { print \"rows: \" rows[ARGV[1]] \" | \" rows[ARGV[2]]; exit 1 }
                for (i = 1; i <= nf; ++i) { d = s[ARGV[1], i] - s[ARGV[2], i]; if (d < 0) d = -d
                  if (d > tol * m[ARGV[1], i] + 1e-12) { print \"column \" i \": \" s[ARGV[1], i] \" | \" s[ARGV[2], i]; exit 1 } }
                print rows[ARGV[1]] \" rows\" }" ${a}/${f} ${b}/${f}
        RESULT_VARIABLE rc OUTPUT_VARIABLE out)
      if(NOT rc EQUAL 0)
        message(FATAL_ERROR "${what}: ${f} differs: ${out}")
      endif()
      string(STRIP "${out}" out)
      message(STATUS "${what}: ${f}: ${out} alike")
    endforeach()
  endfunction()

  separate_arguments(sets UNIX_COMMAND "${SETS}")
  if(NOT CMD)
    set(CMD run)
  endif()
  set(mpirun ${MPIEXEC} ${MPIEXEC_NUMPROC_FLAG} ${NP} ${MPIEXEC_FLAGS})
  run_or_die("one process" ${MPMC} ${CMD} ${SCENE} --out ${OUT}/serial --force --quiet ${sets})
  run_or_die("${NP} ranks" ${mpirun} ${MPMC} ${CMD} ${SCENE} --out ${OUT}/np${NP} --force --quiet ${sets})
  compare("${NP} ranks" ${OUT}/serial ${OUT}/np${NP})
  compare_csvs("${NP} ranks" ${OUT}/serial ${OUT}/np${NP})
  file(READ ${OUT}/np${NP}/summary.json s)
  string(JSON ranks GET "${s}" ranks)
  if(NOT ranks EQUAL NP)
    message(FATAL_ERROR "summary.json over ${NP} ranks says ranks = ${ranks}")
  endif()
  if(DEFINED ENV{MPMC_CHECK_THREADS}) # threads: 0, no OMP_NUM_THREADS: the node's cores shared
    execute_process(COMMAND getconf _NPROCESSORS_ONLN OUTPUT_VARIABLE cores OUTPUT_STRIP_TRAILING_WHITESPACE)
    execute_process(COMMAND nproc OUTPUT_VARIABLE mine OUTPUT_STRIP_TRAILING_WHITESPACE)
    math(EXPR want "${cores} / ${NP}")
    if(want GREATER mine)
      set(want ${mine})
    endif()
    if(want LESS 1)
      set(want 1)
    endif()
    string(JSON threads GET "${s}" threads_per_rank)
    if(NOT threads EQUAL want)
      message(FATAL_ERROR "${NP} ranks on ${cores} cores (${mine} free to each rank): ${threads} threads a rank, expected ${want}")
    endif()
    message(STATUS "${NP} ranks on ${cores} cores: ${threads} threads a rank")
  endif()
  foreach(f snapshots.h5 snapshots.xdmf checkpoint.h5 series.csv)
    if(NOT EXISTS ${OUT}/np${NP}/${f})
      message(FATAL_ERROR "${NP} ranks: no ${f}")
    endif()
  endforeach()
  file(GLOB strays ${OUT}/np${NP}/*.tmp)
  if(strays)
    message(FATAL_ERROR "${NP} ranks: left ${strays}")
  endif()
  if(RESUME_NP)
    separate_arguments(more UNIX_COMMAND "${RESUME_SETS}")
    run_or_die("resume in one process" ${MPMC} resume ${OUT}/serial --quiet ${more})
    run_or_die("resume on ${RESUME_NP} ranks" ${MPIEXEC} ${MPIEXEC_NUMPROC_FLAG} ${RESUME_NP} ${MPIEXEC_FLAGS}
               ${MPMC} resume ${OUT}/np${NP} --quiet ${more})
    compare("${NP} -> ${RESUME_NP} ranks" ${OUT}/serial ${OUT}/np${NP})
  endif()
  return()
endif()

if(NOT MPMC_WITH_MPI)
  return()
endif()
# mpmc_mpi_scene_test(name np scene keys rtol atol sets [resume_np resume_sets [command]])
function(mpmc_mpi_scene_test name np scene keys rtol atol sets)
  set(resume_np "${ARGV7}")
  set(resume_sets "${ARGV8}")
  set(cmd "${ARGV9}")
  add_test(NAME mpmc-mpi-${name}-np${np}
    COMMAND ${CMAKE_COMMAND} -DMPMC=$<TARGET_FILE:mpmc_cli> -DMPIEXEC=${MPIEXEC_EXECUTABLE}
      -DMPIEXEC_NUMPROC_FLAG=${MPIEXEC_NUMPROC_FLAG} "-DMPIEXEC_FLAGS=${MPMC_MPIEXEC_FLAGS}"
      -DNP=${np} -DSCENE=${PROJECT_SOURCE_DIR}/workflows/${scene} "-DKEYS=${keys}" -DRTOL=${rtol}
      -DATOL=${atol} "-DSETS=${sets}" -DRESUME_NP=${resume_np} "-DRESUME_SETS=${resume_sets}" -DCMD=${cmd}
      -DOUT=${CMAKE_CURRENT_BINARY_DIR}/mpi-out/${name}-np${np}
      -P ${CMAKE_CURRENT_SOURCE_DIR}/mpi_workflow.cmake)
  set_tests_properties(mpmc-mpi-${name}-np${np} PROPERTIES LABELS "mpi" PROCESSORS ${np}
    ENVIRONMENT "${MPMC_MPIEXEC_ENV}" TIMEOUT 900)
endfunction()
foreach(np 2 3 4)
  # the self-weight column to rest: the tracked point's settlement; on 4 ranks the even cut
  # above rank 0 lies 4 cells from the floor's wall and moves clear of it (mpi.c, clear_cuts)
  mpmc_mpi_scene_test(column_2d ${np} column_2d.yaml "tip_displacement_y" 1e-9 1e-12 "")
endforeach()
# threads left open (column_2d sets none) and no OMP_NUM_THREADS: each of 3 ranks takes its
# share of the node's cores, at least 1, not all of them (3 x 2 threads on 2 cores before)
mpmc_mpi_scene_test(threads 3 column_2d.yaml "tip_displacement_y" 1e-9 1e-12 "")
set_tests_properties(mpmc-mpi-threads-np3 PROPERTIES ENVIRONMENT "${MPMC_MPIEXEC_ENV};MPMC_CHECK_THREADS=1"
  ENVIRONMENT_MODIFICATION "OMP_NUM_THREADS=unset:")
# the dam break's centre of mass, surge front and hydrostatic error: exact sums and maxima
# over each rank's own points (no point gathered), the same bits as in one process
foreach(np 2 3 4)
  mpmc_mpi_scene_test(dam_break ${np} dam_break.yaml
    "center_of_mass_x;surge_front_x;hydrostatic_pressure_error" 0 0
    "--set grid.cell_size=0.5 --set stages.collapse.end.time=0.3 --set snapshot_plots=[]")
endforeach()
# the 2D slope (J2 with softening, F-bar) at 0.5 m, 2 s of run-out (2.2 m), then continued to
# 3 s on the other number of ranks; on 3 ranks from the geostatic state (K0 = 0.96), whose
# columns' overburden takes in other ranks' points
mpmc_mpi_scene_test(slope_2d 2 slope_2d.yaml "runout_distance" 1e-6 1e-9
  "--set grid.cell_size=0.5 --set stages.runout.end.time=2" 3 "--set stages.runout.end.time=3")
mpmc_mpi_scene_test(slope_2d 3 slope_2d.yaml "runout_distance" 1e-6 1e-9
  "--set grid.cell_size=0.5 --set stages.runout.end.time=2 --set stages.gravity.initial_stress.k0=0.96"
  2 "--set stages.runout.end.time=3")
# adaptive viscous damping over the ranks (each halo node summed once): the gravity stage ends
# on the same step as in one process
mpmc_mpi_scene_test(slope_2d_adaptive 3 slope_2d.yaml "runout_distance" 1e-6 1e-9
  "--set grid.cell_size=0.5 --set stages.gravity.adaptive_damping=true --set stages.gravity.damping=0 --set stages.gravity.end.min_time=0 --set stages.strength_reduction.end.time=0.001 --set stages.runout.end.time=0.2")
# shipped scenes at their CI size (SCENE.expected.yaml's sets) on 3 ranks: Cook's membrane (its
# load stage ends on the kinetic energy), the quick clay (KINSOL's fallbacks), the slope with
# a water table and its factor of safety
mpmc_mpi_scene_test(cook_membrane 3 cook_membrane.yaml "tip_displacement_y;tip_displacement_x" 1e-6 1e-9
  "--set grid.cell_size=2 --set plots=false")
mpmc_mpi_scene_test(slope_2d_quick_clay 3 slope_2d_quick_clay.yaml "runout_distance" 1e-6 1e-9
  "--set grid.cell_size=0.5 --set stages.runout.end.time=1.0 --set plots=false")
mpmc_mpi_scene_test(slope_arai_tagyo_water 3 slope_arai_tagyo_water.yaml "factor_of_safety" 0 0
  "--set grid.cell_size=2.0")
# `mpmc fos` over the ranks: the same trials and factor (slope_2d_fos at 0.5 m, 4 trials)
mpmc_mpi_scene_test(slope_2d_fos 2 slope_2d_fos.yaml "factor_of_safety" 0 0
  "--set grid.cell_size=0.5 --set stages.fos.factor_of_safety.lo=1.3 --set stages.fos.factor_of_safety.hi=1.45 --set stages.fos.factor_of_safety.tolerance=0.06"
  "" "" fos)
