#pragma once
// Fixed-lag smoothing of a pushing trajectory (the incremental mode): measurements are taken in
// time order; every k = config.incremental_update_every object measurements (and at least as
// often in time while the object stream is occluded) the new steps join the window, initialized
// from the measurements received so far, and the window is re-solved (Ceres LM, warm-started;
// for QS and the baseline first with the new steps' kinematic factors, then with their force
// variables and quasi-static factors, like the batch solver's staged start). Steps older than incremental_window object
// measurement periods leave the window: their factors are linearized at the current estimate
// and Schur-complemented onto the states they connect to, which then carry a Gaussian
// MarginalPrior (a sliding-window filter / fixed-lag smoother in the information form). The
// window stays bounded, so the cost of an update does not grow with the trajectory.
// A leaving state keeps its estimate and the marginal covariance of the window it leaves.
//
//   graph::IncrementalEstimator inc(traj, graph::Model::kQs, cfg);
//   while (!inc.Done()) { inc.Update(); use(inc.LatestState()); }
//   graph::EstimationResult r = inc.Finish();
#include <pushgraph/graph/estimator.h>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include <memory>
#include <vector>

namespace pushgraph::graph {

/// Gaussian prior from marginalization, on a list of parameter blocks (chart coordinates):
/// r = S (x - x_bar) + r0, so that 1/2 |r|^2 = 1/2 dx^T H dx + b^T dx + const with H = S^T S
/// and b = S^T r0 (the Schur complement of the removed states).
class MarginalPriorFactor : public ceres::CostFunction {
 public:
  MarginalPriorFactor(std::vector<int> block_sizes, Eigen::VectorXd x_bar, Eigen::MatrixXd S,
                      Eigen::VectorXd r0);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::VectorXd x_bar_, r0_;
  Eigen::MatrixXd S_;
};

class IncrementalEstimator {
 public:
  IncrementalEstimator(const limit_surface::Trajectory& trajectory, Model model,
                       const EstimatorConfig& config = {});
  ~IncrementalEstimator();
  IncrementalEstimator(const IncrementalEstimator&) = delete;
  IncrementalEstimator& operator=(const IncrementalEstimator&) = delete;

  bool Done() const;
  /// Adds the measurements up to the next update time, solves the window, marginalizes the
  /// states leaving it. Returns the wall time of this update (s).
  double Update();
  /// The newest state of the window (after at least one Update()).
  StateEstimate LatestState() const;
  int WindowSteps() const;   ///< steps currently in the window
  int StepsAdded() const;    ///< steps added so far
  int TotalSteps() const;
  /// Covariances of the remaining window, the full result and its metrics. Call once, after Done().
  EstimationResult Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::graph
