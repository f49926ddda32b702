# t013-fortran-bindings: every function declared in the public headers libmpmc/include/*.h
# has a bind(C, name='...') interface of the same name in fortran/mpmc.f90, so a function
# added to the C API without its Fortran binding fails the suite.  Included by
# tests/CMakeLists.txt; run in script mode (cmake -DHEADERS=a.h,b.h -DMODULE=... -P) as the
# check.  The headers are parsed by libmpmc/public_api.cmake, as for the libraries' exports.
# t014-exported-symbols: each shared library exports exactly the functions of its public
# header (libmpmc: mpmc.h and, in an MPI build, mpmc_mpi.h; libmpmc_gmsh: mpmc_gmsh.h, libmpmc_workflow: mpmc_workflow.h).
if(CMAKE_SCRIPT_MODE_FILE)
  cmake_policy(VERSION 3.25) # the project's minimum (IN_LIST)
  # Functions that have no binding of their own, each with the reason:
  #  - mpmc_context_last_error returns a pointer into the context's message buffer, which a
  #    Fortran string cannot borrow safely; the module's mpmc_context_last_error is a Fortran
  #    function of the same name that copies the message through mpmc_context_get_last_error.
  #  - mpmc_sim_create_mpi and mpmc_sim_checkpoint_read_mpi take an MPI_Comm, a C handle
  #    Fortran cannot pass; the module binds their _f twins, which take MPI's Fortran handle
  #    (MPI_Comm_f2c).
  set(NOT_BOUND mpmc_context_last_error mpmc_sim_create_mpi mpmc_sim_checkpoint_read_mpi)

  include(${CMAKE_CURRENT_LIST_DIR}/../libmpmc/public_api.cmake)
  string(REPLACE "," ";" HEADERS "${HEADERS}")
  mpmc_public_functions(functions ${HEADERS})
  file(READ ${MODULE} module)
  list(LENGTH functions nfun)
  if(nfun LESS 50)
    message(FATAL_ERROR "expected the ~100 functions of ${HEADERS}, found ${nfun}: ${functions}")
  endif()
  string(TOLOWER "${module}" module_lc)
  set(missing)
  foreach(f IN LISTS functions)
    if(f IN_LIST NOT_BOUND)
      continue()
    endif()
    string(REGEX MATCH "bind\\( *c *, *name *= *['\"]${f}['\"] *\\)" hit "${module_lc}")
    if(NOT hit)
      list(APPEND missing ${f})
    endif()
  endforeach()
  foreach(f IN LISTS NOT_BOUND)
    if(NOT f IN_LIST functions)
      message(FATAL_ERROR "the exclusion ${f} is no longer a function of ${HEADERS}: drop it")
    endif()
  endforeach()
  if(missing)
    string(REPLACE ";" ", " missing "${missing}")
    message(FATAL_ERROR "expected a bind(C, name='...') interface in ${MODULE} for every "
      "function of ${HEADERS}; none for: ${missing}")
  endif()
  return()
endif()

file(GLOB MPMC_PUBLIC_HEADERS ${PROJECT_SOURCE_DIR}/libmpmc/include/*.h)
list(JOIN MPMC_PUBLIC_HEADERS "," MPMC_PUBLIC_HEADERS)
add_test(NAME t013-fortran-bindings
  COMMAND ${CMAKE_COMMAND} -DHEADERS=${MPMC_PUBLIC_HEADERS}
    -DMODULE=${PROJECT_SOURCE_DIR}/fortran/mpmc.f90 -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(t013-fortran-bindings PROPERTIES LABELS "unit;fortran")

# t014-exported-symbols-<lib> (shared libraries only): `nm -D --defined-only` of the library
# against the functions of its public header.  workflows/ is added after tests/: its target
# is named here and resolved at generate time.
if(BUILD_SHARED_LIBS AND CMAKE_NM)
  set(libs mpmc)
  if(TARGET mpmc_gmsh)
    list(APPEND libs mpmc_gmsh)
  endif()
  if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt)
    list(APPEND libs mpmc_workflow)
  endif()
  foreach(lib IN LISTS libs)
    set(headers ${PROJECT_SOURCE_DIR}/libmpmc/include/${lib}.h)
    if(lib STREQUAL "mpmc")
      list(JOIN MPMC_LIB_HEADERS "," headers) # mpmc.h (+ mpmc_mpi.h in an MPI build)
    endif()
    add_test(NAME t014-exported-symbols-${lib}
      COMMAND ${CMAKE_COMMAND} -DMODE=check -DNM=${CMAKE_NM}
        -DHEADERS=${headers} -DLIBRARY=$<TARGET_FILE:${lib}>
        -P ${PROJECT_SOURCE_DIR}/libmpmc/public_api.cmake)
    set_tests_properties(t014-exported-symbols-${lib} PROPERTIES LABELS unit)
  endforeach()
endif()
