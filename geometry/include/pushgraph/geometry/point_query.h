#pragma once
// Exact point-versus-shape queries: containment, closest boundary point and feature, outward
// normal, signed distance, with derivatives.
//
// Exactness. Inside/outside/on-boundary and the choice of the closest feature are decided
// with exact predicates (CGAL Epick's filtered predicates, exact rational arithmetic where a
// filter fails). Returned doubles agree with an exact computation to within a few ulps: the
// distance to an edge is computed from an error-free (double-double) cross product, so points
// within 1e-12 of an edge still get a distance accurate to the last bits. A point exactly on
// the boundary of an unrounded shape has signed distance exactly 0.
//
// Rounded shapes (radius r > 0) follow the usual rounded-SDF convention: signed distance =
// core signed distance - r and closest point = core closest point + r * normal. This is the
// exact Euclidean signed distance everywhere outside the shape; inside a notch narrower than
// 2r it is the standard rounded-shape value rather than the distance to the rounded boundary.
// Containment of rounded shapes is decided exactly (squared distance against r^2).
//
//   PointQuery q = QueryPoint(shape, Vec2(0.1, 0.02));
//   if (q.containment == Containment::kInside) { ... q.signed_distance < 0 ... }
//
//   PointQueryJacobians J;   // shape at a pose, point in the world frame
//   PointQuery w = QueryPoint(shape, object_pose, finger_tip, &J);
//   // J.J_sd_pose: d signed_distance / d (x, y, theta) of object_pose
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <Eigen/Core>

namespace pushgraph::geometry {

enum class Containment { kOutside, kOnBoundary, kInside };

/// The boundary feature of the core polygons closest to the query point.
struct BoundaryFeature {
  enum class Kind { kVertex, kEdge };
  Kind kind = Kind::kVertex;
  EdgeId edge;     ///< kVertex: the vertex is edge.index of that ring; kEdge: the edge
  double t = 0.0;  ///< kEdge: parameter of the closest point along the edge, in (0, 1)
};

struct PointQuery {
  Containment containment = Containment::kOutside;
  double signed_distance = 0.0;  ///< negative inside, rounding radius included
  Vec2 closest_point{0.0, 0.0};  ///< on the (rounded) boundary
  /// Outward unit normal at the closest point; equals the gradient of the signed distance with
  /// respect to the query point. On the boundary at a vertex: the normalized sum of the two
  /// edge normals. At the exact centre of a point core: (1, 0) by convention.
  Vec2 normal{1.0, 0.0};
  BoundaryFeature feature;
};

/// Derivatives of a posed query (shape at `pose`, point in the world frame).
struct PointQueryJacobians {
  Eigen::Matrix<double, 1, 2> J_sd_point;       ///< d signed_distance / d point (= normal^T)
  Eigen::Matrix<double, 1, 3> J_sd_pose;        ///< d signed_distance / d (x, y, theta)
  Eigen::Matrix2d J_closest_point;              ///< d closest_point / d point
  Eigen::Matrix<double, 2, 3> J_closest_pose;   ///< d closest_point / d (x, y, theta)
  Eigen::Matrix2d J_normal_point;               ///< d normal / d point
  Eigen::Matrix<double, 2, 3> J_normal_pose;    ///< d normal / d (x, y, theta)
};

/// Query in the shape's own frame. Throws GeometryError for a non-finite point or empty shape.
PointQuery QueryPoint(const Shape& shape, const Vec2& point);

/// Query with the shape placed at `pose` (shape frame -> world); `point` and all results are
/// in the world frame.
PointQuery QueryPoint(const Shape& shape, const Pose2& pose, const Vec2& point,
                      PointQueryJacobians* jacobians = nullptr);

/// Exact containment only (cheaper than a full query for unrounded shapes).
Containment Contains(const Shape& shape, const Vec2& point);

/// Signed distance with its gradient with respect to the point (optional).
double SignedDistance(const Shape& shape, const Vec2& point, Vec2* gradient = nullptr);

/// Reference implementation: visits every edge, no acceleration structure. Same answers as
/// QueryPoint (bit for bit); used by tests and benchmarks.
PointQuery QueryPointBruteForce(const Shape& shape, const Vec2& point);

}  // namespace pushgraph::geometry
