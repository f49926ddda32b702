# docs-tutorial: docs/tutorial.md's commands, as a user would type them.  Every code block
# after a line `<!-- file: NAME -->` is written to NAME, every ```sh block is run with bash
# (-e: a failing command fails the test), in order, in a fresh directory with mpmc on PATH.
# Included by tests/CMakeLists.txt; script mode (-DDOC -DMPMC -DDIR) runs the tutorial.
if(CMAKE_SCRIPT_MODE_FILE)
  file(REMOVE_RECURSE ${DIR})
  file(MAKE_DIRECTORY ${DIR})
  # one list element per line: ';' (a list separator) and '[' ']' held as placeholders
  file(READ ${DOC} text)
  string(REPLACE ";" "@SEMI@" text "${text}")
  string(REPLACE "[" "@LB@" text "${text}")
  string(REPLACE "]" "@RB@" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  get_filename_component(bindir ${MPMC} DIRECTORY)
  set(mode "")        # "", "file", "sh": inside which kind of block
  set(target "")      # the file the next block goes to
  set(body "")
  set(nfile 0)
  set(nsh 0)
  foreach(line IN LISTS lines)
    if(mode STREQUAL "")
      if(line MATCHES "^<!-- file: ([^ ]+) -->$")
        set(target ${CMAKE_MATCH_1})
      elseif(line MATCHES "^```")
        if(target)
          set(mode file)
        elseif(line STREQUAL "```sh")
          set(mode sh)
        else()
          set(mode skip)
        endif()
        set(body "")
      endif()
    elseif(line STREQUAL "```")
      string(REPLACE "@SEMI@" ";" body "${body}")
      string(REPLACE "@LB@" "[" body "${body}")
      string(REPLACE "@RB@" "]" body "${body}")
      if(mode STREQUAL "file")
        file(WRITE ${DIR}/${target} "${body}")
        math(EXPR nfile "${nfile} + 1")
        set(target "")
      elseif(mode STREQUAL "sh")
        math(EXPR nsh "${nsh} + 1")
        file(WRITE ${DIR}/step${nsh}.sh "set -e\nexport PATH='${bindir}':$PATH\n${body}")
        execute_process(COMMAND bash ${DIR}/step${nsh}.sh WORKING_DIRECTORY ${DIR}
                        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
        message(STATUS "step ${nsh}:\n${body}${out}")
        if(NOT rc EQUAL 0)
          message(FATAL_ERROR "docs/tutorial.md, command block ${nsh} failed (${rc}):\n${body}\n"
                              "${out}\n${err}")
        endif()
      endif()
      set(mode "")
    elseif(NOT mode STREQUAL "skip")
      string(APPEND body "${line}\n")
    endif()
  endforeach()
  if(nfile LESS 2 OR nsh LESS 4)
    message(FATAL_ERROR "docs/tutorial.md: expected its files and command blocks, found ${nfile} "
                        "files and ${nsh} command blocks")
  endif()
  return()
endif()

if(EXISTS ${PROJECT_SOURCE_DIR}/workflows/CMakeLists.txt AND MPMC_WITH_GMSH)
  add_test(NAME docs-tutorial
    COMMAND ${CMAKE_COMMAND} -DDOC=${PROJECT_SOURCE_DIR}/docs/tutorial.md
            -DMPMC=$<TARGET_FILE:mpmc_cli> -DDIR=${CMAKE_CURRENT_BINARY_DIR}/tutorial
            -P ${CMAKE_CURRENT_SOURCE_DIR}/tutorial.cmake)
  set_tests_properties(docs-tutorial PROPERTIES LABELS workflow
    ENVIRONMENT "OMP_NUM_THREADS=1;OPENBLAS_NUM_THREADS=1")
endif()
