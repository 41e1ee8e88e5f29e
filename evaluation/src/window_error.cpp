#include <pushgraph/evaluation/window_error.h>
#include <pushgraph/push/scoring.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pushgraph::evaluation {

double MeanObjectPositionError(const push::Trajectory& traj, const graph::EstimationResult& result, double t0,
                               double t1) {
  if (!traj.ground_truth) return std::numeric_limits<double>::quiet_NaN();
  double sum = 0.0;
  int count = 0;
  for (const graph::StateEstimate& s : result.states) {
    Eigen::Vector3d truth;
    if (s.t < t0 || s.t > t1 || !push::TruthPoseAt(traj.ground_truth->object_pose, s.t, &truth)) continue;
    sum += push::PoseError(s.object_pose, truth).head<2>().norm();
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

double MeanHeldRawObjectPositionError(const push::Trajectory& traj, double t0, double t1) {
  if (!traj.ground_truth) return std::numeric_limits<double>::quiet_NaN();
  const auto& measured = traj.measured.object_pose;
  double sum = 0.0;
  int count = 0;
  for (const push::PoseSample& truth : traj.ground_truth->object_pose) {
    if (truth.t < t0 || truth.t > t1) continue;
    auto it = std::upper_bound(measured.begin(), measured.end(), truth.t,
                               [](double t, const push::PoseSample& a) { return t < a.t; });
    if (it == measured.begin()) continue;
    sum += ((it - 1)->pose.translation() - truth.pose.translation()).norm();
    ++count;
  }
  return count > 0 ? sum / count : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace pushgraph::evaluation
