#pragma once
// Delivering a recorded trajectory to graph::OnlineEstimator one sample at a time, as a robot's
// sensor callbacks would (the online tests and benchmark).
//
//   for (const Arrival& a : ArrivalOrder(traj, /*object_delay=*/0.06)) Deliver(a, traj, online);
#include <pushgraph/graph/incremental.h>
#include <pushgraph/push/trajectory.h>

#include <algorithm>
#include <vector>

namespace pushgraph::graph::testing {

/// One recorded sample: its time stamp t, when it reaches the estimator (at), its stream
/// (0 object pose, 1 finger pose, 2 contact point, 3 force; 3 k + 1 .. 3 k + 3 finger k's pose,
/// contact point and force in a push with several fingers) and its index in that stream.
struct Arrival {
  double t = 0.0, at = 0.0;
  int stream = 0;
  std::size_t index = 0;
};

/// Every measured sample of `t` in arrival order (stable: streams in the order above at equal
/// times); object poses arrive `object_delay` s after their time stamp, the others at it.
inline std::vector<Arrival> ArrivalOrder(const push::Trajectory& t, double object_delay = 0.0) {
  std::vector<Arrival> out;
  const auto& m = t.measured;
  for (std::size_t i = 0; i < m.object_pose.size(); ++i) out.push_back({m.object_pose[i].t, m.object_pose[i].t + object_delay, 0, i});
  for (std::size_t i = 0; i < m.finger_pose.size(); ++i) out.push_back({m.finger_pose[i].t, m.finger_pose[i].t, 1, i});
  for (std::size_t i = 0; i < m.contact_point.size(); ++i) out.push_back({m.contact_point[i].t, m.contact_point[i].t, 2, i});
  for (std::size_t i = 0; i < m.force.size(); ++i) out.push_back({m.force[i].t, m.force[i].t, 3, i});
  for (std::size_t k = 1; k <= t.extra_fingers.size(); ++k) {
    const push::FingerStreams& f = t.extra_fingers[k - 1].measured;
    const int s = 3 * static_cast<int>(k);
    for (std::size_t i = 0; i < f.finger_pose.size(); ++i) out.push_back({f.finger_pose[i].t, f.finger_pose[i].t, s + 1, i});
    for (std::size_t i = 0; i < f.contact_point.size(); ++i) out.push_back({f.contact_point[i].t, f.contact_point[i].t, s + 2, i});
    for (std::size_t i = 0; i < f.force.size(); ++i) out.push_back({f.force[i].t, f.force[i].t, s + 3, i});
  }
  std::stable_sort(out.begin(), out.end(), [](const Arrival& a, const Arrival& b) { return a.at < b.at; });
  return out;
}

/// Hands one sample to the estimator; returns what Add* returned (false: dropped as late).
inline bool Deliver(const Arrival& a, const push::Trajectory& t, OnlineEstimator& online) {
  const auto& m = t.measured;
  switch (a.stream) {
    case 0: return online.AddObjectPose(a.t, m.object_pose[a.index].pose);
    case 1: return online.AddFingerPose(a.t, m.finger_pose[a.index].pose);
    case 2: return online.AddContactPoint(a.t, m.contact_point[a.index].point);
    case 3: return online.AddForce(a.t, m.force[a.index].force);
  }
  const int finger = (a.stream - 1) / 3;
  const push::FingerStreams& f = t.extra_fingers[finger - 1].measured;
  switch ((a.stream - 1) % 3) {
    case 0: return online.AddFingerPose(a.t, finger, f.finger_pose[a.index].pose);
    case 1: return online.AddContactPoint(a.t, finger, f.contact_point[a.index].point);
    default: return online.AddForce(a.t, finger, f.force[a.index].force);
  }
}

/// What an OnlineEstimator is built from for a recording: object and fingers, no samples, and
/// the ground truth (only for Finish()'s metrics).
inline push::Trajectory SetupOf(const push::Trajectory& t) {
  push::Trajectory setup;
  setup.object = t.object;
  setup.finger = t.finger;
  setup.ground_truth = t.ground_truth;
  setup.extra_fingers = t.extra_fingers;
  for (push::ExtraFinger& f : setup.extra_fingers) f.measured = {};
  return setup;
}

/// The streams a recording has, for OnlineStreams.
inline OnlineStreams StreamsOf(const push::Trajectory& t) {
  OnlineStreams s;
  s.contact_point = !t.measured.contact_point.empty();
  s.force = !t.measured.force.empty();
  for (const push::ExtraFinger& f : t.extra_fingers) {
    s.contact_point = s.contact_point || !f.measured.contact_point.empty();
    s.force = s.force || !f.measured.force.empty();
  }
  return s;
}

}  // namespace pushgraph::graph::testing
