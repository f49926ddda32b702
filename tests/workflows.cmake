# Workflow tests (included by tests/CMakeLists.txt).
# - one CTest per scene in workflows/: mpmc_scene_check runs it at the small size given in
#   SCENE.expected.yaml and compares the metrics in summary.json with the values stored there
# - t65x C tests use libmpmc_workflow and the `mpmc` program
if(NOT TARGET mpmc_workflow AND NOT EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  return()
endif()
file(GLOB MPMC_SCENES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/workflows/*.yaml)
list(FILTER MPMC_SCENES EXCLUDE REGEX ".*\\.expected\\.yaml$")
foreach(scene ${MPMC_SCENES})
  get_filename_component(sname ${scene} NAME_WE)
  set(expected ${PROJECT_SOURCE_DIR}/workflows/${sname}.expected.yaml)
  if(NOT EXISTS ${expected})
    message(WARNING "workflows/${sname}.yaml has no ${sname}.expected.yaml: no CTest")
    continue()
  endif()
  add_test(NAME scene-${sname}
    COMMAND mpmc_scene_check ${scene} ${expected} ${CMAKE_CURRENT_BINARY_DIR}/scene-out/${sname})
  # one thread each: ctest -j2 already fills two cores
  set_tests_properties(scene-${sname} PROPERTIES LABELS workflow
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endforeach()
foreach(t IN ITEMS t650-workflow-scene-errors t651-workflow-run t652-workflow-rigid t660-workflow-resume)
  if(TARGET ${t})
    target_link_libraries(${t} PRIVATE mpmc_workflow)
    target_compile_definitions(${t} PRIVATE MPMC_CLI="$<TARGET_FILE:mpmc_cli>")
    set_tests_properties(${t} PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
  endif()
endforeach()
