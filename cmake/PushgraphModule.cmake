# Warnings for the project's own targets (not for third-party headers).
function(pushgraph_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
endfunction()

# pushgraph_add_module(MODULE src1.cpp ...): the library target pushgraph_MODULE, aliased and
# exported as pushgraph::MODULE, with public headers in MODULE/include (installed to include/).
function(pushgraph_add_module module)
  set(target pushgraph_${module})
  add_library(${target} ${ARGN})
  add_library(pushgraph::${module} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${module} OUTPUT_NAME ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:include>)
  pushgraph_set_warnings(${target})
endfunction()
