#pragma once
// Independent oracle for the penetration depth of a rounded obstacle K (+) D(R), K a set of
// polygon rings (any orientation; holes by even-odd), in extended precision (long double,
// 64-bit mantissa).
//
// The depth of c inside K (+) D(R) is min |x - c| over x with dist(x, K) >= R. The minimizer lies
// on the offset of one feature of K (the point of an offset line or circle nearest to c) or where
// two offsets cross, so the oracle enumerates every such candidate for every feature and pair of
// features, keeps those at distance >= R from K and outside K, and takes the nearest. It shares
// nothing with the library's construction (rounded_boundary.cpp: no splitting, no index, no
// validity tolerance beyond long double rounding).
#include <pushgraph/geometry/shape.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace pushgraph::geometry::testing::rounded {

using LD = long double;

struct LVec {
  LD x = 0, y = 0;
};
inline LVec operator+(LVec a, LVec b) { return {a.x + b.x, a.y + b.y}; }
inline LVec operator-(LVec a, LVec b) { return {a.x - b.x, a.y - b.y}; }
inline LVec operator*(LD s, LVec a) { return {s * a.x, s * a.y}; }
inline LD Dot(LVec a, LVec b) { return a.x * b.x + a.y * b.y; }
inline LD Cross(LVec a, LVec b) { return a.x * b.y - a.y * b.x; }
inline LD Norm(LVec a) { return std::sqrt(Dot(a, a)); }
inline LVec L(const Vec2& v) { return {v.x(), v.y()}; }

struct Segment {
  LVec a, b;
};

inline LD DistanceToSegment(LVec p, const Segment& s) {
  const LVec d = s.b - s.a;
  LD t = Dot(p - s.a, d) / Dot(d, d);
  t = std::min<LD>(1, std::max<LD>(0, t));
  return Norm(p - (s.a + t * d));
}

// Even-odd containment in the core (the candidates tested are far from its boundary).
inline bool InsideCore(LVec p, const std::vector<Segment>& edges) {
  bool inside = false;
  for (const Segment& e : edges)
    if ((e.a.y > p.y) != (e.b.y > p.y) && p.x < e.a.x + (p.y - e.a.y) * (e.b.x - e.a.x) / (e.b.y - e.a.y)) inside = !inside;
  return inside;
}

// A curve of the offset: a line {x : n . x = h} or a circle |x - v| = R, with its feature's
// position (for pruning).
struct OffsetCurve {
  bool circle = false;
  LVec n, v;  // line normal (unit) / circle centre
  LD h = 0;
  Segment feature;
};

/// The penetration depth of c in K (+) D(R) (brute force, header comment).
inline LD OracleDepth(const std::vector<Ring>& rings, LD R, const Vec2& c_in) {
  std::vector<Segment> edges;
  for (const Ring& ring : rings)
    for (size_t i = 0; i < ring.size(); ++i) edges.push_back({L(ring[i]), L(ring[(i + 1) % ring.size()])});
  const LVec c = L(c_in);
  LD scale = R;
  for (const Segment& e : edges) scale = std::max({scale, std::abs(e.a.x), std::abs(e.a.y)});
  const LD slack = 64 * std::numeric_limits<LD>::epsilon() * scale;
  auto valid = [&](LVec x) {
    if (InsideCore(x, edges)) return false;
    for (const Segment& e : edges)
      if (DistanceToSegment(x, e) < R - slack) return false;
    return true;
  };
  LD best = std::numeric_limits<LD>::infinity();
  auto consider = [&](LVec x) {
    const LD d = Norm(x - c);
    if (d < best && valid(x)) best = d;
  };
  std::vector<OffsetCurve> curves;
  for (const Segment& e : edges) {
    const LVec d = e.b - e.a;
    const LD len = Norm(d);
    const LVec n{d.y / len, -d.x / len};
    for (LD side : {LD(1), LD(-1)}) {  // both sides: validity sorts them out
      OffsetCurve cv;
      cv.n = side * n;
      cv.h = Dot(cv.n, e.a) + R;
      cv.feature = e;
      curves.push_back(cv);
      consider(c + (cv.h - Dot(cv.n, c)) * cv.n);
    }
    OffsetCurve circle;
    circle.circle = true;
    circle.v = e.a;
    circle.feature = {e.a, e.a};
    curves.push_back(circle);
    const LD dv = Norm(c - e.a);
    if (dv > 0) consider(e.a + (R / dv) * (c - e.a));
  }
  // Crossings of pairs of curves whose features can generate a point nearer than `best`.
  std::vector<const OffsetCurve*> near;
  for (const OffsetCurve& cv : curves)
    if (DistanceToSegment(c, cv.feature) <= best + R + slack) near.push_back(&cv);
  for (size_t i = 0; i < near.size(); ++i)
    for (size_t j = i + 1; j < near.size(); ++j) {
      const OffsetCurve& a = *near[i];
      const OffsetCurve& b = *near[j];
      if (!a.circle && !b.circle) {
        const LD det = Cross(a.n, b.n);
        if (std::abs(det) < 1e-30L) continue;
        consider({(a.h * b.n.y - b.h * a.n.y) / det, (a.n.x * b.h - b.n.x * a.h) / det});
      } else if (a.circle != b.circle) {
        const OffsetCurve& line = a.circle ? b : a;
        const OffsetCurve& circ = a.circle ? a : b;
        const LD s = line.h - Dot(line.n, circ.v);  // signed distance of the centre's foot
        if (std::abs(s) > R) continue;
        const LVec foot = circ.v + s * line.n;
        const LD t = std::sqrt(std::max<LD>(0, R * R - s * s));
        const LVec along{-line.n.y, line.n.x};
        consider(foot + t * along);
        consider(foot - t * along);
      } else {
        const LVec between = b.v - a.v;
        const LD D = Norm(between);
        if (D == 0 || D > 2 * R) continue;
        const LD t = std::sqrt(std::max<LD>(0, R * R - D * D / 4));
        const LVec mid = a.v + LD(0.5) * between;
        const LVec across{-between.y / D, between.x / D};
        consider(mid + t * across);
        consider(mid - t * across);
      }
    }
  return best;
}

/// The rings of a shape's core.
inline std::vector<Ring> CoreRings(const Shape& s) {
  std::vector<Ring> rings;
  for (const Polygon& p : s.polygons()) {
    rings.push_back(p.outer);
    for (const Ring& h : p.holes) rings.push_back(h);
  }
  return rings;
}

}  // namespace pushgraph::geometry::testing::rounded
