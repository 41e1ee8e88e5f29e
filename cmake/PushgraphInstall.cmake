# Installation: headers, static libraries, the `pushgraph` tool, the shipped shapes, and a CMake
# package (pushgraphConfig.cmake + version file) exporting pushgraph::<module> targets.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(PUSHGRAPH_LIBRARY_TARGETS pushgraph_geometry pushgraph_limit_surface pushgraph_push pushgraph_io)
if(TARGET pushgraph_graph)
  list(APPEND PUSHGRAPH_LIBRARY_TARGETS pushgraph_graph pushgraph_evaluation)
endif()

install(TARGETS ${PUSHGRAPH_LIBRARY_TARGETS}
  EXPORT pushgraphTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS pushgraph RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
foreach(module geometry limit_surface push io graph evaluation)
  if(EXISTS ${PROJECT_SOURCE_DIR}/${module}/include)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/${module}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endforeach()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pushgraph)

set(PUSHGRAPH_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/pushgraph)
install(EXPORT pushgraphTargets NAMESPACE pushgraph:: DESTINATION ${PUSHGRAPH_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/pushgraphConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pushgraphConfig.cmake INSTALL_DESTINATION ${PUSHGRAPH_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pushgraphConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pushgraphConfig.cmake ${PROJECT_BINARY_DIR}/pushgraphConfigVersion.cmake
  DESTINATION ${PUSHGRAPH_CMAKE_DIR})
