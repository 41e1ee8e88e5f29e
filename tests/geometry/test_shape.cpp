// Shape construction: normalization, accessors, and every bad-input case of the issue, with the
// error's polygon/ring/vertex and its message.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

double TwiceSignedArea(const Ring& r) {
  double a = 0.0;
  for (size_t i = 0; i < r.size(); ++i) {
    const Vec2& p = r[i];
    const Vec2& q = r[(i + 1) % r.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return a;
}

/// True if b is a cyclic rotation of a or of reversed a.
bool SameRingUpToOrientation(Ring a, const Ring& b) {
  if (a.size() != b.size()) return false;
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t s = 0; s < a.size(); ++s) {
      bool eq = true;
      for (size_t i = 0; i < a.size() && eq; ++i) eq = a[(i + s) % a.size()] == b[i];
      if (eq) return true;
    }
    std::reverse(a.begin(), a.end());
  }
  return false;
}

Ring Square(double x0, double y0, double side) {
  return {{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
}

// ---------------------------------------------------------------------------------------------
// Normalization and accessors.

// Beyond the documented magnitudes squared distances overflow or underflow: a side of 1e300 gave
// distance 0 and normal (0, 0), a side of 1e-300 a non-unit normal. Refused, saying which limit.
TEST(ShapeConstruction, MagnitudesOutsideTheSupportedRangeAreRefused) {
  auto message = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const GeometryError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { Shape::Box(1e300, 1e300); }).find("outside the supported range"), std::string::npos);
  EXPECT_NE(message([] { Shape::Box(1e-300, 1e-300); }).find("below the supported"), std::string::npos);
  EXPECT_NE(message([] { Shape::Disk(1e300); }).find("above the supported"), std::string::npos);
  EXPECT_NE(message([] { Shape::Box(1.0, 1.0).WithRadius(1e9); }).find("above the supported"), std::string::npos);
  const Shape unit = Shape::Box(1.0, 1.0);
  EXPECT_NE(message([&] { QueryPoint(unit, Vec2(1e300, 0.0)); }).find("outside the supported range"), std::string::npos);
  // The largest and smallest supported shapes still answer exactly, with unit normals.
  const Shape big = Shape::Box(2e6, 2e6);
  const PointQuery q = QueryPoint(big, Vec2(2e6, 0.5e6));
  EXPECT_EQ(q.signed_distance, 1e6);
  EXPECT_EQ(q.normal, Vec2(1.0, 0.0));
  const Shape tiny = Shape::Box(2e-9, 2e-9);
  const PointQuery t = QueryPoint(tiny, Vec2(3e-9, 1e-9));
  EXPECT_NEAR(t.signed_distance, 2e-9, 1e-24);  // 3e-9 - 1e-9, rounded once
  EXPECT_NEAR(t.normal.norm(), 1.0, 1e-15);
}

TEST(ShapeConstruction, NormalizesOrientation) {
  Ring outer_cw = Square(0, 0, 4);
  std::reverse(outer_cw.begin(), outer_cw.end());
  const Ring hole_ccw = Square(1, 1, 1);
  const Shape s = Shape::FromPolygons({Polygon{outer_cw, {hole_ccw}}});
  ASSERT_EQ(s.polygons().size(), 1u);
  const Polygon& p = s.polygons()[0];
  EXPECT_GT(TwiceSignedArea(p.outer), 0.0) << "outer must be stored counter-clockwise";
  ASSERT_EQ(p.holes.size(), 1u);
  EXPECT_LT(TwiceSignedArea(p.holes[0]), 0.0) << "holes must be stored clockwise";
  EXPECT_TRUE(SameRingUpToOrientation(outer_cw, p.outer));
  EXPECT_TRUE(SameRingUpToOrientation(hole_ccw, p.holes[0]));
  EXPECT_DOUBLE_EQ(s.core_area(), 15.0);
  EXPECT_EQ(s.num_vertices(), 8);
  EXPECT_FALSE(s.is_convex());  // a hole makes it non-convex
  EXPECT_FALSE(s.is_degenerate_core());
  EXPECT_EQ(s.bounds().min, Vec2(0, 0));
  EXPECT_EQ(s.bounds().max, Vec2(4, 4));
  EXPECT_EQ(&s.ring(0, -1), &s.polygons()[0].outer);
  EXPECT_EQ(&s.ring(0, 0), &s.polygons()[0].holes[0]);
  EXPECT_THROW(s.ring(1, -1), GeometryError);
  EXPECT_THROW(s.ring(0, 1), GeometryError);
  EXPECT_THROW(s.ring(0, -2), GeometryError);
}

TEST(ShapeConstruction, RandomShapesKeepTheirVertices) {
  std::mt19937_64 rng(401);
  for (int i = 0; i < 30; ++i) {
    testing::RandomPolygonOptions o;
    o.outer_vertices = 6 + 3 * i;
    const auto polys = testing::RandomPolygons(rng, 1 + i % 3, o);
    const Shape s = Shape::FromPolygons(polys, i % 2 ? 0.01 : 0.0);
    ASSERT_EQ(s.polygons().size(), polys.size());
    int n = 0;
    double area = 0.0;
    for (size_t k = 0; k < polys.size(); ++k) {
      const Polygon& in = polys[k];
      const Polygon& out = s.polygons()[k];
      EXPECT_TRUE(SameRingUpToOrientation(in.outer, out.outer));
      EXPECT_GT(TwiceSignedArea(out.outer), 0.0);
      area += 0.5 * std::abs(TwiceSignedArea(in.outer));
      n += static_cast<int>(in.outer.size());
      ASSERT_EQ(in.holes.size(), out.holes.size());
      for (size_t h = 0; h < in.holes.size(); ++h) {
        EXPECT_TRUE(SameRingUpToOrientation(in.holes[h], out.holes[h]));
        EXPECT_LT(TwiceSignedArea(out.holes[h]), 0.0);
        area -= 0.5 * std::abs(TwiceSignedArea(in.holes[h]));
        n += static_cast<int>(in.holes[h].size());
      }
    }
    EXPECT_EQ(s.num_vertices(), n);
    EXPECT_NEAR(s.core_area(), area, 1e-12 * area);
    const double r = s.radius();
    Box2 b{polys[0].outer[0], polys[0].outer[0]};
    for (const auto& p : polys)
      for (const Vec2& v : p.outer) {
        b.min = b.min.cwiseMin(v);
        b.max = b.max.cwiseMax(v);
      }
    EXPECT_EQ(s.bounds().min, (b.min - Vec2::Constant(r)).eval());
    EXPECT_EQ(s.bounds().max, (b.max + Vec2::Constant(r)).eval());
  }
}

TEST(ShapeConstruction, ExplicitClosingVertexIsDropped) {
  Ring r = Square(0, 0, 1);
  r.push_back(r.front());
  const Shape s = Shape::FromPolygons({Polygon{r, {}}});
  EXPECT_EQ(s.num_vertices(), 4);
}

TEST(ShapeConstruction, ConvexityAndDegenerateCores) {
  EXPECT_TRUE(Shape::Box(1, 2).is_convex());
  EXPECT_TRUE(Shape::RegularPolygon(7, 1).is_convex());
  // Refused before any allocation (1e9 corners ran out of memory).
  EXPECT_THROW(Shape::RegularPolygon(1000000000, 1), GeometryError);
  EXPECT_THROW(Shape::RegularPolygon(2, 1), GeometryError);
  EXPECT_TRUE(Shape::Disk(0.1).is_convex());
  EXPECT_TRUE(Shape::Disk(0.1).is_degenerate_core());
  EXPECT_TRUE(Shape::Capsule(Vec2(0, 0), Vec2(1, 0), 0.1).is_degenerate_core());
  EXPECT_FALSE(Shape::Box(1, 2, 0.1).is_degenerate_core());
  EXPECT_FALSE(Shape::FromPolygons({testing::DyadicComb()}).is_convex());
  // Collinear vertex on a convex ring: still convex.
  EXPECT_TRUE(Shape::FromPolygons({Polygon{{{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}}, {}}}).is_convex());
  // Two disjoint convex polygons: not one convex polygon.
  EXPECT_FALSE(Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}, Polygon{Square(3, 0, 1), {}}}).is_convex());
  const Shape disk = Shape::Disk(0.5, Vec2(1, 2));
  EXPECT_EQ(disk.radius(), 0.5);
  EXPECT_EQ(disk.num_vertices(), 1);
  EXPECT_EQ(disk.core_area(), 0.0);
  EXPECT_EQ(disk.bounds().min, Vec2(0.5, 1.5));
  EXPECT_EQ(disk.bounds().max, Vec2(1.5, 2.5));
  const Shape cap = Shape::Capsule(Vec2(0, 0), Vec2(2, 1), 0.25);
  EXPECT_EQ(cap.num_vertices(), 2);
  EXPECT_EQ(cap.bounds().min, Vec2(-0.25, -0.25));
  EXPECT_EQ(cap.bounds().max, Vec2(2.25, 1.25));
}

TEST(ShapeConstruction, PolygonInsideAnotherPolygonsHoleIsAllowed) {
  Polygon ring_shape{Square(0, 0, 10), {Square(2, 2, 6)}};
  Polygon island{Square(4, 4, 2), {}};
  const Shape s = Shape::FromPolygons({ring_shape, island});
  EXPECT_EQ(s.polygons().size(), 2u);
  EXPECT_DOUBLE_EQ(s.core_area(), 100.0 - 36.0 + 4.0);
}

TEST(ShapeConstruction, WithRadius) {
  const Shape s = Shape::Box(2, 2);
  const Shape r = s.WithRadius(0.5);
  EXPECT_EQ(r.radius(), 0.5);
  EXPECT_EQ(s.radius(), 0.0);
  EXPECT_EQ(r.polygons()[0].outer, s.polygons()[0].outer);
  EXPECT_THROW(s.WithRadius(-1.0), GeometryError);
  EXPECT_THROW(s.WithRadius(std::numeric_limits<double>::quiet_NaN()), GeometryError);
  EXPECT_THROW(Shape::Disk(1.0).WithRadius(0.0), GeometryError);
}

TEST(ShapeConstruction, EmptyShape) {
  const Shape s;
  EXPECT_TRUE(s.empty());
  EXPECT_FALSE(Shape::Box(1, 1).empty());
  EXPECT_THROW(s.radius(), GeometryError);
  EXPECT_THROW(s.polygons(), GeometryError);
  EXPECT_THROW(s.bounds(), GeometryError);
}

// ---------------------------------------------------------------------------------------------
// Bad input.

/// Expected location: exact values, or -2 for "any" (the vertex of a crossing may be any of the
/// edges' vertices); allowed vertex set when given.
struct Where {
  int polygon;
  int ring;
  std::vector<int> vertices;  ///< allowed vertex indices; empty = do not check
};

::testing::AssertionResult ThrowsAt(const std::function<void()>& make, const Where& w,
                                    const std::string& what_contains = "") {
  try {
    make();
  } catch (const GeometryError& e) {
    const std::string msg = e.what();
    auto fail = [&]() {
      return ::testing::AssertionFailure() << "GeometryError(polygon " << e.polygon() << ", ring "
                                           << e.ring() << ", vertex " << e.vertex() << "): " << msg
                                           << "\n";
    };
    if (w.polygon != -2 && e.polygon() != w.polygon) return fail() << "expected polygon " << w.polygon;
    if (w.ring != -2 && e.ring() != w.ring) return fail() << "expected ring " << w.ring;
    if (!w.vertices.empty() &&
        std::find(w.vertices.begin(), w.vertices.end(), e.vertex()) == w.vertices.end())
      return fail() << "unexpected vertex";
    // what() names the location it reports.
    if (e.polygon() >= 0 &&
        !std::regex_search(msg, std::regex("polygon\\D{0,3}" + std::to_string(e.polygon()) + "(\\D|$)")))
      return fail() << "what() does not name polygon " << e.polygon();
    if (e.ring() >= 0 &&
        !std::regex_search(msg, std::regex("hole\\D{0,3}" + std::to_string(e.ring()) + "(\\D|$)")))
      return fail() << "what() does not name hole " << e.ring();
    if (e.vertex() >= 0 &&
        !std::regex_search(msg, std::regex("vertex\\D{0,3}" + std::to_string(e.vertex()) + "(\\D|$)")))
      return fail() << "what() does not name vertex " << e.vertex();
    if (!what_contains.empty() && msg.find(what_contains) == std::string::npos)
      return fail() << "what() does not mention \"" << what_contains << "\"";
    return ::testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "threw a non-GeometryError: " << e.what();
  }
  return ::testing::AssertionFailure() << "did not throw";
}

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

// A tessellated cylinder (a round probe's mesh) is read as its disk; nothing else is.
TEST(TessellatedDisk, ARegularPolygonOfManyCornersIsItsDiskAndNothingElseIs) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 20 + static_cast<int>(unit(rng) * 60.0);
    const double r = 1e-3 * (1.0 + 20.0 * unit(rng));
    const Vec2 centre(0.05 * (unit(rng) - 0.5), 0.05 * (unit(rng) - 0.5));
    const double turn = 2.0 * M_PI * unit(rng);
    Ring ring;
    for (int i = 0; i < n; ++i) {
      const double a = turn + 2.0 * M_PI * i / n;
      ring.push_back(centre + r * Vec2(std::cos(a), std::sin(a)));
    }
    const std::optional<TessellatedDiskFit> fit = TessellatedDisk(Shape::FromPolygons({Polygon{ring, {}}}));
    ASSERT_TRUE(fit.has_value()) << n << "-gon";
    EXPECT_EQ(fit->corners, static_cast<std::size_t>(n));
    EXPECT_NEAR(fit->disk.radius(), r, 1e-12);
    EXPECT_LT((fit->disk.polygons()[0].outer[0] - centre).norm(), 1e-12);
    // A seam vertex of an exact union (a point on an edge) is no corner. (A near-duplicate, the
    // other kind, is refused by FromPolygons; the CLI's y-up tip.obj test has one.)
    Ring seams = ring;
    seams.insert(seams.begin() + 3, 0.5 * (ring[2] + ring[3]));
    const std::optional<TessellatedDiskFit> with_seams = TessellatedDisk(Shape::FromPolygons({Polygon{seams, {}}}));
    ASSERT_TRUE(with_seams.has_value());
    EXPECT_EQ(with_seams->corners, static_cast<std::size_t>(n));
    // One corner 1 % out: a polygon, not a disk.
    Ring dented = ring;
    dented[n / 2] = centre + 1.01 * (ring[n / 2] - centre);
    EXPECT_FALSE(TessellatedDisk(Shape::FromPolygons({Polygon{dented, {}}})).has_value()) << n;
    // Rounded, or with a hole: kept as given.
    EXPECT_FALSE(TessellatedDisk(Shape::FromPolygons({Polygon{ring, {}}}, 1e-4)).has_value());
  }
  EXPECT_FALSE(TessellatedDisk(Shape::RegularPolygon(12, 0.005)).has_value());  // a 12-gon is no disk
  EXPECT_TRUE(TessellatedDisk(Shape::RegularPolygon(20, 0.005)).has_value());
  EXPECT_FALSE(TessellatedDisk(Shape::Disk(0.005)).has_value());
  EXPECT_FALSE(TessellatedDisk(Shape::Box(0.01, 0.01)).has_value());
  Ring outer, hole;
  for (int i = 0; i < 32; ++i) {
    const double a = 2.0 * M_PI * i / 32;
    outer.push_back(0.01 * Vec2(std::cos(a), std::sin(a)));
  }
  hole = {{-0.001, -0.001}, {-0.001, 0.001}, {0.001, 0.001}, {0.001, -0.001}};
  EXPECT_FALSE(TessellatedDisk(Shape::FromPolygons({Polygon{outer, {hole}}})).has_value());
}

TEST(ShapeBadInput, SelfIntersectingBowTie) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {1, 1}, {1, 0}, {0, 1}}, {}}}); },
                       {0, -1, {0, 1, 2, 3}}));
  // Bow-tie as the second polygon, and as a hole.
  EXPECT_TRUE(ThrowsAt(
      [] {
        Shape::FromPolygons({Polygon{Square(-5, -5, 1), {}}, Polygon{{{0, 0}, {1, 1}, {1, 0}, {0, 1}}, {}}});
      },
      {1, -1, {0, 1, 2, 3}}));
  EXPECT_TRUE(ThrowsAt(
      [] {
        Shape::FromPolygons({Polygon{Square(-5, -5, 10), {Square(-4, -4, 1), {{0, 0}, {1, 1}, {1, 0}, {0, 1}}}}});
      },
      {0, 1, {0, 1, 2, 3}}));
  // Ring touching itself at a vertex (figure eight).
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{{{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}, {}}}); },
      {0, -1, {}}));
  // A non-adjacent edge passing through a vertex.
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{{{0, 0}, {4, 0}, {4, 4}, {2, 0}, {0, 4}}, {}}}); }, {0, -1, {}}));
  // Long bow-ties crossing far from vertex 0: 20 points in convex position (on a circle) with
  // vertices 5 and 12 swapped; the chords 4-12 and 5-13 then interleave and must cross.
  std::mt19937_64 rng(402);
  std::uniform_real_distribution<double> u(0.1, 3.0);
  for (int i = 0; i < 20; ++i) {
    const double phase = u(rng), radius = u(rng);
    Polygon p;
    for (int k = 0; k < 20; ++k) {
      const double a = phase + 2 * testing::kPi * k / 20;
      p.outer.emplace_back(radius * std::cos(a), radius * std::sin(a));
    }
    std::swap(p.outer[5], p.outer[12]);
    EXPECT_TRUE(ThrowsAt([&] { Shape::FromPolygons({p}); }, {0, -1, {}})) << "case " << i;
  }
}

TEST(ShapeBadInput, RepeatedVertexZeroLengthEdge) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {1, 0}, {1, 0}, {0, 1}}, {}}}); },
                       {0, -1, {1, 2}}));
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {{{1, 1}, {1, 2}, {2, 2}, {2, 2}, {2, 1}}}}}); },
      {0, 0, {2, 3}}));
  // Segment with two equal vertices.
  EXPECT_TRUE(ThrowsAt([] { Shape::Capsule(Vec2(1, 1), Vec2(1, 1), 0.5); }, {0, -1, {}}));
}

TEST(ShapeBadInput, CollinearZeroArea) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {1, 0}, {2, 0}}, {}}}); }, {0, -1, {}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {1, 1}, {3, 3}, {2, 2}}, {}}}); },
                       {0, -1, {}}));
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {{{1, 1}, {2, 1}, {3, 1}}}}}); }, {0, 0, {}}));
  // A zero-width spike folding back on itself.
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{{{0, 0}, {4, 0}, {6, 0}, {4, 0.0 + 0.0}, {4, 4}, {0, 4}}, {}}}); },
      {0, -1, {}}));
}

TEST(ShapeBadInput, HoleOutsideOrCrossingOuterBoundary) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {Square(5, 5, 1)}}}); }, {0, 0, {}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {Square(3, 1, 2)}}}); }, {0, -2, {}}));
  // Hole containing the whole outer boundary.
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(1, 1, 1), {Square(0, 0, 4)}}}); }, {0, -2, {}}));
  // Hole touching the outer boundary (must be strictly inside).
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {Square(0, 1, 1)}}}); }, {0, -2, {}}));
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {{{0, 2}, {1, 1}, {1, 3}}}}}); }, {0, -2, {}}));
  // Hole in the second polygon: the polygon index is right.
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(10, 0, 4), {}}, Polygon{Square(0, 0, 4), {Square(5, 5, 1)}}}); },
      {1, 0, {}}));
  // A hole on a point or segment core.
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}}, {Square(1, 1, 1)}}}, 1.0); }, {0, -2, {}}));
  // A hole with fewer than 3 vertices.
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 4), {{{1, 1}, {2, 2}}}}}); }, {0, 0, {}}));
}

TEST(ShapeBadInput, OverlappingHoles) {
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 10), {Square(1, 1, 3), Square(2, 2, 3)}}}); },
      {0, -2, {}}));
  // Nested holes (no crossing).
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 10), {Square(1, 1, 6), Square(2, 2, 1)}}}); },
      {0, -2, {}}));
  // Touching holes (shared edge).
  EXPECT_TRUE(ThrowsAt(
      [] { Shape::FromPolygons({Polygon{Square(0, 0, 10), {Square(1, 1, 2), Square(3, 1, 2)}}}); },
      {0, -2, {}}));
  // The ring index of a crossing hole must be one of the two.
  try {
    Shape::FromPolygons({Polygon{Square(0, 0, 10), {Square(6, 6, 1), Square(1, 1, 3), Square(2, 2, 3)}}});
    ADD_FAILURE() << "overlapping holes accepted";
  } catch (const GeometryError& e) {
    EXPECT_EQ(e.polygon(), 0);
    EXPECT_TRUE(e.ring() == 1 || e.ring() == 2) << e.what();
  }
}

TEST(ShapeBadInput, OverlappingOrTouchingPolygons) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 2), {}}, Polygon{Square(1, 1, 2), {}}}); },
                       {-2, -2, {}}));
  // Nested: the second polygon inside the first's material.
  try {
    Shape::FromPolygons({Polygon{Square(0, 0, 10), {}}, Polygon{Square(2, 2, 1), {}}});
    ADD_FAILURE() << "nested polygons accepted";
  } catch (const GeometryError& e) {
    EXPECT_TRUE(e.polygon() == 0 || e.polygon() == 1) << e.what();
  }
  // The first inside the second.
  EXPECT_THROW(Shape::FromPolygons({Polygon{Square(2, 2, 1), {}}, Polygon{Square(0, 0, 10), {}}}), GeometryError);
  // Sharing an edge is not allowed; neither is a vertex of one lying inside an edge of the other.
  // Said as such (it was "boundary crosses polygon 1 ... at their shared vertex": they do not cross).
  try {
    Shape::FromPolygons({Polygon{Square(0, 0, 2), {}}, Polygon{Square(2, 0, 2), {}}});
    ADD_FAILURE() << "squares sharing an edge accepted";
  } catch (const GeometryError& e) {
    EXPECT_NE(std::string(e.what()).find("runs along polygon"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not along edges"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Shape::FromPolygons({Polygon{Square(0, 0, 2), {}}, Polygon{{{2, 1}, {3, 0}, {3, 2}}, {}}}), GeometryError);
  // Rings crossing each other through a vertex they share are rejected...
  const Ring notched = {{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}};
  EXPECT_THROW(Shape::FromPolygons({Polygon{notched, {}}, Polygon{{{1, 1}, {3, 0.5}, {3, 2.5}, {0.5, 2.5}}, {}}}),
               GeometryError);
  // ...while touching at a shared vertex (exact footprints of real meshes have such corners) is a
  // valid shape, and queries near the corner see both parts.
  const Shape corners = Shape::FromPolygons({Polygon{Square(0, 0, 2), {}}, Polygon{Square(2, 2, 2), {}}});
  EXPECT_EQ(QueryPoint(corners, Vec2(2, 2)).containment, Containment::kOnBoundary);
  EXPECT_EQ(QueryPoint(corners, Vec2(2, 2)).signed_distance, 0.0);
  EXPECT_EQ(QueryPoint(corners, Vec2(1.9, 1.95)).containment, Containment::kInside);
  EXPECT_EQ(QueryPoint(corners, Vec2(2.1, 2.05)).containment, Containment::kInside);
  EXPECT_EQ(QueryPoint(corners, Vec2(1.9, 2.05)).containment, Containment::kOutside);
  EXPECT_EQ(QueryPoint(corners, Vec2(2.1, 1.95)).containment, Containment::kOutside);
  const Shape notch_touch = Shape::FromPolygons({Polygon{notched, {}}, Polygon{{{1, 1}, {3, 0.5}, {3, 1.5}}, {}}});
  EXPECT_EQ(QueryPoint(notch_touch, Vec2(1.2, 1.0)).containment, Containment::kInside);
  EXPECT_EQ(QueryPoint(notch_touch, Vec2(1.2, 1.1)).containment, Containment::kOutside);
  // Polygon 2 of 3 overlaps polygon 0: polygons named are 0 or 2, never 1.
  try {
    Shape::FromPolygons({Polygon{Square(0, 0, 2), {}}, Polygon{Square(5, 0, 2), {}}, Polygon{Square(1, 1, 2), {}}});
    ADD_FAILURE() << "overlap accepted";
  } catch (const GeometryError& e) {
    EXPECT_TRUE(e.polygon() == 0 || e.polygon() == 2) << e.what();
  }
  // A point core together with another polygon is not a valid shape either.
  EXPECT_THROW(Shape::FromPolygons({Polygon{{{20, 20}}, {}}, Polygon{Square(0, 0, 1), {}}}, 0.5), GeometryError);
}

TEST(ShapeBadInput, NonFiniteCoordinates) {
  EXPECT_TRUE(ThrowsAt(
      [] {
        Polygon a{Square(0, 0, 1), {}};
        Polygon b{Square(0, 5, 4), {Square(1, 6, 1), {{2.5, 6}, {3.5, 6}, {3.5, kNaN}, {2.5, 7}}}};
        Shape::FromPolygons({a, b});
      },
      {1, 1, {2}}, "finite"));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {kInf, 0}, {1, 1}}, {}}}); }, {0, -1, {1}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{0, 0}, {1, 0}, {1, -kInf}}, {}}}); }, {0, -1, {2}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{kNaN, 0}}, {}}}, 1.0); }, {0, -1, {0}}));
  EXPECT_THROW(Shape::Disk(1.0, Vec2(kNaN, 0)), GeometryError);
  EXPECT_THROW(Shape::Capsule(Vec2(0, 0), Vec2(kInf, 0), 1.0), GeometryError);
}

TEST(ShapeBadInput, PointOrSegmentWithoutRadius) {
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{1, 1}}, {}}}, 0.0); }, {0, -1, {}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{{1, 1}, {2, 2}}, {}}}, 0.0); }, {0, -1, {}}));
  EXPECT_THROW(Shape::Disk(0.0), GeometryError);
  EXPECT_THROW(Shape::Capsule(Vec2(0, 0), Vec2(1, 0), 0.0), GeometryError);
  EXPECT_NO_THROW(Shape::Disk(1e-9));
}

TEST(ShapeBadInput, NegativeOrNonFiniteRadius) {
  EXPECT_THROW(Shape::Disk(-1.0), GeometryError);
  EXPECT_THROW(Shape::Capsule(Vec2(0, 0), Vec2(1, 0), -0.1), GeometryError);
  EXPECT_THROW(Shape::Box(1, 1, -0.1), GeometryError);
  EXPECT_THROW(Shape::RegularPolygon(5, 1, -0.1), GeometryError);
  EXPECT_THROW(Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}}, -0.5), GeometryError);
  EXPECT_THROW(Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}}, kNaN), GeometryError);
  EXPECT_THROW(Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}}, kInf), GeometryError);
  try {
    Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}}, -0.5);
  } catch (const GeometryError& e) {
    EXPECT_NE(std::string(e.what()).find("radius"), std::string::npos) << e.what();
  }
}

TEST(ShapeBadInput, EmptyInputs) {
  EXPECT_THROW(Shape::FromPolygons({}), GeometryError);
  EXPECT_THROW(Shape::FromPolygons({}, 1.0), GeometryError);
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{{}, {}}}, 1.0); }, {0, -1, {}}));
  EXPECT_TRUE(ThrowsAt([] { Shape::FromPolygons({Polygon{Square(0, 0, 1), {}}, Polygon{{}, {}}}); }, {1, -1, {}}));
  EXPECT_THROW(Shape::Box(0, 1), GeometryError);
  EXPECT_THROW(Shape::Box(1, -1), GeometryError);
  EXPECT_THROW(Shape::RegularPolygon(2, 1), GeometryError);
  EXPECT_THROW(Shape::RegularPolygon(5, 0), GeometryError);
}

}  // namespace
}  // namespace pushgraph::geometry
