// ComputeMetrics (estimator.h): an estimate against ground truth by push/scoring.h's rule.
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/scoring.h>

#include <Eigen/Cholesky>

#include <cmath>

namespace pushgraph::graph {
namespace {

struct Accumulator {
  double sum = 0.0;
  int n = 0;
  void Add(double sq) { sum += sq; ++n; }
  void Put(std::map<std::string, double>& m, const std::string& key, bool rms = true) const {
    if (n > 0) m[key] = rms ? std::sqrt(sum / n) : sum / n;
  }
};

}  // namespace

std::map<std::string, double> ComputeMetrics(const push::Trajectory& traj,
                                             const std::vector<StateEstimate>& states) {
  std::map<std::string, double> m;
  if (!traj.ground_truth) return m;
  const auto& gt = *traj.ground_truth;
  // Ground truth at the estimate's times, errors and moving rows: push/scoring.h's one rule.
  Accumulator op, orot, op_moving, orot_moving, fp, frot, cp, fo, nees_o, nees_f, nees_c, nees_force;
  // Gauge-free NEES: covariance matrices here are well conditioned, LDLT is enough.
  auto nees = [](const auto& e, const auto& cov) { return e.dot(cov.ldlt().solve(e)); };
  for (const StateEstimate& s : states) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.object_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.object_pose, g);
      op.Add(e.head<2>().squaredNorm());
      orot.Add(e.z() * e.z());
      if (push::ObjectMovingAt(gt.object_pose, s.t)) {
        op_moving.Add(e.head<2>().squaredNorm());
        orot_moving.Add(e.z() * e.z());
      }
      if (s.object_pose_cov) nees_o.Add(nees(e, *s.object_pose_cov));
    }
    if (push::TruthPoseAt(gt.finger_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.finger_pose, g);
      fp.Add(e.head<2>().squaredNorm());
      frot.Add(e.z() * e.z());
      if (s.finger_pose_cov) nees_f.Add(nees(e, *s.finger_pose_cov));
    }
    Vec2 v;
    if (s.contact && push::TruthPointAt(gt.contact_point, s.t, &v)) {
      const Vec2 e = *s.contact - v;
      cp.Add(e.squaredNorm());
      if (s.contact_cov) nees_c.Add(nees(e, *s.contact_cov));
    }
    if (s.force && push::TruthForceAt(gt.force, s.t, &v)) {
      const Vec2 e = *s.force - v;
      fo.Add(e.squaredNorm());
      if (s.force_cov) nees_force.Add(nees(e, *s.force_cov));
    }
  }
  op.Put(m, "object_position_rms");
  orot.Put(m, "object_rotation_rms");
  op_moving.Put(m, "object_position_moving_rms");
  orot_moving.Put(m, "object_rotation_moving_rms");
  fp.Put(m, "finger_position_rms");
  frot.Put(m, "finger_rotation_rms");
  cp.Put(m, "contact_rms");
  fo.Put(m, "force_rms");
  nees_o.Put(m, "object_pose_nees", false);
  nees_f.Put(m, "finger_pose_nees", false);
  nees_c.Put(m, "contact_nees", false);
  nees_force.Put(m, "force_nees", false);
  // The raw measurements against the same ground truth.
  Accumulator mop, morot, mfp, mfrot, mcp, mfo;
  const auto& meas = traj.measured;
  for (const auto& s : meas.object_pose) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.object_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.pose, g);
      mop.Add(e.head<2>().squaredNorm());
      morot.Add(e.z() * e.z());
    }
  }
  for (const auto& s : meas.finger_pose) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.finger_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.pose, g);
      mfp.Add(e.head<2>().squaredNorm());
      mfrot.Add(e.z() * e.z());
    }
  }
  for (const auto& s : meas.contact_point) {
    Vec2 v;
    if (push::TruthPointAt(gt.contact_point, s.t, &v)) mcp.Add((s.point - v).squaredNorm());
  }
  for (const auto& s : meas.force) {
    Vec2 v;
    if (push::TruthForceAt(gt.force, s.t, &v)) mfo.Add((s.force - v).squaredNorm());
  }
  mop.Put(m, "measured_object_position_rms");
  morot.Put(m, "measured_object_rotation_rms");
  mfp.Put(m, "measured_finger_position_rms");
  mfrot.Put(m, "measured_finger_rotation_rms");
  mcp.Put(m, "measured_contact_rms");
  mfo.Put(m, "measured_force_rms");
  return m;
}

}  // namespace pushgraph::graph
