# scene-slope_2d_cphi-dilatant: F-bar with dilatant plastic flow (tests/slope_2d_cphi_psi15.
# expected.yaml says why).  Included by tests/CMakeLists.txt.
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  mpmc_scene_test(scene-slope_2d_cphi-dilatant ${PROJECT_SOURCE_DIR}/workflows/slope_2d_cphi.yaml
                  ${CMAKE_CURRENT_SOURCE_DIR}/slope_2d_cphi_psi15.expected.yaml slope_2d_cphi_psi15)
endif()
