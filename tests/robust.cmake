# Robustness tests (issue 11).  Included by tests/CMakeLists.txt.
# - fuzz-scene-replay: every file of tests/fuzz/corpus (kept by scripts/fuzz-scene) through
#   the libFuzzer target, compiled here with the ordinary compiler; under MPMC_SANITIZE it
#   runs with ASan + UBSan like the unit tests
# - t69x workflow tests use libmpmc_workflow and the `mpmc` program
# workflows/ is added after tests/: its targets are linked by name (resolved at generate time)
if(NOT EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  return()
endif()
add_executable(fuzz_scene_replay ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/replay.c
  ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_scene.c)
target_include_directories(fuzz_scene_replay PRIVATE ${PROJECT_SOURCE_DIR}/workflows
  ${PROJECT_SOURCE_DIR}/libmpmc/src)
# the loader's own functions (wf_scene_load), hidden in libmpmc_workflow
target_link_libraries(fuzz_scene_replay PRIVATE mpmc_workflow_internal mpmc m)
add_test(NAME fuzz-scene-replay COMMAND fuzz_scene_replay ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus)
set_tests_properties(fuzz-scene-replay PROPERTIES LABELS unit)

file(GLOB ROBUST_WF_TESTS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/t69[0-9]-*.c
  ${CMAKE_CURRENT_SOURCE_DIR}/t072-*.c
  ${CMAKE_CURRENT_SOURCE_DIR}/t52[0-9]-*.c)
foreach(src ${ROBUST_WF_TESTS})
  get_filename_component(t ${src} NAME_WE)
  if(TARGET ${t})
    target_link_libraries(${t} PRIVATE mpmc_workflow hdf5::hdf5)
    target_compile_definitions(${t} PRIVATE MPMC_CLI="$<TARGET_FILE:mpmc_cli>")
    set_tests_properties(${t} PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
  endif()
endforeach()
