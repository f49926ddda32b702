# The reduced 3D landslide (issue 10, docs/landslide.md).  Included by tests/CMakeLists.txt.
# tests/workflows.cmake already runs workflows/slope_3d_reduced.yaml with F-bar against
# slope_3d_reduced.expected.yaml (scene-slope_3d_reduced: the slope fails and runs out);
# this adds the same scene without F-bar (scene-slope_3d_reduced-standard: it locks).
# (tests/ is added before workflows/: test for the directory, not the target)
if(NOT EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt OR NOT MPMC_WITH_GMSH)
  return()
endif()
set(_ls_scene ${PROJECT_SOURCE_DIR}/workflows/slope_3d_reduced.yaml)
set(_ls_expected ${PROJECT_SOURCE_DIR}/workflows/slope_3d_reduced_standard.expected.yaml)
if(EXISTS ${_ls_scene} AND EXISTS ${_ls_expected})
  mpmc_scene_test(scene-slope_3d_reduced-standard ${_ls_scene} ${_ls_expected} slope_3d_reduced_standard)
endif()
