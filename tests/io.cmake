# I/O tests (issue 4).  Included by tests/CMakeLists.txt; also run in script mode
# (cmake -DLIBS=... -P io.cmake) as the dependency check below.
if(CMAKE_SCRIPT_MODE_FILE)
  # t605-no-gmsh-dependency: the core library (and the Fortran library, when built) must not
  # need libgmsh: a program that does not seed from gmsh never loads it (~0.12 s, ~60 MB).
  find_program(READELF readelf REQUIRED)
  foreach(lib IN LISTS LIBS)
    if(lib STREQUAL "")
      continue()
    endif()
    execute_process(COMMAND ${READELF} -d ${lib} OUTPUT_VARIABLE dyn RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "expected readelf -d ${lib} to succeed, got exit code ${rc}")
    endif()
    string(REGEX MATCHALL "\\(NEEDED\\)[^\n]*" needed "${dyn}")
    if(NOT needed)
      message(FATAL_ERROR "expected NEEDED entries in ${lib}, found none (not a shared library?)")
    endif()
    string(FIND "${needed}" "libgmsh" pos)
    if(NOT pos EQUAL -1)
      message(FATAL_ERROR "expected ${lib} not to need libgmsh, but its NEEDED entries are: ${needed}")
    endif()
  endforeach()
  return()
endif()

# The HDF5 tests read the files back with the HDF5 library itself.
foreach(t t601-output-hdf5 t602-checkpoint)
  if(TARGET ${t})
    target_link_libraries(${t} PRIVATE hdf5::hdf5)
  endif()
endforeach()
# t316-contact-checkpoint damages the /bodies block of a checkpoint with HDF5 (issue 8)
if(TARGET t316-contact-checkpoint)
  target_link_libraries(t316-contact-checkpoint PRIVATE hdf5::hdf5)
endif()

if(BUILD_SHARED_LIBS)
  # fortran/ is added after tests/: the Fortran library is found at generate time
  add_test(NAME t605-no-gmsh-dependency
    COMMAND ${CMAKE_COMMAND}
      "-DLIBS=$<TARGET_FILE:mpmc>;$<$<TARGET_EXISTS:mpmc_fortran>:$<TARGET_FILE:$<IF:$<TARGET_EXISTS:mpmc_fortran>,mpmc_fortran,mpmc>>>"
      -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(t605-no-gmsh-dependency PROPERTIES LABELS workflow)
endif()
