// Exact penetration depth of rounded fingers (issue 15): disk fingers and rounded polygonal fingers
// against non-convex objects with holes and several parts, where the grown obstacle fills
// notches, slots and holes narrower than the finger.
//
// Oracle: an independent brute force in extended precision (rounded_depth_oracle.h). The library's
// answers are compared in units of the double ulp of the coordinates' scale.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"
#include "geometry/rounded_depth_oracle.h"
#include "minkowski_obstacle.h"  // the obstacle core of a polygonal finger, for the oracle

namespace pushgraph::geometry {
namespace {

using testing::kPi;
using testing::Scaled;
using testing::rounded::CoreRings;
using testing::rounded::LD;
using testing::rounded::OracleDepth;

double Ulp(double scale) { return std::nextafter(scale, 2 * scale) - scale; }

double CoordinateScale(const Shape& s, const Vec2& c, double R) {
  const Box2 b = s.bounds();
  return std::max({b.min.cwiseAbs().maxCoeff(), b.max.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff(), R});
}

ShapePairQuerier::Options Checked() {
  ShapePairQuerier::Options o;
  o.check_rounded_depth = true;  // depth_exact: the finger moved by depth must not overlap
  return o;
}

ShapePairQuerier::Options Bound() {
  ShapePairQuerier::Options o;
  o.exact_rounded_depth = false;
  return o;
}

// Statistics of one comparison run.
struct Tally {
  int queries = 0, deeper_than_bound = 0, corners = 0;
  double worst_ulps = 0.0;
};

// Disk fingers against `object` (K = the object's core, R = both radii): random centres inside
// the grown obstacle, compared with the oracle.
Tally CompareDisk(const Shape& object, double disk_radius, int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const ShapePairQuerier exact(object, Shape::Disk(disk_radius), Checked());
  const ShapePairQuerier bound(object, Shape::Disk(disk_radius), Bound());
  const double R = object.radius() + disk_radius;
  const Shape core = object.WithRadius(0.0);
  const Shape grown = object.WithRadius(R);
  Tally t;
  while (t.queries < n) {
    const Vec2 c = testing::RandomPointNear(rng, grown.bounds(), 0.0);
    if (QueryPoint(grown, c).signed_distance >= 0.0) continue;
    ++t.queries;
    const Pose2 finger{c.x(), c.y(), 0.3};
    const ShapePairResult r = exact.Query(Pose2{}, finger);
    const ShapePairResult b = bound.Query(Pose2{}, finger);
    const LD oracle = OracleDepth(CoreRings(core), R, c);
    const double err = static_cast<double>(std::abs(static_cast<LD>(r.depth) - oracle)) / Ulp(CoordinateScale(object, c, R));
    t.worst_ulps = std::max(t.worst_ulps, err);
    if (oracle > b.depth * (1 + 1e-12) + 1e-12) ++t.deeper_than_bound;
    // Both contacts at distance R from the touching point: the witnesses' normals differ.
    if (std::abs(r.normal.dot(r.finger_point - c)) < (1 - 1e-9) * disk_radius) ++t.corners;
    EXPECT_TRUE(r.intersecting);
    EXPECT_TRUE(r.depth_exact) << "query " << t.queries << " at (" << c.x() << ", " << c.y() << ")";
    EXPECT_LE(err, 8.0) << "query " << t.queries << " at (" << c.x() << ", " << c.y() << ") depth " << r.depth
                        << " oracle " << static_cast<double>(oracle);
    EXPECT_GE(r.depth, b.depth - 1e-15 * CoordinateScale(object, c, R));  // the bound is a lower bound
    // Witness contract: object_point - finger_point = depth * normal; the finger point is on the
    // disk, the object point on the object (rounded by its own radius).
    EXPECT_LT((r.object_point - r.finger_point - r.depth * r.normal).norm(), 1e-12);
    EXPECT_NEAR((r.finger_point - c).norm(), disk_radius, 1e-12);
    EXPECT_NEAR(QueryPoint(object, r.object_point).signed_distance, 0.0, 1e-12);
  }
  return t;
}

TEST(RoundedDepth, DiskInAHoleNarrowerThanTheDisk) {
  Polygon square;
  square.outer = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  square.holes = {{Vec2(0.45, 0.45), Vec2(0.45, 0.55), Vec2(0.55, 0.55), Vec2(0.55, 0.45)}};
  const Shape holed = Shape::FromPolygons({square});
  const ShapePairQuerier q(holed, Shape::Disk(0.2), Checked());
  // Centre 0.15 below the 0.1-wide hole: "core depth + radius" says 0.35 (towards the hole), but
  // the disk does not fit there; it leaves through the bottom edge, 0.5 down.
  const ShapePairResult r = q.Query(Pose2{}, Pose2{0.5, 0.3, 0.0});
  EXPECT_TRUE(r.intersecting);
  EXPECT_EQ(r.depth, 0.5);
  EXPECT_EQ(r.normal, Vec2(0.0, -1.0));
  EXPECT_TRUE(r.depth_exact);
  EXPECT_NEAR(q.Query(Pose2{}, Pose2{0.5, 0.3 - r.depth, 0.0}).signed_distance, 0.0, 1e-15);
  const ShapePairQuerier bound(holed, Shape::Disk(0.2), [] {
    ShapePairQuerier::Options o = Bound();
    o.check_rounded_depth = true;
    return o;
  }());
  const ShapePairResult b = bound.Query(Pose2{}, Pose2{0.5, 0.3, 0.0});
  EXPECT_NEAR(b.depth, 0.35, 1e-15);
  EXPECT_FALSE(b.depth_exact);  // the bound, checked, says so
  // A rounded square finger in the same spot: exact too (out through the bottom: 0.3 + 0.15 + 0.05).
  const ShapePairQuerier rounded(holed, Shape::Box(0.1, 0.1, 0.15), Checked());
  const ShapePairResult rr = rounded.Query(Pose2{}, Pose2{0.5, 0.3, 0.0});
  EXPECT_NEAR(rr.depth, 0.5, 1e-15);
  EXPECT_TRUE(rr.depth_exact);
}

// A disk wedged in a V notch of half-angle a: the free position nearest to a centre on the axis
// is the crossing of the two walls' offsets, R / sin(a) from the apex (closed form).
TEST(RoundedDepth, DiskInAVNotchClosedForm) {
  const double a = 0.3, depth_of_notch = 1.0;
  const double w = depth_of_notch * std::tan(a);
  Polygon block;
  block.outer = {Vec2(-1, -1.5), Vec2(1, -1.5), Vec2(1, 1), Vec2(w, 1), Vec2(0, 1 - depth_of_notch), Vec2(-w, 1), Vec2(-1, 1)};
  const Shape notched = Shape::FromPolygons({block});
  for (double R : {0.05, 0.1, 0.2}) {
    const ShapePairQuerier q(notched, Shape::Disk(R), Checked());
    const Vec2 apex(0.0, 1.0 - depth_of_notch);
    const double free_height = R / std::sin(a);
    for (double s : {0.1, 0.5, 0.9}) {
      const Vec2 c = apex + Vec2(0.0, s * free_height);
      ShapePairJacobians J;
      const ShapePairResult r = q.Query(Pose2{}, Pose2{c.x(), c.y(), 0.0}, &J);
      EXPECT_NEAR(r.depth, (1.0 - s) * free_height, 4e-16) << "R " << R << " s " << s;
      EXPECT_NEAR(r.normal.y(), 1.0, 1e-15);
      EXPECT_TRUE(r.depth_exact);
      // d sd / d finger y = 1 (moving up frees it), d sd / d finger x = 0 at the axis.
      EXPECT_NEAR(J.J_sd_finger_pose(0, 1), 1.0, 1e-12);
      EXPECT_NEAR(J.J_sd_finger_pose(0, 0), 0.0, 1e-12);
      // The finger point touches a wall after the move: the contact normal is the wall's.
      const Vec2 touch = r.object_point;
      EXPECT_NEAR(QueryPoint(notched, touch).signed_distance, 0.0, 1e-14);
      EXPECT_NEAR((r.finger_point - c).norm(), R, 1e-14);
      EXPECT_GT(std::abs(r.finger_point.x() - c.x()), 0.5 * R * std::cos(a));  // on a wall, not below
    }
  }
}

TEST(RoundedDepth, DiskFingersAgainstRandomShapesWithHolesMatchTheOracle) {
  std::mt19937_64 rng(1501);
  Tally all;
  for (int s = 0; s < Scaled(12, 3); ++s) {
    testing::RandomPolygonOptions o;
    o.outer_vertices = 14 + s % 5;
    o.max_holes = 3;
    const bool two_parts = s % 3 == 2;
    const Shape object = Shape::FromPolygons(two_parts ? testing::RandomPolygons(rng, 2, o)
                                                       : std::vector<Polygon>{testing::RandomPolygonWithHoles(rng, Vec2(0.3, -0.1), o)},
                                             s % 4 == 1 ? 0.02 : 0.0);
    const double radius = std::uniform_real_distribution<double>(0.08, 0.45)(rng);
    const Tally t = CompareDisk(object, radius, Scaled(60, 15), 1600 + s);
    all.queries += t.queries;
    all.deeper_than_bound += t.deeper_than_bound;
    all.corners += t.corners;
    all.worst_ulps = std::max(all.worst_ulps, t.worst_ulps);
  }
  std::printf("disk fingers: %d queries, %d deeper than core depth + radius, %d at a corner, worst %.2f ulps\n",
              all.queries, all.deeper_than_bound, all.corners, all.worst_ulps);
  // The set exercises the cases the bound gets wrong, corners included.
  EXPECT_GT(all.deeper_than_bound, all.queries / 10);
  EXPECT_GT(all.corners, all.queries / 20);
}

TEST(RoundedDepth, RoundedPolygonFingersMatchTheOracle) {
  std::mt19937_64 rng(1502);
  const Shape finger = Shape::FromPolygons({Polygon{{{0.0, 0.0}, {0.12, -0.03}, {0.08, 0.03}, {0.13, 0.1}, {-0.01, 0.07}}, {}}}, 0.06);
  int queries = 0, deeper = 0;
  double worst = 0.0;
  for (int s = 0; s < Scaled(6, 2); ++s) {
    testing::RandomPolygonOptions o;
    o.outer_vertices = 12;
    o.max_holes = 2;
    const Shape object = Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2(-0.2, 0.1), o)});
    const ShapePairQuerier exact(object, finger, Checked());
    const ShapePairQuerier bound(object, finger, Bound());
    const double phi = std::uniform_real_distribution<double>(-kPi, kPi)(rng);
    // The oracle's core: the same obstacle core the querier builds at this angle.
    const Shape C = MinkowskiSumOfCores(object, RotatedReflectedCore(finger, WrapAngle(phi)), 0.0);
    const double R = finger.radius();
    const Shape grown = C.WithRadius(R);
    int n = 0;
    while (n < Scaled(40, 10)) {
      const Vec2 c = testing::RandomPointNear(rng, grown.bounds(), 0.0);
      if (QueryPoint(grown, c).signed_distance >= 0.0) continue;
      ++n;
      const ShapePairResult r = exact.Query(Pose2{}, Pose2{c.x(), c.y(), phi});
      const ShapePairResult b = bound.Query(Pose2{}, Pose2{c.x(), c.y(), phi});
      const LD oracle = OracleDepth(CoreRings(C), R, c);
      const double err = static_cast<double>(std::abs(static_cast<LD>(r.depth) - oracle)) / Ulp(CoordinateScale(C, c, R));
      worst = std::max(worst, err);
      if (oracle > b.depth * (1 + 1e-12) + 1e-12) ++deeper;
      EXPECT_TRUE(r.depth_exact) << "shape " << s << " query " << n;
      EXPECT_LE(err, 8.0) << "shape " << s << " query " << n << " depth " << r.depth << " oracle " << static_cast<double>(oracle);
      EXPECT_LT((r.object_point - r.finger_point - r.depth * r.normal).norm(), 1e-12);
      EXPECT_NEAR(QueryPoint(object, r.object_point).signed_distance, 0.0, 1e-12);
      EXPECT_NEAR(QueryPoint(finger, Pose2{c.x(), c.y(), phi}, r.finger_point).signed_distance, 0.0, 1e-12);
    }
    queries += n;
  }
  std::printf("rounded polygon fingers: %d queries, %d deeper than core depth + radius, worst %.2f ulps\n", queries, deeper, worst);
  EXPECT_GT(deeper, queries / 20);
}

// Their Jacobians: test_jacobians.cpp (ShapePairJacobians.*BeyondTheCoreDepthBound), the one harness.

}  // namespace
}  // namespace pushgraph::geometry
