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
inline void TwoSum(double a, double b, double* s, double* e) {
  *s = a + b;
  const double bv = *s - a;
  const double av = *s - bv;
  *e = (a - av) + (b - bv);
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

namespace {

// cross(b - a, p - a) (or, with `dot`, dot(p - a, b - a)) as the double-double s + tail, the
// differences taken error-free (TwoDiff) and the products by TwoProduct; `scale` = |first
// product| + |second product|. The tail's own rounding is below ~4 eps^2 scale.
struct Expansion {
  double s, tail, scale;
};
Expansion CrossOrDot(const Vec2& a, const Vec2& b, const Vec2& p, bool dot) {
  double ex, exl, ey, eyl, px, pxl, py, pyl;
  TwoDiff(b.x(), a.x(), &ex, &exl);
  TwoDiff(b.y(), a.y(), &ey, &eyl);
  TwoDiff(p.x(), a.x(), &px, &pxl);
  TwoDiff(p.y(), a.y(), &py, &pyl);
  // cross = ex py - ey px; dot = ex px + ey py: the same expansion with (px, py) -> (py, -px).
  if (dot) {
    const double qx = py, qxl = pyl;
    py = px, pyl = pxl;
    px = -qx, pxl = -qxl;
  }
  double p1, e1, p2, e2, s, es;
  TwoProduct(ex, py, &p1, &e1);
  TwoProduct(ey, px, &p2, &e2);
  TwoDiff(p1, p2, &s, &es);
  const double tail = es + e1 - e2 + (ex * pyl + exl * py + exl * pyl) - (ey * pxl + eyl * px + eyl * pxl);
  return {s, tail, std::abs(p1) + std::abs(p2)};
}

}  // namespace

double AccurateCross(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Expansion c = CrossOrDot(a, b, p, false);
  const double value = c.s + c.tail;
  // Below half an ulp of the value whenever |value| > 8 eps scale. Closer to the edge's line,
  // compute it exactly.
  if (std::abs(value) > 8.0 * kEps * c.scale) return value;
  return CGAL::to_double(ExactCross(a, b, p));
}

double AccurateDot(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Expansion d = CrossOrDot(a, b, p, true);
  return d.s + d.tail;
}

double AccurateSquaredLength(const Vec2& a, const Vec2& b) {
  double ex, exl, ey, eyl;
  TwoDiff(b.x(), a.x(), &ex, &exl);
  TwoDiff(b.y(), a.y(), &ey, &eyl);
  return ex * ex + ey * ey + 2.0 * (ex * exl + ey * eyl);
}

namespace {

// x^2 + y^2 for x = xh + xl, y = yh + yl (exact differences) as a double-double with its error.
SquaredDistanceDD SumOfSquares(double xh, double xl, double yh, double yl) {
  double sx, ex, sy, ey, s, es;
  TwoProduct(xh, xh, &sx, &ex);
  TwoProduct(yh, yh, &sy, &ey);
  TwoSum(sx, sy, &s, &es);
  SquaredDistanceDD r;
  r.hi = s;
  r.lo = es + ex + ey + 2.0 * (xh * xl + yh * yl) + (xl * xl + yl * yl);
  // Every term of lo is below 3 eps s; their rounding is below a few eps^2 s.
  r.err = 32.0 * kEps * kEps * s;
  return r;
}

}  // namespace

SquaredDistanceDD AccurateSquaredDistance(const Vec2& p, const FeatureDistance& f) {
  if (!f.is_edge) {
    double xh, xl, yh, yl;
    TwoDiff(p.x(), f.a.x(), &xh, &xl);
    TwoDiff(p.y(), f.a.y(), &yh, &yl);
    return SumOfSquares(xh, xl, yh, yl);
  }
  // cross(b - a, p - a)^2 / |b - a|^2, the cross product as a double-double C = ch + cl with
  // |C - exact| <= errc.
  const Vec2 &a = f.a, &b = f.b;
  const Expansion cross = CrossOrDot(a, b, p, false);
  double ch, cl;
  TwoSum(cross.s, cross.tail, &ch, &cl);
  const double errc = 8.0 * kEps * kEps * cross.scale;
  double ex, exl, ey, eyl;
  TwoDiff(b.x(), a.x(), &ex, &exl);
  TwoDiff(b.y(), a.y(), &ey, &eyl);
  const SquaredDistanceDD len2 = SumOfSquares(ex, exl, ey, eyl);
  // C^2 as q + qe, then the quotient by the length: hi = q / L, lo = remainder / L.
  double q, qe;
  TwoProduct(ch, ch, &q, &qe);
  qe += 2.0 * ch * cl + cl * cl;
  const double L = len2.hi;
  SquaredDistanceDD r;
  r.hi = q / L;
  double m, me;
  TwoProduct(r.hi, L, &m, &me);  // r.hi L exactly; q - m is exact (Sterbenz)
  r.lo = ((q - m) - me + qe - r.hi * len2.lo) / L;
  const double c = std::abs(ch) + std::abs(cl);
  r.err = (2.0 * c * errc + errc * errc) / L + r.hi * (len2.err + 4.0 * kEps * kEps * L) / L + 32.0 * kEps * kEps * r.hi;
  return r;
}

int CompareSquaredDistance(const Vec2& p, const FeatureDistance& f, const FeatureDistance& g) {
  const SquaredDistanceDD x = AccurateSquaredDistance(p, f), y = AccurateSquaredDistance(p, g);
  const double diff = (x.hi - y.hi) + (x.lo - y.lo);
  const double bound = (x.err + y.err) * (1.0 + 1e-6) + 4.0 * kEps * (std::abs(x.lo) + std::abs(y.lo) + std::abs(diff)) +
                       4.0 * kEps * kEps * (x.hi + y.hi);
  if (diff > bound) return 1;
  if (-diff > bound) return -1;
  return CompareSquaredDistanceExact(p, f, g);
}

int CompareSquaredDistanceExact(const Vec2& p, const FeatureDistance& f, const FeatureDistance& g) {
  return SignOf(ExactSquaredDistance(p, f) - ExactSquaredDistance(p, g));
}

int CompareSquaredDistanceToRadiusExact(const Vec2& p, const FeatureDistance& f, double r) {
  return SignOf(ExactSquaredDistance(p, f) - Q(r) * Q(r));
}

}  // namespace pushgraph::geometry::exact
