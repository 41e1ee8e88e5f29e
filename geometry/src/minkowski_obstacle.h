#pragma once
// Configuration-space obstacles C = A (+) B of polygonal cores, built exactly with CGAL Epeck
// (Minkowski sums by reduced convolution, Boolean union for several parts and for segment
// cores). The only translation unit of the library that includes CGAL's Minkowski and Boolean
// set operation headers: it takes about 40 s to compile.
#include <pushgraph/geometry/shape.h>

namespace pushgraph::geometry {

/// The Minkowski sum of the cores of `a` and `b` (each: polygons with holes, a segment, or a
/// point), as a shape with rounding radius `radius`. Vertex coordinates are the exact sums
/// rounded to double.
Shape MinkowskiSumOfCores(const Shape& a, const Shape& b, double radius);

/// The core of `shape` rotated by `angle` and reflected through the origin (-R(angle) x).
Shape RotatedReflectedCore(const Shape& shape, double angle);

}  // namespace pushgraph::geometry
