// The contact manifold of two placed shapes (see contacts.h): vertex-edge and vertex-vertex
// pairs of their cores within the tolerance, each gap = core distance - both radii.
#include <pushgraph/geometry/contacts.h>
#include <pushgraph/geometry/errors.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

namespace pushgraph::geometry {
namespace {

// One shape's core in the world frame, ring by ring.
struct PlacedRing {
  EdgeId id;               // index unused
  std::vector<Vec2> points;
  bool has_area = false;   // >= 3 vertices: edges have an outside (interior on the left)
};

std::vector<PlacedRing> Place(const Shape& shape, const Pose2& pose) {
  std::vector<PlacedRing> rings;
  const auto& polygons = shape.polygons();
  for (int p = 0; p < static_cast<int>(polygons.size()); ++p) {
    for (int r = -1; r < static_cast<int>(polygons[p].holes.size()); ++r) {
      const Ring& ring = r < 0 ? polygons[p].outer : polygons[p].holes[r];
      PlacedRing placed;
      placed.id = {p, r, -1};
      placed.has_area = ring.size() >= 3;
      placed.points.reserve(ring.size());
      for (const Vec2& v : ring) placed.points.push_back(Act(pose, v));
      rings.push_back(std::move(placed));
    }
  }
  return rings;
}

int EdgeCount(const PlacedRing& ring) {
  const int n = static_cast<int>(ring.points.size());
  return n >= 3 ? n : n - 1;  // a segment core is one edge; a point has none
}

struct Key {
  EdgeId object, finger;
  int kind;
  bool operator<(const Key& o) const {
    return std::tie(object.polygon, object.ring, object.index, kind, finger.polygon, finger.ring, finger.index) <
           std::tie(o.object.polygon, o.object.ring, o.object.index, o.kind, o.finger.polygon, o.finger.ring,
                    o.finger.index);
  }
};

EdgeId Feature(const PlacedRing& ring, int index) { return {ring.id.polygon, ring.id.ring, index}; }

}  // namespace

std::vector<ContactPoint> FindContacts(const Shape& object, const Pose2& object_pose, const Shape& finger,
                                       const Pose2& finger_pose, const ContactOptions& options) {
  if (object.empty() || finger.empty()) throw GeometryError("FindContacts: the object and the finger must not be empty");
  if (!object_pose.vector().allFinite()) throw GeometryError("FindContacts: the object pose is not finite");
  if (!finger_pose.vector().allFinite()) throw GeometryError("FindContacts: the finger pose is not finite");
  if (!(std::isfinite(options.tolerance) && options.tolerance >= 0.0))
    throw GeometryError("FindContacts: options.tolerance must be finite and >= 0");
  if (!(std::isfinite(options.max_depth) && options.max_depth >= 0.0))
    throw GeometryError("FindContacts: options.max_depth must be finite and >= 0");

  const std::vector<PlacedRing> object_rings = Place(object, object_pose);
  const std::vector<PlacedRing> finger_rings = Place(finger, finger_pose);
  const double radii = object.radius() + finger.radius();
  std::map<Key, ContactPoint> found;

  // Every vertex of `vertex_rings` against every edge of `edge_rings`; `object_has_edge` says
  // which shape owns the edges (the normal is flipped to point out of the object).
  // A vertex counts only within reach of an edge: |gap + radii| is its distance to the edge, and
  // the gap lies in [-max_depth, tolerance]. Edges whose box, grown by that reach (and a relative
  // margin), misses the vertices' box are skipped before the per-vertex work: a finger against an
  // object of 10000 edges spent half the estimate here, once per step.
  const double reach = std::max(radii + options.tolerance, options.max_depth - radii);
  auto pairs = [&](const std::vector<PlacedRing>& edge_rings, const std::vector<PlacedRing>& vertex_rings,
                   bool object_has_edge) {
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const PlacedRing& vr : vertex_rings)
      for (const Vec2& v : vr.points) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    if (!(lo.x() <= hi.x())) return;
    const double margin = reach + 1e-9 * (std::max(hi.cwiseAbs().maxCoeff(), lo.cwiseAbs().maxCoeff()) + reach);
    lo -= Vec2::Constant(margin);
    hi += Vec2::Constant(margin);
    for (const PlacedRing& er : edge_rings) {
      const int ring_size = static_cast<int>(er.points.size());
      for (int e = 0; e < EdgeCount(er); ++e) {
        const Vec2& a = er.points[e];
        const Vec2& b = er.points[(e + 1) % ring_size];
        if (std::max(a.x(), b.x()) < lo.x() || std::min(a.x(), b.x()) > hi.x() || std::max(a.y(), b.y()) < lo.y() ||
            std::min(a.y(), b.y()) > hi.y())
          continue;
        const Vec2 d = b - a;
        const double length2 = d.squaredNorm();
        const Vec2 outward = Vec2(d.y(), -d.x()) / std::sqrt(length2);  // interior on the left
        for (const PlacedRing& vr : vertex_rings) {
          for (int k = 0; k < static_cast<int>(vr.points.size()); ++k) {
            const Vec2& v = vr.points[k];
            const double s = (v - a).dot(d) / length2;
            ContactPoint c;
            Vec2 on_edge, n;  // the edge's nearest core point; unit normal out of the edge's shape
            double distance;  // signed core distance along n
            int edge_vertex = -1;
            if (s > 0.0 && s < 1.0) {
              on_edge = a + s * d;
              if (er.has_area) {
                n = outward;
                distance = (v - a).dot(outward);
              } else {
                distance = (v - on_edge).norm();
                if (distance == 0.0) continue;  // a vertex on a segment core: no direction
                n = (v - on_edge) / distance;
              }
            } else {
              edge_vertex = s <= 0.0 ? e : (e + 1) % ring_size;
              on_edge = er.points[edge_vertex];
              distance = (v - on_edge).norm();
              if (distance == 0.0) {
                if (!er.has_area) continue;
                n = outward;
              } else {
                n = (v - on_edge) / distance;
              }
            }
            const double gap = distance - radii;
            if (gap > options.tolerance || gap < -options.max_depth) continue;
            c.separation = gap;
            const EdgeId edge_feature = Feature(er, edge_vertex >= 0 ? edge_vertex : e);
            const EdgeId vertex_feature = Feature(vr, k);
            Key key;
            if (object_has_edge) {
              c.normal = n;
              c.object_point = on_edge + object.radius() * n;
              c.finger_point = v - finger.radius() * n;
              c.object_feature = edge_feature;
              c.finger_feature = vertex_feature;
            } else {
              c.normal = -n;
              c.object_point = v - object.radius() * n;
              c.finger_point = on_edge + finger.radius() * n;
              c.object_feature = vertex_feature;
              c.finger_feature = edge_feature;
            }
            c.kind = edge_vertex >= 0 ? ContactPoint::Kind::kVertexVertex
                                      : (object_has_edge ? ContactPoint::Kind::kFingerVertexObjectEdge
                                                         : ContactPoint::Kind::kObjectVertexFingerEdge);
            key = {c.object_feature, c.finger_feature, static_cast<int>(c.kind)};
            found.emplace(key, c);  // a vertex pair seen from several edges is kept once
          }
        }
      }
    }
  };
  pairs(object_rings, finger_rings, true);
  pairs(finger_rings, object_rings, false);
  // Two point cores (a disk finger on a disk-like object) have no edges at all.
  for (const PlacedRing& orr : object_rings) {
    if (orr.points.size() != 1) continue;
    for (const PlacedRing& fr : finger_rings) {
      if (fr.points.size() != 1) continue;
      const Vec2 d = fr.points[0] - orr.points[0];
      const double distance = d.norm();
      if (distance == 0.0) continue;
      ContactPoint c;
      c.kind = ContactPoint::Kind::kVertexVertex;
      c.normal = d / distance;
      c.separation = distance - radii;
      if (c.separation > options.tolerance || c.separation < -options.max_depth) continue;
      c.object_point = orr.points[0] + object.radius() * c.normal;
      c.finger_point = fr.points[0] - finger.radius() * c.normal;
      c.object_feature = Feature(orr, 0);
      c.finger_feature = Feature(fr, 0);
      found.emplace(Key{c.object_feature, c.finger_feature, static_cast<int>(c.kind)}, c);
    }
  }
  // A vertex pair next to an edge contact of either vertex's own edges is the same touch seen
  // past the edge's end (a disk on a face near a corner): keep the edge contact alone. Two edge
  // contacts (the walls of a concave corner) are two touches and both stay.
  auto has_edge_contact = [&](const ContactPoint& vv, bool object_edge) {
    const EdgeId& vertex = object_edge ? vv.object_feature : vv.finger_feature;
    const Shape& owner = object_edge ? object : finger;
    const int n = static_cast<int>(owner.ring(vertex.polygon, vertex.ring).size());
    if (n < 2) return false;
    for (const int e : {vertex.index, (vertex.index + n - 1) % n}) {
      if (n == 2 && e != 0) continue;
      const EdgeId edge{vertex.polygon, vertex.ring, e};
      const Key key = object_edge ? Key{edge, vv.finger_feature, static_cast<int>(ContactPoint::Kind::kFingerVertexObjectEdge)}
                                  : Key{vv.object_feature, edge, static_cast<int>(ContactPoint::Kind::kObjectVertexFingerEdge)};
      if (found.count(key)) return true;
    }
    return false;
  };
  std::vector<ContactPoint> out;
  out.reserve(found.size());
  for (auto& entry : found) {
    const ContactPoint& c = entry.second;
    if (c.kind == ContactPoint::Kind::kVertexVertex && (has_edge_contact(c, true) || has_edge_contact(c, false))) continue;
    out.push_back(c);
  }
  return out;
}

}  // namespace pushgraph::geometry
