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
// Two front ends share the smoother:
// - IncrementalEstimator replays a recorded trajectory (the tool's --mode incremental):
//
//     graph::IncrementalEstimator inc(traj, graph::Model::kQs, cfg);
//     while (!inc.Done()) { inc.Update(); use(inc.LatestState()); }
//     graph::EstimationResult r = inc.Finish();
//
// - OnlineEstimator takes measurements one at a time as a robot's sensors deliver them:
//
//     push::Trajectory setup;  // object and finger shapes, mass, frictions; no samples
//     graph::OnlineEstimator online(setup, graph::Model::kQs, cfg, {/*contact_point=*/false, /*force=*/true});
//     online.AddObjectPose(t, pose);    // from the sensor callbacks, each stream in time order
//     online.AddFingerPose(t, pose);
//     online.AddForce(t, force);
//     if (online.UpdateDue()) { online.Update(); use(online.LatestState()); }  // in the loop
//     graph::EstimationResult r = online.Finish();
#include <pushgraph/graph/estimator.h>

#include <ceres/cost_function.h>

#include <Eigen/Core>

#include <cmath>
#include <memory>
#include <string>
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

/// Which measurement streams an online run will receive. They shape the graph as the
/// recorded streams do in batch: contact is gated on the contact stream if there is one, else
/// on the force stream (force above contact_force_threshold, once a contact above its noise was seen), else always on; and the
/// limit-surface load factor runs (limit_surface_load "auto") only when no force will arrive.
struct OnlineStreams {
  bool contact_point = false;  ///< a tactile sensor reports contact points
  bool force = true;           ///< a force/torque sensor reports the contact force
  /// How far (s, in the samples' time) a stream may lag the newest sample of any stream and
  /// still be waited for by Update(); a stream further behind (also at least 1.5 k object
  /// periods, except with incremental_update_every_steps) counts as silent: an occluded camera,
  /// a tactile sensor out of contact. For updates at the sensor rate set it below the slowest
  /// stream's period (else every update waits for the next camera frame); a frame that then
  /// arrives after the update covering its time is dropped (DroppedLateSamples).
  double max_latency = 0.2;
};

class IncrementalEstimator {
 public:
  IncrementalEstimator(const push::Trajectory& trajectory, Model model,
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

/// The fixed-lag smoother fed online, one measurement at a time (the paper's incremental
/// inference on a running robot). Each stream must arrive in strictly increasing time, with
/// finite values (else GraphError, naming the stream, the sample's index and times). Streams may
/// lag one another (a camera tracker is often slower than a force sensor): Update() solves only
/// up to where every live stream has reported. A sample at or before the last update's time
/// would belong to steps already solved: it is dropped, Add* returns false and
/// DroppedLateSamples() counts it. On the same samples and update times the estimate is
/// IncrementalEstimator's (up to contact gating, which here sees only past samples).
class OnlineEstimator {
 public:
  /// `setup` gives the object, the finger (and any others in extra_fingers) and,
  /// when the trajectory has them, mass and frictions; its measured streams must be empty. Its ground truth, if any, is only used
  /// for Finish()'s metrics (simulation and testing).
  OnlineEstimator(const push::Trajectory& setup, Model model, const EstimatorConfig& config = {},
                  const OnlineStreams& streams = {});
  ~OnlineEstimator();
  OnlineEstimator(const OnlineEstimator&) = delete;
  OnlineEstimator& operator=(const OnlineEstimator&) = delete;

  /// Each returns false when the sample came too late (at or before the last update) and was dropped;
  /// AddContactPoint also once the contact check left the stream out (its points off the finger:
  /// another frame or an offset; Finish() says so).
  /// Also false for a sample no sensor of this push could have measured, left out as a sensor
  /// fault (DroppedFaultySamples() counts them; Finish()'s warnings name the first of each kind):
  /// an object pose far from the five before it (a tracker glitch: more than max(1 cm, 10 sigmas)
  /// or max(0.3 rad, 10 sigmas) beyond their motion and the finger's; three such poses in a row
  /// that agree are a step of the tracker, taken from the third); a contact row farther from the
  /// finger than ContactFaultBound (max(2 cm, 10 sigmas)), once the contact check found its stream
  /// on the finger; a force as AddForce says. A position beyond 1e6 m or a force beyond 1e9 N is a
  /// GraphError naming the sample (not taken; the estimator goes on).
  /// Without a finger index: finger 0 (Trajectory::finger).
  bool AddObjectPose(double t, const geometry::Pose2& pose);
  bool AddFingerPose(double t, const geometry::Pose2& pose);
  bool AddContactPoint(double t, const geometry::Vec2& point);
  /// Also false for a force no sensor of this push could have measured (above 50 times the larger
  /// of the recent forces' 95th percentile and mu m g, and above 1 N): a sensor fault, left out.
  bool AddForce(double t, const geometry::Vec2& force);
  /// Finger `finger`'s samples: 0 is Trajectory::finger, k >= 1 the setup's extra_fingers[k - 1]
  /// (a push with several fingers; each has the kinds of sensors OnlineStreams declares). Every
  /// finger's pose is needed by the first update; each finger's contact stream has one or two
  /// rows per time (two: the finger touches at two points). A finger the setup does not have
  /// is an error naming it.
  bool AddFingerPose(double t, int finger, const geometry::Pose2& pose);
  bool AddContactPoint(double t, int finger, const geometry::Vec2& point);
  bool AddForce(double t, int finger, const geometry::Vec2& force);
  int DroppedLateSamples() const;
  int DroppedFaultySamples() const;
  /// What the estimator found wrong with its setup so far, as sentences (Finish()'s warnings
  /// repeat them). With `diagnostics` on, the updates check the object's shape against the
  /// contacts as `Estimate` does (RegisterShape on the samples so far, every 0.1 s of data until
  /// the contacts can judge it, then each time the data has doubled). A shape that fits at a
  /// unit's scale alone (a CAD file in millimetres) is read in that unit from that update on,
  /// every step so far solved again, unless align_shape is "off". Any other misfit (a shape
  /// turned or shifted off the tracker's frame) is named with the placement the contacts prefer,
  /// not applied: the steps already solved keep the shape they were solved with.
  const std::vector<std::string>& Warnings() const;

  /// True once incremental_update_every object measurements up to the settled time (see
  /// Update) arrived since the last update, or, while the object stream is silent (occlusion),
  /// once the settled time ran that many object periods (1.5 x) past it: the schedule
  /// IncrementalEstimator follows.
  bool UpdateDue() const;
  /// Turns the samples up to `until` into steps and solves the window; later samples stay
  /// buffered. Default `until`: the newest time every live stream has reached (a stream is live
  /// when its newest sample is within OnlineStreams::max_latency, and 1.5 k object periods, of the
  /// newest sample of any stream, so an occluded camera or a silent tactile sensor does not
  /// stall the others). The first update needs an object and a
  /// finger pose. Returns the wall time of the update (s); 0 when there was nothing new.
  double Update(double until = INFINITY);
  /// The newest state of the window (after at least one Update()).
  StateEstimate LatestState() const;
  int WindowSteps() const;  ///< steps currently in the window
  int StepsAdded() const;   ///< steps solved so far
  /// Updates with whatever is still buffered, then computes the last window's covariances and
  /// returns every step's estimate (metrics when the setup has ground truth). Call once.
  EstimationResult Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::graph
