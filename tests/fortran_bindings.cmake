# t013-fortran-bindings: every function declared in the public header libmpmc/include/mpmc.h
# has a bind(C, name='...') interface of the same name in fortran/mpmc.f90, so a function
# added to the C API without its Fortran binding fails the suite.  Included by
# tests/CMakeLists.txt; run in script mode (cmake -DHEADER=... -DMODULE=... -P) as the check.
if(CMAKE_SCRIPT_MODE_FILE)
  cmake_policy(VERSION 3.25) # the project's minimum (IN_LIST)
  # Functions that have no binding of their own, each with the reason:
  #  - mpmc_context_last_error returns a pointer into the context's message buffer, which a
  #    Fortran string cannot borrow safely; the module's mpmc_context_last_error is a Fortran
  #    function of the same name that copies the message through mpmc_context_get_last_error.
  set(NOT_BOUND mpmc_context_last_error)

  file(READ ${HEADER} header)
  file(READ ${MODULE} module)
  # comments out (a commented-out prototype is no function), then one declaration a line:
  # a function is a return type at the start of a line followed by its name and "("
  string(REGEX REPLACE "/\\*([^*]|\\*+[^*/])*\\*+/" "" header "${header}")
  string(REGEX REPLACE "//[^\n]*" "" header "${header}")
  string(REGEX MATCHALL "(^|\n)(const )?[a-z_]+[ *]+mpmc_[a-z0-9_]+\\(" decls "${header}")
  set(functions)
  foreach(d IN LISTS decls)
    string(REGEX MATCH "mpmc_[a-z0-9_]+" name "${d}")
    list(APPEND functions ${name})
  endforeach()
  list(REMOVE_DUPLICATES functions)
  list(LENGTH functions nfun)
  if(nfun LESS 50)
    message(FATAL_ERROR "expected the ~90 functions of ${HEADER}, found ${nfun}: ${functions}")
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
      message(FATAL_ERROR "the exclusion ${f} is no longer a function of ${HEADER}: drop it")
    endif()
  endforeach()
  if(missing)
    string(REPLACE ";" ", " missing "${missing}")
    message(FATAL_ERROR "expected a bind(C, name='...') interface in ${MODULE} for every "
      "function of ${HEADER}; none for: ${missing}")
  endif()
  return()
endif()

add_test(NAME t013-fortran-bindings
  COMMAND ${CMAKE_COMMAND} -DHEADER=${PROJECT_SOURCE_DIR}/libmpmc/include/mpmc.h
    -DMODULE=${PROJECT_SOURCE_DIR}/fortran/mpmc.f90 -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(t013-fortran-bindings PROPERTIES LABELS "unit;fortran")
