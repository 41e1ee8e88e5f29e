// tau_max, c, area and centroid against the closed forms and reference values of
// ../shared/notes/limit-surface.md (uniform pressure).
#include "limit_surface/oracles.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pushgraph::limit_surface {
namespace {

using geometry::Polygon;
using geometry::Ring;
using geometry::Shape;
using testing::UniformSupport;

// integral of |r| dA about the centre of pressure = tau_max / (mu p) with mu = 1, p = N / A.
double IntegralOfDistance(const Shape& shape) {
  const Support s = UniformSupport(shape);
  return MaxFrictionTorque(s) * s.area / s.normal_force;
}

double RectangleIntegral(double W, double H) {
  const double D = std::hypot(W, H);
  return W * H * D / 6.0 + (W * W * W * std::asinh(H / W) + H * H * H * std::asinh(W / H)) / 12.0;
}

double NgonIntegral(int n, double apothem) {
  const double alpha = M_PI / n;
  return n * std::pow(apothem, 3) / 3.0 * (std::tan(alpha) / std::cos(alpha) + std::asinh(std::tan(alpha)));
}

Ring EllipseRing(double a, double b, int n) {
  Ring ring;
  for (int i = 0; i < n; ++i) ring.emplace_back(a * std::cos(2 * M_PI * i / n), b * std::sin(2 * M_PI * i / n));
  return ring;
}

// Inscribed n-gons converge like 1/n^2 with an even expansion in 1/n: Richardson removes the
// first two terms, leaving O(1/n^6).
template <class F>
double Extrapolate(F&& value_for_n, int n) {
  const double a = value_for_n(n), b = value_for_n(2 * n), c = value_for_n(4 * n);
  const double ab = (4 * b - a) / 3, bc = (4 * c - b) / 3;
  return (16 * bc - ab) / 15;
}

TEST(LimitSurfaceIntegrals, DiskIsExact) {
  const Support s = UniformSupport(Shape::Disk(1.0, {0.3, -0.2}));
  EXPECT_EQ(s.model, SupportModel::kDisk);
  EXPECT_NEAR(IntegralOfDistance(Shape::Disk(1.0)), 2.0943951023931953, 1e-15);
  EXPECT_NEAR(s.centroid.x(), 0.3, 1e-16);
  const Summary summary = Summarize(UniformSupport(Shape::Disk(0.0525), 0.8937, 0.35, kStandardGravity));
  EXPECT_NEAR(summary.c, 0.035, 1e-15);
  EXPECT_NEAR(summary.f_max, 0.35 * 0.8937 * kStandardGravity, 1e-15);
}

TEST(LimitSurfaceIntegrals, PolygonsConvergeToTheDisk) {
  const double value = Extrapolate(
      [](int n) {
        Ring ring = EllipseRing(1.0, 1.0, n);
        return IntegralOfDistance(Shape::FromPolygons({{ring, {}}}));
      },
      256);
  EXPECT_NEAR(value, 2.0 * M_PI / 3.0, 1e-12);
}

TEST(LimitSurfaceIntegrals, Rectangles) {
  for (auto [W, H] : {std::pair{1.0, 1.0}, {0.1, 0.05}, {5.0, 1.0}, {1e-3, 2e-3}, {0.13501, 0.08994}}) {
    const double expected = RectangleIntegral(W, H);
    EXPECT_NEAR(IntegralOfDistance(Shape::Box(W, H)) / expected, 1.0, 1e-14) << W << " x " << H;
  }
}

TEST(LimitSurfaceIntegrals, ReferenceValues) {
  EXPECT_NEAR(IntegralOfDistance(Shape::Box(0.09, 0.09)) / 2.7891383865120549e-4, 1.0, 1e-13);
  EXPECT_NEAR(IntegralOfDistance(Shape::Box(0.1, 0.05)) / 1.4830835401723750e-4, 1.0, 1e-13);
  EXPECT_NEAR(Summarize(UniformSupport(Shape::Box(0.09, 0.09), 0.8, 0.3, 9.81)).c, 0.034433807240890, 1e-14);
  EXPECT_NEAR(Summarize(UniformSupport(Shape::Box(0.1, 0.05), 2.0, 0.5)).c, 0.029661670803447, 1e-14);
}

TEST(LimitSurfaceIntegrals, RegularPolygons) {
  for (int n : {3, 4, 5, 6, 7, 12, 64, 1000}) {
    const double circumradius = 0.7;
    const double expected = NgonIntegral(n, circumradius * std::cos(M_PI / n));
    EXPECT_NEAR(IntegralOfDistance(Shape::RegularPolygon(n, circumradius)) / expected, 1.0, 1e-13) << n;
  }
}

TEST(LimitSurfaceIntegrals, PolygonAnnulusWithHoleIsExact) {
  // A regular 8-gon with a concentric regular 8-gon hole: the difference of the n-gon formula.
  Ring outer, hole;
  for (int i = 0; i < 8; ++i) {
    const double angle = 2 * M_PI * i / 8;
    outer.emplace_back(2.0 * std::cos(angle), 2.0 * std::sin(angle));
    hole.emplace_back(0.5 * std::cos(angle), 0.5 * std::sin(angle));
  }
  const double expected = NgonIntegral(8, 2.0 * std::cos(M_PI / 8)) - NgonIntegral(8, 0.5 * std::cos(M_PI / 8));
  const Shape shape = Shape::FromPolygons({{outer, {hole}}});
  EXPECT_NEAR(IntegralOfDistance(shape) / expected, 1.0, 1e-14);
}

TEST(LimitSurfaceIntegrals, CircularAnnulus) {
  const double value = Extrapolate(
      [](int n) {
        return IntegralOfDistance(Shape::FromPolygons({{EllipseRing(1.0, 1.0, n), {EllipseRing(0.4, 0.4, n)}}}));
      },
      256);
  EXPECT_NEAR(value, 2.0 * M_PI * (1.0 - 0.4 * 0.4 * 0.4) / 3.0, 1e-12);
}

TEST(LimitSurfaceIntegrals, Ellipse) {
  const double a = 0.065445, b = 0.0525;
  const double e = std::sqrt(1.0 - b * b / (a * a));
  const double expected = 4.0 / 3.0 * a * a * b * std::comp_ellint_2(e);
  const double value = Extrapolate(
      [&](int n) { return IntegralOfDistance(Shape::FromPolygons({{EllipseRing(a, b, n), {}}})); }, 256);
  EXPECT_NEAR(value / expected, 1.0, 1e-11);
  // MIT ellip2: c = integral / area.
  EXPECT_NEAR(expected / (M_PI * a * b), 0.039433, 5e-7);
}

TEST(LimitSurfaceIntegrals, TriangleAboutAVertex) {
  // integral of |r| dA over (0,0),(1,0),(1,2) about the origin: the load of a rotation about the
  // origin, moved to the origin, is mu p G(origin).
  const Shape triangle = Shape::FromPolygons({{Ring{{0, 0}, {1, 0}, {1, 2}}, {}}});
  const Support s = UniformSupport(triangle);
  const Vec2 origin = Vec2::Zero() - s.centre_of_pressure;  // relative to the centre of pressure
  const Twist twist{origin.y(), -origin.x(), 1.0};          // q = (-vy, vx)/omega = origin
  const Load about_origin = MoveLoad(SustainingLoad(s, twist), s.centre_of_pressure, Vec2::Zero());
  EXPECT_NEAR(about_origin.torque * s.area / s.normal_force, 0.98596190502973, 1e-13);
  EXPECT_NEAR(s.area, 1.0, 1e-15);
  EXPECT_NEAR(s.centroid.x(), 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(s.centroid.y(), 2.0 / 3.0, 1e-15);
}

TEST(LimitSurfaceIntegrals, MitObjects) {
  auto rect_c = [](double W, double H) { return Summarize(UniformSupport(Shape::Box(W, H))).c; };
  EXPECT_NEAR(rect_c(0.090, 0.090), 0.034434, 5e-7);
  EXPECT_NEAR(rect_c(0.08991, 0.11258), 0.038884, 5e-7);
  EXPECT_NEAR(rect_c(0.13501, 0.08994), 0.043557, 5e-7);
  auto tri_c = [](double a, double b) {
    return Summarize(UniformSupport(Shape::FromPolygons({{Ring{{0, 0}, {a, 0}, {0, b}}, {}}}))).c;
  };
  EXPECT_NEAR(tri_c(0.12587, 0.1259), 0.037947, 5e-7);
  EXPECT_NEAR(tri_c(0.12587, 0.151), 0.041833, 5e-7);
  // tri3: the note's c = 0.045922 belongs to legs 0.12587 x 0.176286, not the 0.1765 of the
  // dataset table (which tri3.obj confirms: y extent 0.17655); 0.1765 gives c = 0.045957.
  EXPECT_NEAR(tri_c(0.12587, 0.176286), 0.045922, 5e-7);
  EXPECT_NEAR(tri_c(0.12587, 0.1765), 0.045957, 5e-7);
  EXPECT_NEAR(Summarize(UniformSupport(Shape::Disk(0.0525))).c, 0.035000, 5e-7);
}

TEST(LimitSurfaceIntegrals, NonConvexMultiPartShapesMatchRectangleOracle) {
  // Two rectangles, one with a rectangular hole: tau_max about the common centroid from the
  // corner-decomposition oracle.
  const std::vector<testing::Rect> outers{{0, 0, 2, 1}, {3, -1, 4, 2}};
  const std::vector<testing::Rect> holes{{0.5, 0.25, 1.5, 0.75}};
  const Shape shape = testing::RectsToShape(outers, holes);
  const Support s = UniformSupport(shape, 2.0, 0.5);
  std::vector<testing::Rect> all = outers;
  all.push_back({0.5, 0.25, 1.5, 0.75, -1.0});
  const double area = 2.0 + 3.0 - 0.5;
  const Vec2 centroid = (Vec2(1, 0.5) * 2.0 + Vec2(3.5, 0.5) * 3.0 - Vec2(1, 0.5) * 0.5) / area;
  EXPECT_NEAR(s.area, area, 1e-14);
  EXPECT_NEAR((s.centroid - centroid).norm(), 0.0, 1e-14);
  const testing::QuadSums sums = testing::RectSums(all, centroid.x(), centroid.y());
  const double expected = 0.5 * 2.0 / area * static_cast<double>(sums.G);
  EXPECT_NEAR(MaxFrictionTorque(s) / expected, 1.0, 1e-14);
}

}  // namespace
}  // namespace pushgraph::limit_surface
