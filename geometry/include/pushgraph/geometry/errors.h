#pragma once
// The geometry module's error: every invalid geometric input throws it.
#include <stdexcept>
#include <string>

namespace pushgraph::geometry {

/// Thrown for invalid geometric input (degenerate or self-intersecting polygons, NaN, ...).
/// what() says what is wrong and where; the indices are also available (-1 when not applicable).
class GeometryError : public std::invalid_argument {
 public:
  explicit GeometryError(const std::string& message, int polygon = -1, int ring = -1, int vertex = -1)
      : std::invalid_argument(message), polygon_(polygon), ring_(ring), vertex_(vertex) {}
  int polygon() const { return polygon_; }  ///< polygon index
  int ring() const { return ring_; }        ///< -1 outer boundary, k >= 0 hole k ... or -1 unknown
  int vertex() const { return vertex_; }    ///< vertex index within the ring

 private:
  int polygon_, ring_, vertex_;
};

}  // namespace pushgraph::geometry
