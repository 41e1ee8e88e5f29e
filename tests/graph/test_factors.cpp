// Every factor's analytic Jacobians (factor_check.h: the shared harness over the geometry tests'
// CheckJacobian, with its kink detector) over many seeded random configurations, including contact at a
// vertex, pure translation, pure rotation and near-zero rotation; plus the semantics of D.
#include <pushgraph/graph/factors.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/shape_frame.h>

#include <pushgraph/geometry/point_query.h>

#include "graph/factor_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <memory>
#include <random>
#include <vector>

namespace pushgraph::graph {
namespace {

using geometry::Shape;
using geometry::testing::JacobianTally;
using testing::CheckCost;
using testing::V;
using testing::WorstError;

struct Rng {
  std::mt19937_64 g{12345};
  double U(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
  Pose2 P(double s = 0.3) { return {U(-s, s), U(-s, s), U(-M_PI, M_PI)}; }
};

TEST(FactorJacobians, PoseMeasurement) {
  Rng rng;
  JacobianTally tally("M pose");
  WorstError worst{"M pose (Log of Between)"};
  for (int i = 0; i < 300; ++i) {
    const Pose2 meas = rng.P();
    Pose2 est = i % 3 == 0 ? Pose2{meas.x + rng.U(-0.01, 0.01), meas.y, meas.theta + rng.U(-1e-9, 1e-9)} : rng.P();
    if (i % 7 == 0) est.theta = meas.theta + M_PI - 1e-3;  // near the wrap of Log's angle
    PoseMeasurementFactor f(meas, 0.01, 0.1);
    CheckCost(f, {V(est)}, tally, worst, "case " + std::to_string(i));
  }
  EXPECT_TRUE(tally.MostlyChecked(0.95));
}

TEST(FactorJacobians, VectorMeasurement) {
  Rng rng;
  JacobianTally tally("M vector");
  WorstError worst{"M point/force"};
  for (int i = 0; i < 50; ++i) {
    VectorMeasurementFactor f(Vec2(rng.U(-1, 1), rng.U(-1, 1)), 0.5);
    CheckCost(f, {V({rng.U(-1, 1), rng.U(-1, 1)})}, tally, worst, "case " + std::to_string(i));
  }
  JacobianTally trw("force random walk");
  WorstError wrw{"force random walk"};
  for (int i = 0; i < 50; ++i) {
    VectorRandomWalkFactor f(rng.U(0.001, 0.05), 5.0);
    CheckCost(f, {V({rng.U(-1, 1), rng.U(-1, 1)}), V({rng.U(-1, 1), rng.U(-1, 1)})}, trw, wrw, "rw " + std::to_string(i));
  }
  EXPECT_TRUE(tally.MostlyChecked(1.0));
  EXPECT_TRUE(trw.MostlyChecked(1.0));
}

std::vector<Shape> Objects() {
  return {Shape::Box(0.09, 0.09), Shape::RegularPolygon(3, 0.06), Shape::Box(0.1, 0.05, 0.005),
          Shape::Disk(0.04), Shape::RegularPolygon(6, 0.05)};
}

TEST(FactorJacobians, BoundaryPointNearBoundaryAndVertices) {
  Rng rng;
  JacobianTally tally("C boundary");
  WorstError worst{"C contact on boundary"};
  int n = 0;
  for (const Shape& shape : Objects()) {
    BoundaryPointFactor f(shape, 1e-3);
    for (int i = 0; i < 150; ++i, ++n) {
      const Pose2 pose = rng.P(0.2);
      Vec2 local;
      const auto& ring = shape.polygons()[0].outer;
      if (i % 3 == 0) {
        // Contact at a vertex: a point in the vertex's outer region (the finger on a corner).
        const Vec2 v = ring[i % ring.size()];
        const Vec2 c = Vec2::Zero();
        local = v + (v - c).normalized() * rng.U(1e-4, 5e-3) + shape.radius() * (v - c).normalized();
      } else {
        local = Vec2(rng.U(-0.07, 0.07), rng.U(-0.07, 0.07));
      }
      const Vec2 p = geometry::Act(pose, local);
      CheckCost(f, {V(pose), V(p)}, tally, worst, "shape/case " + std::to_string(n));
    }
  }
  // The finger side: a disk finger.
  BoundaryPointFactor finger(Shape::Disk(0.005), 1e-3);
  for (int i = 0; i < 100; ++i) {
    const Pose2 e = rng.P(0.2);
    const double a = rng.U(-M_PI, M_PI), r = rng.U(0.001, 0.01);
    CheckCost(finger, {V(e), V(Vec2(e.x + r * std::cos(a), e.y + r * std::sin(a)))}, tally, worst, "finger");
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
}

// The local witness of one of two contacts: a disk or a rounded square finger near a random
// object's boundary (touching, slightly in, slightly apart), the contact point near the touch.
TEST(FactorJacobians, LocalWitness) {
  Rng rng;
  JacobianTally tally("C local witness");
  WorstError worst{"C local witness"};
  int n = 0;
  for (const Shape& object : Objects()) {
    for (const Shape& finger : {Shape::Disk(0.005), Shape::Box(0.01, 0.01, 0.002)}) {
      LocalWitnessFactor f(object, finger, 1e-3);
      for (int i = 0; i < 60; ++i, ++n) {
        const Pose2 x = rng.P(0.2);
        // A boundary point of the object, the finger just outside it along the normal.
        const Vec2 probe = geometry::Act(x, Vec2(rng.U(-0.07, 0.07), rng.U(-0.07, 0.07)));
        const geometry::PointQuery q = geometry::QueryPoint(object, x, probe);
        const Vec2 centre = q.closest_point + q.normal * (0.005 + rng.U(-0.002, 0.002));
        const Pose2 e{centre.x(), centre.y(), rng.U(-M_PI, M_PI)};
        const Vec2 p = q.closest_point + Vec2(rng.U(-0.002, 0.002), rng.U(-0.002, 0.002));
        CheckCost(f, {V(x), V(e), V(p)}, tally, worst, "case " + std::to_string(n));
      }
    }
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
}

// The witness on a given edge or vertex of the object (inside the edge, past its ends, at a
// vertex), unrounded and rounded objects; on the nearest feature it equals the local witness.
TEST(FactorJacobians, FeatureWitness) {
  Rng rng;
  JacobianTally tally("C feature witness");
  WorstError worst{"C feature witness"};
  int n = 0;
  for (const Shape& base : Objects()) {
    for (const double radius : {0.0, 0.003}) {
      if (radius == 0.0 && base.is_degenerate_core()) continue;  // a point or segment needs its radius
      const Shape object = base.WithRadius(radius);
      const auto& ring = object.polygons()[0].outer;
      for (int i = 0; i < 40; ++i, ++n) {
        const int k = i % static_cast<int>(ring.size());
        const bool vertex = i % 4 == 0 || ring.size() == 1;
        FeatureWitnessFactor f(object, geometry::EdgeId{0, -1, k}, vertex, Shape::Disk(0.005), 1e-3);
        const Pose2 x = rng.P(0.2);
        const Vec2 a = ring[k], b = ring[(k + 1) % ring.size()];
        const Vec2 along = a + rng.U(-0.3, 1.3) * (b - a);
        const Vec2 out(b.y() - a.y(), a.x() - b.x());
        const Vec2 centre = geometry::Act(x, along + out.normalized() * (radius + 0.005 + rng.U(-0.002, 0.002)));
        const Pose2 e{centre.x(), centre.y(), rng.U(-M_PI, M_PI)};
        const Vec2 p = geometry::Act(x, along) + Vec2(rng.U(-0.002, 0.002), rng.U(-0.002, 0.002));
        CheckCost(f, {V(x), V(e), V(p)}, tally, worst, "case " + std::to_string(n));
      }
    }
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
  EXPECT_THROW(FeatureWitnessFactor(Objects()[0], geometry::EdgeId{0, 5, 0}, false, Shape::Disk(0.005), 1e-3), GraphError);
  EXPECT_THROW(FeatureWitnessFactor(Objects()[0], geometry::EdgeId{0, -1, 999}, false, Shape::Disk(0.005), 1e-3), GraphError);
}

// A flat bar along an object edge (a line contact): with overlap_end -1 / +1 the witness is the
// overlap's end toward the edge's start / end wherever p is on the facing bar face (the bar's
// corner projected onto the edge, or the edge's own vertex where the bar hangs past it), and it
// stays on the facing pair's features; Jacobians checked with the bar tilted up to 0.3 rad.
TEST(FactorJacobians, FeatureWitnessAtAnOverlapEnd) {
  Rng rng;
  JacobianTally tally("C feature witness at an overlap end");
  WorstError worst{"C feature witness at an overlap end"};
  const Shape object = Shape::Box(0.12, 0.08);  // edge 2 of its ring: (0.06, 0.04) -> (-0.06, 0.04)
  const Shape bar = Shape::Box(0.01, 0.064);    // its face x = +0.005 runs along y
  const geometry::EdgeId top{0, -1, 2};
  const auto& ring = object.polygons()[0].outer;
  const Vec2 A = ring[2], B = ring[3];
  ASSERT_NEAR(A.y(), 0.04, 1e-15);
  ASSERT_NEAR(B.y(), 0.04, 1e-15);
  int n = 0, at_corner = 0, at_vertex = 0;
  for (const int end : {-1, 1}) {
    FeatureWitnessFactor f(object, top, false, bar, 1e-3, end);
    for (int i = 0; i < 60; ++i, ++n) {
      const Pose2 x = rng.P(0.2);
      // The bar's face on the top edge, turned by pi/2 - tilt so its +x face looks down at it,
      // its centre anywhere from inside the edge to hanging 2 cm past an end.
      const double along = rng.U(-0.07, 0.07), tilt = rng.U(-0.3, 0.3);
      const Vec2 centre_obj(along, 0.04 + 0.005 + rng.U(-0.001, 0.001));
      const Pose2 e = geometry::Compose(x, Pose2{centre_obj.x(), centre_obj.y(), -M_PI / 2 + tilt});
      const Vec2 p = geometry::Act(x, Vec2(along + rng.U(-0.02, 0.02), 0.04 + rng.U(-0.002, 0.002)));
      CheckCost(f, {V(x), V(e), V(p)}, tally, worst, "case " + std::to_string(n));
      // With the bar square to the edge: the end is the bar's corner on that side, or the edge's
      // vertex where the bar hangs past it.
      const Pose2 e0 = geometry::Compose(x, Pose2{along, 0.045, -M_PI / 2});
      const std::vector<Eigen::VectorXd> values{V(x), V(e0), V(p)};
      const double* blocks[] = {values[0].data(), values[1].data(), values[2].data()};
      Eigen::Vector2d r;
      ASSERT_TRUE(f.Evaluate(blocks, r.data(), nullptr));
      const Vec2 q_obj = geometry::InverseAct(x, p - 1e-3 * r);
      // end -1: toward A (x = +0.06); +1: toward B (x = -0.06). The bar spans along +- 0.032.
      const double expected = end < 0 ? std::min(0.06, along + 0.032) : std::max(-0.06, along - 0.032);
      EXPECT_NEAR(q_obj.x(), expected, 1e-12) << "case " << n;
      EXPECT_NEAR(q_obj.y(), 0.04, 1e-12) << "case " << n;
      (std::abs(expected) == 0.06 ? at_vertex : at_corner)++;
    }
  }
  EXPECT_GT(at_corner, 20);
  EXPECT_GT(at_vertex, 10);
  EXPECT_TRUE(tally.MostlyChecked(0.9));
  EXPECT_THROW(FeatureWitnessFactor(object, top, false, bar, 1e-3, 2), GraphError);
}

// A line contact's inner end point measured (a notch's corner between a flat face's ends): the
// same overlap end, as a function of both poses only; Jacobians and the end's position.
TEST(FactorJacobians, OverlapEndMeasurement) {
  Rng rng;
  JacobianTally tally("overlap end measurement");
  WorstError worst{"overlap end measurement"};
  const Shape object = Shape::Box(0.12, 0.08);
  const Shape bar = Shape::Box(0.01, 0.064);
  const geometry::EdgeId top{0, -1, 2}, face{0, -1, 1};  // the bar's edge 1: x = +0.005, y from -0.032 to 0.032
  int n = 0;
  for (const int end : {-1, 1}) {
    for (int i = 0; i < 60; ++i, ++n) {
      const Vec2 measured(rng.U(-0.07, 0.07), rng.U(0.035, 0.045));
      OverlapEndMeasurementFactor f(object, top, bar, face, end, measured, 1e-3);
      const Pose2 x = rng.P(0.2);
      const double along = rng.U(-0.07, 0.07), tilt = rng.U(-0.3, 0.3);
      const Pose2 e = geometry::Compose(x, Pose2{along, 0.045 + rng.U(-0.001, 0.001), -M_PI / 2 + tilt});
      CheckCost(f, {V(x), V(e)}, tally, worst, "case " + std::to_string(n));
      // Square to the edge, at the identity object pose: the end is known in closed form.
      const Pose2 e0{along, 0.045, -M_PI / 2};
      const std::vector<Eigen::VectorXd> values{V(Pose2{0, 0, 0}), V(e0)};
      const double* blocks[] = {values[0].data(), values[1].data()};
      Eigen::Vector2d r;
      ASSERT_TRUE(f.Evaluate(blocks, r.data(), nullptr));
      const double expected = end < 0 ? std::min(0.06, along + 0.032) : std::max(-0.06, along - 0.032);
      EXPECT_NEAR(measured.x() + 1e-3 * r.x(), expected, 1e-12) << "case " << n;
      EXPECT_NEAR(measured.y() + 1e-3 * r.y(), 0.04, 1e-12) << "case " << n;
    }
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
  EXPECT_THROW(OverlapEndMeasurementFactor(object, top, bar, face, 0, Vec2::Zero(), 1e-3), GraphError);
  EXPECT_THROW(OverlapEndMeasurementFactor(object, geometry::EdgeId{0, -1, 9}, bar, face, 1, Vec2::Zero(), 1e-3), GraphError);
  EXPECT_THROW(OverlapEndMeasurementFactor(object, top, bar, geometry::EdgeId{0, 3, 0}, 1, Vec2::Zero(), 1e-3), GraphError);
}

// The friction cone: forces inside (zero residual), pulling, slipping on either side, at
// contact points near the boundary of random objects (the normal varies with pose and point).
TEST(FactorJacobians, FrictionCone) {
  Rng rng;
  JacobianTally tally("friction cone");
  WorstError worst{"friction cone"};
  int n = 0, inside = 0;
  for (const Shape& object : Objects()) {
    FrictionConeFactor f(object, 0.4, 0.05);
    for (int i = 0; i < 80; ++i, ++n) {
      const Pose2 x = rng.P(0.2);
      const geometry::PointQuery q =
          geometry::QueryPoint(object, x, geometry::Act(x, Vec2(rng.U(-0.07, 0.07), rng.U(-0.07, 0.07))));
      const Vec2 p = q.closest_point + 1e-4 * Vec2(rng.U(-1, 1), rng.U(-1, 1));
      const double a = rng.U(-M_PI, M_PI);
      const Vec2 force = rng.U(0.1, 3.0) * Vec2(std::cos(a), std::sin(a));
      const std::vector<Eigen::VectorXd> values{V(x), V(p), V(force)};
      CheckCost(f, values, tally, worst, "case " + std::to_string(n));
      const double* blocks[] = {values[0].data(), values[1].data(), values[2].data()};
      Eigen::Vector2d r;
      ASSERT_TRUE(f.Evaluate(blocks, r.data(), nullptr));
      inside += r.norm() == 0.0;
      // Pushing straight in is inside the cone.
      const Vec2 in = -geometry::QueryPoint(object, x, p).normal;
      const std::vector<Eigen::VectorXd> push{V(x), V(p), V(Vec2(1.5 * in))};
      const double* pb[] = {push[0].data(), push[1].data(), push[2].data()};
      ASSERT_TRUE(f.Evaluate(pb, r.data(), nullptr));
      EXPECT_EQ(r.norm(), 0.0) << "case " << n;
    }
  }
  EXPECT_GT(inside, n / 20);       // some random forces are inside the cone (|angle| < atan 0.4)
  EXPECT_LT(inside, n / 2);        // most are not
  EXPECT_TRUE(tally.MostlyChecked(0.9));
}

TEST(FactorJacobians, TouchingAndIntersection) {
  Rng rng;
  JacobianTally t_touch("C touching"), t_int("S");
  WorstError w_touch{"C touching (separation)"}, w_int{"S intersection"};
  const std::vector<Shape> fingers = {Shape::Disk(0.005), Shape::Box(0.01, 0.004)};
  int intersecting = 0, apart = 0;
  for (const Shape& obj : {Shape::Box(0.09, 0.09), Shape::RegularPolygon(3, 0.06)}) {
    for (const Shape& fin : fingers) {
      auto querier = std::make_shared<const geometry::ShapePairQuerier>(obj, fin);
      TouchingFactor touch(querier, 1e-3);
      IntersectionFactor inter(querier, 1e-3);
      for (int i = 0; i < 120; ++i) {
        const Pose2 x = rng.P(0.1);
        // A boundary point of the object (edges and vertices), then the finger near it.
        const auto& ring = obj.polygons()[0].outer;
        const int k = i % static_cast<int>(ring.size());
        const Vec2 a = ring[k], b = ring[(k + 1) % ring.size()];
        const double s = i % 4 == 0 ? 0.0 : rng.U(0.1, 0.9);  // s = 0: at a vertex
        const Vec2 on = a + s * (b - a);
        const Vec2 n_out = s == 0.0 ? on.normalized() : Vec2((b - a).y(), -(b - a).x()).normalized();
        const double depth = rng.U(-0.004, 0.004);  // < 0: overlapping
        const Vec2 c = on + n_out * (0.005 + depth);
        const Pose2 e = geometry::Compose(x, Pose2{c.x(), c.y(), rng.U(-0.3, 0.3)});
        const auto res = querier->Query(x, e);
        (res.intersecting ? intersecting : apart)++;
        CheckCost(touch, {V(x), V(e)}, t_touch, w_touch, "touch " + std::to_string(i));
        CheckCost(inter, {V(x), V(e)}, t_int, w_int, "S " + std::to_string(i));
        if (!res.intersecting) {
          double r[2];
          const double* ps[2] = {x.vector().data(), e.vector().data()};
          Eigen::Vector3d xv = x.vector(), ev = e.vector();
          ps[0] = xv.data();
          ps[1] = ev.data();
          ASSERT_TRUE(inter.Evaluate(ps, r, nullptr));
          EXPECT_EQ(r[0], 0.0);
          EXPECT_EQ(r[1], 0.0);
        }
      }
    }
  }
  EXPECT_GT(intersecting, 50);
  EXPECT_GT(apart, 50);
  EXPECT_TRUE(t_touch.MostlyChecked(0.8));
  EXPECT_TRUE(t_int.MostlyChecked(0.8));
}

TEST(FactorJacobians, ConstantVelocityAndRandomWalk) {
  Rng rng;
  JacobianTally tv("V"), tr("random walk");
  WorstError wv{"V constant velocity"}, wr{"zero-velocity prior (yu)"};
  for (int i = 0; i < 300; ++i) {
    const double dt1 = rng.U(0.002, 0.05), dt2 = rng.U(0.002, 0.05);
    const Pose2 a = rng.P();
    const double w = i % 3 == 0 ? 0.0 : (i % 3 == 1 ? rng.U(-1e-9, 1e-9) : rng.U(-2, 2));  // pure translation, near-zero rotation
    const Pose2 b = geometry::Compose(a, geometry::Exp(Eigen::Vector3d(rng.U(-0.1, 0.1), rng.U(-0.1, 0.1), w) * dt1));
    const Pose2 c = geometry::Compose(b, geometry::Exp(Eigen::Vector3d(rng.U(-0.1, 0.1), rng.U(-0.1, 0.1), w) * dt2));
    ConstantVelocityFactor v(dt1, dt2, 0.01, 0.1);
    CheckCost(v, {V(a), V(b), V(c)}, tv, wv, "V " + std::to_string(i));
    RandomWalkFactor r(dt1, 0.05, 0.5);
    CheckCost(r, {V(a), V(b)}, tr, wr, "RW " + std::to_string(i));
  }
  EXPECT_TRUE(tv.MostlyChecked(0.95));
  EXPECT_TRUE(tr.MostlyChecked(0.95));
}

TEST(FactorSemantics, ConstantVelocityIsZeroOnAnArcWithUnequalSteps) {
  const Eigen::Vector3d xi(0.05, 0.01, 0.7);
  const Pose2 a{0.1, -0.2, 2.9};
  const Pose2 b = geometry::Compose(a, geometry::Exp(xi * 0.01));
  const Pose2 c = geometry::Compose(b, geometry::Exp(xi * 0.03));  // crosses theta = pi
  ConstantVelocityFactor v(0.01, 0.03, 0.01, 0.1);
  Eigen::Vector3d av = a.vector(), bv = b.vector(), cv = c.vector(), r;
  const double* ps[3] = {av.data(), bv.data(), cv.data()};
  ASSERT_TRUE(v.Evaluate(ps, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-9);
  cv[2] += 0.01;  // a change of angular velocity is penalized
  ASSERT_TRUE(v.Evaluate(ps, r.data(), nullptr));
  EXPECT_GT(std::abs(r[2]), 1.0);
}

// Quasi-static configurations: pure translation, pure rotation, near-zero rotation, general.
struct QsCase {
  Pose2 x_prev, x;
  Vec2 p, f;
};

std::vector<QsCase> QuasiStaticCases(Rng& rng, const QuasiStaticGeometry& g) {
  std::vector<QsCase> cases;
  for (int i = 0; i < 400; ++i) {
    QsCase c;
    c.x_prev = rng.P(0.2);
    Eigen::Vector3d xi(rng.U(-0.1, 0.1), rng.U(-0.1, 0.1), rng.U(-2, 2));
    switch (i % 4) {
      case 0: xi.z() = 0.0; break;                                   // pure translation
      case 1: xi.z() = rng.U(-1e-9, 1e-9); break;                    // near-zero rotation
      case 2: xi.head<2>() = Vec2(g.centre_of_pressure.y(), -g.centre_of_pressure.x()) * xi.z(); break;  // pure rotation about the centre of pressure
      default: break;
    }
    c.x = geometry::Compose(c.x_prev, geometry::Exp(xi * g.dt));
    c.p = geometry::Act(c.x, Vec2(-0.045, rng.U(-0.045, 0.045)));
    c.f = i % 10 == 9 ? Vec2::Zero() : Vec2(rng.U(-3, 3), rng.U(-3, 3));
    cases.push_back(c);
  }
  return cases;
}

// C in its witness form: p against the midpoint of the exact witnesses, for disk and polygonal
// fingers, apart and overlapping, at edges and at vertices of the object.
TEST(FactorJacobians, ContactWitness) {
  Rng rng;
  JacobianTally tally("C witness");
  WorstError worst{"C witness (contact point)"};
  int checked = 0;
  for (const Shape& obj : {Shape::Box(0.09, 0.09), Shape::RegularPolygon(5, 0.06)}) {
    for (const Shape& fin : {Shape::Disk(0.005), Shape::Box(0.01, 0.004)}) {
      auto querier = std::make_shared<const geometry::ShapePairQuerier>(obj, fin);
      ContactWitnessFactor factor(querier, 5e-4);
      for (int i = 0; i < 80; ++i) {
        const Pose2 x = rng.P(0.1);
        const auto& ring = obj.polygons()[0].outer;
        const int k = i % static_cast<int>(ring.size());
        const Vec2 a = ring[k], b = ring[(k + 1) % ring.size()];
        const double s = i % 4 == 0 ? 0.0 : rng.U(0.1, 0.9);
        const Vec2 on = a + s * (b - a);
        const Vec2 n_out = s == 0.0 ? on.normalized() : Vec2((b - a).y(), -(b - a).x()).normalized();
        const Vec2 c = on + n_out * (0.005 + rng.U(-0.003, 0.003));
        const Pose2 e = geometry::Compose(x, Pose2{c.x(), c.y(), rng.U(-0.3, 0.3)});
        const Vec2 p = geometry::Act(x, on) + Vec2(rng.U(-1e-3, 1e-3), rng.U(-1e-3, 1e-3));
        CheckCost(factor, {V(x), V(e), V(p)}, tally, worst, "witness " + std::to_string(i));
        ++checked;
        // Where the shapes touch, p at the touching point has zero residual.
        if (i % 10 == 0) {
          const auto r = querier->Query(x, e);
          const Vec2 mid = 0.5 * (r.object_point + r.finger_point);
          Eigen::Vector3d xv = x.vector(), ev = e.vector();
          Eigen::Vector2d pv = mid;
          const double* ps[3] = {xv.data(), ev.data(), pv.data()};
          double res[2];
          ASSERT_TRUE(factor.Evaluate(ps, res, nullptr));
          EXPECT_EQ(res[0], 0.0);
          EXPECT_EQ(res[1], 0.0);
        }
      }
    }
  }
  EXPECT_EQ(checked, 320);
  EXPECT_TRUE(tally.MostlyChecked(0.8));
}

// Evaluates a 4-block quasi-static factor.
Eigen::VectorXd Residual(const ceres::CostFunction& f, const QsCase& c) {
  Eigen::Vector3d a = c.x_prev.vector(), b = c.x.vector();
  Eigen::Vector2d p = c.p, fo = c.f;
  const double* ps[4] = {a.data(), b.data(), p.data(), fo.data()};
  Eigen::VectorXd r(f.num_residuals());
  EXPECT_TRUE(f.Evaluate(ps, r.data(), nullptr));
  return r;
}

TEST(FactorJacobians, QuasiStaticBothForms) {
  Rng rng;
  QuasiStaticGeometry g;
  g.c = 0.0344;
  g.centre_of_pressure = Vec2(0.003, -0.002);
  g.dt = 0.004;
  JacobianTally td("D"), ty("D yu"), tl("limit-surface load");
  WorstError wd{"D normalized cross product"}, wy{"D cross-multiplied (yu)"}, wl{"D limit-surface load"};
  QuasiStaticFactor d(g, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadFactor l(g, 2.0, 1e-3, 0.05, 0.1);
  CrossMultipliedQuasiStaticFactor y(g, 1e-3);
  QuasiStaticFactorWithC dc(g, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadFactorWithParameters lm(g, 0.8 * 9.81, 0.3, {false, true}, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadFactorWithParameters lc(g, 0.8 * 9.81, 0.3, {true, false}, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadFactorWithParameters lcm(g, 0.8 * 9.81, 0.3, {true, true}, 1e-3, 0.05, 0.1);
  JacobianTally tm("limit-surface load with mu"), tlc("limit-surface load with c"), tlcm("limit-surface load with c and mu");
  WorstError wm{"D limit-surface load with mu as a variable"}, wlc{"D limit-surface load with c as a variable"},
      wlcm{"D limit-surface load with c and mu as variables"};
  JacobianTally tc("D with c");
  WorstError wc{"D with c as a variable"};
  int n = 0;
  for (const QsCase& c : QuasiStaticCases(rng, g)) {
    const std::string ctx = "case " + std::to_string(n++);
    CheckCost(d, {V(c.x_prev), V(c.x), V(c.p), V(c.f)}, td, wd, ctx);
    CheckCost(y, {V(c.x_prev), V(c.x), V(c.p), V(c.f)}, ty, wy, ctx);
    CheckCost(l, {V(c.x_prev), V(c.x), V(c.p), V(c.f)}, tl, wl, ctx);
    CheckCost(dc, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V({g.c * rng.U(0.5, 2.0)})}, tc, wc, ctx);
    CheckCost(lm, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V({rng.U(0.05, 1.0)})}, tm, wm, ctx);
    CheckCost(lc, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V({g.c * rng.U(0.5, 2.0)})}, tlc, wlc, ctx);
    CheckCost(lcm, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V({g.c * rng.U(0.5, 2.0)}), V({rng.U(0.05, 1.0)})}, tlcm,
              wlcm, ctx);
  }
  EXPECT_TRUE(tm.MostlyChecked(0.95));
  EXPECT_TRUE(tlc.MostlyChecked(0.95));
  EXPECT_TRUE(tlcm.MostlyChecked(0.95));
  // With c and mu fixed at the geometry's and the constructor's values it is the plain load factor.
  {
    const QsCase c = QuasiStaticCases(rng, g).front();  // a copy: the vector is a temporary
    const LimitSurfaceLoadFactor plain(g, 0.3 * 0.8 * 9.81, 1e-3, 0.05, 0.1);
    const LimitSurfaceLoadFactorWithParameters fixed(g, 0.8 * 9.81, 0.3, {}, 1e-3, 0.05, 0.1);
    EXPECT_NEAR(Residual(plain, c)[0], Residual(fixed, c)[0], 1e-12 * (1.0 + std::abs(Residual(plain, c)[0])));
  }
  EXPECT_TRUE(tc.MostlyChecked(0.95));
  EXPECT_TRUE(tl.MostlyChecked(0.95));
  EXPECT_TRUE(td.MostlyChecked(0.95));
  EXPECT_TRUE(ty.MostlyChecked(0.95));
}

// Two contacts (a finger wedged in a notch): D and the load of the summed wrench, and the
// finger's net-force measurement. The second contact is another random case's point and force
// (some near zero: a contact about to open). With the second force zero, D is the one-contact D.
TEST(FactorJacobians, TwoContactQuasiStaticAndNetForce) {
  Rng rng;
  QuasiStaticGeometry g;
  g.c = 0.0344;
  g.centre_of_pressure = Vec2(0.003, -0.002);
  g.dt = 0.004;
  QuasiStaticTwoContactFactor d2(g, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadTwoContactFactor l2(g, 2.0, 1e-3, 0.05, 0.1);
  VectorSumMeasurementFactor sum(Vec2(0.7, -0.2), 0.05);
  QuasiStaticFactor d1(g, 1e-3, 0.05, 0.1);
  JacobianTally td("D, two contacts"), tl("limit-surface load, two contacts"), ts("net force");
  WorstError wd{"D with two contacts"}, wl{"limit-surface load with two contacts"}, ws{"net force measurement"};
  const std::vector<QsCase> cases = QuasiStaticCases(rng, g), others = QuasiStaticCases(rng, g);
  for (std::size_t n = 0; n < cases.size(); ++n) {
    const QsCase& c = cases[n];
    const QsCase& o = others[(n * 7 + 3) % others.size()];
    Vec2 f2 = o.f;
    if (n % 5 == 0) f2 *= 1e-6;  // nearly open
    const std::string ctx = "case " + std::to_string(n);
    CheckCost(d2, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V(o.p), V(f2)}, td, wd, ctx);
    CheckCost(l2, {V(c.x_prev), V(c.x), V(c.p), V(c.f), V(o.p), V(f2)}, tl, wl, ctx);
    CheckCost(sum, {V(c.f), V(f2)}, ts, ws, ctx);
    // The second contact without force is no contact.
    const std::vector<Eigen::VectorXd> values{V(c.x_prev), V(c.x), V(c.p), V(c.f), V(o.p), V(Vec2::Zero())};
    const double* two[] = {values[0].data(), values[1].data(), values[2].data(), values[3].data(), values[4].data(),
                           values[5].data()};
    Eigen::Vector3d r2, r1;
    ASSERT_TRUE(d2.Evaluate(two, r2.data(), nullptr));
    ASSERT_TRUE(d1.Evaluate(two, r1.data(), nullptr));
    EXPECT_LE((r2 - r1).norm(), 1e-12 * (1.0 + r1.norm())) << ctx;
  }
  EXPECT_TRUE(td.MostlyChecked(0.95));
  EXPECT_TRUE(tl.MostlyChecked(0.95));
  EXPECT_TRUE(ts.MostlyChecked(0.95));
}


// Any number of contacts (three fingers): D and the load of the summed wrench, checked with
// three contacts (the third another random case's, some nearly open); with two contacts they are
// the two-contact factors to the last bit, and a third contact without force changes nothing.
TEST(FactorJacobians, MultiContactQuasiStaticAndLoad) {
  Rng rng;
  QuasiStaticGeometry g;
  g.c = 0.0344;
  g.centre_of_pressure = Vec2(0.003, -0.002);
  g.dt = 0.004;
  QuasiStaticMultiContactFactor d3(g, 3, 1e-3, 0.05, 0.1), dm2(g, 2, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadMultiContactFactor l3(g, 3, 2.0, 1e-3, 0.05, 0.1), lm2(g, 2, 2.0, 1e-3, 0.05, 0.1);
  QuasiStaticTwoContactFactor d2(g, 1e-3, 0.05, 0.1);
  LimitSurfaceLoadTwoContactFactor l2(g, 2.0, 1e-3, 0.05, 0.1);
  JacobianTally td("D, three contacts"), tl("limit-surface load, three contacts");
  WorstError wd{"D with three contacts"}, wl{"limit-surface load with three contacts"};
  const std::vector<QsCase> cases = QuasiStaticCases(rng, g), others = QuasiStaticCases(rng, g);
  auto eval = [](const ceres::CostFunction& f, const std::vector<Eigen::VectorXd>& values) {
    std::vector<const double*> blocks;
    for (const Eigen::VectorXd& v : values) blocks.push_back(v.data());
    Eigen::VectorXd r(f.num_residuals());
    EXPECT_TRUE(f.Evaluate(blocks.data(), r.data(), nullptr));
    return r;
  };
  for (std::size_t n = 0; n < cases.size(); ++n) {
    const QsCase& c = cases[n];
    const QsCase& o = others[(n * 7 + 3) % others.size()];
    const QsCase& q = others[(n * 5 + 1) % others.size()];
    Vec2 f3 = q.f;
    if (n % 5 == 0) f3 *= 1e-6;  // nearly open
    const std::string ctx = "case " + std::to_string(n);
    const std::vector<Eigen::VectorXd> three{V(c.x_prev), V(c.x), V(c.p), V(c.f), V(o.p), V(o.f), V(q.p), V(f3)};
    CheckCost(d3, three, td, wd, ctx);
    CheckCost(l3, three, tl, wl, ctx);
    const std::vector<Eigen::VectorXd> two(three.begin(), three.begin() + 6);
    EXPECT_EQ(eval(dm2, two), eval(d2, two)) << ctx;
    EXPECT_EQ(eval(lm2, two), eval(l2, two)) << ctx;
    std::vector<Eigen::VectorXd> open = three;
    open[7] = V(Vec2::Zero());
    EXPECT_LE((eval(d3, open) - eval(d2, two)).norm(), 1e-12 * (1.0 + eval(d2, two).norm())) << ctx;
  }
  EXPECT_TRUE(td.MostlyChecked(0.95));
  EXPECT_TRUE(tl.MostlyChecked(0.95));
  EXPECT_THROW(QuasiStaticMultiContactFactor(g, 0, 1e-3, 0.05, 0.1), GraphError);
  EXPECT_THROW(LimitSurfaceLoadMultiContactFactor(g, 0, 2.0, 1e-3, 0.05, 0.1), GraphError);
}

// The shape frame F as a variable (shape registration): the wrapper composes the object-pose
// blocks with F, so its Jacobians with respect to those blocks and to F are chained through
// Compose; checked on wrapped C, touching, S and D, near contact and at vertices, and on its
// prior. The wrapped value must equal the inner factor's at x * F.
TEST(FactorJacobians, ShapeFrame) {
  Rng rng;
  JacobianTally tally("shape frame");
  WorstError worst{"shape frame (wrapped C, S, D)"};
  const Shape object = Shape::Box(0.09, 0.06);
  auto querier = std::make_shared<const geometry::ShapePairQuerier>(object, Shape::Disk(0.005));
  QuasiStaticGeometry g;
  g.c = 0.03;
  g.centre_of_pressure = Vec2(0.002, -0.001);
  g.dt = 0.01;
  const ShapeFrameFactor boundary(new BoundaryPointFactor(object, 1e-3), {0});
  const ShapeFrameFactor touching(new TouchingFactor(querier, 1e-3), {0});
  const ShapeFrameFactor intersection(new IntersectionFactor(querier, 1e-3), {0});
  const ShapeFrameFactor quasi_static(new QuasiStaticFactor(g, 1e-3, 0.05, 0.1), {0, 1});
  for (int i = 0; i < 150; ++i) {
    const Pose2 x = rng.P(0.1);
    const Pose2 F = i % 10 == 0 ? Pose2{} : Pose2{rng.U(-0.02, 0.02), rng.U(-0.02, 0.02), rng.U(-0.6, 0.6)};
    const Pose2 placed = geometry::Compose(x, F);
    // A finger near the placed shape's boundary (edges, and vertices every 4th case).
    const auto& ring = object.polygons()[0].outer;
    const Vec2 a = ring[i % 4], b = ring[(i + 1) % 4];
    const double s = i % 4 == 0 ? 0.0 : rng.U(0.1, 0.9);
    const Vec2 on = a + s * (b - a);
    const Vec2 n_out = s == 0.0 ? on.normalized() : Vec2((b - a).y(), -(b - a).x()).normalized();
    const Vec2 c_local = on + n_out * (0.005 + rng.U(-0.003, 0.003));
    const Pose2 e = geometry::Compose(placed, Pose2{c_local.x(), c_local.y(), rng.U(-0.3, 0.3)});
    const Vec2 p = geometry::Act(placed, on) + Vec2(rng.U(-1e-3, 1e-3), rng.U(-1e-3, 1e-3));
    const std::string ctx = "case " + std::to_string(i);
    CheckCost(boundary, {V(x), V(p), V(F)}, tally, worst, ctx + " C");
    CheckCost(touching, {V(x), V(e), V(F)}, tally, worst, ctx + " touching");
    CheckCost(intersection, {V(x), V(e), V(F)}, tally, worst, ctx + " S");
    const Pose2 x_prev = geometry::Compose(x, Pose2{rng.U(-2e-4, 2e-4), rng.U(-2e-4, 2e-4), rng.U(-5e-3, 5e-3)});
    const Vec2 f(rng.U(-2, 2), rng.U(-2, 2));
    CheckCost(quasi_static, {V(x_prev), V(x), V(p), V(f), V(F)}, tally, worst, ctx + " D");
    // The wrapper's value is the inner factor's at x * F.
    const TouchingFactor inner(querier, 1e-3);
    const Eigen::Vector3d xv = x.vector(), ev = e.vector(), Fv = F.vector(), pv = placed.vector();
    const double* wrapped_params[] = {xv.data(), ev.data(), Fv.data()};
    const double* inner_params[] = {pv.data(), ev.data()};
    double r_wrapped = 0.0, r_inner = 0.0;
    ASSERT_TRUE(touching.Evaluate(wrapped_params, &r_wrapped, nullptr));
    ASSERT_TRUE(inner.Evaluate(inner_params, &r_inner, nullptr));
    EXPECT_EQ(r_wrapped, r_inner) << ctx;
  }
  EXPECT_TRUE(tally.MostlyChecked(0.9));
  // The prior: the centroid placed by F over its sigma, and F's angle over its sigma.
  JacobianTally prior_tally("shape frame prior");
  WorstError prior_worst{"shape frame prior"};
  const ShapeFramePrior prior(Vec2(0.01, -0.02), 0.005, 0.2);
  for (int i = 0; i < 50; ++i) CheckCost(prior, {V(rng.P(0.05))}, prior_tally, prior_worst, "prior " + std::to_string(i));
  EXPECT_TRUE(prior_tally.MostlyChecked(0.99));
  EXPECT_THROW(ShapeFrameFactor(new TouchingFactor(querier, 1e-3), {2}), GraphError);
}

// A consistent quasi-static step: for a load (f_b, tau) the ellipsoid's twist is parallel to
// (f_b, tau / c^2) (paper Eq. 4), so D must vanish; rotating the motion must not.
TEST(FactorSemantics, QuasiStaticVanishesExactlyOnTheEllipsoidAndIsInformativeInTranslation) {
  QuasiStaticGeometry g;
  g.c = 0.0344;
  g.dt = 0.004;
  QuasiStaticFactor d(g, 1e-3, 0.05, 0.1);
  CrossMultipliedQuasiStaticFactor y(g, 1e-3);
  for (double offset : {0.0, 1e-7, 0.01, 0.03}) {  // 0: centred push, pure translation
    const Vec2 q(-0.045, offset);                  // contact in the object frame
    const Vec2 fb(1.5, 0.0);                       // pushing along +x
    const double tau = q.x() * fb.y() - q.y() * fb.x();
    const double k = 0.05 / fb.norm();
    const Eigen::Vector3d xi(k * fb.x(), k * fb.y(), k * tau / (g.c * g.c));
    QsCase c;
    c.x_prev = Pose2{0.1, 0.2, 0.3};
    c.x = geometry::Compose(c.x_prev, geometry::Exp(xi * g.dt));
    c.p = geometry::Act(c.x, q);
    c.f = c.x.rotation() * fb;
    EXPECT_LT(Residual(d, c).norm(), 1e-9) << offset;
    EXPECT_LT(Residual(y, c).norm(), 1e-9) << offset;
    // Same force, the object moving 20 degrees off the force direction.
    QsCase bad = c;
    const Eigen::Vector3d xi_bad(xi.x() * std::cos(0.35) - xi.y() * std::sin(0.35),
                                 xi.x() * std::sin(0.35) + xi.y() * std::cos(0.35), xi.z());
    bad.x = geometry::Compose(c.x_prev, geometry::Exp(xi_bad * g.dt));
    bad.p = geometry::Act(bad.x, q);
    bad.f = bad.x.rotation() * fb;
    EXPECT_GT(Residual(d, bad).norm() * 0.1, 0.2) << offset;  // about sin(20 deg)
    if (offset == 0.0) {
      // The baseline's cross-multiplied form cannot see it in pure translation.
      EXPECT_LT(Residual(y, bad).norm(), 1e-12);
    }
  }
}

// Rotation-dominated pushes (far off-centre contact: about 97% of |V'| is c omega) and pure
// rotation: D stays finite, vanishes on the ellipsoid's motion and sees a wrong one, where the
// paper's Eq. 8 (v / omega - c^2 f / tau) would be ill-conditioned only in translation and
// the baseline's form loses its third component.
TEST(FactorSemantics, QuasiStaticIsInformativeInRotation) {
  QuasiStaticGeometry g;
  g.c = 0.0344;
  g.dt = 0.004;
  QuasiStaticFactor d(g, 1e-3, 0.05, 0.1);
  for (double offset : {0.2, 1.0, -1.0}) {
    const Vec2 q(-0.045, offset);
    const Vec2 fb(1.5, 0.0);
    const double tau = q.x() * fb.y() - q.y() * fb.x();
    const double k = 0.05 / fb.norm();
    const Eigen::Vector3d xi(k * fb.x(), k * fb.y(), k * tau / (g.c * g.c));
    ASSERT_GT(std::abs(g.c * xi.z()), 5.0 * xi.head<2>().norm()) << offset;  // rotation-dominated
    QsCase c;
    c.x_prev = Pose2{0.1, 0.2, 0.3};
    c.x = geometry::Compose(c.x_prev, geometry::Exp(xi * g.dt));
    c.p = geometry::Act(c.x, q);
    c.f = c.x.rotation() * fb;
    EXPECT_LT(Residual(d, c).norm(), 1e-9) << offset;
    // Tilt the twist 20 degrees in the (v_x, c omega) plane: D sees it.
    const double cw = g.c * xi.z();
    Eigen::Vector3d bad = xi;
    bad.x() = xi.x() * std::cos(0.35) - cw * std::sin(0.35);
    bad.z() = (xi.x() * std::sin(0.35) + cw * std::cos(0.35)) / g.c;
    QsCase b = c;
    b.x = geometry::Compose(c.x_prev, geometry::Exp(bad * g.dt));
    b.p = geometry::Act(b.x, q);
    b.f = b.x.rotation() * fb;
    EXPECT_GT(Residual(d, b).norm() * 0.1, 0.2) << offset;
  }
  // Pure rotation about the centre of pressure while pushed off-centre: not what the ellipsoid
  // predicts for a point force, so D is non-zero, finite, with finite Jacobians.
  QsCase c;
  c.x_prev = Pose2{0.0, 0.0, 0.0};
  c.x = Pose2{0.0, 0.0, 0.01};
  c.p = geometry::Act(c.x, Vec2(-0.045, 0.03));
  c.f = Vec2(1.0, 0.0);
  const Eigen::VectorXd r = Residual(d, c);
  EXPECT_TRUE(r.allFinite());
  EXPECT_GT(r.norm() * 0.1, 0.1);
  Rng rng;
  JacobianTally tally("D pure rotation");
  WorstError worst{"D pure rotation"};
  CheckCost(d, {V(c.x_prev), V(c.x), V(c.p), V(c.f)}, tally, worst, "pure rotation");
}

TEST(FactorSemantics, BadSigmasAndStepsAreRejected) {
  EXPECT_THROW(PoseMeasurementFactor(Pose2{}, 0.0, 1.0), GraphError);
  EXPECT_THROW(VectorMeasurementFactor(Vec2::Zero(), NAN), GraphError);
  EXPECT_THROW(ConstantVelocityFactor(0.0, 0.01, 1, 1), GraphError);
  QuasiStaticGeometry g;
  g.c = -1.0;
  EXPECT_THROW(QuasiStaticFactor(g, 1e-3, 0.05, 0.1), GraphError);
  EXPECT_THROW(BoundaryPointFactor(geometry::Shape(), 1.0), GraphError);
}

// The marginalization prior of the fixed-lag smoother: linear in the chart coordinates, so its
// Jacobians are S's column blocks; checked like every factor over random sizes and points (angles
// near +-pi included), and its quadratic form against H = S^T S, b = S^T r0.
TEST(FactorJacobians, MarginalPrior) {
  Rng rng;
  JacobianTally tally("marginal prior");
  WorstError worst{"marginal prior"};
  for (int i = 0; i < 40; ++i) {
    const std::vector<int> sizes = i % 2 == 0 ? std::vector<int>{3, 3, 2, 2} : std::vector<int>{3, 2, 1};
    int n = 0;
    for (int s : sizes) n += s;
    const int m = 1 + i % n;
    Eigen::MatrixXd S(m, n);
    for (int r = 0; r < m; ++r)
      for (int c = 0; c < n; ++c) S(r, c) = rng.U(-50, 50);
    Eigen::VectorXd x_bar(n), r0(m), x(n);
    for (int k = 0; k < n; ++k) x_bar[k] = rng.U(-M_PI, M_PI);
    for (int k = 0; k < m; ++k) r0[k] = rng.U(-1, 1);
    for (int k = 0; k < n; ++k) x[k] = x_bar[k] + rng.U(-0.1, 0.1);
    const MarginalPriorFactor prior(sizes, x_bar, S, r0);
    std::vector<Eigen::VectorXd> blocks;
    int off = 0;
    for (int s : sizes) {
      blocks.push_back(x.segment(off, s));
      off += s;
    }
    CheckCost(prior, blocks, tally, worst, "case " + std::to_string(i));
    // 1/2 |r|^2 = 1/2 dx^T H dx + b^T dx + 1/2 |r0|^2.
    std::vector<const double*> ptrs;
    for (const auto& b : blocks) ptrs.push_back(b.data());
    Eigen::VectorXd r(m);
    ASSERT_TRUE(prior.Evaluate(ptrs.data(), r.data(), nullptr));
    const Eigen::VectorXd dx = x - x_bar;
    const double expected = 0.5 * dx.dot(S.transpose() * S * dx) + (S.transpose() * r0).dot(dx) + 0.5 * r0.squaredNorm();
    EXPECT_NEAR(0.5 * r.squaredNorm(), expected, 1e-9 * std::max(1.0, expected));
  }
  EXPECT_TRUE(tally.MostlyChecked(0.99));
  EXPECT_THROW(MarginalPriorFactor({3, 2}, Eigen::VectorXd::Zero(5), Eigen::MatrixXd::Zero(2, 4), Eigen::VectorXd::Zero(2)),
               GraphError);
}

// The harness covers the module: every cost function class the graph module declares (public
// headers and sources) is constructed in this file, where every construction is checked with
// CheckCost. A new factor without a check fails here, by name.
TEST(FactorJacobians, EveryCostFunctionOfTheModuleIsChecked) {
  std::set<std::string> declared;
  const std::regex cls(R"(class (\w+) : public ceres::(Sized)?CostFunction)");
  for (const char* header : {"graph/include/pushgraph/graph/factors.h", "graph/include/pushgraph/graph/incremental.h",
                             "graph/include/pushgraph/graph/shape_frame.h", "graph/src/graph_builder.h"}) {
    std::ifstream in(std::string(PUSHGRAPH_SOURCE_DIR) + "/" + header);
    ASSERT_TRUE(in) << header;
    std::stringstream text;
    text << in.rdbuf();
    const std::string s = text.str();
    for (auto it = std::sregex_iterator(s.begin(), s.end(), cls); it != std::sregex_iterator(); ++it)
      declared.insert((*it)[1]);
  }
  EXPECT_GE(declared.size(), 17u);
  std::ifstream in(std::string(PUSHGRAPH_SOURCE_DIR) + "/tests/graph/test_factors.cpp");
  ASSERT_TRUE(in);
  std::stringstream text;
  text << in.rdbuf();
  const std::string tests = text.str();
  for (const std::string& name : declared) {
    // Constructed as a variable or with new (not only named in a comment).
    const std::regex use("\\b" + name + "\\s*(\\w+\\s*\\(|\\()");
    EXPECT_TRUE(std::regex_search(tests, use)) << name << " has no Jacobian check in tests/graph/test_factors.cpp";
  }
}

}  // namespace
}  // namespace pushgraph::graph
