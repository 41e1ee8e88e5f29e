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

// t + rho with rho = sqrt(t^2 + d^2), free of cancellation for t < 0.
double TPlusRho(double t, double rho, double d2) { return t >= 0.0 ? t + rho : d2 / (rho - t); }

}  // namespace

// Per edge, with rho_i = |P_i - q| = sqrt(t_i^2 + d^2) (so t sqrt(t^2 + d^2) = t rho) and
// asinh(t / |d|) = log((t + rho) / |d|), the two asinh of H(t2) - H(t1) merge into one log:
//   H(t2) - H(t1) = t2 rho2 - t1 rho1 + d^2 log((t2 + rho2) / (t1 + rho1)).
// The distances rho are shared by consecutive edges.
EdgeSums RingEdgeSums(const std::vector<Vec2>& ring, const Vec2& q) {
  EdgeSums sums;
  const std::size_t size = ring.size();
  if (size == 0) return sums;
  Vec2 a = ring[0] - q;
  double rho_a = a.norm();
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2 b = ring[i + 1 == size ? 0 : i + 1] - q;
    const double rho_b = b.norm();
    const Vec2 edge = b - a;
    const double length = edge.norm();
    if (length > 0.0) {
      const Vec2 e = edge / length;
      const Vec2 n(e.y(), -e.x());
      const double d = a.dot(n), d2 = d * d;
      const double t1 = a.dot(e), t2 = b.dot(e);
      double dH = t2 * rho_b - t1 * rho_a;
      if (d2 > 0.0) dH += d2 * std::log(TPlusRho(t2, rho_b, d2) / TPlusRho(t1, rho_a, d2));
      sums.G += d * dH / 6.0;
      sums.Phi += n * (dH / 2.0);
    }
    a = b;
    rho_a = rho_b;
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
