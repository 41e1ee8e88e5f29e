# The quasi-static pushing model, the push simulator and its measurement noise models: part of
# pushgraph::limit_surface (included from the top-level CMakeLists.txt after limit_surface/).
target_sources(pushgraph_limit_surface PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/pushing.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/simulator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/noise.cpp
)
