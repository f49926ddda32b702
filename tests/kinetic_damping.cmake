# scene-slope_2d-kinetic: slope_2d's gravity stage with kinetic damping reaches its
# quasi-static end in a third of local damping's steps (tests/slope_2d_kinetic.expected.yaml).
# Included by tests/CMakeLists.txt.
# scene-slope_2d-adaptive: the same stage with adaptive viscous damping alone reaches it in
# half of local damping's steps (tests/slope_2d_adaptive.expected.yaml).
if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
  foreach(kind kinetic adaptive)
    mpmc_scene_test(scene-slope_2d-${kind} ${PROJECT_SOURCE_DIR}/workflows/slope_2d.yaml
                    ${CMAKE_CURRENT_SOURCE_DIR}/slope_2d_${kind}.expected.yaml slope_2d_${kind})
  endforeach()
endif()
