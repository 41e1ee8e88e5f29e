// Shape JSON (geometry::ParseShapeJson), then the parsed shape's point query, which must accept it.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape.h>

#include "fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  pushgraph::fuzz::ExpectReturnOrClearError([&] {
    const pushgraph::geometry::Shape s = pushgraph::geometry::ParseShapeJson(text, "fuzz.json");
    if (!s.empty()) pushgraph::geometry::QueryPoint(s, pushgraph::geometry::CoreCentroid(s));
  });
  return 0;
}
