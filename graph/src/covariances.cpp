#include "graph_builder.h"
#include "text.h"

#include <ceres/normal_prior.h>

#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/marginals.h>
#include <pushgraph/graph/shape_frame.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <sstream>
#include <tuple>


// Marginal covariances of a solved graph (selected inversion, with ceres::Covariance as the
// fallback and the reference) and the solver's logging (solver_log.h).
namespace pushgraph::graph::internal {

std::string ComputeCovariances(ceres::Problem& problem, GraphBuilder& builder, const std::vector<int>& steps,
                               std::vector<StateEstimate>& states, EstimatorConfig::CovarianceMethod method,
                               EstimationResult* parameters, Eigen::Matrix3d* frame_cov, ChainSolver* chain) {
  // The shared parameters (c, mu) whose sigmas are wanted.
  std::vector<std::pair<double*, std::optional<double>*>> shared;
  if (parameters != nullptr) {
    if (double* c = builder.c_block()) shared.emplace_back(c, &parameters->c_sigma);
    if (double* mu = builder.mu_block()) shared.emplace_back(mu, &parameters->mu_sigma);
  }
  // Either method answers "the covariance of block b" into a row-major buffer.
  std::function<bool(double*, double*)> get;
  SparseMarginals marginals;
  std::unique_ptr<ceres::Covariance> covariance;
  std::string marginals_error;
  if (method == EstimatorConfig::CovarianceMethod::kSelectedInversion) {
    const auto start = std::chrono::steady_clock::now();
    if (chain != nullptr ? marginals.Compute(*chain) : marginals.Compute(problem)) {
      if (SolverLogLevel() >= 1) {
        const SparseMarginals::Timings& t = marginals.timings();
        std::cerr << "pushgraph marginals: " << marginals.num_unknowns() << " unknowns, "
                  << marginals.num_factor_nonzeros() << " factor nonzeros, "
                  << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                  << " s (Jacobian " << t.jacobian << ", J^T J " << t.normal_equations << ", Cholesky "
                  << t.factorization << ", selected inversion " << t.inversion << "), smallest pivot ratio "
                  << marginals.min_pivot_ratio() << (marginals.extended_precision() ? ", in long double (the double pass refused a pivot)" : "") << "\n";
      }
      get = [&](double* b, double* out) {
        const Eigen::MatrixXd m = marginals.Covariance(b);
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(out, m.rows(), m.cols()) = m;
        return true;
      };
    } else {
      // Name the state, then try the QR on J (it copes with worse conditioning than J^T J).
      marginals_error = marginals.error();
      const double* bad = marginals.failed_block();
      for (int i = 0; bad != nullptr && i < static_cast<int>(builder.steps().size()); ++i) {
        const StepVars& v = builder.vars()[i];
        std::vector<std::pair<const double*, std::string>> blocks{
            {v.x, "object pose"}, {v.e, "finger pose"}, {v.p, "contact point"}, {v.f, "force"},
            {v.p2, builder.several_fingers() ? "finger 1 contact point" : "second contact point"},
            {v.f2, builder.several_fingers() ? "finger 1 force" : "second contact force"}};
        for (int k = 1; k < builder.num_fingers(); ++k) {
          const std::string finger = "finger " + std::to_string(k);
          blocks.emplace_back(builder.FingerPose(i, k), finger + " pose");
          if (k >= 2) {
            blocks.emplace_back(builder.FingerContact(i, k), finger + " contact point");
            blocks.emplace_back(builder.FingerForce(i, k), finger + " force");
          }
        }
        for (int k = 0; k < builder.num_fingers() && builder.several_fingers(); ++k) {
          const std::string finger = "finger " + std::to_string(k);
          blocks.emplace_back(builder.SecondContactPoint(i, k), finger + " second contact point");
          blocks.emplace_back(builder.SecondContactForce(i, k), finger + " second contact force");
        }
        for (const auto& [block, name] : blocks) {
          if (block != bad) continue;
          marginals_error += " [step " + std::to_string(i) + ", t = " + StepTime(builder.steps()[i].t, builder.steps().front().t) +
                             ", " + name + "]";
        }
      }
      if (bad != nullptr && bad == builder.c_block()) marginals_error += " [c]";
      if (bad != nullptr && bad == builder.mu_block()) marginals_error += " [mu]";
      if (SolverLogLevel() >= 1) std::cerr << "pushgraph marginals: " << marginals_error << "; trying ceres::Covariance\n";
    }
  }
  if (!get) {
    ceres::Covariance::Options options;
    options.algorithm_type = ceres::SPARSE_QR;
    options.num_threads = 1;
    covariance = std::make_unique<ceres::Covariance>(options);
    std::vector<std::pair<const double*, const double*>> pairs;
    for (int i : steps) {
      for (double* b : builder.Blocks(i)) pairs.emplace_back(b, b);
    }
    for (const auto& sh : shared) pairs.emplace_back(sh.first, sh.first);
    if (frame_cov != nullptr && builder.frame_block() != nullptr) pairs.emplace_back(builder.frame_block(), builder.frame_block());
    if (!covariance->Compute(pairs, &problem)) {
      return "failed (" + (marginals_error.empty() ? std::string("rank-deficient Jacobian") : marginals_error) + ")";
    }
    get = [&](double* b, double* out) { return covariance->GetCovarianceBlock(b, b, out); };
  }
  for (const auto& [block, sigma] : shared) {
    if (double var = 0.0; get(block, &var)) *sigma = std::sqrt(var);
  }
  if (frame_cov != nullptr && builder.frame_block() != nullptr) {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c3;
    if (get(builder.frame_block(), c3.data())) *frame_cov = c3;
  }
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const int i = steps[k];
    StepVars& v = builder.vars()[i];
    StateEstimate& s = states[k];
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c3;
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> c2;
    get(v.x, c3.data());
    s.object_pose_cov = Eigen::Matrix3d(c3);
    get(v.e, c3.data());
    s.finger_pose_cov = Eigen::Matrix3d(c3);
    if (builder.HasContactVars(i)) {
      get(v.p, c2.data());
      s.contact_cov = Eigen::Matrix2d(c2);
    }
    if (builder.HasForceVars(i)) {
      get(v.f, c2.data());
      s.force_cov = Eigen::Matrix2d(c2);
    }
    if (builder.several_fingers()) {
      // Every finger's pose; each finger's contact and force (their own: each finger has a sensor).
      for (FingerPoseEstimate& f : s.other_fingers)
        if (get(builder.FingerPose(i, f.finger), c3.data())) f.pose_cov = Eigen::Matrix3d(c3);
      // Each finger's first contact entry, then its second (a finger touching at two points).
      std::vector<int> seen(builder.num_fingers(), 0);
      for (ContactEstimate& c : s.contacts) {
        const int nth = seen[c.finger]++;
        if (c.finger == 0 && nth == 0) {
          c.point_cov = s.contact_cov;
          c.force_cov = s.force_cov;
          continue;
        }
        double* point = nth == 0 ? builder.FingerContact(i, c.finger) : builder.SecondContactPoint(i, c.finger);
        double* force = nth == 0 ? builder.FingerForce(i, c.finger) : builder.SecondContactForce(i, c.finger);
        if (get(point, c2.data())) c.point_cov = Eigen::Matrix2d(c2);
        if (c.force && get(force, c2.data())) c.force_cov = Eigen::Matrix2d(c2);
      }
      if (seen[0] == 2) s.force_cov.reset();  // the sum's would need the cross-covariance
    } else if (builder.HasSecondContact(i) && s.contacts.size() == 2) {
      // Each contact's own; the net force's would need the cross-covariance of f and f2.
      s.contacts[0].point_cov = s.contact_cov;
      get(v.p2, c2.data());
      s.contacts[1].point_cov = Eigen::Matrix2d(c2);
      if (builder.HasForceVars(i)) {
        s.contacts[0].force_cov = s.force_cov;
        get(v.f2, c2.data());
        s.contacts[1].force_cov = Eigen::Matrix2d(c2);
        s.force_cov.reset();
      }
    }
  }
  return "ok";
}

int SolverLogLevel() {
  static const int level = [] {
    const char* v = std::getenv("PUSHGRAPH_SOLVER_LOG");
    return v == nullptr || *v == '\0' ? 0 : std::atoi(v);
  }();
  return level;
}

void LogSummary(const char* what, const ceres::Solver::Summary& summary) {
  if (SolverLogLevel() >= 1) std::cerr << "pushgraph " << what << ":\n" << summary.FullReport() << "\n";
}

ceres::Solver::Options SolverOptions(int max_iterations, double function_tolerance) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = function_tolerance;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = 1e-10;
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  if (SolverLogLevel() >= 2) {
    o.logging_type = ceres::PER_MINIMIZER_ITERATION;  // per-iteration trace, for tuning
    o.minimizer_progress_to_stdout = true;
  }
  return o;
}

}  // namespace pushgraph::graph::internal
