// Shape-versus-shape queries. Disk fingers against non-convex objects (exact, equal to the point
// query); polygonal fingers with kExact against an independent CGAL Epeck Minkowski-sum oracle
// (and, when apart, an Epeck segment-segment distance oracle); kVertexSampling against kExact
// (equal when apart, a lower bound on the depth when overlapping, error reported); witness
// consistency; the separating translation really separates; obstacle caching.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/minkowski_sum_2.h>
#include <CGAL/squared_distance_2.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"
#include "geometry/rounded_depth_oracle.h"

namespace pushgraph::geometry {
namespace {

using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using FT = EK::FT;
using EPoint = EK::Point_2;
using ESegment = EK::Segment_2;
using EPolygon = CGAL::Polygon_2<EK>;
using EPolygonWithHoles = CGAL::Polygon_with_holes_2<EK>;
using testing::kPi;
using testing::Scaled;

EPoint E(const Vec2& p) { return EPoint(p.x(), p.y()); }

std::string Str(const Pose2& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x << ", " << p.y << ", " << p.theta << ")";
  return s.str();
}

/// Signed distance of a point to a polygon with holes, exactly up to the final sqrt.
double ExactSignedDistance(const EPolygonWithHoles& c, const EPoint& p) {
  FT best = -1;
  auto visit = [&](const EPolygon& ring) {
    for (auto e = ring.edges_begin(); e != ring.edges_end(); ++e) {
      const FT d = CGAL::squared_distance(p, *e);
      if (best < 0 || d < best) best = d;
    }
  };
  visit(c.outer_boundary());
  for (auto h = c.holes_begin(); h != c.holes_end(); ++h) visit(*h);
  bool inside = c.outer_boundary().bounded_side(p) == CGAL::ON_BOUNDED_SIDE;
  for (auto h = c.holes_begin(); h != c.holes_end() && inside; ++h)
    inside = h->bounded_side(p) == CGAL::ON_UNBOUNDED_SIDE;
  const double d = std::sqrt(CGAL::to_double(best));
  return inside ? -d : d;
}

/// Independent oracle: the exact core signed separation through CGAL's Minkowski sum of the
/// object's (single) polygon with holes and the reflected, rotated finger polygon, evaluated at
/// the finger's origin in the object frame, minus the rounding radii. Where that is negative and
/// the shapes are rounded, the depth is the distance to the boundary of the Minkowski sum grown by
/// the radii (rounded_depth_oracle.h, on the sum's vertices rounded to double).
double MinkowskiOracle(const Shape& object, const Pose2& object_pose, const Shape& finger, const Pose2& finger_pose) {
  const Pose2 rel = Between(object_pose, finger_pose);
  const Polygon& op = object.polygons().at(0);
  const Ring& fo = finger.polygons().at(0).outer;
  EPolygon outer;
  for (const Vec2& v : op.outer) outer.push_back(E(v));
  EPolygonWithHoles obj(outer);
  for (const Ring& h : op.holes) {
    EPolygon hole;
    for (const Vec2& v : h) hole.push_back(E(v));
    obj.add_hole(hole);
  }
  const double radii = object.radius() + finger.radius();
  auto rounded_depth = [radii](const EPolygonWithHoles& c, const Vec2& at, double bound) {
    if (radii == 0.0 || bound >= 0.0) return bound;
    std::vector<Ring> rings;
    auto add = [&rings](const EPolygon& ring) {
      rings.emplace_back();
      for (auto v = ring.vertices_begin(); v != ring.vertices_end(); ++v)
        rings.back().emplace_back(CGAL::to_double(v->x()), CGAL::to_double(v->y()));
    };
    add(c.outer_boundary());
    for (auto h = c.holes_begin(); h != c.holes_end(); ++h) add(*h);
    return -static_cast<double>(testing::rounded::OracleDepth(rings, radii, at));
  };
  // A point core v: C is the object translated by -R v; evaluate at the finger point directly.
  if (fo.size() == 1) {
    const Vec2 at = Act(rel, fo[0]);
    return rounded_depth(obj, at, ExactSignedDistance(obj, E(at)) - radii);
  }
  EPolygon neg_finger;  // -R(phi) F: a point reflection of a rotation keeps the orientation
  const Eigen::Matrix2d R = rel.rotation();
  for (const Vec2& v : fo) neg_finger.push_back(E(-(R * v)));
  const EPolygonWithHoles c = CGAL::minkowski_sum_2(obj, neg_finger);
  return rounded_depth(c, rel.translation(), ExactSignedDistance(c, E(rel.translation())) - radii);
}

/// Independent oracle for separated shapes: exact minimum distance over edge pairs (object frame).
double SegmentPairDistance(const Shape& object, const Pose2& object_pose, const Shape& finger, const Pose2& finger_pose) {
  const Pose2 rel = Between(object_pose, finger_pose);
  std::vector<ESegment> fe;
  for (const auto& ref : testing::AllRings(finger)) {
    const Ring& r = *ref.points;
    for (size_t i = 0; i < r.size(); ++i) fe.emplace_back(E(Act(rel, r[i])), E(Act(rel, r[(i + 1) % r.size()])));
  }
  FT best = -1;
  for (const auto& ref : testing::AllRings(object)) {
    const Ring& r = *ref.points;
    for (size_t i = 0; i < r.size(); ++i) {
      const ESegment s(E(r[i]), E(r[(i + 1) % r.size()]));
      for (const auto& f : fe) {
        const FT d = CGAL::squared_distance(s, f);
        if (best < 0 || d < best) best = d;
      }
    }
  }
  return std::sqrt(CGAL::to_double(best)) - object.radius() - finger.radius();
}

Shape RandomObject(std::mt19937_64& rng, int n = 14) {
  testing::RandomPolygonOptions o;
  o.outer_vertices = n;
  o.max_holes = 2;
  return Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2(0.02, -0.03), o)});
}

Shape RandomFinger(std::mt19937_64& rng, double radius = 0.0) {
  testing::RandomPolygonOptions o;
  o.outer_vertices = 6;
  o.max_holes = 0;
  o.size = 0.15;
  return Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2(0.01, 0.0), o)}, radius);
}

/// Finger pose whose origin is `offset` along the outward normal from a random boundary point.
Pose2 FingerPoseNear(std::mt19937_64& rng, const Shape& object, const Pose2& object_pose, double offset) {
  const Vec2 b = testing::NearBoundaryPoints(rng, object, 4, 0.0)[0];
  const PointQuery q = QueryPoint(object, b);
  const Vec2 c = Act(object_pose, b + offset * q.normal);
  return {c.x(), c.y(), std::uniform_real_distribution<double>(-kPi, kPi)(rng)};
}

Pose2 RandomPose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1), a(-kPi, kPi);
  return {u(rng), u(rng), a(rng)};
}

/// Witness and result invariants every method must satisfy.
void CheckWitnesses(const ShapePairQuerier& q, const Pose2& op, const Pose2& fp, const ShapePairResult& r,
                    const std::string& ctx) {
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12) << ctx;
  EXPECT_EQ(r.depth, std::max(0.0, -r.signed_distance)) << ctx;
  EXPECT_LT((r.object_point - r.finger_point + r.signed_distance * r.normal).norm(), 1e-12) << ctx;
  if (std::abs(r.signed_distance) > 1e-9) {
    EXPECT_EQ(r.intersecting, r.signed_distance < 0) << ctx;
  }
  // The object witness lies on the object's boundary, the finger witness on the finger's.
  // (Overlapping rounded shapes follow the rounded-shape convention: the witness is the core
  // witness moved by r, which is inside the shape but inside narrow notches not on its
  // boundary.)
  const double so = QueryPoint(q.object(), op, r.object_point).signed_distance;
  const double sf = QueryPoint(q.finger(), fp, r.finger_point).signed_distance;
  if (r.signed_distance > 0 || q.object().radius() == 0.0) {
    EXPECT_NEAR(so, 0.0, 1e-11) << "object witness off the object boundary; " << ctx;
  } else {
    EXPECT_LE(so, 1e-11) << "object witness outside the object; " << ctx;
  }
  if (r.signed_distance > 0 || q.finger().radius() == 0.0) {
    EXPECT_NEAR(sf, 0.0, 1e-11) << "finger witness off the finger boundary; " << ctx;
  } else {
    EXPECT_LE(sf, 1e-11) << "finger witness outside the finger; " << ctx;
  }
}

// ---------------------------------------------------------------------------------------------
// Disk fingers: the point query of the finger centre minus the finger radius (the exact depth where
// the disk can leave along the core normal; deeper where it cannot: test_rounded_depth.cpp).

TEST(ShapePairDisk, EqualsPointQueryOfCentre) {
  std::mt19937_64 rng(701);
  const Shape object = RandomObject(rng);
  for (double ro : {0.0, 0.01}) {
    const Shape obj = object.WithRadius(ro);
    for (double rf : {0.002, 0.05}) {
      const Shape finger = Shape::Disk(rf);
      ShapePairQuerier::Options core_depth;
      core_depth.exact_rounded_depth = false;
      const ShapePairQuerier q(obj, finger, core_depth);
      const ShapePairQuerier exact(obj, finger);
      int apart = 0, overlap = 0, deeper = 0;
      for (int i = 0; i < Scaled(300, 40); ++i) {
        const Pose2 op = RandomPose(rng);
        const Pose2 fp = FingerPoseNear(rng, obj, op, std::uniform_real_distribution<double>(-0.1, 0.1)(rng));
        const ShapePairResult r = q.Query(op, fp);
        // The exact depth: the same answer, bit for bit, unless the disk cannot leave along the normal.
        const ShapePairResult e = exact.Query(op, fp);
        if (e.depth > r.depth) {
          ++deeper;
        } else {
          EXPECT_EQ(e.signed_distance, r.signed_distance);
          EXPECT_EQ(e.object_point, r.object_point);
          EXPECT_EQ(e.finger_point, r.finger_point);
        }
        const PointQuery pq = QueryPoint(obj, op, fp.translation());
        const std::string ctx = "object " + Str(op) + " finger " + Str(fp);
        EXPECT_NEAR(r.signed_distance, pq.signed_distance - rf,
                    2 * std::numeric_limits<double>::epsilon() * (std::abs(pq.signed_distance) + rf))
            << ctx;
        EXPECT_NEAR((r.normal - pq.normal).norm(), 0.0, 1e-14) << ctx;
        EXPECT_NEAR((r.object_point - pq.closest_point).norm(), 0.0, 1e-14) << ctx;
        EXPECT_NEAR((r.finger_point - (fp.translation() - rf * pq.normal)).norm(), 0.0, 1e-14) << ctx;
        EXPECT_EQ(r.intersecting, r.signed_distance < 0) << ctx;
        CheckWitnesses(q, op, fp, r, ctx);
        (r.intersecting ? overlap : apart)++;
        // Oracle: exact core distance of the centre in the object frame, and where overlapping the
        // distance to the grown object's boundary.
        EXPECT_NEAR(e.signed_distance, MinkowskiOracle(obj, op, finger, fp), 1e-12) << ctx;
        CheckWitnesses(exact, op, fp, e, ctx);
      }
      EXPECT_GT(apart, 0);
      EXPECT_GT(overlap, 0);
      EXPECT_LT(deeper, overlap);
      EXPECT_EQ(q.obstacles_built(), 0) << "a disk finger needs no Minkowski sum";
      EXPECT_EQ(exact.obstacles_built(), 0);
    }
  }
}

TEST(ShapePairDisk, TouchingApartOverlapping) {
  const Shape comb = Shape::FromPolygons({testing::DyadicComb()});
  const Shape disk = Shape::Disk(0.5);
  const ShapePairQuerier q(comb, disk);
  // Touching the bottom edge exactly.
  ShapePairResult r = q.Query(Pose2{}, Pose2{3.0, -0.5, 0.7});
  EXPECT_EQ(r.signed_distance, 0.0);
  EXPECT_FALSE(r.intersecting);
  EXPECT_EQ(r.depth, 0.0);
  EXPECT_EQ(r.object_point, Vec2(3, 0));
  EXPECT_EQ(r.finger_point, Vec2(3, 0));
  EXPECT_EQ(r.normal, Vec2(0, -1));
  // Apart by 0.25.
  r = q.Query(Pose2{}, Pose2{3.0, -0.75, 0.0});
  EXPECT_EQ(r.signed_distance, 0.25);
  EXPECT_FALSE(r.intersecting);
  // Overlapping by 0.25: depth 0.25, separate by moving along -y.
  r = q.Query(Pose2{}, Pose2{3.0, -0.25, 0.0});
  EXPECT_EQ(r.signed_distance, -0.25);
  EXPECT_TRUE(r.intersecting);
  EXPECT_EQ(r.depth, 0.25);
  EXPECT_EQ(r.normal, Vec2(0, -1));
  EXPECT_EQ(r.finger_point, Vec2(3, 0.25));  // the deepest finger point (inside the object)
  EXPECT_EQ(r.object_point, Vec2(3, 0));      // its projection onto the object boundary
  // Centre deep inside the left column (tie between x = 0 and x = 2): depth 1.5.
  r = q.Query(Pose2{}, Pose2{1.0, 5.0, 0.0});
  EXPECT_EQ(r.signed_distance, -1.5);
  EXPECT_TRUE(r.intersecting);
  // The same with the object moved and turned: the separation is invariant.
  const Pose2 op{10.0, -3.0, 0.5};
  r = q.Query(op, Compose(op, Pose2{3.0, -0.75, 0.0}));
  EXPECT_NEAR(r.signed_distance, 0.25, 1e-14);
  // QueryShapePair is the one-off wrapper.
  const ShapePairResult w = QueryShapePair(comb, Pose2{}, disk, Pose2{3.0, -0.25, 0.0});
  EXPECT_EQ(w.signed_distance, -0.25);
}

// With exact_rounded_depth off, the rounded-shape depth (core depth + radius) is a lower bound
// where the disk cannot leave along the core normal; check_rounded_depth says so in depth_exact.
// (The exact depth: test_rounded_depth.cpp.)
TEST(ShapePairDisk, CoreDepthBoundIsFlaggedWhereItDoesNotSeparate) {
  Polygon square;
  square.outer = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  square.holes = {{Vec2(0.45, 0.45), Vec2(0.45, 0.55), Vec2(0.55, 0.55), Vec2(0.55, 0.45)}};
  const Shape holed = Shape::FromPolygons({square});
  ShapePairQuerier::Options bound;
  bound.exact_rounded_depth = false;
  bound.check_rounded_depth = true;
  const ShapePairQuerier q(holed, Shape::Disk(0.2), bound);
  // Centre 0.15 below a hole narrower than the disk: core depth + radius = 0.35 towards the hole,
  // but the disk does not fit there; the true depth is 0.5 (out through the bottom edge).
  const ShapePairResult r = q.Query(Pose2{}, Pose2{0.5, 0.3, 0.0});
  EXPECT_TRUE(r.intersecting);
  EXPECT_NEAR(r.depth, 0.35, 1e-15);
  EXPECT_FALSE(r.depth_exact);
  const ShapePairResult moved = q.Query(Pose2{}, Pose2{0.5 + r.depth * r.normal.x(), 0.3 + r.depth * r.normal.y(), 0.0});
  EXPECT_LT(moved.signed_distance, -0.01);                              // still overlapping
  EXPECT_EQ(q.Query(Pose2{}, Pose2{0.5, -0.2, 0.0}).signed_distance, 0.0);  // 0.5 down: touching
  // Near the outer edge the same query is exact, and says so.
  const ShapePairResult edge = q.Query(Pose2{}, Pose2{0.5, 0.1, 0.0});
  EXPECT_NEAR(edge.depth, 0.3, 1e-15);
  EXPECT_TRUE(edge.depth_exact);
  // A rounded polygonal finger in the same spot: flagged too.
  const ShapePairQuerier rounded(holed, Shape::Box(0.1, 0.1, 0.15), bound);
  EXPECT_FALSE(rounded.Query(Pose2{}, Pose2{0.5, 0.3, 0.0}).depth_exact);
  // Sharp polygons through the exact obstacle: always exact.
  const ShapePairQuerier sharp(holed, Shape::Box(0.3, 0.3), bound);
  const ShapePairResult s = sharp.Query(Pose2{}, Pose2{0.5, 0.3, 0.0});
  EXPECT_TRUE(s.intersecting);
  EXPECT_TRUE(s.depth_exact);
}

// ---------------------------------------------------------------------------------------------
// Polygonal fingers: kExact against the Minkowski oracle.

TEST(ShapePairPolygon, ExactMatchesMinkowskiOracle) {
  std::mt19937_64 rng(702);
  int apart = 0, overlap = 0, failures = 0;
  for (int c = 0; c < Scaled(6, 2); ++c) {
    const Shape object = RandomObject(rng, 10 + 2 * c);
    for (double rf : {0.0, 0.01}) {
      const Shape finger = RandomFinger(rng, rf);
      const ShapePairQuerier q(object, finger);
      for (int i = 0; i < Scaled(8, 3); ++i) {
        const Pose2 op = RandomPose(rng);
        const Pose2 fp = FingerPoseNear(rng, object, op, std::uniform_real_distribution<double>(-0.15, 0.3)(rng));
        const ShapePairResult r = q.Query(op, fp);
        const std::string ctx = "case " + std::to_string(c) + "/" + std::to_string(i) + " rf " +
                                std::to_string(rf) + " object " + Str(op) + " finger " + Str(fp);
        const double oracle = MinkowskiOracle(object, op, finger, fp);
        if (!(std::abs(r.signed_distance - oracle) <= 1e-10)) {
          ++failures;
          ADD_FAILURE() << ctx << ": kExact " << r.signed_distance << ", Minkowski oracle " << oracle;
        }
        if (oracle > 1e-9) {
          ++apart;
          EXPECT_NEAR(r.signed_distance, SegmentPairDistance(object, op, finger, fp), 1e-10) << ctx;
          EXPECT_FALSE(r.intersecting) << ctx;
        } else if (oracle < -1e-9) {
          ++overlap;
          EXPECT_TRUE(r.intersecting) << ctx;
        }
        CheckWitnesses(q, op, fp, r, ctx);
        if (r.intersecting) {
          // Moving the finger by depth along the normal makes it touch; a little further
          // separates; a little less still overlaps (rounded fingers too: the depth is exact).
          auto moved = [&](double s) {
            return Pose2{fp.x + s * r.normal.x(), fp.y + s * r.normal.y(), fp.theta};
          };
          EXPECT_NEAR(q.Query(op, moved(r.depth)).signed_distance, 0.0, 1e-9) << ctx;
          // (Rounded: at a concave corner of the grown obstacle the free region is a wedge that
          // need not contain the direction of the move, so going further can overlap again.)
          if (rf == 0.0) {
            EXPECT_GT(q.Query(op, moved(r.depth + 1e-6)).signed_distance, 0.0) << ctx;
          }
          EXPECT_LT(q.Query(op, moved(r.depth - 1e-6)).signed_distance, 0.0) << ctx;
        }
      }
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(apart, 0);
  EXPECT_GT(overlap, 0);
}

// With angles cached at a resolution, the query is the exact answer at the rounded relative
// angle: never an error (the touching pairs are searched at that angle), and within
// resolution x finger size of the exact separation.
TEST(ShapePairPolygon, AngleCacheIsCloseAndNeverFails) {
  std::mt19937_64 rng(712);
  for (int c = 0; c < Scaled(3, 1); ++c) {
    const Shape object = RandomObject(rng, 12);
    const Shape finger = RandomFinger(rng, c % 2 == 0 ? 0.0 : 0.005);
    ShapePairQuerier::Options options;
    options.angle_cache_resolution = 2e-3;
    const ShapePairQuerier cached(object, finger, options);
    const ShapePairQuerier exact(object, finger);
    const Box2 fb = finger.bounds();
    const double size = (fb.max - fb.min).norm() + finger.radius();
    for (int i = 0; i < Scaled(12, 4); ++i) {
      const Pose2 op = RandomPose(rng);
      const Pose2 fp = FingerPoseNear(rng, object, op, std::uniform_real_distribution<double>(-0.01, 0.02)(rng));
      ShapePairJacobians J;
      ShapePairResult rc;
      ASSERT_NO_THROW(rc = cached.Query(op, fp, &J)) << "case " << c << "/" << i;
      const ShapePairResult re = exact.Query(op, fp);
      EXPECT_NEAR(rc.signed_distance, re.signed_distance, 2e-3 * size) << "case " << c << "/" << i;
      EXPECT_TRUE(J.J_sd_object_pose.allFinite());
    }
    EXPECT_LE(cached.obstacles_built(), exact.obstacles_built());
  }
}

TEST(ShapePairPolygon, RoundedConvexFingerIsExact) {
  std::mt19937_64 rng(703);
  const Shape object = RandomObject(rng, 16);
  const Shape finger = Shape::Box(0.1, 0.04, 0.01);
  const ShapePairQuerier q(object, finger);
  for (int i = 0; i < Scaled(12, 4); ++i) {
    const Pose2 op = RandomPose(rng);
    const Pose2 fp = FingerPoseNear(rng, object, op, std::uniform_real_distribution<double>(-0.08, 0.1)(rng));
    const ShapePairResult r = q.Query(op, fp);
    EXPECT_NEAR(r.signed_distance, MinkowskiOracle(object, op, finger, fp), 1e-10) << Str(op) << " " << Str(fp);
    CheckWitnesses(q, op, fp, r, "rounded box finger");
  }
}

TEST(ShapePairPolygon, ObstacleCachePerRelativeAngle) {
  std::mt19937_64 rng(704);
  const Shape object = RandomObject(rng, 12);
  const Shape finger = RandomFinger(rng);
  ShapePairQuerier q(object, finger);
  EXPECT_EQ(q.obstacles_built(), 0);
  // Overlapping configurations at the same relative angle (0.25 = 0.5 - 0.25 = 0.75 - 0.5, exact).
  const ShapePairResult a = q.Query(Pose2{0, 0, 0.25}, Pose2{0.02, -0.03, 0.5});
  const int built = q.obstacles_built();
  EXPECT_LE(built, 1);
  const ShapePairResult b =
      q.Query(Pose2{1, 2, 0.5}, Compose(Pose2{1, 2, 0.5}, Between(Pose2{0, 0, 0.25}, Pose2{0.02, -0.03, 0.5})));
  EXPECT_EQ(q.obstacles_built(), built) << "same relative angle must reuse the obstacle";
  EXPECT_NEAR(a.signed_distance, b.signed_distance, 1e-12);
  q.Query(Pose2{0, 0, 0.25}, Pose2{0.02, -0.03, 0.5 + 1e-3});
  EXPECT_LE(q.obstacles_built(), built + 1);
  // Move semantics keep the cache usable.
  ShapePairQuerier moved(Shape::Box(1, 1), Shape::Disk(0.1));
  moved = std::move(q);
  ShapePairQuerier constructed(std::move(moved));
  EXPECT_EQ(constructed.object().num_vertices(), object.num_vertices());
  EXPECT_NEAR(constructed.Query(Pose2{0, 0, 0.25}, Pose2{0.02, -0.03, 0.5}).signed_distance, a.signed_distance, 0.0);
}

// ---------------------------------------------------------------------------------------------
// kVertexSampling against kExact.

TEST(ShapePairPolygon, VertexSamplingErrorIsBoundedAndReported) {
  std::mt19937_64 rng(705);
  ShapePairQuerier::Options vs;
  vs.method = ShapePairQuerier::Method::kVertexSampling;
  double max_err = 0.0, sum_err = 0.0, max_rel = 0.0, max_diameter_ratio = 0.0;
  int overlaps = 0, apart = 0, exact_hits = 0;
  for (int c = 0; c < Scaled(5, 2); ++c) {
    const Shape object = RandomObject(rng, 12 + 2 * c);
    const Shape finger = RandomFinger(rng, c % 2 ? 0.005 : 0.0);
    const ShapePairQuerier exact(object, finger), fast(object, finger, vs);
    double finger_diameter = 0.0;
    for (const Vec2& a : finger.polygons()[0].outer)
      for (const Vec2& b : finger.polygons()[0].outer) finger_diameter = std::max(finger_diameter, (a - b).norm());
    finger_diameter += 2 * finger.radius();
    for (int i = 0; i < Scaled(10, 4); ++i) {
      const Pose2 op = RandomPose(rng);
      const Pose2 fp = FingerPoseNear(rng, object, op, std::uniform_real_distribution<double>(-0.1, 0.2)(rng));
      const ShapePairResult e = exact.Query(op, fp), f = fast.Query(op, fp);
      const std::string ctx = "object " + Str(op) + " finger " + Str(fp);
      CheckWitnesses(fast, op, fp, f, "kVertexSampling " + ctx);
      if (e.signed_distance > 1e-9) {
        ++apart;
        EXPECT_NEAR(f.signed_distance, e.signed_distance, 1e-12) << "apart: must be exact; " << ctx;
        EXPECT_FALSE(f.intersecting) << ctx;
      } else if (e.signed_distance < -1e-9) {
        ++overlaps;
        // The depth of a vertex inside the other shape is a lower bound of the true depth, and
        // the fast path never reports separation for overlapping shapes: 0 <= err <= depth.
        EXPECT_GE(f.signed_distance, e.signed_distance - 1e-12) << ctx;
        const double err = f.signed_distance - e.signed_distance;
        EXPECT_LE(f.signed_distance, 1e-12) << "overlapping shapes reported apart; " << ctx;
        EXPECT_TRUE(f.intersecting) << ctx;
        max_diameter_ratio = std::max(max_diameter_ratio, err / finger_diameter);
        max_err = std::max(max_err, err);
        max_rel = std::max(max_rel, err / e.depth);
        sum_err += err;
        exact_hits += err <= 1e-12;
      }
    }
  }
  EXPECT_GT(apart, 0);
  EXPECT_GT(overlaps, 0);
  std::printf("[ kVertexSampling vs kExact ] %d overlapping configurations: max error %.3g, mean %.3g, "
              "max relative to depth %.3g, max relative to finger diameter %.3g, exact in %d\n",
              overlaps, max_err, overlaps ? sum_err / overlaps : 0.0, max_rel, max_diameter_ratio, exact_hits);
  ::testing::Test::RecordProperty("vertex_sampling_max_error", std::to_string(max_err));
  ::testing::Test::RecordProperty("vertex_sampling_mean_error", std::to_string(overlaps ? sum_err / overlaps : 0.0));
}

// Two squares whose edges lie along each other: every vertex of each is on the other's boundary
// or outside, none inside, yet they overlap (the fast path said "apart", signed distance 0, for
// squares overlapping by half: `pushgraph penetration sq.json sq.json --finger-pose 0.05,0,0
// --fast`). Side by side they only touch.
TEST(ShapePairPolygon, VertexSamplingSeesSquaresOverlappingAlongTheirEdges) {
  const Shape square = Shape::FromPolygons({Polygon{{{0, 0}, {0.1, 0}, {0.1, 0.1}, {0, 0.1}}, {}}});
  ShapePairQuerier::Options vs;
  vs.method = ShapePairQuerier::Method::kVertexSampling;
  const ShapePairQuerier exact(square, square), fast(square, square, vs);
  for (double turn : {0.0, 0.3, -1.2}) {
    const Pose2 object{0.01, -0.02, turn};
    for (const Vec2& shift : {Vec2(0.05, 0.0), Vec2(0.0, 0.05), Vec2(0.0, 0.0), Vec2(0.1, 0.0), Vec2(0.1, 0.1),
                              Vec2(0.02, 0.1)}) {
      const Pose2 finger = Compose(object, Pose2{shift.x(), shift.y(), 0.0});
      const ShapePairResult e = exact.Query(object, finger), f = fast.Query(object, finger);
      const std::string ctx = "turn " + std::to_string(turn) + ", shift (" + std::to_string(shift.x()) + ", " +
                              std::to_string(shift.y()) + ")";
      // Turned, the side-by-side squares' rounded vertices may overlap by 1e-17: the exact path's
      // answer on those coordinates, which the fast one must give too.
      EXPECT_EQ(f.intersecting, e.intersecting) << ctx;
      EXPECT_NEAR(f.signed_distance, e.signed_distance, 1e-12) << ctx;
      if (std::abs(shift.x()) + std::abs(shift.y()) < 0.1 - 1e-9) {
        EXPECT_NEAR(e.depth, 0.1 - shift.norm(), 1e-12) << ctx;
      }
    }
  }
}

TEST(ShapePairPolygon, VertexSamplingIsExactForDiskFingers) {
  std::mt19937_64 rng(706);
  ShapePairQuerier::Options vs;
  vs.method = ShapePairQuerier::Method::kVertexSampling;
  const Shape object = RandomObject(rng, 20);
  const ShapePairQuerier exact(object, Shape::Disk(0.03)), fast(object, Shape::Disk(0.03), vs);
  for (int i = 0; i < Scaled(200, 30); ++i) {
    const Pose2 op = RandomPose(rng);
    const Pose2 fp = FingerPoseNear(rng, object, op, std::uniform_real_distribution<double>(-0.1, 0.1)(rng));
    EXPECT_NEAR(fast.Query(op, fp).signed_distance, exact.Query(op, fp).signed_distance, 1e-15) << Str(op) << Str(fp);
  }
}

}  // namespace
}  // namespace pushgraph::geometry
