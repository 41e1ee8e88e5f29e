// Batch solve time against the number of steps (the push generator's 250 Hz clock with object
// poses at 25 Hz), with and without marginal covariances, and the incremental (fixed-lag)
// update time against trajectory length: it must stay flat, replayed (IncrementalEstimator) and
// fed sample by sample (OnlineEstimator).
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/registration.h>

#include "graph/online_feed.h"
#include "graph/push_generator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <vector>

namespace {

using namespace pushgraph;

const push::Trajectory& Push(int steps) {
  static std::map<int, push::Trajectory> cache;
  auto it = cache.find(steps);
  if (it == cache.end()) {
    graph::testing::PushSpec s;
    s.contact_offset = 0.01;
    s.duration = (steps - 1) / 250.0;
    s.seed = 5;
    it = cache.emplace(steps, graph::testing::GeneratePush(s)).first;
  }
  return it->second;
}

// One batch estimate of `traj` by the chain solver or Ceres (the peer). The self-diagnosis is
// left out and no shape is aligned; the shape check (BM_RegisterShape) still runs, whichever
// solver; every solver stage is in.
void BatchOn(benchmark::State& state, const push::Trajectory& traj, bool ceres, graph::Model model, bool covariance,
             graph::EstimatorConfig::CovarianceMethod method = graph::EstimatorConfig::CovarianceMethod::kSelectedInversion) {
  graph::EstimatorConfig cfg;
  cfg.covariance = covariance;
  cfg.covariance_method = method;
  cfg.diagnostics = false;
  cfg.align_shape = graph::EstimatorConfig::AlignShape::kOff;
  cfg.tessellated_finger_as_disk = false;  // BM_BatchQsPolygonFinger measures the 32-gon itself
  cfg.solver = ceres ? graph::EstimatorConfig::Solver::kCeres : graph::EstimatorConfig::Solver::kChain;
  graph::SolverStats stats;
  for (auto _ : state) {
    const graph::EstimationResult r = graph::Estimate(traj, model, graph::Mode::kBatch, cfg);
    stats = r.solver;
    benchmark::DoNotOptimize(r.states.data());
  }
  state.SetLabel(stats.name);
  state.counters["iterations"] = stats.iterations;
  state.counters["solver_ms"] = 1e3 * stats.time_s;
  if (stats.factor_flops > 0.0) {
    // The final stage's profile: where an iteration's time goes, and the factorization's rate
    // against its flop count (the physical limit: about 1-4 GFlop/s for this sparse, scalar
    // code on one core of this machine).
    state.counters["final_stage_eval_ms"] = 1e3 * stats.evaluation_time_s;
    state.counters["final_stage_linear_ms"] = 1e3 * stats.linear_solve_time_s;
    state.counters["factor_mflop"] = 1e-6 * stats.factor_flops;
  }
}

// range(0): steps; range(1): 0 the chain solver, 1 Ceres.
void Batch(benchmark::State& state, graph::Model model, bool covariance,
           graph::EstimatorConfig::CovarianceMethod method = graph::EstimatorConfig::CovarianceMethod::kSelectedInversion) {
  BatchOn(state, Push(static_cast<int>(state.range(0))), state.range(1) == 1, model, covariance, method);
  state.counters["steps"] = static_cast<double>(state.range(0));
}

// The same square with every side cut into equal collinear edges: the same geometry, so the same
// estimate, with n vertices. Its time against the 4-vertex square's is what a detailed mesh costs
// the estimator (the registration, every factor's shape query and the diagnostics included).
geometry::Shape SubdividedSquare(double side, int vertices) {
  const int per_side = std::max(1, vertices / 4);
  geometry::Polygon p;
  const geometry::Vec2 corners[4] = {{-side / 2, -side / 2}, {side / 2, -side / 2}, {side / 2, side / 2}, {-side / 2, side / 2}};
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < per_side; ++k)
      p.outer.push_back(corners[c] + (corners[(c + 1) % 4] - corners[c]) * (static_cast<double>(k) / per_side));
  return geometry::Shape::FromPolygons({p});
}

void BM_BatchQsDetailedObject(benchmark::State& state) {
  push::Trajectory traj = Push(1000);
  traj.object.shape = SubdividedSquare(0.09, static_cast<int>(state.range(0)));
  graph::EstimatorConfig cfg;
  cfg.covariance = false;
  double rms = 0.0;
  for (auto _ : state) {
    const graph::EstimationResult r = graph::Estimate(traj, graph::Model::kQs, graph::Mode::kBatch, cfg);
    rms = r.metrics.count("object_position_rms") ? r.metrics.at("object_position_rms") : -1.0;
    benchmark::DoNotOptimize(r.states.data());
  }
  state.counters["vertices"] = static_cast<double>(traj.object.shape.num_vertices());
  state.counters["object_rms_m"] = rms;
}
BENCHMARK(BM_BatchQsDetailedObject)->Arg(4)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->Iterations(1);

// The shape check every estimate runs (RegisterShape: the units, mirror and rotation search over
// the contacts, then the refinement): part of BM_BatchQs' time for either solver.
void BM_RegisterShape(benchmark::State& state) {
  const auto& traj = Push(static_cast<int>(state.range(0)));
  graph::EstimatorConfig cfg;
  const graph::RegistrationOptions options = graph::RegistrationOptionsFor(cfg);
  for (auto _ : state) {
    const graph::RegistrationResult r = graph::RegisterShape(traj, options);
    benchmark::DoNotOptimize(r.transform.pose.x);
  }
}
BENCHMARK(BM_RegisterShape)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond)->Iterations(1);

// A polygonal finger against the disk it tessellates (range(0) 0: the 5 mm disk, the peer; 1: a
// 32-gon of the same circumradius, as `pushgraph footprint tip.obj` gives): every contact factor's
// shape-pair query then goes through the Minkowski obstacle of the pair at its relative angle.
void BM_BatchQsPolygonFinger(benchmark::State& state) {
  push::Trajectory traj = Push(1000);
  if (state.range(0) == 1) traj.finger.shape = geometry::Shape::RegularPolygon(32, traj.finger.shape.radius());
  BatchOn(state, traj, /*ceres=*/false, graph::Model::kQs, /*covariance=*/false);
  state.SetLabel(state.range(0) == 1 ? "32-gon finger" : "disk finger");
}
BENCHMARK(BM_BatchQsPolygonFinger)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_BatchQs(benchmark::State& s) { Batch(s, graph::Model::kQs, false); }
void BM_BatchQsWithCovariance(benchmark::State& s) { Batch(s, graph::Model::kQs, true); }
// The peer of the covariances: ceres::Covariance (SPARSE_QR) for the marginals.
void BM_BatchQsWithCeresCovariance(benchmark::State& s) {
  Batch(s, graph::Model::kQs, true, graph::EstimatorConfig::CovarianceMethod::kCeres);
}
void BM_BatchCp(benchmark::State& s) { Batch(s, graph::Model::kCp, false); }
// Args: steps, solver (0 chain, 1 Ceres).
BENCHMARK(BM_BatchQs)->ArgsProduct({{100, 1000, 10000}, {0, 1}})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BatchCp)->ArgsProduct({{100, 1000, 10000}, {0, 1}})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BatchQsWithCovariance)->ArgsProduct({{100, 1000, 10000}, {0, 1}})->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BatchQsWithCeresCovariance)->Args({100, 1})->Args({1000, 1})->Unit(benchmark::kMillisecond)->Iterations(1);

// Runs the whole incremental estimation; reports the mean and max update time and the mean of
// the last quarter of the updates (flat against length means bounded cost).
// range(1): incremental_update_every_steps (0: every 5 object samples, the default); range(2):
// 0 chain, 1 Ceres.
void Incremental(benchmark::State& state, bool covariance) {
  const auto& traj = Push(static_cast<int>(state.range(0)));
  graph::EstimatorConfig cfg;
  cfg.covariance = covariance;
  cfg.diagnostics = false;
  cfg.incremental_update_every_steps = static_cast<int>(state.range(1));
  cfg.solver = state.range(2) == 1 ? graph::EstimatorConfig::Solver::kCeres : graph::EstimatorConfig::Solver::kChain;
  double mean = 0, worst = 0, last_quarter = 0, p95 = 0, finish = 0;
  for (auto _ : state) {
    graph::IncrementalEstimator inc(traj, graph::Model::kQs, cfg);
    std::vector<double> times;
    while (!inc.Done()) times.push_back(inc.Update());
    const auto finish_start = std::chrono::steady_clock::now();
    const auto r = inc.Finish();
    finish = std::chrono::duration<double>(std::chrono::steady_clock::now() - finish_start).count();
    benchmark::DoNotOptimize(r.states.data());
    mean = worst = last_quarter = 0;
    const std::size_t q = times.size() * 3 / 4;
    for (std::size_t i = 0; i < times.size(); ++i) {
      mean += times[i] / times.size();
      worst = std::max(worst, times[i]);
      if (i >= q) last_quarter += times[i] / (times.size() - q);
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    p95 = sorted.empty() ? 0.0 : sorted[sorted.size() * 95 / 100];
  }
  state.counters["steps"] = static_cast<double>(state.range(0));
  state.counters["mean_update_ms"] = 1e3 * mean;
  state.counters["last_quarter_update_ms"] = 1e3 * last_quarter;
  state.counters["p95_update_ms"] = 1e3 * p95;
  state.counters["max_update_ms"] = 1e3 * worst;
  // Finish(): the rest of the window eliminated and the backward smoothing pass over every step
  // (with covariances when asked).
  state.counters["finish_ms"] = 1e3 * finish;
}
void BM_IncrementalQs(benchmark::State& s) { Incremental(s, false); }
void BM_IncrementalQsWithCovariance(benchmark::State& s) { Incremental(s, true); }
// Args: steps, update every k steps (0: every 5 object samples), solver (0 chain, 1 Ceres).
// An update at every step (the 250 Hz sensor rate) keeps a 15-step window; 50000 steps (200 s of
// pushing) with the chain solver only (Ceres' per-call overhead makes it minutes).
BENCHMARK(BM_IncrementalQs)
    ->ArgsProduct({{500, 2000, 8000}, {0}, {0, 1}})
    ->ArgsProduct({{500, 2000, 8000}, {1}, {0, 1}})
    ->Args({50000, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_IncrementalQsWithCovariance)
    ->ArgsProduct({{500, 2000}, {0}, {0, 1}})
    ->ArgsProduct({{500, 8000}, {1}, {0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// The machine's own noise floor for a worst update: `range(0)` chunks of fixed arithmetic, each
// about one mean per-step update (0.9 ms) long, timed like the updates. On this 2-core VM their
// maximum is 3 to 5 ms (the scheduler takes the core away now and then), so a worst update
// within a few ms of it is the machine, not the solver.
void BM_MachineJitter(benchmark::State& state) {
  double mean = 0.0, worst = 0.0;
  for (auto _ : state) {
    std::vector<double> times;
    double sink = 0.0;
    for (int k = 0; k < state.range(0); ++k) {
      const auto start = std::chrono::steady_clock::now();
      double sum = 0.0;
      for (int i = 0; i < 900000; ++i) sum += static_cast<double>(i & 7) * 1e-9;
      benchmark::DoNotOptimize(sum);
      sink += sum;
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    benchmark::DoNotOptimize(sink);
    mean = worst = 0.0;
    for (double t : times) mean += t / times.size(), worst = std::max(worst, t);
  }
  state.counters["chunks"] = static_cast<double>(state.range(0));
  state.counters["mean_chunk_ms"] = 1e3 * mean;
  state.counters["max_chunk_ms"] = 1e3 * worst;
}
BENCHMARK(BM_MachineJitter)->Arg(8000)->Unit(benchmark::kMillisecond)->Iterations(1);

// The same push through graph::OnlineEstimator, one sample at a time (grouped by time stamp,
// UpdateDue polled after each stamp): the update times, and the bookkeeping per sample outside
// the updates (Add* and UpdateDue), which must not grow with the length either.
void BM_OnlineQs(benchmark::State& state) {
  const auto& traj = Push(static_cast<int>(state.range(0)));
  const std::vector<graph::testing::Arrival> samples = graph::testing::ArrivalOrder(traj);
  push::Trajectory setup = graph::testing::SetupOf(traj);
  setup.ground_truth.reset();
  graph::EstimatorConfig cfg;
  cfg.covariance = false;
  // As the other benchmarks: no self-diagnosis, here the shape checks some updates make (up to a
  // 4 s registration each, at doublings of the data; OnlineEstimator::Warnings).
  cfg.diagnostics = false;
  cfg.incremental_update_every_steps = static_cast<int>(state.range(1));
  double mean = 0, worst = 0, per_sample_us = 0;
  for (auto _ : state) {
    graph::OnlineStreams streams = graph::testing::StreamsOf(traj);
    // At the sensor rate the 25 Hz camera is not waited for between frames (its frames arrive
    // with the other streams' samples of the same stamp, so none is late).
    if (cfg.incremental_update_every_steps >= 1) streams.max_latency = 0.0;
    graph::OnlineEstimator online(setup, graph::Model::kQs, cfg, streams);
    std::vector<double> times;
    double total = 0;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < samples.size(); ++k) {
      graph::testing::Deliver(samples[k], traj, online);
      const bool stamp_complete = k + 1 == samples.size() || samples[k + 1].t > samples[k].t;
      if (stamp_complete && online.UpdateDue()) {
        times.push_back(online.Update());
        total += times.back();
      }
    }
    const double loop = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const auto r = online.Finish();
    benchmark::DoNotOptimize(r.states.data());
    mean = worst = 0;
    for (double t : times) {
      mean += t / times.size();
      worst = std::max(worst, t);
    }
    per_sample_us = 1e6 * (loop - total) / samples.size();
  }
  state.counters["steps"] = static_cast<double>(state.range(0));
  state.counters["mean_update_ms"] = 1e3 * mean;
  state.counters["max_update_ms"] = 1e3 * worst;
  state.counters["per_sample_us"] = per_sample_us;
}
// Args: steps, update every k steps (0: every 5 object samples).
BENCHMARK(BM_OnlineQs)->ArgsProduct({{500, 2000, 8000}, {0, 1}})->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
