// The full limit surface: exact disk, rectangle unions with holes against the quad-precision
// corner oracle for rotation centres from 0 to 1e6 sizes, symmetry and convexity.
#include "limit_surface/oracles.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace pushgraph::limit_surface {
namespace {

using geometry::Ring;
using geometry::Shape;
using testing::LoadError;
using testing::UniformSupport;

// The note's disk formulas (mu = N = 1), evaluated directly for the test.
Load NoteDiskLoad(double R, double d) {
  double f, tau;
  if (d <= R) {
    const double k = d / R, E = std::comp_ellint_2(k), K = std::comp_ellint_1(k);
    f = 4 * ((1 + k * k) * E - (1 - k * k) * K) / (3 * M_PI * k);
    tau = 4 * R / (9 * M_PI) * ((4 - 2 * k * k) * E - (1 - k * k) * K);
  } else {
    const double k = R / d, E = std::comp_ellint_2(k), K = std::comp_ellint_1(k);
    f = 4 * ((1 + k * k) * E - (1 - k * k) * K) / (3 * M_PI * k * k);
    tau = 4 * R / (9 * M_PI * k * k * k) * ((4 * k * k - 2) * E - (1 - k * k) * (3 * k * k - 2) * K);
  }
  return {Vec2(f, 0.0), tau};  // |force| in x
}

// Twist of the centre of pressure whose rotation centre is q (relative to it), omega > 0.
Twist RotationAbout(const Vec2& q, double omega = 1.0) { return {q.y() * omega, -q.x() * omega, omega}; }

TEST(LimitSurfaceRanges, AbsurdMassesAndFrictionsAreRefused) {
  SupportSpec spec;
  spec.region = Shape::Box(0.1, 0.1);
  spec.mass = 1e308;
  spec.mu = 0.3;
  EXPECT_THROW(MakeSupport(spec), LimitSurfaceError);
  spec.mass = 1.0;
  spec.mu = 1e5;
  try {
    MakeSupport(spec);
    ADD_FAILURE() << "accepted";
  } catch (const LimitSurfaceError& e) {
    EXPECT_NE(std::string(e.what()).find("above the supported 10"), std::string::npos) << e.what();
  }
  spec.mu = 10.0;  // the bound itself is fine
  EXPECT_GT(Summarize(MakeSupport(spec)).f_max, 0.0);
  // Each within its range, together underflowing: f_max was 0 and c NaN, without a word.
  spec.mass = 1e-300;
  spec.mu = 1e-300;
  try {
    MakeSupport(spec);
    ADD_FAILURE() << "accepted";
  } catch (const LimitSurfaceError& e) {
    EXPECT_NE(std::string(e.what()).find("friction load mu m g = 0 N"), std::string::npos) << e.what();
  }
  spec.mass = 1e-50;  // small but representable: kept
  spec.mu = 1e-40;
  EXPECT_GT(Summarize(MakeSupport(spec)).f_max, 0.0);
}

TEST(LimitSurfaceDisk, SpecialValues) {
  const double R = 0.7;
  const Support s = UniformSupport(Shape::Disk(R));  // mu = N = 1
  const Load rotation = SustainingLoad(s, {0, 0, 1});
  EXPECT_NEAR(rotation.force.norm(), 0.0, 1e-16);
  EXPECT_NEAR(rotation.torque, 2 * R / 3, 1e-15);
  const Load rim = SustainingLoad(s, RotationAbout({0.0, R}));  // q on the rim
  EXPECT_NEAR(rim.force.norm(), 8 / (3 * M_PI), 1e-15);
  EXPECT_NEAR(rim.torque, 8 * R / (9 * M_PI), 1e-15);
  // Rotation about (0, R) counter-clockwise moves the centre along +x: force along +x.
  EXPECT_GT(rim.force.x(), 0.0);
  const Load translation = SustainingLoad(s, {0.0, -2.0, 0.0});
  EXPECT_NEAR((translation.force - Vec2(0, -1)).norm(), 0.0, 1e-16);
  EXPECT_EQ(translation.torque, 0.0);
}

TEST(LimitSurfaceDisk, MatchesNoteClosedFormsAndFarField) {
  const double R = 1.3;
  const Support s = UniformSupport(Shape::Disk(R));
  // (The rim, where the test's own K(1) is infinite, is checked in SpecialValues.)
  for (double ratio : {1e-6, 0.01, 0.3, 0.99, 1.01, 1.5, 1.999, 2.001, 3.0, 4.0, 6.0, 10.0}) {
    const double d = ratio * R;
    const Load expected = NoteDiskLoad(R, d);
    const Load load = SustainingLoad(s, RotationAbout({0.0, d}));
    // Cancellation in the test's own formula grows like (R/d)^2 inside and (d/R)^4 outside.
    const double tolerance = 2e-15 * std::max({1.0, std::pow(ratio, 4), 1.0 / (ratio * ratio)});
    EXPECT_NEAR(load.force.x(), expected.force.x(), tolerance) << ratio;
    EXPECT_NEAR(load.force.y(), 0.0, 1e-15) << ratio;
    EXPECT_NEAR(load.torque / R, expected.torque / R, tolerance) << ratio;
  }
}

TEST(LimitSurfaceDisk, FarFieldTendsToItsLeadingOrder) {
  // tau -> mu s integral of x_e^2 P dA = mu s N R^2 / 4, f -> mu N v/|v|: relative error O(R/d).
  const double R = 0.0525;
  const Support s = UniformSupport(Shape::Disk(R, {0.2, -0.1}), 0.9, 0.35, kStandardGravity);
  const double muN = s.mu * s.normal_force;
  for (double ratio : {1e2, 1e3, 1e4, 1e6}) {
    const double d = ratio * R;
    const Load load = SustainingLoad(s, RotationAbout({d * 0.6, -d * 0.8}));  // v = (-0.8, -0.6) d
    EXPECT_NEAR(load.torque / (muN * R * R / (4 * d)), 1.0, 1.0 / ratio) << ratio;
    EXPECT_NEAR((load.force - muN * Vec2(-0.8, -0.6)).norm() / muN, 0.0, 1.0 / ratio) << ratio;
  }
}

TEST(LimitSurfaceDisk, PolygonsConvergeToTheExactDisk) {
  // Independent of the elliptic forms: edge sums of inscribed n-gons, Richardson-extrapolated.
  const Support disk = UniformSupport(Shape::Disk(1.0));
  for (double d : {0.0, 0.25, 0.8, 1.5, 2.5}) {
    auto load = [d](int n) -> Eigen::Vector3d {
      Ring ring;
      for (int i = 0; i < n; ++i) ring.emplace_back(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n));
      Support s = UniformSupport(Shape::FromPolygons({{ring, {}}}));
      // Normal force proportional to the n-gon's area keeps the pressure of the unit disk
      // fixed; compare the pressure-normalised integrals.
      const Load l = SustainingLoad(s, RotationAbout({0.0, d}));
      return Eigen::Vector3d(l.force.x(), l.force.y(), l.torque) * (s.area / s.normal_force);
    };
    const Eigen::Vector3d a = load(512), b = load(1024), c = load(2048);
    const Eigen::Vector3d ab = (4 * b - a) / 3, bc = (4 * c - b) / 3, extrapolated = (16 * bc - ab) / 15;
    const Load exact = SustainingLoad(disk, RotationAbout({0.0, d}));
    const Eigen::Vector3d expected = Eigen::Vector3d(exact.force.x(), exact.force.y(), exact.torque) * M_PI;
    EXPECT_NEAR((extrapolated - expected).norm(), 0.0, 1e-11) << d;
  }
}

class RectangleOracle : public ::testing::Test {
 protected:
  // An L-ish union: a rectangle with a hole plus a separate bar.
  const std::vector<testing::Rect> outers{{-0.04, -0.03, 0.05, 0.02}, {0.06, -0.05, 0.08, 0.04}};
  const std::vector<testing::Rect> holes{{-0.02, -0.01, 0.01, 0.01}};
  const Support support = UniformSupport(testing::RectsToShape(outers, holes), 0.8, 0.3, kStandardGravity);

  std::vector<testing::Rect> all() const {
    std::vector<testing::Rect> rects = outers;
    for (testing::Rect h : holes) rects.push_back({h.x0, h.y0, h.x1, h.y1, -1.0});
    return rects;
  }
};

TEST_F(RectangleOracle, RotationCentresFromZeroToAMillionSizes) {
  const double muN = support.mu * support.normal_force, L = support.size;
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> angle(0.0, 2 * M_PI);
  double worst = 0.0;
  for (double ratio : {0.0, 1e-3, 0.1, 0.5, 1.0, 1.5, 1.99, 2.01, 2.5, 3.0, 5.0, 10.0, 1e2, 1e3, 1e4, 1e5, 1e6}) {
    for (int trial = 0; trial < 8; ++trial) {
      const double a = angle(random);
      const Vec2 q = ratio * L * Vec2(std::cos(a), std::sin(a));
      const double omega = trial % 2 == 0 ? 2.5 : -0.7;
      const Twist twist = RotationAbout(q, omega);
      const Load expected = testing::RectLoad(all(), support.normal_force, support.mu, support.centre_of_pressure, twist);
      const Load load = SustainingLoad(support, twist);
      const double error = LoadError(load, expected, muN, L);
      worst = std::max(worst, error);
      EXPECT_LT(error, 1e-13) << "ratio " << ratio << " trial " << trial;
      // The torque vanishes like 1/ratio while its absolute error stays at rounding of the
      // coordinates (the centre of pressure itself is rounded): relative error ~ 1e-16 ratio.
      if (ratio >= 1.0) {
        const double tolerance = ratio < kFarFieldRatio ? 1e-13 : 4e-15 * ratio;  // closed form / far field
        EXPECT_NEAR(load.torque / expected.torque, 1.0, tolerance) << "ratio " << ratio;
      }
    }
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
}

TEST_F(RectangleOracle, FarFieldTorqueTendsToItsLeadingOrder) {
  // tau -> mu s integral of x_e^2 P dA as s = omega/|v| -> 0 (x_e along v): relative error O(s L).
  const Vec2 direction = Vec2(0.6, 0.8);
  for (double ratio : {1e4, 1e5, 1e6, 1e9}) {
    const double s = 1.0 / (ratio * support.size);
    const Load load = SustainingLoad(support, {direction.x(), direction.y(), s});
    double second_moment = 0.0;  // integral of ((r - c) . direction)^2 dA, rectangles exactly
    for (const testing::Rect& r : all()) {
      // integral over the rectangle of (x e_x + y e_y)^2, about the centre of pressure
      const double x0 = r.x0 - support.centre_of_pressure.x(), x1 = r.x1 - support.centre_of_pressure.x();
      const double y0 = r.y0 - support.centre_of_pressure.y(), y1 = r.y1 - support.centre_of_pressure.y();
      const double ix = (x1 * x1 * x1 - x0 * x0 * x0) / 3, iy = (y1 * y1 * y1 - y0 * y0 * y0) / 3;
      const double mx = (x1 * x1 - x0 * x0) / 2, my = (y1 * y1 - y0 * y0) / 2;
      second_moment += r.weight * (direction.x() * direction.x() * ix * (y1 - y0) +
                                   direction.y() * direction.y() * iy * (x1 - x0) +
                                   2 * direction.x() * direction.y() * mx * my);
    }
    const double leading = support.mu * s * second_moment * support.normal_force / support.area;
    EXPECT_NEAR(load.torque / leading, 1.0, 3.0 / ratio) << ratio;
    EXPECT_NEAR((load.force - support.mu * support.normal_force * direction).norm() /
                    (support.mu * support.normal_force), 0.0, 3.0 / ratio) << ratio;
  }
}

TEST_F(RectangleOracle, ContinuousAcrossTheFarFieldSwitch) {
  for (double a : {0.1, 1.0, 2.0, 4.0}) {
    const Vec2 unit(std::cos(a), std::sin(a));
    const double d = kFarFieldRatio * support.size;
    const Load inside = SustainingLoad(support, RotationAbout(d * (1 - 1e-14) * unit));
    const Load outside = SustainingLoad(support, RotationAbout(d * (1 + 1e-14) * unit));
    EXPECT_LT(LoadError(inside, outside, support.mu * support.normal_force, support.size), 1e-13);
  }
}

TEST(LimitSurfaceSymmetry, ReversalMirrorAndRotation) {
  const Shape shape = Shape::FromPolygons({{Ring{{0, 0}, {0.1, 0}, {0.1, 0.02}, {0.03, 0.02}, {0.03, 0.08}, {0, 0.08}}, {}}});
  const Support s = UniformSupport(shape, 1.2, 0.4, kStandardGravity);
  const double muN = s.mu * s.normal_force;
  // Rotated copy of the shape by 0.7 rad about the origin.
  const Eigen::Rotation2Dd rotation(0.7);
  Ring rotated;
  for (const Vec2& p : shape.polygons()[0].outer) rotated.push_back(rotation * p);
  const Support r = UniformSupport(Shape::FromPolygons({{rotated, {}}}), 1.2, 0.4, kStandardGravity);
  std::mt19937_64 random(3);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 200; ++i) {
    const Twist t{normal(random), normal(random), normal(random) * 20.0 * std::pow(10.0, normal(random))};
    const Load load = SustainingLoad(s, t);
    const Load reversed = SustainingLoad(s, {-t.vx, -t.vy, -t.omega});
    EXPECT_LT(LoadError(load, Load{-reversed.force, -reversed.torque}, muN, s.size), 1e-15);
    const Load scaled = SustainingLoad(s, {3 * t.vx, 3 * t.vy, 3 * t.omega});
    EXPECT_LT(LoadError(load, scaled, muN, s.size), 1e-14);
    const Vec2 v = rotation * Vec2(t.vx, t.vy);
    const Load turned = SustainingLoad(r, {v.x(), v.y(), t.omega});
    EXPECT_LT(LoadError(Load{rotation * load.force, load.torque}, turned, muN, s.size), 1e-13);
  }
  // Mirror symmetry of a shape symmetric about the x axis.
  const Support box = UniformSupport(Shape::Box(0.2, 0.05), 1.0, 0.5, kStandardGravity);
  for (int i = 0; i < 50; ++i) {
    const Twist t{normal(random), normal(random), 10 * normal(random)};
    const Load load = SustainingLoad(box, t);
    const Load mirrored = SustainingLoad(box, {t.vx, -t.vy, -t.omega});
    EXPECT_LT(LoadError(load, Load{Vec2(mirrored.force.x(), -mirrored.force.y()), -mirrored.torque}, box.mu * box.normal_force, box.size), 1e-14);
  }
}

TEST(LimitSurfaceConvexity, MaximumDissipation) {
  // The load of a twist maximizes the power over the surface (the surface is convex and the
  // twist is its normal): xi1 . L(xi1) >= xi1 . L(xi2) for every pair.
  const Shape notch = Shape::FromPolygons({{Ring{{0, 0}, {3, 0}, {3, 2}, {2, 2}, {1.5, 0.5}, {1, 2}, {0, 2}}, {}},
                                           {Ring{{4, 0}, {5, 0}, {5, 1}}, {}}});
  for (const Shape& shape : {notch, Shape::Disk(0.5), Shape::Box(1.0, 0.1)}) {
    const Support s = UniformSupport(shape);
    std::mt19937_64 random(11);
    std::normal_distribution<double> normal;
    std::vector<Twist> twists;
    for (int i = 0; i < 60; ++i) twists.push_back({normal(random), normal(random), normal(random) / s.size});
    std::vector<Load> loads;
    for (const Twist& t : twists) loads.push_back(SustainingLoad(s, t));
    for (std::size_t i = 0; i < twists.size(); ++i) {
      const Eigen::Vector3d xi(twists[i].vx, twists[i].vy, twists[i].omega);
      auto power = [&](const Load& l) { return xi.dot(Eigen::Vector3d(l.force.x(), l.force.y(), l.torque)); };
      for (std::size_t j = 0; j < twists.size(); ++j) {
        EXPECT_GE(power(loads[i]) - power(loads[j]), -1e-14 * s.normal_force * xi.norm() * s.size) << i << " " << j;
      }
    }
  }
}

TEST(LimitSurfaceLoads, PureTranslationAndMovedReferencePoints) {
  const Shape triangle = Shape::FromPolygons({{Ring{{0, 0}, {0.1, 0}, {0, 0.05}}, {}}});
  const Support s = UniformSupport(triangle, 0.5, 0.3, kStandardGravity);
  const Load load = SustainingLoad(s, {0.0, 0.2, 0.0});
  EXPECT_NEAR((load.force - Vec2(0, 0.3 * 0.5 * kStandardGravity)).norm(), 0.0, 1e-15);
  EXPECT_EQ(load.torque, 0.0);
  // About the origin, the torque is the moment of the force through the centroid.
  const Load moved = MoveLoad(load, s.centre_of_pressure, Vec2::Zero());
  EXPECT_NEAR(moved.torque, s.centroid.x() * load.force.y(), 1e-16);
  // Moving a twist and back is the identity; the velocity at the rotation centre is zero.
  const Twist t{0.1, -0.2, 3.0};
  const Vec2 q(0.2 / 3.0, 0.1 / 3.0);
  const Twist at_q = MoveTwist(t, Vec2::Zero(), q);
  EXPECT_NEAR(std::hypot(at_q.vx, at_q.vy), 0.0, 1e-16);
  double error = -1.0;
  SustainingLoad(s, t, &error);
  EXPECT_EQ(error, 0.0);  // closed forms carry no quadrature error
  // Extreme magnitudes: only the direction matters, nothing overflows.
  const double muN = s.mu * s.normal_force;
  for (const Twist& unit : {Twist{1.0, 1.0, 0.1}, Twist{0.0, 1e-3, 30.0}, Twist{-1.0, 0.5, 1e3}}) {
    const Load expected = SustainingLoad(s, unit);
    for (double scale : {1e-300, 1e300, 1.5e308 / 1e3}) {
      const Load load = SustainingLoad(s, {unit.vx * scale, unit.vy * scale, unit.omega * scale});
      EXPECT_LT(LoadError(load, expected, muN, s.size), 1e-14) << scale;
    }
  }
}

}  // namespace
}  // namespace pushgraph::limit_surface
