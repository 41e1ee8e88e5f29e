// Exact signed distance + closest point on detailed non-convex polygons (64 to 100000 vertices),
// on query sets that cannot hide a worst case: uniform in the bounding box, deep inside, far
// outside (a random star polygon), inside, near the centre and on the medial axis (spokes) of a
// regular polygon, and its exact centre. pushgraph's QueryPoint against the naive CGAL Epick
// edge loop and Boost.Geometry on the same points in the same run; DistanceField lookups and
// 256 x 256 field construction. Before a case is timed, every method's answers on its points are
// compared with QueryPoint (the program aborts on a mismatch above 1e-9 m); cases are built
// lazily, so `--benchmark_list_tests` builds nothing and timing starts after the first case's
// set-up (printed).
//
//   build-gt/bench/geometry/bench_geometry --benchmark_min_time=0.2 --benchmark_repetitions=3
//
// After the Google Benchmark output, markdown tables of ns/query, speed-ups and each set's ratio to
// the uniform set are printed (the tables in docs/benchmarks.md).
#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/squared_distance_2.h>
#include <benchmark/benchmark.h>

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/linestring.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "geometry/random_shapes.h"

namespace pg = pushgraph::geometry;
namespace bg = boost::geometry;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using BPoint = bg::model::d2::point_xy<double>;
using BPolygon = bg::model::polygon<BPoint, /*clockwise=*/false, /*closed=*/true>;
using BLinestring = bg::model::linestring<BPoint>;

namespace {

constexpr int kNumQueries = 4096;  // power of two: index = i & (kNumQueries - 1)
constexpr int kSizes[] = {64, 1000, 10000, 100000};
constexpr double kSize = 0.05;     // object radius in metres (a 10 cm object)

struct Answer {
  double sd;
  pg::Vec2 closest;
};

// --- The naive CGAL Epick loop: min squared_distance over edges, bounded_side for the sign. ---
Answer CgalNaive(const std::vector<K::Point_2>& ring, const K::Point_2& p) {
  const size_t n = ring.size();
  double best = std::numeric_limits<double>::infinity();
  size_t best_i = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = CGAL::squared_distance(p, K::Segment_2(ring[i], ring[i + 1 == n ? 0 : i + 1]));
    const bool better = d < best;  // written to compile to conditional moves (no branch)
    best = better ? d : best;
    best_i = better ? i : best_i;
  }
  const CGAL::Bounded_side side = CGAL::bounded_side_2(ring.begin(), ring.end(), p, K());
  // Closest point on the argmin edge (clamped projection).
  const K::Point_2& a = ring[best_i];
  const K::Point_2& b = ring[best_i + 1 == n ? 0 : best_i + 1];
  const K::Vector_2 e = b - a;
  const double t = std::clamp(((p - a) * e) / e.squared_length(), 0.0, 1.0);
  const K::Point_2 c = a + t * e;
  const double d = std::sqrt(best);
  return {side == CGAL::ON_BOUNDED_SIDE ? -d : d, {c.x(), c.y()}};
}

// Components of the naive loop, to compare with ../shared/notes/geometry-speed.md.
double CgalEdgeLoopOnly(const std::vector<K::Point_2>& ring, const K::Point_2& p) {
  const size_t n = ring.size();
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i)
    best = std::min(best, CGAL::squared_distance(p, K::Segment_2(ring[i], ring[i + 1 == n ? 0 : i + 1])));
  return best;
}

// A plain double loop (clamped projection + crossing-number parity): what one writes without a
// geometry library. Not exact (neither the sign near the boundary nor ties), for reference only.
double PlainDoubleSignedDistance(const std::vector<pg::Vec2>& ring, const pg::Vec2& p) {
  const size_t n = ring.size();
  double best = std::numeric_limits<double>::infinity();
  bool inside = false;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const pg::Vec2& a = ring[j];
    const pg::Vec2& b = ring[i];
    const pg::Vec2 e = b - a, d = p - a;
    const double t = std::clamp(d.dot(e) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (d - t * e).squaredNorm());
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) * e.x() / e.y()) inside = !inside;
  }
  return inside ? -std::sqrt(best) : std::sqrt(best);
}

// --- Boost.Geometry: distance to the boundary, within for the sign (no closest point in 1.74).
double BoostSignedDistance(const BPolygon& poly, const BLinestring& boundary, const BPoint& p) {
  const double d = bg::distance(p, boundary);
  return bg::within(p, poly) ? -d : d;
}

pg::Polygon MakePolygon(int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  pg::Polygon p;
  p.outer = pg::testing::RandomStarRing(rng, pg::Vec2(0.0, 0.0), n, 0.5 * kSize, kSize);
  return p;
}

[[noreturn]] void Mismatch(const char* what, int n, const pg::Vec2& p, double a, double b) {
  std::fprintf(stderr, "ANSWER MISMATCH (%s, %d vertices) at (%.17g, %.17g): %.17g vs %.17g\n", what, n, p.x(),
               p.y(), a, b);
  std::abort();
}


// --- Cases: one shape per (kind, size) with every competitor's structures; query sets. ---------

enum class Kind { kStar, kRound };

struct Shape {
  Kind kind;
  int n = 0;
  pg::Shape shape;
  std::vector<K::Point_2> cgal_ring;
  BPolygon boost_polygon;
  BLinestring boost_boundary;
};

struct QuerySet {
  std::string name;
  const Shape* shape = nullptr;
  std::vector<pg::Vec2> points;
  std::vector<K::Point_2> cgal_points;
  std::vector<BPoint> boost_points;
};

double Seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

const Shape& GetShape(Kind kind, int n) {
  static std::map<std::pair<int, int>, std::unique_ptr<Shape>> shapes;
  auto& slot = shapes[{static_cast<int>(kind), n}];
  if (slot) return *slot;
  const auto t0 = std::chrono::steady_clock::now();
  slot = std::make_unique<Shape>();
  Shape& c = *slot;
  c.kind = kind;
  c.n = n;
  c.shape = kind == Kind::kStar ? pg::Shape::FromPolygons({MakePolygon(n, 1000 + static_cast<uint64_t>(n))})
                                : pg::Shape::RegularPolygon(n, kSize);
  const pg::Ring& ring = c.shape.polygons()[0].outer;  // normalized (CCW)
  for (const pg::Vec2& v : ring) {
    c.cgal_ring.emplace_back(v.x(), v.y());
    bg::append(c.boost_polygon.outer(), BPoint(v.x(), v.y()));
    c.boost_boundary.emplace_back(v.x(), v.y());
  }
  bg::append(c.boost_polygon.outer(), BPoint(ring[0].x(), ring[0].y()));
  c.boost_boundary.emplace_back(ring[0].x(), ring[0].y());
  std::printf("set-up: %s polygon, %d vertices: shape and index built in %.3f s\n",
              kind == Kind::kStar ? "star" : "regular", n, Seconds(t0));
  return c;
}

const char* const kSets[] = {"uniform", "deep", "far", "round", "centre", "medial", "exact-centre"};

// Points of one set (seeded; the same in every run).
const QuerySet& GetSet(const std::string& name, int n) {
  static std::map<std::pair<std::string, int>, std::unique_ptr<QuerySet>> sets;
  auto& slot = sets[{name, n}];
  if (slot) return *slot;
  const bool star = name == "uniform" || name == "deep" || name == "far";
  const Shape& shape = GetShape(star ? Kind::kStar : Kind::kRound, n);
  const auto t0 = std::chrono::steady_clock::now();
  slot = std::make_unique<QuerySet>();
  QuerySet& q = *slot;
  q.name = name;
  q.shape = &shape;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double apothem = kSize * std::cos(M_PI / n);
  const auto in_disk = [&](double radius) {  // uniform in a disk about the origin
    const double r = radius * std::sqrt(unit(rng)), a = 2.0 * M_PI * unit(rng);
    return pg::Vec2(r * std::cos(a), r * std::sin(a));
  };
  const pg::Ring& ring = shape.shape.polygons()[0].outer;
  for (int i = 0; i < kNumQueries; ++i) {
    pg::Vec2 p;
    if (name == "uniform") {
      p = pg::testing::RandomPointNear(rng, shape.shape.bounds(), 0.1);  // about half inside
    } else if (name == "deep") {  // at least a third of the size inside
      p = in_disk(0.9 * pg::testing::InscribedRadius(n, 0.5 * kSize));
    } else if (name == "far") {  // 10 to 1000 sizes away
      const double r = kSize * std::pow(10.0, 1.0 + 2.0 * unit(rng)), a = 2.0 * M_PI * unit(rng);
      p = pg::Vec2(r * std::cos(a), r * std::sin(a));
    } else if (name == "round") {  // anywhere inside a near-circular shape
      p = in_disk(0.99 * apothem);
    } else if (name == "centre") {  // within 1 % of the size of its centre
      p = in_disk(0.01 * kSize);
    } else if (name == "medial") {  // on a spoke: equidistant from two edges (up to rounding)
      const pg::Vec2& v = ring[std::uniform_int_distribution<std::size_t>(0, ring.size() - 1)(rng)];
      p = (0.01 + 0.98 * unit(rng)) * v;
    } else {  // every edge at the same distance, up to the rounding of the vertices
      p = pg::Vec2(0.0, 0.0);
    }
    q.points.push_back(p);
    q.cgal_points.emplace_back(p.x(), p.y());
    q.boost_points.emplace_back(p.x(), p.y());
  }
  // Same answers, or no timings (a subset at 100000 vertices: the naive loops take 0.5 ms each).
  const int step = n >= 100000 ? 16 : 1;
  for (int i = 0; i < kNumQueries; i += step) {
    const pg::Vec2& p = q.points[static_cast<size_t>(i)];
    const pg::PointQuery a = pg::QueryPoint(shape.shape, p);
    if (i % 64 == 0) {
      const pg::PointQuery r = pg::QueryPointBruteForce(shape.shape, p);
      if (a.signed_distance != r.signed_distance || a.feature.edge.index != r.feature.edge.index)
        Mismatch("QueryPointBruteForce", n, p, a.signed_distance, r.signed_distance);
    }
    const Answer c = CgalNaive(shape.cgal_ring, q.cgal_points[static_cast<size_t>(i)]);
    if (std::abs(c.sd - a.signed_distance) > 1e-9) Mismatch("CGAL Epick loop sd", n, p, c.sd, a.signed_distance);
    if ((c.closest - a.closest_point).norm() > 1e-9 &&
        std::abs((c.closest - p).norm() - (a.closest_point - p).norm()) > 1e-9)  // a tie may pick either
      Mismatch("CGAL Epick loop closest point", n, p, (c.closest - a.closest_point).norm(), 0.0);
    const double b = BoostSignedDistance(shape.boost_polygon, shape.boost_boundary, q.boost_points[static_cast<size_t>(i)]);
    if (std::abs(b - a.signed_distance) > 1e-9) Mismatch("Boost.Geometry sd", n, p, b, a.signed_distance);
  }
  std::printf("set-up: %s set, %d vertices: %d points made and checked in %.3f s\n", name.c_str(), n, kNumQueries,
              Seconds(t0));
  return q;
}

// --- Benchmarks: one query per iteration, cycling through the set's 4096 points. -------------

void BM_Pushgraph(benchmark::State& state, std::string set, int n) {
  const QuerySet& q = GetSet(set, n);
  size_t i = 0;
  for (auto _ : state) {
    const pg::PointQuery r = pg::QueryPoint(q.shape->shape, q.points[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(r.signed_distance);
    benchmark::DoNotOptimize(r.closest_point);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_CgalNaive(benchmark::State& state, std::string set, int n) {
  const QuerySet& q = GetSet(set, n);
  size_t i = 0;
  for (auto _ : state) {
    const Answer a = CgalNaive(q.shape->cgal_ring, q.cgal_points[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(a.sd);
    benchmark::DoNotOptimize(a.closest);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_Boost(benchmark::State& state, std::string set, int n) {
  const QuerySet& q = GetSet(set, n);
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ & (kNumQueries - 1);
    benchmark::DoNotOptimize(BoostSignedDistance(q.shape->boost_polygon, q.shape->boost_boundary, q.boost_points[k]));
  }
  state.SetItemsProcessed(state.iterations());
}

// Components of the naive loop and a plain double loop (not exact), on the uniform set.
void BM_CgalEdgeLoopOnly(benchmark::State& state, int n) {
  const QuerySet& q = GetSet("uniform", n);
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(CgalEdgeLoopOnly(q.shape->cgal_ring, q.cgal_points[i++ & (kNumQueries - 1)]));
  state.SetItemsProcessed(state.iterations());
}

void BM_PlainDoubleLoop(benchmark::State& state, int n) {
  const QuerySet& q = GetSet("uniform", n);
  const pg::Ring& ring = q.shape->shape.polygons()[0].outer;
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(PlainDoubleSignedDistance(ring, q.points[i++ & (kNumQueries - 1)]));
  state.SetItemsProcessed(state.iterations());
}

// A 256 x 256 distance field over the star polygon (65536 exact queries plus the error estimate
// at 2 samples per cell): its cost per node against a query's.
pg::DistanceField::Options FieldOptions(const pg::Shape& shape) {
  const pg::Box2 b = shape.bounds();
  const double side = std::max(b.max.x() - b.min.x(), b.max.y() - b.min.y());
  pg::DistanceField::Options fo;
  fo.margin = 0.1 * side + 1e-9;
  fo.resolution = (side + 2 * fo.margin) / 255.0;
  fo.error_samples_per_cell = 2;
  return fo;
}

void BM_DistanceFieldBuild(benchmark::State& state, int n) {
  const Shape& s = GetShape(Kind::kStar, n);
  int nodes = 0;
  for (auto _ : state) {
    pg::DistanceField field(s.shape, FieldOptions(s.shape));
    nodes = field.rows() * field.cols();
    benchmark::DoNotOptimize(field.max_error());
  }
  state.counters["nodes"] = nodes;
}

void BM_DistanceFieldLookup(benchmark::State& state, int n) {
  const QuerySet& q = GetSet("uniform", n);
  static std::map<int, std::unique_ptr<pg::DistanceField>> fields;
  auto& field = fields[n];
  if (!field) field = std::make_unique<pg::DistanceField>(q.shape->shape, FieldOptions(q.shape->shape));
  size_t i = 0;
  pg::Vec2 g;
  for (auto _ : state) {
    benchmark::DoNotOptimize(field->Evaluate(q.points[i++ & (kNumQueries - 1)], &g));
    benchmark::DoNotOptimize(g);
  }
  state.SetItemsProcessed(state.iterations());
}

// --- Penetration depth of rounded fingers (issue 15): the exact depth (the grown obstacle's
// boundary, rounded_boundary.h) against the "core depth + radius" bound, side by side, on
// overlapping queries against the star polygon (narrow notches everywhere). A disk of 0.2 * kSize
// radius, and a rounded box at one relative angle (its Minkowski obstacle and boundary cached). ---
struct PairSet {
  std::unique_ptr<pg::ShapePairQuerier> exact, bound;
  std::vector<pg::Pose2> fingers;
  int deeper = 0;  // queries whose exact depth exceeds the bound
};

const PairSet& GetPairSet(bool disk, int n) {
  static std::map<std::pair<bool, int>, std::unique_ptr<PairSet>> sets;
  auto& slot = sets[{disk, n}];
  if (slot) return *slot;
  slot = std::make_unique<PairSet>();
  PairSet& p = *slot;
  const pg::Shape& object = GetShape(Kind::kStar, n).shape;
  const pg::Shape finger = disk ? pg::Shape::Disk(0.2 * kSize) : pg::Shape::Box(0.2 * kSize, 0.1 * kSize, 0.1 * kSize);
  pg::ShapePairQuerier::Options bound_options;
  bound_options.exact_rounded_depth = false;
  p.exact = std::make_unique<pg::ShapePairQuerier>(object, finger);
  p.bound = std::make_unique<pg::ShapePairQuerier>(object, finger, bound_options);
  std::mt19937_64 rng(1515 + n);
  const pg::Box2 box = object.bounds();
  std::uniform_real_distribution<double> ux(box.min.x(), box.max.x()), uy(box.min.y(), box.max.y());
  while (static_cast<int>(p.fingers.size()) < kNumQueries) {
    const pg::Pose2 f{ux(rng), uy(rng), 0.4};
    const pg::ShapePairResult e = p.exact->Query(pg::Pose2{}, f);  // builds the boundary once
    if (!e.intersecting) continue;
    p.deeper += e.depth > p.bound->Query(pg::Pose2{}, f).depth;
    p.fingers.push_back(f);
  }
  return p;
}

void BM_PairDepth(benchmark::State& state, bool disk, bool exact, int n) {
  const PairSet& p = GetPairSet(disk, n);
  const pg::ShapePairQuerier& q = exact ? *p.exact : *p.bound;
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(q.Query(pg::Pose2{}, p.fingers[i++ & (kNumQueries - 1)]).depth);
  state.SetItemsProcessed(state.iterations());
  state.counters["deeper_than_bound"] = static_cast<double>(p.deeper) / kNumQueries;
}

// The one-off cost of the boundary: a new querier's first overlapping query (disk: the boundary of
// the grown object; box: the Minkowski obstacle and, for the exact depth, its boundary).
void BM_PairFirstQuery(benchmark::State& state, bool disk, bool exact, int n) {
  const pg::Shape& object = GetShape(Kind::kStar, n).shape;
  const pg::Shape finger = disk ? pg::Shape::Disk(0.2 * kSize) : pg::Shape::Box(0.2 * kSize, 0.1 * kSize, 0.1 * kSize);
  pg::ShapePairQuerier::Options o;
  o.exact_rounded_depth = exact;
  for (auto _ : state) {
    const pg::ShapePairQuerier q(object, finger, o);
    benchmark::DoNotOptimize(q.Query(pg::Pose2{}, pg::Pose2{0.0, 0.0, 0.4}).depth);
  }
}

void RegisterAll() {
  for (const int n : kSizes) {
    for (const char* set : kSets) {
      const std::string tail = std::string("/") + set + "/" + std::to_string(n);
      benchmark::RegisterBenchmark(("pushgraph" + tail).c_str(), BM_Pushgraph, std::string(set), n);
      benchmark::RegisterBenchmark(("cgal_loop" + tail).c_str(), BM_CgalNaive, std::string(set), n);
      benchmark::RegisterBenchmark(("boost" + tail).c_str(), BM_Boost, std::string(set), n);
    }
    const std::string tail = "/uniform/" + std::to_string(n);
    benchmark::RegisterBenchmark(("cgal_edge_loop_only" + tail).c_str(), BM_CgalEdgeLoopOnly, n);
    benchmark::RegisterBenchmark(("plain_double_loop" + tail).c_str(), BM_PlainDoubleLoop, n);
    benchmark::RegisterBenchmark(("field_lookup" + tail).c_str(), BM_DistanceFieldLookup, n);
    benchmark::RegisterBenchmark(("field_build_256" + tail).c_str(), BM_DistanceFieldBuild, n)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
  }
  for (const int n : {64, 1000, 10000}) {
    for (const bool disk : {true, false}) {
      const std::string tail = std::string(disk ? "/disk-overlap/" : "/rounded-box-overlap/") + std::to_string(n);
      benchmark::RegisterBenchmark(("pair_exact_depth" + tail).c_str(), BM_PairDepth, disk, true, n);
      benchmark::RegisterBenchmark(("pair_bound_depth" + tail).c_str(), BM_PairDepth, disk, false, n);
      benchmark::RegisterBenchmark(("pair_first_query_exact" + tail).c_str(), BM_PairFirstQuery, disk, true, n)
          ->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("pair_first_query_bound" + tail).c_str(), BM_PairFirstQuery, disk, false, n)
          ->Unit(benchmark::kMillisecond);
    }
  }
}

/// Console output plus markdown tables at the end (median CPU time over the repetitions).
class TableReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const double unit = r.time_unit == benchmark::kMicrosecond ? 1e3
                          : r.time_unit == benchmark::kMillisecond ? 1e6
                          : r.time_unit == benchmark::kSecond     ? 1e9
                                                                  : 1.0;
      // CPU time (the machine is shared: wall time includes being descheduled).
      std::string name = r.benchmark_name();
      const auto tag = name.find("/iterations:");
      if (tag != std::string::npos) name.erase(tag);
      samples_[name].push_back(r.GetAdjustedCPUTime() * unit);
    }
  }
  double Ns(const std::string& method, const std::string& set, int n) const {
    auto it = samples_.find(method + "/" + set + "/" + std::to_string(n));
    if (it == samples_.end() || it->second.empty()) return std::nan("");
    std::vector<double> v = it->second;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
  void PrintTables() const {
    std::printf("\nMedian CPU time per query (ns) over the repetitions; x CGAL = the naive CGAL loop's time over "
                "pushgraph's; / uniform = pushgraph's time over its uniform set's.\n");
    std::printf("\n| vertices | set | pushgraph | CGAL Epick loop | Boost.Geometry | x CGAL | x Boost | / uniform |\n");
    std::printf("|---:|---|---:|---:|---:|---:|---:|---:|\n");
    for (const int n : kSizes) {
      const double uniform = Ns("pushgraph", "uniform", n);
      double worst = 0.0;
      std::string worst_set;
      for (const char* set : kSets) {
        const double p = Ns("pushgraph", set, n), c = Ns("cgal_loop", set, n), b = Ns("boost", set, n);
        if (std::isnan(p)) continue;
        std::printf("| %d | %s | %.0f | %.0f | %.0f | %.0fx | %.0fx | %.2f |\n", n, set, p, c, b, c / p, b / p, p / uniform);
        if (std::string(set) != "exact-centre" && p > worst) worst = p, worst_set = set;
      }
      if (!worst_set.empty())
        std::printf("| %d | **worst set (%s)** | %.0f | | | | | **%.2f** |\n", n, worst_set.c_str(), worst, worst / uniform);
    }
    std::printf("\n| vertices | CGAL edge loop only | plain double loop (not exact) | field lookup | 256^2 field build | "
                "build per node | / uniform query |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const int n : kSizes) {
      const double build = Ns("field_build_256", "uniform", n);
      std::printf("| %d | %.0f ns | %.0f ns | %.1f ns | %.1f ms | %.0f ns | %.2f |\n", n,
                  Ns("cgal_edge_loop_only", "uniform", n), Ns("plain_double_loop", "uniform", n),
                  Ns("field_lookup", "uniform", n), build * 1e-6, build / 65536.0,
                  build / 65536.0 / Ns("pushgraph", "uniform", n));
    }
    std::printf("\n| vertices | finger | exact depth | core depth + radius | exact / bound | first query, exact | "
                "first query, bound |\n|---:|---|---:|---:|---:|---:|---:|\n");
    for (const int n : {64, 1000, 10000})
      for (const char* set : {"disk-overlap", "rounded-box-overlap"}) {
        const double e = Ns("pair_exact_depth", set, n), b = Ns("pair_bound_depth", set, n);
        if (std::isnan(e)) continue;
        std::printf("| %d | %s | %.0f ns | %.0f ns | %.2f | %.2f ms | %.2f ms |\n", n, set, e, b, e / b,
                    Ns("pair_first_query_exact", set, n) * 1e-6, Ns("pair_first_query_bound", set, n) * 1e-6);
      }
  }

 private:
  std::map<std::string, std::vector<double>> samples_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RegisterAll();
  TableReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintTables();
  benchmark::Shutdown();
  return 0;
}
