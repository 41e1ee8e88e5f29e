#pragma once
// Seeded generators of valid random shapes for the geometry tests and benchmarks: star-shaped
// (generally non-convex) polygons with holes, several disjoint polygons, and helpers for the
// test scale (PUSHGRAPH_TEST_SCALE) and for constructing near-boundary query points.
//
// Validity is by construction, not by rejection (so a too-permissive validator in Shape cannot
// make the generator look right):
// - a star polygon whose vertex angles strictly increase and whose radii are positive is simple;
// - with radii in [rho, R] and consecutive angular gaps <= D (< pi), every edge keeps at least
//   rho * cos(D / 2) from the centre (the chord bound), so the disk of that radius is inside;
// - holes are star polygons inside disjoint disks placed in that inscribed disk;
// - separate polygons are placed in disjoint disks.
#include <pushgraph/geometry/shape.h>

#include "test_scale.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace pushgraph::geometry::testing {

using pushgraph::testing::Scaled;     // test_scale.h: PUSHGRAPH_TEST_SCALE
using pushgraph::testing::TestScale;

constexpr double kPi = 3.14159265358979323846;

/// Star-shaped ring around `centre`: n vertices, angles 2 pi k / n + jitter (|jitter| <= 0.3 of
/// the nominal gap, so gaps are in [0.4, 1.6] * 2 pi / n), radii uniform in [r_min, r_max].
/// Counter-clockwise.
inline Ring RandomStarRing(std::mt19937_64& rng, const Vec2& centre, int n, double r_min,
                           double r_max) {
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  std::uniform_real_distribution<double> radius(r_min, r_max);
  const double phase = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(rng);
  Ring ring;
  ring.reserve(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double a = phase + 2.0 * kPi * (k + jitter(rng)) / n;
    const double r = radius(rng);
    ring.emplace_back(centre.x() + r * std::cos(a), centre.y() + r * std::sin(a));
  }
  return ring;
}

/// Radius of a disk around the centre guaranteed inside a RandomStarRing(n, r_min, .).
inline double InscribedRadius(int n, double r_min) {
  const double max_gap = 1.6 * 2.0 * kPi / n;
  return r_min * std::cos(0.5 * max_gap);
}

struct RandomPolygonOptions {
  int outer_vertices = 16;     ///< >= 6
  int max_holes = 3;           ///< 0..3
  int hole_vertices = 6;       ///< >= 5 (keeps every angular gap < pi)
  double size = 1.0;           ///< outer radii in [0.5, 1] * size
  bool reverse_some_rings = true;  ///< randomly flip orientations (either is accepted)
};

/// A star polygon with 0..max_holes star holes, centred at `centre`.
inline Polygon RandomPolygonWithHoles(std::mt19937_64& rng, const Vec2& centre,
                                      const RandomPolygonOptions& o = {}) {
  const int n = std::max(6, o.outer_vertices);
  const double R = o.size;
  Polygon poly;
  poly.outer = RandomStarRing(rng, centre, n, 0.5 * R, R);
  const double inscribed = InscribedRadius(n, 0.5 * R);  // >= 0.5 R cos(0.8 pi / 3) ~ 0.33 R
  const int holes = std::uniform_int_distribution<int>(0, std::clamp(o.max_holes, 0, 3))(rng);
  // Hole j lives in a disk of radius hr around c_j; the disks are disjoint and inside the
  // inscribed disk (with a margin).
  const double ring_r = holes <= 1 ? 0.0 : 0.45 * inscribed;
  const double hr = holes <= 1 ? 0.5 * inscribed : 0.35 * inscribed;
  const double phase = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(rng);
  for (int j = 0; j < holes; ++j) {
    const double a = phase + 2.0 * kPi * j / std::max(holes, 1);
    const Vec2 c = centre + ring_r * Vec2(std::cos(a), std::sin(a));
    poly.holes.push_back(RandomStarRing(rng, c, std::max(5, o.hole_vertices) + j, 0.4 * hr, hr));
  }
  if (o.reverse_some_rings) {
    std::bernoulli_distribution flip(0.5);
    if (flip(rng)) std::reverse(poly.outer.begin(), poly.outer.end());
    for (auto& h : poly.holes)
      if (flip(rng)) std::reverse(h.begin(), h.end());
  }
  return poly;
}

/// `count` disjoint random polygons with holes, side by side along x (centres 2.5 size apart).
inline std::vector<Polygon> RandomPolygons(std::mt19937_64& rng, int count,
                                           const RandomPolygonOptions& o = {}) {
  std::vector<Polygon> polys;
  std::uniform_real_distribution<double> dy(-0.2, 0.2);
  for (int i = 0; i < count; ++i) {
    const Vec2 c(2.5 * o.size * i + 0.1234, dy(rng) * o.size - 0.0567);
    polys.push_back(RandomPolygonWithHoles(rng, c, o));
  }
  return polys;
}

/// Axis-aligned test polygon with dyadic coordinates: an L-shaped comb with a square hole.
/// Every vertex and many edge points are exactly representable.
///   outer: (0,0) (8,0) (8,2) (6,2) (6,6) (4,6) (4,2) (2,2) (2,8) (0,8)   [CCW]
///   hole : (0.5,0.5) (1.5,0.5) (1.5,1.5) (0.5,1.5)                       [given CCW too]
inline Polygon DyadicComb() {
  Polygon p;
  p.outer = {{0, 0}, {8, 0}, {8, 2}, {6, 2}, {6, 6}, {4, 6}, {4, 2}, {2, 2}, {2, 8}, {0, 8}};
  p.holes = {{{0.5, 0.5}, {1.5, 0.5}, {1.5, 1.5}, {0.5, 1.5}}};
  return p;
}

/// Uniform point in the shape's bounds grown by `grow` (relative to the larger side).
inline Vec2 RandomPointNear(std::mt19937_64& rng, const Box2& b, double grow = 0.2) {
  const double s = std::max(b.max.x() - b.min.x(), b.max.y() - b.min.y());
  std::uniform_real_distribution<double> ux(b.min.x() - grow * s, b.max.x() + grow * s);
  std::uniform_real_distribution<double> uy(b.min.y() - grow * s, b.max.y() + grow * s);
  return {ux(rng), uy(rng)};
}

/// All rings of a shape as (polygon, ring, ring reference), ring -1 = outer.
struct RingRef {
  int polygon;
  int ring;
  const Ring* points;
};
inline std::vector<RingRef> AllRings(const Shape& s) {
  std::vector<RingRef> out;
  const auto& polys = s.polygons();
  for (int i = 0; i < static_cast<int>(polys.size()); ++i) {
    out.push_back({i, -1, &polys[static_cast<size_t>(i)].outer});
    for (int k = 0; k < static_cast<int>(polys[static_cast<size_t>(i)].holes.size()); ++k)
      out.push_back({i, k, &polys[static_cast<size_t>(i)].holes[static_cast<size_t>(k)]});
  }
  return out;
}

/// Points near the boundary: on edges (vertex interpolation, rounded), offset by +-offset along
/// the edge normal, and near vertices offset in random directions.
inline std::vector<Vec2> NearBoundaryPoints(std::mt19937_64& rng, const Shape& s, int count,
                                            double offset) {
  std::vector<Vec2> pts;
  const auto rings = AllRings(s);
  std::uniform_int_distribution<size_t> pick_ring(0, rings.size() - 1);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::uniform_real_distribution<double> ang(0.0, 2.0 * kPi);
  for (int i = 0; i < count; ++i) {
    const Ring& r = *rings[pick_ring(rng)].points;
    const size_t n = r.size();
    const size_t k = std::uniform_int_distribution<size_t>(0, n - 1)(rng);
    const Vec2 a = r[k], b = r[(k + 1) % n];
    switch (i % 4) {
      case 0:
      case 1: {  // along an edge, offset along the normal (both sides)
        const double t = u01(rng);
        const Vec2 e = b - a;
        const Vec2 nrm = Vec2(e.y(), -e.x()).normalized();
        const double sgn = (i % 4 == 0) ? 1.0 : -1.0;
        pts.push_back(a + t * e + sgn * offset * nrm);
        break;
      }
      case 2: {  // near a vertex
        const double t = ang(rng);
        pts.push_back(a + offset * Vec2(std::cos(t), std::sin(t)));
        break;
      }
      default:  // on an edge up to rounding (t interpolation, no offset)
        pts.push_back(a + u01(rng) * (b - a));
        break;
    }
  }
  return pts;
}

}  // namespace pushgraph::geometry::testing
