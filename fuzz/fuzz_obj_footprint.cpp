// Wavefront OBJ meshes (io::MeshFootprint: tinyobjloader, then the exact footprint).
#include <pushgraph/io/footprint.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 20000) return 0;  // the footprint's Boolean union is O(faces log faces); keep runs fast
  const std::string path = pushgraph::fuzz::AsFile(data, size, ".obj");
  pushgraph::fuzz::ExpectReturnOrClearError([&] { pushgraph::io::MeshFootprint(path); });
  return 0;
}
