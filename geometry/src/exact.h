#pragma once
// Exact and error-free primitives for the point queries.
//
// Signs of orientation and dot-product determinants use a static floating-point filter
// (error bound in the style of Shewchuk, "Adaptive precision floating-point arithmetic and fast
// robust geometric predicates", 1997) and fall back to CGAL Epick's filtered exact predicates.
// Cross products that feed distances are computed in double-double arithmetic (Dekker's
// TwoProduct via fma, Knuth's TwoSum), so a point 1e-12 from an edge still gets its distance to
// full double precision.
#include <pushgraph/geometry/types.h>

#include <cmath>

namespace pushgraph::geometry::exact {

constexpr double kEps = 1.1102230246251565e-16;  // 2^-53

int OrientationSignExact(const Vec2& a, const Vec2& b, const Vec2& p);
int DotSignExact(const Vec2& p, const Vec2& a, const Vec2& b);

/// Sign of cross(b - a, p - a): +1 if p is left of a->b, -1 right, 0 collinear. Exact.
inline int OrientationSign(const Vec2& a, const Vec2& b, const Vec2& p) {
  const double l = (b.x() - a.x()) * (p.y() - a.y());
  const double r = (b.y() - a.y()) * (p.x() - a.x());
  const double det = l - r;
  const double bound = 3.3306690738754716e-16 * (std::abs(l) + std::abs(r));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return OrientationSignExact(a, b, p);
}

/// Sign of dot(p - a, b - a). Exact.
inline int DotSign(const Vec2& p, const Vec2& a, const Vec2& b) {
  const double l = (p.x() - a.x()) * (b.x() - a.x());
  const double r = (p.y() - a.y()) * (b.y() - a.y());
  const double dot = l + r;
  const double bound = 3.3306690738754716e-16 * (std::abs(l) + std::abs(r));
  if (dot > bound) return 1;
  if (-dot > bound) return -1;
  return DotSignExact(p, a, b);
}

/// Bounds lo <= |p - segment a-b| <= hi from the clamped projection in plain doubles: the
/// rounding of every branch is below 8 eps (|p - a| + |b - a|) in the 1-norm. Near the switch
/// between the edge's interior and an end the formulas agree to far below the bound, so the
/// bounds hold even where the double classification could be wrong.
inline void SegmentDistanceBounds(const Vec2& p, const Vec2& a, const Vec2& b, double* lo, double* hi) {
  const double ex = b.x() - a.x(), ey = b.y() - a.y(), wx = p.x() - a.x(), wy = p.y() - a.y();
  const double t = ex * wx + ey * wy;
  const double len2 = ex * ex + ey * ey;
  double d2;
  if (t <= 0.0) {
    d2 = wx * wx + wy * wy;
  } else if (t >= len2) {
    const double vx = p.x() - b.x(), vy = p.y() - b.y();
    d2 = vx * vx + vy * vy;
  } else {
    const double c = ex * wy - ey * wx;
    d2 = c * c / len2;
  }
  const double err = 8.0 * kEps * (std::abs(wx) + std::abs(wy) + std::abs(ex) + std::abs(ey));
  const double d = std::sqrt(d2);
  *lo = d > err ? d - err : 0.0;
  *hi = d + err;
}

/// cross(b - a, p - a) to about 2^-100 relative to |b - a| |p - a|; exact-rational fallback when
/// even that is not enough to give full double precision.
double AccurateCross(const Vec2& a, const Vec2& b, const Vec2& p);

/// dot(p - a, b - a) in double-double arithmetic, rounded once (about 1 ulp unless the
/// terms cancel to below 1e-16 of their size).
double AccurateDot(const Vec2& a, const Vec2& b, const Vec2& p);

/// |b - a|^2 with the differences taken error-free (about 1 ulp).
double AccurateSquaredLength(const Vec2& a, const Vec2& b);

/// A candidate closest feature of the core boundary: a vertex (b unused) or an edge interior.
struct FeatureDistance {
  bool is_edge = false;
  Vec2 a{0, 0}, b{0, 0};
};

/// The squared distance from p to a feature in double-double arithmetic: the value is hi + lo
/// and its error is at most err (about 1e-30 relative away from the feature's line). Decides
/// comparisons of near-tied features (medial axes, centres of regular polygons) without rationals.
struct SquaredDistanceDD {
  double hi = 0.0, lo = 0.0, err = 0.0;
};
SquaredDistanceDD AccurateSquaredDistance(const Vec2& p, const FeatureDistance& f);

/// Compares two features' squared distances from p: -1, 0, +1, the double-double filter first and
/// exact rationals only where it cannot decide (true ties and the nearly collinear).
int CompareSquaredDistance(const Vec2& p, const FeatureDistance& f, const FeatureDistance& g);

/// Exact comparison of the squared distances from p to two features: -1, 0, +1.
int CompareSquaredDistanceExact(const Vec2& p, const FeatureDistance& f, const FeatureDistance& g);

/// Exact comparison of the squared distance from p to a feature with r^2: -1, 0, +1.
int CompareSquaredDistanceToRadiusExact(const Vec2& p, const FeatureDistance& f, double r);

}  // namespace pushgraph::geometry::exact
