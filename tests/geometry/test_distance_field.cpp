// Distance fields: interpolation of exact samples, the reported maximum error against the exact
// query (it must bound the error seen at random points, approximately, and shrink with the
// resolution), the C1 gradient, the conservative continuation outside the grid, and bad options.
#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "geometry/numeric_diff.h"
#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

using testing::Scaled;

DistanceField::Options Opt(double resolution, double margin, int samples = 2) {
  DistanceField::Options o;
  o.resolution = resolution;
  o.margin = margin;
  o.error_samples_per_cell = samples;
  return o;
}

Shape TestShape() {
  std::mt19937_64 rng(801);
  testing::RandomPolygonOptions o;
  o.outer_vertices = 12;
  o.max_holes = 1;
  return Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2(0.1, 0.0), o)});
}

Vec2 RandomInGrid(std::mt19937_64& rng, const Box2& b) {
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
  return {ux(rng), uy(rng)};
}

TEST(DistanceField, GridCoversShapeAndMargin) {
  const Shape s = TestShape();
  const DistanceField f(s, Opt(0.05, 0.1));
  const Box2 b = f.grid_bounds(), sb = s.bounds();
  EXPECT_LE(b.min.x(), sb.min.x() - 0.1 + 1e-12);
  EXPECT_LE(b.min.y(), sb.min.y() - 0.1 + 1e-12);
  EXPECT_GE(b.max.x(), sb.max.x() + 0.1 - 1e-12);
  EXPECT_GE(b.max.y(), sb.max.y() + 0.1 - 1e-12);
  EXPECT_NEAR(b.max.x() - b.min.x(), (f.cols() - 1) * 0.05, 1e-9);
  EXPECT_NEAR(b.max.y() - b.min.y(), (f.rows() - 1) * 0.05, 1e-9);
  // Not wastefully larger than needed (at most one extra cell per axis).
  EXPECT_LE(b.max.x() - b.min.x(), sb.max.x() - sb.min.x() + 0.2 + 0.05 + 1e-9);
}

TEST(DistanceField, InterpolatesTheExactSamples) {
  const Shape s = TestShape();
  const DistanceField f(s, Opt(0.04, 0.08));
  const Box2 b = f.grid_bounds();
  for (int i = 0; i < f.rows(); i += 3)
    for (int j = 0; j < f.cols(); j += 3) {
      const Vec2 node = b.min + 0.04 * Vec2(j, i);
      EXPECT_NEAR(f.Evaluate(node), QueryPoint(s, node).signed_distance, 1e-12) << i << "," << j;
    }
}

TEST(DistanceField, ReportedMaxErrorBoundsErrorAtRandomPoints) {
  const Shape s = TestShape();
  std::mt19937_64 rng(802);
  const std::vector<std::pair<std::string, Shape>> shapes = {
      {"random polygon", s}, {"random polygon r=0.02", s.WithRadius(0.02)}, {"rounded box", Shape::Box(0.8, 0.3, 0.05)}};
  for (const auto& [name, shape] : shapes) {
    SCOPED_TRACE(name);
    const DistanceField f(shape, Opt(0.02, 0.05));
    ASSERT_GT(f.max_error(), 0.0);
    ASSERT_TRUE(std::isfinite(f.max_error()));
    // The location reported is where that error occurs.
    const Vec2 at = f.max_error_location();
    EXPECT_NEAR(std::abs(f.Evaluate(at) - QueryPoint(shape, at).signed_distance), f.max_error(), 1e-12);
    double seen = 0.0;
    Vec2 seen_at(0, 0);
    for (int i = 0; i < Scaled(20000, 2000); ++i) {
      const Vec2 p = RandomInGrid(rng, f.grid_bounds());
      const double e = std::abs(f.Evaluate(p) - QueryPoint(shape, p).signed_distance);
      if (e > seen) seen = e, seen_at = p;
    }
    // The build-time check samples a sub-grid, so random points may exceed it a little; not
    // by a large factor.
    EXPECT_LE(seen, 2.0 * f.max_error()) << "reported " << f.max_error() << " at " << at.transpose() << ", seen " << seen << " at "
                                         << seen_at.transpose();
    EXPECT_GE(seen, 0.1 * f.max_error()) << "reported " << f.max_error() << ", seen " << seen;
    // The error is small relative to the resolution (a distance field is 1-Lipschitz).
    EXPECT_LT(f.max_error(), 0.02);
  }
}

TEST(DistanceField, ErrorDecreasesWithResolution) {
  const Shape s = TestShape();
  double previous = std::numeric_limits<double>::infinity();
  std::vector<double> resolutions = {0.08, 0.04, 0.02};
  if (testing::TestScale() >= 1.0) resolutions.push_back(0.01);  // the slow one (sanitizers: skip)
  for (double h : resolutions) {
    const DistanceField f(s, Opt(h, 0.05));
    EXPECT_LT(f.max_error(), previous) << "resolution " << h;
    previous = f.max_error();
  }
  const DistanceField off(s, Opt(0.05, 0.05, 0));
  EXPECT_TRUE(std::isnan(off.max_error()));  // check disabled: no figure, not 0
}

TEST(DistanceField, GradientMatchesNumericDifferences) {
  const Shape s = TestShape();
  const DistanceField f(s, Opt(0.03, 0.05));
  std::mt19937_64 rng(803);
  testing::JacobianTally tally("DistanceField gradient");
  for (int i = 0; i < Scaled(300, 50); ++i) {
    const Vec2 p = RandomInGrid(rng, f.grid_bounds());
    Vec2 g;
    const double v = f.Evaluate(p, &g);
    EXPECT_EQ(v, f.Evaluate(p));
    testing::NumericDiffOptions o;
    o.h = 1e-7;
    o.rel_tol = 1e-5;
    o.abs_tol = 1e-6;
    EXPECT_TRUE(tally.Record(
        testing::CheckJacobian([&](const Eigen::VectorXd& x) {
          return Eigen::VectorXd::Constant(1, f.Evaluate(Vec2(x[0], x[1])));
        },
                               Eigen::VectorXd(p), Eigen::MatrixXd(g.transpose()), o)));
    // Close to the exact gradient away from the medial axis (loose: interpolated).
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
}

// The outermost half cell keeps the exact gradient: the interpolation reads exact samples beyond
// the grid (it read copies of the last row: 0.5 for 1.0 on a box's last row, (0.33, 0.33) at the
// grid's corners, (0, 0) at a corner with margin 0).
TEST(DistanceField, TheGradientHoldsUpToTheGridsEdge) {
  const Shape box = Shape::Box(0.12, 0.08);
  for (const double margin : {0.01, 0.0}) {
    const DistanceField f(box, Opt(0.002, margin));
    const Box2 b = f.grid_bounds();
    std::mt19937_64 rng(805);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double worst = 0.0;
    Vec2 worst_at = Vec2::Zero();
    for (int k = 0; k < Scaled(400, 100); ++k) {
      // A point in the outermost half cell of a random side, away from the box's corners and
      // (inside the box) from its medial axis.
      const int side = k % 4;
      const double along = u(rng), depth = 0.5 * 0.002 * u(rng);
      Vec2 p;
      if (side == 0) p = Vec2(b.min.x() + 0.03 + 0.06 * along, b.max.y() - depth);
      if (side == 1) p = Vec2(b.min.x() + 0.03 + 0.06 * along, b.min.y() + depth);
      if (side == 2) p = Vec2(b.max.x() - depth, b.min.y() + 0.03 + (b.max.y() - b.min.y() - 0.06) * along);
      if (side == 3) p = Vec2(b.min.x() + depth, b.min.y() + 0.03 + (b.max.y() - b.min.y() - 0.06) * along);
      Vec2 g;
      f.Evaluate(p, &g);
      const double err = (g - QueryPoint(box, p).normal).norm();
      if (err > worst) worst = err, worst_at = p;
    }
    EXPECT_LT(worst, 0.02) << "margin " << margin << " at " << worst_at.transpose();
    if (margin > 0.0) {
      // The grid's corners lie outside the box, where the exact gradient is smooth.
      for (const Vec2& corner : {b.min, b.max, Vec2(b.min.x(), b.max.y()), Vec2(b.max.x(), b.min.y())}) {
        Vec2 g;
        f.Evaluate(corner, &g);
        EXPECT_LT((g - QueryPoint(box, corner).normal).norm(), 0.02) << corner.transpose() << ": " << g.transpose();
      }
    }
  }
}

TEST(DistanceField, ConservativeOutsideTheGrid) {
  const Shape s = TestShape();
  const DistanceField f(s, Opt(0.05, 0.02));
  std::mt19937_64 rng(804);
  for (int i = 0; i < Scaled(2000, 200); ++i) {
    const Vec2 p = testing::RandomPointNear(rng, f.grid_bounds(), 3.0);
    Vec2 g;
    const double v = f.Evaluate(p, &g);
    const double exact = QueryPoint(s, p).signed_distance;
    EXPECT_GE(v, exact - f.max_error() - 1e-12) << p.transpose();
    const Box2 b = f.grid_bounds();
    const Vec2 clamped = p.cwiseMax(b.min).cwiseMin(b.max);
    if (clamped != p) {
      EXPECT_NEAR(v, f.Evaluate(clamped) + (p - clamped).norm(), 1e-12);
      EXPECT_NEAR(g.norm(), 1.0, 1e-12);
      EXPECT_GT(v, 0.0);
    }
  }
}

TEST(DistanceField, MoveAndBadOptions) {
  const Shape s = Shape::Box(1, 1);
  DistanceField f(s, Opt(0.1, 0.1));
  const double v = f.Evaluate(Vec2(0.1, 0.2));
  DistanceField g(std::move(f));
  EXPECT_EQ(g.Evaluate(Vec2(0.1, 0.2)), v);
  DistanceField h(Shape::Disk(0.1), Opt(0.05, 0.0));
  h = std::move(g);
  EXPECT_EQ(h.Evaluate(Vec2(0.1, 0.2)), v);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DistanceField(s, Opt(0.0, 0.1)), GeometryError);
  EXPECT_THROW(DistanceField(s, Opt(-0.1, 0.1)), GeometryError);
  EXPECT_THROW(DistanceField(s, Opt(nan, 0.1)), GeometryError);
  EXPECT_THROW(DistanceField(s, Opt(0.1, -0.1)), GeometryError);
  EXPECT_THROW(DistanceField(s, Opt(0.1, 0.1, -1)), GeometryError);
  // No check, no error figure (a 0 read as an exact field).
  EXPECT_TRUE(std::isnan(DistanceField(s, Opt(0.1, 0.1, 0)).max_error()));
  EXPECT_THROW(DistanceField(s, Opt(1e-9, 0.1)), GeometryError);  // absurdly many samples
  EXPECT_THROW(DistanceField(Shape(), Opt(0.1, 0.1)), GeometryError);
  EXPECT_THROW(h.Evaluate(Vec2(nan, 0)), GeometryError);
  // Beyond the query coordinates' bound, as the exact query (it answered inf from 1e154 on).
  EXPECT_THROW(h.Evaluate(Vec2(1e13, 0)), GeometryError);
  EXPECT_THROW(h.Evaluate(Vec2(0, -1e200)), GeometryError);
  EXPECT_TRUE(std::isfinite(h.Evaluate(Vec2(1e11, 0))));
  // A moved-from field is an error, not a null dereference (it crashed).
  EXPECT_THROW(g.Evaluate(Vec2(0.1, 0.2)), GeometryError);
  EXPECT_THROW(g.max_error(), GeometryError);
  EXPECT_THROW(g.rows(), GeometryError);
}

// A moved-from querier is an error, not a null dereference (it crashed).
TEST(MovedFrom, AShapePairQuerierSaysSo) {
  ShapePairQuerier a(Shape::Box(0.1, 0.1), Shape::Disk(0.01));
  ShapePairQuerier b = std::move(a);
  EXPECT_NEAR(b.Query(Pose2{}, Pose2{0.2, 0, 0}).signed_distance, 0.14, 1e-12);
  EXPECT_THROW(a.Query(Pose2{}, Pose2{0.2, 0, 0}), GeometryError);  // NOLINT(bugprone-use-after-move)
  EXPECT_THROW(a.obstacles_built(), GeometryError);
  EXPECT_THROW(a.object(), GeometryError);
}

}  // namespace
}  // namespace pushgraph::geometry
