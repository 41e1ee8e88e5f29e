// tau_max and one limit-surface load, exact (this library) against a 16 x 16 grid integration
// (what public pusher-slider code does: cell centres inside the footprint, sum of |r| dA), in
// the same run. Counters: rel_error against the exact value (the regular n-gon closed form for
// tau_max; the exact load for the load benchmarks). docs/limit_surface.md holds the table.
#include <pushgraph/limit_surface/limit_surface.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

namespace {

namespace ls = pushgraph::limit_surface;
using pushgraph::geometry::Shape;
using pushgraph::geometry::Vec2;

constexpr double kCircumradius = 0.05, kMass = 1.0, kMu = 0.35;

ls::Support Polygon(int n) {
  ls::SupportSpec spec;
  spec.region = Shape::RegularPolygon(n, kCircumradius);
  spec.mass = kMass;
  spec.mu = kMu;
  return ls::MakeSupport(spec);
}

// The note's regular n-gon closed form: integral of |r| dA = (n a^3 / 3)(tan a sec a + asinh tan a).
double NgonTauMax(int n) {
  const double alpha = M_PI / n, apothem = kCircumradius * std::cos(alpha);
  const double integral = n * std::pow(apothem, 3) / 3 * (std::tan(alpha) / std::cos(alpha) + std::asinh(std::tan(alpha)));
  const double area = n * apothem * apothem * std::tan(alpha);
  return kMu * kMass * ls::kStandardGravity / area * integral;
}

// The grid method: centres of the 16 x 16 cells of the bounding box that lie inside, each
// carrying pressure * cell area.
struct Grid {
  std::vector<Vec2> points;
  double weight = 0.0;  // mu * p * cell area
};

bool Inside(const std::vector<Vec2>& ring, const Vec2& p) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    if ((ring[i].y() > p.y()) != (ring[j].y() > p.y()) &&
        p.x() < (ring[j].x() - ring[i].x()) * (p.y() - ring[i].y()) / (ring[j].y() - ring[i].y()) + ring[i].x())
      inside = !inside;
  }
  return inside;
}

Grid MakeGrid(int n) {
  const std::vector<Vec2> ring = Shape::RegularPolygon(n, kCircumradius).polygons()[0].outer;
  Grid grid;
  const double cell = 2 * kCircumradius / 16;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) {
      const Vec2 p(-kCircumradius + (i + 0.5) * cell, -kCircumradius + (j + 0.5) * cell);
      if (Inside(ring, p)) grid.points.push_back(p);
    }
  // Pressure from the grid's own area, as such code does.
  const double area = grid.points.size() * cell * cell;
  grid.weight = kMu * kMass * ls::kStandardGravity / area * cell * cell;
  return grid;
}

ls::Load GridLoad(const Grid& grid, const ls::Twist& t) {
  ls::Load load;
  for (const Vec2& r : grid.points) {
    const Vec2 v(t.vx - t.omega * r.y(), t.vy + t.omega * r.x());
    const Vec2 u = v / v.norm();
    load.force += grid.weight * u;
    load.torque += grid.weight * (r.x() * u.y() - r.y() * u.x());
  }
  return load;
}

double RelativeError(const ls::Load& a, const ls::Load& exact) {
  return (a.force - exact.force).norm() / exact.force.norm() + std::abs(a.torque - exact.torque) / std::abs(exact.torque);
}

// A twist whose rotation centre (0.03, 0.01) lies inside the polygon, and one 10 sizes away.
const ls::Twist kNearTwist{0.01, -0.03, 1.0};
const ls::Twist kFarTwist{0.05, 0.02, 0.1};

void BM_TauMaxExact(benchmark::State& state) {
  const ls::Support s = Polygon(static_cast<int>(state.range(0)));
  double tau = 0.0;
  for (auto _ : state) benchmark::DoNotOptimize(tau = ls::MaxFrictionTorque(s));
  state.counters["rel_error"] = std::abs(tau / NgonTauMax(static_cast<int>(state.range(0))) - 1);
}

void BM_TauMaxGrid16(benchmark::State& state) {
  const Grid grid = MakeGrid(static_cast<int>(state.range(0)));
  double tau = 0.0;
  for (auto _ : state) {
    tau = 0.0;
    for (const Vec2& r : grid.points) tau += grid.weight * r.norm();
    benchmark::DoNotOptimize(tau);
  }
  state.counters["rel_error"] = std::abs(tau / NgonTauMax(static_cast<int>(state.range(0))) - 1);
}

void LoadExact(benchmark::State& state, const ls::Twist& twist) {
  const ls::Support s = Polygon(static_cast<int>(state.range(0)));
  ls::Load load;
  for (auto _ : state) benchmark::DoNotOptimize(load = ls::SustainingLoad(s, twist));
  state.counters["rel_error"] = 0.0;  // it is the reference (tests: ~1e-15 against oracles)
}

void LoadGrid(benchmark::State& state, const ls::Twist& twist) {
  const int n = static_cast<int>(state.range(0));
  const Grid grid = MakeGrid(n);
  ls::Load load;
  for (auto _ : state) benchmark::DoNotOptimize(load = GridLoad(grid, twist));
  state.counters["rel_error"] = RelativeError(load, ls::SustainingLoad(Polygon(n), twist));
}

void BM_LoadNearExact(benchmark::State& state) { LoadExact(state, kNearTwist); }
void BM_LoadNearGrid16(benchmark::State& state) { LoadGrid(state, kNearTwist); }
void BM_LoadFarExact(benchmark::State& state) { LoadExact(state, kFarTwist); }
void BM_LoadFarGrid16(benchmark::State& state) { LoadGrid(state, kFarTwist); }

// Non-uniform (tilted) pressure: adaptive quadrature split at the rotation centre.
void BM_LoadNearLinearPressure(benchmark::State& state) {
  ls::SupportSpec spec;
  spec.region = Shape::RegularPolygon(static_cast<int>(state.range(0)), kCircumradius);
  spec.mass = kMass;
  spec.mu = kMu;
  spec.pressure = ls::Pressure::Linear(1.0, {8.0, 3.0});
  const ls::Support s = ls::MakeSupport(spec);
  ls::Load load;
  double error = 0.0;
  for (auto _ : state) benchmark::DoNotOptimize(load = ls::SustainingLoad(s, kNearTwist, &error));
  state.counters["est_error"] = error;
}

BENCHMARK(BM_TauMaxExact)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TauMaxGrid16)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadNearExact)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadNearGrid16)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadFarExact)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadFarGrid16)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LoadNearLinearPressure)->Arg(64)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
