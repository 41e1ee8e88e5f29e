// A regular polygon of many corners (a tessellated cylinder) recognized as the disk it
// approximates. A polygonal finger needs an exact Minkowski-sum obstacle per relative angle and
// many short faces, each a local witness's feature: a rect1 recording took 6.4 s against 0.4 s as
// a disk, and the fixed-lag smoother drifted 11 mm from a 0.1 mm tracker on a slow ellip1 push.
#include <pushgraph/geometry/shape.h>

#include <cmath>

namespace pushgraph::geometry {

std::optional<TessellatedDiskFit> TessellatedDisk(const Shape& shape) {
  if (shape.polygons().size() != 1 || !shape.polygons()[0].holes.empty() || shape.radius() != 0.0) return std::nullopt;
  const Ring& given = shape.polygons()[0].outer;
  const Box2 box = shape.bounds();
  const double size = (box.max - box.min).norm();
  // A vertex within 1e-9 of the outline's size of the previous one is a seam (a y-up tip.obj
  // gave 34 vertices, two of them 1e-18 m apart), as is one on the straight line between its
  // neighbours to 1e-9 of the edge.
  Ring distinct;
  for (const Vec2& v : given)
    if (distinct.empty() || (v - distinct.back()).norm() > 1e-9 * size) distinct.push_back(v);
  while (distinct.size() > 1 && (distinct.front() - distinct.back()).norm() <= 1e-9 * size) distinct.pop_back();
  Ring ring;
  for (std::size_t i = 0; i < distinct.size(); ++i) {
    const std::size_t m = distinct.size();
    const Vec2 a = distinct[(i + m - 1) % m], v = distinct[i], b = distinct[(i + 1) % m];
    const Vec2 ab = b - a, av = v - a;
    if (std::abs(ab.x() * av.y() - ab.y() * av.x()) > 1e-9 * ab.squaredNorm()) ring.push_back(v);
  }
  const std::size_t n = ring.size();
  if (n < 20) return std::nullopt;
  Vec2 centre = Vec2::Zero();
  for (const Vec2& v : ring) centre += v;
  centre /= static_cast<double>(n);
  double mean = 0.0;
  for (const Vec2& v : ring) mean += (v - centre).norm();
  mean /= static_cast<double>(n);
  const double step = 2.0 * M_PI / static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = ring[i] - centre, b = ring[(i + 1) % n] - centre;
    const double turn = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));  // counter-clockwise, convex: one step
    if (std::abs(a.norm() - mean) > 5e-3 * mean || std::abs(turn - step) > 0.2 * step) return std::nullopt;
  }
  for (int k = 0; k < 2; ++k)
    if (std::abs(centre[k]) < 1e-9 * mean) centre[k] = 0.0;  // the mean of a centred ring: rounding only
  return TessellatedDiskFit{Shape::Disk(mean, centre), n};
}

}  // namespace pushgraph::geometry
