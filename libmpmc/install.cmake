# Install rules and the package files (included at the end of the top-level CMakeLists.txt):
#   lib/libmpmc.so (+ libmpmc_fortran.so with include/mpmc.mod, libmpmc_workflow.so,
#   libmpmc_gmsh.so and bin/mpmc when built), include/mpmc.h (+ mpmc_workflow.h, mpmc_gmsh.h),
#   lib/cmake/mpmc/{mpmcConfig,mpmcConfigVersion,mpmcTargets}.cmake exporting mpmc::mpmc,
#   mpmc::mpmc_fortran, mpmc::mpmc_workflow, mpmc::mpmc_gmsh,
#   lib/pkgconfig/mpmc.pc (and mpmc-fortran.pc).
# Consumers: find_package(mpmc CONFIG REQUIRED [COMPONENTS Fortran]) and link mpmc::mpmc,
# or `pkg-config --cflags --libs mpmc`.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(MPMC_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/mpmc)

# Installed libraries find their siblings (libmpmc_fortran -> libmpmc, the workflow library's
# dlopen of libmpmc_gmsh) next to themselves; programs look in ../lib.
set(MPMC_INSTALL_TARGETS mpmc)
foreach(t mpmc_fortran mpmc_workflow mpmc_gmsh)
  if(TARGET ${t})
    list(APPEND MPMC_INSTALL_TARGETS ${t})
  endif()
endforeach()
set_target_properties(${MPMC_INSTALL_TARGETS} PROPERTIES INSTALL_RPATH "$ORIGIN")
foreach(t ${MPMC_INSTALL_TARGETS})
  string(REGEX REPLACE "^mpmc_?" "" export_name ${t})
  if(export_name STREQUAL "")
    set(export_name mpmc)
  else()
    set(export_name mpmc_${export_name})
  endif()
  set_target_properties(${t} PROPERTIES EXPORT_NAME ${export_name})
endforeach()

install(TARGETS ${MPMC_INSTALL_TARGETS} EXPORT mpmcTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(FILES ${MPMC_LIB_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# the optional libraries' headers, with their libraries
foreach(t gmsh workflow)
  if(TARGET mpmc_${t})
    install(FILES ${PROJECT_SOURCE_DIR}/libmpmc/include/mpmc_${t}.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endforeach()

if(TARGET mpmc_fortran)
  # the compiled module interface: compiler-specific, installed beside mpmc.h
  get_target_property(MPMC_FORTRAN_MODDIR mpmc_fortran Fortran_MODULE_DIRECTORY)
  install(FILES ${MPMC_FORTRAN_MODDIR}/mpmc.mod DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set(MPMC_HAVE_FORTRAN 1)
else()
  set(MPMC_HAVE_FORTRAN 0)
endif()

if(TARGET mpmc_cli)
  set_target_properties(mpmc_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
  install(TARGETS mpmc_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

install(EXPORT mpmcTargets NAMESPACE mpmc:: DESTINATION ${MPMC_INSTALL_CMAKEDIR})

# mpmcConfig.cmake: the targets, plus a Fortran component that is found only when the
# Fortran library was built.
# An MPI build's mpmc links MPI::MPI_C for its users (mpmc_mpi.h includes mpi.h): found first.
if(MPMC_WITH_MPI)
  set(MPMC_CONFIG_DEPENDENCIES "include(CMakeFindDependencyMacro)\nfind_dependency(MPI COMPONENTS C)")
else()
  set(MPMC_CONFIG_DEPENDENCIES "")
endif()
file(WRITE ${PROJECT_BINARY_DIR}/mpmcConfig.cmake.in [=[
@PACKAGE_INIT@
@MPMC_CONFIG_DEPENDENCIES@
include("${CMAKE_CURRENT_LIST_DIR}/mpmcTargets.cmake")
set(mpmc_Fortran_FOUND @MPMC_HAVE_FORTRAN@)
set(mpmc_C_FOUND 1)
check_required_components(mpmc)
]=])
configure_package_config_file(${PROJECT_BINARY_DIR}/mpmcConfig.cmake.in
  ${PROJECT_BINARY_DIR}/mpmcConfig.cmake INSTALL_DESTINATION ${MPMC_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/mpmcConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/mpmcConfig.cmake ${PROJECT_BINARY_DIR}/mpmcConfigVersion.cmake
  DESTINATION ${MPMC_INSTALL_CMAKEDIR})

# pkg-config: relocatable (prefix from the .pc file's own location)
file(WRITE ${PROJECT_BINARY_DIR}/mpmc.pc "prefix=\${pcfiledir}/../..
libdir=\${prefix}/${CMAKE_INSTALL_LIBDIR}
includedir=\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}

Name: mpmc
Description: Explicit material point method with the F-bar method of Zhao, Jiang & Choo (2023)
Version: ${PROJECT_VERSION}
Libs: -L\${libdir} -lmpmc
Cflags: -I\${includedir}
")
install(FILES ${PROJECT_BINARY_DIR}/mpmc.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(MPMC_HAVE_FORTRAN)
  file(WRITE ${PROJECT_BINARY_DIR}/mpmc-fortran.pc "prefix=\${pcfiledir}/../..
libdir=\${prefix}/${CMAKE_INSTALL_LIBDIR}
includedir=\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}

Name: mpmc-fortran
Description: Fortran 2008 module of libmpmc (module mpmc, built with ${CMAKE_Fortran_COMPILER_ID} ${CMAKE_Fortran_COMPILER_VERSION})
Version: ${PROJECT_VERSION}
Requires: mpmc = ${PROJECT_VERSION}
Libs: -L\${libdir} -lmpmc_fortran
Cflags: -I\${includedir}
")
  install(FILES ${PROJECT_BINARY_DIR}/mpmc-fortran.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endif()
