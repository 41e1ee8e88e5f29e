// Rigid placement and scaling of a whole shape, its centroid and its extent about a point.
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <cmath>
#include <string>

namespace pushgraph::geometry {

Shape TransformShape(const Shape& shape, const Pose2& pose, double scale, bool mirror) {
  if (shape.empty()) throw GeometryError("TransformShape: the shape is empty");
  if (!(std::isfinite(pose.x) && std::isfinite(pose.y) && std::isfinite(pose.theta))) {
    throw GeometryError("TransformShape: the pose must be finite");
  }
  if (!(std::isfinite(scale) && scale > 0.0)) {
    throw GeometryError("TransformShape: the scale must be finite and > 0 (got " + std::to_string(scale) + ")");
  }
  auto move = [&](const Ring& ring) {
    Ring out;
    out.reserve(ring.size());
    for (const Vec2& p : ring) out.push_back(Act(pose, Vec2(scale * p.x(), mirror ? -scale * p.y() : scale * p.y())));
    return out;
  };
  std::vector<Polygon> polygons;
  for (const Polygon& p : shape.polygons()) {
    Polygon q;
    q.outer = move(p.outer);
    for (const Ring& h : p.holes) q.holes.push_back(move(h));
    polygons.push_back(std::move(q));
  }
  // Rigid motions, mirroring and scaling keep rings simple and disjoint; FromPolygons still
  // validates (extreme scales can make distinct vertices round to the same double) and restores
  // the orientation a mirror reverses.
  return Shape::FromPolygons(std::move(polygons), scale * shape.radius());
}

Vec2 CoreCentroid(const Shape& shape) {
  if (shape.empty()) throw GeometryError("CoreCentroid: the shape is empty");
  if (shape.is_degenerate_core()) {
    Vec2 sum = Vec2::Zero();
    int n = 0;
    for (const Polygon& p : shape.polygons()) {
      for (const Vec2& v : p.outer) { sum += v; ++n; }
    }
    return sum / n;
  }
  // Sum over rings of the triangle fan about the first vertex of the whole shape (holes are
  // clockwise, so they subtract); the reference point keeps the products small.
  const Vec2 o = shape.polygons().front().outer.front();
  double area2 = 0.0;
  Vec2 moment = Vec2::Zero();
  auto add = [&](const Ring& ring) {
    const int n = static_cast<int>(ring.size());
    for (int i = 0; i < n; ++i) {
      const Vec2 a = ring[i] - o, b = ring[(i + 1) % n] - o;
      const double cross = a.x() * b.y() - a.y() * b.x();
      area2 += cross;
      moment += cross * (a + b);
    }
  };
  for (const Polygon& p : shape.polygons()) {
    add(p.outer);
    for (const Ring& h : p.holes) add(h);
  }
  return o + moment / (3.0 * area2);
}

double RadiusAbout(const Shape& shape, const Vec2& centre) {
  if (shape.empty()) throw GeometryError("RadiusAbout: the shape is empty");
  double r = 0.0;
  for (const Polygon& p : shape.polygons()) {
    for (const Vec2& v : p.outer) r = std::max(r, (v - centre).norm());
  }
  return r + shape.radius();
}

}  // namespace pushgraph::geometry
