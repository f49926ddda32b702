# scene-slope_2d_cphi-dilatant: F-bar with dilatant plastic flow (tests/slope_2d_cphi_psi15.
# expected.yaml says why).  Included by tests/CMakeLists.txt.
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  add_test(NAME scene-slope_2d_cphi-dilatant
    COMMAND mpmc_scene_check ${PROJECT_SOURCE_DIR}/workflows/slope_2d_cphi.yaml
            ${CMAKE_CURRENT_SOURCE_DIR}/slope_2d_cphi_psi15.expected.yaml
            ${CMAKE_CURRENT_BINARY_DIR}/scene-out/slope_2d_cphi_psi15)
  set_tests_properties(scene-slope_2d_cphi-dilatant PROPERTIES LABELS workflow
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
