// Point queries: closed forms on rounded primitives, exact boundary points with representable
// coordinates, medial-axis ties, invariants on random non-convex shapes, posed queries, and the
// accelerated query against the brute-force reference bit for bit (64 to 10000 vertices).
// The CGAL Epeck oracle comparisons are in test_point_query_exact.cpp.
#include <pushgraph/geometry/point_query.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

using testing::Scaled;
constexpr double kEps = std::numeric_limits<double>::epsilon();

std::string Str(const Vec2& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

const char* Name(Containment c) {
  switch (c) {
    case Containment::kInside: return "inside";
    case Containment::kOutside: return "outside";
    default: return "on boundary";
  }
}

::testing::AssertionResult Near(const Vec2& a, const Vec2& b, double tol) {
  if ((a - b).norm() <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << Str(a) << " vs " << Str(b) << " (|diff| " << (a - b).norm()
                                       << " > " << tol << ")";
}

// ---------------------------------------------------------------------------------------------
// Rounded primitives: closed forms.

TEST(PointQueryDisk, ClosedForm) {
  const Vec2 c(1.0, 2.0);
  const Shape disk = Shape::Disk(5.0, c);
  std::mt19937_64 rng(201);
  std::uniform_real_distribution<double> u(-12, 12);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(u(rng), u(rng));
    const PointQuery q = QueryPoint(disk, p);
    const double d = (p - c).norm();
    EXPECT_NEAR(q.signed_distance, d - 5.0, 1e-14 * (1 + d)) << Str(p);
    EXPECT_TRUE(Near(q.normal, (p - c) / d, 1e-14)) << Str(p);
    EXPECT_TRUE(Near(q.closest_point, c + 5.0 * (p - c) / d, 1e-13)) << Str(p);
    EXPECT_EQ(q.containment, d < 5.0 ? Containment::kInside : Containment::kOutside) << Str(p);
    EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kVertex);
    EXPECT_EQ(q.feature.edge.polygon, 0);
    EXPECT_EQ(q.feature.edge.ring, -1);
    EXPECT_EQ(q.feature.edge.index, 0);
  }
}

TEST(PointQueryDisk, ExactContainmentAtRadius) {
  // |p - c| == r exactly for the 3-4-5 triangle, at several dyadic scales.
  for (double s : {1.0, 0.125, 1.0 / 1024, 64.0}) {
    const Vec2 c(0.5 * s, -0.25 * s);
    const Shape disk = Shape::Disk(5.0 * s, c);
    for (const Vec2& d : {Vec2(3, 4), Vec2(-3, 4), Vec2(4, -3), Vec2(-4, -3), Vec2(5, 0), Vec2(0, -5)}) {
      const Vec2 p = c + s * d;
      const PointQuery q = QueryPoint(disk, p);
      EXPECT_EQ(q.containment, Containment::kOnBoundary) << "scale " << s << " " << Str(p);
      EXPECT_EQ(Contains(disk, p), Containment::kOnBoundary);
      EXPECT_NEAR(q.signed_distance, 0.0, 1e-15 * s);
      // One ulp in or out decides exactly.
      const Vec2 out(p.x(), std::nextafter(p.y(), p.y() > c.y() ? 1e300 : -1e300));
      const Vec2 in(p.x(), std::nextafter(p.y(), c.y()));
      if (d.y() != 0) {
        EXPECT_EQ(Contains(disk, out), Containment::kOutside) << Str(out);
        EXPECT_EQ(Contains(disk, in), Containment::kInside) << Str(in);
        EXPECT_EQ(QueryPoint(disk, out).containment, Containment::kOutside);
        EXPECT_EQ(QueryPoint(disk, in).containment, Containment::kInside);
      }
    }
  }
}

TEST(PointQueryDisk, CentreConvention) {
  const Shape disk = Shape::Disk(0.25, Vec2(1.0, -1.0));
  const PointQuery q = QueryPoint(disk, Vec2(1.0, -1.0));
  EXPECT_EQ(q.containment, Containment::kInside);
  EXPECT_EQ(q.signed_distance, -0.25);
  EXPECT_EQ(q.normal, Vec2(1.0, 0.0));
  EXPECT_TRUE(Near(q.closest_point, Vec2(1.25, -1.0), 1e-15));
  Vec2 g;
  EXPECT_EQ(SignedDistance(disk, Vec2(1.0, -1.0), &g), -0.25);
  EXPECT_EQ(g, Vec2(1.0, 0.0));
}

double SegmentDistance(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 e = b - a;
  const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (a + t * e - p).norm();
}

TEST(PointQueryCapsule, ClosedForm) {
  const Vec2 a(-1.0, 0.5), b(2.0, 1.5);
  const double r = 0.3;
  const Shape cap = Shape::Capsule(a, b, r);
  EXPECT_TRUE(cap.is_degenerate_core());
  EXPECT_TRUE(cap.is_convex());
  std::mt19937_64 rng(202);
  std::uniform_real_distribution<double> u(-3, 4);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(u(rng), u(rng));
    const double d = SegmentDistance(a, b, p);
    if (d < 1e-9) continue;
    const PointQuery q = QueryPoint(cap, p);
    EXPECT_NEAR(q.signed_distance, d - r, 1e-13) << Str(p);
    EXPECT_NEAR(q.normal.norm(), 1.0, 1e-14);
    EXPECT_TRUE(Near(q.closest_point + (d - r) * q.normal, p, 1e-12)) << Str(p);
    EXPECT_EQ(q.containment, d < r ? Containment::kInside : Containment::kOutside) << Str(p);
  }
  // Side of the segment and the end caps.
  const Shape flat = Shape::Capsule(Vec2(0, 0), Vec2(8, 0), 5.0);
  PointQuery q = QueryPoint(flat, Vec2(4, 7));
  EXPECT_EQ(q.signed_distance, 2.0);
  EXPECT_EQ(q.normal, Vec2(0, 1));
  EXPECT_TRUE(Near(q.closest_point, Vec2(4, 5), 0.0));
  EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kEdge);
  EXPECT_DOUBLE_EQ(q.feature.t, 0.5);  // either direction of the segment's two edges
  q = QueryPoint(flat, Vec2(4, -7));
  EXPECT_EQ(q.normal, Vec2(0, -1));
  EXPECT_TRUE(Near(q.closest_point, Vec2(4, -5), 0.0));
  q = QueryPoint(flat, Vec2(-2, 0));
  EXPECT_EQ(q.signed_distance, -3.0);
  EXPECT_EQ(q.containment, Containment::kInside);
  EXPECT_EQ(q.normal, Vec2(-1, 0));
  EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kVertex);
  // Exact containment on the rounded boundary: cap (3-4-5) and side.
  for (const Vec2& p : {Vec2(-3, 4), Vec2(11, -4), Vec2(4, 5), Vec2(0.5, -5)}) {
    EXPECT_EQ(Contains(flat, p), Containment::kOnBoundary) << Str(p);
    EXPECT_EQ(QueryPoint(flat, p).containment, Containment::kOnBoundary) << Str(p);
    EXPECT_EQ(QueryPoint(flat, p).signed_distance, 0.0) << Str(p);
  }
  EXPECT_EQ(Contains(flat, Vec2(-3, std::nextafter(4.0, 5.0))), Containment::kOutside);
  EXPECT_EQ(Contains(flat, Vec2(-3, std::nextafter(4.0, 3.0))), Containment::kInside);
  EXPECT_EQ(Contains(flat, Vec2(4, std::nextafter(5.0, 6.0))), Containment::kOutside);
}

double BoxSd(double hw, double hh, const Vec2& p) {  // exact-math SDF of a box (unrounded)
  const Vec2 d(std::abs(p.x()) - hw, std::abs(p.y()) - hh);
  const Vec2 o(std::max(d.x(), 0.0), std::max(d.y(), 0.0));
  return o.norm() + std::min(std::max(d.x(), d.y()), 0.0);
}

TEST(PointQueryBox, ClosedFormUnrounded) {
  const Shape box = Shape::Box(4.0, 2.0);
  EXPECT_EQ(box.radius(), 0.0);
  EXPECT_TRUE(box.is_convex());
  EXPECT_FALSE(box.is_degenerate_core());
  EXPECT_EQ(box.num_vertices(), 4);
  EXPECT_DOUBLE_EQ(box.core_area(), 8.0);
  EXPECT_EQ(box.bounds().min, Vec2(-2, -1));
  EXPECT_EQ(box.bounds().max, Vec2(2, 1));
  std::mt19937_64 rng(203);
  std::uniform_real_distribution<double> u(-4, 4);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(u(rng), u(rng));
    const PointQuery q = QueryPoint(box, p);
    EXPECT_NEAR(q.signed_distance, BoxSd(2, 1, p), 1e-14) << Str(p);
    EXPECT_NEAR(std::abs(q.signed_distance), (p - q.closest_point).norm(), 1e-14) << Str(p);
  }
  PointQuery q = QueryPoint(box, Vec2(3, 2));
  EXPECT_TRUE(Near(q.closest_point, Vec2(2, 1), 0.0));
  EXPECT_TRUE(Near(q.normal, Vec2(1, 1).normalized(), 1e-15));
  EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kVertex);
  // On an edge and on a vertex: exactly zero; vertex normal = normalized sum of edge normals.
  q = QueryPoint(box, Vec2(2, 0.5));
  EXPECT_EQ(q.containment, Containment::kOnBoundary);
  EXPECT_EQ(q.signed_distance, 0.0);
  EXPECT_EQ(q.normal, Vec2(1, 0));
  q = QueryPoint(box, Vec2(-2, 1));
  EXPECT_EQ(q.containment, Containment::kOnBoundary);
  EXPECT_EQ(q.signed_distance, 0.0);
  EXPECT_TRUE(Near(q.normal, Vec2(-1, 1).normalized(), 1e-15));
  EXPECT_TRUE(Near(q.closest_point, Vec2(-2, 1), 0.0));
}

TEST(PointQueryBox, Rounded) {
  const Shape box = Shape::Box(4.0, 2.0, 5.0);  // core 4 x 2, rounded by 5
  EXPECT_EQ(box.radius(), 5.0);
  EXPECT_TRUE(box.is_convex());
  EXPECT_DOUBLE_EQ(box.core_area(), 8.0);
  EXPECT_EQ(box.bounds().min, Vec2(-7, -6));
  EXPECT_EQ(box.bounds().max, Vec2(7, 6));
  std::mt19937_64 rng(204);
  std::uniform_real_distribution<double> u(-9, 9);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(u(rng), u(rng));
    const PointQuery q = QueryPoint(box, p);
    EXPECT_NEAR(q.signed_distance, BoxSd(2, 1, p) - 5.0, 1e-13) << Str(p);
    const PointQuery core = QueryPoint(box.WithRadius(0.0), p);
    EXPECT_TRUE(Near(q.closest_point, core.closest_point + 5.0 * core.normal, 1e-13)) << Str(p);
    EXPECT_TRUE(Near(q.normal, core.normal, 0.0)) << Str(p);
  }
  // Corner arc: (2,1) + (3,4) is exactly on the rounded boundary.
  for (const Vec2& p : {Vec2(5, 5), Vec2(-6, 4), Vec2(-5, -5), Vec2(0, 6), Vec2(7, 0.5)}) {
    EXPECT_EQ(Contains(box, p), Containment::kOnBoundary) << Str(p);
    EXPECT_EQ(QueryPoint(box, p).containment, Containment::kOnBoundary) << Str(p);
  }
  EXPECT_EQ(Contains(box, Vec2(5, std::nextafter(5.0, 6.0))), Containment::kOutside);
  EXPECT_EQ(Contains(box, Vec2(5, std::nextafter(5.0, 4.0))), Containment::kInside);
  // Deep inside: rounded-shape convention (core sd - r).
  const PointQuery c = QueryPoint(box, Vec2(0, 0));
  EXPECT_EQ(c.signed_distance, -6.0);
  EXPECT_EQ(c.containment, Containment::kInside);
  EXPECT_NEAR(std::abs(c.closest_point.y()), 6.0, 1e-15);
  EXPECT_EQ(c.closest_point.x(), 0.0);
}

TEST(PointQueryRegularPolygon, InradiusAndVertices) {
  for (int n : {3, 5, 6, 17}) {
    const Shape s = Shape::RegularPolygon(n, 2.0);
    EXPECT_EQ(s.num_vertices(), n);
    EXPECT_TRUE(s.is_convex());
    const double pi = testing::kPi;
    EXPECT_NEAR(s.core_area(), 0.5 * n * 4.0 * std::sin(2 * pi / n), 1e-12);
    EXPECT_NEAR(QueryPoint(s, Vec2::Zero()).signed_distance, -2.0 * std::cos(pi / n), 1e-14);
    for (const Vec2& v : s.polygons()[0].outer) {
      EXPECT_NEAR(v.norm(), 2.0, 1e-14);
      EXPECT_NEAR(QueryPoint(s, 1.5 * v).signed_distance, 0.5 * v.norm(), 1e-13);
    }
    const Shape r = Shape::RegularPolygon(n, 2.0, 0.25);
    EXPECT_NEAR(QueryPoint(r, Vec2::Zero()).signed_distance, -2.0 * std::cos(pi / n) - 0.25, 1e-14);
  }
}

// ---------------------------------------------------------------------------------------------
// Exact boundary points with representable coordinates, medial-axis ties.

Shape CombWithTriangle() {
  Polygon tri;
  tri.outer = {{20, 0}, {23, 1}, {20, 3}};
  return Shape::FromPolygons({testing::DyadicComb(), tri});
}

TEST(PointQueryExactBoundary, RepresentablePointsOnEdgesAndVertices) {
  const Shape s = CombWithTriangle();
  std::vector<std::pair<Vec2, Vec2>> on_edges = {
      // point, expected outward normal
      {{3, 0}, {0, -1}},      {{8, 1}, {1, 0}},      {{7, 2}, {0, 1}},     {{6, 4}, {1, 0}},
      {{5, 6}, {0, 1}},       {{4, 4}, {-1, 0}},     {{3, 2}, {0, 1}},     {{2, 5}, {1, 0}},
      {{1, 8}, {0, 1}},       {{0, 3}, {-1, 0}},     {{0.0625, 0}, {0, -1}},
      // hole edges: the outward normal of the shape points into the hole
      {{1, 0.5}, {0, 1}},     {{1.5, 1}, {-1, 0}},   {{0.75, 1.5}, {0, -1}}, {{0.5, 0.625}, {1, 0}},
      // slanted triangle edges: (20,0)-(23,1) contains (20.75, 0.25); (23,1)-(20,3) (21.5, 2)
      {{20.75, 0.25}, Vec2(1, -3).normalized()}, {{21.5, 2}, Vec2(2, 3).normalized()},
      {{20, 1.5}, {-1, 0}}};
  for (const auto& [p, n] : on_edges) {
    const PointQuery q = QueryPoint(s, p);
    EXPECT_EQ(q.containment, Containment::kOnBoundary) << Str(p) << " got " << Name(q.containment);
    EXPECT_EQ(Contains(s, p), Containment::kOnBoundary) << Str(p);
    EXPECT_EQ(q.signed_distance, 0.0) << Str(p);
    EXPECT_TRUE(Near(q.closest_point, p, 4 * kEps * p.norm())) << Str(p);
    EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kEdge) << Str(p);
    EXPECT_TRUE(Near(q.normal, n, 1e-15)) << Str(p);
    EXPECT_EQ(SignedDistance(s, p), 0.0) << Str(p);
  }
  for (const auto& ref : testing::AllRings(s))
    for (const Vec2& v : *ref.points) {
      const PointQuery q = QueryPoint(s, v);
      EXPECT_EQ(q.containment, Containment::kOnBoundary) << Str(v);
      EXPECT_EQ(q.signed_distance, 0.0) << Str(v);
      EXPECT_EQ(q.closest_point, v) << Str(v);
      EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kVertex) << Str(v);
      EXPECT_NEAR(q.normal.norm(), 1.0, 1e-15) << Str(v);
    }
  // The comb's reflex vertex (4,2): normalized sum of the edge normals (0,1) and (-1,0)?
  // Edges at (4,2): (4,6)->(4,2) has outward normal (-1,0); (4,2)->(2,2) has (0,1).
  EXPECT_TRUE(Near(QueryPoint(s, Vec2(4, 2)).normal, Vec2(-1, 1).normalized(), 1e-15));
  // Convex vertex (8,0): (0,-1) + (1,0).
  EXPECT_TRUE(Near(QueryPoint(s, Vec2(8, 0)).normal, Vec2(1, -1).normalized(), 1e-15));
}

TEST(PointQueryExactBoundary, OneUlpOffTheBoundary) {
  const Shape s = CombWithTriangle();
  // Outside / inside by one ulp of the coordinate across an axis-aligned edge.
  EXPECT_EQ(Contains(s, Vec2(3, std::nextafter(0.0, -1.0))), Containment::kOutside);
  EXPECT_EQ(Contains(s, Vec2(3, std::nextafter(0.0, 1.0))), Containment::kInside);
  EXPECT_EQ(Contains(s, Vec2(std::nextafter(8.0, 9.0), 1)), Containment::kOutside);
  EXPECT_EQ(Contains(s, Vec2(std::nextafter(8.0, 7.0), 1)), Containment::kInside);
  // Into the hole by one ulp.
  EXPECT_EQ(Contains(s, Vec2(1, std::nextafter(0.5, 1.0))), Containment::kOutside);
  EXPECT_EQ(Contains(s, Vec2(1, std::nextafter(0.5, 0.0))), Containment::kInside);
  const PointQuery q = QueryPoint(s, Vec2(3, std::nextafter(0.0, -1.0)));
  EXPECT_GE(q.signed_distance, 0.0);  // exact value: the smallest subnormal
  EXPECT_LE(q.signed_distance, 4 * std::nextafter(0.0, 1.0));
  const double tiny = std::ldexp(1.0, -60);
  EXPECT_NEAR(QueryPoint(s, Vec2(3, -tiny)).signed_distance, tiny, 4 * kEps * tiny);
  EXPECT_NEAR(QueryPoint(s, Vec2(3, tiny)).signed_distance, -tiny, 4 * kEps * tiny);
  EXPECT_NEAR(QueryPoint(s, Vec2(1, 0.5 + 0.5 * kEps)).signed_distance, 0.5 * kEps, 4 * kEps * kEps);
  EXPECT_GT(QueryPoint(s, Vec2(std::nextafter(8.0, 9.0), 1)).signed_distance, 0.0);
  EXPECT_LT(QueryPoint(s, Vec2(std::nextafter(8.0, 7.0), 1)).signed_distance, 0.0);
  // Slanted edge (20,0)-(23,1): one ulp in y off (20.75, 0.25).
  EXPECT_EQ(Contains(s, Vec2(20.75, std::nextafter(0.25, 0.0))), Containment::kOutside);
  EXPECT_EQ(Contains(s, Vec2(20.75, std::nextafter(0.25, 1.0))), Containment::kInside);
  EXPECT_GT(QueryPoint(s, Vec2(20.75, std::nextafter(0.25, 0.0))).signed_distance, 0.0);
  EXPECT_LT(QueryPoint(s, Vec2(20.75, std::nextafter(0.25, 1.0))).signed_distance, 0.0);
}

TEST(PointQueryExactBoundary, MedialAxisTies) {
  const Shape square = Shape::Box(2.0, 2.0);
  std::mt19937_64 rng(205);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const double t = u(rng);
    for (const Vec2& p : {Vec2(t, t), Vec2(t, -t)}) {
      const PointQuery q = QueryPoint(square, p);
      const double d = 1.0 - std::abs(t);  // correctly rounded exact distance
      EXPECT_NEAR(q.signed_distance, -d, 4 * kEps * d) << Str(p);
      EXPECT_EQ(q.containment, Containment::kInside);
      EXPECT_EQ(q.feature.kind, BoundaryFeature::Kind::kEdge);
      EXPECT_NEAR(std::abs(q.normal.x()) + std::abs(q.normal.y()), 1.0, 0.0) << Str(p);
      EXPECT_NEAR((p - q.closest_point).norm(), d, 8 * kEps) << Str(p);
    }
  }
  const PointQuery c = QueryPoint(square, Vec2(0, 0));  // four-way tie
  EXPECT_EQ(c.signed_distance, -1.0);
  EXPECT_EQ(c.closest_point.norm(), 1.0);
  // Outside a convex corner on the diagonal: the vertex.
  const PointQuery v = QueryPoint(square, Vec2(2, 2));
  EXPECT_EQ(v.feature.kind, BoundaryFeature::Kind::kVertex);
  EXPECT_EQ(v.closest_point, Vec2(1, 1));
}

// ---------------------------------------------------------------------------------------------
// Invariants on random non-convex shapes with holes.

void CheckInvariants(const Shape& s, const Vec2& p, const std::string& ctx) {
  const PointQuery q = QueryPoint(s, p);
  const double r = s.radius();
  ASSERT_TRUE(std::isfinite(q.signed_distance)) << ctx;
  EXPECT_NEAR(q.normal.norm(), 1.0, 1e-14) << ctx;
  EXPECT_EQ(Contains(s, p), q.containment) << ctx;
  switch (q.containment) {
    case Containment::kInside: EXPECT_LE(q.signed_distance, 0.0) << ctx; break;
    case Containment::kOutside: EXPECT_GE(q.signed_distance, 0.0) << ctx; break;
    default:
      if (r == 0.0) {
        EXPECT_EQ(q.signed_distance, 0.0) << ctx;
      }
  }
  // p = closest + sd * normal.
  const double scale = std::max(1.0, p.norm());
  EXPECT_TRUE(Near(q.closest_point + q.signed_distance * q.normal, p, 1e-13 * scale)) << ctx;
  // The feature is valid and the core closest point lies on it.
  const auto& f = q.feature;
  ASSERT_GE(f.edge.polygon, 0) << ctx;
  ASSERT_LT(f.edge.polygon, static_cast<int>(s.polygons().size())) << ctx;
  const Ring& ring = s.ring(f.edge.polygon, f.edge.ring);
  ASSERT_GE(f.edge.index, 0) << ctx;
  ASSERT_LT(f.edge.index, static_cast<int>(ring.size())) << ctx;
  const Vec2 core_closest = q.closest_point - r * q.normal;
  const Vec2 a = ring[static_cast<size_t>(f.edge.index)];
  if (f.kind == BoundaryFeature::Kind::kVertex) {
    if (r == 0.0) {
      EXPECT_EQ(q.closest_point, a) << ctx;
    } else {
      EXPECT_TRUE(Near(core_closest, a, 1e-14 * scale)) << ctx;
    }
  } else {
    const Vec2 b = ring[(static_cast<size_t>(f.edge.index) + 1) % ring.size()];
    EXPECT_GT(f.t, 0.0) << ctx;
    EXPECT_LT(f.t, 1.0) << ctx;
    EXPECT_TRUE(Near(core_closest, a + f.t * (b - a), 1e-13 * scale)) << ctx;
    // Edge normal: outward = right of the direction of travel (interior on the left).
    const Vec2 e = (b - a).normalized();
    EXPECT_TRUE(Near(q.normal, Vec2(e.y(), -e.x()), 1e-14)) << ctx;
  }
  // The closest point is on the boundary. (Rounded: the closest point of the core moved by r,
  // which lies in the shape but, inside notches narrower than 2r, not on its boundary.)
  const double sd_at_closest = QueryPoint(s, q.closest_point).signed_distance;
  if (r == 0.0) {
    EXPECT_NEAR(sd_at_closest, 0.0, 1e-13 * scale) << ctx;
  } else {
    EXPECT_LE(sd_at_closest, 1e-13 * scale) << ctx;
    if (q.containment == Containment::kOutside) {
      EXPECT_NEAR(sd_at_closest, 0.0, 1e-13 * scale) << ctx;
    }
  }
}

TEST(PointQueryRandom, InvariantsOnNonConvexPolygonsWithHoles) {
  std::mt19937_64 rng(206);
  for (int shape_i = 0; shape_i < Scaled(12, 4); ++shape_i) {
    testing::RandomPolygonOptions o;
    o.outer_vertices = 8 + 7 * shape_i;
    const auto polys = testing::RandomPolygons(rng, 1 + shape_i % 3, o);
    for (double r : {0.0, 0.02}) {
      const Shape s = Shape::FromPolygons(polys, r);
      for (int i = 0; i < Scaled(300, 30); ++i) {
        const Vec2 p = testing::RandomPointNear(rng, s.bounds(), 0.3);
        CheckInvariants(s, p, "shape " + std::to_string(shape_i) + " r " + std::to_string(r) + " p " + Str(p));
      }
      for (const Vec2& p : testing::NearBoundaryPoints(rng, s, Scaled(100, 20), 1e-9))
        CheckInvariants(s, p, "near boundary, shape " + std::to_string(shape_i) + " p " + Str(p));
    }
  }
}

TEST(PointQueryRandom, RoundedIsCoreMinusRadius) {
  std::mt19937_64 rng(207);
  const auto polys = testing::RandomPolygons(rng, 2);
  const Shape core = Shape::FromPolygons(polys);
  for (double r : {1e-6, 0.01, 0.3}) {
    const Shape s = core.WithRadius(r);
    EXPECT_EQ(s.radius(), r);
    EXPECT_EQ(s.num_vertices(), core.num_vertices());
    for (int i = 0; i < Scaled(300, 30); ++i) {
      const Vec2 p = testing::RandomPointNear(rng, s.bounds(), 0.3);
      const PointQuery qc = QueryPoint(core, p), qr = QueryPoint(s, p);
      EXPECT_NEAR(qr.signed_distance, qc.signed_distance - r, 4 * std::numeric_limits<double>::epsilon() * (std::abs(qc.signed_distance) + r)) << Str(p);
      EXPECT_TRUE(Near(qr.closest_point, qc.closest_point + r * qc.normal, 1e-14 * (1 + p.norm()))) << Str(p);
      EXPECT_TRUE(Near(qr.normal, qc.normal, 1e-15)) << Str(p);
      const Containment expect = qc.containment != Containment::kOutside ? Containment::kInside
                                 : qc.signed_distance < r ? Containment::kInside
                                                          : Containment::kOutside;
      if (std::abs(qc.signed_distance - r) > 1e-12) {
        EXPECT_EQ(qr.containment, expect) << Str(p);
      }
    }
  }
}

TEST(PointQueryRandom, IndependentOfInputOrientationAndStartVertex) {
  std::mt19937_64 rng(209);
  testing::RandomPolygonOptions o;
  o.reverse_some_rings = false;
  o.outer_vertices = 30;
  const std::vector<Polygon> polys = testing::RandomPolygons(rng, 2, o);
  std::vector<Polygon> flipped = polys;
  for (Polygon& p : flipped) {
    std::reverse(p.outer.begin(), p.outer.end());
    std::rotate(p.outer.begin(), p.outer.begin() + 7, p.outer.end());
    for (Ring& h : p.holes) {
      std::reverse(h.begin(), h.end());
      std::rotate(h.begin(), h.begin() + 2, h.end());
    }
  }
  const Shape a = Shape::FromPolygons(polys), b = Shape::FromPolygons(flipped);
  std::vector<Vec2> pts;
  for (int i = 0; i < Scaled(1000, 100); ++i) pts.push_back(testing::RandomPointNear(rng, a.bounds(), 0.2));
  for (const Vec2& p : testing::NearBoundaryPoints(rng, a, Scaled(300, 30), 1e-12)) pts.push_back(p);
  for (const Vec2& p : pts) {
    const PointQuery qa = QueryPoint(a, p), qb = QueryPoint(b, p);
    EXPECT_EQ(qa.containment, qb.containment) << Str(p);
    EXPECT_NEAR(qa.signed_distance, qb.signed_distance, 4 * kEps * std::abs(qa.signed_distance)) << Str(p);
    EXPECT_TRUE(Near(qa.closest_point, qb.closest_point, 1e-15 + 4 * kEps * p.norm())) << Str(p);
  }
}

// ---------------------------------------------------------------------------------------------
// Posed queries equal the local query mapped through the pose.

TEST(PointQueryPosed, MatchesLocalQuery) {
  std::mt19937_64 rng(208);
  const Shape s = Shape::FromPolygons(testing::RandomPolygons(rng, 2), 0.01);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < Scaled(300, 30); ++i) {
    const Pose2 pose{u(rng), u(rng), u(rng)};
    const Vec2 local = testing::RandomPointNear(rng, s.bounds(), 0.3);
    const Vec2 world = Act(pose, local);
    const PointQuery w = QueryPoint(s, pose, world);
    const PointQuery l = QueryPoint(s, InverseAct(pose, world));
    EXPECT_NEAR(w.signed_distance, l.signed_distance, 1e-14 * (1 + world.norm()));
    EXPECT_TRUE(Near(w.closest_point, Act(pose, l.closest_point), 1e-13 * (1 + world.norm())));
    EXPECT_TRUE(Near(w.normal, pose.rotation() * l.normal, 1e-14));
    EXPECT_EQ(w.containment, l.containment);
    PointQueryJacobians J;
    const PointQuery wj = QueryPoint(s, pose, world, &J);
    EXPECT_EQ(wj.signed_distance, w.signed_distance);  // asking for Jacobians changes nothing
    EXPECT_EQ(wj.closest_point, w.closest_point);
  }
}

// ---------------------------------------------------------------------------------------------
// Accelerated query == brute force, bit for bit.

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

::testing::AssertionResult BitIdentical(const PointQuery& a, const PointQuery& b) {
  const bool same =
      a.containment == b.containment && BitEqual(a.signed_distance, b.signed_distance) &&
      BitEqual(a.closest_point.x(), b.closest_point.x()) &&
      BitEqual(a.closest_point.y(), b.closest_point.y()) && BitEqual(a.normal.x(), b.normal.x()) &&
      BitEqual(a.normal.y(), b.normal.y()) && a.feature.kind == b.feature.kind &&
      a.feature.edge.polygon == b.feature.edge.polygon && a.feature.edge.ring == b.feature.edge.ring &&
      a.feature.edge.index == b.feature.edge.index && BitEqual(a.feature.t, b.feature.t);
  if (same) return ::testing::AssertionSuccess();
  std::ostringstream s;
  s.precision(17);
  auto dump = [&](const char* tag, const PointQuery& q) {
    s << tag << ": " << Name(q.containment) << " sd " << q.signed_distance << " closest "
      << Str(q.closest_point) << " normal " << Str(q.normal) << " feature "
      << (q.feature.kind == BoundaryFeature::Kind::kEdge ? "edge" : "vertex") << " ("
      << q.feature.edge.polygon << "," << q.feature.edge.ring << "," << q.feature.edge.index
      << ") t " << q.feature.t << "\n";
  };
  dump("QueryPoint          ", a);
  dump("QueryPointBruteForce", b);
  return ::testing::AssertionFailure() << s.str();
}

void CompareWithBruteForce(const Shape& s, int n_points, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec2> pts;
  for (int i = 0; i < n_points; ++i) pts.push_back(testing::RandomPointNear(rng, s.bounds(), 0.2));
  for (int i = 0; i < n_points / 10; ++i) pts.push_back(testing::RandomPointNear(rng, s.bounds(), 1000.0));
  for (const Vec2& p : testing::NearBoundaryPoints(rng, s, n_points / 5, 1e-12)) pts.push_back(p);
  for (const Vec2& p : testing::NearBoundaryPoints(rng, s, n_points / 10, 1e-3)) pts.push_back(p);
  const auto rings = testing::AllRings(s);
  for (int i = 0; i < n_points / 10; ++i) {  // exact vertices
    const Ring& r = *rings[static_cast<size_t>(i) % rings.size()].points;
    pts.push_back(r[static_cast<size_t>(i * 7919) % r.size()]);
  }
  int failures = 0;
  for (const Vec2& p : pts) {
    const auto res = BitIdentical(QueryPoint(s, p), QueryPointBruteForce(s, p));
    if (!res && ++failures <= 5) ADD_FAILURE() << "at " << Str(p) << "\n" << res.message();
  }
  EXPECT_EQ(failures, 0) << "of " << pts.size() << " points";
}

Shape BigStar(int n, int holes, uint64_t seed, double radius = 0.0) {
  std::mt19937_64 rng(seed);
  testing::RandomPolygonOptions o;
  o.outer_vertices = n;
  o.max_holes = holes;
  o.hole_vertices = std::max(5, n / 20);
  // Force the requested number of holes by retrying the (cheap) generator.
  for (int tries = 0; tries < 100; ++tries) {
    Polygon p = testing::RandomPolygonWithHoles(rng, Vec2(0.3, -0.1), o);
    if (static_cast<int>(p.holes.size()) == holes || tries == 99) return Shape::FromPolygons({p}, radius);
  }
  return {};
}

TEST(PointQueryAccelerated, BitIdenticalToBruteForce64) {
  CompareWithBruteForce(BigStar(64, 2, 301), Scaled(20000, 2000), 311);
  CompareWithBruteForce(BigStar(64, 1, 302, 0.05), Scaled(5000, 500), 312);
}

TEST(PointQueryAccelerated, BitIdenticalToBruteForce1000) {
  CompareWithBruteForce(BigStar(1000, 3, 303), Scaled(5000, 500), 313);
  std::mt19937_64 rng(304);
  testing::RandomPolygonOptions o;
  o.outer_vertices = 300;
  CompareWithBruteForce(Shape::FromPolygons(testing::RandomPolygons(rng, 3, o)), Scaled(3000, 300), 314);
}

TEST(PointQueryAccelerated, BitIdenticalToBruteForce10000) {
  const Shape s = BigStar(10000, 2, 305);
  EXPECT_GE(s.num_vertices(), 10000);
  CompareWithBruteForce(s, Scaled(1000, 100), 315);
}

// The index on regular polygons (near-circular: the strip tree's sectors) at the points where
// bounding-box indexes read every edge: the exact centre, near it, the spokes (medial axis),
// deep inside and far outside; bit for bit against the brute force.
TEST(PointQueryAccelerated, BitIdenticalToBruteForceOnRegularPolygons) {
  std::mt19937_64 rng(316);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const int n : {100, 5000, Scaled(50000, 5000)}) {
    for (const Vec2& centre : {Vec2(0.0, 0.0), Vec2(0.3, -0.7)}) {
      const Shape s = TransformShape(Shape::RegularPolygon(n, 0.05), Pose2{centre.x(), centre.y(), 0.3});
      std::vector<Vec2> pts{centre};
      for (int i = 0; i < Scaled(200, 40); ++i) {
        const double a = 2.0 * testing::kPi * unit(rng);
        const Vec2 dir(std::cos(a), std::sin(a));
        pts.push_back(centre + 0.05 * std::pow(10.0, -14.0 + 12.0 * unit(rng)) * dir);
        pts.push_back(centre + 0.05 * unit(rng) * dir);
        pts.push_back(centre + 0.05 * std::pow(10.0, 1.0 + 3.0 * unit(rng)) * dir);
        const Ring& ring = s.polygons()[0].outer;
        const Vec2& v = ring[std::uniform_int_distribution<std::size_t>(0, ring.size() - 1)(rng)];
        pts.push_back(centre + unit(rng) * (v - centre));
      }
      int failures = 0;
      for (const Vec2& p : pts) {
        const auto res = BitIdentical(QueryPoint(s, p), QueryPointBruteForce(s, p));
        if (!res && ++failures <= 5) ADD_FAILURE() << n << " vertices, at " << Str(p) << "\n" << res.message();
      }
      EXPECT_EQ(failures, 0) << n << " vertices, of " << pts.size() << " points";
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Errors.

TEST(PointQueryErrors, EmptyShapeAndNonFinitePoints) {
  const Shape empty;
  EXPECT_TRUE(empty.empty());
  EXPECT_THROW(QueryPoint(empty, Vec2(0, 0)), GeometryError);
  EXPECT_THROW(Contains(empty, Vec2(0, 0)), GeometryError);
  EXPECT_THROW(SignedDistance(empty, Vec2(0, 0)), GeometryError);
  EXPECT_THROW(QueryPointBruteForce(empty, Vec2(0, 0)), GeometryError);
  const Shape box = Shape::Box(1, 1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const Vec2& p : {Vec2(nan, 0), Vec2(0, nan), Vec2(inf, 0), Vec2(0, -inf)}) {
    EXPECT_THROW(QueryPoint(box, p), GeometryError) << Str(p);
    EXPECT_THROW(QueryPoint(box, Pose2{}, p), GeometryError) << Str(p);
    EXPECT_THROW(Contains(box, p), GeometryError) << Str(p);
    EXPECT_THROW(SignedDistance(box, p), GeometryError) << Str(p);
  }
  EXPECT_THROW(QueryPoint(box, Pose2{nan, 0, 0}, Vec2(0, 0)), GeometryError);
}

}  // namespace
}  // namespace pushgraph::geometry
