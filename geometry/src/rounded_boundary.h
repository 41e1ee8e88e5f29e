#pragma once
// The boundary of a rounded obstacle K (+) D(R): a polygonal core K (several polygons with holes)
// grown by a disk of radius R > 0, as segments and circular arcs.
//
// Construction (the offset curve's classical description; Held, "On the Computational Geometry
// of Pocket Machining", 1991, ch. 3): every edge of K contributes its offset segment, translated
// by R along the outward normal; every convex vertex the arc of radius R between its two edge
// normals. The boundary of K (+) D(R) is the part of these raw curves at distance exactly R from K
// (Held's "validity"), so the raw curves are split where they cross one another and every piece is
// kept or dropped by the exact point query of its midpoint against K. What is left is the exact
// boundary, up to the rounding of the crossing points: in a notch, a slot or a hole narrower than
// 2R the offset segments and arcs of the facing walls cross, and the crossings are the obstacle's
// concave corners, where the rounded depth "core depth + R" is only a lower bound.
//
// The nearest boundary point to a point c inside the obstacle is the exact translational
// penetration depth of a rounded shape at c (docs/geometry.md). Each piece remembers the feature
// of K it offsets, and each piece end that is a crossing remembers the other piece's feature, so
// the caller can differentiate the depth (a segment moves with an edge, an arc with a vertex, a
// corner with both).
#include <pushgraph/geometry/shape.h>

#include <memory>

namespace pushgraph::geometry {

/// A feature of the core K: a vertex (global vertex number) or an edge (global start vertex).
struct CoreFeatureRef {
  bool is_vertex = false;
  int index = -1;
};

struct RoundedBoundaryPoint {
  double distance = 0.0;  ///< from the query point to `point`
  Vec2 point{0.0, 0.0};   ///< the nearest point of the boundary
  CoreFeatureRef feature; ///< the feature of K whose offset carries `point`
  /// `point` is a corner of the boundary: where the offset of `feature` crosses the offset of
  /// `other` (two features of K at distance R from `point`).
  bool corner = false;
  CoreFeatureRef other;
};

class RoundedBoundary {
 public:
  /// `rounded`: a shape with a polygonal core (not a point or a segment) and radius > 0.
  explicit RoundedBoundary(const Shape& rounded);
  ~RoundedBoundary();
  RoundedBoundary(const RoundedBoundary&) = delete;
  RoundedBoundary& operator=(const RoundedBoundary&) = delete;

  /// The boundary point nearest to c. `lower_bound` (>= 0) is a distance no larger than the
  /// answer (for a point inside the obstacle: R minus its distance to K), used to size the search.
  RoundedBoundaryPoint Nearest(const Vec2& c, double lower_bound) const;

  /// Number of boundary pieces kept (segments and arcs).
  int piece_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::geometry
