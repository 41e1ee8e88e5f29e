// Using pushgraph's exact geometry as the reference for testing another geometry kernel.
//
// Random non-convex polygons with holes, random query points (many of them within 1e-3 to
// 1e-15 m of an edge, exactly on vertices, or on edges up to the rounding of their
// coordinates), exact answers from pushgraph::geometry, compared with
//   - Boost.Geometry in double (bg::within, bg::covered_by, bg::distance to the rings), and
//   - a naive float32 kernel (crossing-number test, point-segment distance),
// reporting the worst absolute and relative signed-distance errors, where they occur, and the
// points each kernel puts on the wrong side of the boundary.
//
//   kernel_check [SHAPES=40] [SEED=1]
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape.h>

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace pushgraph;
using geometry::Containment;
using geometry::Vec2;
namespace bg = boost::geometry;
using BPoint = bg::model::d2::point_xy<double>;
using BPolygon = bg::model::polygon<BPoint>;      // clockwise outer ring by default; we correct()
using BLines = bg::model::multi_linestring<bg::model::linestring<BPoint>>;

// ---- A random shape: a star-shaped, usually non-convex outline with 1 to 3 star-shaped holes,
// rotated and moved away from the origin (so coordinates carry rounding like real data).
geometry::Ring StarRing(std::mt19937_64& rng, const Vec2& centre, double radius, int vertices, double min_ratio) {
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), ratio(min_ratio, 1.0);
  geometry::Ring ring;
  for (int k = 0; k < vertices; ++k) {
    const double angle = 2 * M_PI * (k + jitter(rng)) / vertices;
    ring.push_back(centre + radius * ratio(rng) * Vec2(std::cos(angle), std::sin(angle)));
  }
  return ring;
}

geometry::Shape RandomShape(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> outer_vertices(8, 24), hole_vertices(4, 9), hole_count(1, 3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double radius = 0.05;  // 10 cm objects
  geometry::Polygon polygon;
  // Radii >= 0.6 R and angular gaps <= 1.6 * 2 pi / 8 keep the disk of radius 0.48 R inside the
  // outline; holes of radius <= 0.1 R centred 0.25 R from the middle, 120 degrees apart, fit in it
  // without touching each other.
  polygon.outer = StarRing(rng, Vec2::Zero(), radius, outer_vertices(rng), 0.6);
  const int holes = hole_count(rng);
  const double phase = 2 * M_PI * unit(rng);
  for (int h = 0; h < holes; ++h) {
    const double angle = phase + 2 * M_PI * h / 3;
    polygon.holes.push_back(StarRing(rng, 0.25 * radius * Vec2(std::cos(angle), std::sin(angle)), 0.1 * radius,
                                     hole_vertices(rng), 0.4));
  }
  // A rigid motion to somewhere in a 1 m workspace.
  const geometry::Pose2 placement{unit(rng) - 0.5, unit(rng) - 0.5, 2 * M_PI * unit(rng)};
  auto place = [&](geometry::Ring& ring) {
    for (Vec2& v : ring) v = geometry::Act(placement, v);
  };
  place(polygon.outer);
  for (geometry::Ring& hole : polygon.holes) place(hole);
  return geometry::Shape::FromPolygons({polygon});  // throws GeometryError if invalid
}

// ---- Query points: uniform in the bounding box, near edges at 1e-3 .. 1e-15 m, on vertices,
// and on edges (up to the rounding of the point's coordinates).
std::vector<Vec2> QueryPoints(const geometry::Shape& shape, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0), exponent(3.0, 15.0);
  std::vector<Vec2> points;
  const geometry::Box2 box = shape.bounds();
  for (int i = 0; i < 150; ++i)
    points.push_back(box.min + Vec2(unit(rng), unit(rng)).cwiseProduct(box.max - box.min) * 1.2 -
                     0.1 * (box.max - box.min));
  std::vector<const geometry::Ring*> rings;
  for (const geometry::Polygon& p : shape.polygons()) {
    rings.push_back(&p.outer);
    for (const geometry::Ring& h : p.holes) rings.push_back(&h);
  }
  for (int i = 0; i < 300; ++i) {
    const geometry::Ring& ring = *rings[static_cast<size_t>(unit(rng) * rings.size()) % rings.size()];
    const size_t k = static_cast<size_t>(unit(rng) * ring.size()) % ring.size();
    const Vec2 a = ring[k], b = ring[(k + 1) % ring.size()];
    const Vec2 on_edge = a + unit(rng) * (b - a);
    const Vec2 normal = Vec2((b - a).y(), -(b - a).x()).normalized();
    if (i % 10 == 0) {
      points.push_back(a);  // a vertex, exactly
    } else if (i % 10 == 1) {
      points.push_back(on_edge);  // on the edge up to rounding: exact says in, out or on
    } else {
      const double offset = std::pow(10.0, -exponent(rng)) * (unit(rng) < 0.5 ? -1 : 1);
      points.push_back(on_edge + offset * normal);
    }
  }
  return points;
}

// ---- The other kernels. Each returns a signed distance (negative inside) and a containment.
struct Answer {
  double signed_distance;
  Containment containment;
};

Answer BoostAnswer(const geometry::Shape& shape, const Vec2& q) {
  BPolygon polygon;
  BLines boundary;
  const geometry::Polygon& p = shape.polygons()[0];
  auto add_ring = [&](const geometry::Ring& ring, auto& target) {
    bg::model::linestring<BPoint> line;
    for (const Vec2& v : ring) {
      target.push_back(BPoint(v.x(), v.y()));
      line.push_back(BPoint(v.x(), v.y()));
    }
    line.push_back(BPoint(ring[0].x(), ring[0].y()));
    boundary.push_back(line);
  };
  add_ring(p.outer, polygon.outer());
  for (const geometry::Ring& h : p.holes) {
    polygon.inners().emplace_back();
    add_ring(h, polygon.inners().back());
  }
  bg::correct(polygon);  // closes the rings and orients them as Boost expects
  const BPoint point(q.x(), q.y());
  const bool within = bg::within(point, polygon);
  const bool covered = bg::covered_by(point, polygon);
  const double d = bg::distance(point, boundary);
  return {within ? -d : d, within ? Containment::kInside : covered ? Containment::kOnBoundary : Containment::kOutside};
}

Answer Float32Answer(const geometry::Shape& shape, const Vec2& q) {
  const float px = static_cast<float>(q.x()), py = static_cast<float>(q.y());
  float best = std::numeric_limits<float>::infinity();
  bool inside = false;
  auto visit = [&](const geometry::Ring& ring) {
    for (size_t i = 0; i < ring.size(); ++i) {
      const float ax = static_cast<float>(ring[i].x()), ay = static_cast<float>(ring[i].y());
      const float bx = static_cast<float>(ring[(i + 1) % ring.size()].x());
      const float by = static_cast<float>(ring[(i + 1) % ring.size()].y());
      const float ex = bx - ax, ey = by - ay;
      const float t = std::clamp(((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey), 0.0f, 1.0f);
      best = std::min(best, std::hypot(px - (ax + t * ex), py - (ay + t * ey)));
      if ((ay > py) != (by > py) && px < ax + (py - ay) * ex / ey) inside = !inside;  // crossing number
    }
  };
  for (const geometry::Polygon& p : shape.polygons()) {
    visit(p.outer);
    for (const geometry::Ring& h : p.holes) visit(h);
  }
  if (best == 0.0f) return {0.0, Containment::kOnBoundary};
  return {inside ? -best : best, inside ? Containment::kInside : Containment::kOutside};
}

// ---- Bookkeeping of the comparison. Distances and containment are two questions: the
// distance error compares |distance| (so a point the kernel puts on the wrong side is counted
// once, as a containment error, not twice).
struct Worst {
  double error = -1.0;
  int shape = -1;
  Vec2 point = Vec2::Zero();
  double exact = 0.0, other = 0.0;
};

struct Tally {
  const char* name;
  std::function<Answer(const geometry::Shape&, const Vec2&)> kernel;
  Worst absolute{}, relative{};
  int wrong_side = 0;        // strictly inside and strictly outside swapped
  int missed_boundary = 0;   // exactly on the boundary, the kernel says inside or outside
  int false_boundary = 0;    // the kernel says on the boundary, the point is strictly in or out
  Worst worst_wrong_side{};  // the wrong-side point farthest from the boundary (error = |exact|)
  Worst worst_false_boundary{};  // the "boundary" point farthest from the boundary
  // Worst relative error by band of |exact distance|: >= 1e-3, [1e-6, 1e-3), ..., < 1e-12.
  double band_relative[5] = {0, 0, 0, 0, 0};
};

void Record(Tally& t, int shape_index, const Vec2& p, const geometry::PointQuery& exact, const Answer& other) {
  const double exact_distance = std::abs(exact.signed_distance);
  const double error = std::abs(std::abs(other.signed_distance) - exact_distance);
  if (error > t.absolute.error) t.absolute = {error, shape_index, p, exact.signed_distance, other.signed_distance};
  if (exact_distance > 0.0) {
    const double relative = error / exact_distance;
    if (relative > t.relative.error) t.relative = {relative, shape_index, p, exact.signed_distance, other.signed_distance};
    const int band = std::clamp(static_cast<int>(-std::log10(exact_distance) / 3.0), 0, 4);
    t.band_relative[band] = std::max(t.band_relative[band], relative);
  }
  const bool exact_boundary = exact.containment == Containment::kOnBoundary;
  const bool other_boundary = other.containment == Containment::kOnBoundary;
  if (exact_boundary && !other_boundary) {
    ++t.missed_boundary;
  } else if (!exact_boundary && other_boundary) {
    ++t.false_boundary;
    if (exact_distance > t.worst_false_boundary.error)
      t.worst_false_boundary = {exact_distance, shape_index, p, exact.signed_distance, other.signed_distance};
  } else if (exact.containment != other.containment) {
    ++t.wrong_side;
    if (exact_distance > t.worst_wrong_side.error)
      t.worst_wrong_side = {exact_distance, shape_index, p, exact.signed_distance, other.signed_distance};
  }
}

void PrintWorst(const char* what, const Worst& w) {
  std::printf("  worst %-9s error %.3e  shape %d, point (%.17g, %.17g): exact %.17g, kernel %.17g\n", what, w.error,
              w.shape, w.point.x(), w.point.y(), w.exact, w.other);
}

}  // namespace

int main(int argc, char** argv) {
  const int shapes = argc > 1 ? std::atoi(argv[1]) : 40;
  const unsigned long seed = argc > 2 ? std::strtoul(argv[2], nullptr, 10) : 1;
  if (shapes <= 0) {
    std::fprintf(stderr, "usage: %s [SHAPES > 0] [SEED]\n", argv[0]);
    return 2;
  }
  std::mt19937_64 rng(seed);
  std::vector<Tally> tallies(2);
  tallies[0].name = "Boost.Geometry (double)";
  tallies[0].kernel = BoostAnswer;
  tallies[1].name = "naive float32";
  tallies[1].kernel = Float32Answer;
  int points = 0, rejected = 0, exact_on_boundary = 0, holes = 0, vertices = 0;
  try {
    for (int s = 0; s < shapes; ++s) {
      geometry::Shape shape;
      try {
        shape = RandomShape(rng);
      } catch (const geometry::GeometryError& e) {  // e.g. a self-intersecting draw: try again
        ++rejected;
        --s;
        continue;
      }
      holes += static_cast<int>(shape.polygons()[0].holes.size());
      vertices += shape.num_vertices();
      for (const Vec2& p : QueryPoints(shape, rng)) {
        const geometry::PointQuery exact = geometry::QueryPoint(shape, p);  // the reference
        exact_on_boundary += exact.containment == Containment::kOnBoundary;
        for (Tally& t : tallies) Record(t, s, p, exact, t.kernel(shape, p));
        ++points;
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "kernel_check: %s\n", e.what());
    return 1;
  }

  std::printf("%d random non-convex shapes (%d vertices, %d holes; %d invalid draws rejected), seed %lu\n", shapes,
              vertices, holes, rejected, seed);
  std::printf("%d query points, %d of them exactly on the boundary according to pushgraph\n\n", points,
              exact_on_boundary);
  for (const Tally& t : tallies) {
    std::printf("%s vs exact:\n", t.name);
    PrintWorst("absolute", t.absolute);
    PrintWorst("relative", t.relative);
    std::printf("  worst relative error by exact distance  >=1e-3: %.1e  [1e-6,1e-3): %.1e  [1e-9,1e-6): %.1e  "
                "[1e-12,1e-9): %.1e  <1e-12: %.1e\n",
                t.band_relative[0], t.band_relative[1], t.band_relative[2], t.band_relative[3], t.band_relative[4]);
    std::printf("  containment: %d on the wrong side; %d boundary points called inside/outside; %d interior or "
                "exterior points called boundary\n",
                t.wrong_side, t.missed_boundary, t.false_boundary);
    if (t.wrong_side > 0)
      std::printf("  wrong side farthest from the boundary: shape %d, point (%.17g, %.17g), exact signed distance %.3e\n",
                  t.worst_wrong_side.shape, t.worst_wrong_side.point.x(), t.worst_wrong_side.point.y(),
                  t.worst_wrong_side.exact);
    if (t.false_boundary > 0)
      std::printf("  called boundary farthest from it: shape %d, point (%.17g, %.17g), exact signed distance %.3e\n",
                  t.worst_false_boundary.shape, t.worst_false_boundary.point.x(), t.worst_false_boundary.point.y(),
                  t.worst_false_boundary.exact);
    std::printf("\n");
  }
  // This program is also a test: Boost.Geometry's double distances must agree with the exact ones
  // to far below a nanometre (its weakness is the boundary decision, not the distance).
  if (!(tallies[0].absolute.error < 1e-12)) {
    std::fprintf(stderr, "kernel_check: Boost.Geometry and pushgraph distances differ by %.3e m\n",
                 tallies[0].absolute.error);
    return 1;
  }
  return 0;
}
