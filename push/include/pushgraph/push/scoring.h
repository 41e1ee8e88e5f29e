#pragma once
// The one rule by which estimates are scored against ground truth: graph::ComputeMetrics (the
// RESULT.json metrics), the evaluation's statistics and tables, the pictures' error panels and
// the demo all use it.
//
// - Ground truth at a time t: the sample at t, or the linear interpolation of its two
//   neighbours when they are at most kTruthMaxGap apart (theta linearly: truth is sampled far
//   faster than it turns); no value outside the stream or across a larger gap (occlusion
//   windows of a recording are not bridged).
// - Pose errors: position difference and the wrapped angle difference.
// - "Moving" object rows (the paper scores the object while it moves): the truth's speed over
//   +-10 ms is above kMovingSpeed or its angular speed above kMovingAngularSpeed.
//
//   Eigen::Vector3d truth;
//   if (push::TruthPoseAt(gt.object_pose, s.t, &truth)) {
//     const Eigen::Vector3d e = push::PoseError(s.object_pose, truth);   // x, y, wrapped theta
//     bool moving = push::ObjectMovingAt(gt.object_pose, s.t);
//   }
#include <pushgraph/push/trajectory.h>

#include <Eigen/Core>

#include <vector>

namespace pushgraph::push {

inline constexpr double kTruthMaxGap = 0.1;          ///< s
inline constexpr double kMovingSpeed = 2e-3;         ///< m/s (as io::MitReadOptions::moving_speed)
inline constexpr double kMovingAngularSpeed = 0.02;  ///< rad/s

/// Ground truth at t by the rule above: (x, y, theta), a point, a force.
bool TruthPoseAt(const std::vector<PoseSample>& truth, double t, Eigen::Vector3d* pose);
bool TruthPointAt(const std::vector<PointSample>& truth, double t, Vec2* point);
bool TruthForceAt(const std::vector<ForceSample>& truth, double t, Vec2* force);
/// The true contact of a point estimated or measured at t: where the truth has several rows at t
/// (several contacts at once), the one nearest `point`; else TruthPointAt.
bool TruthContactNear(const std::vector<PointSample>& truth, double t, const Vec2& point, Vec2* contact);

/// (x, y, theta) error of an estimate against a truth pose, theta wrapped to (-pi, pi].
Eigen::Vector3d PoseError(const geometry::Pose2& estimate, const Eigen::Vector3d& truth);

/// Whether the object moves at t (see above); false where the truth has no value near t.
bool ObjectMovingAt(const std::vector<PoseSample>& truth, double t);

}  // namespace pushgraph::push
