// Exact signed distance + closest point on non-convex polygons (64, 1000, 10000 vertices):
// pushgraph's QueryPoint against the naive CGAL Epick edge loop and Boost.Geometry, plus
// pushgraph's brute-force reference and DistanceField lookups, all in the same run on the same
// query points. Before timing, every exact method's answers are compared with QueryPoint on all
// query points; the program aborts on a mismatch above 1e-9 (m).
//
//   build-gt/bench/geometry/bench_geometry --benchmark_min_time=0.3 --benchmark_repetitions=5 \
//       --benchmark_enable_random_interleaving=true
//
// After the Google Benchmark output, a markdown table of ns/query and speed-ups is printed
// (the table in docs/benchmarks.md).
#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/point_query.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/squared_distance_2.h>
#include <benchmark/benchmark.h>

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/linestring.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
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
constexpr double kSize = 0.05;     // object radius in metres (a 10 cm object)

struct Answer {
  double sd;
  pg::Vec2 closest;
};

/// One polygon size: the shape and every competitor's data structure, and the query points.
struct Case {
  int n = 0;
  pg::Shape shape;
  std::vector<K::Point_2> cgal_ring;
  BPolygon boost_polygon;
  BLinestring boost_boundary;
  std::unique_ptr<pg::DistanceField> field;
  std::vector<pg::Vec2> queries;
  std::vector<K::Point_2> cgal_queries;
  std::vector<BPoint> boost_queries;
  double field_max_error_seen = 0.0;
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

Case& GetCase(int n) {
  static std::map<int, std::unique_ptr<Case>> cases;
  auto it = cases.find(n);
  if (it != cases.end()) return *it->second;
  auto c = std::make_unique<Case>();
  c->n = n;
  const pg::Polygon poly = MakePolygon(n, 1000 + static_cast<uint64_t>(n));
  c->shape = pg::Shape::FromPolygons({poly});
  const pg::Ring& ring = c->shape.polygons()[0].outer;  // normalized (CCW)
  for (const pg::Vec2& v : ring) {
    c->cgal_ring.emplace_back(v.x(), v.y());
    bg::append(c->boost_polygon.outer(), BPoint(v.x(), v.y()));
    c->boost_boundary.emplace_back(v.x(), v.y());
  }
  bg::append(c->boost_polygon.outer(), BPoint(ring[0].x(), ring[0].y()));
  c->boost_boundary.emplace_back(ring[0].x(), ring[0].y());
  // A 256 x 256 field over the shape (the resolution of the figure in geometry-speed.md); the
  // margin covers every query point, so all lookups interpolate.
  const pg::Box2 b = c->shape.bounds();
  const double side = std::max(b.max.x() - b.min.x(), b.max.y() - b.min.y());
  pg::DistanceField::Options fo;
  fo.margin = 0.1 * side + 1e-9;
  fo.resolution = (side + 2 * fo.margin) / 255.0;
  fo.error_samples_per_cell = 2;
  c->field = std::make_unique<pg::DistanceField>(c->shape, fo);
  // Query points: uniform in the bounding box grown by 10 % (about half inside).
  std::mt19937_64 rng(42);
  for (int i = 0; i < kNumQueries; ++i) {
    const pg::Vec2 p = pg::testing::RandomPointNear(rng, b, 0.1);
    c->queries.push_back(p);
    c->cgal_queries.emplace_back(p.x(), p.y());
    c->boost_queries.emplace_back(p.x(), p.y());
  }
  // Same answers, or no timings.
  for (int i = 0; i < kNumQueries; ++i) {
    const pg::Vec2& p = c->queries[static_cast<size_t>(i)];
    const pg::PointQuery q = pg::QueryPoint(c->shape, p);
    const pg::PointQuery r = pg::QueryPointBruteForce(c->shape, p);
    if (q.signed_distance != r.signed_distance) Mismatch("QueryPointBruteForce", n, p, q.signed_distance, r.signed_distance);
    const Answer a = CgalNaive(c->cgal_ring, c->cgal_queries[static_cast<size_t>(i)]);
    if (std::abs(a.sd - q.signed_distance) > 1e-9) Mismatch("CGAL Epick loop sd", n, p, a.sd, q.signed_distance);
    if ((a.closest - q.closest_point).norm() > 1e-9 &&
        std::abs((a.closest - p).norm() - (q.closest_point - p).norm()) > 1e-9)  // a tie may pick either
      Mismatch("CGAL Epick loop closest point", n, p, (a.closest - q.closest_point).norm(), 0.0);
    const double bsd = BoostSignedDistance(c->boost_polygon, c->boost_boundary, c->boost_queries[static_cast<size_t>(i)]);
    if (std::abs(bsd - q.signed_distance) > 1e-9) Mismatch("Boost.Geometry sd", n, p, bsd, q.signed_distance);
    c->field_max_error_seen =
        std::max(c->field_max_error_seen, std::abs(c->field->Evaluate(p) - q.signed_distance));
  }
  return *cases.emplace(n, std::move(c)).first->second;
}

// --- Benchmarks: one query per iteration, cycling through the same 4096 points. -------------

void BM_PushgraphQueryPoint(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state) {
    const pg::PointQuery q = pg::QueryPoint(c.shape, c.queries[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(q.signed_distance);
    benchmark::DoNotOptimize(q.closest_point);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_PushgraphBruteForce(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state) {
    const pg::PointQuery q = pg::QueryPointBruteForce(c.shape, c.queries[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(q.signed_distance);
    benchmark::DoNotOptimize(q.closest_point);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_CgalEpickNaiveLoop(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state) {
    const Answer a = CgalNaive(c.cgal_ring, c.cgal_queries[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(a.sd);
    benchmark::DoNotOptimize(a.closest);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_CgalEpickEdgeLoopOnly(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(CgalEdgeLoopOnly(c.cgal_ring, c.cgal_queries[i++ & (kNumQueries - 1)]));
  state.SetItemsProcessed(state.iterations());
}

void BM_CgalEpickBoundedSideOnly(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state)
    benchmark::DoNotOptimize(
        CGAL::bounded_side_2(c.cgal_ring.begin(), c.cgal_ring.end(), c.cgal_queries[i++ & (kNumQueries - 1)], K()));
  state.SetItemsProcessed(state.iterations());
}

void BM_PlainDoubleLoop(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  const pg::Ring& ring = c.shape.polygons()[0].outer;
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(PlainDoubleSignedDistance(ring, c.queries[i++ & (kNumQueries - 1)]));
  state.SetItemsProcessed(state.iterations());
}

void BM_BoostGeometry(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  for (auto _ : state) {
    const double d = BoostSignedDistance(c.boost_polygon, c.boost_boundary, c.boost_queries[i++ & (kNumQueries - 1)]);
    benchmark::DoNotOptimize(d);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_DistanceField(benchmark::State& state) {
  const Case& c = GetCase(static_cast<int>(state.range(0)));
  size_t i = 0;
  pg::Vec2 g;
  for (auto _ : state) {
    const double v = c.field->Evaluate(c.queries[i++ & (kNumQueries - 1)], &g);
    benchmark::DoNotOptimize(v);
    benchmark::DoNotOptimize(g);
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["max_err_seen_m"] = c.field_max_error_seen;
  state.counters["max_err_reported_m"] = c.field->max_error();
}

BENCHMARK(BM_PushgraphQueryPoint)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_PushgraphBruteForce)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_CgalEpickNaiveLoop)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_CgalEpickEdgeLoopOnly)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_CgalEpickBoundedSideOnly)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_PlainDoubleLoop)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_BoostGeometry)->Arg(64)->Arg(1000)->Arg(10000);
BENCHMARK(BM_DistanceField)->Arg(64)->Arg(1000)->Arg(10000);

/// Console output plus a markdown table of ns/query and ratios at the end.
class TableReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.error_occurred || r.run_type != Run::RT_Iteration) continue;
      const std::string name = r.benchmark_name();
      const auto slash = name.find('/');
      // CPU time (the machine is shared: wall time includes being descheduled); the table
      // takes the median over --benchmark_repetitions.
      samples_[std::stoi(name.substr(slash + 1))][name.substr(0, slash)].push_back(
          r.GetAdjustedCPUTime() * (r.time_unit == benchmark::kMicrosecond ? 1e3 : r.time_unit == benchmark::kMillisecond ? 1e6 : 1.0));
    }
  }
  void PrintTable() {
    for (auto& [n, m] : samples_)
      for (auto& [k, v] : m) {
        std::sort(v.begin(), v.end());
        ns_[n][k] = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
      }
    std::printf("\nMedian CPU time per query over %zu repetition(s).\n",
                samples_.empty() ? size_t{0} : samples_.begin()->second.begin()->second.size());
    std::printf("\n| vertices | pushgraph QueryPoint | brute force (ref.) | CGAL Epick naive loop | Boost.Geometry "
                "distance + within | DistanceField 256^2 | speed-up vs CGAL loop | vs Boost.Geometry |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const auto& [n, m] : ns_) {
      auto get = [&](const char* k) {
        auto it = m.find(k);
        return it == m.end() ? std::nan("") : it->second;
      };
      const double q = get("BM_PushgraphQueryPoint");
      std::printf("| %d | %.0f ns | %.0f ns | %.0f ns | %.0f ns | %.1f ns | %.1fx | %.1fx |\n", n, q,
                  get("BM_PushgraphBruteForce"), get("BM_CgalEpickNaiveLoop"), get("BM_BoostGeometry"),
                  get("BM_DistanceField"), get("BM_CgalEpickNaiveLoop") / q, get("BM_BoostGeometry") / q);
    }
    std::printf("\n| vertices | CGAL edge loop only | CGAL bounded_side_2 only | plain double loop (not exact) |\n");
    std::printf("|---:|---:|---:|---:|\n");
    for (const auto& [n, m] : ns_) {
      auto get = [&](const char* k) {
        auto it = m.find(k);
        return it == m.end() ? std::nan("") : it->second;
      };
      std::printf("| %d | %.0f ns | %.0f ns | %.0f ns |\n", n, get("BM_CgalEpickEdgeLoopOnly"),
                  get("BM_CgalEpickBoundedSideOnly"), get("BM_PlainDoubleLoop"));
    }
    std::printf("\n");
    for (const int n : {64, 1000, 10000}) {
      const Case& c = GetCase(n);
      std::printf("DistanceField %d vertices: %d x %d grid, max |error| on the 4096 query points %.3g m, reported "
                  "max_error() %.3g m\n",
                  n, c.field->rows(), c.field->cols(), c.field_max_error_seen, c.field->max_error());
    }
  }

 private:
  std::map<int, std::map<std::string, double>> ns_;
  std::map<int, std::map<std::string, std::vector<double>>> samples_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // Build every case (and check every answer) before any timing.
  for (const int n : {64, 1000, 10000}) GetCase(n);
  std::printf("answers agree on %d query points per polygon (|diff| <= 1e-9 m)\n", kNumQueries);
  TableReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.PrintTable();
  benchmark::Shutdown();
  return 0;
}
