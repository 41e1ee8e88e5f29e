#pragma once
// Basic types shared by the geometry module. Plain Eigen types in the public API; CGAL stays
// inside the library's .cpp files.
#include <pushgraph/geometry/errors.h>

#include <Eigen/Core>

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

}  // namespace pushgraph::geometry
