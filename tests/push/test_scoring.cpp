// The one scoring rule (push/scoring.h): gap-limited interpolation, wrapped angles, moving rows.
#include <pushgraph/push/scoring.h>

#include <gtest/gtest.h>

#include <cmath>

namespace pushgraph::push {
namespace {

std::vector<PoseSample> Truth() {
  // 1 cm/s along x for 0.1 s, then a 0.4 s hole (occlusion of a recording), then at rest.
  return {{0.00, {0.000, 0.0, 0.0}}, {0.05, {0.0005, 0.0, 0.0}}, {0.10, {0.001, 0.0, 0.0}},
          {0.50, {0.001, 0.0, 0.0}}, {0.55, {0.001, 0.0, 0.0}}};
}

TEST(Scoring, TruthIsInterpolatedOnlyBetweenCloseSamples) {
  Eigen::Vector3d x;
  ASSERT_TRUE(TruthPoseAt(Truth(), 0.075, &x));
  EXPECT_NEAR(x.x(), 0.00075, 1e-15);
  EXPECT_TRUE(TruthPoseAt(Truth(), 0.10, &x));    // a sample itself
  EXPECT_FALSE(TruthPoseAt(Truth(), 0.30, &x));   // inside the 0.4 s hole: not bridged
  EXPECT_FALSE(TruthPoseAt(Truth(), -0.01, &x));  // outside the stream
  EXPECT_FALSE(TruthPoseAt(Truth(), 0.60, &x));
  Vec2 p;
  const std::vector<PointSample> points = {{0.0, {0.0, 0.0}}, {0.1, {0.0, 0.002}}};
  ASSERT_TRUE(TruthPointAt(points, 0.05, &p));
  EXPECT_NEAR(p.y(), 0.001, 1e-15);
  const std::vector<ForceSample> forces = {{0.0, {1.0, 0.0}}, {0.2, {3.0, 0.0}}};
  EXPECT_FALSE(TruthForceAt(forces, 0.1, &p));  // 0.2 s apart: a gap
}

TEST(Scoring, PoseErrorsWrapTheAngle) {
  const Eigen::Vector3d e = PoseError(geometry::Pose2{0.01, 0.0, M_PI - 0.01}, Eigen::Vector3d(0.0, 0.02, -M_PI + 0.01));
  EXPECT_NEAR(e.x(), 0.01, 1e-15);
  EXPECT_NEAR(e.y(), -0.02, 1e-15);
  EXPECT_NEAR(e.z(), -0.02, 1e-12);
}

// A truth wrapped into [-pi, pi] is interpolated along the shorter arc (a hostile-user file: from
// -3.133 to +3.138 linearly, states between scored about 180 degrees off, rotation RMS 16.2
// degrees instead of 1.1), and an object turning through pi slowly is not "moving" fast.
TEST(Scoring, AWrappedTruthIsInterpolatedAlongTheShorterArc) {
  const std::vector<PoseSample> wrapped = {{0.00, {0.0, 0.0, M_PI - 0.01}}, {0.01, {0.0, 0.0, -M_PI + 0.01}}};
  Eigen::Vector3d x;
  ASSERT_TRUE(TruthPoseAt(wrapped, 0.005, &x));
  EXPECT_NEAR(std::abs(geometry::WrapAngle(x.z() - M_PI)), 0.0, 1e-12) << x.z();
  ASSERT_TRUE(TruthPoseAt(wrapped, 0.0025, &x));
  EXPECT_NEAR(PoseError(geometry::Pose2{0.0, 0.0, M_PI - 0.005}, x).z(), 0.0, 1e-12);
  ASSERT_TRUE(TruthPoseAt(wrapped, 0.01, &x));  // a sample itself is returned as stored
  EXPECT_EQ(x.z(), -M_PI + 0.01);
  // Turning at 0.01 rad/s through the wrap (below kMovingAngularSpeed): at rest; read linearly
  // across the wrap it was about 300 rad/s.
  std::vector<PoseSample> slow;
  for (int i = 0; i <= 40; ++i) slow.push_back({0.005 * i, {0.0, 0.0, geometry::WrapAngle(M_PI - 0.001 + 5e-5 * i)}});
  EXPECT_FALSE(ObjectMovingAt(slow, 0.1));
  EXPECT_FALSE(ObjectMovingAt(slow, 0.098));
}

TEST(Scoring, MovingRowsFollowTheTruthsSpeed) {
  EXPECT_TRUE(ObjectMovingAt(Truth(), 0.05));   // 1 cm/s > 2 mm/s
  EXPECT_TRUE(ObjectMovingAt(Truth(), 0.0));    // one-sided at the start
  EXPECT_FALSE(ObjectMovingAt(Truth(), 0.52));  // at rest
  EXPECT_FALSE(ObjectMovingAt(Truth(), 0.30));  // no truth there
  // Turning in place at 0.1 rad/s (> 0.02 rad/s) is moving too.
  const std::vector<PoseSample> turning = {{0.0, {0.0, 0.0, 0.0}}, {0.05, {0.0, 0.0, 0.005}}, {0.1, {0.0, 0.0, 0.01}}};
  EXPECT_TRUE(ObjectMovingAt(turning, 0.05));
}

}  // namespace
}  // namespace pushgraph::push
