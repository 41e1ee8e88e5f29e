#pragma once
// Independent oracles for the limit-surface tests: closed forms derived separately from the
// library's edge sums (axis-aligned rectangles by corner decomposition, evaluated in quad
// precision so they stay exact where double closed forms cancel), the note's reference values,
// and small helpers to build supports.
#include <pushgraph/geometry/shape.h>
#include <pushgraph/limit_surface/limit_surface.h>

#include <quadmath.h>

#include <cmath>
#include <vector>

namespace pushgraph::limit_surface::testing {

using Quad = __float128;

inline Quad Sqrt(Quad x) { return sqrtq(x); }
inline Quad Asinh(Quad x) { return asinhq(x); }
inline Quad Abs(Quad x) { return fabsq(x); }
inline Quad Sign(Quad x) { return x > 0 ? Quad(1) : (x < 0 ? Quad(-1) : Quad(0)); }

// Over [0, a] x [0, b] (a, b >= 0): integral of |r| dA and of r/|r| dA. G is a quarter of the
// note's W x H rectangle formula with W = 2a, H = 2b; Phi_x = int_0^b (sqrt(a^2 + y^2) - y) dy.
struct CornerIntegrals {
  Quad G = 0, phi_x = 0, phi_y = 0;
};
inline CornerIntegrals Corner(Quad a, Quad b) {
  CornerIntegrals c;
  if (a == 0 || b == 0) return c;
  const Quad D = Sqrt(a * a + b * b);
  c.G = a * b * D / 3 + (a * a * a * Asinh(b / a) + b * b * b * Asinh(a / b)) / 6;
  c.phi_x = (b * D + a * a * Asinh(b / a)) / 2 - b * b / 2;
  c.phi_y = (a * D + b * b * Asinh(a / b)) / 2 - a * a / 2;
  return c;
}

struct Rect {
  double x0, y0, x1, y1;
  double weight = 1.0;  // +1 region, -1 hole
};

// G(q) and Phi(q) of a union of axis-aligned rectangles (holes with weight -1), quad precision.
struct QuadSums {
  Quad G = 0, phi_x = 0, phi_y = 0;
};
inline QuadSums RectSums(const std::vector<Rect>& rects, Quad qx, Quad qy) {
  QuadSums s;
  for (const Rect& r : rects) {
    const Quad xs[2] = {Quad(r.x0) - qx, Quad(r.x1) - qx};
    const Quad ys[2] = {Quad(r.y0) - qy, Quad(r.y1) - qy};
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        // Inclusion-exclusion over the corners, each an oriented integral over [0, a] x [0, b]
        // (flipping the sign of a negates x and the orientation: phi_x keeps its sign).
        const Quad sign = ((i + j) % 2 == 0 ? 1 : -1) * Quad(r.weight);
        const Quad a = xs[i], b = ys[j];
        const CornerIntegrals c = Corner(Abs(a), Abs(b));
        s.G += sign * Sign(a) * Sign(b) * c.G;
        s.phi_x += sign * Sign(b) * c.phi_x;
        s.phi_y += sign * Sign(a) * c.phi_y;
      }
    }
  }
  return s;
}

// The sustaining load about `centre` (the centroid) for a uniform pressure over `rects` with
// total normal force N and coefficient mu, for a twist of `centre` with omega != 0.
inline Load RectLoad(const std::vector<Rect>& rects, double N, double mu, const Vec2& centre, const Twist& twist) {
  Quad area = 0;
  for (const Rect& r : rects) area += Quad(r.weight) * (Quad(r.x1) - Quad(r.x0)) * (Quad(r.y1) - Quad(r.y0));
  const Quad p = Quad(N) * Quad(mu) / area;
  const Quad w = twist.omega;
  const Quad qx = -Quad(twist.vy) / w, qy = Quad(twist.vx) / w;  // relative to the centre
  const QuadSums s = RectSums(rects, qx + Quad(centre.x()), qy + Quad(centre.y()));
  const Quad sign = Sign(w);
  Load load;
  load.force = Vec2(static_cast<double>(-sign * p * s.phi_y), static_cast<double>(sign * p * s.phi_x));
  load.torque = static_cast<double>(sign * p * (s.G + qx * s.phi_x + qy * s.phi_y));
  return load;
}

inline geometry::Shape RectsToShape(const std::vector<Rect>& outers, const std::vector<Rect>& holes = {}) {
  std::vector<geometry::Polygon> polygons;
  auto ring = [](const Rect& r) {
    return geometry::Ring{{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}};
  };
  for (const Rect& r : outers) polygons.push_back({ring(r), {}});
  for (const Rect& h : holes) {
    for (auto& polygon : polygons) {
      const auto& o = polygon.outer;
      if (h.x0 > o[0].x() && h.x1 < o[2].x() && h.y0 > o[0].y() && h.y1 < o[2].y()) polygon.holes.push_back(ring(h));
    }
  }
  return geometry::Shape::FromPolygons(polygons);
}

inline Support UniformSupport(const geometry::Shape& region, double mass = 1.0, double mu = 1.0, double gravity = 1.0) {
  SupportSpec spec;
  spec.region = region;
  spec.mass = mass;
  spec.mu = mu;
  spec.gravity = gravity;
  return MakeSupport(spec);
}

// Relative difference of two loads, force scaled by mu N and torque by mu N size.
inline double LoadError(const Load& a, const Load& b, double muN, double size) {
  return (a.force - b.force).norm() / muN + std::abs(a.torque - b.torque) / (muN * size);
}

}  // namespace pushgraph::limit_surface::testing
