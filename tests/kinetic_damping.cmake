# scene-slope_2d-kinetic: slope_2d's gravity stage with kinetic damping reaches its
# quasi-static end in a third of local damping's steps (tests/slope_2d_kinetic.expected.yaml).
# Included by tests/CMakeLists.txt.
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  add_test(NAME scene-slope_2d-kinetic
    COMMAND mpmc_scene_check ${PROJECT_SOURCE_DIR}/workflows/slope_2d.yaml
            ${CMAKE_CURRENT_SOURCE_DIR}/slope_2d_kinetic.expected.yaml
            ${CMAKE_CURRENT_BINARY_DIR}/scene-out/slope_2d_kinetic)
  set_tests_properties(scene-slope_2d-kinetic PROPERTIES LABELS workflow
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
# scene-slope_2d-adaptive: the same stage with adaptive viscous damping alone reaches it in
# half of local damping's steps (tests/slope_2d_adaptive.expected.yaml).
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  add_test(NAME scene-slope_2d-adaptive
    COMMAND mpmc_scene_check ${PROJECT_SOURCE_DIR}/workflows/slope_2d.yaml
            ${CMAKE_CURRENT_SOURCE_DIR}/slope_2d_adaptive.expected.yaml
            ${CMAKE_CURRENT_BINARY_DIR}/scene-out/slope_2d_adaptive)
  set_tests_properties(scene-slope_2d-adaptive PROPERTIES LABELS workflow
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
