// Sufficient statistics of one estimate against ground truth (Lambert et al. 2019, Sec. V:
// RMS errors, marginal sigmas, NEES with its 95% chi-square interval), by push/scoring.h's rule.
#include "internal.h"

#include <pushgraph/push/scoring.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <optional>

namespace pushgraph::evaluation::internal {
namespace {

using geometry::Vec2;

constexpr double kDirectionMinForce = 0.25;  // N: force directions below this are not compared

// Two-sided 95% interval of a chi-square variable with 2 and 3 degrees of freedom
// (quantiles 0.025 and 0.975; e.g. Bar-Shalom, Li, Kirubarajan 2001, Table 5.2 style values).
constexpr double kChi2Lo[4] = {0.0, 0.000982, 0.05064, 0.2158};
constexpr double kChi2Hi[4] = {0.0, 5.0239, 7.3778, 9.3484};

template <int N>
double NeesOf(const Eigen::Matrix<double, N, 1>& e, const Eigen::Matrix<double, N, N>& cov) {
  return e.dot(cov.ldlt().solve(e));
}

double SignedAngle(const Vec2& a, const Vec2& b) {  // from b to a
  return std::atan2(b.x() * a.y() - b.y() * a.x(), b.dot(a));
}


}  // namespace

void StatSink::Error(const std::string& key, double e) {
  Add(key + "/n", 1.0);
  Add(key + "/sum", e);
  Add(key + "/abs", std::abs(e));
  Add(key + "/sq", e * e);
}

void StatSink::Variance(const std::string& key, double var) {
  Add(key + "/var", var);
  Add(key + "/nvar", 1.0);
}

void StatSink::Nees(const std::string& key, double nees, int dim) {
  Add(key + "/nees", nees);
  Add(key + "/nees_n", 1.0);
  Add(key + "/nees_in", (nees >= kChi2Lo[dim] && nees <= kChi2Hi[dim]) ? 1.0 : 0.0);
  (*stats_)[key + "/dim"] = dim;  // constant: aggregated as max
}

void StatSink::Max(const std::string& key, double v) {
  auto [it, inserted] = stats_->emplace(key, v);
  if (!inserted) it->second = std::max(it->second, v);
}

void AccumulateRun(const push::Trajectory& traj, const graph::EstimationResult& r, const std::string& prefix,
                   const Window& occluded, StatSink& sink) {
  const push::Streams& gt = *traj.ground_truth;
  for (const graph::StateEstimate& s : r.states) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.object_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.object_pose, g);
      const double ep = e.head<2>().norm(), er = std::abs(e.z());
      sink.Error(prefix + "/object_position", ep);
      sink.Error(prefix + "/object_rotation", er);
      const bool moving = push::ObjectMovingAt(gt.object_pose, s.t);
      if (moving) {
        sink.Error(prefix + "/object_position_moving", ep);
        sink.Error(prefix + "/object_rotation_moving", er);
      }
      if (occluded.Contains(s.t)) {
        sink.Error(prefix + "/object_position_occluded", ep);
        sink.Error(prefix + "/object_rotation_occluded", er);
      } else if (occluded.t1 >= occluded.t0) {
        sink.Error(prefix + "/object_position_visible", ep);
        sink.Error(prefix + "/object_rotation_visible", er);
      }
      if (s.object_pose_cov) {
        const Eigen::Matrix3d& P = *s.object_pose_cov;
        sink.Variance(prefix + "/object_position", P(0, 0) + P(1, 1));
        sink.Variance(prefix + "/object_rotation", P(2, 2));
        if (moving) {
          sink.Variance(prefix + "/object_position_moving", P(0, 0) + P(1, 1));
          sink.Variance(prefix + "/object_rotation_moving", P(2, 2));
        }
        sink.Nees(prefix + "/object_pose", NeesOf<3>(e, P), 3);
      }
    }
    // Every finger's position (fingers 1, 2, ... against their own ground truth).
    auto finger_position = [&](const std::vector<push::PoseSample>& truth, const geometry::Pose2& pose,
                               const std::optional<Eigen::Matrix3d>& cov) {
      if (!push::TruthPoseAt(truth, s.t, &g)) return;
      const Eigen::Vector2d e(pose.x - g.x(), pose.y - g.y());
      sink.Error(prefix + "/finger_position", e.norm());
      if (cov) {
        // Position block only: the finger's angle is not measured meaningfully (pinned).
        const Eigen::Matrix2d P = cov->topLeftCorner<2, 2>();
        sink.Variance(prefix + "/finger_position", P.trace());
        sink.Nees(prefix + "/finger_position", NeesOf<2>(e, P), 2);
      }
    };
    finger_position(gt.finger_pose, s.finger_pose, s.finger_pose_cov);
    for (const graph::FingerPoseEstimate& f : s.other_fingers)
      if (f.finger >= 1 && f.finger <= static_cast<int>(traj.extra_fingers.size()) && traj.extra_fingers[f.finger - 1].ground_truth)
        finger_position(traj.extra_fingers[f.finger - 1].ground_truth->finger_pose, f.pose, f.pose_cov);
    Vec2 v;
    // Every estimated contact against its finger's nearest true contact at that time (several
    // contacts: a wedged finger, a flat pusher, two fingers).
    std::vector<graph::ContactEstimate> contacts = s.contacts;
    if (contacts.empty() && s.contact) contacts.push_back({0, *s.contact, s.force, s.contact_cov, s.force_cov});
    for (const graph::ContactEstimate& c : contacts) {
      const bool own = c.finger == 0;
      if (!own && (c.finger > static_cast<int>(traj.extra_fingers.size()) || !traj.extra_fingers[c.finger - 1].ground_truth))
        continue;
      const auto& truth = own ? gt.contact_point : traj.extra_fingers[c.finger - 1].ground_truth->contact_point;
      if (!push::TruthContactNear(truth, s.t, c.point, &v)) continue;
      const Eigen::Vector2d e = c.point - v;
      sink.Error(prefix + "/contact", e.norm());
      if (c.point_cov) {
        sink.Variance(prefix + "/contact", c.point_cov->trace());
        sink.Nees(prefix + "/contact", NeesOf<2>(e, *c.point_cov), 2);
      }
      // Another finger's own force (finger 0's is `force` below); one touching at two points
      // measures their sum, which has no covariance of its own: its first contact's is not it.
      const bool its_only = std::count_if(contacts.begin(), contacts.end(),
                                          [&](const graph::ContactEstimate& o) { return o.finger == c.finger; }) == 1;
      if (!own && its_only && c.force && push::TruthForceAt(traj.extra_fingers[c.finger - 1].ground_truth->force, s.t, &v)) {
        const Eigen::Vector2d ef = *c.force - v;
        sink.Error(prefix + "/force", ef.norm());
        if (c.force_cov) {
          sink.Variance(prefix + "/force", c.force_cov->trace());
          sink.Nees(prefix + "/force", NeesOf<2>(ef, *c.force_cov), 2);
        }
      }
    }
    if (s.force && push::TruthForceAt(gt.force, s.t, &v)) {
      const Eigen::Vector2d e = *s.force - v;
      sink.Error(prefix + "/force", e.norm());
      sink.Error(prefix + "/force_magnitude", s.force->norm() - v.norm());
      if (v.norm() >= kDirectionMinForce) sink.Error(prefix + "/force_direction", SignedAngle(*s.force, v) * 180.0 / M_PI);
      if (s.force_cov) {
        sink.Variance(prefix + "/force", s.force_cov->trace());
        sink.Nees(prefix + "/force", NeesOf<2>(e, *s.force_cov), 2);
      }
    }
  }
  const graph::SolverStats& st = r.solver;
  sink.Add(prefix + "/time/sum", st.time_s);
  sink.Add(prefix + "/time/n", 1.0);
  sink.Max(prefix + "/time/max", st.time_s);
  sink.Add(prefix + "/steps/sum", static_cast<double>(r.states.size()));
  if (r.mode == graph::Mode::kIncremental && st.updates > 0) {
    sink.Add(prefix + "/update_time/sum", st.mean_update_time_s * st.updates);
    sink.Add(prefix + "/update_time/n", st.updates);
    sink.Max(prefix + "/update_time/max", st.max_update_time_s);
  }
}

// The raw measurements against the same ground truth.
void AccumulateRaw(const push::Trajectory& traj, const std::string& prefix, StatSink& sink) {
  const push::Streams& gt = *traj.ground_truth;
  const push::Streams& m = traj.measured;
  for (const push::PoseSample& s : m.object_pose) {
    Eigen::Vector3d g;
    if (!push::TruthPoseAt(gt.object_pose, s.t, &g)) continue;
    const double ep = std::hypot(s.pose.x - g.x(), s.pose.y - g.y());
    const double er = std::abs(geometry::WrapAngle(s.pose.theta - g.z()));
    sink.Error(prefix + "/object_position", ep);
    sink.Error(prefix + "/object_rotation", er);
    if (push::ObjectMovingAt(gt.object_pose, s.t)) {
      sink.Error(prefix + "/object_position_moving", ep);
      sink.Error(prefix + "/object_rotation_moving", er);
    }
  }
  auto finger_positions = [&](const std::vector<push::PoseSample>& measured, const std::vector<push::PoseSample>& truth) {
    for (const push::PoseSample& s : measured) {
      Eigen::Vector3d g;
      if (push::TruthPoseAt(truth, s.t, &g)) sink.Error(prefix + "/finger_position", std::hypot(s.pose.x - g.x(), s.pose.y - g.y()));
    }
  };
  finger_positions(m.finger_pose, gt.finger_pose);
  for (const push::ExtraFinger& f : traj.extra_fingers)
    if (f.ground_truth) finger_positions(f.measured.finger_pose, f.ground_truth->finger_pose);
  // Every finger's contact rows, each against its finger's nearest true contact.
  auto contacts = [&](const std::vector<push::PointSample>& measured, const std::vector<push::PointSample>& truth) {
    for (const push::PointSample& s : measured) {
      Vec2 v;
      if (push::TruthContactNear(truth, s.t, s.point, &v)) sink.Error(prefix + "/contact", (s.point - v).norm());
    }
  };
  contacts(m.contact_point, gt.contact_point);
  for (const push::ExtraFinger& f : traj.extra_fingers)
    if (f.ground_truth) contacts(f.measured.contact_point, f.ground_truth->contact_point);
  for (const push::ForceSample& s : m.force) {
    Vec2 v;
    if (!push::TruthForceAt(gt.force, s.t, &v)) continue;
    sink.Error(prefix + "/force", (s.force - v).norm());
    sink.Error(prefix + "/force_magnitude", s.force.norm() - v.norm());
    if (v.norm() >= kDirectionMinForce) sink.Error(prefix + "/force_direction", SignedAngle(s.force, v) * 180.0 / M_PI);
  }
  // The other fingers' force rows (their estimates count in "force" too).
  for (const push::ExtraFinger& f : traj.extra_fingers) {
    if (!f.ground_truth) continue;
    for (const push::ForceSample& s : f.measured.force) {
      Vec2 v;
      if (push::TruthForceAt(f.ground_truth->force, s.t, &v)) sink.Error(prefix + "/force", (s.force - v).norm());
    }
  }
}


}  // namespace pushgraph::evaluation::internal
