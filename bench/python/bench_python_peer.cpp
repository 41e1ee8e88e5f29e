// The C++ peer of bench/python/bench_python.py: the same exact signed-distance query over 1e6
// points (uniform in the notched block's bounds widened by 1 cm, the Python script's
// distribution) in a plain C++ loop. The Python script runs this binary and reports its
// vectorized call's time as a ratio to it.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape.h>

#include <benchmark/benchmark.h>

#include <random>
#include <vector>

namespace {

using namespace pushgraph::geometry;

void BM_CppLoopSignedDistance(benchmark::State& state) {
  const Shape shape = LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  const Box2 b = shape.bounds();
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> ux(b.min.x() - 0.01, b.max.x() + 0.01), uy(b.min.y() - 0.01, b.max.y() + 0.01);
  std::vector<Vec2> points(static_cast<std::size_t>(state.range(0)));
  for (Vec2& p : points) p = Vec2(ux(rng), uy(rng));
  std::vector<double> out(points.size());
  for (auto _ : state) {
    for (std::size_t i = 0; i < points.size(); ++i) out[i] = QueryPoint(shape, points[i]).signed_distance;
    benchmark::DoNotOptimize(out.data());
  }
  // Seconds per point (printed with an SI prefix: "45n" is 45 ns).
  state.counters["per_point"] = benchmark::Counter(static_cast<double>(points.size()),
                                                   benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CppLoopSignedDistance)->Arg(1000000)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
