#include "graph_builder.h"

#include <pushgraph/graph/incremental.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <map>

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

struct IncrementalEstimator::Impl {
  const limit_surface::Trajectory& traj;
  EstimatorConfig cfg;
  internal::GraphBuilder builder;
  std::unique_ptr<ceres::Problem> problem;
  std::vector<double> triggers;
  std::size_t next_trigger = 0;
  double window_duration = 0.0;
  int next_step = 0;  // first step not yet added
  int lo = 0;         // oldest step in the window
  std::vector<StateEstimate> states;
  std::vector<bool> done;
  SolverStats stats;
  double total_update_time = 0.0;
  double last_cost = 0.0;

  Impl(const limit_surface::Trajectory& t, Model model, const EstimatorConfig& c)
      : traj(t), cfg(c), builder(t, model, c) {
    if (cfg.estimate_c || cfg.estimate_mu) {
      throw GraphError("estimate_c and estimate_mu are batch only: the incremental mode keeps c and mu fixed");
    }
    ceres::Problem::Options po;
    po.enable_fast_removal = true;
    problem = std::make_unique<ceres::Problem>(po);
    const auto& obj = traj.measured.object_pose;
    std::vector<double> periods;
    for (std::size_t i = 1; i < obj.size(); ++i) periods.push_back(obj[i].t - obj[i - 1].t);
    double period;
    if (!periods.empty()) {
      std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
      period = periods[periods.size() / 2];
    } else {
      const auto& steps = builder.steps();
      period = steps.size() > 1 ? 10.0 * (steps.back().t - steps.front().t) / double(steps.size() - 1) : 1.0;
    }
    const int k = cfg.incremental_update_every;
    window_duration = cfg.incremental_window * period;
    const double max_spacing = 1.5 * k * period;
    for (std::size_t j = k - 1; j < obj.size(); j += k) {
      // While the object stream is occluded, update on time anyway.
      while (!triggers.empty() && obj[j].t - triggers.back() > max_spacing) triggers.push_back(triggers.back() + k * period);
      triggers.push_back(obj[j].t);
    }
    const double t_end = builder.steps().back().t;
    if (triggers.empty()) triggers.push_back(builder.steps().front().t);
    while (t_end - triggers.back() > max_spacing) triggers.push_back(triggers.back() + k * period);
    if (triggers.back() < t_end) triggers.push_back(t_end);
    states.resize(builder.steps().size());
    done.assign(builder.steps().size(), false);
  }

  void Record(const std::vector<int>& idx) {
    std::vector<StateEstimate> out;
    for (int i : idx) out.push_back(builder.State(i));
    if (cfg.covariance && !idx.empty()) {
      const std::string status = internal::ComputeCovariances(*problem, builder, idx, out, cfg.covariance_method);
      if (status != "ok") stats.covariance_status = status;
      else if (stats.covariance_status == "not computed") stats.covariance_status = "ok";
    }
    for (std::size_t k = 0; k < idx.size(); ++k) {
      states[idx[k]] = out[k];
      done[idx[k]] = true;
    }
  }

  // Schur-complements every factor touching step s onto the blocks they share with other steps.
  void Marginalize(int s) {
    std::vector<double*> removed = builder.Blocks(s);
    // In a deterministic order (a set of pointers would make the sums, and so the result,
    // depend on heap addresses).
    std::vector<ceres::ResidualBlockId> rbs;
    for (double* b : removed) {
      std::vector<ceres::ResidualBlockId> v;
      problem->GetResidualBlocksForParameterBlock(b, &v);
      for (ceres::ResidualBlockId id : v) {
        if (std::find(rbs.begin(), rbs.end(), id) == rbs.end()) rbs.push_back(id);
      }
    }
    std::vector<double*> order(removed);
    std::map<double*, int> offset;
    int dim = 0;
    for (double* b : removed) { offset[b] = dim; dim += problem->ParameterBlockSize(b); }
    const int removed_dim = dim;
    std::vector<std::vector<double*>> rb_params;
    for (ceres::ResidualBlockId id : rbs) {
      std::vector<double*> ps;
      problem->GetParameterBlocksForResidualBlock(id, &ps);
      for (double* p : ps) {
        if (!offset.count(p)) { offset[p] = dim; order.push_back(p); dim += problem->ParameterBlockSize(p); }
      }
      rb_params.push_back(ps);
    }
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(dim);
    std::size_t k = 0;
    for (ceres::ResidualBlockId id : rbs) {
      const std::vector<double*>& ps = rb_params[k++];
      const ceres::CostFunction* cost = problem->GetCostFunctionForResidualBlock(id);
      const ceres::LossFunction* loss = problem->GetLossFunctionForResidualBlock(id);
      const int m = cost->num_residuals();
      Eigen::VectorXd r(m);
      std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(ps.size());
      std::vector<double*> jp(ps.size());
      for (std::size_t q = 0; q < ps.size(); ++q) {
        J[q].resize(m, problem->ParameterBlockSize(ps[q]));
        jp[q] = J[q].data();
      }
      if (!cost->Evaluate(ps.data(), r.data(), jp.data())) continue;
      double scale = 1.0;
      if (loss != nullptr) {
        double rho[3];
        loss->Evaluate(r.squaredNorm(), rho);
        scale = std::sqrt(std::max(rho[1], 0.0));
      }
      Eigen::MatrixXd Jf = Eigen::MatrixXd::Zero(m, dim);
      for (std::size_t q = 0; q < ps.size(); ++q) Jf.middleCols(offset[ps[q]], J[q].cols()) += scale * J[q];
      H.noalias() += Jf.transpose() * Jf;
      b.noalias() += Jf.transpose() * (scale * r);
    }
    // Remove the step (its residual blocks go with its parameter blocks).
    for (double* p : removed) problem->RemoveParameterBlock(p);
    const int sep_dim = dim - removed_dim;
    if (sep_dim == 0) return;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> er(H.topLeftCorner(removed_dim, removed_dim));
    const double emax = std::max(er.eigenvalues().maxCoeff(), 1e-300);
    Eigen::VectorXd inv = er.eigenvalues();
    for (int i = 0; i < inv.size(); ++i) inv[i] = inv[i] > 1e-12 * emax ? 1.0 / inv[i] : 0.0;
    const Eigen::MatrixXd Hrr_inv = er.eigenvectors() * inv.asDiagonal() * er.eigenvectors().transpose();
    const Eigen::MatrixXd Hsr = H.bottomLeftCorner(sep_dim, removed_dim);
    const Eigen::MatrixXd Hm = H.bottomRightCorner(sep_dim, sep_dim) - Hsr * Hrr_inv * Hsr.transpose();
    const Eigen::VectorXd bm = b.tail(sep_dim) - Hsr * Hrr_inv * b.head(removed_dim);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Hm + Hm.transpose()));
    const double smax = es.eigenvalues().maxCoeff();
    std::vector<int> keep;
    for (int i = 0; i < sep_dim; ++i) if (es.eigenvalues()[i] > 1e-10 * smax && es.eigenvalues()[i] > 0) keep.push_back(i);
    if (keep.empty()) return;
    Eigen::MatrixXd S(keep.size(), sep_dim);
    Eigen::VectorXd r0(keep.size());
    for (std::size_t i = 0; i < keep.size(); ++i) {
      const double lambda = es.eigenvalues()[keep[i]];
      const Eigen::VectorXd u = es.eigenvectors().col(keep[i]);
      S.row(i) = std::sqrt(lambda) * u.transpose();
      r0[i] = u.dot(bm) / std::sqrt(lambda);
    }
    std::vector<double*> sep(order.begin() + removed.size(), order.end());
    std::vector<int> sizes;
    Eigen::VectorXd x_bar(sep_dim);
    int off = 0;
    for (double* p : sep) {
      const int n = problem->ParameterBlockSize(p);
      sizes.push_back(n);
      for (int j = 0; j < n; ++j) x_bar[off + j] = p[j];
      off += n;
    }
    problem->AddResidualBlock(new MarginalPriorFactor(sizes, x_bar, S, r0), nullptr, sep);
  }

  double Update() {
    const auto start = std::chrono::steady_clock::now();
    const double target = triggers[next_trigger++];
    const int n = static_cast<int>(builder.steps().size());
    const int first_new = next_step;
    while (next_step < n && (builder.steps()[next_step].t <= target + 1e-12 || next_trigger == triggers.size())) {
      builder.Initialize(next_step, target);
      ++next_step;
    }
    // The new steps start from a causal motion-only smoother (as the batch solver's start).
    stats.iterations += builder.SmoothInitialMotion(10, 1e-3, first_new, next_step);
    for (int i = first_new; i < next_step; ++i) builder.AddFactors(*problem, i, internal::GraphBuilder::kKinematic);
    ceres::Solver::Summary summary;
    const auto options = internal::SolverOptions(cfg.incremental_max_iterations, cfg.function_tolerance);
    if (ModelHasForce(builder.model())) {
      // Staged like the batch solver: the new steps' kinematics first (the window's older
      // steps held fixed: only the new ones need a start), then everything with the dynamics.
      std::vector<double*> held;
      for (int i = lo; i < first_new; ++i) {
        for (double* b : builder.Blocks(i)) {
          if (problem->HasParameterBlock(b) && !problem->IsParameterBlockConstant(b)) {
            problem->SetParameterBlockConstant(b);
            held.push_back(b);
          }
        }
      }
      ceres::Solve(options, problem.get(), &summary);
      internal::LogSummary("incremental update, new steps' kinematics", summary);
      for (double* b : held) problem->SetParameterBlockVariable(b);
      stats.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
      for (int i = first_new; i < next_step; ++i) builder.AddFactors(*problem, i, internal::GraphBuilder::kDynamic);
    }
    ceres::Solve(options, problem.get(), &summary);
    internal::LogSummary("incremental update, window", summary);
    stats.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    last_cost = summary.final_cost;
    // States leaving the window (keep at least three steps for the V factors).
    std::vector<int> leaving;
    const double t_now = builder.steps()[next_step - 1].t;
    int s = lo;
    while (s < next_step - 3 && builder.steps()[s].t < t_now - window_duration) leaving.push_back(s++);
    const auto record_start = std::chrono::steady_clock::now();
    Record(leaving);
    const auto marginalize_start = std::chrono::steady_clock::now();
    for (int i : leaving) Marginalize(i);
    if (internal::SolverLogLevel() >= 1) {
      const auto now = std::chrono::steady_clock::now();
      std::cerr << "pushgraph incremental update: record " << leaving.size() << " steps "
                << std::chrono::duration<double>(marginalize_start - record_start).count() << " s, marginalize "
                << std::chrono::duration<double>(now - marginalize_start).count() << " s, whole update "
                << std::chrono::duration<double>(now - start).count() << " s\n";
    }
    lo = s;
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++stats.updates;
    total_update_time += dt;
    stats.max_update_time_s = std::max(stats.max_update_time_s, dt);
    return dt;
  }
};

IncrementalEstimator::IncrementalEstimator(const limit_surface::Trajectory& trajectory, Model model,
                                           const EstimatorConfig& config)
    : impl_(std::make_unique<Impl>(trajectory, model, config)) {}
IncrementalEstimator::~IncrementalEstimator() = default;

bool IncrementalEstimator::Done() const { return impl_->next_trigger >= impl_->triggers.size(); }
double IncrementalEstimator::Update() {
  if (Done()) throw GraphError("IncrementalEstimator::Update called after the last update");
  return impl_->Update();
}
StateEstimate IncrementalEstimator::LatestState() const {
  if (impl_->next_step == 0) throw GraphError("IncrementalEstimator::LatestState before the first Update");
  return impl_->builder.State(impl_->next_step - 1);
}
int IncrementalEstimator::WindowSteps() const { return impl_->next_step - impl_->lo; }
int IncrementalEstimator::StepsAdded() const { return impl_->next_step; }
int IncrementalEstimator::TotalSteps() const { return static_cast<int>(impl_->builder.steps().size()); }

EstimationResult IncrementalEstimator::Finish() {
  Impl& m = *impl_;
  if (!Done()) throw GraphError("IncrementalEstimator::Finish called before the last update");
  const auto start = std::chrono::steady_clock::now();
  std::vector<int> rest;
  for (int i = m.lo; i < m.next_step; ++i) rest.push_back(i);
  m.Record(rest);
  m.total_update_time += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EstimationResult r;
  r.model = m.builder.model();
  r.mode = Mode::kIncremental;
  r.states = m.states;
  r.solver = m.stats;
  r.solver.time_s = m.total_update_time;
  r.solver.final_cost = m.last_cost;
  r.solver.mean_update_time_s = m.stats.updates > 0 ? m.total_update_time / m.stats.updates : 0.0;
  r.metrics = ComputeMetrics(m.traj, r.states);
  return r;
}

}  // namespace pushgraph::graph
