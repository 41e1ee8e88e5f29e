// Input checks of a trajectory before any estimate (docs/estimation.md, Input checks): finite,
// sorted samples within the supported magnitudes, no clock jumps within or between streams, and
// the force-fault bound shared by the batch and online estimators.
#include "graph_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

namespace pushgraph::graph::internal {
namespace {

void CheckFinite(bool ok, const std::string& stream, std::size_t i) {
  if (!ok) throw GraphError("trajectory: non-finite value in streams." + stream + "[" + std::to_string(i) + "]");
}

// The supported magnitudes (docs/estimation.md): times within +-1e11 s (epoch time stamps, about
// 1.7e9 s, are fine; their double resolution is 2.4e-7 s), positions within the geometry's
// +-1e6 m, forces within +-1e9 N (a plausible but wrong force is a sensor fault, DropForceSpikes;
// one beyond this is a corrupt value).
constexpr double kMaxTime = 1e11, kMaxForce = 1e9;
void CheckRange(double t, double value, double bound, const std::string& stream, std::size_t i, const char* what) {
  if (std::abs(t) > kMaxTime || std::abs(value) > bound) {
    std::ostringstream text;
    text << "trajectory: streams." << stream << "[" << i << "] is out of the supported range (t = " << t << " s, "
         << what << " " << value << "; |t| <= 1e11 s, positions within 1e6 m, forces within 1e9 N)";
    throw GraphError(text.str());
  }
}

// `repeats`: a time may repeat (contact_point: one row per contact).
template <class Sample>
void CheckSorted(const std::vector<Sample>& s, const std::string& stream, bool repeats = false) {
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (!(s[i].t > s[i - 1].t) && !(repeats && s[i].t == s[i - 1].t)) {
      throw GraphError("trajectory: streams." + stream + " is not " + (repeats ? "increasing" : "strictly increasing") +
                       " in time at sample " + std::to_string(i));
    }
  }
}

// A clock jump: a gap in a stream, or between streams, longer than max(kClockJumpSeconds,
// kClockJumpPeriods median periods). The estimator's states follow the clock, so such a gap
// (a corrupted time stamp 1e9 s ahead) would cost memory and time in proportion to the gap, not
// to the samples; it is refused with the stream and the sample.
constexpr double kClockJumpSeconds = 10.0;
constexpr double kClockJumpPeriods = 1000.0;

template <class Sample>
double MedianPeriod(const std::vector<Sample>& s) {
  std::vector<double> d;
  for (std::size_t i = 1; i < s.size(); ++i)
    if (s[i].t != s[i - 1].t) d.push_back(s[i].t - s[i - 1].t);  // repeated contact times: one sample time
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

std::string Seconds(double t) {
  std::ostringstream s;
  s.precision(6);
  s << t << " s";
  return s.str();
}

template <class Sample>
void CheckNoClockJump(const std::vector<Sample>& s, const std::string& stream, double finest_period) {
  const double period = MedianPeriod(s);
  const double bound = std::max(kClockJumpSeconds, kClockJumpPeriods * std::max(period, finest_period));
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i].t - s[i - 1].t > bound) {
      throw GraphError("trajectory: streams." + stream + "[" + std::to_string(i) + "] jumps " + Seconds(s[i].t - s[i - 1].t) +
                       " ahead of the previous sample (t = " + Seconds(s[i - 1].t) + " -> " + Seconds(s[i].t) +
                       "; the stream's median period is " + Seconds(period) + "): a clock jump longer than " +
                       Seconds(bound) + " is refused; fix the time stamps or split the recording");
    }
  }
}

}  // namespace

double Percentile95(std::vector<double> values) {
  const std::size_t k = values.size() * 95 / 100;
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

double ForceFaultBound(double force_p95, const push::ObjectDescription& object) {
  double scale = force_p95;
  if (object.mass > 0.0 && object.mu_surface > 0.0) {
    scale = std::max(scale, object.mu_surface * object.mass * limit_surface::kStandardGravity);
  }
  return std::max(50.0 * scale, 1.0);
}

void ValidateTrajectory(const push::Trajectory& traj) {
  if (traj.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
  // Pushes with several fingers are simulated and stored (push::MultiPushingModel, "fingers" in
  // the file format); the factor graphs model one finger (with up to two contacts).
  if (!traj.extra_fingers.empty())
    throw GraphError("trajectory: " + std::to_string(push::FingerCount(traj)) +
                     " fingers: the estimator models one finger (with up to two contacts); several fingers are not "
                     "estimated yet");
  const auto& m = traj.measured;
  for (std::size_t i = 0; i < m.object_pose.size(); ++i) {
    CheckFinite(std::isfinite(m.object_pose[i].t) && m.object_pose[i].pose.vector().allFinite(), "object_pose", i);
  }
  for (std::size_t i = 0; i < m.finger_pose.size(); ++i) {
    CheckFinite(std::isfinite(m.finger_pose[i].t) && m.finger_pose[i].pose.vector().allFinite(), "finger_pose", i);
  }
  for (std::size_t i = 0; i < m.contact_point.size(); ++i) {
    CheckFinite(std::isfinite(m.contact_point[i].t) && m.contact_point[i].point.allFinite(), "contact_point", i);
  }
  for (std::size_t i = 0; i < m.force.size(); ++i) {
    CheckFinite(std::isfinite(m.force[i].t) && m.force[i].force.allFinite(), "force", i);
  }
  for (std::size_t i = 0; i < m.object_pose.size(); ++i) {
    const auto& s = m.object_pose[i];
    CheckRange(s.t, std::max(std::abs(s.pose.x), std::abs(s.pose.y)), geometry::kMaxCoordinate, "object_pose", i, "|position|");
  }
  for (std::size_t i = 0; i < m.finger_pose.size(); ++i) {
    const auto& s = m.finger_pose[i];
    CheckRange(s.t, std::max(std::abs(s.pose.x), std::abs(s.pose.y)), geometry::kMaxCoordinate, "finger_pose", i, "|position|");
  }
  for (std::size_t i = 0; i < m.contact_point.size(); ++i) {
    const auto& s = m.contact_point[i];
    CheckRange(s.t, s.point.cwiseAbs().maxCoeff(), geometry::kMaxCoordinate, "contact_point", i, "|position|");
  }
  for (std::size_t i = 0; i < m.force.size(); ++i) {
    CheckRange(m.force[i].t, m.force[i].force.cwiseAbs().maxCoeff(), kMaxForce, "force", i, "|force|");
  }
  CheckSorted(m.object_pose, "object_pose");
  CheckSorted(m.finger_pose, "finger_pose");
  CheckSorted(m.contact_point, "contact_point", /*repeats=*/true);
  CheckSorted(m.force, "force");
  {
    double finest = INFINITY;
    for (double p : {MedianPeriod(m.object_pose), MedianPeriod(m.finger_pose), MedianPeriod(m.contact_point), MedianPeriod(m.force)})
      if (p > 0.0) finest = std::min(finest, p);
    if (!std::isfinite(finest)) finest = 0.0;
    CheckNoClockJump(m.object_pose, "object_pose", 0.0);
    CheckNoClockJump(m.finger_pose, "finger_pose", 0.0);
    CheckNoClockJump(m.contact_point, "contact_point", 0.0);
    CheckNoClockJump(m.force, "force", 0.0);
    // Between streams: the streams' spans must overlap or follow within the same bound.
    std::vector<std::pair<double, std::pair<double, std::string>>> spans;
    auto add = [&](const auto& s, const std::string& name) {
      if (!s.empty()) spans.push_back({s.front().t, {s.back().t, name}});
    };
    add(m.object_pose, "object_pose");
    add(m.finger_pose, "finger_pose");
    add(m.contact_point, "contact_point");
    add(m.force, "force");
    std::sort(spans.begin(), spans.end());
    const double bound = std::max(kClockJumpSeconds, kClockJumpPeriods * finest);
    double reach = spans.empty() ? 0.0 : spans.front().second.first;
    std::string reached_by = spans.empty() ? "" : spans.front().second.second;
    for (std::size_t i = 1; i < spans.size(); ++i) {
      if (spans[i].first - reach > bound) {
        throw GraphError("trajectory: streams." + spans[i].second.second + " starts " + Seconds(spans[i].first - reach) +
                         " after streams." + reached_by + " ends (t = " + Seconds(reach) + " -> " + Seconds(spans[i].first) +
                         "): a clock jump longer than " + Seconds(bound) + " between streams is refused; are the streams on one clock?");
      }
      if (spans[i].second.first > reach) reach = spans[i].second.first, reached_by = spans[i].second.second;
    }
  }
  if (m.object_pose.empty()) {
    throw GraphError("trajectory: no object pose measurements (streams.object_pose is empty): nothing anchors the object");
  }
  if (m.finger_pose.empty()) {
    throw GraphError("trajectory: no finger pose measurements (streams.finger_pose is empty)");
  }
}

}  // namespace pushgraph::graph::internal
