// Exact fallbacks (CGAL Epick filtered predicates, GMP rationals) and error-free arithmetic.
#include "exact.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>

namespace pushgraph::geometry::exact {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Q = CGAL::Exact_rational;

K::Point_2 P(const Vec2& v) { return {v.x(), v.y()}; }

// Knuth's TwoSum / Dekker's TwoProduct (fma): value + error represent the exact result.
inline void TwoDiff(double a, double b, double* s, double* e) {
  *s = a - b;
  const double bv = a - *s;
  const double av = *s + bv;
  *e = (a - av) + (bv - b);
}
inline void TwoProduct(double a, double b, double* p, double* e) {
  *p = a * b;
#if defined(__FMA__) || defined(__aarch64__)
  *e = std::fma(a, b, -*p);
#else
  // Dekker's product with Veltkamp splitting: exact without a hardware fma (std::fma would be
  // a slow library call here).
  constexpr double kSplit = 134217729.0;  // 2^27 + 1
  const double ta = kSplit * a, ah = ta - (ta - a), al = a - ah;
  const double tb = kSplit * b, bh = tb - (tb - b), bl = b - bh;
  *e = ((ah * bh - *p) + ah * bl + al * bh) + al * bl;
#endif
}

Q ExactCross(const Vec2& a, const Vec2& b, const Vec2& p) {
  return (Q(b.x()) - Q(a.x())) * (Q(p.y()) - Q(a.y())) - (Q(b.y()) - Q(a.y())) * (Q(p.x()) - Q(a.x()));
}

Q ExactSquaredDistance(const Vec2& p, const FeatureDistance& f) {
  if (!f.is_edge) {
    const Q dx = Q(p.x()) - Q(f.a.x()), dy = Q(p.y()) - Q(f.a.y());
    return dx * dx + dy * dy;
  }
  const Q ex = Q(f.b.x()) - Q(f.a.x()), ey = Q(f.b.y()) - Q(f.a.y());
  const Q cross = ExactCross(f.a, f.b, p);
  return cross * cross / (ex * ex + ey * ey);
}

int SignOf(const Q& q) { return CGAL::sign(q) == CGAL::POSITIVE ? 1 : (CGAL::sign(q) == CGAL::NEGATIVE ? -1 : 0); }

}  // namespace

int OrientationSignExact(const Vec2& a, const Vec2& b, const Vec2& p) {
  switch (CGAL::orientation(P(a), P(b), P(p))) {
    case CGAL::LEFT_TURN: return 1;
    case CGAL::RIGHT_TURN: return -1;
    default: return 0;
  }
}

int DotSignExact(const Vec2& p, const Vec2& a, const Vec2& b) {
  // CGAL::angle(p, a, b) is the sign of dot(p - a, b - a).
  switch (CGAL::angle(P(p), P(a), P(b))) {
    case CGAL::ACUTE: return 1;
    case CGAL::OBTUSE: return -1;
    default: return 0;
  }
}

double AccurateCross(const Vec2& a, const Vec2& b, const Vec2& p) {
  double ex, exl, ey, eyl, px, pxl, py, pyl;
  TwoDiff(b.x(), a.x(), &ex, &exl);
  TwoDiff(b.y(), a.y(), &ey, &eyl);
  TwoDiff(p.x(), a.x(), &px, &pxl);
  TwoDiff(p.y(), a.y(), &py, &pyl);
  double p1, e1, p2, e2, s, es;
  TwoProduct(ex, py, &p1, &e1);
  TwoProduct(ey, px, &p2, &e2);
  TwoDiff(p1, p2, &s, &es);
  const double tail = es + e1 - e2 + (ex * pyl + exl * py + exl * pyl) - (ey * pxl + eyl * px + eyl * pxl);
  const double value = s + tail;
  // The tail's own rounding is below ~4 eps^2 (|ex py| + |ey px|): below half an ulp of the
  // value whenever |value| > 8 eps scale. Closer to the edge's line, compute it exactly.
  const double scale = std::abs(p1) + std::abs(p2);
  if (std::abs(value) > 8.0 * kEps * scale) return value;
  return CGAL::to_double(ExactCross(a, b, p));
}

double AccurateSquaredLength(const Vec2& a, const Vec2& b) {
  double ex, exl, ey, eyl;
  TwoDiff(b.x(), a.x(), &ex, &exl);
  TwoDiff(b.y(), a.y(), &ey, &eyl);
  return ex * ex + ey * ey + 2.0 * (ex * exl + ey * eyl);
}

int CompareSquaredDistanceExact(const Vec2& p, const FeatureDistance& f, const FeatureDistance& g) {
  return SignOf(ExactSquaredDistance(p, f) - ExactSquaredDistance(p, g));
}

int CompareSquaredDistanceToRadiusExact(const Vec2& p, const FeatureDistance& f, double r) {
  return SignOf(ExactSquaredDistance(p, f) - Q(r) * Q(r));
}

}  // namespace pushgraph::geometry::exact
