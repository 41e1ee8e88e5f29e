// Quasi-static push simulator (see simulator.h and docs/simulator.md).
#include <pushgraph/push/errors.h>
#include <pushgraph/push/simulator.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

namespace pushgraph::push {
using namespace limit_surface;
namespace {

using geometry::Pose2;

void Require(bool ok, const std::string& message) {
  if (!ok) throw PushError("PushPlan." + message);
}

void ValidatePlan(const PushPlan& p) {
  Require(!p.object.shape.empty(), "object.shape is empty");
  Require(!p.finger.shape.empty(), "finger.shape is empty");
  Require(std::isfinite(p.speed) && p.speed > 0.0, "speed must be finite and > 0 (got " + std::to_string(p.speed) + ")");
  Require(std::isfinite(p.duration), "duration must be finite");
  Require(std::isfinite(p.internal_step) && p.internal_step > 0.0, "internal_step must be finite and > 0");
  Require(std::isfinite(p.max_step_length) && p.max_step_length > 0.0, "max_step_length must be finite and > 0");
  Require(std::isfinite(p.object_pose.x) && std::isfinite(p.object_pose.y) && std::isfinite(p.object_pose.theta),
          "object_pose must be finite");
  Require(std::isfinite(p.finger_theta), "finger_theta must be finite");
  Require(p.waypoints.size() >= 2, "waypoints needs at least 2 points (got " + std::to_string(p.waypoints.size()) + ")");
  for (std::size_t i = 0; i < p.waypoints.size(); ++i)
    Require(p.waypoints[i].allFinite(), "waypoints[" + std::to_string(i) + "] is not finite");
  Require(PathLength(p.waypoints) > 0.0, "waypoints: the path has zero length");
  const double rates[] = {p.rates.object_pose, p.rates.finger_pose, p.rates.contact_point, p.rates.force};
  const char* names[] = {"object_pose", "finger_pose", "contact_point", "force"};
  for (int i = 0; i < 4; ++i)
    Require(std::isfinite(rates[i]) && rates[i] >= 0.0,
            std::string("rates.") + names[i] + " must be finite and >= 0 (got " + std::to_string(rates[i]) + ")");
  ValidateNoise(p.noise);
  for (std::size_t i = 0; i < p.extra_fingers.size(); ++i)
    Require(!p.extra_fingers[i].shape.empty(), "extra_fingers[" + std::to_string(i) + "].shape is empty");
  // Fingers move together at one pose: they must not overlap each other.
  std::vector<const FingerDescription*> fingers{&p.finger};
  for (const FingerDescription& f : p.extra_fingers) fingers.push_back(&f);
  for (std::size_t i = 0; i < fingers.size(); ++i)
    for (std::size_t j = i + 1; j < fingers.size(); ++j) {
      const double sd = geometry::ShapePairQuerier(fingers[i]->shape, fingers[j]->shape).Query({}, {}).signed_distance;
      // Touching each other is allowed (they move together); inside each other is not.
      Require(sd >= 0.0, "fingers " + std::to_string(i) + " and " + std::to_string(j) +
                             " overlap each other (" + std::to_string(-1e3 * sd) + " mm inside each other at the pusher's pose)");
    }
}

// All fingers of the plan (finger 0 first).
std::vector<FingerDescription> AllFingers(const PushPlan& p) {
  std::vector<FingerDescription> fingers{p.finger};
  fingers.insert(fingers.end(), p.extra_fingers.begin(), p.extra_fingers.end());
  return fingers;
}

// The multi-contact answer summarized as a single-contact response (SimulationState::response).
PushResponse Summarize(const MultiPushResponse& r) {
  PushResponse out;
  out.touching = r.touching;
  out.twist = r.twist;
  out.load = r.load;
  out.force = r.finger_force.empty() ? Vec2::Zero() : r.finger_force[0];
  out.torque_residual = r.wrench_residual;
  if (!r.contacts.empty()) {
    out.contact_point = r.contacts[0].point;
    out.contact_normal = r.contacts[0].normal;
    out.separation = r.contacts[0].separation;
  }
  if (r.moving) {
    // The step's mode: sliding if any contact slides, else sticking if any sticks.
    out.mode = ContactMode::kSeparated;
    for (const ContactState& c : r.contacts) {
      if (c.mode == ContactMode::kSliding) out.mode = ContactMode::kSliding;
      if (c.mode == ContactMode::kSticking && out.mode == ContactMode::kSeparated) out.mode = ContactMode::kSticking;
    }
  }
  return out;
}

// Direction of the path just after arc length s; zero once the path has ended.
Vec2 PathDirection(const std::vector<Vec2>& w, double s) {
  double acc = 0.0;
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    const double len = (w[i + 1] - w[i]).norm();
    // A waypoint reached up to rounding counts as passed (the direction just after it).
    if (len > 0.0 && s < acc + len - 1e-12 * (1.0 + acc + len)) return (w[i + 1] - w[i]) / len;
    acc += len;
  }
  return Vec2::Zero();
}

}  // namespace

double PathLength(const std::vector<Vec2>& waypoints) {
  double length = 0.0;
  for (std::size_t i = 0; i + 1 < waypoints.size(); ++i) length += (waypoints[i + 1] - waypoints[i]).norm();
  return length;
}

Vec2 PathPoint(const std::vector<Vec2>& w, double s) {
  if (w.empty()) throw PushError("PathPoint: no waypoints");
  double acc = 0.0;
  for (std::size_t i = 0; i + 1 < w.size(); ++i) {
    const double len = (w[i + 1] - w[i]).norm();
    if (len > 0.0 && s <= acc + len) {
      const double a = std::max(0.0, (s - acc) / len);
      return w[i] + a * (w[i + 1] - w[i]);
    }
    acc += len;
  }
  return w.back();
}

std::vector<Vec2> StraightPushPath(const PushPlan& plan, double push_angle, double offset, double standoff,
                                   double push_distance) {
  if (!std::isfinite(push_angle)) throw PushError("StraightPushPath: push_angle must be finite");
  if (!std::isfinite(offset)) throw PushError("StraightPushPath: offset must be finite");
  if (!std::isfinite(standoff) || standoff <= 0.0) throw PushError("StraightPushPath: standoff must be > 0");
  if (!std::isfinite(push_distance) || push_distance <= 0.0)
    throw PushError("StraightPushPath: push_distance must be > 0");
  if (plan.object.shape.empty() || plan.finger.shape.empty()) throw PushError("StraightPushPath: empty object or finger");
  SupportSpec area_spec;
  area_spec.region = plan.object.shape;
  area_spec.mass = 1.0;
  area_spec.mu = 1.0;
  const Vec2 centroid = geometry::Act(plan.object_pose, MakeSupport(area_spec).centroid);
  const Vec2 u(std::cos(push_angle), std::sin(push_angle));
  const Vec2 left(-u.y(), u.x());
  const geometry::Box2 ob = plan.object.shape.bounds();
  geometry::Box2 fb = plan.finger.shape.bounds();
  for (const FingerDescription& f : plan.extra_fingers) {
    if (f.shape.empty()) continue;
    fb.min = fb.min.cwiseMin(f.shape.bounds().min);
    fb.max = fb.max.cwiseMax(f.shape.bounds().max);
  }
  const double reach = (ob.max - ob.min).norm() + (fb.max - fb.min).norm() + fb.max.norm() + fb.min.norm() +
                       (plan.object_pose.translation() - centroid).norm() + standoff + 0.01;
  const Vec2 start_far = centroid + offset * left - reach * u;
  std::vector<geometry::ShapePairQuerier> queriers;
  for (const FingerDescription& f : AllFingers(plan)) {
    if (f.shape.empty()) throw PushError("StraightPushPath: empty finger");
    queriers.emplace_back(plan.object.shape, f.shape);
  }
  // The separation of the nearest finger (all fingers share the pusher's pose).
  struct {
    const std::vector<geometry::ShapePairQuerier>& queriers;
    double Query(const Pose2& object, const Pose2& pusher) const {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& q : queriers) best = std::min(best, q.Query(object, pusher).signed_distance);
      return best;
    }
  } nearest{queriers};
  // Conservative advancement along +u until the separation equals the standoff.
  double travelled = 0.0;
  for (int iteration = 0; iteration < 100000; ++iteration) {
    const Vec2 p = start_far + travelled * u;
    const double sd = nearest.Query(plan.object_pose, Pose2{p.x(), p.y(), plan.finger_theta});
    if (sd - standoff <= 1e-12) {
      if (sd < 0.5 * standoff) throw PushError("StraightPushPath: the finger would start in contact");
      // The travel to first contact along u (longer than the separation when the line meets
      // the boundary obliquely or in a notch): advance further until touching.
      const Vec2 start = p;
      double to_contact = 0.0, gap = sd;
      for (int k = 0; k < 100000 && gap > 1e-13; ++k) {
        to_contact += gap;
        if (to_contact > 2.0 * reach) break;
        const Vec2 q = start + to_contact * u;
        gap = nearest.Query(plan.object_pose, Pose2{q.x(), q.y(), plan.finger_theta});
      }
      if (gap > 1e-9)
        throw PushError("StraightPushPath: the push line (angle " + std::to_string(push_angle) + " rad, offset " +
                                std::to_string(offset) + " m) misses the object");
      return {start, start + (to_contact + push_distance) * u};
    }
    travelled += sd - standoff;
    if (travelled > 2.0 * reach)
      throw PushError("StraightPushPath: the push line (angle " + std::to_string(push_angle) + " rad, offset " +
                              std::to_string(offset) + " m) misses the object");
  }
  throw PushError("StraightPushPath: no convergence to the standoff distance");
}

SimulationResult Simulate(const PushPlan& plan) {
  ValidatePlan(plan);
  const std::vector<FingerDescription> fingers = AllFingers(plan);
  const std::size_t finger_count = fingers.size();
  const bool multi = plan.multi_contact || finger_count > 1;
  PushingSpec spec;
  spec.object = plan.object;
  spec.finger = plan.finger;
  spec.surface = plan.surface;
  spec.contact_tolerance = plan.contact_tolerance;
  spec.penetration_tolerance = plan.penetration_tolerance;
  const PushingModel model(spec);
  std::optional<MultiPushingModel> multi_model;
  if (multi) {
    MultiPushingSpec m;
    m.object = plan.object;
    m.fingers = fingers;
    m.surface = plan.surface;
    m.contact_tolerance = plan.contact_tolerance;
    m.penetration_tolerance = plan.penetration_tolerance;
    multi_model.emplace(std::move(m));
  }

  const double path_length = PathLength(plan.waypoints);
  const double duration = plan.duration > 0.0 ? plan.duration : path_length / plan.speed;
  // Bounds checked in doubles before any count is cast (a 1e17 m push overflowed the cast and
  // passed the sample check, then integrated forever). A state costs about 1.5 kB: 1e6 samples of
  // one stream (66 min at 250 Hz) is 1.5 GB; 1e8 integration steps take minutes.
  constexpr double kMaxStreamSamples = 1e6, kMaxIntegrationSteps = 1e8;
  const double step_time = std::min(plan.internal_step, plan.max_step_length / plan.speed);
  if (!(duration / step_time <= kMaxIntegrationSteps)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "PushPlan: a %.3g s push in steps of %.3g s is more than 1e8 integration steps (shorten the push or "
                  "enlarge internal_step / max_step_length)",
                  duration, step_time);
    throw PushError(text);
  }

  // Sample times of every stream: t_k = k / rate, exact doubles shared by the integrator.
  enum : unsigned { kObject = 1, kFinger = 2, kContact = 4, kForce = 8 };
  std::map<double, unsigned> samples;
  auto add_stream = [&](double rate, unsigned bit) {
    if (rate <= 0.0) return;
    const double samples_in_stream = std::floor(duration * rate + 1e-9);
    if (!(samples_in_stream <= kMaxStreamSamples)) {
      char text[200];
      std::snprintf(text, sizeof text, "PushPlan.rates: a %.3g s push at %.3g Hz is more than 1e6 samples in one stream",
                    duration, rate);
      throw PushError(text);
    }
    const long long count = static_cast<long long>(samples_in_stream);
    for (long long k = 0; k <= count; ++k) samples[std::min(duration, static_cast<double>(k) / rate)] |= bit;
  };
  add_stream(plan.rates.object_pose, kObject);
  add_stream(plan.rates.finger_pose, kFinger);
  add_stream(plan.rates.contact_point, kContact);
  add_stream(plan.rates.force, kForce);

  SimulationResult result;
  Trajectory& traj = result.trajectory;
  traj.object = plan.object;
  traj.finger = plan.finger;
  Streams truth;
  std::vector<FingerStreams> extra_truth(finger_count - 1);

  const Vec2 start = PathPoint(plan.waypoints, 0.0);
  Pose2 object = plan.object_pose;
  Pose2 finger{start.x(), start.y(), plan.finger_theta};
  for (std::size_t i = 0; i < finger_count; ++i) {
    const double initial_separation =
        geometry::ShapePairQuerier(plan.object.shape, fingers[i].shape).Query(object, finger).signed_distance;
    if (initial_separation < -plan.contact_tolerance)
      throw PushError("PushPlan: " + (finger_count > 1 ? "finger " + std::to_string(i) : std::string("the finger")) +
                      " starts inside the object (separation " + std::to_string(initial_separation) + " m)");
  }
  auto poses = [&](const Pose2& f) { return std::vector<Pose2>(finger_count, f); };
  auto motions = [&](const Vec2& d) { return std::vector<Vec2>(finger_count, d); };
  auto separation_of = [&](const Pose2& o, const Pose2& f) {
    return multi ? multi_model->Separation(o, poses(f)) : model.querier().Query(o, f).signed_distance;
  };
  SimulationStats& stats = result.stats;

  auto record = [&](double t, unsigned streams) {
    const double s = std::min(plan.speed * t, path_length);
    const Vec2 direction = s < path_length ? PathDirection(plan.waypoints, s) : Vec2::Zero();
    SimulationState state{t, object, finger, {}, std::nullopt};
    if (multi) {
      state.contacts = multi_model->Respond(object, poses(finger), motions(plan.speed * direction));
      state.response = Summarize(*state.contacts);
    } else {
      state.response = model.Respond(object, finger, plan.speed * direction);
    }
    if (streams & kObject) truth.object_pose.push_back({t, object});
    if (streams & kFinger) {
      truth.finger_pose.push_back({t, finger});
      for (FingerStreams& e : extra_truth) e.finger_pose.push_back({t, finger});
    }
    if (streams & kContact) {
      if (multi) {
        // Every contact, one row each (a finger wedged in a notch: two rows at this time).
        for (const ContactState& c : state.contacts->contacts) {
          if (c.finger == 0) truth.contact_point.push_back({t, c.point});
          else extra_truth[c.finger - 1].contact_point.push_back({t, c.point});
        }
      } else if (state.response.touching) {
        truth.contact_point.push_back({t, state.response.contact_point});
      }
    }
    if (streams & kForce) {
      truth.force.push_back({t, multi ? state.contacts->finger_force[0] : state.response.force});
      for (std::size_t k = 1; k < finger_count; ++k) extra_truth[k - 1].force.push_back({t, state.contacts->finger_force[k]});
    }
    result.states.push_back(state);
  };

  double t = 0.0;
  auto next_sample = samples.begin();
  if (next_sample != samples.end() && next_sample->first <= 0.0) {
    record(0.0, next_sample->second);
    ++next_sample;
  }
  while (t < duration) {
    double t_next = std::min(t + step_time, duration);
    bool at_sample = false;
    if (next_sample != samples.end() && next_sample->first <= t_next) {
      t_next = next_sample->first;
      at_sample = true;
    }
    const Vec2 p0 = PathPoint(plan.waypoints, std::min(plan.speed * t, path_length));
    const Vec2 p1 = PathPoint(plan.waypoints, std::min(plan.speed * t_next, path_length));
    const Vec2 displacement = p1 - p0;
    // Follow the path exactly: the finger's reference point is put back on the path
    // (Step moves it by the same displacement; this removes floating-point drift).
    ContactMode mode;
    double residual;
    if (multi) {
      MultiPushStep step;
      try {
        step = multi_model->Step(object, poses(finger), motions(displacement));
      } catch (const PushError& e) {
        throw PushError("PushPlan: at t = " + std::to_string(t) + " s: " + e.what());
      }
      object = step.object_pose;
      const PushResponse summary = Summarize(step.response);
      mode = summary.mode;
      residual = std::max(step.response.wrench_residual, step.response.kinematic_residual);
    } else {
      const PushStep step = model.Step(object, finger, displacement);
      object = step.object_pose;
      mode = step.response.mode;
      residual = step.response.torque_residual;
    }
    finger = {p1.x(), p1.y(), plan.finger_theta};
    ++stats.steps;
    switch (mode) {
      case ContactMode::kSticking: ++stats.sticking_steps; break;
      case ContactMode::kSliding: ++stats.sliding_steps; break;
      case ContactMode::kSeparated: ++stats.separated_steps; break;
    }
    const double separation = separation_of(object, finger);
    stats.max_penetration = std::max(stats.max_penetration, -separation);
    if (mode != ContactMode::kSeparated) {
      stats.contact_time += t_next - t;
      stats.max_gap_in_contact = std::max(stats.max_gap_in_contact, separation);
      stats.max_torque_residual = std::max(stats.max_torque_residual, residual);
    }
    t = t_next;
    if (at_sample) {
      record(t, next_sample->second);
      ++next_sample;
    }
  }
  for (const SimulationState& s : result.states)
    stats.max_torque_residual = std::max(stats.max_torque_residual, s.response.torque_residual);

  traj.measured = ApplyNoise(truth, plan.noise, plan.seed);
  traj.measurement_sigmas = SigmasOf(plan.noise);
  for (std::size_t k = 0; k + 1 < finger_count; ++k) {
    // Each finger's own sensors: the finger's streams with the plan's noise, their own seed.
    const FingerStreams& e = extra_truth[k];
    const Streams noisy = ApplyNoise(Streams{{}, e.finger_pose, e.contact_point, e.force}, plan.noise,
                                     plan.seed + 0x9E3779B97F4A7C15ull * (k + 1));
    traj.extra_fingers.push_back({fingers[k + 1], {noisy.finger_pose, noisy.contact_point, noisy.force}, e});
  }
  traj.ground_truth = std::move(truth);
  return result;
}

}  // namespace pushgraph::push
