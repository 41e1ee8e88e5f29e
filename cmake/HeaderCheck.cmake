# Public-header hygiene, used from tests/CMakeLists.txt:
#
# 1. Self-containment: every public header <module>/include/pushgraph/**/*.h is compiled first in
#    its own generated translation unit (twice, to check its include guard), in one OBJECT
#    library per module linked to pushgraph::<module> (so only that module's public usage
#    requirements are visible). A header that needs an include it does not have breaks the build.
# 2. No CGAL in public headers (CGAL stays in the .cpp files: compile time, and downstream users
#    do not need CGAL's headers): the generated unit fails with #error when CGAL_VERSION_NR (set by
#    every CGAL header through CGAL/config.h) is defined after the header, i.e. when it includes
#    CGAL directly or through another header; and a CTest test (headers_no_cgal) scans the
#    headers' own #include lines and names the offending header.
#
# Exceptions: PUSHGRAPH_CGAL_HEADER_ALLOWLIST, pairs of "pushgraph/<module>/<file>.h" "one-line
# reason". Currently empty: no public header needs CGAL.
#
# Run as a script (the CTest test): cmake -DSOURCE_DIR=<repo> -P cmake/HeaderCheck.cmake
set(PUSHGRAPH_CGAL_HEADER_ALLOWLIST
  # "pushgraph/geometry/example.h" "reason it must expose a CGAL type"
)

# The public headers as "pushgraph/<module>/...h" paths relative to <module>/include, for every
# <module>/include/pushgraph/<module> folder of the source tree.
function(pushgraph_public_headers source_dir out_modules)
  file(GLOB module_dirs LIST_DIRECTORIES true "${source_dir}/*/include/pushgraph/*")
  set(modules)
  foreach(dir ${module_dirs})
    get_filename_component(module "${dir}" NAME)
    if(IS_DIRECTORY "${dir}" AND dir STREQUAL "${source_dir}/${module}/include/pushgraph/${module}")
      if(CMAKE_SCRIPT_MODE_FILE)
        file(GLOB_RECURSE headers RELATIVE "${source_dir}/${module}/include" "${dir}/*.h")
      else()  # a new header re-runs the configuration
        file(GLOB_RECURSE headers CONFIGURE_DEPENDS RELATIVE "${source_dir}/${module}/include" "${dir}/*.h")
      endif()
      list(SORT headers)
      set(PUSHGRAPH_HEADERS_${module} ${headers} PARENT_SCOPE)
      list(APPEND modules ${module})
    endif()
  endforeach()
  set(${out_modules} ${modules} PARENT_SCOPE)
endfunction()

function(pushgraph_cgal_allowed header out_allowed)
  set(allowed 0)
  set(list ${PUSHGRAPH_CGAL_HEADER_ALLOWLIST})
  list(LENGTH list n)
  set(i 0)
  while(i LESS n)
    list(GET list ${i} entry)
    if(entry STREQUAL header)
      set(allowed 1)
    endif()
    math(EXPR i "${i} + 2")
  endwhile()
  set(${out_allowed} ${allowed} PARENT_SCOPE)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE)  # ---- the CTest test: scan #include lines
  if(NOT SOURCE_DIR)
    message(FATAL_ERROR "usage: cmake -DSOURCE_DIR=<repository> -P HeaderCheck.cmake")
  endif()
  pushgraph_public_headers("${SOURCE_DIR}" modules)
  set(checked 0)
  set(violations)
  foreach(module ${modules})
    foreach(header ${PUSHGRAPH_HEADERS_${module}})
      math(EXPR checked "${checked} + 1")
      file(STRINGS "${SOURCE_DIR}/${module}/include/${header}" cgal_lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]CGAL/")
      pushgraph_cgal_allowed("${header}" allowed)
      if(cgal_lines AND NOT allowed)
        list(GET cgal_lines 0 first)
        string(STRIP "${first}" first)
        list(APPEND violations "${module}/include/${header} includes CGAL (${first})")
      endif()
    endforeach()
  endforeach()
  if(checked EQUAL 0)
    message(FATAL_ERROR "no public headers found under ${SOURCE_DIR}/*/include/pushgraph/")
  endif()
  if(violations)
    string(REPLACE ";" "\n  " text "${violations}")
    message(FATAL_ERROR "public headers must not include CGAL (keep it in the .cpp files, or add the header "
                        "with a reason to PUSHGRAPH_CGAL_HEADER_ALLOWLIST in cmake/HeaderCheck.cmake):\n  ${text}")
  endif()
  message("headers_no_cgal: ${checked} public headers checked, none includes CGAL")
  return()
endif()

# ---- pushgraph_add_header_check(): the OBJECT libraries and the CTest tests (label headers).
function(pushgraph_add_header_check)
  set(out_dir "${PROJECT_BINARY_DIR}/header_check")
  pushgraph_public_headers("${PROJECT_SOURCE_DIR}" modules)
  if(NOT TARGET pushgraph_headers_tests)
    add_custom_target(pushgraph_headers_tests)
  endif()
  foreach(module ${modules})
    if(NOT TARGET pushgraph::${module})
      message(STATUS "Header check: module ${module} is not built, its headers are not compiled")
      continue()
    endif()
    set(sources)
    foreach(header ${PUSHGRAPH_HEADERS_${module}})
      # io's result header needs the estimation module, which is optional.
      file(STRINGS "${PROJECT_SOURCE_DIR}/${module}/include/${header}" graph_include REGEX "#include <pushgraph/graph/")
      if(graph_include AND NOT TARGET pushgraph::graph)
        continue()
      endif()
      pushgraph_cgal_allowed("${header}" allowed)
      string(MAKE_C_IDENTIFIER "${header}" id)
      set(source "${out_dir}/${id}.cpp")
      file(CONFIGURE OUTPUT "${source}" CONTENT
"// Generated by cmake/HeaderCheck.cmake: @header@ must compile on its own.
#include <@header@>
#include <@header@>  // again: the include guard works
#if defined(CGAL_VERSION_NR) && !@allowed@
#error \"@header@ includes CGAL (directly or through another header); see cmake/HeaderCheck.cmake\"
#endif
" @ONLY)
      list(APPEND sources "${source}")
    endforeach()
    set(target pushgraph_header_check_${module})
    add_library(${target} OBJECT ${sources})
    target_link_libraries(${target} PRIVATE pushgraph::${module})
    pushgraph_set_warnings(${target})
    add_dependencies(pushgraph_headers_tests ${target})
  endforeach()

  add_test(NAME headers_no_cgal
    COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${PROJECT_SOURCE_DIR} -P ${PROJECT_SOURCE_DIR}/cmake/HeaderCheck.cmake)
  set_tests_properties(headers_no_cgal PROPERTIES LABELS headers)
  # The scan itself can fail: on a tree with a public header that includes CGAL it must name it.
  set(fixture "${out_dir}/fixture")
  file(WRITE "${fixture}/leaky/include/pushgraph/leaky/leaky.h"
       "#pragma once\n#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>\n")
  add_test(NAME headers_no_cgal_detects_violation
    COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${fixture} -P ${PROJECT_SOURCE_DIR}/cmake/HeaderCheck.cmake)
  set_tests_properties(headers_no_cgal_detects_violation PROPERTIES LABELS headers
    PASS_REGULAR_EXPRESSION "leaky/include/pushgraph/leaky/leaky.h includes CGAL")
endfunction()
