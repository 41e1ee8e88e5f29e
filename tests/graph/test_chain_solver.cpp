// The chain solver (chain_solver.h) against Ceres: the same minimum on random chains with robust
// losses and bounds, on simulated pushes (a square and the non-convex notched block) and on a real
// MIT recording; its covariances against SparseMarginals on the problem; its errors (a factor
// that is not finite is named with its step); the incremental mode at every step.
#include <pushgraph/graph/chain_solver.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/factors.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/marginals.h>
#include <pushgraph/io/mit_push.h>
#include <pushgraph/push/simulator.h>

#include "graph/push_generator.h"
#include "test_scale.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace pushgraph::graph {
namespace {

using geometry::Pose2;
using geometry::Vec2;

// A chain of n poses with pose measurements (every third under a Huber loss, some outliers),
// constant-velocity factors, and a bounded 2-vector shared by every tenth pose through a
// measurement whose unconstrained optimum lies outside its box.
struct RandomChain {
  std::vector<std::array<double, 3>> poses;
  std::array<double, 2> shared{0.0, 0.0};
  ceres::Problem problem;

  RandomChain(int n, unsigned seed, double bound = 0.1) : poses(n) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (int i = 0; i < n; ++i) {
      const double t = 0.01 * i;
      const Pose2 truth{0.05 * t, 0.02 * std::sin(3 * t), 0.3 * t};
      Pose2 measured{truth.x + 0.005 * noise(rng), truth.y + 0.005 * noise(rng), truth.theta + 0.05 * noise(rng)};
      if (i % 17 == 5) measured.x += 0.05;  // outlier
      poses[i] = {measured.x + 0.01 * noise(rng), measured.y, measured.theta};
      ceres::LossFunction* loss = i % 3 == 0 ? new ceres::HuberLoss(1.0) : nullptr;
      problem.AddResidualBlock(new PoseMeasurementFactor(measured, 0.005, 0.05), loss, poses[i].data());
      if (i >= 2) {
        problem.AddResidualBlock(new ConstantVelocityFactor(0.01, 0.01, 0.05, 0.5), nullptr, poses[i - 2].data(),
                                 poses[i - 1].data(), poses[i].data());
      }
    }
    problem.AddResidualBlock(new VectorMeasurementFactor(Vec2(0.3, -0.2), 0.1), nullptr, shared.data());
    for (int i = 0; i < n; i += 10) {
      // |x_i - shared| small: the shared block is tied to many poses (the border of the band).
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Tie, 2, 3, 2>(new Tie), nullptr, poses[i].data(),
                               shared.data());
    }
    problem.SetParameterLowerBound(shared.data(), 0, -bound);
    problem.SetParameterUpperBound(shared.data(), 0, bound);
  }
  struct Tie {
    template <class T>
    bool operator()(const T* x, const T* s, T* r) const {
      r[0] = (x[0] * 0.0 + s[0] - T(0.05)) / T(0.5);
      r[1] = (x[1] * 0.0 + s[1] + T(0.05)) / T(0.5);
      return true;
    }
  };
};

ceres::Solver::Options TightCeres() {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.max_num_iterations = 500;
  o.function_tolerance = 1e-14;
  o.gradient_tolerance = 1e-14;
  o.parameter_tolerance = 1e-14;
  return o;
}

ChainSolverOptions TightChain() {
  ChainSolverOptions o;
  o.max_iterations = 500;
  o.function_tolerance = 1e-14;
  o.gradient_tolerance = 1e-14;
  o.parameter_tolerance = 1e-14;
  return o;
}

TEST(ChainSolver, SameMinimumAsCeresOnRandomChainsWithLosses) {
  for (unsigned seed : {1u, 2u, 3u}) {
    RandomChain a(300, seed, 1.0), b(300, seed, 1.0);  // bounds inactive at the minimum
    ceres::Solver::Summary ceres_summary;
    ceres::Solve(TightCeres(), &a.problem, &ceres_summary);
    ChainSolver solver(b.problem);
    const ChainSolverSummary s = solver.Solve(TightChain());
    EXPECT_TRUE(s.converged) << s.termination;
    EXPECT_NEAR(s.final_cost, ceres_summary.final_cost, 1e-9 * ceres_summary.final_cost);
    double worst = 0.0;
    for (std::size_t i = 0; i < a.poses.size(); ++i) {
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(a.poses[i][k] - b.poses[i][k]));
    }
    EXPECT_LT(worst, 1e-6) << "seed " << seed;
    EXPECT_NEAR(b.shared[0], a.shared[0], 1e-6);
    EXPECT_NEAR(b.shared[1], a.shared[1], 1e-6);
    // The factor is banded: a 300-pose chain with a shared border has no dense fill.
    EXPECT_LT(s.factor_nonzeros, 20L * s.unknowns);
  }
}

// The soft iteration limit: from that iteration on, a step that changes the cost by less than
// soft_function_tolerance of it ends the solve, unconverged; a larger change goes on.
TEST(ChainSolver, ASoftIterationLimitEndsOnlyWhereTheCostSettles) {
  RandomChain full(200, 4, 1.0), loose(200, 4, 1.0), tight(200, 4, 1.0);
  const ChainSolverSummary reference = ChainSolver(full.problem).Solve(TightChain());
  ASSERT_TRUE(reference.converged) << reference.termination;
  ChainSolverOptions o = TightChain();
  o.soft_iteration_limit = 2;
  o.soft_function_tolerance = 1.0;  // any successful step is small enough
  const ChainSolverSummary a = ChainSolver(loose.problem).Solve(o);
  EXPECT_FALSE(a.converged);
  EXPECT_NE(a.termination.find("soft limit (2 iterations"), std::string::npos) << a.termination;
  EXPECT_GE(a.iterations, 2);
  EXPECT_LT(a.iterations, reference.iterations);
  o.soft_function_tolerance = 0.0;  // no step is: the solve goes on to the tight tolerance
  const ChainSolverSummary b = ChainSolver(tight.problem).Solve(o);
  EXPECT_TRUE(b.converged) << b.termination;
  EXPECT_EQ(b.iterations, reference.iterations);
  EXPECT_EQ(b.final_cost, reference.final_cost);
}

// With the bound active: the Karush-Kuhn-Tucker conditions (zero gradient in every free
// unknown, the bounded one on its bound with the gradient pushing outward). Ceres' projected
// LM stops early on this problem (its cost 2e-8 relative above ours, gradient not zero), so
// the oracle is the optimality conditions, not Ceres.
TEST(ChainSolver, ActiveBoundsMeetTheOptimalityConditions) {
  for (unsigned seed : {1u, 2u, 3u}) {
    RandomChain b(300, seed, 0.1);
    ChainSolver solver(b.problem);
    const ChainSolverSummary s = solver.Solve(TightChain());
    EXPECT_TRUE(s.converged) << s.termination;
    EXPECT_DOUBLE_EQ(b.shared[0], 0.1);
    ceres::Problem::EvaluateOptions eval;
    for (auto& p : b.poses) eval.parameter_blocks.push_back(p.data());
    eval.parameter_blocks.push_back(b.shared.data());
    std::vector<double> gradient;
    double cost = 0.0;
    b.problem.Evaluate(eval, &cost, nullptr, &gradient, nullptr);
    const std::size_t bounded = gradient.size() - 2;
    EXPECT_LT(gradient[bounded], -1.0);  // the cost would fall beyond the upper bound
    double worst = 0.0;
    for (std::size_t i = 0; i < gradient.size(); ++i) {
      if (i != bounded) worst = std::max(worst, std::abs(gradient[i]));
    }
    // The information is about 4e4 per unknown (sigma 5 mm): 1e-3 is a step below 1e-7.
    EXPECT_LT(worst, 1e-3) << "seed " << seed;
  }
}

TEST(ChainSolver, CovariancesFromItsFactorEqualSparseMarginalsOnTheProblem) {
  RandomChain chain(200, 7);
  ChainSolver solver(chain.problem);
  solver.Solve(TightChain());
  SparseMarginals from_solver, from_problem;
  ASSERT_TRUE(from_solver.Compute(solver)) << from_solver.error();
  ASSERT_TRUE(from_problem.Compute(chain.problem)) << from_problem.error();
  for (std::size_t i = 0; i < chain.poses.size(); i += 7) {
    const Eigen::MatrixXd a = from_solver.Covariance(chain.poses[i].data());
    const Eigen::MatrixXd b = from_problem.Covariance(chain.poses[i].data());
    EXPECT_LT((a - b).norm(), 1e-9 * b.norm()) << "pose " << i;
  }
  const Eigen::MatrixXd a = from_solver.Covariance(chain.shared.data());
  const Eigen::MatrixXd b = from_problem.Covariance(chain.shared.data());
  EXPECT_LT((a - b).norm(), 1e-9 * b.norm());
}

// r = (x - 2) while x <= 1; fails to evaluate (or gives NaN) beyond: the solver must reject
// those steps and stop at the edge, never return NaN.
class FailsBeyondOne : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit FailsBeyondOne(bool nan) : nan_(nan) {}
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    if (p[0][0] > 1.0) {
      if (!nan_) return false;
      r[0] = NAN;
      if (J && J[0]) J[0][0] = 1.0;
      return true;
    }
    r[0] = p[0][0] - 2.0;
    if (J && J[0]) J[0][0] = 1.0;
    return true;
  }

 private:
  bool nan_;
};

TEST(ChainSolver, StepsThatFailToEvaluateAreRejected) {
  for (bool nan : {false, true}) {
    double x = 0.0;
    ceres::Problem problem;
    problem.AddResidualBlock(new FailsBeyondOne(nan), nullptr, &x);
    ChainSolver solver(problem);
    const ChainSolverSummary s = solver.Solve();
    EXPECT_TRUE(std::isfinite(x));
    EXPECT_LE(x, 1.0);
    EXPECT_GT(x, 0.9);
    EXPECT_GT(s.unsuccessful_steps, 0);
  }
}

// A residual that jumps right next to the start (a contact feature that switches): every real
// step raises the cost, and the step finally accepted under a huge damping changes it by nothing.
// That is a stall, not convergence: said, with the residual that jumps (an L-shaped finger's
// forces stayed at their measurements and the solve reported "function tolerance").
class JumpsAboveZero : public ceres::SizedCostFunction<1, 1> {
 public:
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    r[0] = p[0][0] > 1e-9 ? 1000.0 : 0.0;
    if (J != nullptr && J[0] != nullptr) J[0][0] = 0.0;
    return true;
  }
};

TEST(ChainSolver, AStallIsSaidWithTheResidualThatJumps) {
  double x = 0.0;
  ceres::Problem problem;
  ceres::Matrix a(1, 1);
  ceres::Vector b(1);
  a(0, 0) = 10.0;
  b(0) = 2.0;
  problem.AddResidualBlock(new ceres::NormalPrior(a, b), nullptr, &x);
  const ceres::ResidualBlockId jump = problem.AddResidualBlock(new JumpsAboveZero, nullptr, &x);
  ChainSolverOptions options;
  options.describe = [&](ceres::ResidualBlockId id) { return id == jump ? std::string("the jump factor") : "the prior"; };
  ChainSolver solver(problem);
  const ChainSolverSummary s = solver.Solve(options);
  EXPECT_FALSE(s.converged);
  EXPECT_TRUE(s.stalled);
  EXPECT_EQ(s.termination.rfind("stalled", 0), 0u) << s.termination;
  EXPECT_NE(s.termination.find("the jump factor"), std::string::npos) << s.termination;
  EXPECT_LT(x, 1e-6);
  // A smooth problem converges as before.
  double y = 0.0;
  ceres::Problem smooth;
  smooth.AddResidualBlock(new ceres::NormalPrior(a, b), nullptr, &y);
  ChainSolver plain(smooth);
  EXPECT_TRUE(plain.Solve().converged);
  EXPECT_NEAR(y, 2.0, 1e-9);
}

TEST(ChainSolver, NamesTheFactorThatIsNotFiniteAtTheStart) {
  double x = 3.0, y[2] = {0.0, 0.0};
  ceres::Problem problem;
  problem.AddResidualBlock(new VectorMeasurementFactor(Vec2(0, 0), 1.0), nullptr, y);
  const ceres::ResidualBlockId bad = problem.AddResidualBlock(new FailsBeyondOne(true), nullptr, &x);
  ChainSolverOptions options;
  options.describe = [&](ceres::ResidualBlockId id) { return id == bad ? std::string("the D factor at step 17") : "other"; };
  ChainSolver solver(problem);
  try {
    solver.Solve(options);
    FAIL() << "no error";
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("the D factor at step 17"), std::string::npos) << e.what();
  }
  // Without a description: its position in the problem.
  ChainSolver plain(problem);
  try {
    plain.Solve();
    FAIL() << "no error";
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("residual block 1"), std::string::npos) << e.what();
  }
}

// Both solvers to tight tolerances on the same trajectory: the same minimum.
void ExpectSameMinimum(const push::Trajectory& traj, Model model, const char* what, double state_tolerance = 1e-6) {
  EstimatorConfig cfg;
  if (traj.measurement_sigmas) cfg = ApplyMeasurementSigmas(cfg, *traj.measurement_sigmas);
  cfg.function_tolerance = 1e-12;
  cfg.max_iterations = 500;
  cfg.diagnostics = false;
  cfg.solver = EstimatorConfig::Solver::kCeres;
  const EstimationResult ceres_result = Estimate(traj, model, Mode::kBatch, cfg);
  cfg.solver = EstimatorConfig::Solver::kChain;
  const EstimationResult chain_result = Estimate(traj, model, Mode::kBatch, cfg);
  EXPECT_EQ(chain_result.solver.name, "chain");
  EXPECT_EQ(ceres_result.solver.name, "ceres");
  EXPECT_NEAR(chain_result.solver.final_cost, ceres_result.solver.final_cost, 1e-6 * ceres_result.solver.final_cost) << what;
  ASSERT_EQ(chain_result.states.size(), ceres_result.states.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < chain_result.states.size(); ++i) {
    const StateEstimate& a = chain_result.states[i];
    const StateEstimate& b = ceres_result.states[i];
    worst = std::max({worst, (a.object_pose.vector() - b.object_pose.vector()).cwiseAbs().maxCoeff(),
                      (a.finger_pose.vector() - b.finger_pose.vector()).cwiseAbs().maxCoeff()});
    if (a.contact && b.contact) worst = std::max(worst, (*a.contact - *b.contact).cwiseAbs().maxCoeff());
    ASSERT_EQ(a.object_pose_cov.has_value(), b.object_pose_cov.has_value());
    if (a.object_pose_cov) {
      EXPECT_LT((*a.object_pose_cov - *b.object_pose_cov).norm(), 1e-3 * b.object_pose_cov->norm()) << what << " step " << i;
    }
  }
  EXPECT_LT(worst, state_tolerance) << what;
  std::printf("[same minimum] %s: %zu steps, cost %.9g (chain) %.9g (ceres), worst state difference %.2g, "
              "iterations %d / %d\n",
              what, chain_result.states.size(), chain_result.solver.final_cost, ceres_result.solver.final_cost, worst,
              chain_result.solver.iterations, ceres_result.solver.iterations);
}

TEST(ChainSolver, SameMinimumAsCeresOnSimulatedPushes) {
  testing::PushSpec spec;
  spec.contact_offset = 0.02;
  spec.duration = 1.5;
  const push::Trajectory square = testing::GeneratePush(spec);
  ExpectSameMinimum(square, Model::kQs, "square, QS");
  ExpectSameMinimum(square, Model::kCp, "square, CP");
  ExpectSameMinimum(push::Simulate(testing::NotchedBlockPushPlan(0.7, 3)).trajectory, Model::kQs, "notched block, QS");
}

// An MIT recording's contact phase with the paper's tracker noise (5 mm, 0.05 rad on the object,
// 5 mm on the finger; 0.5 N on the force when `force_noise`).
push::Trajectory NoisyMitPush(const std::string& file, const geometry::Shape& shape, double mass, double finger_radius,
                              double mu_contact, unsigned seed, bool force_noise) {
  io::MitReadOptions options;
  options.trim_to_contact = true;
  const io::MitRecording rec = io::ReadMitPush(file, options);
  push::ObjectDescription object;
  object.shape = shape;
  object.mass = mass;
  object.mu_surface = 0.35;
  push::FingerDescription finger;
  finger.shape = geometry::Shape::Disk(finger_radius);
  finger.mu_contact = mu_contact;
  push::Trajectory t = io::MitToTrajectory(rec, object, finger);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto& s : t.measured.object_pose) s.pose = {s.pose.x + 0.005 * n(rng), s.pose.y + 0.005 * n(rng), s.pose.theta + 0.05 * n(rng)};
  for (auto& s : t.measured.finger_pose) s.pose = {s.pose.x + 0.005 * n(rng), s.pose.y + 0.005 * n(rng), s.pose.theta};
  if (force_noise) {
    for (auto& s : t.measured.force) s.force += Vec2(0.5 * n(rng), 0.5 * n(rng));
  }
  return t;
}

TEST(ChainSolver, SameMinimumAsCeresOnARealRecording) {
  const std::string file = std::string(PUSHGRAPH_SHARED_DIR) +
                           "/data/mit-push/abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.349.h5";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "no MIT data at " << file;
  const push::Trajectory t = NoisyMitPush(file, geometry::Shape::Box(0.09, 0.09), 0.8374, 0.00235, 0.2, 5, false);
  ExpectSameMinimum(t, Model::kQs, "MIT rect1, QS");
}

// The largest distance between two estimates' object positions, step by step.
double WorstObjectGap(const EstimationResult& a, const EstimationResult& b) {
  double worst = 0.0;
  for (std::size_t k = 0; k < a.states.size() && k < b.states.size(); ++k) {
    worst = std::max(worst, (a.states[k].object_pose.translation() - b.states[k].object_pose.translation()).norm());
  }
  return worst;
}

// A generated push, its batch QS estimate with the chain solver, and the config of an
// incremental update at every step.
struct PerStepCase {
  push::Trajectory traj;
  EstimatorConfig cfg;
  EstimationResult batch;
};
PerStepCase MakePerStepCase(double contact_offset, double duration, unsigned seed) {
  testing::PushSpec spec;
  spec.contact_offset = contact_offset;
  spec.duration = duration;
  spec.seed = seed;
  PerStepCase c;
  c.traj = testing::GeneratePush(spec);
  c.cfg.diagnostics = false;
  c.cfg.solver = EstimatorConfig::Solver::kChain;
  c.batch = Estimate(c.traj, Model::kQs, Mode::kBatch, c.cfg);
  c.cfg.incremental_update_every_steps = 1;
  return c;
}

TEST(ChainSolver, IncrementalAtEveryStepMatchesBatch) {
  const auto [traj, cfg, batch] = MakePerStepCase(0.02, 0.8, testing::PushSpec{}.seed);
  const EstimationResult inc = Estimate(traj, Model::kQs, Mode::kIncremental, cfg);
  EXPECT_EQ(inc.solver.updates, static_cast<int>(inc.states.size()) - 2);  // the first takes three steps
  EXPECT_EQ(inc.solver.update_times_s.size(), static_cast<std::size_t>(inc.solver.updates));
  for (double t : inc.solver.update_times_s) EXPECT_GT(t, 0.0);
  EXPECT_EQ(inc.solver.name, "chain");
  const double b = batch.metrics.at("object_position_rms"), i = inc.metrics.at("object_position_rms");
  std::printf("[incremental every step] %d updates, object RMS %.3f mm (batch %.3f)\n", inc.solver.updates, 1e3 * i, 1e3 * b);
  EXPECT_LT(i, 1.05 * b);
  EXPECT_LT(i, 0.3 * inc.metrics.at("measured_object_position_rms"));
}

// At the sensor rate the window is short (15 steps unless incremental_window_steps says
// otherwise); the final backward pass through the marginalized steps' conditionals brings every
// state to the batch estimate, means and marginal covariances alike. Without it each state is
// what it was when it left the short window: measurably further from batch.
TEST(ChainSolver, SmoothingPassBringsAShortWindowToTheBatchEstimate) {
  PerStepCase c = MakePerStepCase(0.015, 1.0, 9);
  const push::Trajectory& traj = c.traj;
  EstimatorConfig& cfg = c.cfg;
  const EstimationResult& batch = c.batch;
  IncrementalEstimator inc(traj, Model::kQs, cfg);
  int widest = 0;
  while (!inc.Done()) {
    inc.Update();
    widest = std::max(widest, inc.WindowSteps());
  }
  EXPECT_LE(widest, 15 + 1);  // the default window at the sensor rate, plus the step just added
  const EstimationResult smoothed = inc.Finish();
  cfg.incremental_smoothing = false;
  const EstimationResult lagged = Estimate(traj, Model::kQs, Mode::kIncremental, cfg);
  ASSERT_EQ(smoothed.states.size(), batch.states.size());
  ASSERT_EQ(lagged.states.size(), batch.states.size());
  double gap_smoothed = 0.0, gap_lagged = 0.0, worst_cov_ratio = 1.0;
  for (std::size_t k = 0; k < batch.states.size(); ++k) {
    gap_smoothed += (smoothed.states[k].object_pose.translation() - batch.states[k].object_pose.translation()).squaredNorm();
    gap_lagged += (lagged.states[k].object_pose.translation() - batch.states[k].object_pose.translation()).squaredNorm();
    ASSERT_TRUE(smoothed.states[k].object_pose_cov.has_value()) << k;
    ASSERT_TRUE(batch.states[k].object_pose_cov.has_value()) << k;
    const double ratio = smoothed.states[k].object_pose_cov->trace() / batch.states[k].object_pose_cov->trace();
    worst_cov_ratio = std::max(worst_cov_ratio, std::max(ratio, 1.0 / ratio));
    if (batch.states[k].force_cov) {
      ASSERT_TRUE(smoothed.states[k].force_cov.has_value()) << k;
      EXPECT_GT(smoothed.states[k].force_cov->determinant(), 0.0) << k;
    }
  }
  gap_smoothed = std::sqrt(gap_smoothed / batch.states.size());
  gap_lagged = std::sqrt(gap_lagged / batch.states.size());
  const double b = batch.metrics.at("object_position_rms"), i = smoothed.metrics.at("object_position_rms");
  std::printf("[smoothing pass] RMS |inc - batch|: %.4f mm smoothed, %.4f mm without; object RMS %.3f mm (batch %.3f, "
              "without %.3f); worst covariance trace ratio %.3f; status %s\n",
              1e3 * gap_smoothed, 1e3 * gap_lagged, 1e3 * i, 1e3 * b, 1e3 * lagged.metrics.at("object_position_rms"),
              worst_cov_ratio, smoothed.solver.covariance_status.c_str());
  EXPECT_EQ(smoothed.solver.covariance_status, "ok");
  EXPECT_LT(i, 1.05 * b);
  EXPECT_LT(gap_smoothed, 0.5 * gap_lagged);
  EXPECT_LT(worst_cov_ratio, 1.5);
  // Same bits for the same input (the pass sums in a fixed order).
  cfg.incremental_smoothing = true;
  const EstimationResult again = Estimate(traj, Model::kQs, Mode::kIncremental, cfg);
  for (std::size_t k = 0; k < again.states.size(); ++k) {
    ASSERT_EQ(again.states[k].object_pose.vector(), smoothed.states[k].object_pose.vector()) << k;
    ASSERT_EQ(*again.states[k].object_pose_cov, *smoothed.states[k].object_pose_cov) << k;
  }
}

// At the sensor rate an update's window solve has a soft limit (unset
// incremental_window_iterations: from the third iteration on it ends at a step that changes the
// cost by less than 3e-4 of it, a bounded relinearization per update as iSAM2's); a step is
// refined by the ten or more updates it spends in the window, and Finish re-solves the last
// window, which no later update refines. The result stays with the unlimited smoother's, the
// newest steps included.
TEST(ChainSolver, BoundedWindowSolvesAtTheSensorRateKeepTheResult) {
  PerStepCase c = MakePerStepCase(0.015, 1.0, 5);
  EstimatorConfig cfg = c.cfg;
  ASSERT_EQ(cfg.incremental_window_iterations, 0);  // unset: a soft limit of 3 at the sensor rate
  const EstimationResult capped = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  cfg.incremental_window_iterations = cfg.incremental_max_iterations;
  const EstimationResult full = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  ASSERT_EQ(capped.states.size(), full.states.size());
  double worst = 0.0, worst_last = 0.0;
  const std::size_t n = capped.states.size();
  for (std::size_t k = 0; k < n; ++k) {
    const double d = (capped.states[k].object_pose.translation() - full.states[k].object_pose.translation()).norm();
    worst = std::max(worst, d);
    if (k + 15 >= n) worst_last = std::max(worst_last, d);
  }
  const double b = c.batch.metrics.at("object_position_rms"), i = capped.metrics.at("object_position_rms");
  std::printf("[bounded window solves] %d against %d iterations over %d updates; |capped - uncapped| worst %.4f mm, "
              "last 15 steps %.4f mm; object RMS %.3f mm (uncapped %.3f, batch %.3f)\n",
              capped.solver.iterations, full.solver.iterations, capped.solver.updates, 1e3 * worst, 1e3 * worst_last,
              1e3 * i, 1e3 * full.metrics.at("object_position_rms"), 1e3 * b);
  // Measured: 2086 against 2551 iterations since the new QS steps' kinematic stage is capped at 2
  // (2147 against 2612 before), worst and last 15 steps 0.004 mm (the hard cap of 3
  // before 2026-11-28: 2073 iterations, 0.009 mm; 0.07 mm when Finish did not converge the last
  // window).
  EXPECT_LT(capped.solver.iterations, full.solver.iterations);
  EXPECT_LT(worst_last, 2e-5);
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(i, 1.05 * b);
  // Unset is a soft limit of 3 there, which goes on where a window is far from its minimum; 3 set
  // is a hard cap, which does not.
  cfg.incremental_window_iterations = 3;
  const EstimationResult three = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  std::printf("[bounded window solves] a hard cap of 3: %d iterations\n", three.solver.iterations);
  EXPECT_LT(three.solver.iterations, capped.solver.iterations);
  // The Ceres path runs the soft limit as two solves (GraphBuilder::Solve): the same estimate
  // within the solves' tolerances.
  EstimatorConfig by_ceres_cfg = c.cfg;
  by_ceres_cfg.solver = EstimatorConfig::Solver::kCeres;
  const EstimationResult by_ceres = Estimate(c.traj, Model::kQs, Mode::kIncremental, by_ceres_cfg);
  ASSERT_EQ(by_ceres.states.size(), n);
  const double ceres_gap = WorstObjectGap(by_ceres, capped);
  std::printf("[bounded window solves] Ceres: %d iterations, |Ceres - chain| worst %.4f mm, object RMS %.3f mm\n",
              by_ceres.solver.iterations, 1e3 * ceres_gap, 1e3 * by_ceres.metrics.at("object_position_rms"));
  EXPECT_LT(ceres_gap, 1e-4);
  EXPECT_LT(by_ceres.metrics.at("object_position_rms"), 1.05 * b);
  // Where a step spends fewer than ten updates in the window (every 5 steps, a 15-step window)
  // unset means uncapped: the same bits as incremental_max_iterations set.
  cfg.incremental_update_every_steps = 5;
  cfg.incremental_window_steps = 15;
  cfg.incremental_window_iterations = 0;
  const EstimationResult short_unset = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  cfg.incremental_window_iterations = cfg.incremental_max_iterations;
  const EstimationResult short_full = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  EXPECT_EQ(short_unset.solver.iterations, short_full.solver.iterations);
  for (std::size_t k = 0; k < n; ++k) {
    ASSERT_EQ(short_unset.states[k].object_pose.vector(), short_full.states[k].object_pose.vector()) << k;
  }
  // A last window that does not converge within incremental_max_iterations is said so.
  cfg = c.cfg;
  cfg.incremental_max_iterations = 1;
  const EstimationResult starved = Estimate(c.traj, Model::kQs, Mode::kIncremental, cfg);
  bool warned = false;
  for (const std::string& w : starved.warnings) {
    warned = warned || w.find("the last window's solve stopped at incremental_max_iterations (1)") != std::string::npos;
  }
  EXPECT_TRUE(warned);
  bool warned_before = false;
  for (const std::string& w : capped.warnings) warned_before = warned_before || w.find("the last window's solve") != std::string::npos;
  EXPECT_FALSE(warned_before);
}

// Every k object samples (incremental_update_every_steps unset) the window solves have the same
// soft limit of 3 at 3e-5 of the cost (FixedLagSmoother::WindowSoftTolerance): fewer iterations,
// the same estimate within a fraction of the noise; set, incremental_window_iterations is a hard
// cap instead, so incremental_max_iterations set is the solve without a limit.
TEST(ChainSolver, WindowSolvesEveryFewObjectSamplesStopWhereTheCostSettles) {
  const push::Trajectory traj = testing::GeneratePush(testing::PushSpec{});
  EstimatorConfig cfg;
  cfg.diagnostics = false;
  ASSERT_EQ(cfg.incremental_update_every_steps, 0);
  ASSERT_EQ(cfg.incremental_window_iterations, 0);
  const EstimationResult soft = Estimate(traj, Model::kQs, Mode::kIncremental, cfg);
  cfg.incremental_window_iterations = cfg.incremental_max_iterations;
  const EstimationResult full = Estimate(traj, Model::kQs, Mode::kIncremental, cfg);
  ASSERT_EQ(soft.states.size(), full.states.size());
  const double worst = WorstObjectGap(soft, full);
  const double s = soft.metrics.at("object_position_rms"), f = full.metrics.at("object_position_rms");
  std::printf("[window solves every 5 samples] %d against %d iterations over %d updates; |soft - full| worst %.4f mm; "
              "object RMS %.3f mm against %.3f\n",
              soft.solver.iterations, full.solver.iterations, soft.solver.updates, 1e3 * worst, 1e3 * s, 1e3 * f);
  // Measured: 143 against 157 iterations over 11 updates, worst 0.020 mm, 1.082 against 1.079 mm
  // (equal iterations before this change, the afternoon of 2026-11-28, when only the sensor rate
  // had a soft limit).
  EXPECT_LT(soft.solver.iterations, full.solver.iterations);
  EXPECT_LT(worst, 1e-4);  // the noise is 5 mm
  EXPECT_LT(s, 1.02 * f);
  // The Ceres path runs the soft limit as two solves at the same tolerance: the same estimate
  // within the solves' tolerances.
  EstimatorConfig by_ceres_cfg;
  by_ceres_cfg.diagnostics = false;
  by_ceres_cfg.solver = EstimatorConfig::Solver::kCeres;
  const EstimationResult by_ceres = Estimate(traj, Model::kQs, Mode::kIncremental, by_ceres_cfg);
  ASSERT_EQ(by_ceres.states.size(), soft.states.size());
  const double ceres_gap = WorstObjectGap(by_ceres, soft);
  std::printf("[window solves every 5 samples] Ceres: %d iterations, |Ceres - chain| worst %.4f mm\n",
              by_ceres.solver.iterations, 1e3 * ceres_gap);
  EXPECT_LT(ceres_gap, 1e-4);
}

// A slow real push (ellip1 at 20 mm/s, 1456 steps of 250 Hz) with the tracker noise of the
// paper's protocol, an update at every step. With a hard cap of 3 iterations per window solve its
// first windows stopped far from their minimum, the marginal priors kept that and the estimate
// diverged (object RMS 22.5 mm, rotation 0.6 rad, against 0.62 mm uncapped); the soft limit goes
// on where a step still changes the cost by more than 3e-4 of it.
TEST(ChainSolver, WindowSolvesAtTheSensorRateDoNotDivergeOnASlowRealPush) {
  const std::string file = std::string(PUSHGRAPH_SHARED_DIR) +
                           "/data/mit-push/abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=20_i=0.000_s=0.675_t=1.047.h5";
  if (!std::filesystem::exists(file)) GTEST_SKIP() << "no MIT data at " << file;
  const push::Trajectory t = NoisyMitPush(file, geometry::Shape::Disk(0.0525), 0.8937, 0.0047, 0.25, 1, true);
  EstimatorConfig cfg;
  cfg.diagnostics = false;
  const EstimationResult batch = Estimate(t, Model::kQs, Mode::kBatch, cfg);
  cfg.incremental_update_every_steps = 1;
  const EstimationResult inc = Estimate(t, Model::kQs, Mode::kIncremental, cfg);
  const double b = batch.metrics.at("object_position_rms"), i = inc.metrics.at("object_position_rms");
  std::printf("[slow real push, an update per step] %zu steps, object RMS %.3f mm (batch %.3f, raw %.3f), rotation "
              "%.4f rad (batch %.4f), %d iterations\n",
              inc.states.size(), 1e3 * i, 1e3 * b, 1e3 * inc.metrics.at("measured_object_position_rms"),
              inc.metrics.at("object_rotation_rms"), batch.metrics.at("object_rotation_rms"), inc.solver.iterations);
  EXPECT_LT(i, 1.2 * b);
  EXPECT_LT(inc.metrics.at("object_rotation_rms"), 1.2 * batch.metrics.at("object_rotation_rms"));
  if (pushgraph::testing::TestScale() < 1.0) return;  // the sanitizer stage: the comparison below is a third estimate
  // The push still shows what the soft limit is for: the hard cap of 3, the default until
  // 2026-11-28, diverges on it (11.5 mm).
  cfg.incremental_window_iterations = 3;
  const EstimationResult capped = Estimate(t, Model::kQs, Mode::kIncremental, cfg);
  std::printf("[slow real push] a hard cap of 3: object RMS %.3f mm, %d iterations\n",
              1e3 * capped.metrics.at("object_position_rms"), capped.solver.iterations);
  EXPECT_GT(capped.metrics.at("object_position_rms"), 3.0 * i);
}

TEST(ChainSolver, ConfigSelectsTheSolverAndTheUpdateRate) {
  EXPECT_EQ(ParseEstimatorConfig(R"({"solver": "ceres"})").solver, EstimatorConfig::Solver::kCeres);
  EXPECT_EQ(ParseEstimatorConfig(R"({"solver": "chain"})").solver, EstimatorConfig::Solver::kChain);
  EXPECT_EQ(EstimatorConfig{}.solver, EstimatorConfig::Solver::kChain);
  EXPECT_EQ(ParseEstimatorConfig(R"({"incremental_update_every_steps": 1})").incremental_update_every_steps, 1);
  EXPECT_EQ(ParseEstimatorConfig(R"({"incremental_window_steps": 40})").incremental_window_steps, 40);
  EXPECT_EQ(ParseEstimatorConfig(R"({"incremental_window_iterations": 5})").incremental_window_iterations, 5);
  EXPECT_TRUE(EstimatorConfig{}.incremental_smoothing);
  EXPECT_FALSE(ParseEstimatorConfig(R"({"incremental_smoothing": false})").incremental_smoothing);
  for (const char* bad : {R"({"solver": "gtsam"})", R"({"incremental_update_every_steps": 0})",
                          R"({"incremental_update_every_steps": 1.5})", R"({"incremental_window_steps": 2})",
                          R"({"incremental_window_steps": "25"})", R"({"incremental_smoothing": 1})",
                          R"({"incremental_window_iterations": 0})", R"({"incremental_window_iterations": 2.5})"}) {
    try {
      ParseEstimatorConfig(bad, "cfg.json");
      ADD_FAILURE() << bad;
    } catch (const GraphError& e) {
      EXPECT_NE(std::string(e.what()).find("cfg.json"), std::string::npos) << e.what();
    }
  }
}

// An integer key's value outside int's range is an error naming the key, not a silent wrap
// (4294967297 read as 1 would cap every solve at one iteration).
TEST(ChainSolver, ConfigIntegersOutOfRangeAreErrors) {
  EXPECT_EQ(ParseEstimatorConfig(R"({"max_iterations": 2147483647})").max_iterations, 2147483647);
  for (const std::string key : {"max_iterations", "incremental_window", "incremental_update_every",
                                "incremental_max_iterations", "incremental_update_every_steps",
                                "incremental_window_steps", "incremental_window_iterations"}) {
    for (const std::string value : {"4294967297", "2147483648", "18446744073709551615", "-4294967295"}) {
      const std::string text = "{\"" + key + "\": " + value + "}";
      try {
        ParseEstimatorConfig(text, "cfg.json");
        ADD_FAILURE() << text;
      } catch (const GraphError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("cfg.json: config key '" + key + "'"), std::string::npos) << what;
        EXPECT_NE(what.find("out of range"), std::string::npos) << what;
      }
    }
  }
  // Unset, the window is the larger of 5 and the update interval; set, it must hold one update.
  EXPECT_EQ(ParseEstimatorConfig("{}").IncrementalWindowPeriods(), 5);
  EXPECT_EQ(ParseEstimatorConfig(R"({"incremental_update_every": 8})").IncrementalWindowPeriods(), 8);
  EXPECT_EQ(ParseEstimatorConfig(R"({"incremental_window": 9})").IncrementalWindowPeriods(), 9);
  EXPECT_THROW(ParseEstimatorConfig(R"({"incremental_window": 0})"), GraphError);
  // A window shorter than the default update interval names both values (it named only the key
  // the user had not set).
  try {
    ParseEstimatorConfig(R"({"incremental_window": 2})", "cfg.json");
    ADD_FAILURE() << "incremental_window 2 accepted";
  } catch (const GraphError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("incremental_window (2 object periods) must be >= incremental_update_every (5;"), std::string::npos)
        << what;
  }
}

}  // namespace
}  // namespace pushgraph::graph
