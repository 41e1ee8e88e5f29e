// Input checks of a trajectory before any estimate (docs/estimation.md, Input checks): finite,
// sorted samples within the supported magnitudes, no clock jumps within or between streams, and
// the force-fault bound shared by the batch and online estimators.
#include "graph_builder.h"
#include "text.h"

#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/limit_surface/support.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>

namespace pushgraph::graph::internal {
namespace {

void CheckFinite(bool ok, const std::string& stream, std::size_t i) {
  if (!ok) throw GraphError("trajectory: non-finite value in streams." + stream + "[" + std::to_string(i) + "]");
}

// The supported magnitudes (docs/estimation.md): times within +-1e11 s (epoch time stamps, about
// 1.7e9 s, are fine; their double resolution is 2.4e-7 s), positions within the geometry's
// +-1e6 m, forces within +-1e9 N (a plausible but wrong force is a sensor fault, DropForceSpikes;
// one beyond this is a corrupt value).
constexpr double kMaxTime = push::kMaxTimeStamp, kMaxForce = 1e9;
void CheckRange(double t, double value, double bound, const std::string& stream, std::size_t i, const char* what) {
  if (std::abs(t) > kMaxTime || std::abs(value) > bound) {
    std::ostringstream text;
    text << "trajectory: streams." << stream << "[" << i << "] is out of the supported range (t = " << t << " s, "
         << what << " " << value << "; |t| <= 1e11 s, positions within 1e6 m, forces within 1e9 N)";
    // Unix time in milliseconds or microseconds (1.7e12, 1.7e15) is the usual way past 1e11 s.
    if (std::abs(t) > kMaxTime && std::abs(t) < 1e17)
      text << ": are the time stamps in milliseconds or microseconds? Trajectory times are in seconds";
    throw GraphError(text.str());
  }
}

// Positions in another unit than metres: a pushing recording moves slower than 5 m/s, and its
// poses do not span 0.2 m at more than that (the default simulated push written in millimetres:
// its finger spanning 57 "m" in 1.5 s; it ran, with the shape "1000 times too small" and its
// residuals 3e4 to 3e7 times their expected size).
constexpr double kMaxPushSpeed = 5.0, kMinJudgedSpan = 0.2;  // m/s, m
// The nearest finger 0 comes to the object's origin, over the object's size (in metres, the
// shape's): 0.1 to 1 for a push; 10 to 100 in centimetres, 100 to 1000 in millimetres. Beyond 10 it
// is no push in metres even when slow (a 5 cm/s push in centimetres moves at 3.8 "m/s"), or the
// finger's and object's frames differ. The nearest, not the median: a finger that retreats 40 cm
// from a 1 cm block after a brief push spends almost all of the recording far from it (median 24
// sizes) and was refused. Noise only brings it nearer.
// The finger's nearest approach to the object's tracked origin (each finger sample against the
// object sample nearest in time) and the finger sample's time; INFINITY without samples.
std::pair<double, double> NearestApproach(const std::vector<push::PoseSample>& fingers,
                                          const std::vector<push::PoseSample>& objects) {
  double nearest = INFINITY, at = 0.0;
  for (std::size_t i = 0, j = 0; i < fingers.size() && !objects.empty(); ++i) {
    while (j + 1 < objects.size() && std::abs(objects[j + 1].t - fingers[i].t) <= std::abs(objects[j].t - fingers[i].t)) ++j;
    const double d = (fingers[i].pose.translation() - objects[j].pose.translation()).norm();
    if (d < nearest) nearest = d, at = fingers[i].t;
  }
  return {nearest, at};
}

double NearestFingerRatio(const push::Trajectory& traj) {
  const double nearest = NearestApproach(traj.measured.finger_pose, traj.measured.object_pose).first;
  const geometry::Box2 box = traj.object.shape.bounds();
  const double size = std::max(box.max.x() - box.min.x(), box.max.y() - box.min.y());
  return size > 0.0 && std::isfinite(nearest) ? nearest / size : 0.0;
}

// The sample of a time-sorted stream nearest to t (the stream is not empty).
template <typename Sample>
const Sample& NearestInTime(const std::vector<Sample>& s, double t) {
  auto it = std::lower_bound(s.begin(), s.end(), t, [](const Sample& a, double x) { return a.t < x; });
  if (it == s.end()) return s.back();
  if (it != s.begin() && t - std::prev(it)->t < it->t - t) --it;
  return *it;
}

double Reach(const geometry::Shape& s) { return s.empty() ? 0.0 : geometry::RadiusAbout(s, geometry::Vec2::Zero()); }

constexpr double kLeastReach = 0.5;  // m

// A finger that never comes near the object's tracked origin pushes nothing: a finger and an
// object tracker in different frames (a fixed offset of metres) or units. Near is within the
// shapes' reach of their pose origins (a shape file too small by 100 has no say: the streams
// alone put the finger 2 m away) and at least 0.5 m, more than any tabletop object needs. The
// shape check had "repaired" such files by scaling the object 100 or 1000 times (a 12 cm block
// made 12 m, c = 3.9 m).
// The object's reach as given: a shape alone in millimetres lifts the bound with it (a tracker
// 2 m off then passes, and the shape check rescales the shape), but a large object in metres
// (the notched block 100 times larger, pushed by a 5 cm finger) is no error; the two cannot be
// told apart from the streams here.
double ReachBound(const geometry::Shape& object, const geometry::Shape& finger) {
  return std::max(kLeastReach, 2.0 * (Reach(object) + Reach(finger)));
}

}  // namespace

std::optional<std::string> FingerFarFromObject(const push::Trajectory& traj, int finger, double t,
                                               const push::PointSample* contact) {
  const auto& objects = traj.measured.object_pose;
  const auto& poses = finger == 0 ? traj.measured.finger_pose : traj.extra_fingers[finger - 1].measured.finger_pose;
  const geometry::Shape& shape = finger == 0 ? traj.finger.shape : traj.extra_fingers[finger - 1].finger.shape;
  if (objects.empty() || poses.empty()) return std::nullopt;
  const double bound = ReachBound(traj.object.shape, shape);
  const std::string prefix = finger == 0 ? "" : "fingers[" + std::to_string(finger) + "].";
  const double d = (NearestInTime(poses, t).pose.translation() - NearestInTime(objects, t).pose.translation()).norm();
  if (d > bound) {
    return Format("finger %d is %.3g m from the object at t = %.9g s, where its %s says it touches, beyond the %.3g m a "
                  "push allows (twice the object's and the finger's reach from their pose origins, and at least %.3g m): "
                  "are streams.%sfinger_pose and streams.object_pose in different frames (an offset between the two "
                  "trackers) or units?",
                  finger, d, t, contact != nullptr ? "contact stream" : "force", bound, kLeastReach, prefix.c_str());
  }
  if (contact != nullptr) {
    const double c = (contact->point - NearestInTime(objects, contact->t).pose.translation()).norm();
    if (c > bound) {
      return Format("streams.%scontact_point's first sample lies %.3g m from the object's tracked origin (t = %.9g s), "
                    "beyond the %.3g m a contact on the object allows: is the contact sensor in another frame or unit "
                    "than streams.object_pose?",
                    prefix.c_str(), c, contact->t, bound);
    }
  }
  return std::nullopt;
}

void CheckFingerReachesObject(const push::Trajectory& traj) {
  const auto& objects = traj.measured.object_pose;
  // Every finger that measures a contact or a force must come near (an idle finger parked next to
  // the object passed the check for a pusher 2 m off); with none, the nearest finger.
  struct Finger {
    const std::vector<push::PoseSample>* pose;
    const geometry::Shape* shape;
    bool touches;
  };
  // A force stream of zeros alone (an idle finger's sensor) is no touch.
  auto touches = [](const std::vector<push::PointSample>& contacts, const std::vector<push::ForceSample>& forces) {
    return !contacts.empty() ||
           std::any_of(forces.begin(), forces.end(), [](const push::ForceSample& f) { return f.force.norm() > 0.0; });
  };
  const push::Streams& m = traj.measured;
  std::vector<Finger> fingers = {{&m.finger_pose, &traj.finger.shape, touches(m.contact_point, m.force)}};
  for (const push::ExtraFinger& f : traj.extra_fingers)
    fingers.push_back({&f.measured.finger_pose, &f.finger.shape, touches(f.measured.contact_point, f.measured.force)});
  const bool any_touches = std::any_of(fingers.begin(), fingers.end(), [](const Finger& f) { return f.touches; });
  double nearest = any_touches ? -INFINITY : INFINITY, at = 0.0, first = 0.0;
  const geometry::Shape* farthest = &traj.finger.shape;
  for (const Finger& f : fingers) {
    if (any_touches && !f.touches) continue;
    const auto [d, t] = NearestApproach(*f.pose, objects);
    // Touching fingers: the farthest one's nearest approach; otherwise the nearest of all.
    if (std::isfinite(d) && (any_touches ? d > nearest : d < nearest)) {
      nearest = d, at = t, farthest = f.shape;
      first = f.pose->empty() ? 0.0 : f.pose->front().t;
    }
  }
  const double bound = ReachBound(traj.object.shape, *farthest);
  if (nearest > bound && std::isfinite(nearest)) {
    throw GraphError(Format("trajectory: the finger never comes nearer than %.3g m to the object (at t = %s), beyond the "
                            "%.3g m a push allows (twice the object's and the finger's reach from their pose origins, and at "
                            "least %.3g m): are streams.finger_pose and streams.object_pose in different frames (an offset "
                            "between the two trackers) or units?",
                            nearest, StepTime(at, first, "the finger's first sample").c_str(), bound, kLeastReach));
  }
  // A contact stream lies on the object: its median distance from the object's tracked origin
  // (the object sample nearest in time) is within the same bound, or the contact sensor reports
  // in another frame (a stream 2 m off was estimated, its factors' residuals blamed on the probe).
  auto contacts_far = [&](const std::vector<push::PointSample>& contacts, const std::string& stream,
                          const geometry::Shape& finger) {
    if (contacts.empty() || objects.empty()) return;
    std::vector<double> distances;
    for (const push::PointSample& c : contacts)
      distances.push_back((c.point - NearestInTime(objects, c.t).pose.translation()).norm());
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    const double median = distances[distances.size() / 2];
    const double contact_bound = ReachBound(traj.object.shape, finger);
    if (!(median > contact_bound)) return;
    throw GraphError(Format("trajectory: streams.%s lies %.3g m from the object's tracked origin (the median of its %zu "
                            "samples), beyond the %.3g m a contact on the object allows: is the contact sensor in another "
                            "frame or unit than streams.object_pose?",
                            stream.c_str(), median, contacts.size(), contact_bound));
  };
  contacts_far(traj.measured.contact_point, "contact_point", traj.finger.shape);
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k)
    contacts_far(traj.extra_fingers[k].measured.contact_point, "fingers[" + std::to_string(k + 1) + "].contact_point",
                 traj.extra_fingers[k].finger.shape);
}

namespace {

void CheckPositionUnits(const std::vector<push::PoseSample>& s, const std::string& stream, double ratio) {
  if (s.size() < 2 || !(s.back().t > s.front().t)) return;
  Eigen::Vector2d low = s.front().pose.translation(), high = low;
  for (const push::PoseSample& p : s) {
    low = low.cwiseMin(p.pose.translation());
    high = high.cwiseMax(p.pose.translation());
  }
  const double span = (high - low).norm(), duration = s.back().t - s.front().t;
  if (span <= kMinJudgedSpan || (span / duration <= kMaxPushSpeed && ratio <= 10.0)) return;
  const char* unit = ratio > 100.0 ? "millimetres" : ratio > 10.0 ? "centimetres" : nullptr;
  std::ostringstream text;
  text << "trajectory: streams." << stream << " spans " << span << " m in " << duration << " s (" << span / duration
       << " m/s at least) and the finger comes no nearer than " << ratio << " times the object's size to it (a push "
       << "in metres: below " << kMaxPushSpeed << " m/s, 0.1 to 1 times): ";
  if (unit) {
    text << "are the positions in " << unit << "? Trajectory positions are in metres: divide x and y of every stream "
         << "(and the contact points) by " << (ratio > 100.0 ? 1000 : 100) << " (or are the finger and the object in "
         << "different frames?)";
  } else {
    text << "are the positions in another unit than metres (millimetres: divide by 1000), or the time stamps in one "
         << "too small?";
  }
  throw GraphError(text.str());
}

// `repeats`: a time may repeat (contact_point: one row per contact).
template <class Sample>
void CheckSorted(const std::vector<Sample>& s, const std::string& stream, bool repeats = false) {
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (!(s[i].t > s[i - 1].t) && !(repeats && s[i].t == s[i - 1].t)) {
      // Where and why: a Python dict's rows are taken in their order (the file reader sorts a
      // file's), and epoch times in float32 repeat for 128 s.
      const bool float32 = s[i].t == s[i - 1].t && std::abs(s[i].t) > 1e7 && static_cast<double>(static_cast<float>(s[i].t)) == s[i].t;
      throw GraphError(Format("trajectory: streams.%s is not %s in time at sample %zu (t = %.17g s after t = %.17g s at "
                              "sample %zu): %s",
                              stream.c_str(), repeats ? "increasing" : "strictly increasing", i, s[i].t, s[i - 1].t, i - 1,
                              float32 ? "the time stamps look like float32 values (epoch seconds in float32 step by "
                                        "128 s): keep them as float64"
                              : s[i].t == s[i - 1].t
                                  ? "one time stamp twice: remove the repeated sample"
                                  : "sort each stream's samples by time (the trajectory file reader does; a "
                                    "trajectory built in code or a Python dict is taken in its order)"));
    }
    // As the trajectory reader: less than a nanosecond apart is one time stamp written twice.
    if (!repeats && s[i].t - s[i - 1].t < 1e-9) {
      throw GraphError(Format("trajectory: streams.%s samples %zu and %zu are %.3g s apart: less than 1 ns, the same "
                              "time stamp written twice?",
                              stream.c_str(), i - 1, i, s[i].t - s[i - 1].t));
    }
    if constexpr (std::is_same_v<Sample, push::PointSample>) {
      // As the trajectory reader: the same contact twice at one time is a sample added twice.
      for (std::size_t j = i; repeats && j-- > 0 && s[j].t == s[i].t;) {
        if (s[j].point == s[i].point) {
          throw GraphError(Format("trajectory: streams.%s samples %zu and %zu are the same contact point (%.17g, %.17g) at "
                                  "t = %.17g: a sample added twice? (Samples at one time are several contacts, each at "
                                  "its own point)",
                                  stream.c_str(), j, i, s[i].point.x(), s[i].point.y(), s[i].t));
        }
      }
    }
  }
}

// A clock jump: a gap in a stream, or between streams, longer than max(kClockJumpSeconds,
// kClockJumpPeriods median periods). The estimator's states follow the clock, so such a gap
// (a corrupted time stamp 1e9 s ahead) would cost memory and time in proportion to the gap, not
// to the samples; it is refused with the stream and the sample.
using push::kClockJumpPeriods;
using push::kClockJumpSeconds;

// Calls visit(stream, name) on each finger's pose, contact and force streams, finger 0's first
// (named "finger_pose", ..., then "fingers[k].finger_pose", ...).
template <typename Visit>
void ForEachFingerStream(const push::Trajectory& traj, Visit&& visit) {
  const auto& m = traj.measured;
  visit(m.finger_pose, std::string("finger_pose"));
  visit(m.contact_point, std::string("contact_point"));
  visit(m.force, std::string("force"));
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    const push::FingerStreams& f = traj.extra_fingers[k].measured;
    const std::string who = "fingers[" + std::to_string(k + 1) + "].";
    visit(f.finger_pose, who + "finger_pose");
    visit(f.contact_point, who + "contact_point");
    visit(f.force, who + "force");
  }
}

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

// How deep the finger's origin lies inside it (a disk's: its radius), rounded or polygonal alike,
// against how far the push reaches: the finger's farthest distance from the object's origin and
// the object's reach about it. Deeper than both together, the finger would hold the whole object
// inside it at every sample.
struct FingerDepth {
  double depth = 0.0, farthest = 0.0, object_reach = 0.0;
  bool HoldsWholePush() const { return depth > farthest + object_reach; }
};

std::optional<FingerDepth> MeasureFingerDepth(const geometry::Shape& finger, const std::vector<push::PoseSample>& finger_pose,
                                              const std::vector<push::PoseSample>& object_pose, const geometry::Shape& object) {
  if (finger.empty() || finger_pose.empty() || object_pose.empty()) return std::nullopt;
  FingerDepth d;
  std::size_t k = 0;
  for (const push::PoseSample& f : finger_pose) {
    while (k + 1 < object_pose.size() && std::abs(object_pose[k + 1].t - f.t) <= std::abs(object_pose[k].t - f.t)) ++k;
    d.farthest = std::max(d.farthest, (f.pose.translation() - object_pose[k].pose.translation()).norm());
  }
  d.object_reach = geometry::RadiusAbout(object, geometry::Vec2::Zero());
  d.depth = -geometry::QueryPoint(finger, geometry::Vec2::Zero()).signed_distance;
  return d;
}

// The units a finger file read as metres may be in: those that make it a tabletop probe, 0.5 to
// 100 mm from its origin to its farthest point, that does not hold the push inside it.
struct FingerReading {
  double scale;
  const char* unit;
  double reach;  // m, from its origin, so read
};
std::vector<FingerReading> FingerReadings(const geometry::Shape& finger, const std::vector<push::PoseSample>& finger_pose,
                                          const std::vector<push::PoseSample>& object_pose, const geometry::Shape& object) {
  std::vector<FingerReading> readings;
  if (finger.empty()) return readings;
  const double reach = geometry::RadiusAbout(finger, geometry::Vec2::Zero());
  for (const auto& [scale, unit] : {std::pair{1e-3, "millimetres"}, {1e-2, "centimetres"}, {0.0254, "inches"}}) {
    if (!(scale * reach >= 5e-4 && scale * reach <= 0.1)) continue;
    const std::optional<FingerDepth> d =
        MeasureFingerDepth(geometry::TransformShape(finger, geometry::Pose2(), scale), finger_pose, object_pose, object);
    if (d && !d->HoldsWholePush()) readings.push_back({scale, unit, scale * reach});
  }
  return readings;
}

// A finger whose origin lies deeper inside it than every finger-object distance of the recording
// plus the object's reach: its file is in other units (a probe of radius 4.7 given in millimetres
// was read as 4.7 m, and the shape check then "aligned" the object 4 m away; a 32-gon probe in
// millimetres ran for 51 s to an object 2.5 m off the tracker's, exit 0). The object's own units
// the registration detects; a finger in other units FingerUnits scales (align_shape auto and on)
// before this check.
void CheckFingerSize(const geometry::Shape& finger, const std::vector<push::PoseSample>& finger_pose,
                     const std::vector<push::PoseSample>& object_pose, const geometry::Shape& object, const std::string& who) {
  const std::optional<FingerDepth> d = MeasureFingerDepth(finger, finger_pose, object_pose, object);
  if (!d || !d->HoldsWholePush()) return;
  // Which units make it a probe: a file in centimetres or inches was asked "in millimetres?", and
  // --scale 0.001 made a 4.7 mm probe 0.47 mm.
  std::string units, readings;
  for (const FingerReading& r : FingerReadings(finger, finger_pose, object_pose, object)) {
    units += std::string(units.empty() ? "" : " or ") + r.unit;
    readings += Format("%sin %s it reaches %.3g mm from its origin (pushgraph footprint FILE --scale %g)",
                       readings.empty() ? "" : ", ", r.unit, r.reach * 1e3, r.scale);
  }
  if (units.empty()) units = "millimetres", readings = "pushgraph footprint FILE --scale 0.001 converts one from millimetres";
  throw GraphError(Format("trajectory: %sthe finger's shape covers %.6g m about its origin (its rounding radius %.6g m), "
                          "more than the whole push: the finger stays within %.3g m of the object's origin and the object "
                          "within %.3g m of it, so at every sample the finger would hold the whole object inside it. Is the "
                          "finger's shape file in %s? Shape files are in metres: %s",
                          who.c_str(), d->depth, finger.radius(), d->farthest, d->object_reach, units.c_str(),
                          readings.c_str()));
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

// Finger j against finger k in their measured poses (at the times both are measured, at most
// 200 of them): inside each other by more than 1 mm at the median is a wrong shape, offset or
// pose stream, which no estimate could fit (the estimator would blame the sensors instead).
void CheckFingersApart(const push::Trajectory& traj, std::size_t j, std::size_t k) {
  const auto& a = j == 0 ? traj.measured.finger_pose : traj.extra_fingers[j - 1].measured.finger_pose;
  const auto& b = traj.extra_fingers[k - 1].measured.finger_pose;
  std::vector<std::pair<std::size_t, std::size_t>> common;
  for (std::size_t u = 0, w = 0; u < a.size() && w < b.size();) {
    if (std::abs(a[u].t - b[w].t) <= 1e-9) common.emplace_back(u++, w++);
    else if (a[u].t < b[w].t) ++u;
    else ++w;
  }
  if (common.size() < 5) return;
  const geometry::ShapePairQuerier querier(j == 0 ? traj.finger.shape : traj.extra_fingers[j - 1].finger.shape,
                                           traj.extra_fingers[k - 1].finger.shape);
  const std::size_t stride = std::max<std::size_t>(1, common.size() / 200);
  std::vector<double> separation;
  std::size_t deepest = 0;  // the common time where they overlap most: the example named
  for (std::size_t c = 0; c < common.size(); c += stride) {
    separation.push_back(querier.Query(a[common[c].first].pose, b[common[c].second].pose).signed_distance);
    if (separation.back() < separation[deepest / stride]) deepest = c;
  }
  const double median = Median(separation);
  if (median < -1e-3) {
    const std::string a_rows = j == 0 ? "finger_pose[" : "fingers[" + std::to_string(j) + "].finger_pose[";
    throw GraphError("trajectory: fingers " + std::to_string(j) + " and " + std::to_string(k) +
                     " overlap each other in their measured poses (median separation " + Format("%.2f", 1e3 * median) +
                     " mm over " + std::to_string(separation.size()) + " common times; deepest " +
                     Format("%.2f", -1e3 * separation[deepest / stride]) + " mm at t = " + Format("%.9g", a[common[deepest].first].t) +
                     " s, " + a_rows + std::to_string(common[deepest].first) + "] and fingers[" + std::to_string(k) +
                     "].finger_pose[" + std::to_string(common[deepest].second) +
                     "]): check the fingers' shapes and their pose streams");
  }
}

void ValidateFingers(const push::Trajectory& traj) {
  // The factor graphs model one finger with up to two contacts, or several fingers with one each.
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k)
    if (traj.extra_fingers[k].finger.shape.empty())
      throw GraphError("trajectory: fingers[" + std::to_string(k + 1) + "].shape is missing or empty");
}

void CheckFingerSizes(const push::Trajectory& traj) {
  const push::Streams& m = traj.measured;
  CheckFingerSize(traj.finger.shape, m.finger_pose, m.object_pose, traj.object.shape, "");
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    CheckFingerSize(traj.extra_fingers[k].finger.shape, traj.extra_fingers[k].measured.finger_pose, m.object_pose,
                    traj.object.shape, "fingers[" + std::to_string(k + 1) + "]: ");
  }
}

void ValidateTrajectory(const push::Trajectory& traj, bool finger_size) {
  if (traj.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
  ValidateFingers(traj);
  // The object's and fingers' parameters as the file format bounds them (a trajectory built in
  // code or from a Python dict skips the file reader: mass -1 or NaN and mu_surface NaN were
  // estimated as if valid, mu_surface 50 gave forces of 107 N); a mass or mu_surface of 0 is
  // "unknown" there (QS then leaves out the load factor and says so).
  // The bounds are the limit-surface module's supported ranges (support.h).
  using limit_surface::kMaxFriction, limit_surface::kMaxGravity, limit_surface::kMaxMass;
  auto in_range = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in_range(traj.object.mass, 0.0, kMaxMass))
    throw GraphError("trajectory: object.mass must be in (0, 1e6] kg (0: unknown), got " + Format("%.9g", traj.object.mass));
  if (!in_range(traj.object.mu_surface, 0.0, kMaxFriction))
    throw GraphError("trajectory: object.mu_surface must be in [0, 10] (0: unknown), got " + Format("%.9g", traj.object.mu_surface));
  if (!(in_range(traj.object.gravity, 0.0, kMaxGravity) && traj.object.gravity > 0.0))
    throw GraphError("trajectory: object.gravity must be in (0, 1e3] m/s^2, got " + Format("%.9g", traj.object.gravity));
  if (!in_range(traj.finger.mu_contact, 0.0, kMaxFriction))
    throw GraphError("trajectory: finger.mu_contact must be in [0, 10], got " + Format("%.9g", traj.finger.mu_contact));
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    if (!in_range(traj.extra_fingers[k].finger.mu_contact, 0.0, kMaxFriction))
      throw GraphError("trajectory: fingers[" + std::to_string(k + 1) + "].mu_contact must be in [0, 10], got " +
                       Format("%.9g", traj.extra_fingers[k].finger.mu_contact));
  }
  const auto& m = traj.measured;
  for (std::size_t i = 0; i < m.object_pose.size(); ++i) {
    CheckFinite(std::isfinite(m.object_pose[i].t) && m.object_pose[i].pose.vector().allFinite(), "object_pose", i);
  }
  // Ground truth only scores the estimate, yet a NaN there made every metric NaN without a word
  // (a Python dict skips the file reader, which refuses it).
  auto check_truth = [](const auto& samples, const std::string& stream, auto finite) {
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!std::isfinite(samples[i].t) || !finite(samples[i]))
        throw GraphError("trajectory: non-finite value in ground_truth." + stream + "[" + std::to_string(i) + "]");
    }
  };
  auto check_truth_streams = [&](const auto& g, const std::string& who) {
    check_truth(g.finger_pose, who + "finger_pose", [](const push::PoseSample& x) { return x.pose.vector().allFinite(); });
    check_truth(g.contact_point, who + "contact_point", [](const push::PointSample& x) { return x.point.allFinite(); });
    check_truth(g.force, who + "force", [](const push::ForceSample& x) { return x.force.allFinite(); });
  };
  if (traj.ground_truth) {
    check_truth(traj.ground_truth->object_pose, "object_pose",
                [](const push::PoseSample& x) { return x.pose.vector().allFinite(); });
    check_truth_streams(*traj.ground_truth, "");
  }
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    if (traj.extra_fingers[k].ground_truth)
      check_truth_streams(*traj.extra_fingers[k].ground_truth, "fingers[" + std::to_string(k + 1) + "].");
  }
  for (std::size_t i = 0; i < m.object_pose.size(); ++i) {
    const auto& s = m.object_pose[i];
    CheckRange(s.t, std::max(std::abs(s.pose.x), std::abs(s.pose.y)), geometry::kMaxCoordinate, "object_pose", i, "|position|");
  }
  // Each finger's streams; finger k > 0's named streams.fingers[k].<stream>[its own sample index].
  auto check_finger = [](const std::vector<push::PoseSample>& pose, const std::vector<push::PointSample>& contact,
                         const std::vector<push::ForceSample>& force, const std::string& who) {
    for (std::size_t i = 0; i < pose.size(); ++i) {
      CheckFinite(std::isfinite(pose[i].t) && pose[i].pose.vector().allFinite(), who + "finger_pose", i);
      CheckRange(pose[i].t, std::max(std::abs(pose[i].pose.x), std::abs(pose[i].pose.y)), geometry::kMaxCoordinate,
                 who + "finger_pose", i, "|position|");
    }
    for (std::size_t i = 0; i < contact.size(); ++i) {
      CheckFinite(std::isfinite(contact[i].t) && contact[i].point.allFinite(), who + "contact_point", i);
      CheckRange(contact[i].t, contact[i].point.cwiseAbs().maxCoeff(), geometry::kMaxCoordinate, who + "contact_point", i,
                 "|position|");
    }
    for (std::size_t i = 0; i < force.size(); ++i) {
      CheckFinite(std::isfinite(force[i].t) && force[i].force.allFinite(), who + "force", i);
      CheckRange(force[i].t, force[i].force.cwiseAbs().maxCoeff(), kMaxForce, who + "force", i, "|force|");
    }
    CheckSorted(pose, who + "finger_pose");
    CheckSorted(contact, who + "contact_point", /*repeats=*/true);
    CheckSorted(force, who + "force");
    CheckNoClockJump(pose, who + "finger_pose", 0.0);
    CheckNoClockJump(contact, who + "contact_point", 0.0);
    CheckNoClockJump(force, who + "force", 0.0);
  };
  check_finger(m.finger_pose, m.contact_point, m.force, "");
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    const push::FingerStreams& f = traj.extra_fingers[k].measured;
    const std::string who = "fingers[" + std::to_string(k + 1) + "].";
    check_finger(f.finger_pose, f.contact_point, f.force, who);
    if (f.finger_pose.empty())
      throw GraphError("trajectory: no pose measurements of finger " + std::to_string(k + 1) +
                       " (its finger_pose rows are missing)");
    for (std::size_t j = 0; j <= k; ++j) CheckFingersApart(traj, j, k + 1);
  }
  CheckSorted(m.object_pose, "object_pose");
  {
    double finest = INFINITY;
    for (double p : {MedianPeriod(m.object_pose), MedianPeriod(m.finger_pose), MedianPeriod(m.contact_point), MedianPeriod(m.force)})
      if (p > 0.0) finest = std::min(finest, p);
    if (!std::isfinite(finest)) finest = 0.0;
    CheckNoClockJump(m.object_pose, "object_pose", 0.0);
    // Between streams: the streams' spans must overlap or follow within the same bound.
    std::vector<std::pair<double, std::pair<double, std::string>>> spans;
    auto add = [&](const auto& s, const std::string& name) {
      if (!s.empty()) spans.push_back({s.front().t, {s.back().t, name}});
    };
    add(m.object_pose, "object_pose");
    ForEachFingerStream(traj, add);
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
  CheckStreamTimeUnits(traj);
  if (m.finger_pose.empty()) {
    throw GraphError("trajectory: no finger pose measurements (streams.finger_pose is empty)");
  }
  const double finger_ratio = NearestFingerRatio(traj);
  CheckPositionUnits(m.finger_pose, "finger_pose", finger_ratio);
  CheckPositionUnits(m.object_pose, "object_pose", finger_ratio);
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k)
    CheckPositionUnits(traj.extra_fingers[k].measured.finger_pose, "fingers[" + std::to_string(k + 1) + "].finger_pose",
                       finger_ratio);
  CheckFingerReachesObject(traj);
  if (finger_size) CheckFingerSizes(traj);
}

namespace {

// The finger's position at t, linearly interpolated (nullopt outside the stream).
std::optional<geometry::Vec2> FingerPositionAt(const std::vector<push::PoseSample>& s, double t) {
  if (s.empty() || t < s.front().t || t > s.back().t) return std::nullopt;
  return push::StreamValueClamped(s, t, [](const push::PoseSample& p) -> geometry::Vec2 { return p.pose.translation(); });
}

// Each object pose against the component-wise median of a window centred on it (it included, an
// odd count: on a steady motion the median is the sample itself), +-max(0.1 s, 3 periods) wide
// with two neighbours or more on each side. A glitch of up to ~40 % of the window (a 40 ms jump of
// a 250 Hz tracker) leaves the median on the true path; one-sided windows at the stream's ends
// and beside gaps are biased by the motion and are not judged.
struct CentredGaps {
  double half = 0.0;                    ///< the window's half-width, s
  std::vector<bool> judged;
  std::vector<double> position, angle;  ///< m, rad; 0 where not judged
  /// 1.4826 MAD of the judged gaps (a Gaussian's sigma); 0 with none judged.
  double Scatter(const std::vector<double>& gaps) const {
    std::vector<double> kept;
    for (std::size_t i = 0; i < gaps.size(); ++i)
      if (judged[i]) kept.push_back(gaps[i]);
    return 1.4826 * Median(kept);
  }
};

CentredGaps CentredMedianGaps(const std::vector<push::PoseSample>& s) {
  const std::size_t n = s.size();
  CentredGaps g;
  g.half = std::max(0.1, 3.0 * MedianPeriod(s));
  g.judged.assign(n, false);
  g.position.assign(n, 0.0);
  g.angle.assign(n, 0.0);
  std::vector<double> xs, ys, as;
  for (std::size_t i = 0, lo = 0, hi = 0; i < n; ++i) {
    while (s[i].t - s[lo].t > g.half) ++lo;
    while (hi + 1 < n && s[hi + 1].t - s[i].t <= g.half) ++hi;
    const std::size_t side = std::min(i - lo, hi - i);
    if (side < 2) continue;
    xs.clear(), ys.clear(), as.clear();
    for (std::size_t j = i - side; j <= i + side; ++j) {
      xs.push_back(s[j].pose.x), ys.push_back(s[j].pose.y);
      as.push_back(std::remainder(s[j].pose.theta - s[i].pose.theta, 2.0 * M_PI));
    }
    g.judged[i] = true;
    g.position[i] = std::hypot(s[i].pose.x - Median(xs), s[i].pose.y - Median(ys));
    g.angle[i] = std::abs(Median(as));
  }
  return g;
}

}  // namespace

std::optional<std::string> ForceDirectionNote(const push::Trajectory& traj) {
  const auto& forces = traj.measured.force;
  const auto& finger = traj.measured.finger_pose;
  if (forces.size() < 20 || finger.size() < 5 || !traj.extra_fingers.empty()) return std::nullopt;
  std::vector<double> magnitude;
  for (const auto& f : forces) magnitude.push_back(f.force.norm());
  const double strong = 0.25 * Percentile95(magnitude);
  // The finger's velocity by a central difference over +-h. Summed over the samples, its noise
  // (a 5 mm tracker at 250 Hz is noisier than a 50 mm/s push sample by sample) averages out of
  // the work sum f . v while |f| |v| keeps it: the ratio is a lower bound of the mean cosine.
  const double h = std::max(0.1, 2.0 * MedianPeriod(finger));
  double work = 0.0, scale = 0.0, work_swapped = 0.0;
  std::size_t used = 0, against = 0;
  for (const auto& f : forces) {
    if (!(f.force.norm() >= strong) || !(f.force.norm() > 0.0)) continue;
    const auto a = FingerPositionAt(finger, f.t - h), b = FingerPositionAt(finger, f.t + h);
    if (!a || !b) continue;
    const geometry::Vec2 v = (*b - *a) / (2.0 * h);
    work += f.force.dot(v);
    work_swapped += f.force.y() * v.x() + f.force.x() * v.y();
    scale += f.force.norm() * v.norm();
    against += f.force.dot(v) < 0.0;
    ++used;
  }
  if (used < 20 || !(scale > 0.0)) return std::nullopt;
  // Quasi-static pushing dissipates what the finger puts in: the force on the object has a
  // positive component along the contact point's velocity, which is the finger's.
  const double mean_cosine = work / scale;
  // Real pushes: 0.20 to 0.93 (the dataset's ellip1 recordings with the paper's noise); a flipped
  // stream about -0.9. Some margin below 0 for slow pushes under heavy finger noise.
  // Axes swapped: the force is then at an angle to the motion that swapping undoes (a diagonal
  // push read 0.30 as recorded, 0.95 swapped, and ran with no word, force RMS 1.27 N against 0.07;
  // a 0.5 s push along x under 5 mm finger noise 0.10 and 0.71).
  const double swapped_cosine = work_swapped / scale;
  if (mean_cosine >= -0.2 && swapped_cosine > 0.5 && swapped_cosine > mean_cosine + 0.4)
    return Format("force: the measured force and the finger's motion are at a mean cosine of %.2f over the %zu samples "
                  "where it pushes, %.2f with its x and y exchanged: are the force stream's x and y swapped?",
                  mean_cosine, used, swapped_cosine);
  if (mean_cosine >= -0.2) return std::nullopt;
  return Format("force: the measured force does negative work on the object (the force and the finger's motion are at a "
                "mean cosine of %.2f over the %zu samples where it pushes, %.0f%% of them pointing against the motion), "
                "but a pushing finger does positive work: is the stream the force on the sensor (the reaction: negate "
                "it), are its x and y swapped, or is it in another frame than the poses'?",
                mean_cosine, used, 100.0 * static_cast<double>(against) / static_cast<double>(used));
}

namespace {

// The mean force of the samples outside [first, last] (shifted by `lag`: the force stream's time
// stamps read lag s late), with the mean's standard error (both axes) from their own scatter.
struct OutOfContactForce {
  geometry::Vec2 mean = geometry::Vec2::Zero();
  double standard_error = 0.0;
  std::size_t count = 0;
  std::vector<double> touching;  // |f| of the samples inside
  bool Clear() const { return mean.norm() > 4.0 * standard_error && mean.norm() > 0.05; }
};

OutOfContactForce ForceOutOfContact(const std::vector<push::ForceSample>& forces, double first, double last, double lag) {
  OutOfContactForce out;
  std::vector<geometry::Vec2> free;
  geometry::Vec2 sum = geometry::Vec2::Zero();
  for (const auto& f : forces) {
    const double t = f.t - lag;
    if (t < first || t > last) {
      free.push_back(f.force);
      sum += f.force;
    } else {
      out.touching.push_back(f.force.norm());
    }
  }
  out.count = free.size();
  if (free.size() < 2) return out;
  const double n = static_cast<double>(free.size());
  out.mean = sum / n;
  double spread = 0.0;
  for (const geometry::Vec2& f : free) spread += (f - out.mean).squaredNorm();
  out.standard_error = std::sqrt(spread / (n - 1.0) / n);
  return out;
}

// The shift of the force stream against the contact stream, within +-1 s, that best separates
// its magnitudes in contact from those out of contact (the difference of their means). A force
// stream whose clock runs behind reads the push's force after the last contact row and little at
// the first ones: what the bias check alone read as "a bias". In contact: within a contact phase
// (rows at most 2.5 contact periods apart) widened by half a period at each end; widening each row
// by the 2.5 periods instead made the shift up to that much too large (0.325 s for 0.2 s late under
// a 20 Hz contact stream). The sums are exact for every shift, from prefix sums over the samples.
std::optional<double> ForceStreamLag(const std::vector<push::ForceSample>& forces,
                                     const std::vector<push::PointSample>& contacts) {
  const double force_period = MedianPeriod(forces), contact_period = MedianPeriod(contacts);
  if (!(force_period > 0.0) || !(contact_period > 0.0)) return std::nullopt;
  std::vector<std::pair<double, double>> samples;  // (t, |f|), in time order
  for (const auto& f : forces) samples.emplace_back(f.t, f.force.norm());
  std::sort(samples.begin(), samples.end());
  std::vector<double> times, magnitude_sum{0.0};
  for (const auto& [t, magnitude] : samples) {
    times.push_back(t);
    magnitude_sum.push_back(magnitude_sum.back() + magnitude);
  }
  std::vector<double> rows;
  for (const auto& c : contacts) rows.push_back(c.t);
  std::sort(rows.begin(), rows.end());
  std::vector<std::pair<double, double>> phases;
  for (double t : rows) {
    if (!phases.empty() && t - phases.back().second <= 2.5 * contact_period) phases.back().second = t;
    else phases.emplace_back(t, t);
  }
  const double total = magnitude_sum.back(), n = static_cast<double>(times.size());
  auto contrast_at = [&](double lag, double* contrast) {
    double in_sum = 0.0, in_count = 0.0;
    for (const auto& [a, b] : phases) {
      const auto lo = std::lower_bound(times.begin(), times.end(), a - 0.5 * contact_period + lag) - times.begin();
      const auto hi = std::upper_bound(times.begin(), times.end(), b + 0.5 * contact_period + lag) - times.begin();
      in_sum += magnitude_sum[hi] - magnitude_sum[lo];
      in_count += static_cast<double>(hi - lo);
    }
    if (in_count < 5.0 || n - in_count < 5.0) return false;
    *contrast = in_sum / in_count - (total - in_sum) / (n - in_count);
    return true;
  };
  // Shifts in the order 0, +1, -1, +2, ... steps: where several separate equally well (a stream
  // stuck at one value), the smallest wins, and a stuck stream stays "stuck", not "late".
  const double step = std::max(force_period, 1e-3);
  const int steps = static_cast<int>(std::floor(1.0 / step));
  std::optional<double> best;
  double best_contrast = -INFINITY;
  for (int i = 0; i <= 2 * steps; ++i) {
    const double lag = (i % 2 == 1 ? 1.0 : -1.0) * static_cast<double>((i + 1) / 2) * step;
    double contrast = 0.0;
    if (!contrast_at(lag, &contrast)) continue;
    if (!best || contrast > best_contrast + 1e-9 * std::max(1.0, std::abs(best_contrast))) {
      best_contrast = contrast;
      best = lag;
    }
  }
  return best;
}

}  // namespace

std::optional<ForceOutOfContactNote> ForceBiasNote(const push::Trajectory& traj) {
  const auto& forces = traj.measured.force;
  const auto& contacts = traj.measured.contact_point;
  if (forces.size() < 20 || contacts.size() < 10 || !traj.extra_fingers.empty()) return std::nullopt;
  // Out of contact by the contact stream, with a margin for the sensors' own timing.
  constexpr double kMargin = 0.05;  // s
  const double first = contacts.front().t - kMargin, last = contacts.back().t + kMargin;
  OutOfContactForce as_stamped = ForceOutOfContact(forces, first, last, 0.0);
  constexpr std::size_t kFewestOutOfContact = 10;  // for a standard error worth counting in
  if (as_stamped.count < kFewestOutOfContact || as_stamped.touching.empty() || !as_stamped.Clear()) return std::nullopt;
  // A clock offset, not a bias, where shifting the stream by more than the margin leaves no clear
  // force out of contact (a simulated push with its force stamps 0.1 to 0.3 s late was called
  // "a bias" of 1.3 N).
  if (const std::optional<double> lag = ForceStreamLag(forces, contacts); lag && std::abs(*lag) > kMargin) {
    const OutOfContactForce shifted = ForceOutOfContact(forces, first, last, *lag);
    if (shifted.count >= kFewestOutOfContact && !shifted.Clear()) {
      return ForceOutOfContactNote{
          Format("force: the force stream looks about %.2f s %s against the contact stream: shifted by %+.2f s its force "
                    "rises and falls with the contact rows, and out of contact it reads %.3g N (%zu samples) instead of "
                    "%.3g N as stamped (%zu samples): are the two sensors' clocks offset? Shift the force stream's time "
                    "stamps by %+.2f s, or the contact stream's by %+.2f s if its clock is the one off (a simulated "
                    "push's force stamped 0.2 s late: force estimate 0.95 N RMS against 0.50 N raw)",
                    std::abs(*lag), *lag > 0.0 ? "late" : "early", -*lag, shifted.mean.norm(), shifted.count,
                    as_stamped.mean.norm(), as_stamped.count, -*lag, *lag),
          true};
    }
  }
  std::vector<double>& touching = as_stamped.touching;
  const geometry::Vec2 mean = as_stamped.mean;
  const double standard_error = as_stamped.standard_error;
  std::nth_element(touching.begin(), touching.begin() + touching.size() / 2, touching.end());
  // A stream that does not scatter there (a sensor stuck at a value, or quantized) has no standard error to count in.
  const std::string how_clear =
      standard_error > 0.0 ? Format("%.3g standard errors", mean.norm() / standard_error) : std::string("without scatter");
  return ForceOutOfContactNote{
      Format("force: the sensor reads a mean (%.3g, %.3g) N (%s) over the %zu samples before and after the contact "
                "stream, where the finger does not touch (median %.3g N in contact): a bias, or a sensor stuck at a value? "
                "Tare the sensor, or subtract the bias from the stream (a bias of a fifth of the push's force moved a true "
                "shape by 17 mm)",
                mean.x(), mean.y(), how_clear.c_str(), as_stamped.count, touching[touching.size() / 2]),
      false};
}

std::optional<std::string> ForceScaleNote(const push::Trajectory& traj, double force_sigma, bool mu_estimated) {
  const auto& forces = traj.measured.force;
  const auto& object = traj.measured.object_pose;
  if (forces.size() < 20 || object.size() < 2 || !(traj.object.mass > 0.0) || !(traj.object.mu_surface > 0.0) ||
      !traj.extra_fingers.empty())
    return std::nullopt;
  std::vector<double> magnitude;
  for (const auto& f : forces) magnitude.push_back(f.force.norm());
  const double p95 = Percentile95(magnitude);
  const double load = traj.object.mu_surface * traj.object.mass * limit_surface::kStandardGravity;
  // A quasi-static push needs about the friction load mu m g to slide the object (from about a
  // third of it, turning about a far point, to the whole of it in translation); impacts and
  // miscalibration aside, 20 times more or less is another unit or a wrong mass or mu.
  constexpr double kFactor = 20.0;
  double travel = 0.0;
  for (const auto& o : object) travel = std::max(travel, (o.pose.translation() - object.front().pose.translation()).norm());
  // The sensor's noise alone (|n| of a 2-D Gaussian: up to 2.5 sigma at the 95th percentile) sets
  // the percentile of a light object's stream: only a level well above it counts.
  if (p95 > std::max(kFactor * load, 5.0 * force_sigma)) {
    return Format("force: the measured forces (95th percentile %.3g N) are %.0f times the object's friction load mu_surface "
                  "m g = %.3g N, about what a quasi-static push needs: is the force in millinewtons (or the mass or "
                  "mu_surface too small)?",
                  p95, p95 / load, load);
  }
  // Low: the fifth-largest force, since a long recording may push for a few per cent of it only.
  std::vector<double> top = magnitude;
  std::nth_element(top.begin(), top.begin() + 4, top.end(), std::greater<double>());
  const double high = top[4];
  if (travel > 0.01 && high == 0.0) {
    return Format("force: the object moves %.0f mm but every measured force is exactly 0 N: is the force stream "
                  "recorded (a sensor not switched on, or the wrong columns)? Leave it out if it carries nothing",
                  1e3 * travel);
  }
  if (travel > 0.01 && high < load / kFactor) {
    return Format("force: the object moves %.0f mm but the measured forces (at most %.3g N, the fifth largest) are 1/%.0f "
                  "of its friction load mu_surface m g = %.3g N, about what a quasi-static push needs: is the force in "
                  "kilonewtons, or the mass or mu_surface too large?",
                  1e3 * travel, high, load / high, load);
  }
  // Low by a smaller factor, where the object is seen moving: the forces then are what slides
  // it, 1.0 to 1.8 times mu m g in the median on the MIT ellip1 recordings (mu_surface 0.25).
  // Their upper quartile under a quarter of the load is a force in kgf (1/9.81), or a mass or
  // mu_surface several times too large: the load factor and D then disagree with the force
  // measurements (a push in kgf: force RMS 1.27 N, NEES 673, and no warning). The object moves
  // where its pose changes by 1 cm or more over +-0.25 s (a 5 mm tracker's noise gives 7 mm).
  std::vector<double> moving;
  for (const auto& f : forces) {
    const auto a = std::lower_bound(object.begin(), object.end(), f.t - 0.25,
                                    [](const push::PoseSample& p, double t) { return p.t < t; });
    const auto b = std::lower_bound(object.begin(), object.end(), f.t + 0.25,
                                    [](const push::PoseSample& p, double t) { return p.t < t; });
    if (a == object.end() || b == object.end() || b->t - a->t < 0.4) continue;
    if ((b->pose.translation() - a->pose.translation()).norm() >= 0.01) moving.push_back(f.force.norm());
  }
  if (moving.size() >= 20) {
    std::nth_element(moving.begin(), moving.begin() + 3 * moving.size() / 4, moving.end());
    const double upper = moving[3 * moving.size() / 4];
    if (upper < 0.25 * load && upper > 3.0 * force_sigma / std::sqrt(static_cast<double>(moving.size()))) {
      return Format("force: while the object moves, three quarters of the measured forces are below %.3g N, %.2f of its "
                    "friction load mu_surface m g = %.3g N (a quasi-static push slides it with about the load): is the "
                    "force in kgf (1/9.81 of newtons), or the mass or mu_surface too large?",
                    upper, upper / load, load);
    }
    // High: quasi-static sliding needs at most the load (the limit surface bounds the friction
    // wrench; 1.0 to 1.2 times it in the lower quartile on the MIT ellip1 recordings and the
    // simulator's pushes), so three quarters of the forces above twice it are a sensor's gain, or
    // a mass or mu_surface too small (a force stream 3 or 10 times too large was estimated as it
    // stood, the 10 times blamed on the sensor's noise only).
    std::nth_element(moving.begin(), moving.begin() + moving.size() / 4, moving.end());
    const double lower = moving[moving.size() / 4];
    if (!mu_estimated && lower > 2.0 * load && lower > 2.0 * force_sigma) {
      return Format("force: while the object moves, three quarters of the measured forces are above %.3g N, %.1f times its "
                    "friction load mu_surface m g = %.3g N (mu_surface %.3g, mass %.3g kg), though quasi-static sliding "
                    "needs at most the load: is the force sensor's scale off, or the mass or mu_surface too small? The "
                    "force estimate follows the sensor's scale; \"estimate_mu\": true (batch) fits mu_surface to it",
                    lower, lower / load, load, traj.object.mu_surface, traj.object.mass);
    }
  }
  return std::nullopt;
}

namespace {

// One pose stream's glitches (DropObjectPoseGlitches), `floor` the least position bound (m); an
// empty note when it has none or more than a tenth.
// The 95th percentile of a pose stream's speed over windows of `half` to 2 `half` (0 with none).
double FastSpeed(const std::vector<push::PoseSample>& s, double half) {
  std::vector<double> speeds;
  for (std::size_t i = 0, j = 0; i < s.size(); ++i) {
    while (j + 1 < s.size() && s[j].t - s[i].t < 2.0 * half) ++j;
    if (s[j].t - s[i].t >= half) speeds.push_back((s[j].pose.translation() - s[i].pose.translation()).norm() / (s[j].t - s[i].t));
  }
  return speeds.empty() ? 0.0 : Percentile95(speeds);
}

std::vector<bool> PoseGlitches(const std::vector<push::PoseSample>& s, const char* stream, double floor, std::string* note) {
  const std::size_t n = s.size();
  if (n < 7) return {};
  const CentredGaps gaps = CentredMedianGaps(s);
  const std::vector<double>& position_gap = gaps.position;
  const std::vector<double>& angle_gap = gaps.angle;
  const double half = gaps.half;
  // A centred median cuts a sharp turn of the path by up to about v h / 2 (a finger's U-turn at
  // 0.5 m/s: 22 mm, three true samples dropped), so the floor grows with the stream's fast
  // motion: v the 95th percentile of its speed over the window's width.
  const double fast = FastSpeed(s, gaps.half);
  const double bound_p = std::max({floor, fast * gaps.half, 10.0 * gaps.Scatter(position_gap)});
  const double bound_a = std::max(0.3, 10.0 * gaps.Scatter(angle_gap));
  std::vector<bool> glitch(n);
  std::vector<double> end_position(n, 0.0), end_angle(n, 0.0);
  std::size_t count = 0, first = n;
  for (std::size_t i = 0; i < n; ++i) {
    if (gaps.judged[i]) {
      glitch[i] = position_gap[i] > bound_p || angle_gap[i] > bound_a;
    } else {
      // The stream's ends and a gap's sides (no centred window): against the median of the five
      // samples on a side that has them, allowing twice the motion across those five. A 1 m jump on the first
      // or last pose left the object 75 or 34 mm off and the shape "aligned" to follow it.
      // Only samples within 2 half-widths of it: beside an occlusion the other side of the gap
      // is where the object went meanwhile.
      auto close = [&](std::size_t k, bool after) {
        const std::size_t j = after ? i + k : i - k;
        return (after ? j < n : k <= i) && std::abs(s[j].t - s[i].t) <= 2.0 * half;
      };
      const bool after = close(5, true);
      if (!after && !close(5, false)) continue;
      std::vector<double> xs, ys, as;
      for (std::size_t k = 1; k <= 5; ++k) {
        const push::PoseSample& q = s[after ? i + k : i - k];
        xs.push_back(q.pose.x), ys.push_back(q.pose.y), as.push_back(std::remainder(q.pose.theta - s[i].pose.theta, 2.0 * M_PI));
      }
      const push::PoseSample& near = s[after ? i + 1 : i - 1];
      const push::PoseSample& far = s[after ? i + 5 : i - 5];
      const double motion = (far.pose.translation() - near.pose.translation()).norm();
      const double turn = std::abs(std::remainder(far.pose.theta - near.pose.theta, 2.0 * M_PI));
      end_position[i] = std::hypot(s[i].pose.x - Median(xs), s[i].pose.y - Median(ys));
      end_angle[i] = std::abs(Median(as));
      glitch[i] = end_position[i] > bound_p + 2.0 * motion || end_angle[i] > bound_a + 2.0 * turn;
    }
    if (glitch[i] && count++ == 0) first = i;
  }
  // More than a tenth is no glitch but the stream itself (a yaw in degrees, another unit): left
  // to the other checks and the diagnostics.
  if (count == 0 || 10 * count > n) return {};
  *note = Format("%zu %s sample%s left out as tracker glitches (more than %.3g mm or %.3g deg from the median of "
                 "their neighbours within +-%.3g s); the first: %s[%zu] at t = %.9g s, %.3g mm and %.3g deg off",
                 count, stream, count == 1 ? "" : "s", 1e3 * bound_p, bound_a * 180.0 / M_PI, half, stream, first, s[first].t,
                 1e3 * std::max(position_gap[first], end_position[first]),
                 std::max(angle_gap[first], end_angle[first]) * 180.0 / M_PI);
  return glitch;
}

}  // namespace

std::optional<push::Trajectory> DropObjectPoseGlitches(const push::Trajectory& traj, std::string* note) {
  // The object's tracker, and the finger's (a 1 m jump of one finger sample put the contact 5.5
  // mm off against 1.1 and had the shape turned by 16 degrees). A finger's centred median cuts
  // a sharp turn of its path by up to about v h / 2 (1 cm at 0.2 m/s): its floor is 2 cm.
  std::string object_note, finger_note;
  const std::vector<bool> object = PoseGlitches(traj.measured.object_pose, "object_pose", 0.01, &object_note);
  const std::vector<bool> finger = PoseGlitches(traj.measured.finger_pose, "finger_pose", 0.02, &finger_note);
  if (object_note.empty() && finger_note.empty()) return std::nullopt;
  push::Trajectory out = traj;
  auto keep = [](const std::vector<push::PoseSample>& in, const std::vector<bool>& glitch, std::vector<push::PoseSample>* kept) {
    if (glitch.empty()) return;
    kept->clear();
    for (std::size_t i = 0; i < in.size(); ++i)
      if (!glitch[i]) kept->push_back(in[i]);
  };
  if (!object_note.empty()) keep(traj.measured.object_pose, object, &out.measured.object_pose);
  if (!finger_note.empty()) keep(traj.measured.finger_pose, finger, &out.measured.finger_pose);
  *note = object_note + (object_note.empty() || finger_note.empty() ? "" : "; ") + finger_note;
  return out;
}

std::optional<std::string> TrackerStepNote(const push::Trajectory& traj) {
  // A step of the object's tracker that stays (a re-initialization, a marker swap): the samples
  // on each side agree among themselves, so the glitch test, which compares a sample with its
  // neighbours, keeps them all; the estimate then follows the step and the shape check "aligned"
  // the shape by 18 degrees to explain it (rect1 with its poses 50 mm off from the 100th on).
  // A step: between two samples the position moves by most of the difference of the medians of
  // the five samples on either side, and that difference exceeds 1 cm, ten times the tracker's
  // scatter and twice the finger's motion over those ten samples (without a finger stream, the
  // stream's own fastest motion).
  const auto& s = traj.measured.object_pose;
  const std::size_t n = s.size();
  if (n < 12) return std::nullopt;
  const CentredGaps gaps = CentredMedianGaps(s);
  const double scatter = gaps.Scatter(gaps.position);
  // The finger's motion over a time span (the median of up to five samples at each end): the
  // object moves with it while pushed, and a step of the object's tracker is not in it. Without
  // a finger stream, the object stream's own fast motion.
  const auto& fingers = traj.measured.finger_pose;
  const double fast = fingers.size() >= 5 ? 0.0 : FastSpeed(s, gaps.half);
  auto finger_at = [&](double t) {
    const auto it = std::lower_bound(fingers.begin(), fingers.end(), t, [](const push::PoseSample& a, double v) { return a.t < v; });
    const std::size_t k = static_cast<std::size_t>(it - fingers.begin());
    std::vector<double> xs, ys;
    for (std::size_t j = k >= 2 ? k - 2 : 0; j < fingers.size() && j < k + 3; ++j) xs.push_back(fingers[j].pose.x), ys.push_back(fingers[j].pose.y);
    return Vec2(Median(xs), Median(ys));
  };
  double worst = 0.0;
  std::size_t at = 0;
  for (std::size_t i = 5; i + 5 <= n; ++i) {
    std::vector<double> bx, by, ax, ay;
    for (std::size_t k = 1; k <= 5; ++k) bx.push_back(s[i - k].pose.x), by.push_back(s[i - k].pose.y);
    for (std::size_t k = 0; k < 5; ++k) ax.push_back(s[i + k].pose.x), ay.push_back(s[i + k].pose.y);
    const double jump = std::hypot(Median(ax) - Median(bx), Median(ay) - Median(by));
    const double span = s[i + 4].t - s[i - 5].t;
    const double motion = fingers.size() >= 5 ? (finger_at(s[i + 4].t) - finger_at(s[i - 5].t)).norm() : fast * span;
    const double allowed = std::max({0.01, 10.0 * scatter, 2.0 * motion});
    const double single = (s[i].pose.translation() - s[i - 1].pose.translation()).norm();
    if (jump > allowed && single > 0.7 * jump && jump > worst) worst = jump, at = i;
  }
  if (worst == 0.0) return std::nullopt;
  const double dt = s[at].t - s[at - 1].t;
  return Format("object_pose: the tracker steps by %.1f mm between samples %zu and %zu (t = %s -> %s, %.3g m/s) and "
                "stays there: a re-initialized tracker or a swapped marker, not a motion of a pushed object. The estimate "
                "follows both sides (and a shape check may turn or shift the shape to explain the step): cut the "
                "recording there, or correct one side",
                worst * 1e3, at - 1, at, StepTime(s[at - 1].t, s.front().t, "the stream's first").c_str(),
                StepTime(s[at].t, s.front().t, "its first").c_str(),
                dt > 0.0 ? worst / dt : INFINITY);
}

std::optional<std::string> YawUnitNote(const push::Trajectory& traj) {
  const auto& s = traj.measured.object_pose;
  if (s.size() < 7) return std::nullopt;
  // The yaw's scatter about its centred running median: a tracker's is below a few degrees; a yaw
  // in degrees read as radians scatters by tens of "radians".
  const CentredGaps gaps = CentredMedianGaps(s);
  if (std::count(gaps.judged.begin(), gaps.judged.end(), true) < 5) return std::nullopt;
  const double scatter = gaps.Scatter(gaps.angle);
  const double half = gaps.half;
  // The turning rate over the same windows: a pushed object turns at a few rad/s at most (a
  // 10 cm object pushed at 0.2 m/s at its edge: 4 rad/s); in degrees a slow turn reads 57 times faster.
  std::vector<double> rates;
  for (std::size_t i = 0, j = 0; i < s.size(); ++i) {
    while (j + 1 < s.size() && s[j].t - s[i].t < half) ++j;
    if (s[j].t - s[i].t >= half) rates.push_back(std::abs(std::remainder(s[j].pose.theta - s[i].pose.theta, 2.0 * M_PI)) / (s[j].t - s[i].t));
  }
  const double rate = rates.size() >= 5 ? Median(rates) : 0.0;
  double lo_t = INFINITY, hi_t = -INFINITY;
  for (const auto& p : s) lo_t = std::min(lo_t, p.pose.theta), hi_t = std::max(hi_t, p.pose.theta);
  constexpr double kMaxScatter = 0.2, kMaxRate = 8.0;  // rad (11 degrees), rad/s (1.3 turns a second)
  if (scatter < kMaxScatter && rate < kMaxRate) return std::nullopt;
  return Format("object_pose: the yaw scatters by %.3g rad (%.0f deg) about the median of its neighbours within +-%.3g s, "
                "turns at a median %.3g rad/s, and spans %.3g to %.3g: is it in degrees? Trajectory angles are in radians "
                "(a tracker's yaw noise is a few degrees at most, and a pushed object turns at a few rad/s)",
                scatter, scatter * 180.0 / M_PI, half, rate, lo_t, hi_t);
}

std::optional<std::string> ShapeSizeNote(const push::Trajectory& traj) {
  // Objects pushed on a table by a finger span centimetres to decimetres (MIT's: 9 to 16 cm); the
  // shape's reach from its centroid beyond 1 m (2 m across) is a file in centimetres or millimetres
  // from end to end: its shapes and positions agree, so no other check sees the unit, but the noise
  // model's scales (m/s^2, the 5 mm tracker sigma of the defaults) are off by 100 or 1000.
  const geometry::Shape& object = traj.object.shape;
  if (object.empty()) return std::nullopt;
  const double reach = geometry::RadiusAbout(object, geometry::CoreCentroid(object));
  if (!(reach > kTabletopReach)) return std::nullopt;
  // Positions on the shape's scale (the finger's nearest approach 0.1 to 1 object sizes, as in
  // metres): a shape file alone in millimetres against positions in metres (about 1e-3 sizes) is
  // the shape check's case, which finds its units.
  if (NearestFingerRatio(traj) < 0.02) return std::nullopt;
  // And a finger of the same scale: a probe read in centimetres reaches 0.1 "m" or more (a 2.4 m
  // box pushed by a 5 cm finger in metres was asked to divide by 100).
  const geometry::Shape& finger = traj.finger.shape;
  if (finger.empty() || !(geometry::RadiusAbout(finger, geometry::CoreCentroid(finger)) >= 0.1)) return std::nullopt;
  const bool milli = reach > 100.0 * kTabletopReach;
  return Format("object: its shape reaches %.4g m from its centroid (%.4g m across) and the finger's radius is %.3g m: is "
                "the whole file in %s? Trajectory files are in metres (shapes, positions, sigmas): a tabletop object read "
                "in %s would be %.3g cm across. The noise model's scales do not fit such a push, and the estimate may be "
                "worse than the measurements: divide every length by %d",
                reach, 2.0 * reach, traj.finger.shape.radius(), milli ? "millimetres" : "centimetres",
                milli ? "millimetres" : "centimetres", 2.0 * reach * (milli ? 0.1 : 1.0), milli ? 1000 : 100);
}

namespace {

// A whole set of files in millimetres (object and finger alike, a CAD export) has the object 1000
// times too large as well, which would hide the finger's units and frame from its checks (the
// registration finds the object's units later; ShapeSizeNote covers a trajectory file in
// millimetres throughout, positions included, which this leaves).
geometry::Shape ObjectInMetres(const geometry::Shape& object) {
  if (!object.empty() && geometry::RadiusAbout(object, geometry::CoreCentroid(object)) > 1.0)
    return geometry::TransformShape(object, geometry::Pose2(), 1e-3);
  return object;
}

// No tabletop finger's file reaches 1 m from its tracked origin: a probe in millimetres drawn
// 10 mm off its origin does not hold the push (its origin outside it) but reaches 14.7 "m"; the
// shape check then called the object's file "6.36 times the size of the finger's path".
constexpr double kFingerReach = 1.0;  // m

}  // namespace

push::Trajectory WithObjectInMetres(const push::Trajectory& traj) {
  push::Trajectory judged = traj;
  judged.object.shape = ObjectInMetres(traj.object.shape);
  return judged;
}

push::Trajectory WithObjectDelay(const push::Trajectory& traj, double delay) {
  push::Trajectory out = traj;
  std::vector<push::PoseSample>& measured = out.measured.object_pose;
  if (out.ground_truth) {
    std::vector<push::PoseSample>& truth = out.ground_truth->object_pose;
    const bool same_stamps = truth.size() == measured.size() &&
                             std::equal(truth.begin(), truth.end(), measured.begin(),
                                        [](const push::PoseSample& a, const push::PoseSample& b) { return a.t == b.t; });
    if (same_stamps && !truth.empty())
      for (push::PoseSample& s : truth) s.t -= delay;
  }
  for (push::PoseSample& s : measured) s.t -= delay;
  return out;
}

bool FingerPoseNear(const std::vector<push::PoseSample>& finger_poses, double t) {
  constexpr double kNearInTime = 0.05;  // s
  return !finger_poses.empty() && std::abs(NearestInTime(finger_poses, t).t - t) <= kNearInTime;
}

double DistanceFromFinger(const std::vector<push::PoseSample>& finger_poses, const geometry::Shape& finger, double t,
                          const geometry::Vec2& point) {
  // The finger's pose at the contact's time, interpolated (a 10 Hz tracker at 0.3 m/s moves the
  // finger 15 mm between its samples).
  const geometry::Pose2 pose = push::PoseAtClamped(finger_poses.begin(), finger_poses.end(), t);
  return std::abs(geometry::QueryPoint(finger, geometry::InverseAct(pose, point)).signed_distance);
}

std::optional<push::Trajectory> DropContactStreamsOffTheFinger(const push::Trajectory& traj,
                                                               const push::MeasurementSigmas& sigmas, std::string* note) {
  constexpr double kLeastOffset = 5e-3;  // m
  constexpr std::size_t kLeastSamples = 5;
  // Three times the two noises combined (root sum of squares): pure noise has a median of 0.67 times it.
  const double bound = std::max(kLeastOffset, 3.0 * std::hypot(sigmas.contact, sigmas.finger_trans));
  std::string said;
  // Judged on the trajectory as given; a copy is made only for a stream left out.
  auto off = [&](const std::vector<push::PoseSample>& poses, const geometry::Shape& finger,
                 const std::vector<push::PointSample>& contacts, const std::string& prefix) {
    if (poses.empty() || contacts.size() < kLeastSamples || finger.empty()) return false;
    std::vector<double> distances;
    for (const push::PointSample& c : contacts) {
      if (FingerPoseNear(poses, c.t)) distances.push_back(DistanceFromFinger(poses, finger, c.t, c.point));
    }
    if (distances.size() < kLeastSamples) return false;
    const auto mid = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
    std::nth_element(distances.begin(), mid, distances.end());
    const double median = *mid;
    if (!(median > bound)) return false;
    said += (said.empty() ? "" : "; ") +
            Format("streams.%scontact_point: its %zu samples lie a median %.1f mm from the finger's boundary (the finger "
                   "pose at their times), where the contact sensor's and the finger tracker's noise (%.3g and %.3g mm) "
                   "would put them within %.1f mm: a contact sensor in another frame than the poses' (the finger's or "
                   "the object's) or with an offset; left out of the estimate",
                   prefix.c_str(), contacts.size(), 1e3 * median, 1e3 * sigmas.contact, 1e3 * sigmas.finger_trans,
                   1e3 * bound);
    return true;
  };
  std::vector<bool> dropped{off(traj.measured.finger_pose, traj.finger.shape, traj.measured.contact_point, "")};
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    const push::ExtraFinger& f = traj.extra_fingers[k];
    dropped.push_back(off(f.measured.finger_pose, f.finger.shape, f.measured.contact_point,
                          "fingers[" + std::to_string(k + 1) + "]."));
  }
  if (said.empty()) return std::nullopt;
  push::Trajectory out = traj;
  if (dropped[0]) out.measured.contact_point.clear();
  for (std::size_t k = 0; k < out.extra_fingers.size(); ++k)
    if (dropped[k + 1]) out.extra_fingers[k].measured.contact_point.clear();
  *note = said + " (contact is then gated on the force stream, else taken as always on; a stream in the world frame "
                 "of the poses, on the finger's boundary, is used)";
  return out;
}

double ContactFaultBound(const push::MeasurementSigmas& sigmas) {
  return std::max(kContactFaultFloor, 10.0 * std::hypot(sigmas.contact, sigmas.finger_trans));
}

std::optional<push::Trajectory> DropContactRowFaults(const push::Trajectory& traj, const push::MeasurementSigmas& sigmas,
                                                     std::string* note) {
  const double bound = ContactFaultBound(sigmas);
  std::string said;
  // Rows judged against their own finger's pose near in time (FingerPoseNear), interpolated.
  auto faults = [&](const std::vector<push::PoseSample>& poses, const geometry::Shape& finger,
                    const std::vector<push::PointSample>& contacts, const std::string& prefix) {
    std::vector<bool> fault(contacts.size(), false);
    if (poses.empty() || finger.empty()) return fault;
    std::size_t count = 0, first = 0;
    double first_distance = 0.0;
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      const push::PointSample& c = contacts[i];
      if (!FingerPoseNear(poses, c.t)) continue;
      const double d = DistanceFromFinger(poses, finger, c.t, c.point);
      if (!(d > bound)) continue;
      fault[i] = true;
      if (count++ == 0) first = i, first_distance = d;
    }
    // Any number: the bound is far beyond any noise, and a stream off its finger as a whole (the
    // median beyond a much smaller bound) is DropContactStreamsOffTheFinger's, which runs first. (A
    // cap at a tenth let 36 of 251 rows moved by 5 m through: 322 mm against 2.84 mm raw.)
    if (count == 0) return fault;
    said += (said.empty() ? "" : "; ") +
            Format("%zu %scontact_point row%s left out as sensor faults (more than %.3g mm from the finger's boundary at "
                   "the finger pose of their time, ten times the contact sensor's and the finger tracker's noise "
                   "combined); the first: %scontact_point[%zu] at t = %.9g s, %.3g mm off",
                   count, prefix.c_str(), count == 1 ? "" : "s", 1e3 * bound, prefix.c_str(), first, contacts[first].t,
                   1e3 * first_distance);
    return fault;
  };
  auto keep = [](std::vector<push::PointSample>* rows, const std::vector<bool>& fault) {
    std::vector<push::PointSample> kept;
    for (std::size_t i = 0; i < rows->size(); ++i)
      if (!fault[i]) kept.push_back((*rows)[i]);
    *rows = std::move(kept);
  };
  const std::vector<bool> first = faults(traj.measured.finger_pose, traj.finger.shape, traj.measured.contact_point, "");
  std::vector<std::vector<bool>> extra;
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k) {
    const push::ExtraFinger& f = traj.extra_fingers[k];
    extra.push_back(faults(f.measured.finger_pose, f.finger.shape, f.measured.contact_point, "fingers[" + std::to_string(k + 1) + "]."));
  }
  if (said.empty()) return std::nullopt;
  push::Trajectory out = traj;
  keep(&out.measured.contact_point, first);
  for (std::size_t k = 0; k < out.extra_fingers.size(); ++k) keep(&out.extra_fingers[k].measured.contact_point, extra[k]);
  *note = said;
  return out;
}

std::optional<push::Trajectory> TessellatedFingersAsDisks(const push::Trajectory& traj, const EstimatorConfig& config,
                                                          std::string* note) {
  if (!config.tessellated_finger_as_disk) return std::nullopt;
  std::string said;
  std::optional<push::Trajectory> disks;  // copied at the first tessellated finger only
  auto replace = [&](const geometry::Shape& shape, auto&& place, const std::string& which) {
    const std::optional<geometry::TessellatedDiskFit> fit = geometry::TessellatedDisk(shape);
    if (!fit) return;
    const geometry::Vec2 centre = fit->disk.polygons()[0].outer[0];
    said += (said.empty() ? "" : "; ") +
            Format("%s: its shape is a regular %zu-gon (a tessellated cylinder): estimated as the disk of radius %.4g mm "
                   "at (%.3f, %.3f) mm it approximates",
                   which.c_str(), fit->corners, 1e3 * fit->disk.radius(), 1e3 * centre.x(), 1e3 * centre.y());
    if (!disks) disks = traj;
    place(*disks) = fit->disk;
  };
  replace(traj.finger.shape, [](push::Trajectory& t) -> geometry::Shape& { return t.finger.shape; }, "finger");
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k)
    replace(traj.extra_fingers[k].finger.shape,
            [k](push::Trajectory& t) -> geometry::Shape& { return t.extra_fingers[k].finger.shape; },
            "finger " + std::to_string(k + 1));
  if (!disks) return std::nullopt;
  // Why: a polygon's many short faces are each a local witness's feature, and its exact
  // C-obstacles are cached per relative angle.
  *note = said +
          " (as the 32-gon of the MIT tip.obj, the probe solved 6 to 13 times slower and the fixed-lag smoother drifted "
          "from the tracker on a slow push; \"tessellated_finger_as_disk\": false keeps the polygon)";
  return disks;
}

std::optional<push::Trajectory> FingerUnits(const push::Trajectory& traj, const RegistrationOptions& options,
                                            std::string* note, double* finger_scale) {
  // Judged without a copy of the trajectory first: it is made only for a finger that needs it
  // (every estimate passes here).
  const geometry::Shape object = ObjectInMetres(traj.object.shape);
  auto poses_of = [&](int index) -> const std::vector<push::PoseSample>& {
    return index == 0 ? traj.measured.finger_pose : traj.extra_fingers[index - 1].measured.finger_pose;
  };
  auto shape_of = [&](const push::Trajectory& t, int index) -> const geometry::Shape& {
    return index == 0 ? t.finger.shape : t.extra_fingers[index - 1].finger.shape;
  };
  std::vector<int> suspects;
  for (int index = 0; index <= static_cast<int>(traj.extra_fingers.size()); ++index) {
    const std::optional<FingerDepth> d = MeasureFingerDepth(shape_of(traj, index), poses_of(index), traj.measured.object_pose, object);
    if (d && (d->HoldsWholePush() || geometry::RadiusAbout(shape_of(traj, index), geometry::Vec2::Zero()) > kFingerReach))
      suspects.push_back(index);
  }
  if (suspects.empty()) return std::nullopt;
  push::Trajectory judged = traj;
  judged.object.shape = object;
  std::vector<std::string> said;
  bool scaled = false;
  for (const int index : suspects) {
    geometry::Shape& finger = index == 0 ? judged.finger.shape : judged.extra_fingers[index - 1].finger.shape;
    const auto& poses = poses_of(index);
    const std::optional<FingerDepth> as_given = MeasureFingerDepth(finger, poses, judged.measured.object_pose, object);
    const double reach = geometry::RadiusAbout(finger, geometry::Vec2::Zero());
    const std::vector<FingerReading> readings = FingerReadings(finger, poses, judged.measured.object_pose, object);
    if (readings.empty()) continue;  // refused by ValidateTrajectory, or left to the shape check
    // Which reading the contacts fit (CheckShapeFit: the finger at its radius from the object): a
    // 5 mm probe in centimetres read as a 0.5 mm one in millimetres was estimated 2.99 mm off,
    // "a finger radius 3.4 mm larger would touch". None fits (the object's own frame is off, or
    // too few contacts): millimetres, a CAD export's unit, when it is one of them.
    const geometry::Shape given = finger;
    std::optional<std::size_t> chosen;
    double best_gap = INFINITY;
    std::vector<std::string> gaps;
    for (std::size_t k = 0; k < readings.size(); ++k) {
      finger = geometry::TransformShape(given, geometry::Pose2(), readings[k].scale);
      try {
        const ShapeFitCheck check = CheckShapeFit(judged, options);
        gaps.push_back(Format("in %s %s (%s)", readings[k].unit, check.fits ? "it fits" : "it does not", check.Describe().c_str()));
        if (check.fits && check.gap_median < best_gap) best_gap = check.gap_median, chosen = k;
      } catch (const std::exception&) {
      }
    }
    const bool by_contacts = chosen.has_value();
    if (!chosen && readings.front().scale == 1e-3) chosen = 0;
    if (!chosen) {
      finger = given;
      continue;
    }
    const FingerReading& r = readings[*chosen];
    finger = geometry::TransformShape(given, geometry::Pose2(), r.scale);
    *finger_scale = r.scale;
    scaled = true;
    const std::string who = index == 0 ? "the finger's shape" : "fingers[" + std::to_string(index) + "]'s shape";
    std::string text =
        as_given->HoldsWholePush()
            ? Format("%s covers %.4g m about its origin, more than the whole push (the finger stays within %.3g m of the "
                     "object's origin)", who.c_str(), as_given->depth, as_given->farthest)
            : Format("%s reaches %.4g m from its origin, more than any finger's %.3g m", who.c_str(), reach, kFingerReach);
    text += Format(", so it is read as %s: it reaches %.4g mm from its origin (rounding radius %.4g mm)", r.unit,
                   r.reach * 1e3, finger.radius() * 1e3);
    if (readings.size() > 1) {
      if (by_contacts) {
        std::string all;
        for (const std::string& g : gaps) all += (all.empty() ? "" : "; ") + g;
        text += " (the contacts decide: " + all + ")";
      } else {
        for (std::size_t k = 1; k < readings.size(); ++k)
          text += Format(" (in %s it would reach %.3g mm: if so, pushgraph footprint FILE --scale %g)", readings[k].unit,
                         readings[k].reach * 1e3, readings[k].scale);
      }
    }
    said.push_back(text + Format(". Shape files are in metres: to save it so, pushgraph footprint FILE --scale %g -o "
                                 "finger.json (align_shape \"off\" refuses such a finger instead)", r.scale));
  }
  if (!scaled) return std::nullopt;
  if (note) {
    note->clear();
    for (const std::string& s : said) *note += (note->empty() ? "" : "; ") + s;
  }
  push::Trajectory out = traj;
  out.finger.shape = judged.finger.shape;
  for (std::size_t k = 0; k < traj.extra_fingers.size(); ++k)
    out.extra_fingers[k].finger.shape = judged.extra_fingers[k].finger.shape;
  return out;
}

std::optional<std::string> MeasurementSigmaNote(const push::Trajectory& traj, const push::MeasurementSigmas& sigma) {
  const auto& m = traj.measured;
  // How far a stream's values range: a sigma ten times beyond it (and beyond 1 cm, 1 N) leaves its
  // samples no weight at all, which no sensor's noise model means (1000 m typed for 1000 um?).
  auto span = [](const auto& samples, auto value) {
    if (samples.empty()) return 0.0;
    Eigen::Vector2d lo = value(samples.front()), hi = lo;
    for (const auto& x : samples) lo = lo.cwiseMin(value(x)), hi = hi.cwiseMax(value(x));
    return (hi - lo).norm();
  };
  const auto pose = [](const push::PoseSample& x) -> Eigen::Vector2d { return x.pose.translation(); };
  std::string found;
  auto check = [&](double value, double range, double floor, const char* name, const char* unit) {
    const double bound = 10.0 * std::max(range, floor);
    if (value > bound) {
      found += Format("%s%s %.3g %s (the stream ranges over %.3g %s)", found.empty() ? "" : ", ", name, value, unit, range, unit);
    }
  };
  if (!m.object_pose.empty()) check(sigma.object_trans, span(m.object_pose, pose), 0.01, "object_pose", "m");
  if (!m.finger_pose.empty()) check(sigma.finger_trans, span(m.finger_pose, pose), 0.01, "finger_pose", "m");
  if (!m.contact_point.empty())
    check(sigma.contact, span(m.contact_point, [](const push::PointSample& x) -> Eigen::Vector2d { return x.point; }), 0.01,
          "contact_point", "m");
  if (!m.force.empty())
    check(sigma.force, span(m.force, [](const push::ForceSample& x) -> Eigen::Vector2d { return x.force; }), 1.0, "force", "N");
  if (!m.object_pose.empty() && sigma.object_rot > 10.0)
    found += Format("%sobject_pose rotation %.3g rad", found.empty() ? "" : ", ", sigma.object_rot);
  if (found.empty()) return std::nullopt;
  return "measurement sigmas: " + found +
         ": ten times beyond the values the stream takes, its samples carry no weight in the estimate; are the sigmas "
         "in other units (metres, radians, newtons)?";
}

std::optional<std::string> TimeUnitNote(const push::Trajectory& traj, const char** unit_out) {
  const auto& m = traj.measured;
  double finest = INFINITY;
  for (double p : {MedianPeriod(m.object_pose), MedianPeriod(m.finger_pose), MedianPeriod(m.contact_point), MedianPeriod(m.force)})
    if (p > 0.0) finest = std::min(finest, p);
  // Pushing recordings sample their fastest sensor at 10 Hz or more (MIT's: 250 Hz and 100-250 Hz
  // for the tracker); 5 Hz is already an outlier, 0.25 Hz is a millisecond clock.
  constexpr double kSlowestPeriod = 0.2;  // s
  if (!(finest >= kSlowestPeriod * (1.0 - 1e-9)) || !std::isfinite(finest)) return std::nullopt;
  // The finger's net travel over the recording (a path summed sample by sample would add up noise).
  const double duration = m.finger_pose.size() > 1 ? m.finger_pose.back().t - m.finger_pose.front().t : 0.0;
  const double speed =
      duration > 0.0 ? (m.finger_pose.back().pose.translation() - m.finger_pose.front().pose.translation()).norm() / duration
                     : 0.0;
  // The unit that brings the fastest stream to 5 Hz or faster: a 250 Hz sensor stamped in
  // nanoseconds (every 4e6) was asked "are the times in microseconds?", which reads 0.25 Hz.
  double factor = 1e3;
  const char* unit = "milliseconds";
  if (finest / 1e3 > kSlowestPeriod) factor = 1e6, unit = "microseconds";
  if (finest / 1e6 > kSlowestPeriod) factor = 1e9, unit = "nanoseconds";
  // Only where the other reading is a push: a sensor of at most 20 kHz, a finger of at most 2 m/s
  // (a 4 Hz recording in seconds would read 4000 Hz and 18 m/s in milliseconds).
  if (finest / factor > kSlowestPeriod || factor / finest > 2e4 || speed * factor > 2.0) return std::nullopt;
  if (unit_out) *unit_out = unit;
  return Format("time stamps: the fastest stream is sampled every %.4g s (%.3g Hz) and the finger travels at %.3g mm/s: "
                "are the times in %s? Trajectory times are in seconds; read as %s the streams would run at %.4g Hz and "
                "the finger at %.3g mm/s. The noise model's per-second scales (accelerations, force random walk, D's "
                "per-10-ms sigma) do not fit a clock this slow, and the estimate may be worse than the measurements: "
                "divide the times by %g",
                finest, 1.0 / finest, 1e3 * speed, unit, unit, factor / finest, 1e3 * speed * factor, factor);
}

std::optional<std::string> StreamOverlapNote(const push::Trajectory& traj) {
  const auto& m = traj.measured;
  struct Span {
    const char* name;
    double first, last, period;
  };
  std::vector<Span> spans;
  // A stream of one sample has no period to judge a gap by (its own warning names it): a 0.02 s
  // push with one 25 Hz object sample was said to have its clocks offset.
  auto add = [&spans](const char* name, const auto& s) {
    if (s.size() >= 2) spans.push_back({name, s.front().t, s.back().t, MedianPeriod(s)});
  };
  add("object_pose", m.object_pose);
  add("finger_pose", m.finger_pose);
  add("contact_point", m.contact_point);
  add("force", m.force);
  // One push, recorded by sensors on one clock: every pair of streams shares some time. Streams
  // that share none were shifted against each other (a clock offset, a second recording's
  // stream): the graph then never sees the object and the finger together (a 2 s shift ran with
  // no word, object 3.4 mm against 1.35 aligned).
  for (std::size_t a = 0; a < spans.size(); ++a)
    for (std::size_t b = a + 1; b < spans.size(); ++b) {
      const Span& x = spans[a];
      const Span& y = spans[b];
      if (x.last >= y.first && y.last >= x.first) continue;
      // Within two sample periods of either stream the two only interleave (a short push).
      const double gap = std::max(y.first - x.last, x.first - y.last);
      if (gap <= 2.0 * std::max(x.period, y.period)) continue;
      return Format("streams: %s (%.6g to %.6g s) and %s (%.6g to %.6g s) share no time: one push's sensors record "
                    "together, so their clocks are probably offset (or the streams come from different recordings); "
                    "the estimate never sees them together and may be worse than the measurements",
                    x.name, x.first, x.last, y.name, y.first, y.last);
    }
  return std::nullopt;
}

// A stream 100 times as long as the object's, most of its rows outside the object's time: another
// time unit (a force stream in milliseconds beside poses in seconds lost every force with no word,
// and the estimate ran over 1100 s of an object tracked for 1.1).
void CheckStreamTimeUnits(const push::Trajectory& traj) {
  const auto& object = traj.measured.object_pose;
  if (object.size() < 2) return;
  const double t0 = object.front().t, t1 = object.back().t, span = t1 - t0;
  if (!(span > 0.0)) return;
  auto check = [&](const auto& s, const std::string& name) {
    if (s.size() < 2) return;
    const double first = s.front().t, last = s.back().t;
    const auto inside = std::count_if(s.begin(), s.end(), [&](const auto& a) { return a.t >= t0 && a.t <= t1; });
    if (last - first >= 100.0 * span && static_cast<std::size_t>(inside) * 10 < s.size())
      throw GraphError(Format("trajectory: streams.%s runs from %.6g to %.6g s, %.0f times as long as streams.object_pose "
                              "(%.6g to %.6g s), and only %zu of its %zu rows fall within the object's time: are its "
                              "time stamps in another unit (milliseconds?) than the object's?",
                              name.c_str(), first, last, (last - first) / span, t0, t1,
                              static_cast<std::size_t>(inside), s.size()));
  };
  ForEachFingerStream(traj, check);
  // The object's stream in another unit than the finger's (an object tracker in milliseconds
  // beside the rest in seconds ran over 1080 s, 23 mm off, with a hint about the finger stream).
  // Refused only when the unit is evident: divided by 1000 (or 1e6) most of its rows fall within
  // the finger's time. A long object recording around a finger tracked for a short tap is data.
  const auto& finger = traj.measured.finger_pose;
  if (finger.size() < 2 || object.size() < 3) return;
  const double f0 = finger.front().t, f1 = finger.back().t, finger_span = f1 - f0;
  if (!(finger_span > 0.0) || span < 100.0 * finger_span) return;
  const double slack = 0.1 * finger_span + 0.05;
  // (No structured binding: a lambda cannot capture one in C++17, which clang enforces.)
  for (const std::pair<double, const char*>& reading : {std::pair<double, const char*>{1e3, "milliseconds"}, {1e6, "microseconds"}}) {
    const double scale = reading.first;
    const char* unit = reading.second;
    const auto within = std::count_if(object.begin(), object.end(), [&](const push::PoseSample& a) {
      return a.t / scale >= f0 - slack && a.t / scale <= f1 + slack;
    });
    if (static_cast<double>(within) < 0.8 * static_cast<double>(object.size())) continue;
    throw GraphError(Format("trajectory: streams.object_pose runs from %.6g to %.6g s, %.0f times as long as "
                            "streams.finger_pose (%.6g to %.6g s), and divided by %g its times fall within the finger's: "
                            "are its time stamps in %s? Trajectory times are in seconds",
                            t0, t1, span / finger_span, f0, f1, scale, unit));
  }
}

// Where the object's tracker is silent for a long stretch (over 0.5 s and 10 of its periods), the
// estimated object moving much faster than its pusher: a pushed object cannot outrun the finger
// (its speed at the contact is the finger's along the normal, and it turns about a point away
// from it), so the estimate there is a local minimum of the pushing model. A hostile user's
// 1.6 s gap in a 2 cm/s push: the batch QS object slid 52 mm along its edge (0.5 m/s) to put the
// contact at a corner, 20.6 mm RMS against the tracker's 2.6, sigmas of 0.2 mm, and no word; the
// incremental mode stayed at 1.0 mm.
std::optional<std::string> UnobservedRunawayNote(const push::Trajectory& traj, const std::vector<StateEstimate>& states,
                                                        Model model, Mode mode) {
  constexpr double kSpeedRatio = 5.0, kSpeedFloor = 0.02;  // m/s
  const auto& object = traj.measured.object_pose;
  if (object.size() < 3 || states.size() < 3) return std::nullopt;
  const double gap = std::max(0.5, 10.0 * MedianPeriod(object));
  std::string said;
  for (std::size_t i = 0; i + 1 < object.size(); ++i) {
    const double a = object[i].t, b = object[i + 1].t;
    if (!(b - a > gap)) continue;
    // Speeds over at least kSpan s (a step's 4 ms would measure the estimate's own jitter).
    constexpr double kSpan = 0.04;
    auto j = std::lower_bound(states.begin(), states.end(), a, [](const StateEstimate& s, double t) { return s.t < t; });
    auto k = j;
    double object_speed = 0.0, finger_speed = 0.0, at = a;
    for (; j != states.end(); ++j) {
      if (k <= j) k = j + 1;
      while (k != states.end() && k->t < j->t + kSpan) ++k;
      if (k == states.end() || k->t > b) break;
      const double dt = k->t - j->t;
      const double v = (k->object_pose.translation() - j->object_pose.translation()).norm() / dt;
      if (v > object_speed) object_speed = v, at = j->t;
      finger_speed = std::max(finger_speed, (k->finger_pose.translation() - j->finger_pose.translation()).norm() / dt);
    }
    if (!(object_speed > kSpeedRatio * finger_speed + kSpeedFloor)) continue;
    said += Format(
        "%sbetween t = %.9g and %.9g s, where streams.object_pose has no sample, the estimated object moves at up to %.3g "
        "m/s (at t = %.9g s) while the finger moves at most %.3g m/s",
        said.empty() ? "" : "; ", a, b, object_speed, at, finger_speed);
  }
  if (said.empty()) return std::nullopt;
  std::string why;
  if (model == Model::kCp || model == Model::kSdf) {
    why = "; CP and SDF have no pushing model to hold the object's motion to the finger's there (--model qs has one)";
  } else if (mode == Mode::kBatch) {
    why = "; it is a local minimum of the pushing model (D holds the object's direction of motion, not its speed): "
          "--mode incremental, whose fixed-lag smoother follows the push through the gap, may not fall into it";
  } else {
    why = "; the fixed-lag smoother lost the object there (--mode batch solves the whole push at once)";
  }
  return "object unobserved: " + said + ": a pushed object cannot outrun its pusher, so the estimate there is wrong and its "
         "sigmas understate the error" + why + "; samples of the tracker in that stretch would settle it";
}

std::optional<std::string> StreamCoverageNote(const push::Trajectory& traj) {
  const auto& object = traj.measured.object_pose;
  if (object.size() < 3) return std::nullopt;
  const double t0 = object.front().t, t1 = object.back().t, span = t1 - t0;
  if (!(span > 0.0)) return std::nullopt;
  // The object's position over up to five samples from index `from` on (medians: tracker noise).
  auto position = [&object](std::size_t from) {
    from = std::min(from, object.size() - 1);
    std::vector<double> x, y;
    for (std::size_t i = from; i < std::min(object.size(), from + 5); ++i) x.push_back(object[i].pose.x), y.push_back(object[i].pose.y);
    std::nth_element(x.begin(), x.begin() + x.size() / 2, x.end());
    std::nth_element(y.begin(), y.begin() + y.size() / 2, y.end());
    return Vec2(x[x.size() / 2], y[y.size() / 2]);
  };
  auto first_at_or_after = [&object](double t) {
    return static_cast<std::size_t>(std::lower_bound(object.begin(), object.end(), t,
                                                     [](const auto& a, double b) { return a.t < b; }) - object.begin());
  };
  const std::size_t last5 = object.size() >= 5 ? object.size() - 5 : 0;
  constexpr double kMoves = 0.01;  // m: ten times a good tracker's noise, a tenth of a push
  auto coverage_gap = [&](const auto& s, const std::string& name, const char* without) -> std::optional<std::string> {
    if (s.size() < 2) return std::nullopt;
    const double first = s.front().t, last = s.back().t;
    // A sensor that stopped (or started late) while the object moved: force RMS 0.07 -> 0.23 N
    // with a force stream cut halfway, and no word.
    if (last < t1) {
      const std::size_t from = first_at_or_after(last);
      const double moved = (position(last5) - position(from)).norm();
      if (from < last5 && moved > kMoves)
        return Format("streams.%s ends at t = %.6g s, and the object moves %.0f mm after that (streams.object_pose "
                      "goes on to %.6g s): %s there",
                      name.c_str(), last, 1e3 * moved, t1, without);
    }
    if (first > t0) {
      const std::size_t to = first_at_or_after(first);
      const double moved = (position(to >= 5 ? to - 5 : 0) - position(0)).norm();
      if (to >= 5 && moved > kMoves)
        return Format("streams.%s starts at t = %.6g s, and the object moves %.0f mm before that (streams.object_pose "
                      "from %.6g s): %s there",
                      name.c_str(), first, 1e3 * moved, t0, without);
    }
    return std::nullopt;
  };
  std::optional<std::string> note;
  // Pose and force streams (a contact stream has rows only while touching).
  auto check = [&](const auto& s, const std::string& name) {
    using Sample = typename std::decay_t<decltype(s)>::value_type;
    if constexpr (!std::is_same_v<Sample, push::PointSample>) {
      if (!note) note = coverage_gap(s, name, std::is_same_v<Sample, push::ForceSample>
                                                 ? "the forces come from the pushing model alone"
                                                 : "the finger's path rests on the contacts and the motion prior");
    }
  };
  ForEachFingerStream(traj, check);
  return note;
}

double LongObjectGap(const push::Trajectory& trajectory) {
  const auto& poses = trajectory.measured.object_pose;
  if (poses.size() < 2) return INFINITY;
  return std::max(3.0 * MedianPeriod(poses), 0.1);
}

}  // namespace pushgraph::graph::internal
