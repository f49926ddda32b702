# t640-install-package: install the build into PREFIX, then configure, build and run an
# out-of-tree C and Fortran program with find_package(mpmc), and the C one with pkg-config.
# cmake -DBUILD_DIR= -DPREFIX= -DWORK= -DSRC= -DC_COMPILER= -DFortran_COMPILER= -P run.cmake
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "FAILED: ${what} (exit ${rc})\n${out}\n${err}")
  endif()
  set(run_out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${PREFIX} ${WORK}/build ${WORK}/pc)
run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX})
foreach(f include/mpmc.h include/mpmc.mod lib/cmake/mpmc/mpmcConfig.cmake
          lib/cmake/mpmc/mpmcConfigVersion.cmake lib/cmake/mpmc/mpmcTargets.cmake
          lib/pkgconfig/mpmc.pc)
  if(NOT EXISTS ${PREFIX}/${f})
    message(FATAL_ERROR "FAILED: expected ${PREFIX}/${f} after cmake --install")
  endif()
endforeach()

if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()
run("configure the consumer" ${CMAKE_COMMAND} -S ${SRC} -B ${WORK}/build
  -DCMAKE_PREFIX_PATH=${PREFIX} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
  -DCMAKE_C_COMPILER=${C_COMPILER} -DCMAKE_Fortran_COMPILER=${Fortran_COMPILER}
  -DCMAKE_BUILD_TYPE=${BUILD_TYPE})
# the package must come from the prefix, not from the build tree
if(NOT run_out MATCHES "mpmc_DIR=${PREFIX}/lib/cmake/mpmc")
  message(FATAL_ERROR "FAILED: expected mpmc_DIR=${PREFIX}/lib/cmake/mpmc, got:\n${run_out}")
endif()
run("build the consumer" ${CMAKE_COMMAND} --build ${WORK}/build)
foreach(p consumer_c consumer_f)
  run("run ${p}" ${WORK}/build/${p})
  if(NOT run_out MATCHES "${p}: mpmc [0-9]+\\.[0-9]+\\.[0-9]+ ok")
    message(FATAL_ERROR "FAILED: ${p}: expected '${p}: mpmc X.Y.Z ok', got '${run_out}'")
  endif()
endforeach()

# pkg-config: compile and link the C consumer by hand
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${PREFIX}/lib/pkgconfig)
run("pkg-config mpmc" ${PKG_CONFIG} --cflags --libs mpmc)
string(STRIP "${run_out}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
file(MAKE_DIRECTORY ${WORK}/pc)
run("cc with pkg-config flags" ${C_COMPILER} ${SRC}/main.c -o ${WORK}/pc/consumer_c ${flags}
  -Wl,-rpath,${PREFIX}/lib -lm)
run("run the pkg-config consumer" ${WORK}/pc/consumer_c)
if(NOT run_out MATCHES "consumer_c: mpmc [0-9]+\\.[0-9]+\\.[0-9]+ ok")
  message(FATAL_ERROR "FAILED: pkg-config consumer: got '${run_out}'")
endif()

# pkg-config for the Fortran module: mpmc-fortran.pc (.mod directory and both libraries)
run("pkg-config mpmc-fortran" ${PKG_CONFIG} --cflags --libs mpmc-fortran)
string(STRIP "${run_out}" fflags)
separate_arguments(fflags UNIX_COMMAND "${fflags}")
run("gfortran with pkg-config flags" ${Fortran_COMPILER} ${SRC}/main.f90 -o ${WORK}/pc/consumer_f
  -J${WORK}/pc ${fflags} -Wl,-rpath,${PREFIX}/lib)
run("run the pkg-config Fortran consumer" ${WORK}/pc/consumer_f)
if(NOT run_out MATCHES "consumer_f: mpmc [0-9]+\\.[0-9]+\\.[0-9]+ ok")
  message(FATAL_ERROR "FAILED: pkg-config Fortran consumer: got '${run_out}'")
endif()
