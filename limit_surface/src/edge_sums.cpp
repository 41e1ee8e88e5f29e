// Closed-form integrals over polygons as sums over directed edges (docs/limit_surface.md and
// ../shared/notes/limit-surface.md). For an edge P1 -> P2 with unit direction e, outward
// normal n = (e_y, -e_x), d = (P1 - q).n, t_i = (P_i - q).e and
// H(t) = t sqrt(t^2 + d^2) + d^2 asinh(t / |d|):
//   G(q)   = integral of |r - q| dA           = sum d (H(t2) - H(t1)) / 6
//   Phi(q) = integral of (r - q)/|r - q| dA   = sum n (H(t2) - H(t1)) / 2
// (integrate |r - q| and its gradient over the triangle (q, P1, P2) in polar coordinates).
#include "detail.h"

#include <cmath>

namespace pushgraph::limit_surface::detail {
namespace {

double H(double t, double d) {
  const double d2 = d * d;
  if (d2 == 0.0) return t * std::abs(t);
  return t * std::sqrt(t * t + d2) + d2 * std::asinh(t / std::abs(d));
}

}  // namespace

EdgeSums RingEdgeSums(const std::vector<Vec2>& ring, const Vec2& q) {
  EdgeSums sums;
  const std::size_t size = ring.size();
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2 a = ring[i] - q;
    const Vec2 b = ring[(i + 1) % size] - q;
    const Vec2 edge = b - a;
    const double length = edge.norm();
    if (length == 0.0) continue;
    const Vec2 e = edge / length;
    const Vec2 n(e.y(), -e.x());
    const double d = a.dot(n);
    const double dH = H(b.dot(e), d) - H(a.dot(e), d);
    sums.G += d * dH / 6.0;
    sums.Phi += n * (dH / 2.0);
  }
  return sums;
}

RingMoments MomentsOf(const std::vector<Vec2>& ring) {
  // Shoelace: each edge closes a triangle with the origin, taken relative to the first vertex
  // to keep the sums small.
  RingMoments m;
  if (ring.empty()) return m;
  const Vec2 o = ring[0];
  const std::size_t size = ring.size();
  double twice_area = 0.0;
  Vec2 six_first = Vec2::Zero();
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2 a = ring[i] - o;
    const Vec2 b = ring[(i + 1) % size] - o;
    const double cross = a.x() * b.y() - a.y() * b.x();
    twice_area += cross;
    six_first += cross * (a + b);
  }
  m.area = 0.5 * twice_area;
  m.first = six_first / 6.0 + m.area * o;
  return m;
}

}  // namespace pushgraph::limit_surface::detail
