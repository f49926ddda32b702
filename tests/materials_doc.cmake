# docs-materials-table: the parameter tables of docs/materials.md are `mpmc models`' output
# (generated from the library's model table), so a model or parameter changed without the
# docs fails the suite.  Included by tests/CMakeLists.txt; run in script mode as the check.
# Regenerate: build/workflows/mpmc models, pasted between the two markers.
if(CMAKE_SCRIPT_MODE_FILE)
  execute_process(COMMAND ${MPMC} models OUTPUT_VARIABLE generated RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "mpmc models failed (${rc})")
  endif()
  file(READ ${DOC} doc)
  set(begin "<!-- mpmc models: begin -->\n")
  set(end "<!-- mpmc models: end -->")
  string(FIND "${doc}" "${begin}" b)
  string(FIND "${doc}" "${end}" e)
  if(b LESS 0 OR e LESS b)
    message(FATAL_ERROR "${DOC}: no '${begin}' ... '${end}' section")
  endif()
  string(LENGTH "${begin}" lb)
  math(EXPR start "${b} + ${lb}")
  math(EXPR len "${e} - ${start}")
  string(SUBSTRING "${doc}" ${start} ${len} documented)
  if(NOT documented STREQUAL generated)
    file(WRITE ${CMAKE_CURRENT_BINARY_DIR}/models.generated.md "${generated}")
    message(FATAL_ERROR "${DOC}: the parameter tables differ from `mpmc models` "
                        "(written to ${CMAKE_CURRENT_BINARY_DIR}/models.generated.md): "
                        "paste its output between the markers")
  endif()
  return()
endif()
add_test(NAME docs-materials-table
         COMMAND ${CMAKE_COMMAND} -DMPMC=$<TARGET_FILE:mpmc_cli>
                 -DDOC=${PROJECT_SOURCE_DIR}/docs/materials.md
                 -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties(docs-materials-table PROPERTIES LABELS unit)
