#pragma once
// A pushing trajectory: the object and finger descriptions and time-stamped measurement
// streams (plus optional ground truth), as plain data. The simulator produces it, the
// estimator consumes it, and pushgraph::io reads and writes it as JSON
// ("pushgraph-trajectory-1", see docs/formats.md).
//
// Units: metres, radians, newtons, seconds. Poses and points in the world frame; `force` is the
// force the finger applies to the object, world frame. Every stream may be empty; samples are
// sorted by time (io's reader sorts and reports duplicates).
//
//   Trajectory traj = pushgraph::io::LoadTrajectoryJson("push.json");
//   for (const PoseSample& s : traj.measured.object_pose) { ... s.t, s.pose ... }
#include <pushgraph/push/errors.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/limit_surface/support.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::push {

/// Time stamps every reader and the estimator accept: |t| up to kMaxTimeStamp s (epoch time,
/// about 1.7e9 s, is fine), and no gap within or between streams longer than
/// max(kClockJumpSeconds, kClockJumpPeriods median periods) (a corrupted stamp, not a recording).
inline constexpr double kMaxTimeStamp = 1e11;
inline constexpr double kClockJumpSeconds = 10.0;
inline constexpr double kClockJumpPeriods = 1000.0;

using geometry::Vec2;

struct PoseSample {
  double t = 0.0;
  geometry::Pose2 pose;
};

struct PointSample {
  double t = 0.0;
  geometry::Vec2 point{0.0, 0.0};
};

struct ForceSample {
  double t = 0.0;
  geometry::Vec2 force{0.0, 0.0};  ///< applied by the finger to the object, world frame
};

/// The four streams of a push, each with its own clock.
struct Streams {
  std::vector<PoseSample> object_pose;
  std::vector<PoseSample> finger_pose;
  std::vector<PointSample> contact_point;
  std::vector<ForceSample> force;
};

/// The pushed object, the one description every spec and file embeds (PushingSpec, PushPlan,
/// Trajectory, the evaluation's object models): its footprint is also its support region.
struct ObjectDescription {
  geometry::Shape shape;
  double mass = 0.0;                  ///< kg
  double mu_surface = 0.0;            ///< object-table friction coefficient
  limit_surface::Pressure pressure;   ///< support pressure; default uniform (files: uniform only)
  double gravity = limit_surface::kStandardGravity;  ///< m/s^2
};

/// The finger (pusher), embedded likewise.
struct FingerDescription {
  geometry::Shape shape;
  double mu_contact = 0.0;  ///< finger-object friction coefficient
};

/// The object's support for the limit-surface module (the one place its fields are copied).
limit_surface::SupportSpec SupportOf(const ObjectDescription& object);

/// Standard deviations of the measurement noise (per axis), when known: simulated pushes and
/// recordings with added noise carry them so an estimator can weight its measurement factors
/// to match (graph::ApplyMeasurementSigmas). 0 means noise-free.
struct MeasurementSigmas {
  double object_trans = 0.0;  ///< m
  double object_rot = 0.0;    ///< rad
  double finger_trans = 0.0;  ///< m
  double finger_rot = 0.0;    ///< rad
  double contact = 0.0;       ///< m
  double force = 0.0;         ///< N
};

/// The streams of one finger of a push with several fingers.
struct FingerStreams {
  std::vector<PoseSample> finger_pose;
  std::vector<PointSample> contact_point;  ///< may repeat a time: one row per contact
  std::vector<ForceSample> force;          ///< the finger's net force on the object
};

/// Finger 1, 2, ... of a push with several fingers (finger 0 is Trajectory::finger, its streams
/// in Trajectory::measured): its description and streams.
struct ExtraFinger {
  FingerDescription finger;
  FingerStreams measured;
  std::optional<FingerStreams> ground_truth;  ///< present when the trajectory's is
};

struct Trajectory {
  ObjectDescription object;
  FingerDescription finger;   ///< finger 0
  /// The object's stream and finger 0's. contact_point may repeat a time (a finger touching the
  /// object at several points, e.g. wedged in a notch: one row per contact).
  Streams measured;
  std::optional<Streams> ground_truth;
  std::optional<MeasurementSigmas> measurement_sigmas;
  std::vector<ExtraFinger> extra_fingers;  ///< empty for the usual single-finger push
};

/// 1 + extra fingers.
inline int FingerCount(const Trajectory& t) { return 1 + static_cast<int>(t.extra_fingers.size()); }

/// Whether a contact stream holds several contacts at one time (a multi-contact push).
inline bool HasRepeatedTimes(const std::vector<PointSample>& samples) {
  for (std::size_t i = 1; i < samples.size(); ++i)
    if (samples[i].t == samples[i - 1].t) return true;
  return false;
}

/// A time-sorted, non-empty stream's value at t by linear interpolation, clamped to the first
/// and last samples outside them (initial guesses, plot positions).
template <class Sample, class Get>
auto StreamValueClamped(const std::vector<Sample>& samples, double t, Get get) -> decltype(get(samples[0])) {
  const auto it = std::lower_bound(samples.begin(), samples.end(), t,
                                   [](const Sample& s, double tt) { return s.t < tt; });
  if (it == samples.begin()) return get(samples.front());
  if (it == samples.end()) return get(samples.back());
  const Sample& a = *(it - 1);
  const Sample& b = *it;  // a.t < t <= b.t
  const double w = (t - a.t) / (b.t - a.t);
  return get(a) + w * (get(b) - get(a));
}

/// A pose stream [first, last) (time-sorted, non-empty) at t, clamped like StreamValueClamped,
/// with theta interpolated along the shorter arc.
template <class It>
geometry::Pose2 PoseAtClamped(It first, It last, double t) {
  const auto it = std::lower_bound(first, last, t, [](const PoseSample& s, double tt) { return s.t < tt; });
  if (it == first) return first->pose;
  if (it == last) return (last - 1)->pose;
  const geometry::Pose2& a = (it - 1)->pose;
  const geometry::Pose2& b = it->pose;
  const double w = (t - (it - 1)->t) / (it->t - (it - 1)->t);
  return {a.x + w * (b.x - a.x), a.y + w * (b.y - a.y), a.theta + w * geometry::WrapAngle(b.theta - a.theta)};
}

/// A time-sorted stream's value at t (e.g. ground truth at an estimate's time): the sample at t
/// (within 1e-9 s), or the linear interpolation of its two neighbours when they are at most
/// max_gap apart; false outside the stream or across a larger gap. `get` maps a sample to the
/// interpolated quantity linearly (for poses, TruthPoseAt in scoring.h takes theta along the shorter arc).
///
///   Eigen::Vector3d x;
///   if (StreamValueAt(gt.object_pose, t, 0.1, [](const PoseSample& s) { return s.pose.vector(); }, &x)) ...
template <class Sample, class Get>
bool StreamValueAt(const std::vector<Sample>& samples, double t, double max_gap, Get get,
                   decltype(get(samples[0]))* out) {
  if (samples.empty() || t < samples.front().t - 1e-9 || t > samples.back().t + 1e-9) return false;
  const auto it = std::lower_bound(samples.begin(), samples.end(), t - 1e-9,
                                   [](const Sample& a, double tt) { return a.t < tt; });
  if (it == samples.end()) return false;  // unreachable: t <= back().t + 1e-9
  if (std::abs(it->t - t) <= 1e-9) {
    *out = get(*it);
    return true;
  }
  if (it == samples.begin()) return false;
  const Sample& a = *(it - 1);
  const Sample& b = *it;
  if (b.t - a.t > max_gap) return false;
  const double w = (t - a.t) / (b.t - a.t);
  *out = get(a) + w * (get(b) - get(a));
  return true;
}

}  // namespace pushgraph::push
