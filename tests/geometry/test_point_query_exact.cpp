// Exactness of the point queries against an independent CGAL Epeck (exact rational) oracle:
// containment exactly; signed distance within 4 ulps, checked exactly (the interval
// [|sd| - tol, |sd| + tol] is squared in exact arithmetic and must bracket the exact minimum
// squared distance, so the oracle itself adds no rounding); the reported feature's exact
// squared distance equals the exact minimum; closest point within a few ulps of the coordinate
// magnitude. Query points include random points, points 1e-12 from edges and vertices, exact
// vertices, exact edge points with representable coordinates, medial-axis ties and far points.
#include <pushgraph/geometry/point_query.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/squared_distance_2.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

using EK = CGAL::Exact_predicates_exact_constructions_kernel;
using FT = EK::FT;
using EPoint = EK::Point_2;
using ESegment = EK::Segment_2;
using testing::Scaled;

double Ulp(double x) {
  x = std::abs(x);
  if (x == 0.0) return std::numeric_limits<double>::denorm_min();
  return std::nextafter(x, std::numeric_limits<double>::infinity()) - x;
}

std::string Str(const Vec2& p) {
  std::ostringstream s;
  s.precision(17);
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

EPoint E(const Vec2& p) { return EPoint(p.x(), p.y()); }

/// The exact oracle: the shape's normalized rings as Epeck points.
class ExactOracle {
 public:
  explicit ExactOracle(const Shape& s) : radius_(s.radius()) {
    for (const auto& p : s.polygons()) {
      std::vector<std::vector<EPoint>> rings;
      rings.push_back(ToE(p.outer));
      for (const auto& h : p.holes) rings.push_back(ToE(h));
      polygons_.push_back(std::move(rings));
    }
  }

  /// Exact containment of the core (unrounded) polygons.
  Containment CoreContainment(const EPoint& p) const {
    for (const auto& rings : polygons_) {
      if (rings[0].size() < 3) continue;  // point or segment core: no interior
      for (const auto& r : rings)
        if (CGAL::bounded_side_2(r.begin(), r.end(), p, EK()) == CGAL::ON_BOUNDARY)
          return Containment::kOnBoundary;
      if (CGAL::bounded_side_2(rings[0].begin(), rings[0].end(), p, EK()) != CGAL::ON_BOUNDED_SIDE) continue;
      bool in_hole = false;
      for (size_t h = 1; h < rings.size(); ++h)
        in_hole = in_hole || CGAL::bounded_side_2(rings[h].begin(), rings[h].end(), p, EK()) == CGAL::ON_BOUNDED_SIDE;
      if (!in_hole) return Containment::kInside;
    }
    return Containment::kOutside;
  }

  /// Exact minimum squared distance from p to the core boundary.
  FT MinSquaredDistance(const EPoint& p) const {
    bool first = true;
    FT best = 0;
    for (const auto& rings : polygons_)
      for (const auto& r : rings)
        for (size_t i = 0; i < r.size(); ++i) {
          const FT d = r.size() == 1 ? CGAL::squared_distance(p, r[0])
                                     : CGAL::squared_distance(p, ESegment(r[i], r[(i + 1) % r.size()]));
          if (first || d < best) best = d;
          first = false;
        }
    return best;
  }

  /// Exact containment of the rounded shape.
  Containment RoundedContainment(const EPoint& p, const FT& min_sq) const {
    const Containment core = CoreContainment(p);
    if (radius_ == 0.0) return core;
    if (core != Containment::kOutside) return Containment::kInside;
    const FT r = radius_;
    const auto c = CGAL::compare(min_sq, r * r);
    return c == CGAL::SMALLER ? Containment::kInside : c == CGAL::EQUAL ? Containment::kOnBoundary : Containment::kOutside;
  }

  /// Exact squared distance from p to a reported feature.
  FT FeatureSquaredDistance(const EPoint& p, const BoundaryFeature& f) const {
    const auto& r = Ring(f.edge);
    const EPoint& a = r.at(static_cast<size_t>(f.edge.index));
    if (f.kind == BoundaryFeature::Kind::kVertex) return CGAL::squared_distance(p, a);
    const EPoint& b = r[(static_cast<size_t>(f.edge.index) + 1) % r.size()];
    return CGAL::squared_distance(p, ESegment(a, b));
  }

  const std::vector<EPoint>& Ring(const EdgeId& e) const {
    return polygons_.at(static_cast<size_t>(e.polygon)).at(static_cast<size_t>(e.ring + 1));
  }

 private:
  static std::vector<EPoint> ToE(const pushgraph::geometry::Ring& r) {
    std::vector<EPoint> out;
    for (const Vec2& v : r) out.push_back(E(v));
    return out;
  }
  double radius_;
  std::vector<std::vector<std::vector<EPoint>>> polygons_;
};

/// Exact check that the true value s * sqrt(m) (s = +-1) lies in [lo, hi].
bool SignedSqrtInInterval(int s, const FT& m, const FT& lo, const FT& hi) {
  FT L = lo, H = hi;
  if (s < 0) {  // -sqrt(m) in [lo, hi]  <=>  sqrt(m) in [-hi, -lo]
    L = -hi;
    H = -lo;
  }
  if (H < 0) return false;
  if (H * H < m) return false;
  if (L > 0 && L * L > m) return false;
  return true;
}

const char* Name(Containment c) {
  return c == Containment::kInside ? "inside" : c == Containment::kOutside ? "outside" : "on boundary";
}

struct ExactStats {
  int points = 0, zero = 0, ties = 0, failures = 0;
};

/// Compares one query with the oracle; returns false (and reports) on a contract violation.
void CheckAgainstOracle(const Shape& shape, const ExactOracle& oracle, const Vec2& p, const std::string& ctx,
                        ExactStats* stats, int ulps = 4) {
  const PointQuery q = QueryPoint(shape, p);
  const EPoint ep = E(p);
  const FT m = oracle.MinSquaredDistance(ep);
  const Containment core = oracle.CoreContainment(ep);
  const Containment expect = oracle.RoundedContainment(ep, m);
  const double r = shape.radius();
  ++stats->points;
  std::ostringstream err;
  err.precision(17);
  // 1. Containment: exact.
  if (q.containment != expect) err << "containment " << Name(q.containment) << ", exact " << Name(expect) << "; ";
  if (Contains(shape, p) != expect) err << "Contains() " << Name(Contains(shape, p)) << ", exact " << Name(expect) << "; ";
  // 2. Signed distance.
  const double d_approx = std::sqrt(CGAL::to_double(m));
  if (m == 0 && r == 0.0) {
    ++stats->zero;
    if (q.signed_distance != 0.0 || std::signbit(q.signed_distance))
      err << "on the boundary but signed distance " << q.signed_distance << " (must be exactly +0); ";
  } else {
    const double tol = ulps * Ulp(std::max(d_approx, r));
    const FT core_sd = FT(q.signed_distance) + FT(r);  // exact
    const int s = core == Containment::kInside ? -1 : 1;
    if (!SignedSqrtInInterval(s, m, core_sd - FT(tol), core_sd + FT(tol)))
      err << "signed distance " << q.signed_distance << ", exact " << (s * d_approx - r) << " (off by "
          << (q.signed_distance - (s * d_approx - r)) << ", tol " << tol << "); ";
    if (r == 0.0 && expect == Containment::kInside && !(q.signed_distance < 0))
      err << "inside but signed distance " << q.signed_distance << "; ";
    if (r == 0.0 && expect == Containment::kOutside && !(q.signed_distance > 0))
      err << "outside but signed distance " << q.signed_distance << "; ";
  }
  // 3. The feature's exact distance is the exact minimum.
  const auto& f = q.feature;
  const bool valid_feature = f.edge.polygon >= 0 && f.edge.polygon < static_cast<int>(shape.polygons().size()) &&
                             f.edge.ring >= -1 &&
                             f.edge.ring < static_cast<int>(shape.polygons()[static_cast<size_t>(f.edge.polygon)].holes.size()) &&
                             f.edge.index >= 0 &&
                             f.edge.index < static_cast<int>(shape.ring(f.edge.polygon, f.edge.ring).size());
  if (!valid_feature) {
    err << "invalid feature (" << f.edge.polygon << "," << f.edge.ring << "," << f.edge.index << "); ";
  } else {
    const FT fd = oracle.FeatureSquaredDistance(ep, f);
    if (fd != m)
      err << "closest feature " << (f.kind == BoundaryFeature::Kind::kEdge ? "edge" : "vertex") << " ("
          << f.edge.polygon << "," << f.edge.ring << "," << f.edge.index << ") is at squared distance "
          << CGAL::to_double(fd) << ", the exact minimum is " << CGAL::to_double(m) << "; ";
    const auto& ring = oracle.Ring(f.edge);
    const EPoint& a = ring[static_cast<size_t>(f.edge.index)];
    EPoint exact_closest = a;
    const Ring& dring = shape.ring(f.edge.polygon, f.edge.ring);
    const Vec2 da = dring[static_cast<size_t>(f.edge.index)];
    const Vec2 db = dring[(static_cast<size_t>(f.edge.index) + 1) % dring.size()];
    if (f.kind == BoundaryFeature::Kind::kEdge) {
      const EPoint& b = ring[(static_cast<size_t>(f.edge.index) + 1) % ring.size()];
      const FT num = (ep - a) * (b - a), den = (b - a).squared_length();
      if (!(num > 0 && num < den))
        err << "edge feature but the exact projection parameter is " << CGAL::to_double(num / den) << "; ";
      else
        exact_closest = a + (num / den) * (b - a);
      // The exact value (to_double of a lazy number is only its interval's estimate: far from
      // a short edge that is off by 1e-12 where the query's t is within an ulp).
      const double t_exact = CGAL::to_double(CGAL::exact(num / den));
      if (std::abs(f.t - t_exact) > 4 * Ulp(t_exact))
        err << "feature.t " << f.t << " vs exact " << t_exact << "; ";
    }
    // 4. Closest point within a few ulps of the coordinate magnitude (unrounded shapes; the
    // rounded relation closest = core closest + r n is checked in test_point_query.cpp).
    if (r == 0.0) {
      const Vec2 ec(CGAL::to_double(exact_closest.x()), CGAL::to_double(exact_closest.y()));
      // Magnitude of the coordinates involved: the query point and the feature's endpoints.
      const double mag = std::max({p.cwiseAbs().maxCoeff(), da.cwiseAbs().maxCoeff(),
                                   f.kind == BoundaryFeature::Kind::kEdge ? db.cwiseAbs().maxCoeff() : 0.0});
      const double tol = 8 * Ulp(mag);
      if (!((q.closest_point - ec).cwiseAbs().maxCoeff() <= tol))
        err << "closest point " << Str(q.closest_point) << ", exact " << Str(ec) << " (off by "
            << (q.closest_point - ec).cwiseAbs().maxCoeff() << ", tol " << tol << "); ";
    }
  }
  const std::string e = err.str();
  if (!e.empty()) {
    ++stats->failures;
    if (stats->failures <= 8) ADD_FAILURE() << ctx << " at " << Str(p) << ": " << e;
  }
}

std::vector<Vec2> QueryPointsFor(std::mt19937_64& rng, const Shape& s, int n) {
  std::vector<Vec2> pts;
  for (int i = 0; i < n; ++i) pts.push_back(testing::RandomPointNear(rng, s.bounds(), 0.3));
  for (int i = 0; i < n / 10; ++i) pts.push_back(testing::RandomPointNear(rng, s.bounds(), 100.0));
  for (const Vec2& p : testing::NearBoundaryPoints(rng, s, n, 1e-12)) pts.push_back(p);
  for (const Vec2& p : testing::NearBoundaryPoints(rng, s, n / 4, 1e-9)) pts.push_back(p);
  for (const auto& ref : testing::AllRings(s))
    for (const Vec2& v : *ref.points) pts.push_back(v);
  return pts;
}

TEST(PointQueryExact, RandomNonConvexPolygonsWithHoles) {
  std::mt19937_64 rng(601);
  ExactStats stats;
  for (int shape_i = 0; shape_i < Scaled(10, 3); ++shape_i) {
    testing::RandomPolygonOptions o;
    o.outer_vertices = 12 + 6 * shape_i;  // 12 .. 66
    const Shape s = Shape::FromPolygons(testing::RandomPolygons(rng, 1 + shape_i % 3, o));
    const ExactOracle oracle(s);
    for (const Vec2& p : QueryPointsFor(rng, s, Scaled(300, 40)))
      CheckAgainstOracle(s, oracle, p, "shape " + std::to_string(shape_i), &stats);
  }
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
  EXPECT_GT(stats.zero, 0);  // exact vertices were included
}

TEST(PointQueryExact, Scale) {
  // Metre-scale objects (a few cm) and large coordinates far from the origin.
  std::mt19937_64 rng(602);
  ExactStats stats;
  for (double size : {0.03, 1e3}) {
    testing::RandomPolygonOptions o;
    o.size = size;
    o.outer_vertices = 24;
    std::vector<Polygon> polys = testing::RandomPolygons(rng, 2, o);
    if (size > 1.0)
      for (auto& p : polys) {
        for (auto& v : p.outer) v += Vec2(1e5, -3e4);
        for (auto& h : p.holes)
          for (auto& v : h) v += Vec2(1e5, -3e4);
      }
    const Shape s = Shape::FromPolygons(polys);
    const ExactOracle oracle(s);
    for (const Vec2& p : QueryPointsFor(rng, s, Scaled(200, 30)))
      CheckAgainstOracle(s, oracle, p, "size " + std::to_string(size), &stats);
  }
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
}

TEST(PointQueryExact, RoundedShapes) {
  std::mt19937_64 rng(603);
  ExactStats stats;
  testing::RandomPolygonOptions o;
  o.outer_vertices = 20;
  const auto polys = testing::RandomPolygons(rng, 2, o);
  for (double r : {0.1, 0.01, 1e-9}) {
    const Shape s = Shape::FromPolygons(polys, r);
    const Shape core = s.WithRadius(0.0);
    const ExactOracle oracle(s);
    std::vector<Vec2> pts = QueryPointsFor(rng, s, Scaled(150, 30));
    // Points on the rounded boundary up to rounding: the oracle decides exactly.
    for (int i = 0; i < Scaled(300, 30); ++i) {
      const Vec2 p0 = testing::RandomPointNear(rng, s.bounds(), 0.2);
      const PointQuery qc = QueryPoint(core, p0);
      if (qc.containment == Containment::kOutside) pts.push_back(qc.closest_point + r * qc.normal);
    }
    for (const Vec2& p : pts) CheckAgainstOracle(s, oracle, p, "r " + std::to_string(r), &stats);
  }
  // Representable points exactly on the rounded boundary of the comb, r = 5/8.
  const Shape comb = Shape::FromPolygons({testing::DyadicComb()}, 0.625);
  const ExactOracle oracle(comb);
  for (const Vec2& p : {Vec2(8.375, -0.5), Vec2(8.625, 1.0), Vec2(3.0, -0.625), Vec2(-0.375, 8.5),
                        Vec2(5.0, 6.625)}) {
    EXPECT_EQ(QueryPoint(comb, p).containment, Containment::kOnBoundary) << Str(p);
    EXPECT_EQ(Contains(comb, p), Containment::kOnBoundary) << Str(p);
    CheckAgainstOracle(comb, oracle, p, "comb r=5/8", &stats);
  }
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
}

TEST(PointQueryExact, DisksAndCapsulesContainment) {
  std::mt19937_64 rng(604);
  std::uniform_real_distribution<double> u(-1, 1), ang(0, 2 * testing::kPi);
  ExactStats stats;
  const Shape disk = Shape::Disk(0.1, Vec2(0.3, -0.7));
  const Shape cap = Shape::Capsule(Vec2(-0.2, 0.1), Vec2(0.5, 0.35), 0.07);
  for (const Shape* s : {&disk, &cap}) {
    const ExactOracle oracle(*s);
    for (int i = 0; i < Scaled(1000, 100); ++i) {
      const Vec2 p0 = testing::RandomPointNear(rng, s->bounds(), 0.2);
      const PointQuery q = QueryPoint(*s, p0);
      // On the rounded boundary up to the rounding of the coordinates.
      const Vec2 p = q.closest_point;
      CheckAgainstOracle(*s, oracle, p, "rounded primitive", &stats);
      CheckAgainstOracle(*s, oracle, p0, "rounded primitive", &stats);
    }
  }
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
}

TEST(PointQueryExact, RepresentableBoundaryPointsAndMedialAxis) {
  Polygon tri;
  tri.outer = {{20, 0}, {23, 1}, {20, 3}};
  const Shape s = Shape::FromPolygons({testing::DyadicComb(), tri});
  const ExactOracle oracle(s);
  ExactStats stats;
  std::mt19937_64 rng(605);
  std::uniform_int_distribution<int> k(1, 1023);
  std::vector<Vec2> pts;
  for (int i = 0; i < Scaled(200, 40); ++i) {
    const double t = k(rng) / 1024.0;
    pts.push_back({8 * t, 0});         // bottom edge
    pts.push_back({8, 2 * t});         // right end
    pts.push_back({0, 8 * t});         // left edge
    pts.push_back({4, 2 + 4 * t});     // tower left side
    pts.push_back({0.5 + t, 1.5});     // hole top
    pts.push_back({20 + 3 * t, t});    // slanted edge, exactly on it
    pts.push_back({1, 2 + 6 * t});     // medial axis of the left column (tie x=0 / x=2)
    pts.push_back({5, 2 + 4 * t});     // medial axis of the tower
    pts.push_back({4 + 2 * t, 6 - 2 * t});  // tower corner diagonal
    pts.push_back({8 - t, 1});         // medial axis of the right leg (y=0 / y=2)
    pts.push_back({1, 0.25 * t});      // between bottom edge and hole
  }
  for (const Vec2& p : pts) CheckAgainstOracle(s, oracle, p, "dyadic comb", &stats);
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
  EXPECT_GT(stats.zero, Scaled(200, 40) * 5);
}

// Detailed shapes everywhere (the strip tree's search and the double-double tie filter): a
// regular polygon at its exact centre (every edge tied up to the rounding of the vertices), near
// it (1e-12 to 1e-3 of the size), on its spokes (two edges tied), deep inside and far outside; a
// random star and a polygon with holes at the same kinds of points.
TEST(PointQueryExact, DetailedShapesAtTheirHardestPoints) {
  std::mt19937_64 rng(606);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  ExactStats stats;
  const int n = Scaled(1500, 300);
  std::vector<std::pair<std::string, Shape>> shapes;
  shapes.emplace_back("regular", Shape::RegularPolygon(n, 0.05));
  {
    Polygon star;
    star.outer = testing::RandomStarRing(rng, Vec2(0.01, -0.02), n, 0.025, 0.05);
    shapes.emplace_back("star", Shape::FromPolygons({star}));
  }
  testing::RandomPolygonOptions o;
  o.outer_vertices = n;
  o.hole_vertices = n / 10;
  o.max_holes = 3;
  o.size = 0.05;
  shapes.emplace_back("holes", Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2(0.0, 0.0), o)}));
  for (const auto& [name, shape] : shapes) {
    const ExactOracle oracle(shape);
    const Box2 b = shape.bounds();
    const Vec2 centre = 0.5 * (b.min + b.max);
    const double size = 0.5 * (b.max - b.min).maxCoeff();
    std::vector<Vec2> pts{centre};
    for (int i = 0; i < Scaled(40, 10); ++i) {
      const double a = 2.0 * testing::kPi * unit(rng);
      const Vec2 dir(std::cos(a), std::sin(a));
      pts.push_back(centre + size * std::pow(10.0, -12.0 + 9.0 * unit(rng)) * dir);  // near the centre
      pts.push_back(centre + 0.4 * size * unit(rng) * dir);                          // deep
      pts.push_back(centre + size * std::pow(10.0, 1.0 + 2.0 * unit(rng)) * dir);   // far
      const Ring& ring = shape.polygons()[0].outer;
      const Vec2& v = ring[std::uniform_int_distribution<std::size_t>(0, ring.size() - 1)(rng)];
      pts.push_back(centre + (0.02 + 0.96 * unit(rng)) * (v - centre));  // a spoke
    }
    // Both ways of the edge index (edge_index.h): a shape's first 256 queries read its strip
    // tree, later ones its grid (built on the 256th). The same points on a fresh copy, then on
    // one warmed past the threshold.
    const Shape fresh = Shape::FromPolygons(shape.polygons(), shape.radius());
    for (const Vec2& p : pts) CheckAgainstOracle(fresh, oracle, p, name + " (strip tree)", &stats);
    for (int i = 0; i < 300; ++i) (void)QueryPoint(shape, centre + size * Vec2(unit(rng) - 0.5, unit(rng) - 0.5));
    for (const Vec2& p : pts) CheckAgainstOracle(shape, oracle, p, name + " (grid)", &stats);
  }
  EXPECT_EQ(stats.failures, 0) << "of " << stats.points << " points";
}

}  // namespace
}  // namespace pushgraph::geometry
