#pragma once
// Internal: meshes in the formats CAD tools export besides OBJ (STL, PLY, OFF), read by CGAL's
// polygon-soup readers for MeshFootprint (footprint.cpp).
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::io::internal {

struct MeshSoup {
  const char* format = "";          ///< "STL", "PLY" or "OFF"
  std::vector<double> coordinates;  ///< x, y, z of each vertex (an STL's repeated corners merged)
  std::vector<std::vector<int>> faces;
};

/// An STL (binary or ASCII: by its extension or an ASCII "solid" header), PLY or OFF file;
/// nullopt for any other. Throws IoError naming the file when it cannot be read, and the vertex
/// when a coordinate is not finite.
std::optional<MeshSoup> ReadMeshSoup(const std::string& path);

}  // namespace pushgraph::io::internal
