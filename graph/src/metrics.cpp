// ComputeMetrics (estimator.h): an estimate against ground truth by push/scoring.h's rule.
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/scoring.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <optional>

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

// Squared position and rotation errors of a pose.
struct PoseAccumulator {
  Accumulator position, rotation;
  void Add(const Eigen::Vector3d& e) {
    position.Add(e.head<2>().squaredNorm());
    rotation.Add(e.z() * e.z());
  }
};

std::optional<Eigen::Vector3d> PoseErrorAt(const std::vector<push::PoseSample>& truth, double t, const Pose2& pose) {
  Eigen::Vector3d g;
  if (!push::TruthPoseAt(truth, t, &g)) return std::nullopt;
  return push::PoseError(pose, g);
}

// Gauge-free NEES: covariance matrices here are well conditioned, LDLT is enough.
template <class Vector, class Matrix>
double Nees(const Vector& e, const Matrix& cov) {
  return e.dot(cov.ldlt().solve(e));
}

}  // namespace

std::map<std::string, double> ComputeMetrics(const push::Trajectory& traj,
                                             const std::vector<StateEstimate>& states) {
  std::map<std::string, double> m;
  if (!traj.ground_truth) return m;
  const push::Streams& gt = *traj.ground_truth;
  // Ground truth at the estimate's times, errors and moving rows: push/scoring.h's one rule.
  PoseAccumulator object, object_moving, finger;
  Accumulator contact, force, nees_object, nees_finger, nees_contact, nees_force;
  for (const StateEstimate& s : states) {
    if (const auto e = PoseErrorAt(gt.object_pose, s.t, s.object_pose)) {
      object.Add(*e);
      if (push::ObjectMovingAt(gt.object_pose, s.t)) object_moving.Add(*e);
      if (s.object_pose_cov) nees_object.Add(Nees(*e, *s.object_pose_cov));
    }
    if (const auto e = PoseErrorAt(gt.finger_pose, s.t, s.finger_pose)) {
      finger.Add(*e);
      if (s.finger_pose_cov) nees_finger.Add(Nees(*e, *s.finger_pose_cov));
    }
    Vec2 v;
    // Finger k >= 1's truth (null when absent).
    const auto truth_of = [&](int k) -> const push::FingerStreams* {
      if (k < 1 || k > static_cast<int>(traj.extra_fingers.size())) return nullptr;
      const auto& g = traj.extra_fingers[k - 1].ground_truth;
      return g ? &*g : nullptr;
    };
    // Every other finger's pose (two-finger pushes; the finger metrics pool the fingers).
    for (const FingerPoseEstimate& f : s.other_fingers) {
      const push::FingerStreams* g = truth_of(f.finger);
      if (g == nullptr) continue;
      if (const auto e = PoseErrorAt(g->finger_pose, s.t, f.pose)) {
        finger.Add(*e);
        if (f.pose_cov) nees_finger.Add(Nees(*e, *f.pose_cov));
      }
    }
    // Every contact against its finger's nearest true contact at this time; other fingers' forces
    // against theirs (finger 0's is `force`, below).
    std::vector<ContactEstimate> contacts = s.contacts;
    if (contacts.empty() && s.contact) contacts.push_back({0, *s.contact, std::nullopt, s.contact_cov, std::nullopt});
    for (const ContactEstimate& c : contacts) {
      const push::FingerStreams* g = truth_of(c.finger);
      if (c.finger != 0 && g == nullptr) continue;
      if (push::TruthContactNear(c.finger == 0 ? gt.contact_point : g->contact_point, s.t, c.point, &v)) {
        contact.Add((c.point - v).squaredNorm());
        if (c.point_cov) nees_contact.Add(Nees(Vec2(c.point - v), *c.point_cov));
      }
      if (c.finger != 0 && c.force && push::TruthForceAt(g->force, s.t, &v)) {
        force.Add((*c.force - v).squaredNorm());
        if (c.force_cov) nees_force.Add(Nees(Vec2(*c.force - v), *c.force_cov));
      }
    }
    if (s.force && push::TruthForceAt(gt.force, s.t, &v)) {
      const Vec2 e = *s.force - v;
      force.Add(e.squaredNorm());
      if (s.force_cov) nees_force.Add(Nees(e, *s.force_cov));
    }
  }
  object.position.Put(m, "object_position_rms");
  object.rotation.Put(m, "object_rotation_rms");
  object_moving.position.Put(m, "object_position_moving_rms");
  object_moving.rotation.Put(m, "object_rotation_moving_rms");
  finger.position.Put(m, "finger_position_rms");
  finger.rotation.Put(m, "finger_rotation_rms");
  contact.Put(m, "contact_rms");
  force.Put(m, "force_rms");
  nees_object.Put(m, "object_pose_nees", false);
  nees_finger.Put(m, "finger_pose_nees", false);
  nees_contact.Put(m, "contact_nees", false);
  nees_force.Put(m, "force_nees", false);

  // The raw measurements against the same ground truth.
  const push::Streams& measured = traj.measured;
  PoseAccumulator raw_object, raw_finger;
  Accumulator raw_contact, raw_force;
  for (const push::PoseSample& s : measured.object_pose) {
    if (const auto e = PoseErrorAt(gt.object_pose, s.t, s.pose)) raw_object.Add(*e);
  }
  for (const push::PoseSample& s : measured.finger_pose) {
    if (const auto e = PoseErrorAt(gt.finger_pose, s.t, s.pose)) raw_finger.Add(*e);
  }
  Vec2 v;
  for (const push::PointSample& s : measured.contact_point) {
    if (push::TruthContactNear(gt.contact_point, s.t, s.point, &v)) raw_contact.Add((s.point - v).squaredNorm());
  }
  for (const push::ForceSample& s : measured.force) {
    if (push::TruthForceAt(gt.force, s.t, &v)) raw_force.Add((s.force - v).squaredNorm());
  }
  raw_object.position.Put(m, "measured_object_position_rms");
  raw_object.rotation.Put(m, "measured_object_rotation_rms");
  raw_finger.position.Put(m, "measured_finger_position_rms");
  raw_finger.rotation.Put(m, "measured_finger_rotation_rms");
  raw_contact.Put(m, "measured_contact_rms");
  raw_force.Put(m, "measured_force_rms");
  return m;
}

}  // namespace pushgraph::graph
