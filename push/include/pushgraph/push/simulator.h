#pragma once
// A quasi-static push simulator: a finger following a piecewise-linear path at constant speed
// pushes a sliding object (pushing.h); the result is a Trajectory with ground truth and
// measured streams, each sampled at its own rate (Lambert et al.: object 25 Hz, finger and
// force 250 Hz), measured = ground truth + noise (noise.h).
//
//   using namespace pushgraph;
//   push::PushPlan plan;
//   plan.object = {geometry::Shape::Box(0.09, 0.09), /*mass=*/0.8374, /*mu_surface=*/0.25};
//   plan.finger = {geometry::Shape::Disk(0.00235), /*mu_contact=*/0.3};
//   plan.waypoints = push::StraightPushPath(plan, M_PI / 2, /*offset=*/0.01,
//                                                    /*standoff=*/0.005, /*push=*/0.05);
//   plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
//   push::SimulationResult r = push::Simulate(plan);
//   io::SaveTrajectoryJson(r.trajectory, "push.json");
//
// Integration: the finger moves along its path in steps of at most internal_step seconds and
// max_step_length metres, cut at every sample time of every stream so that samples are exact
// states (no interpolation). Each step is PushingModel::Step: contact made by conservative
// advancement, quasi-static twist, penetration pushed out. The force and contact samples at
// time t are the model's instantaneous answer for the finger's velocity just after t.
#include <pushgraph/push/errors.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/multi_contact.h>
#include <pushgraph/push/pushing.h>
#include <pushgraph/push/trajectory.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace pushgraph::push {

/// Sample rates (Hz) of the four streams; 0 disables a stream.
struct StreamRates {
  double object_pose = 25.0;
  double finger_pose = 250.0;
  double contact_point = 250.0;
  double force = 250.0;
};

struct PushPlan {
  ObjectDescription object;        ///< shape = support region
  FingerDescription finger;
  SurfaceModel surface = SurfaceModel::kExact;
  geometry::Pose2 object_pose;     ///< initial pose of the object's shape frame (world)
  double finger_theta = 0.0;       ///< the finger's (constant) orientation
  /// Finger reference-point path (world): at least 2 points; the finger starts at the first.
  std::vector<Vec2> waypoints;
  double speed = 0.05;             ///< m/s along the path, > 0
  /// Simulated time (s); <= 0: the time to travel the path. The finger rests after the path ends.
  double duration = 0.0;
  StreamRates rates;
  double internal_step = 1e-3;     ///< s, > 0
  double max_step_length = 2e-4;   ///< m, > 0: finger travel per internal step at most this
  double contact_tolerance = 1e-6; ///< m (PushingSpec::contact_tolerance, MultiPushingSpec's)
  double penetration_tolerance = 1e-10;  ///< m (PushingSpec::penetration_tolerance)
  NoiseModel noise;                ///< default: no noise
  std::uint64_t seed = 1;
  /// More fingers moving with the first (a hand with several fingers, two arms, ...): every
  /// finger has the pusher's pose (the path point, finger_theta), so place each one by its
  /// shape's own coordinates (e.g. Shape::Disk(r, {0, 0.02})). Fingers must not overlap.
  std::vector<FingerDescription> extra_fingers;
  /// Every contact of every finger (MultiPushingModel: a finger wedged in a notch touches both
  /// walls, a flat pusher face touches along a segment). On whenever extra_fingers is not empty;
  /// off: one contact, the nearest (PushingModel).
  bool multi_contact = false;
};

/// A straight push: the finger starts at separation `standoff` (m) from the object on the line
/// with direction angle `push_angle` (world) through the object's centroid shifted sideways by
/// `offset` (to the left of the push direction), travels along it to first contact, and then
/// `push_distance` further. Returns the two waypoints.
/// Uses plan.object, plan.finger, plan.object_pose and plan.finger_theta. Throws
/// LimitSurfaceError when the line misses the object or the finger starts in contact.
std::vector<Vec2> StraightPushPath(const PushPlan& plan, double push_angle, double offset, double standoff,
                                   double push_distance);

/// The state at one sample time.
struct SimulationState {
  double t = 0.0;
  geometry::Pose2 object_pose;
  geometry::Pose2 finger_pose;
  /// For the finger's velocity just after t (separated when at rest); response.twist is then
  /// the object's body velocity (m/s, m/s, rad/s of the centre of pressure, shape axes).
  PushResponse response;
  /// Multi-contact runs: every contact with its mode and force. `response` then summarizes it
  /// (the twist and load, finger 0's net force, the first contact's point, normal and mode).
  std::optional<MultiPushResponse> contacts;
};

struct SimulationStats {
  int steps = 0;
  int sticking_steps = 0;
  int sliding_steps = 0;
  int separated_steps = 0;
  double max_penetration = 0.0;      ///< deepest overlap at the end of any step (m)
  double max_gap_in_contact = 0.0;   ///< largest positive separation at the end of a pushing step (m)
  double max_torque_residual = 0.0;  ///< largest PushResponse::torque_residual
  double contact_time = 0.0;         ///< s spent pushing (sticking or sliding)
};

struct SimulationResult {
  Trajectory trajectory;                 ///< measured streams + ground_truth
  std::vector<SimulationState> states;   ///< every distinct sample time of any stream, in order
  SimulationStats stats;
};

/// Validates the plan (throws LimitSurfaceError naming the field) and runs it.
SimulationResult Simulate(const PushPlan& plan);

/// The finger's path position at arc length s (clamped to the path), and the path's length.
Vec2 PathPoint(const std::vector<Vec2>& waypoints, double s);
double PathLength(const std::vector<Vec2>& waypoints);

}  // namespace pushgraph::push
