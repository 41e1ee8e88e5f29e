#pragma once
// Every contact between two placed shapes: the contact manifold of a finger and an object, for
// pushes with several contacts (a finger wedged in a notch touches both walls; a flat pusher
// face lying on an object face touches it along a segment, represented by its two end points).
//
// ShapePairQuerier answers "how far apart, and where is the single nearest pair"; this answers
// "which pairs of boundary features are within a tolerance of touching". A contact is a pair of
// core features, one vertex and one edge (or two vertices), of the two shapes whose rounded
// boundaries are at signed gap in [-max_depth, tolerance]:
//   finger vertex - object edge   (a disk finger on a wall; a polygon finger's corner on a face)
//   object vertex - finger edge   (an object corner on a flat pusher face)
//   vertex - vertex               (a disk finger on a convex corner)
// A face lying on a face gives the contacts at the ends of their overlap (the standard 2-D
// contact manifold, as in Box2D's polygon clipping). Pairs whose nearest points coincide (a
// vertex seen from both of its edges) are reported once.
//
// Accuracy: gaps and points are double-precision closed forms (projection on a segment), not
// exact predicates: the manifold decides which contacts a quasi-static model treats as active,
// with a tolerance far above rounding (the nearest pair itself stays ShapePairQuerier's, exact).
// Cost: O(V_finger * E_object + V_object * E_finger) feature pairs, no acceleration structure;
// for a disk finger one pass over the object's edges.
//
//   std::vector<ContactPoint> contacts = FindContacts(object, object_pose, finger, finger_pose);
//   for (const ContactPoint& c : contacts) { ... c.object_point, c.normal, c.separation ... }
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <vector>

namespace pushgraph::geometry {

struct ContactOptions {
  /// Contacts with a gap up to this (m) are reported. Must be finite and >= 0.
  double tolerance = 1e-7;
  /// Overlaps deeper than this (m) are not contacts of the feature pair (a vertex far behind an
  /// edge is on the other side of the shape, not touching it). Must be finite and >= 0.
  double max_depth = 1e-4;
};

struct ContactPoint {
  enum class Kind { kFingerVertexObjectEdge, kObjectVertexFingerEdge, kVertexVertex };
  Kind kind = Kind::kFingerVertexObjectEdge;
  Vec2 object_point{0.0, 0.0};  ///< world, on the object's (rounded) boundary
  Vec2 finger_point{0.0, 0.0};  ///< world, on the finger's (rounded) boundary
  Vec2 normal{1.0, 0.0};        ///< world, unit, out of the object towards the finger
  double separation = 0.0;      ///< signed gap (m): > 0 apart, < 0 overlap
  /// The features: a vertex is the start vertex of the named edge (EdgeId::index).
  EdgeId object_feature;
  EdgeId finger_feature;
};

/// The contacts of `finger` at `finger_pose` with `object` at `object_pose` (world frame), in a
/// deterministic order (by object feature, then finger feature). Throws GeometryError for an
/// empty shape, non-finite poses or bad options.
std::vector<ContactPoint> FindContacts(const Shape& object, const Pose2& object_pose, const Shape& finger,
                                       const Pose2& finger_pose, const ContactOptions& options = {});

}  // namespace pushgraph::geometry
