// SE(2) pose algebra: values (Jacobians are in test_jacobians.cpp).
#include <pushgraph/geometry/pose.h>

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

using testing::kPi;

Pose2 RandomPose(std::mt19937_64& rng, double angle_range = kPi) {
  std::uniform_real_distribution<double> u(-2.0, 2.0), a(-angle_range, angle_range);
  return {u(rng), u(rng), a(rng)};
}

void ExpectPoseNear(const Pose2& a, const Pose2& b, double tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(WrapAngle(a.theta - b.theta), 0.0, tol) << a.theta << " vs " << b.theta;
}

TEST(Pose2, RotationIsOrthonormalWithAngleTheta) {
  const Pose2 p{1.0, 2.0, 0.3};
  const Eigen::Matrix2d R = p.rotation();
  EXPECT_NEAR(R(0, 0), std::cos(0.3), 1e-15);
  EXPECT_NEAR(R(1, 0), std::sin(0.3), 1e-15);
  EXPECT_NEAR(R(0, 1), -std::sin(0.3), 1e-15);
  EXPECT_NEAR(R(1, 1), std::cos(0.3), 1e-15);
  EXPECT_NEAR((R.transpose() * R - Eigen::Matrix2d::Identity()).norm(), 0.0, 1e-15);
  EXPECT_EQ(p.translation(), Vec2(1.0, 2.0));
  EXPECT_EQ(p.vector(), Eigen::Vector3d(1.0, 2.0, 0.3));
  const Pose2 q = Pose2::FromVector(Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(q.x, 4.0);
  EXPECT_EQ(q.y, 5.0);
  EXPECT_EQ(q.theta, 6.0);
}

// rotation() remembers the last angles' cos and sin (pose.cpp): whatever the order of the calls
// (repeats, two angles alternating, +0 and -0, NaN, a fresh thread), the same bits as cos and sin.
TEST(Pose2, RotationIsExactlyCosAndSinInAnyOrderOfCalls) {
  auto same_bits = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0 || (std::isnan(a) && std::isnan(b)); };
  auto check = [&](double theta) {
    const Eigen::Matrix2d R = Pose2{0.0, 0.0, theta}.rotation();
    EXPECT_TRUE(same_bits(R(0, 0), std::cos(theta))) << theta;
    EXPECT_TRUE(same_bits(R(1, 0), std::sin(theta))) << theta;
    EXPECT_TRUE(same_bits(R(0, 1), -std::sin(theta))) << theta;
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> a(-10.0, 10.0);
  std::vector<double> angles{0.0, -0.0, 0.0, -0.0, std::nan(""), 1e-300, -1e-300, 0.0};
  for (int i = 0; i < 300; ++i) angles.push_back(i % 3 == 0 && !angles.empty() ? angles[angles.size() - 2] : a(rng));
  for (double theta : angles) check(theta);
  std::thread other([&] { for (double theta : angles) check(theta); });
  other.join();
}

TEST(Pose2, WrapAngleRange) {
  EXPECT_EQ(WrapAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(WrapAngle(kPi), kPi);  // (-pi, pi]: pi stays
  EXPECT_DOUBLE_EQ(WrapAngle(-kPi), kPi);
  EXPECT_NEAR(WrapAngle(2 * kPi + 0.25), 0.25, 1e-12);
  EXPECT_NEAR(WrapAngle(-2 * kPi - 0.25), -0.25, 1e-12);
  EXPECT_NEAR(WrapAngle(1e3), std::remainder(1e3, 2 * kPi), 1e-9);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  for (int i = 0; i < 1000; ++i) {
    const double a = u(rng);
    const double w = WrapAngle(a);
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    EXPECT_NEAR(std::sin(w), std::sin(a), 1e-12);
    EXPECT_NEAR(std::cos(w), std::cos(a), 1e-12);
  }
}

TEST(Pose2, ComposeMatchesDefinition) {
  const Pose2 a{1.0, -2.0, 0.5}, b{0.25, 0.75, -1.25};
  const Pose2 c = Compose(a, b);
  const Vec2 t = a.translation() + a.rotation() * b.translation();
  EXPECT_NEAR(c.x, t.x(), 1e-15);
  EXPECT_NEAR(c.y, t.y(), 1e-15);
  EXPECT_DOUBLE_EQ(c.theta, 0.5 - 1.25);  // not wrapped
  // theta is a chart coordinate: Compose does not wrap.
  const Pose2 d = Compose(Pose2{0, 0, 3.0}, Pose2{0, 0, 3.0});
  EXPECT_DOUBLE_EQ(d.theta, 6.0);
}

TEST(Pose2, GroupAxioms) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 200; ++i) {
    const Pose2 a = RandomPose(rng), b = RandomPose(rng), c = RandomPose(rng);
    ExpectPoseNear(Compose(Compose(a, b), c), Compose(a, Compose(b, c)), 1e-12);
    ExpectPoseNear(Compose(a, Inverse(a)), Pose2{}, 1e-12);
    ExpectPoseNear(Compose(Inverse(a), a), Pose2{}, 1e-12);
    ExpectPoseNear(Between(a, b), Compose(Inverse(a), b), 1e-12);
    ExpectPoseNear(Compose(a, Between(a, b)), b, 1e-12);
    ExpectPoseNear(Compose(a, Pose2{}), a, 1e-15);
  }
}

TEST(Pose2, ActAndInverseAct) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 200; ++i) {
    const Pose2 a = RandomPose(rng), b = RandomPose(rng);
    const Vec2 p(u(rng), u(rng));
    const Vec2 q = Act(a, p);
    EXPECT_NEAR((q - (a.rotation() * p + a.translation())).norm(), 0.0, 1e-14);
    EXPECT_NEAR((InverseAct(a, q) - p).norm(), 0.0, 1e-13);
    // Act is a homomorphism: (a*b) p = a (b p).
    EXPECT_NEAR((Act(Compose(a, b), p) - Act(a, Act(b, p))).norm(), 0.0, 1e-13);
    EXPECT_NEAR((InverseAct(a, p) - Act(Inverse(a), p)).norm(), 0.0, 1e-13);
  }
  // A quarter turn about the origin.
  const Vec2 r = Act(Pose2{1.0, 0.0, kPi / 2}, Vec2(1.0, 0.0));
  EXPECT_NEAR(r.x(), 1.0, 1e-15);
  EXPECT_NEAR(r.y(), 1.0, 1e-15);
}

TEST(Pose2, LogExpRoundTrip) {
  std::mt19937_64 rng(13);
  for (int i = 0; i < 500; ++i) {
    Pose2 a = RandomPose(rng);
    if (i % 5 == 0) a.theta = std::ldexp(a.theta, -40);       // near zero
    if (i % 7 == 0) a.theta = (i % 2 ? 1 : -1) * (kPi - 1e-9);  // near pi
    const Eigen::Vector3d v = Log(a);
    EXPECT_NEAR(v.z(), WrapAngle(a.theta), 1e-15);
    ExpectPoseNear(Exp(v), a, 1e-12);
    if (HasFailure()) {
      ADD_FAILURE() << "case " << i << " theta " << a.theta;
      return;
    }
    // Exp then Log on tangents with |phi| < pi.
    const Eigen::Vector3d w(a.x, a.y, WrapAngle(a.theta) * 0.999);
    EXPECT_NEAR((Log(Exp(w)) - w).norm(), 0.0, 1e-11);
  }
}

// Log and Exp to (nearly) full double precision at small and large angles, against a
// long-double evaluation of the cancellation-free forms A = (phi/2) (1 + cos) / sin and
// (1 - cos) / phi = 2 sin^2(phi/2) / phi.
TEST(Pose2, LogExpSmallAngleAccuracy) {
  const Vec2 t(0.690594913551756, 0.757232449965136);
  for (double th : {1e-9, 5e-5, 1.0001e-4, -1.5e-4, 2e-4, 5e-4, 1e-3, -3e-3, 1e-2, 0.3, -2.0, 3.0}) {
    const long double phi = th, s = sinl(phi), c = cosl(phi), sh = sinl(phi / 2);
    const long double A = 0.5L * phi * (1 + c) / s, B = 0.5L * phi;
    const Eigen::Vector3d v = Log(Pose2{t.x(), t.y(), th});
    EXPECT_NEAR(v.x(), static_cast<double>(A * t.x() + B * t.y()), 4e-16) << "Log theta " << th;
    EXPECT_NEAR(v.y(), static_cast<double>(-B * t.x() + A * t.y()), 4e-16) << "Log theta " << th;
    const long double sa = s / phi, cb = 2 * sh * sh / phi;
    const Pose2 e = Exp(Eigen::Vector3d(t.x(), t.y(), th));
    EXPECT_NEAR(e.x, static_cast<double>(sa * t.x() - cb * t.y()), 4e-16) << "Exp theta " << th;
    EXPECT_NEAR(e.y, static_cast<double>(cb * t.x() + sa * t.y()), 4e-16) << "Exp theta " << th;
  }
}

TEST(Pose2, LogMatchesClosedForm) {
  // rho = V(phi)^-1 t with V = [sin/phi, -(1-cos)/phi; (1-cos)/phi, sin/phi].
  const Pose2 a{0.3, -0.7, 1.1};
  const double phi = 1.1;
  Eigen::Matrix2d V;
  V << std::sin(phi) / phi, -(1 - std::cos(phi)) / phi, (1 - std::cos(phi)) / phi,
      std::sin(phi) / phi;
  const Eigen::Vector2d rho = V.inverse() * a.translation();
  const Eigen::Vector3d v = Log(a);
  EXPECT_NEAR(v.x(), rho.x(), 1e-14);
  EXPECT_NEAR(v.y(), rho.y(), 1e-14);
  EXPECT_DOUBLE_EQ(v.z(), phi);
  // Wrapped angle: theta = 2 pi + 1.1 has the same Log.
  const Eigen::Vector3d v2 = Log(Pose2{0.3, -0.7, 1.1 + 2 * kPi});
  EXPECT_NEAR((v2 - v).norm(), 0.0, 1e-12);
}

TEST(Pose2, ExpAtZeroAngleIsTranslation) {
  const Pose2 p = Exp(Eigen::Vector3d(0.5, -0.25, 0.0));
  EXPECT_EQ(p.x, 0.5);
  EXPECT_EQ(p.y, -0.25);
  EXPECT_EQ(p.theta, 0.0);
  // t = V(phi) rho with V = [1 - phi^2/6, -phi/2; phi/2, 1 - phi^2/6] + O(phi^3).
  const double phi = 1e-6;
  const Pose2 q = Exp(Eigen::Vector3d(0.5, -0.25, phi));
  EXPECT_NEAR(q.x, 0.5 * (1 - phi * phi / 6) + 0.25 * phi / 2, 1e-16);
  EXPECT_NEAR(q.y, 0.5 * phi / 2 - 0.25 * (1 - phi * phi / 6), 1e-16);
  EXPECT_TRUE(std::isfinite(q.x) && std::isfinite(q.y));
  const Eigen::Vector3d l = Log(Pose2{0.5, -0.25, 0.0});
  EXPECT_EQ(l, Eigen::Vector3d(0.5, -0.25, 0.0));
}

}  // namespace
}  // namespace pushgraph::geometry
