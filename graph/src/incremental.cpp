#include "graph_builder.h"
#include "contact_fit.h"
#include "text.h"
#include <pushgraph/graph/registration.h>

#include <pushgraph/graph/incremental.h>

#include <Eigen/QR>

#include <algorithm>
#include <deque>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace pushgraph::graph {

MarginalPriorFactor::MarginalPriorFactor(std::vector<int> block_sizes, Eigen::VectorXd x_bar,
                                         Eigen::MatrixXd S, Eigen::VectorXd r0)
    : x_bar_(std::move(x_bar)), r0_(std::move(r0)), S_(std::move(S)) {
  int total = 0;
  for (int s : block_sizes) {
    mutable_parameter_block_sizes()->push_back(s);
    total += s;
  }
  if (total != x_bar_.size() || S_.cols() != total || S_.rows() != r0_.size() || S_.rows() == 0) {
    throw GraphError("MarginalPriorFactor: inconsistent dimensions");
  }
  set_num_residuals(static_cast<int>(S_.rows()));
}

bool MarginalPriorFactor::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const auto& sizes = parameter_block_sizes();
  Eigen::VectorXd dx(x_bar_.size());
  int off = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    for (int j = 0; j < sizes[k]; ++j) dx[off + j] = parameters[k][j] - x_bar_[off + j];
    off += sizes[k];
  }
  Eigen::Map<Eigen::VectorXd>(residuals, S_.rows()) = S_ * dx + r0_;
  if (jacobians != nullptr) {
    off = 0;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      if (jacobians[k] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[k], S_.rows(), sizes[k]) = S_.middleCols(off, sizes[k]);
      }
      off += sizes[k];
    }
  }
  return true;
}

namespace {

// The median spacing of the object stream's samples (0 with fewer than two); of the newest
// `recent` only, when given (the online front end: constant cost per call).
double MedianObjectPeriod(const std::vector<push::PoseSample>& obj,
                          std::size_t recent = std::numeric_limits<std::size_t>::max()) {
  std::vector<double> periods;
  const std::size_t first = obj.size() > recent ? obj.size() - recent : 0;
  for (std::size_t i = first + 1; i < obj.size(); ++i) periods.push_back(obj[i].t - obj[i - 1].t);
  if (periods.empty()) return 0.0;
  std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
  return periods[periods.size() / 2];
}

// A time in a message, in the fewest digits that read back as the same double (samples can be
// nanoseconds apart; 17 digits printed the update time 0.36 as 0.35999999999999999).
std::string Precise(double t) {
  std::ostringstream o;
  for (int digits = 6; digits <= 17; ++digits) {
    o.str("");
    o.precision(digits);
    o << t;
    if (digits == 17 || std::strtod(o.str().c_str(), nullptr) == t) break;
  }
  return o.str();
}

// The blocks' values, concatenated.
Eigen::VectorXd Values(const std::vector<double*>& blocks, const std::vector<int>& sizes) {
  int total = 0;
  for (int n : sizes) total += n;
  Eigen::VectorXd v(total);
  int off = 0;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    for (int j = 0; j < sizes[k]; ++j) v[off + j] = blocks[k][j];
    off += sizes[k];
  }
  return v;
}

// What marginalizing one step leaves behind: the Gaussian conditional of its blocks given the
// blocks it was connected to (its separator), linearized where the step left the window:
// x_r = x_r_lin + G (x_s - x_s_lin), covariance Hrr^-1 (H the information of the factors that
// touched the step). Kept for the backward smoothing pass.
struct StepConditional {
  int step = 0;
  std::vector<double*> removed, separator;
  std::vector<int> removed_sizes, separator_sizes;
  Eigen::VectorXd removed_lin, separator_lin;
  Eigen::MatrixXd G;       // removed_dim x separator_dim
  // The conditional's square-root information, S^T S = H_rr (only when covariances are wanted;
  // rank-revealing like the marginal prior).
  Eigen::MatrixXd S;
};

// The fixed-lag smoother both front ends drive: steps join at updates, the window is re-solved,
// steps older than the window are marginalized.
struct FixedLagSmoother {
  const push::Trajectory& traj;
  EstimatorConfig cfg;
  internal::GraphBuilder builder;
  std::unique_ptr<ceres::Problem> problem;
  double window_duration = INFINITY;
  int next_step = 0;  // first step not yet added
  int lo = 0;         // oldest step in the window
  std::vector<StateEstimate> states;
  std::vector<bool> done;
  SolverStats stats;
  double total_update_time = 0.0;
  double last_cost = 0.0;
  bool window_converged = true;  // the last window solve met a tolerance (not its iteration cap)
  bool window_stalled = false;     // or stalled (window_termination says where)
  std::string window_termination;
  // In the order the steps were marginalized; a deque: appending never moves the older ones (a
  // vector's doubling at 32768 steps moved them all in one update: 4.3 ms).
  std::deque<StepConditional> conditionals;

  // online == nullptr: every step of the recorded `t` exists from the start.
  FixedLagSmoother(const push::Trajectory& t, Model model, const EstimatorConfig& c,
                   const OnlineStreams* online)
      : traj(t), cfg(c),
        builder(online != nullptr ? internal::GraphBuilder(t, model, c, *online) : internal::GraphBuilder(t, model, c)) {
    if (cfg.estimate_c || cfg.estimate_mu) {
      throw GraphError("estimate_c and estimate_mu are batch only: the incremental mode keeps c and mu fixed");
    }
    builder.set_incremental(true);
    ceres::Problem::Options po;
    po.enable_fast_removal = true;
    problem = std::make_unique<ceres::Problem>(po);
    states.resize(builder.steps().size());
    done.assign(builder.steps().size(), false);
    stats.name = cfg.solver == EstimatorConfig::Solver::kCeres ? "ceres" : "chain";
  }

  // chain: the solver that just solved the problem as it stands (its factor gives the covariances).
  void Record(const std::vector<int>& idx, ChainSolver* chain = nullptr) {
    std::vector<StateEstimate> out;
    for (int i : idx) out.push_back(builder.State(i));
    if (cfg.covariance && !cfg.incremental_smoothing && !idx.empty()) {
      const std::string status = internal::ComputeCovariances(*problem, builder, idx, out, cfg.covariance_method, nullptr, nullptr, chain);
      if (status != "ok") stats.covariance_status = status;
      else if (stats.covariance_status == "not computed") stats.covariance_status = "ok";
    }
    for (std::size_t k = 0; k < idx.size(); ++k) {
      states[idx[k]] = out[k];
      done[idx[k]] = true;
    }
  }

  // Marginalizes `steps` (consecutive, oldest first). Each step's residual blocks are found in
  // one pass over the problem for all of them, in the problem's own order: with
  // enable_fast_removal, GetResidualBlocksForParameterBlock walks a hash set of pointers, whose
  // order (and so the sums, and so the result) depends on heap addresses (two runs of one input
  // gave different incremental estimates); a pass over the whole problem per step was 40 % of
  // the marginalization (33 of 84 us a step in a 250-step window).
  void MarginalizeSteps(const std::vector<int>& steps) {
    if (steps.empty()) return;
    std::unordered_map<const double*, int> leaving;  // parameter block -> index into `steps`
    for (std::size_t k = 0; k < steps.size(); ++k)
      for (double* b : builder.Blocks(steps[k])) leaving[b] = static_cast<int>(k);
    // A block is eliminated with the oldest leaving step it touches.
    std::vector<std::vector<ceres::ResidualBlockId>> blocks(steps.size());
    std::vector<double*> ps;
    auto assign = [&](ceres::ResidualBlockId id) {
      problem->GetParameterBlocksForResidualBlock(id, &ps);
      int first = -1;
      for (double* p : ps) {
        const auto it = leaving.find(p);
        if (it != leaving.end() && (first < 0 || it->second < first)) first = it->second;
      }
      if (first >= 0) blocks[static_cast<std::size_t>(first)].push_back(id);
    };
    std::vector<ceres::ResidualBlockId> all;
    problem->GetResidualBlocks(&all);
    for (ceres::ResidualBlockId id : all) assign(id);
    for (std::size_t k = 0; k < steps.size(); ++k) {
      // The step's marginal prior joins the blocks of the next leaving step it touches.
      const ceres::ResidualBlockId prior = Marginalize(steps[k], blocks[k]);
      if (prior != nullptr) assign(prior);
    }
  }

  // Schur-complements the factors touching step s (`rbs`, in a deterministic order) onto the
  // blocks they share with other steps; returns the marginal prior added (nullptr: none).
  ceres::ResidualBlockId Marginalize(int s, const std::vector<ceres::ResidualBlockId>& rbs) {
    std::vector<double*> removed = builder.Blocks(s);
    // `order` (the removed step's blocks, then the separator's) and their offsets: a few blocks,
    // found by a linear search (a std::map's nodes were a tenth of the marginalization's time).
    std::vector<double*> order(removed);
    std::vector<int> order_sizes, order_offsets;
    int dim = 0;
    for (double* b : removed) {
      order_offsets.push_back(dim);
      order_sizes.push_back(problem->ParameterBlockSize(b));
      dim += order_sizes.back();
    }
    auto offset_of = [&](const double* p) {
      const auto it = std::find(order.begin(), order.end(), p);
      return it == order.end() ? -1 : order_offsets[static_cast<std::size_t>(it - order.begin())];
    };
    const int removed_dim = dim;
    std::vector<std::vector<double*>>& rb_params = scratch_params_;
    if (rb_params.size() < rbs.size()) rb_params.resize(rbs.size());
    for (std::size_t k = 0; k < rbs.size(); ++k) {
      std::vector<double*>& ps = rb_params[k];
      problem->GetParameterBlocksForResidualBlock(rbs[k], &ps);
      for (double* p : ps) {
        if (offset_of(p) < 0) {
          order.push_back(p);
          order_offsets.push_back(dim);
          order_sizes.push_back(problem->ParameterBlockSize(p));
          dim += order_sizes.back();
        }
      }
    }
    // The factors' whitened Jacobians stacked, [A | r] (rows of every factor; the robust loss as
    // the solver weighs it, sqrt(rho')), the removed step's columns first; filled in place.
    int rows = 0;
    for (ceres::ResidualBlockId id : rbs) rows += problem->GetCostFunctionForResidualBlock(id)->num_residuals();
    Eigen::MatrixXd& A = scratch_A_;
    A.setZero(rows, dim + 1);
    {
      int row = 0;
      std::size_t k = 0;
      Eigen::VectorXd& r = scratch_r_;
      std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& J = scratch_J_;
      std::vector<double*>& jp = scratch_jp_;
      for (ceres::ResidualBlockId id : rbs) {
        const std::vector<double*>& ps = rb_params[k++];
        const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(id);
        const ceres::LossFunction* loss = problem->GetLossFunctionForResidualBlock(id);
        const int m = cost->num_residuals();
        r.resize(m);
        J.resize(ps.size());
        jp.resize(ps.size());
        for (std::size_t q = 0; q < ps.size(); ++q) {
          J[q].resize(m, problem->ParameterBlockSize(ps[q]));
          jp[q] = J[q].data();
        }
        // A factor that does not evaluate here (its own domain: a contact "not facing", c or f_max
        // out of range) or evaluates to non-finite values keeps zero rows: it adds no information
        // to the marginal prior, the documented fallback (docs/estimation.md), rather than ending
        // the run or putting NaN into the prior.
        const bool usable = cost->Evaluate(ps.data(), r.data(), jp.data()) && r.allFinite() &&
                            std::all_of(J.begin(), J.end(), [](const auto& Jq) { return Jq.allFinite(); });
        if (!usable) {
          row += m;
          continue;
        }
        double scale = 1.0;
        if (loss != nullptr) {
          double rho[3];
          loss->Evaluate(r.squaredNorm(), rho);
          scale = std::sqrt(std::max(rho[1], 0.0));
        }
        for (std::size_t q = 0; q < ps.size(); ++q) A.block(row, offset_of(ps[q]), m, J[q].cols()) += scale * J[q];
        A.col(dim).segment(row, m) = scale * r;
        row += m;
      }
    }
    // Remove the step: its residual blocks in the order above first (RemoveParameterBlock would
    // remove them in hash-set order, and fast removal moves the problem's last block into each
    // freed place, so the problem's order, and Ceres' sums, would depend on heap addresses).
    for (ceres::ResidualBlockId id : rbs) {
      builder.ForgetResidualBlock(id);
      problem->RemoveResidualBlock(id);
    }
    for (double* p : removed) problem->RemoveParameterBlock(p);
    const int sep_dim = dim - removed_dim;
    // Elimination in square-root form (the Jacobian's QR, as GTSAM eliminates Jacobian factors;
    // M. Kaess et al., "iSAM: Incremental Smoothing and Mapping", T-RO 2008): the marginal prior's
    // information T2^T T2 is positive semidefinite by construction. The Schur complement of
    // J^T J it replaces (H_ss - H_sr H_rr^+ H_rs) squared the removed block's condition number:
    // on docs/results.md's recordings 20 of 25000 priors came out indefinite beyond 1e-6 of their
    // largest eigenvalue, the worst -0.75 against 12.7 (the negative part dropped, the rest
    // rounding). Columns scaled to unit norm (D = the column norms, sqrt(diag J^T J)) so that the
    // rank decisions do not depend on units: relative to the largest entry of the unscaled
    // factor, a direction held only by a weak prior (a force at its 100 N prior against a contact
    // point at 0.5 mm) fell below the cutoff and a flat pusher's smoothed covariances failed.
    Eigen::VectorXd d(dim);
    for (int j = 0; j < dim; ++j) {
      d[j] = A.col(j).norm();
      if (!(d[j] > 0.0)) d[j] = 1.0;
      A.col(j) /= d[j];
    }
    // The removed step's columns: Q^T A_r P = [R11 R12; 0 0], rank k where |R_ii| falls below
    // 1e-6 of the largest (the square root of the eigenvalue cutoff 1e-12 used before).
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd>& removed_qr = scratch_removed_qr_;
    removed_qr.compute(A.leftCols(removed_dim));
    removed_qr.setThreshold(kRemovedRankCutoff);
    const int rank = static_cast<int>(removed_qr.rank());
    Eigen::MatrixXd& rest = scratch_rest_;
    rest = A.rightCols(sep_dim + 1);  // [A_s | r], rotated by Q^T below
    rest.applyOnTheLeft(removed_qr.householderQ().transpose());
    const Eigen::MatrixXd R = removed_qr.matrixR().topRows(rank).triangularView<Eigen::Upper>();  // rank x removed_dim
    const std::vector<double*> sep(order.begin() + removed.size(), order.end());
    const std::vector<int> sep_sizes(order_sizes.begin() + removed.size(), order_sizes.end());
    const Eigen::VectorXd x_bar = Values(sep, sep_sizes);  // the separator's linearization point
    if (cfg.incremental_smoothing) {
      StepConditional c;
      c.step = s;
      c.removed = removed;
      c.separator = sep;
      c.removed_sizes.assign(order_sizes.begin(), order_sizes.begin() + removed.size());
      c.separator_sizes = sep_sizes;
      c.removed_lin = Values(c.removed, c.removed_sizes);
      c.separator_lin = x_bar;
      // R11 (P^T D_r dx_r)_1 + T1 D_s dx_s = 0 on the first `rank` rows; the directions beyond
      // the rank (no factor holds them) do not move: G = -D_r^-1 P [R11^-1 T1; 0] D_s.
      Eigen::MatrixXd G_scaled = Eigen::MatrixXd::Zero(removed_dim, sep_dim);
      if (rank > 0 && sep_dim > 0) {
        G_scaled.topRows(rank) =
            -R.leftCols(rank).triangularView<Eigen::Upper>().solve(rest.topLeftCorner(rank, sep_dim));
      }
      // The permutation applied by indices: Eigen's permutation products read through a null
      // pointer on an empty operand (UBSan; a step with no separator, or of rank 0).
      const Eigen::VectorXi& perm = removed_qr.colsPermutation().indices();
      c.G = Eigen::MatrixXd::Zero(removed_dim, sep_dim);
      for (int i = 0; i < removed_dim; ++i) {
        for (int j = 0; j < sep_dim; ++j) {
          c.G(perm[i], j) = (1.0 / d[perm[i]]) * G_scaled(i, j) * d[removed_dim + j];  // D_r^-1 P G_scaled D_s
        }
      }
      // S^T S = H_rr: S = [R11 R12] P^T D_r.
      if (cfg.covariance) {
        c.S = Eigen::MatrixXd::Zero(rank, removed_dim);
        for (int i = 0; i < rank; ++i) {
          for (int j = 0; j < removed_dim; ++j) c.S(i, perm[j]) = R(i, j) * d[perm[j]];
        }
      }
      conditionals.push_back(std::move(c));
    }
    if (sep_dim == 0 || rows <= rank) return nullptr;
    // The rows below the rank hold the separator alone: T2 dx_s + c2. Compressed to at most
    // sep_dim rows by a second QR, rank-revealing at 1e-5 (the eigenvalue cutoff 1e-10 before).
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd>& separator_qr = scratch_separator_qr_;
    separator_qr.compute(rest.bottomLeftCorner(rows - rank, sep_dim));
    separator_qr.setThreshold(kSeparatorRankCutoff);
    const int kept = static_cast<int>(separator_qr.rank());
    if (kept == 0) return nullptr;
    const Eigen::VectorXd c2 = separator_qr.householderQ().transpose() * rest.bottomRightCorner(rows - rank, 1);
    // The prior 1/2 |S (x - x_bar) + r0|^2: S = R2 P2^T D_s, r0 = (Q2^T c2) on the kept rows.
    const Eigen::MatrixXd R2 = separator_qr.matrixR().topRows(kept).triangularView<Eigen::Upper>();
    const Eigen::VectorXi& perm2 = separator_qr.colsPermutation().indices();
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(kept, sep_dim);
    for (int i = 0; i < kept; ++i) {
      for (int j = 0; j < sep_dim; ++j) S(i, perm2[j]) = R2(i, j) * d[removed_dim + perm2[j]];
    }
    Eigen::VectorXd r0 = c2.head(kept);
    return problem->AddResidualBlock(new MarginalPriorFactor(sep_sizes, x_bar, std::move(S), std::move(r0)), nullptr, sep);
  }
  static constexpr double kRemovedRankCutoff = 1e-6, kSeparatorRankCutoff = 1e-5;
  // Marginalize's buffers, kept between steps (their allocations were a fifth of its time).
  std::vector<std::vector<double*>> scratch_params_;
  Eigen::MatrixXd scratch_A_, scratch_rest_;
  Eigen::VectorXd scratch_r_;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> scratch_J_;
  std::vector<double*> scratch_jp_;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> scratch_removed_qr_, scratch_separator_qr_;

  // The window's length in steps (0: in time, window_duration).
  int WindowSteps() const {
    if (cfg.incremental_window_steps > 0) return cfg.incremental_window_steps;
    // At least ten updates' worth: a window of three 5-step updates left two of three notched-block
    // pushes 27 % and 58 % above batch (tests/python); with ten, all three were at or below it.
    return cfg.incremental_update_every_steps > 0
               ? std::max(kDefaultWindowStepsAtSensorRate, 10 * cfg.incremental_update_every_steps)
               : 0;
  }
  static constexpr int kDefaultWindowStepsAtSensorRate = 15;

  // Iterations of an update's window solve after the first (which starts cold and converges):
  // incremental_window_iterations, a hard cap, when set; else incremental_max_iterations.
  int WindowIterations() const {
    return cfg.incremental_window_iterations > 0 ? cfg.incremental_window_iterations : cfg.incremental_max_iterations;
  }
  // The soft iteration limit of those solves (0: none; ChainSolverOptions::soft_iteration_limit).
  // Unset incremental_window_iterations: 3 where a step spends ten or more updates in the window
  // (the sensor rate with its default window), each of which refines it, and Finish re-solves the
  // last window (the worst update 2.3-3.0 -> 0.7-1.1 ms on three simulated pushes). Soft, not a
  // hard cap: a cap of 3 left the first windows of slow real pushes (ellip1 at 20 mm/s) far
  // from their minimum, the marginal priors kept that, and the estimates diverged (8 to 16 mm at
  // 100 Hz on docs/results.md's set, 22.5 mm at 250 Hz on one recording, against about 1 mm
  // without a limit). Every k object samples (incremental_update_every_steps unset) a step sees
  // one or two updates and leaves with the linearization point it had, so the same limit stops
  // at a tighter tolerance there (WindowSoftTolerance; a hard cap of 3: ellip1's QS incremental
  // object RMS 1.25 -> 1.81 mm on docs/results.md's set).
  int WindowSoftLimit() const {
    const int every = cfg.incremental_update_every_steps;
    if (cfg.incremental_window_iterations > 0) return 0;
    if (every <= 0) return kDefaultWindowSoftLimit;
    return WindowSteps() >= 10 * every ? kDefaultWindowSoftLimit : 0;
  }
  static constexpr int kDefaultWindowSoftLimit = 3;
  // The soft limit's tolerance (0: ChainSolverOptions::soft_function_tolerance, 3e-4, at the
  // sensor rate). Every k object samples 3e-5: the window solves' iterations 4 to 7 change the
  // cost by 1e-4 to 1e-6 of it; at 3e-5 an update every 5 object samples took 11.8 % fewer
  // instructions (callgrind, BM_IncrementalQs/500/0/0: 0.860e9 -> 0.758e9), with docs/results.md's
  // incremental rows within -2.0..+0.9 % (object RMS) and their NEES within -22..+12 % (the
  // baseline's force 4.56 -> 3.57 on the notched block, 8.19 -> 9.20 on its two-finger pushes;
  // the models' own within -9..+4 %); at 3e-4 the notched block's SDF object NEES rose 3.13 ->
  // 3.87 and ellip1's QS force NEES 1.83 -> 2.21.
  double WindowSoftTolerance() const { return cfg.incremental_update_every_steps <= 0 ? kWindowSoftToleranceEveryK : 0.0; }
  static constexpr double kWindowSoftToleranceEveryK = 3e-5;
  // Iterations of the new QS steps' kinematic stage after the first update. Its iterations 3 to 5
  // (5 in all every 5 object samples) each changed the cost by less than 1e-3 of it, and the window
  // solve then moves those steps anyway: capping at 2 cut an update's instructions every 5
  // object samples by 7.7 % (callgrind, BM_IncrementalQs/500/0/0: 0.932e9 -> 0.860e9), with docs/results.md's
  // QS incremental rows within -0.7..+1.7 % (object RMS) and NEES within -10.1..+8.3 % (ellip1's
  // force 2.04 -> 1.83). Not for the baseline: its two-finger rows (sim-multi) went 2.84 -> 2.96 mm
  // and its force NEES 8.2 -> 17.8. CP and SDF have no such stage.
  static constexpr int kNewStepKinematicIterations = 2;
  static constexpr double kWindowEdgeTolerance = 1e-6;  // s

  // Adds the steps up to `target` (every remaining one when take_all) and solves the window.
  double Update(double target, bool take_all) {
    const auto start = std::chrono::steady_clock::now();
    const int n = static_cast<int>(builder.steps().size());
    states.resize(n);
    done.resize(n, false);
    const int first_new = next_step;
    while (next_step < n && (builder.steps()[next_step].t <= target + 1e-12 || take_all)) {
      builder.Initialize(next_step, target);
      ++next_step;
    }
    if (next_step == first_new) return 0.0;
    const auto stage_start = std::chrono::steady_clock::now();
    // The new steps staged as in the batch solver (the window's older steps held fixed); after
    // the first update a QS step's kinematic stage is only the window solve's start
    // (kNewStepKinematicIterations; the baseline keeps its full stage).
    stats.iterations += builder.StageSteps(*problem, first_new, next_step, cfg.incremental_max_iterations,
                                           cfg.function_tolerance, "incremental update, new steps",
                                           first_new == 0 || builder.model() != Model::kQs ? 0 : kNewStepKinematicIterations);
    const auto solve_start = std::chrono::steady_clock::now();
    // A bounded relinearization per update (as iSAM2's one Gauss-Newton step), WindowIterations.
    const int window_iterations = first_new == 0 ? cfg.incremental_max_iterations : WindowIterations();
    const internal::SolveOutcome summary = builder.Solve(*problem, window_iterations, cfg.function_tolerance,
                                                         "incremental update, window", first_new == 0 ? 0 : WindowSoftLimit(),
                                                         WindowSoftTolerance());
    stats.iterations += summary.iterations;
    last_cost = summary.final_cost;
    window_converged = summary.converged;
    window_stalled = summary.stalled;
    window_termination = summary.termination;
    // States leaving the window (keep at least three steps for the V factors).
    std::vector<int> leaving;
    const double t_now = builder.steps()[next_step - 1].t;
    int s = lo;
    const int window_steps = WindowSteps();
    if (window_steps > 0) {
      while (s < next_step - window_steps) leaving.push_back(s++);
    } else {
      // The window's edge falls on a step (a whole number of object periods back from an update);
      // within 1 us of it the step stays, so that the online front end, whose period estimate
      // differs from the replay's in its last bits, keeps the same steps.
      while (s < next_step - 3 && builder.steps()[s].t < t_now - window_duration - kWindowEdgeTolerance) leaving.push_back(s++);
    }
    const auto record_start = std::chrono::steady_clock::now();
    Record(leaving, summary.chain.get());
    const auto marginalize_start = std::chrono::steady_clock::now();
    MarginalizeSteps(leaving);
    if (internal::SolverLogLevel() >= 1) {
      const auto now = std::chrono::steady_clock::now();
      auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
      std::cerr << "pushgraph incremental update: new steps initialized " << seconds(start, stage_start)
                << " s, staged " << seconds(stage_start, solve_start) << " s, window solved "
                << seconds(solve_start, record_start) << " s, record " << leaving.size() << " steps "
                << std::chrono::duration<double>(marginalize_start - record_start).count() << " s, marginalize "
                << std::chrono::duration<double>(now - marginalize_start).count() << " s, whole update "
                << std::chrono::duration<double>(now - start).count() << " s\n";
    }
    lo = s;
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++stats.updates;
    stats.update_times_s.push_back(dt);
    total_update_time += dt;
    stats.max_update_time_s = std::max(stats.max_update_time_s, dt);
    return dt;
  }

  // The remaining window's covariances and the whole result.
  EstimationResult Finish() {
    const auto start = std::chrono::steady_clock::now();
    std::vector<int> rest;
    for (int i = lo; i < next_step; ++i) rest.push_back(i);
    std::unique_ptr<ChainSolver> chain;
    if (!window_converged && !rest.empty()) {
      // The last update's window solve stopped at its cap: no later update refines it.
      internal::SolveOutcome summary =
          builder.Solve(*problem, cfg.incremental_max_iterations, cfg.function_tolerance, "incremental finish, window");
      stats.iterations += summary.iterations;
      last_cost = summary.final_cost;
      window_converged = summary.converged;
      window_stalled = summary.stalled;
      window_termination = summary.termination;
      chain = std::move(summary.chain);
    }
    Record(rest, chain.get());
    if (cfg.incremental_smoothing) {
      // The window eliminated in time order too, then one backward pass over every conditional.
      MarginalizeSteps(rest);
      lo = next_step;
      SmoothBackwards();
    }
    total_update_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EstimationResult r;
    r.object_delay = cfg.object_delay;  // 0 from Estimate, which applied it and says so itself
    r.model = builder.model();
    r.mode = Mode::kIncremental;
    r.states.assign(states.begin(), states.begin() + next_step);
    r.solver = stats;
    r.solver.time_s = total_update_time;
    r.solver.final_cost = last_cost;
    // The updates' own mean (time_s also holds Finish's smoothing pass, which is no update).
    double update_sum = 0.0;
    for (double u : stats.update_times_s) update_sum += u;
    r.solver.mean_update_time_s = stats.updates > 0 ? update_sum / stats.updates : 0.0;
    builder.DropUnobservableForces(r);
    // The model's shared parameters, as batch reports them (never estimated incrementally).
    if (ModelHasForce(r.model)) r.c = builder.c();
    if (r.model == Model::kQs && builder.uses_load_factor()) r.mu = builder.mu();
    r.metrics = ComputeMetrics(traj, r.states);
    if (window_stalled) {
      r.warnings.push_back("incremental: the last window's solve " + window_termination +
                           "; the newest states may be left near their starting values");
    } else if (!window_converged) {
      r.warnings.push_back("incremental: the last window's solve stopped at incremental_max_iterations (" +
                           std::to_string(cfg.incremental_max_iterations) +
                           ") without meeting its tolerance; the newest states may not be converged");
    }
    return r;
  }

  // The backward (Rauch-Tung-Striebel) pass over the conditionals, newest first: each step's
  // blocks move with the final estimate of their separator, x_r = x_r_lin + G (x_s - x_s_lin).
  // Covariances: the conditionals multiply to the whole chain's linearized Gaussian, whose
  // information is sum_k A_k^T S_k^T S_k A_k with A_k = [I, -G_k] on (step k, its separator): a
  // block-banded matrix whose marginals come from one sparse Cholesky factor and a selected
  // inversion (SparseMarginals, AMD order). The covariance form of the recursion,
  // Sigma_rr = H_rr^-1 + G Sigma_ss G^T, is the same algebra in time order, and it is unstable
  // here: with a stiff constant-velocity prior G extrapolates backwards (|G| up to 20 on an MIT
  // recording) and rounding in the frontier's nearly singular covariance of two consecutive
  // poses grew to -1e164 within 450 steps.
  void SmoothBackwards() {
    for (int k = static_cast<int>(conditionals.size()) - 1; k >= 0; --k) {
      const StepConditional& c = conditionals[k];
      const Eigen::VectorXd x_r = c.removed_lin + c.G * (Values(c.separator, c.separator_sizes) - c.separator_lin);
      int off = 0;
      for (std::size_t q = 0; q < c.removed.size(); ++q) {
        for (int j = 0; j < c.removed_sizes[q]; ++j) c.removed[q][j] = x_r[off + j];
        off += c.removed_sizes[q];
      }
      states[c.step] = builder.State(c.step);  // covariances: SmoothedCovariances
    }
    if (cfg.covariance) SmoothedCovariances();
    conditionals.clear();
  }

  void SmoothedCovariances() {
    ceres::Problem chain;  // linear factors, one per conditional
    std::unordered_set<double*> eliminated;
    for (const StepConditional& c : conditionals) eliminated.insert(c.removed.begin(), c.removed.end());
    for (const StepConditional& c : conditionals) {
      if (c.S.rows() == 0) continue;
      std::vector<double*> blocks(c.removed);
      blocks.insert(blocks.end(), c.separator.begin(), c.separator.end());
      std::vector<int> sizes(c.removed_sizes);
      sizes.insert(sizes.end(), c.separator_sizes.begin(), c.separator_sizes.end());
      const int nr = static_cast<int>(c.removed_lin.size()), ns = static_cast<int>(c.separator_lin.size());
      Eigen::MatrixXd A(c.S.rows(), nr + ns);
      A.leftCols(nr) = c.S;
      A.rightCols(ns) = -c.S * c.G;
      Eigen::VectorXd x_lin(nr + ns);
      x_lin << c.removed_lin, c.separator_lin;
      chain.AddResidualBlock(new MarginalPriorFactor(sizes, x_lin, A, Eigen::VectorXd::Zero(c.S.rows())), nullptr, blocks);
    }
    // Blocks no step owns (constant in the window's problem) stay constant.
    std::vector<double*> all;
    chain.GetParameterBlocks(&all);
    for (double* b : all) if (!eliminated.count(b)) chain.SetParameterBlockConstant(b);
    // Selected inversion, or ceres::Covariance's QR on J when J^T J is too ill-conditioned for it
    // (both as in batch).
    std::vector<int> idx;
    std::vector<StateEstimate> out;
    for (const StepConditional& c : conditionals) {
      idx.push_back(c.step);
      out.push_back(states[c.step]);
    }
    const std::string status = internal::ComputeCovariances(chain, builder, idx, out, cfg.covariance_method, nullptr, nullptr, nullptr);
    stats.covariance_status = status == "ok" ? status : "smoothed covariances " + status;
    if (status != "ok") return;
    for (std::size_t k = 0; k < idx.size(); ++k) states[idx[k]] = out[k];
  }

  StateEstimate LatestState(const char* who) const {
    if (next_step == 0) throw GraphError(std::string(who) + "::LatestState: no step estimated yet (no Update has added a step)");
    StateEstimate s = builder.State(next_step - 1);
    if (!builder.ForceScaleObservable()) s.force.reset();  // as Finish() reports it
    return s;
  }
};

}  // namespace

// Replay: the update times come from the recorded object stream.
struct IncrementalEstimator::Impl {
  // The trajectory as Estimate reads it, its tessellated fingers as disks and a contact stream
  // off its finger left out (nullopt: neither applies), and what was said of each.
  std::string finger_disks, contact_note;
  std::optional<push::Trajectory> prepared;
  FixedLagSmoother smoother;
  std::vector<double> triggers;
  std::size_t next_trigger = 0;

  static std::optional<push::Trajectory> Prepare(const push::Trajectory& given, const EstimatorConfig& cfg,
                                                 std::string* disks_note, std::string* contacts_note) {
    // A tracker's latency (object_delay): the object's stamps moved back first, as Estimate does.
    std::optional<push::Trajectory> delayed;
    if (cfg.object_delay != 0.0) delayed = internal::WithObjectDelay(given, cfg.object_delay);
    const push::Trajectory& traj = delayed ? *delayed : given;
    std::optional<push::Trajectory> disks = internal::TessellatedFingersAsDisks(traj, cfg, disks_note);
    std::optional<push::Trajectory> without_contacts =
        internal::DropContactStreamsOffTheFinger(disks ? *disks : traj, cfg.measurement, contacts_note);
    std::string faults_note;
    std::optional<push::Trajectory> without_faults = internal::DropContactRowFaults(
        without_contacts ? *without_contacts : disks ? *disks : traj, cfg.measurement, &faults_note);
    if (without_faults) {
      *contacts_note += (contacts_note->empty() ? "" : "; ") + faults_note;
      return without_faults;
    }
    return without_contacts ? std::move(without_contacts) : disks ? std::move(disks) : std::move(delayed);
  }

  Impl(const push::Trajectory& traj, Model model, const EstimatorConfig& cfg)
      : prepared(Prepare(traj, cfg, &finger_disks, &contact_note)),
        smoother(prepared ? *prepared : traj, model, cfg, nullptr) {
    const auto& obj = (prepared ? *prepared : traj).measured.object_pose;
    const auto& steps = smoother.builder.steps();
    double period = MedianObjectPeriod(obj);
    if (!(period > 0.0)) {
      period = steps.size() > 1 ? 10.0 * (steps.back().t - steps.front().t) / double(steps.size() - 1) : 1.0;
    }
    const int k = cfg.incremental_update_every;
    smoother.window_duration = cfg.IncrementalWindowPeriods() * period;
    if (cfg.incremental_update_every_steps >= 1) {
      // An update every k estimator steps (1: at the sensor rate).
      // The first update takes at least three steps: one step alone has no motion prior, and
      // its stiff contact factors can turn the object about the finger (measured: a square
      // push then spun at 190 rad/s, 82 mm RMS, with either solver).
      const std::size_t every = static_cast<std::size_t>(cfg.incremental_update_every_steps);
      for (std::size_t j = std::max<std::size_t>(every - 1, 2); j < steps.size(); j += every) triggers.push_back(steps[j].t);
      if (triggers.empty() || triggers.back() < steps.back().t) triggers.push_back(steps.back().t);
      return;
    }
    const double max_spacing = 1.5 * k * period;
    for (std::size_t j = k - 1; j < obj.size(); j += k) {
      // While the object stream is occluded, update on time anyway.
      while (!triggers.empty() && obj[j].t - triggers.back() > max_spacing) triggers.push_back(triggers.back() + k * period);
      triggers.push_back(obj[j].t);
    }
    const double t_end = steps.back().t;
    if (triggers.empty()) triggers.push_back(steps.front().t);
    while (t_end - triggers.back() > max_spacing) triggers.push_back(triggers.back() + k * period);
    if (triggers.back() < t_end) triggers.push_back(t_end);
  }
};

IncrementalEstimator::IncrementalEstimator(const push::Trajectory& trajectory, Model model,
                                           const EstimatorConfig& config)
    : impl_(std::make_unique<Impl>(trajectory, model, config)) {}
IncrementalEstimator::~IncrementalEstimator() = default;

bool IncrementalEstimator::Done() const { return impl_->next_trigger >= impl_->triggers.size(); }
double IncrementalEstimator::Update() {
  if (Done()) throw GraphError("IncrementalEstimator::Update called after the last update");
  const double target = impl_->triggers[impl_->next_trigger++];
  return impl_->smoother.Update(target, Done());
}
StateEstimate IncrementalEstimator::LatestState() const { return impl_->smoother.LatestState("IncrementalEstimator"); }
int IncrementalEstimator::WindowSteps() const { return impl_->smoother.next_step - impl_->smoother.lo; }
int IncrementalEstimator::StepsAdded() const { return impl_->smoother.next_step; }
int IncrementalEstimator::TotalSteps() const { return static_cast<int>(impl_->smoother.builder.steps().size()); }

EstimationResult IncrementalEstimator::Finish() {
  if (!Done()) throw GraphError("IncrementalEstimator::Finish called before the last update");
  EstimationResult r = impl_->smoother.Finish();
  if (!impl_->contact_note.empty()) r.warnings.insert(r.warnings.begin(), impl_->contact_note);
  if (!impl_->finger_disks.empty()) r.warnings.insert(r.warnings.begin(), impl_->finger_disks);
  return r;
}

// Online: the samples are appended to an owned trajectory as they arrive.
struct OnlineEstimator::Impl {
  std::string finger_disks;  // the setup's tessellated fingers read as disks (empty: none); before traj
  push::Trajectory traj;  // grows; the smoother's builder reads it
  Model model;
  OnlineStreams streams;
  // Replaced when the shape check applies the shape's units (the steps so far solved again).
  std::unique_ptr<FixedLagSmoother> smoother;
  double last_update_t = -INFINITY;
  double newest_t = -INFINITY;
  double first_t = INFINITY;
  // Streams: 0 object pose; finger 0's pose, contact point, force (1-3); finger k's at
  // 3 k + 1 .. 3 k + 3.
  std::vector<double> last_seen;  // dropped samples included
  std::vector<bool> repeated_contact;  // per finger: its newest contact sample is the second at its time
  std::vector<std::size_t> seen;
  int dropped_late = 0;
  // Force sensor faults (the batch rule, Estimate's DropForceSpikes): a force above 50 times the
  // larger of the recent forces' 95th percentile and mu m g (and above 1 N) is left out.
  std::deque<double> recent_force;  // |f| of the newest accepted samples (at most kRecentForces)
  static constexpr std::size_t kRecentForces = 512;
  double recent_p95 = 0.0;  // of recent_force, refreshed every 32 samples (a selection of 512: ~2 us)
  std::size_t since_p95 = 0;
  int dropped_faults = 0;
  // Per kind of sample left out as a fault ("force sample", "object_pose sample", "contact_point
  // row"): how many, why, and the first (Finish() names each kind).
  struct Faults {
    int count = 0;
    std::string why, first;
  };
  std::map<std::string, Faults> faults;
  void Fault(const std::string& kind, const std::string& why, const std::string& first) {
    ++dropped_faults;
    Faults& f = faults[kind];
    if (f.count++ == 0) f.why = why, f.first = first;
  }
  // Object tracker glitches (the batch rule's end-of-stream form, DropObjectPoseGlitches): a pose
  // farther from the median of the five accepted before it than max(1 cm, 10 sigmas) (0.3 rad) plus twice their
  // motion plus their speed times the time since, when those five lie within 0.5 s of it. One
  // pose 5 m off pulled the online estimate 10 cm past where the object ever went, with no word.
  // Three left out in a row that agree with one another are a step of the tracker (a
  // re-initialization), not glitches: the third and those after it are taken.
  std::vector<push::PoseSample> pending_glitches;
  // A pose stream's speed over its newest 0.1 s or more (its newest pose against the last one at
  // least 0.1 s older, or its oldest); 0 with fewer than two poses.
  static double RecentSpeed(const std::vector<push::PoseSample>& poses) {
    if (poses.size() < 2) return 0.0;
    const push::PoseSample& newest = poses.back();
    std::size_t k = poses.size() - 2;
    while (k > 0 && newest.t - poses[k].t < 0.1) --k;
    const double dt = newest.t - poses[k].t;
    return dt > 0.0 ? (newest.pose.translation() - poses[k].pose.translation()).norm() / dt : 0.0;
  }
  static constexpr double kGlitchFloor = 0.01, kGlitchAngle = 0.3, kGlitchWindow = 0.5;  // m, rad, s
  static constexpr std::size_t kStepSamples = 3;
  bool ObjectPoseGlitch(double t, const geometry::Pose2& pose, double* off) {
    const auto& s = traj.measured.object_pose;
    if (s.size() < 5 || t - s[s.size() - 5].t > kGlitchWindow) return false;
    std::vector<double> xs, ys, as;
    for (std::size_t k = s.size() - 5; k < s.size(); ++k) {
      xs.push_back(s[k].pose.x), ys.push_back(s[k].pose.y);
      as.push_back(std::remainder(s[k].pose.theta - pose.theta, 2.0 * M_PI));
    }
    const push::PoseSample &near = s.back(), &far = s[s.size() - 5];
    const double motion = (near.pose.translation() - far.pose.translation()).norm();
    const double turn = std::abs(std::remainder(near.pose.theta - far.pose.theta, 2.0 * M_PI));
    const double span = std::max(near.t - far.t, 1e-9), ahead = t - near.t;
    // Ten of the tracker's sigmas at least (the batch's ten scatters): with the paper's 5 mm
    // noise a 1 cm floor is two sigmas.
    const push::MeasurementSigmas& sigma = smoother->cfg.measurement;
    const double floor = std::max(kGlitchFloor, 10.0 * sigma.object_trans), floor_angle = std::max(kGlitchAngle, 10.0 * sigma.object_rot);
    // A pushed object can start to move as fast as its finger (the five poses before at rest
    // allowed nothing: a 0.4 m/s push had 0.3 s of poses refused at its onset): twice the
    // fastest finger's recent speed over the time since the oldest of the five.
    double finger_speed = RecentSpeed(traj.measured.finger_pose);
    for (const push::ExtraFinger& f : traj.extra_fingers) finger_speed = std::max(finger_speed, RecentSpeed(f.measured.finger_pose));
    *off = std::hypot(pose.x - internal::Median(xs), pose.y - internal::Median(ys));
    const bool glitch = *off > floor + 2.0 * motion + motion / span * ahead + 2.0 * finger_speed * (t - far.t) ||
                        std::abs(internal::Median(as)) > floor_angle + 2.0 * turn + turn / span * ahead;
    if (!glitch) {
      pending_glitches.clear();
      return false;
    }
    // A step: agrees with the glitches just before it (within the floor plus their own motion).
    if (!pending_glitches.empty()) {
      const push::PoseSample& last = pending_glitches.back();
      const bool agrees = (pose.translation() - last.pose.translation()).norm() <=
                              floor + 2.0 * std::max(motion / span, finger_speed) * (t - last.t) &&
                          std::abs(std::remainder(pose.theta - last.pose.theta, 2.0 * M_PI)) <= floor_angle;
      if (!agrees) pending_glitches.clear();
    }
    pending_glitches.push_back({t, pose});
    if (pending_glitches.size() >= kStepSamples) {
      pending_glitches.clear();
      return false;
    }
    return true;
  }
  bool finished = false;
  // The batch's check that a touching finger is near the object (trajectory_checks.cpp), per
  // finger at its first touch: its first contact point, or the first force sample the estimator's
  // own contact gating takes as a touch (ForceSaysTouching). Without it a pusher 2 m off
  // (another tracker's frame) gave an object 1.87 m off, and no word (helper-27 N0b).
  std::vector<bool> reach_checked;        // per finger
  std::vector<std::size_t> touch_scanned;  // per finger: force samples looked at

  // The batch's check that the contact points lie on their finger (Estimate's
  // DropContactStreamsOffTheFinger), per finger, once kContactCheckSamples of its contacts have a
  // finger pose near them (internal::FingerPoseNear; counted once older than `until` - kNearInTime,
  // when every pose near them has come). With one finger a stream off it (another frame, an offset) is left out from
  // then on and the steps so far solved again without it, before the shape check reads the
  // contacts; with several (one OnlineStreams flag gates them all) it is said. Online it was used
  // as given: a tactile stream 5 cm off moved the object estimate with it, and the shape check
  // blamed the shape.
  static constexpr std::size_t kContactCheckSamples = 10;
  static constexpr double kNearInTime = 0.05;  // s, FingerPoseNear's window
  enum class ContactVerdict { kUndecided, kOnFinger, kOff };
  std::vector<ContactVerdict> contact_verdict;  // per finger
  std::vector<std::size_t> contacts_scanned, contacts_judgeable;  // per finger
  bool contacts_left_out = false;

  // A new smoother on traj as it now is: the next update solves every step so far. The updates
  // so far stay in the result's count and update_times_s.
  void RestartSmoother() {
    auto fresh = std::make_unique<FixedLagSmoother>(traj, model, smoother->cfg, &streams);
    fresh->stats.updates = smoother->stats.updates;
    fresh->stats.update_times_s = smoother->stats.update_times_s;
    fresh->stats.max_update_time_s = smoother->stats.max_update_time_s;
    fresh->total_update_time = smoother->total_update_time;
    smoother = std::move(fresh);
  }

  // `until`: the update's time; `last`: Finish()'s look at what is left undecided (5 contacts
  // suffice, as in batch, and nothing is solved again).
  void CheckContacts(double until, bool last) {
    if (contacts_left_out || !streams.contact_point) return;
    if (contact_verdict.size() != static_cast<std::size_t>(fingers)) {
      contact_verdict.assign(fingers, ContactVerdict::kUndecided);
      contacts_scanned.assign(fingers, 0);
      contacts_judgeable.assign(fingers, 0);
    }
    for (int k = 0; k < fingers; ++k) {
      if (contact_verdict[k] != ContactVerdict::kUndecided) continue;
      const auto& poses = k == 0 ? traj.measured.finger_pose : traj.extra_fingers[k - 1].measured.finger_pose;
      const auto& contacts = k == 0 ? traj.measured.contact_point : traj.extra_fingers[k - 1].measured.contact_point;
      // Count once each contact whose nearby poses have all come.
      std::size_t& scanned = contacts_scanned[k];
      while (scanned < contacts.size() && (last || contacts[scanned].t <= until - kNearInTime)) {
        contacts_judgeable[k] += internal::FingerPoseNear(poses, contacts[scanned].t);
        ++scanned;
      }
      if (contacts_judgeable[k] < (last ? std::size_t{5} : kContactCheckSamples)) continue;
      // Finger k alone, its contacts so far.
      push::Trajectory view;
      view.finger.shape = k == 0 ? traj.finger.shape : traj.extra_fingers[k - 1].finger.shape;
      view.measured.finger_pose = poses;
      view.measured.contact_point.assign(contacts.begin(), contacts.begin() + static_cast<std::ptrdiff_t>(scanned));
      std::string note;
      const bool off = internal::DropContactStreamsOffTheFinger(view, smoother->cfg.measurement, &note).has_value();
      contact_verdict[k] = off ? ContactVerdict::kOff : ContactVerdict::kOnFinger;
      if (!off) continue;
      if (k > 0) {
        const std::string named = "streams.fingers[" + std::to_string(k) + "].contact_point";
        for (std::size_t at = note.find("streams.contact_point"); at != std::string::npos; at = note.find("streams.contact_point", at + named.size()))
          note.replace(at, 21, named);
      }
      const std::string text = internal::Format("contact check (OnlineEstimator, on the samples up to %.3f s into the data, t = %s s): ",
                                                last_update_t - first_t, Precise(last_update_t).c_str()) + note;
      if (last || fingers > 1) {
        warnings.push_back(text + (last ? "; OnlineEstimator used it as given (too few contacts to judge it before the end)"
                                        : "; OnlineEstimator uses it as given (one OnlineStreams flag gates every finger's "
                                          "contacts)") +
                           ": estimate the recording with `pushgraph estimate`, which leaves it out");
        continue;
      }
      traj.measured.contact_point.clear();
      streams.contact_point = false;
      contacts_left_out = true;
      RestartSmoother();
      warnings.push_back(text + "; from this update on, every step so far solved again without it");
      return;
    }
  }

  void CheckTouchingFingersAreNear() {
    const EstimatorConfig& cfg = smoother->cfg;
    for (int k = 0; k < fingers; ++k) {
      if (reach_checked[k]) continue;
      const auto& contacts = k == 0 ? traj.measured.contact_point : traj.extra_fingers[k - 1].measured.contact_point;
      const auto& forces = k == 0 ? traj.measured.force : traj.extra_fingers[k - 1].measured.force;
      double touch = INFINITY;
      if (!contacts.empty()) {
        touch = contacts.front().t;
      } else {
        // Held for 0.1 s (the gating's test at t, t + 0.05 and t + 0.1 s): one window's median
        // crosses the noise bound now and then (a finger 0.58 m away on its approach).
        auto says = [&](double at) {
          return internal::ForceSaysTouching(forces, at, cfg.contact_max_gap, cfg.contact_force_threshold,
                                             cfg.measurement.force);
        };
        for (std::size_t& j = touch_scanned[k]; j < forces.size() && forces.back().t >= forces[j].t + 0.12; ++j) {
          if (says(forces[j].t) && says(forces[j].t + 0.05) && says(forces[j].t + 0.1)) {
            touch = forces[j].t;
            break;
          }
        }
      }
      if (!std::isfinite(touch)) continue;
      reach_checked[k] = true;
      if (const std::optional<std::string> far = internal::FingerFarFromObject(traj, k, touch, contacts.empty() ? nullptr : &contacts.front()))
        throw GraphError("OnlineEstimator::Update: " + *far);
    }
  }
  // The batch's shape check (RegisterShape) on the samples so far: without it a shape in
  // millimetres gave an object 11.6 m off, and a shape turned by 34 degrees 11.7 mm against 1.03,
  // with no word. Run at updates until the contacts can judge the shape (kShapeCheckSamples
  // independent samples), at most every kShapeCheckRetry s of data; then, while it fits, again
  // each time the data has doubled (a 30-degree turn of a square fitted the first 0.16 s of
  // contact), on the newest kShapeCheckSpan s only, so that no check costs more than one of a
  // 1000-step recording. A misfit is said at once, and the checks stop.
  // Finish() checks once more on every sample: the placement a few contacts suggest is loose (a
  // turn of 14 degrees at 0.16 s where 34 was right). A shape that fits the contacts but not the
  // push's mechanics (20 mm off along the pushed side: 1.70 mm against 1.03) is left to Estimate,
  // whose whole-graph comparison finds it; the contacts' own "fits better elsewhere" named the
  // true rect1 shape on a 4 s push.
  static constexpr double kShapeCheckSamples = 3.0;  // the batch's "too little contact" bound
  static constexpr double kShapeCheckRetry = 0.1;    // s (0.5: the second check of a 250 Hz MIT recording came 25 updates late)
  static constexpr double kShapeCheckSpan = 4.0;     // s
  bool shape_judged = false;
  double next_shape_check_t = -INFINITY;
  std::vector<std::string> warnings;
  std::optional<std::size_t> shape_warning;  // its place in warnings

  // The samples from `from` on (the streams that RegisterShape reads).
  push::Trajectory Newest(double from) const {
    push::Trajectory out = traj;
    auto trim = [from](auto& stream) {
      stream.erase(stream.begin(), std::lower_bound(stream.begin(), stream.end(), from,
                                                    [](const auto& sample, double t) { return sample.t < t; }));
    };
    trim(out.measured.object_pose), trim(out.measured.finger_pose), trim(out.measured.contact_point), trim(out.measured.force);
    for (push::ExtraFinger& f : out.extra_fingers)
      trim(f.measured.finger_pose), trim(f.measured.contact_point), trim(f.measured.force);
    return out;
  }

  // The check of the shape at the registration's scale alone, when that scale is a unit's and
  // the shape fits so; nothing otherwise.
  std::optional<ShapeFitCheck> UnitsAloneFit(const RegistrationResult& r, const RegistrationOptions& options) const {
    if (internal::registration::UnitPhrase(r.transform.scale).empty()) return std::nullopt;
    push::Trajectory scaled = traj;
    scaled.object.shape = geometry::TransformShape(traj.object.shape, geometry::Pose2{}, r.transform.scale, false);
    ShapeFitCheck check = CheckShapeFit(scaled, options);
    if (!check.fits) return std::nullopt;
    return check;
  }

  // Finish()'s shape_alignment: the check as given, and the units when they were applied.
  ShapeAlignment alignment;

  // Checks the shape on the samples up to `until` (the next update's) when due; `last`: the
  // final check of Finish(). A shape that fits at a unit's scale alone is read in that unit
  // unless align_shape is "off": the smoother starts again at that scale, and the next update
  // solves every step so far (a shape in millimetres: its object 11.6 m off, now the estimate
  // of the shape in metres, `Online.AShapeInMillimetresOrTurnedIsNamedDuringThePush`).
  void CheckShape(double until, bool last) {
    if (!smoother->cfg.diagnostics || alignment.units_only) return;
    if (!last && (shape_judged || until < next_shape_check_t)) return;
    next_shape_check_t = until + kShapeCheckRetry;
    RegistrationOptions options = RegistrationOptionsFor(smoother->cfg);
    options.estimate_scale = smoother->cfg.align_scale;
    std::optional<RegistrationResult> r;
    try {
      r = RegisterShape(last ? traj : Newest(until - kShapeCheckSpan), options);
    } catch (const GraphError&) {
      // Too few contacts with object poses near them so far.
    }
    if (!r || r->independent_samples < kShapeCheckSamples) return;
    alignment.checked = true;
    alignment.check = r->check;
    if (r->fits_as_given) {
      next_shape_check_t = std::max(next_shape_check_t, first_t + 2.0 * (until - first_t));
      return;
    }
    shape_judged = true;
    // The time into the data: a robot's epoch time stamps printed as "t = 1.462e+09 s" hid it.
    std::string text = internal::Format("shape check (OnlineEstimator, on the samples up to %.3f s into the data, t = %s s): ",
                                        until - first_t, Precise(until).c_str());
    text += "the object's shape does not fit the contacts as given (" + r->check.Describe() + ")";
    if (r->size_mismatch) {
      text += internal::Format(
          ": it is %.3g times the size of the finger's path around the object's origin, and no unit makes it fit: check "
          "the shape's size and units, and that the finger and object pose streams share one frame",
          r->size_ratio);
    } else if (const std::optional<ShapeFitCheck> units = UnitsAloneFit(*r, options)) {
      // One push's contacts often fit a turned placement a little better than the units alone
      // (the notched block in millimetres: "turned by 68.8 deg" at scale 0.001, sigma 8.8 deg);
      // a shape that fits at the unit's scale alone is most likely only in other units.
      const double scale = r->transform.scale;
      std::string phrase = internal::registration::UnitPhrase(scale);
      if (phrase.rfind("the file", 0) == 0) phrase.replace(0, 8, "the shape");
      text += internal::Format("; at scale %g alone (no turn or shift) it fits them (%s): %s", scale,
                               units->Describe().c_str(), phrase.c_str());
      if (!last && smoother->cfg.align_shape != EstimatorConfig::AlignShape::kOff) {
        text += internal::Format(
            ". Read so from this update on: every step so far is solved again at that scale (align_shape \"off\" "
            "keeps the shape as given); the setup's shape scaled by %g saves this", scale);
        traj.object.shape = geometry::TransformShape(traj.object.shape, geometry::Pose2{}, scale, false);
        RestartSmoother();
        alignment.aligned = alignment.units_only = alignment.suggested = true;
        alignment.transform = ShapeTransform{};
        alignment.transform.scale = scale;
        Say(text);
        return;
      }
    } else {
      text += "; the contacts' best placement: " + r->Describe();
    }
    alignment.suggested = true;
    alignment.transform = r->transform;
    alignment.sigma = r->sigma;
    alignment.rotation_observable = r->rotation_observable;
    text += ". OnlineEstimator estimates with the shape as given (it solves steps as they come and cannot re-place "
            "them): place the setup's shape so (geometry::TransformShape; Shape.transformed in Python), or estimate the "
            "recording with `pushgraph estimate`, which aligns it";
    Say(text);
  }

  // The shape check's warning: the first, or its refinement by a later check.
  void Say(const std::string& text) {
    if (shape_warning) warnings[*shape_warning] = text;
    else shape_warning = warnings.size(), warnings.push_back(text);
  }

  std::vector<bool> declared;
  int fingers = 1;
  double max_latency = 0.2;
  static constexpr std::size_t kRecentPeriods = 64;  // object periods the schedule looks at
  double object_period = 0.0;  // median of the newest kRecentPeriods; updated per object sample

  static const push::Trajectory& Empty(const push::Trajectory& setup) {
    const auto& m = setup.measured;
    bool empty = m.object_pose.empty() && m.finger_pose.empty() && m.contact_point.empty() && m.force.empty();
    for (const push::ExtraFinger& f : setup.extra_fingers)
      empty = empty && f.measured.finger_pose.empty() && f.measured.contact_point.empty() && f.measured.force.empty();
    if (!empty) {
      throw GraphError("OnlineEstimator: the setup trajectory must have empty streams (measurements arrive through Add*)");
    }
    return setup;
  }
  // The setup with its tessellated fingers as disks, as Estimate reads them (`note` says so).
  static push::Trajectory AsEstimated(const push::Trajectory& setup, const EstimatorConfig& cfg, std::string* note) {
    std::optional<push::Trajectory> disks = internal::TessellatedFingersAsDisks(Empty(setup), cfg, note);
    return disks ? std::move(*disks) : setup;
  }
  Impl(const push::Trajectory& setup, Model model, const EstimatorConfig& cfg, const OnlineStreams& streams)
      : traj(AsEstimated(setup, cfg, &finger_disks)),
        model(model),
        streams(streams),
        smoother(std::make_unique<FixedLagSmoother>(traj, model, cfg, &this->streams)) {
    if (!finger_disks.empty()) warnings.push_back(finger_disks);
    // A shape that no tabletop object has: its units are read by the shape check, once the contacts
    // can judge them; until then (0.2 to 0.4 s of contact) the updates were metres off, unsaid.
    if (cfg.diagnostics && !traj.object.shape.empty()) {
      const double reach = geometry::RadiusAbout(traj.object.shape, geometry::CoreCentroid(traj.object.shape));
      if (reach > internal::kTabletopReach)
        warnings.push_back(internal::Format(
            "object: its shape reaches %.4g m from its centroid, which no tabletop object does: a file in millimetres, "
            "centimetres or inches? The shape check %s once the contacts can judge them (3 independent contact "
            "samples); the updates before that estimate with the shape as given",
            reach,
            cfg.align_shape == EstimatorConfig::AlignShape::kOff ? "names its units (align_shape \"off\" applies none)"
                                                                  : "reads its units"));
    }
    // Every finger (finger k is the setup's extra_fingers[k - 1]) has the same kinds of sensors.
    fingers = 1 + static_cast<int>(traj.extra_fingers.size());
    last_seen.assign(1 + 3 * fingers, -INFINITY);
    seen.assign(1 + 3 * fingers, 0);
    declared.assign(1 + 3 * fingers, false);
    repeated_contact.assign(fingers, false);
    reach_checked.assign(fingers, false);
    touch_scanned.assign(fingers, 0);
    declared[0] = true;
    for (int k = 0; k < fingers; ++k) {
      declared[3 * k + 1] = true;
      declared[3 * k + 2] = streams.contact_point;
      declared[3 * k + 3] = streams.force;
    }
    if (!(streams.max_latency >= 0.0) || !std::isfinite(streams.max_latency)) {
      throw GraphError("OnlineStreams::max_latency must be finite and >= 0 (s)");
    }
    max_latency = streams.max_latency;
  }

  // Throws for a sample that is not finite or not after its stream's previous one; returns
  // false (and counts it) for one at or before the last update: it would belong to steps
  // already solved, so it is dropped.
  // The stream of `finger`'s pose (kind 0), contact point (1) or force (2); throws for a finger
  // the setup does not have.
  int FingerStream(int finger, int kind, const char* call) const {
    if (finger >= 0 && finger < fingers) return 3 * finger + 1 + kind;
    throw GraphError("OnlineEstimator::" + std::string(call) + ": finger " + std::to_string(finger) +
                     " is out of range: the setup has " +
                     (fingers == 1 ? std::string("finger 0 only") : "fingers 0 to " + std::to_string(fingers - 1)) +
                     " (finger k >= 1 is the setup's extra finger k: Trajectory::extra_fingers[k - 1] in C++, "
                     "setup[\"fingers\"][k - 1] in Python)");
  }

  // `magnitude` within `bound` (positions within geometry::kMaxCoordinate, forces within 1e9 N,
  // the batch reader's bounds): one position of 1e20 m was taken, and every update after it
  // failed in the geometry with no word of which sample.
  bool Accept(int stream, const char* name, double t, bool finite, double magnitude = 0.0, double bound = INFINITY,
              const char* unit = "") {
    const std::size_t index = seen[stream];
    auto where = [&] {
      return "OnlineEstimator: streams." + (stream >= 4 ? "fingers[" + std::to_string((stream - 1) / 3) + "]." : std::string()) + name + "[" +
             std::to_string(index) + "] at t = " + Precise(t);
    };
    if (finished) throw GraphError(where() + " arrived after Finish()");
    if (!declared[stream]) {
      throw GraphError(where() + ": the stream was not declared (OnlineStreams in C++, the contact_point= and force= "
                       "arguments in Python): it decides contact gating and the load factor");
    }
    if (!std::isfinite(t) || !finite) throw GraphError(where() + " is not finite");
    if (magnitude > bound) {
      throw GraphError(where() + " is out of the supported range (" + Precise(magnitude) + " " + unit +
                       "; positions within 1e6 m, forces within 1e9 N): a corrupt sample? It is not taken");
    }
    // The trajectory's bound (|t| <= 1e11 s: epoch seconds): one wild first time stamp (-1e300)
    // was accepted and every later sample then refused as a clock jump.
    if (std::abs(t) > push::kMaxTimeStamp) {
      throw GraphError(where() + " is out of the supported range (|t| <= " + Precise(push::kMaxTimeStamp) +
                       " s, epoch seconds): milliseconds or a corrupt time stamp?");
    }
    // A second contact point of a finger at the same time is its second contact (a finger wedged
    // in a notch, a flat face along the object's).
    const bool contact = stream >= 1 && (stream - 1) % 3 == 1;
    const int finger = (stream - 1) / 3;
    const bool second_contact = contact && t == last_seen[stream] && !repeated_contact[finger];
    if (!(t > last_seen[stream]) && !second_contact) {
      throw GraphError(where() + " is not after the previous sample (t = " + Precise(last_seen[stream]) + ")" +
                       (contact && t == last_seen[stream]
                            ? ": at most two contacts at one time (per finger)"
                            : ": each stream must arrive in time order"));
    }
    if (contact) repeated_contact[finger] = second_contact;
    // A clock jump (the batch estimator's bound: 10 s or 1000 object periods): the smoother's
    // states follow the clock, so its cost would follow the jump, not the samples.
    const double jump_bound = std::max(10.0, std::isfinite(object_period) ? 1000.0 * object_period : 0.0);
    if (std::isfinite(newest_t) && t - newest_t > jump_bound) {
      throw GraphError(where() + " is " + Precise(t - newest_t) + " s after the newest sample of any stream (t = " +
                       Precise(newest_t) + "): a clock jump longer than " + Precise(jump_bound) +
                       " s is refused; fix the time stamps or start a new estimator");
    }
    last_seen[stream] = t;
    ++seen[stream];
    newest_t = std::max(newest_t, t);
    first_t = std::min(first_t, t);
    if (!(t > last_update_t + 1e-9)) {
      ++dropped_late;
      return false;
    }
    return true;
  }

  // The newest time every live stream has reached: a stream is live when its newest sample is
  // within max_latency (and 1.5 k object periods) of the newest sample of any stream, so a late
  // camera is waited for while an occluded one, or a tactile sensor silent out of contact, does
  // not hold the others back.
  // Every pose stream (the object's, each finger's) has a sample at or before `until`.
  bool PosesUpTo(double until) const {
    auto has = [until](const std::vector<push::PoseSample>& poses) { return !poses.empty() && !(poses.front().t > until); };
    bool all = has(traj.measured.object_pose) && has(traj.measured.finger_pose);
    for (const push::ExtraFinger& f : traj.extra_fingers) all = all && has(f.measured.finger_pose);
    return all;
  }

  double SettledTime() const {
    // At the sensor rate (incremental_update_every_steps) only max_latency counts: a camera slower
    // than the update rate is not waited for between its frames.
    const double live = smoother->cfg.incremental_update_every_steps >= 1
                            ? max_latency
                            : std::max(max_latency, 1.5 * smoother->cfg.incremental_update_every * object_period);
    double settled = newest_t;
    for (std::size_t k = 0; k < last_seen.size(); ++k) {
      const double t = last_seen[k];
      // A late tracker's poses (object_delay, stream 0) are behind the rest by the delay itself.
      const double allowed = live + (k == 0 ? std::max(0.0, smoother->cfg.object_delay) : 0.0);
      if (std::isfinite(t) && newest_t - t <= allowed) settled = std::min(settled, t);
    }
    return settled;
  }

  // Distinct time stamps of any stream with from < t <= to (the steps an update would add),
  // counted up to `cap`.
  int StepsSince(double from, double to, int cap) const {
    const auto& m = traj.measured;
    std::vector<double> times;
    auto collect = [&](const auto& stream) {
      for (auto it = stream.rbegin(); it != stream.rend() && it->t > from; ++it) {
        if (it->t <= to) times.push_back(it->t);
      }
    };
    collect(m.object_pose);
    collect(m.finger_pose);
    collect(m.contact_point);
    collect(m.force);
    for (const push::ExtraFinger& f : traj.extra_fingers) {
      collect(f.measured.finger_pose);
      collect(f.measured.contact_point);
      collect(f.measured.force);
    }
    std::sort(times.begin(), times.end());
    const int distinct = static_cast<int>(std::unique(times.begin(), times.end()) - times.begin());
    return std::min(distinct, cap);
  }

  // Object samples with from < t <= to.
  int ObjectSamplesSince(double from, double to) const {
    const auto& obj = traj.measured.object_pose;
    auto after = [&](double t) {
      return std::upper_bound(obj.begin(), obj.end(), t, [](double x, const push::PoseSample& a) { return x < a.t; });
    };
    return to > from ? static_cast<int>(after(to) - after(from)) : 0;
  }
};

OnlineEstimator::OnlineEstimator(const push::Trajectory& setup, Model model, const EstimatorConfig& config,
                                 const OnlineStreams& streams)
    : impl_(std::make_unique<Impl>(setup, model, config, streams)) {}
OnlineEstimator::~OnlineEstimator() = default;

bool OnlineEstimator::AddObjectPose(double stamp, const geometry::Pose2& pose) {
  // A tracker's latency (object_delay): the pose belongs to its stamp minus the delay (errors and
  // the stream's liveness, Impl::SettledTime, speak of that time).
  const double t = stamp - impl_->smoother->cfg.object_delay;
  const std::size_t index = impl_->seen[0];
  if (!impl_->Accept(0, "object_pose", t, pose.vector().allFinite(), pose.translation().cwiseAbs().maxCoeff(),
                     geometry::kMaxCoordinate, "m"))
    return false;
  double off = 0.0;
  if (impl_->ObjectPoseGlitch(t, pose, &off)) {
    impl_->Fault("object_pose sample", "tracker glitches: more than max(1 cm, 10 sigmas) or max(0.3 rad, 10 sigmas), plus the recent motion, from the median of the five poses before",
                 internal::Format("object_pose[%zu] at t = %s s, %.3g mm off", index, Precise(t).c_str(), 1e3 * off));
    return false;
  }
  impl_->traj.measured.object_pose.push_back({t, pose});
  impl_->object_period = MedianObjectPeriod(impl_->traj.measured.object_pose, Impl::kRecentPeriods);
  return true;
}
bool OnlineEstimator::AddFingerPose(double t, const geometry::Pose2& pose) { return AddFingerPose(t, 0, pose); }
bool OnlineEstimator::AddContactPoint(double t, const geometry::Vec2& point) { return AddContactPoint(t, 0, point); }
bool OnlineEstimator::AddForce(double t, const geometry::Vec2& force) { return AddForce(t, 0, force); }

bool OnlineEstimator::AddFingerPose(double t, int finger, const geometry::Pose2& pose) {
  Impl& m = *impl_;
  const int stream = m.FingerStream(finger, 0, "AddFingerPose");
  if (!m.Accept(stream, "finger_pose", t, pose.vector().allFinite(), pose.translation().cwiseAbs().maxCoeff(),
                geometry::kMaxCoordinate, "m"))
    return false;
  (finger == 0 ? m.traj.measured.finger_pose : m.traj.extra_fingers[finger - 1].measured.finger_pose).push_back({t, pose});
  return true;
}
bool OnlineEstimator::AddContactPoint(double t, int finger, const geometry::Vec2& point) {
  Impl& m = *impl_;
  const int stream = m.FingerStream(finger, 1, "AddContactPoint");
  const std::size_t index = m.seen[stream];
  if (!m.Accept(stream, "contact_point", t, point.allFinite(), point.cwiseAbs().maxCoeff(), geometry::kMaxCoordinate, "m"))
    return false;
  if (m.contacts_left_out) return false;  // the contact check left the stream out
  // A corrupt row (the batch's DropContactRowFaults), against the finger's pose near its time,
  // once the contact check has found the stream on its finger (before, a stream 5 cm off had
  // every row refused one by one, and the check that leaves the stream out never ran). Beyond the
  // newest finger pose, the finger's recent speed widens the bound (a 20 Hz finger at 0.5 m/s
  // moves 25 mm between poses: good rows were refused against the stale pose).
  const auto& poses = finger == 0 ? m.traj.measured.finger_pose : m.traj.extra_fingers[finger - 1].measured.finger_pose;
  const geometry::Shape& shape = finger == 0 ? m.traj.finger.shape : m.traj.extra_fingers[finger - 1].finger.shape;
  const bool on_finger = m.contact_verdict.size() == static_cast<std::size_t>(m.fingers) &&
                         m.contact_verdict[finger] == Impl::ContactVerdict::kOnFinger;
  if (on_finger && internal::FingerPoseNear(poses, t) && !shape.empty()) {
    const double d = internal::DistanceFromFinger(poses, shape, t, point);
    const double beyond = std::max(0.0, t - poses.back().t);
    const double bound = internal::ContactFaultBound(m.smoother->cfg.measurement) + 2.0 * Impl::RecentSpeed(poses) * beyond;
    if (d > bound) {
      m.Fault("contact_point row",
              internal::Format("more than %.3g mm from the finger's boundary at its pose near the row's time", 1e3 * bound),
              internal::Format("%scontact_point[%zu] at t = %s s, %.3g mm off",
                               finger == 0 ? "" : ("fingers[" + std::to_string(finger) + "].").c_str(), index,
                               Precise(t).c_str(), 1e3 * d));
      return false;
    }
  }
  (finger == 0 ? m.traj.measured.contact_point : m.traj.extra_fingers[finger - 1].measured.contact_point).push_back({t, point});
  return true;
}
bool OnlineEstimator::AddForce(double t, int finger, const geometry::Vec2& force) {
  Impl& m = *impl_;
  const int stream = m.FingerStream(finger, 2, "AddForce");
  const std::size_t index = m.seen[stream];
  if (!m.Accept(stream, "force", t, force.allFinite(), force.cwiseAbs().maxCoeff(), 1e9, "N")) return false;
  const double magnitude = force.norm();
  const bool known_object = m.traj.object.mass > 0.0 && m.traj.object.mu_surface > 0.0;
  if (m.recent_force.size() >= 8) {
    if (m.since_p95 == 0) m.recent_p95 = internal::Percentile95({m.recent_force.begin(), m.recent_force.end()});
    m.since_p95 = (m.since_p95 + 1) % 32;
  }
  // Before 8 forces arrived only the object's friction limit bounds them (when known).
  const bool judged = known_object || m.recent_force.size() >= 8;
  const double bound = internal::ForceFaultBound(m.recent_p95, m.traj.object);
  if (judged && magnitude > bound) {
    m.Fault("force sample", "50 times the recent forces or the object's friction limit",
            internal::Format("%sforce[%zu] at t = %.9g s, |f| = %.3g N (bound %.3g N)",
                             finger == 0 ? "" : ("fingers[" + std::to_string(finger) + "].").c_str(), index, t, magnitude,
                             bound));
    return false;
  }
  m.recent_force.push_back(magnitude);
  if (m.recent_force.size() > Impl::kRecentForces) m.recent_force.pop_front();
  (finger == 0 ? m.traj.measured.force : m.traj.extra_fingers[finger - 1].measured.force).push_back({t, force});
  return true;
}
const std::vector<std::string>& OnlineEstimator::Warnings() const { return impl_->warnings; }
int OnlineEstimator::DroppedLateSamples() const { return impl_->dropped_late; }
int OnlineEstimator::DroppedFaultySamples() const { return impl_->dropped_faults; }

bool OnlineEstimator::UpdateDue() const {
  const Impl& m = *impl_;
  const int k = m.smoother->cfg.incremental_update_every;
  // Only what an update would take counts: samples up to the settled time (a late camera's
  // poses are waited for, not counted before they arrive).
  const double settled = m.SettledTime();
  // The first update needs every pose stream up to that time (Update refuses it otherwise): on an
  // MIT recording a force sample before the first camera frame made it due, and Update threw.
  if (m.smoother->next_step == 0 && !m.PosesUpTo(settled)) return false;
  if (m.smoother->cfg.incremental_update_every_steps >= 1) {
    // At least three steps in the first update (see IncrementalEstimator).
    const int needed = std::max(m.smoother->cfg.incremental_update_every_steps, m.smoother->next_step == 0 ? 3 : 1);
    return m.StepsSince(m.last_update_t, settled, needed) >= needed;
  }
  if (m.ObjectSamplesSince(m.last_update_t, settled) >= k) return true;
  // The object stream is silent (occlusion): update on time, as IncrementalEstimator does.
  const double since = std::isfinite(m.last_update_t) ? m.last_update_t : m.first_t;
  return m.object_period > 0.0 && settled - since > 1.5 * k * m.object_period;
}

double OnlineEstimator::Update(double until) {
  Impl& m = *impl_;
  if (m.finished) throw GraphError("OnlineEstimator::Update called after Finish()");
  if (std::isnan(until)) throw GraphError("OnlineEstimator::Update: the update time is NaN");
  // Default: up to where every live stream has reported; an explicit time is taken as given.
  until = until == INFINITY ? m.SettledTime() : std::min(until, m.newest_t);
  if (!(until > m.last_update_t)) return 0.0;  // nothing new
  const auto& meas = m.traj.measured;
  if (m.smoother->next_step == 0) {
    // The first update needs both poses: nothing else anchors the object and the finger.
    if (meas.object_pose.empty() || meas.object_pose.front().t > until) {
      throw GraphError("OnlineEstimator::Update: no object pose measurement (streams.object_pose) up to t = " +
                       Precise(until) + ": the first update needs one to anchor the object");
    }
    if (meas.finger_pose.empty() || meas.finger_pose.front().t > until) {
      throw GraphError("OnlineEstimator::Update: no finger pose measurement (streams.finger_pose) up to t = " + Precise(until));
    }
    for (int k = 1; k < m.fingers; ++k) {
      const auto& poses = m.traj.extra_fingers[k - 1].measured.finger_pose;
      if (poses.empty() || poses.front().t > until) {
        const std::string finger = std::to_string(k);
        throw GraphError("OnlineEstimator::Update: no pose measurement of finger " + finger + " (streams.fingers[" + finger +
                         "].finger_pose) up to t = " + Precise(until));
      }
    }
  }
  m.CheckTouchingFingersAreNear();
  // Samples within 1e-9 s after `until` join its step now (as batch merges them), so no later
  // step can be closer than that to a solved one.
  m.last_update_t = until;  // later samples must come more than 1e-9 s after it (Accept)
  until += 1e-9;
  // The contact and shape checks first: either may start the smoother again (without the
  // contact stream, with the shape in its units).
  const auto start = std::chrono::steady_clock::now();
  m.CheckContacts(until, false);
  m.CheckShape(until, false);
  const double checked = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  m.smoother->builder.AppendSteps(until);
  if (m.object_period > 0.0) m.smoother->window_duration = m.smoother->cfg.IncrementalWindowPeriods() * m.object_period;
  const double solved = m.smoother->Update(until, false);
  // The check is part of this update's time, in the result's update_times_s too.
  SolverStats& stats = m.smoother->stats;
  stats.update_times_s.back() += checked;
  stats.max_update_time_s = std::max(stats.max_update_time_s, stats.update_times_s.back());
  m.smoother->total_update_time += checked;
  return checked + solved;
}

StateEstimate OnlineEstimator::LatestState() const { return impl_->smoother->LatestState("OnlineEstimator"); }
int OnlineEstimator::WindowSteps() const { return impl_->smoother->next_step - impl_->smoother->lo; }
int OnlineEstimator::StepsAdded() const { return impl_->smoother->next_step; }

EstimationResult OnlineEstimator::Finish() {
  Impl& m = *impl_;
  if (m.finished) throw GraphError("OnlineEstimator::Finish called twice");
  if (m.newest_t > m.last_update_t) Update(m.newest_t);  // the end: wait for nobody
  m.finished = true;
  if (m.smoother->next_step == 0) throw GraphError("OnlineEstimator::Finish: no measurements were added");
  m.CheckContacts(m.last_update_t, true);
  m.CheckShape(m.last_update_t, true);
  EstimationResult r = m.smoother->Finish();
  if (m.alignment.checked) r.shape_alignment = m.alignment;
  r.warnings.insert(r.warnings.begin(), m.warnings.begin(), m.warnings.end());
  // Updates at the sensor rate that waited for the camera: documented (OnlineStreams::
  // max_latency), but a user who set incremental_update_every_steps 1 got one update per camera
  // frame, 54 where the replay made 274, and estimates 4 mm apart, with no word.
  const int every = m.smoother->cfg.incremental_update_every_steps;
  if (every >= 1 && m.object_period > 0.0 && m.max_latency >= m.object_period && r.solver.updates > 0 &&
      2 * r.solver.updates * every < static_cast<int>(r.states.size())) {
    r.warnings.push_back(internal::Format(
        "updates at the sensor rate waited for the camera: %d updates for %zu steps with incremental_update_every_steps "
        "%d, because OnlineStreams::max_latency (%.3g s) is not below the object stream's period (%.3g s), so every "
        "update waited for the next frame; set max_latency below the period (max_latency=0 in Python) for an update "
        "per %d step%s",
        r.solver.updates, r.states.size(), every, m.max_latency, m.object_period, every, every == 1 ? "" : "s"));
  }
  for (const auto& [kind, f] : m.faults) {
    r.warnings.insert(r.warnings.begin(), std::to_string(f.count) + " " + kind + (f.count == 1 ? "" : "s") +
                                              " left out as sensor faults (" + f.why + "); the first: " + f.first);
  }
  return r;
}

}  // namespace pushgraph::graph
