# Tests of the quasi-static pushing model, the push simulator and the noise models
# (pushgraph::limit_surface), and of `pushgraph simulate` (runs the real binary).
pushgraph_add_test(test_simulation
  LIBS pushgraph::limit_surface pushgraph::io nlohmann_json::nlohmann_json
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/test_pushing.cpp
    ${CMAKE_CURRENT_LIST_DIR}/test_simulator.cpp
)
add_dependencies(test_simulation pushgraph)
target_compile_definitions(test_simulation PRIVATE PUSHGRAPH_TOOL="$<TARGET_FILE:pushgraph>")
