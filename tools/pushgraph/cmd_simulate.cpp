// pushgraph simulate -o OUT.json [options]: a quasi-static push (finger along a straight line
// or waypoints at constant speed) of an object on a table, written as a pushgraph-trajectory-1
// file with ground truth and noisy measured streams (docs/simulator.md). Prints a one-object
// JSON summary (contact time, sticking/sliding steps, max penetration, load residual).
#include "cli_common.h"

#include <pushgraph/evaluation/plots.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/limit_surface/support.h>
#include <pushgraph/push/simulator.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

namespace pushgraph::cli {
namespace {


struct SimulateOptions {
  std::string output;
  std::string object_path = DefaultDataDir() + "/shapes/notched_block.json";
  std::string finger_path = DefaultDataDir() + "/shapes/disk_finger_5mm.json";
  double mass = 0.5;
  double mu_surface = 0.3;
  double mu_contact = 0.4;
  std::string surface = "exact";
  std::string object_pose = "0,0,0";
  double push_angle = M_PI / 2;
  double offset = 0.01;
  double standoff = 0.005;
  double distance = 0.05;
  std::string waypoints;
  double speed = 0.05;
  double duration = 0.0;
  double rate_object = 25.0, rate_finger = 250.0, rate_contact = 250.0, rate_force = 250.0;
  double internal_step = 1e-3;
  std::uint64_t seed = 1;
  std::string noise = "gaussian";
  std::string sigma_object, sigma_finger, sigma_contact, sigma_force;
  std::vector<std::string> occlusions;
  std::string occlusion_mode = "stop";
  double occlusion_scale = 10.0;
  double outliers = 0.0;
  std::vector<std::string> frozen;
  bool no_ground_truth = false;
  std::vector<std::string> finger_paths;  // --fingers: several fingers at the pusher's pose
  bool multi_contact = false;
  std::string svg;  // --svg: a picture of the push
};

void Positive(double value, const std::string& name) {
  if (!std::isfinite(value) || !(value > 0.0)) throw CliError(name + " must be a finite number > 0 (got " + FormatDouble(value) + ")");
}
void NonNegative(double value, const std::string& name) {
  if (!std::isfinite(value) || value < 0.0) throw CliError(name + " must be a finite number >= 0 (got " + FormatDouble(value) + ")");
}

std::vector<geometry::Vec2> ParseWaypoints(const std::string& text) {
  std::vector<geometry::Vec2> points;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ';')) {
    const std::vector<double> v = ParseNumbers(item, 2, "--waypoints (X,Y;X,Y;...)");
    points.emplace_back(v[0], v[1]);
  }
  if (points.size() < 2) throw CliError("--waypoints needs at least 2 points X,Y;X,Y (got '" + text + "')");
  return points;
}

std::pair<double, double> ParseWindow(const std::string& text, const std::string& what) {
  const std::vector<double> v = ParseNumbers(text, 2, what + " (T0,T1)");
  if (v[1] < v[0]) throw CliError(what + " " + text + ": T1 must be >= T0");
  return {v[0], v[1]};
}

void Run(const SimulateOptions& o) {
  std::vector<NamedPath> inputs{{"--object", o.object_path}, {"--finger", o.finger_path}};
  for (const std::string& path : o.finger_paths) inputs.push_back({"--fingers", path});
  CheckOutputsAreNew(inputs, {{"-o", o.output}, {"--svg", o.svg}});
  if (o.finger_paths.size() == 1)
    throw CliError("--fingers needs two or more finger files (one finger: --finger FILE, with --multi-contact for "
                   "all its contacts)");
  push::PushPlan plan;
  Positive(o.mass, "--mass");
  Positive(o.mu_surface, "--mu-surface");
  // estimate's force models (qs, yu) refuse a friction load below 1 mN (graph_builder.cpp): said
  // here, where the file is made (cp can still estimate it).
  if (const double load = o.mu_surface * o.mass * limit_surface::kStandardGravity; load < 1e-3) {
    std::cerr << "simulate: warning: the friction load mu_surface m g = " << FormatDouble(load)
              << " N is below the 1 mN that estimate's force models (qs, yu) support: is --mass in kg?\n";
  }
  NonNegative(o.mu_contact, "--mu-contact");
  Positive(o.speed, "--speed");
  NonNegative(o.duration, "--duration");
  Positive(o.standoff, "--standoff");
  Positive(o.distance, "--distance");
  Positive(o.internal_step, "--internal-step");
  if (!std::isfinite(o.push_angle)) throw CliError("--push-angle must be finite");
  if (!std::isfinite(o.offset)) throw CliError("--offset must be finite");
  NonNegative(o.rate_object, "--rate-object");
  NonNegative(o.rate_finger, "--rate-finger");
  NonNegative(o.rate_contact, "--rate-contact");
  NonNegative(o.rate_force, "--rate-force");
  if (!std::isfinite(o.outliers) || o.outliers < 0.0 || o.outliers > 1.0)
    throw CliError("--outliers must be a probability in [0, 1] (got " + FormatDouble(o.outliers) + ")");
  NonNegative(o.occlusion_scale, "--occlusion-scale");

  plan.object.shape = LoadShapeArgument(o.object_path, "--object");
  WarnShapeUnits(plan.object.shape, "--object", o.object_path);
  plan.object.mass = o.mass;
  plan.object.mu_surface = o.mu_surface;
  plan.finger = {LoadShapeArgument(o.finger_paths.empty() ? o.finger_path : o.finger_paths[0],
                                   o.finger_paths.empty() ? "--finger" : "--fingers"),
                 o.mu_contact};
  for (std::size_t i = 1; i < o.finger_paths.size(); ++i)
    plan.extra_fingers.push_back({LoadShapeArgument(o.finger_paths[i], "--fingers"), o.mu_contact});
  plan.multi_contact = o.multi_contact;
  plan.surface = o.surface == "ellipsoid" ? push::SurfaceModel::kEllipsoid : push::SurfaceModel::kExact;
  plan.object_pose = ParsePose(o.object_pose, "--object-pose");
  plan.speed = o.speed;
  plan.duration = o.duration;
  plan.rates = {o.rate_object, o.rate_finger, o.rate_contact, o.rate_force};
  plan.internal_step = o.internal_step;
  plan.seed = o.seed;

  const push::NoiseKind kind = o.noise == "none"       ? push::NoiseKind::kNone
                             : o.noise == "bimodal" ? push::NoiseKind::kBimodal
                                                    : push::NoiseKind::kGaussian;
  plan.noise = push::DefaultNoise(kind);
  if (kind == push::NoiseKind::kNone) {
    for (const auto& [flag, value] : {std::pair{"--sigma-object", &o.sigma_object}, {"--sigma-finger", &o.sigma_finger},
                                      {"--sigma-contact", &o.sigma_contact}, {"--sigma-force", &o.sigma_force}})
      if (!value->empty())
        throw CliError(std::string(flag) + " " + *value + " is given with --noise none, which adds no noise: drop it or "
                       "choose --noise gaussian or bimodal");
  }
  // Noise up to 1 m, 10 rad, 1e6 N: beyond, the samples leave the range that estimate reads
  // (positions within 1e6 m), so the file written could not be used (1e300 was written).
  auto set_sigma = [&](const std::string& text, push::StreamNoise& stream, bool with_angle, double max_value,
                       const std::string& what) {
    if (text.empty()) return;
    const std::vector<double> v = ParseNumbers(text, with_angle ? 2 : 1, what);
    for (std::size_t k = 0; k < v.size(); ++k) {
      NonNegative(v[k], what);
      const double bound = k == 0 ? max_value : 10.0;
      if (v[k] > bound)
        throw CliError(what + ": " + FormatDouble(v[k]) + " is beyond the supported " + FormatDouble(bound) +
                       (k == 0 ? (max_value == 1.0 ? " m" : " N") : " rad"));
    }
    stream.position.sigma = v[0];
    if (with_angle) stream.angle.sigma = v[1];
  };
  set_sigma(o.sigma_object, plan.noise.object_pose, true, 1.0, "--sigma-object (M,RAD)");
  set_sigma(o.sigma_finger, plan.noise.finger_pose, false, 1.0, "--sigma-finger (M)");
  set_sigma(o.sigma_contact, plan.noise.contact_point, false, 1.0, "--sigma-contact (M)");
  set_sigma(o.sigma_force, plan.noise.force, false, 1e6, "--sigma-force (N)");
  if (!o.occlusions.empty() && o.occlusion_mode == "degrade" && o.occlusion_scale != 1.0 && o.noise != "none") {
    // One sigma per stream cannot say that a window is noisier: the file's is the object's outside
    // the windows, and an estimate trusting it inside was overconfident (object NEES 626).
    std::fprintf(stderr,
                 "simulate: note: --occlusion-mode degrade: inside the windows the object's noise is %g times the "
                 "measurement_sigmas the file records (one sigma per stream); estimates trusting them there are "
                 "overconfident: estimate with a robust object loss, --config with {\"losses\": {\"object_pose\": "
                 "{\"type\": \"cauchy\", \"scale\": 2}}}\n",
                 o.occlusion_scale);
  }
  for (const std::string& text : o.occlusions) {
    const auto [t0, t1] = ParseWindow(text, "--occlusion");
    plan.noise.occlusions.push_back({t0, t1, o.occlusion_mode == "degrade" ? push::OcclusionMode::kDegrade
                                                                            : push::OcclusionMode::kStop,
                                     o.occlusion_scale});
  }
  for (const std::string& text : o.frozen) {
    const auto [t0, t1] = ParseWindow(text, "--frozen-force");
    plan.noise.frozen_force.push_back({t0, t1, std::nullopt});
  }
  if (o.outliers > 0.0) {
    // Outliers: 2 cm / 0.5 rad jumps of the tracker, 1 cm contact or finger glitches, 1 N spikes.
    plan.noise.object_pose.outlier_probability = o.outliers;
    plan.noise.object_pose.outlier_magnitude = 0.02;
    plan.noise.object_pose.outlier_angle = 0.5;
    plan.noise.finger_pose.outlier_probability = o.outliers;
    plan.noise.finger_pose.outlier_magnitude = 0.01;
    plan.noise.contact_point.outlier_probability = o.outliers;
    plan.noise.contact_point.outlier_magnitude = 0.01;
    plan.noise.force.outlier_probability = o.outliers;
    plan.noise.force.outlier_magnitude = 1.0;
  }

  plan.waypoints = o.waypoints.empty() ? push::StraightPushPath(plan, o.push_angle, o.offset, o.standoff, o.distance)
                                       : ParseWaypoints(o.waypoints);
  const push::SimulationResult result = push::Simulate(plan);
  push::Trajectory trajectory = result.trajectory;
  if (o.no_ground_truth) trajectory.ground_truth.reset();
  // --occlusion windows (stop mode) over the whole push leave nothing that anchors the object,
  // which estimate refuses: said here, before a file that cannot be estimated is written.
  // A push shorter than two sample periods of every stream (--speed 50 typed for mm/s: 5 cm in
  // 1 ms) writes one sample per stream, which no estimate can use.
  const std::size_t most = std::max({trajectory.measured.object_pose.size(), trajectory.measured.finger_pose.size(),
                                     trajectory.measured.contact_point.size(), trajectory.measured.force.size()});
  if (most < 3) {
    throw CliError("the push is sampled at most " + std::to_string(most) + " time(s) per stream: it ends within two "
                   "sample periods of every stream (--speed " + FormatDouble(o.speed) +
                   " m/s; is it in m/s?), or every stream is disabled (--rate-* 0)");
  }
  if (trajectory.measured.object_pose.empty() && !o.occlusions.empty() && o.rate_object > 0.0) {
    throw CliError("every object pose sample falls inside an --occlusion window (stop mode): the file would have no "
                   "object poses, which estimate needs; shorten the windows or use --occlusion-mode degrade");
  }
  // What the file will not support, said as it is written (it was said only by estimate).
  if (trajectory.measured.object_pose.empty())
    std::fprintf(stderr, "pushgraph: warning: simulate: %s has no object poses (--rate-object 0): pushgraph estimate "
                         "refuses it, since nothing else anchors the object\n", o.output.c_str());
  // The simulator is quasi-static (no inertia): faster than about 0.5 m/s a real tabletop object
  // no longer follows it (mu g = 3 m/s^2 stops a 1 m/s slide within 17 cm).
  if (o.speed > 0.5)
    std::fprintf(stderr, "pushgraph: warning: simulate: --speed %s m/s: the quasi-static model ignores inertia, which "
                         "a real object pushed this fast does not (tabletop pushes are 1 to 300 mm/s)\n",
                 FormatDouble(o.speed).c_str());
  io::SaveTrajectoryJson(trajectory, o.output);
  if (!o.svg.empty()) {
    evaluation::PushPlotOptions picture;
    picture.title = "simulated push: " + std::to_string(push::FingerCount(trajectory)) + " finger(s)" +
                    (plan.multi_contact || !plan.extra_fingers.empty() ? ", every contact" : "");
    evaluation::WriteSvgFile(o.svg, evaluation::PushSvg(trajectory, picture));
  }

  const push::SimulationStats& s = result.stats;
  // The simulator's own last state (the object stream may be disabled, --rate-object 0).
  const geometry::Pose2 end = result.states.empty() ? plan.object_pose : result.states.back().object_pose;
  nlohmann::json out;
  out["output"] = o.output;
  out["surface"] = push::ToString(plan.surface);
  out["duration"] = result.states.empty() ? 0.0 : result.states.back().t;
  out["steps"] = s.steps;
  out["sticking_steps"] = s.sticking_steps;
  out["sliding_steps"] = s.sliding_steps;
  out["separated_steps"] = s.separated_steps;
  out["contact_time"] = s.contact_time;
  out["max_penetration"] = s.max_penetration;
  out["max_gap_in_contact"] = s.max_gap_in_contact;
  out["max_torque_residual"] = s.max_torque_residual;
  out["final_object_pose"] = {end.x, end.y, end.theta};
  out["fingers"] = push::FingerCount(trajectory);
  out["multi_contact"] = plan.multi_contact || !plan.extra_fingers.empty();
  std::size_t most_contacts = 0;
  for (const push::SimulationState& state : result.states)
    if (state.contacts) most_contacts = std::max(most_contacts, state.contacts->contacts.size());
  if (plan.multi_contact || !plan.extra_fingers.empty()) out["max_simultaneous_contacts"] = most_contacts;
  // Rows in the file: every finger's (fingers 1, 2, ... too), as the file holds them.
  std::size_t finger_rows = trajectory.measured.finger_pose.size(), contact_rows = trajectory.measured.contact_point.size(),
              force_rows = trajectory.measured.force.size();
  for (const push::ExtraFinger& f : trajectory.extra_fingers) {
    finger_rows += f.measured.finger_pose.size();
    contact_rows += f.measured.contact_point.size();
    force_rows += f.measured.force.size();
  }
  out["samples"] = {{"object_pose", trajectory.measured.object_pose.size()},
                    {"finger_pose", finger_rows},
                    {"contact_point", contact_rows},
                    {"force", force_rows}};
  std::cout << DumpJson(out) << "\n";
}

}  // namespace

void RegisterSimulate(CLI::App& app) {
  auto o = std::make_shared<SimulateOptions>();
  auto* cmd = app.add_subcommand("simulate", "Simulate a quasi-static push and write a trajectory file");
  cmd->add_option("-o,--output", o->output, "Trajectory JSON file to write (pushgraph-trajectory-1)")->required();
  cmd->add_option("--object", o->object_path, "Object shape JSON or OBJ mesh (also the support region; uniform pressure)")
      ->capture_default_str();
  auto* finger = cmd->add_option("--finger", o->finger_path, "Finger shape JSON or OBJ mesh (any shape)")->capture_default_str();
  cmd->add_option("--fingers", o->finger_paths,
                  "Two or more finger shape JSON files moving together (instead of --finger): every finger has the "
                  "pusher's pose, placed by its own shape coordinates; all contacts of all fingers are modelled")
      ->excludes(finger);
  cmd->add_flag("--multi-contact", o->multi_contact,
                "Model every contact of the finger (a finger wedged in a notch touches both walls; a flat "
                "pusher face touches along a segment) instead of the nearest one");
  cmd->add_option("--mass", o->mass, "Object mass in kg (> 0)")->check(MassValue())->capture_default_str();
  cmd->add_option("--mu-surface", o->mu_surface, "Object-table friction coefficient (> 0)")
      ->check(FrictionValue(false))
      ->capture_default_str();
  cmd->add_option("--mu-contact", o->mu_contact, "Finger-object friction coefficient (>= 0)")
      ->check(FrictionValue(true))
      ->capture_default_str();
  cmd->add_option("--surface", o->surface, "Limit surface model: exact or ellipsoid (the paper's Eq. 3)")
      ->check(CLI::IsMember({"exact", "ellipsoid"}))
      ->capture_default_str();
  cmd->add_option("--object-pose", o->object_pose, "Initial object pose X,Y,THETA (m, m, rad), world")
      ->capture_default_str();
  cmd->add_option("--push-angle", o->push_angle, "Straight push: direction of the finger's motion (rad, world)")
      ->capture_default_str();
  cmd->add_option("--offset", o->offset,
                  "Straight push: the push line passes this far (m) to the left of the object's centroid")
      ->capture_default_str();
  cmd->add_option("--standoff", o->standoff, "Straight push: the finger starts this far (m) from the object")
      ->capture_default_str();
  cmd->add_option("--distance", o->distance, "Straight push: finger travel (m) after reaching the object")
      ->capture_default_str();
  cmd->add_option("--waypoints", o->waypoints,
                  "Finger path X,Y;X,Y;... (world, m) instead of the straight push; the finger starts at the first");
  cmd->add_option("--speed", o->speed, "Finger speed along the path (m/s, > 0)")->capture_default_str();
  cmd->add_option("--duration", o->duration, "Simulated time (s); 0: the time to travel the path")
      ->capture_default_str();
  cmd->add_option("--rate-object", o->rate_object, "Object pose stream rate (Hz; 0 disables)")->capture_default_str();
  cmd->add_option("--rate-finger", o->rate_finger, "Finger pose stream rate (Hz; 0 disables)")->capture_default_str();
  cmd->add_option("--rate-contact", o->rate_contact, "Contact point stream rate (Hz; 0 disables)")
      ->capture_default_str();
  cmd->add_option("--rate-force", o->rate_force, "Force stream rate (Hz; 0 disables)")->capture_default_str();
  cmd->add_option("--internal-step", o->internal_step, "Largest integration step (s)")->capture_default_str();
  AddSeedOption(cmd, &o->seed, "Noise seed (same seed, same file)");
  cmd->add_option("--noise", o->noise,
                  "Measurement noise: gaussian, bimodal (mixture of two triangular densities, same sigma) or none")
      ->check(CLI::IsMember({"gaussian", "bimodal", "none"}))
      ->capture_default_str();
  cmd->add_option("--sigma-object", o->sigma_object, "Object pose noise M,RAD (default 0.002,0.02)");
  cmd->add_option("--sigma-finger", o->sigma_finger, "Finger position noise M (default 0.0005)");
  cmd->add_option("--sigma-contact", o->sigma_contact, "Contact point noise M (default 0.001)");
  cmd->add_option("--sigma-force", o->sigma_force, "Force noise N per axis (default 0.05)");
  cmd->add_option("--occlusion", o->occlusions, "Occlude the object stream during T0,T1 (s); repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--occlusion-mode", o->occlusion_mode,
                  "stop: no object samples in the window; degrade: noise times --occlusion-scale")
      ->check(CLI::IsMember({"stop", "degrade"}))
      ->capture_default_str();
  cmd->add_option("--occlusion-scale", o->occlusion_scale, "Noise multiplier for --occlusion-mode degrade")
      ->capture_default_str();
  cmd->add_option("--outliers", o->outliers,
                  "Outlier probability per sample, every stream (object 2 cm + 0.5 rad, finger/contact 1 cm, force 1 N)")
      ->capture_default_str();
  cmd->add_option("--frozen-force", o->frozen, "Force sensor stuck at its last reading during T0,T1 (s); repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--no-ground-truth", o->no_ground_truth, "Leave the ground_truth streams out of the file");
  cmd->add_option("--svg", o->svg,
                  "Also draw the push (ground truth: footprints, every finger, contact point and finger force)");
  cmd->footer(
      "Quasi-static pushing with point contact and Coulomb friction (sticking/sliding by motion cones),\n"
      "exact limit surface unless --surface ellipsoid. Default job: the 5 mm disk finger pushes\n"
      "data/shapes/notched_block.json (0.5 kg) 5 cm along +y, 1 cm left of its centroid, at 5 cm/s.\n"
      "Streams: object 25 Hz, finger/contact/force 250 Hz. Prints a JSON summary; see docs/simulator.md.\n"
      "Several contacts (--fingers, --multi-contact): the file lists \"fingers\" and finger rows carry\n"
      "the finger's index after the time; contact_point has a row per contact (docs/formats.md).");
  cmd->callback([o] { Run(*o); });
}

}  // namespace pushgraph::cli
