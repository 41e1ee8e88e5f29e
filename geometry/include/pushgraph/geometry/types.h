#pragma once
// Basic types shared by the geometry module. Plain Eigen types in the public API; CGAL stays
// inside the library's .cpp files.
#include <Eigen/Core>

#include <stdexcept>
#include <string>

namespace pushgraph::geometry {

using Vec2 = Eigen::Vector2d;

/// The supported magnitudes (documented in docs/geometry.md): shape coordinates and rounding
/// radii within +-kMaxCoordinate (metres: 1000 km; any other unit as long as it holds), a shape
/// at least kMinExtent across, query points and poses within +-kMaxQueryCoordinate. Beyond them
/// squared distances overflow or underflow in double precision (a side of 1e300 gave distance
/// 0 and normal (0, 0), a side of 1e-300 a non-unit normal): refused with GeometryError.
inline constexpr double kMaxCoordinate = 1e6;
inline constexpr double kMinExtent = 1e-9;
inline constexpr double kMaxQueryCoordinate = 1e12;

/// Axis-aligned box [min, max].
struct Box2 {
  Vec2 min{0.0, 0.0};
  Vec2 max{0.0, 0.0};
};

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
