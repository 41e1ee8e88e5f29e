#include "contact_fit.h"
#include "graph_builder.h"
#include "text.h"

#include <ceres/normal_prior.h>

#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/marginals.h>
#include <pushgraph/graph/shape_frame.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>
#include <pushgraph/push/scoring.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <memory>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <sstream>
#include <tuple>

namespace pushgraph::graph {

Model ParseModel(const std::string& name) {
  if (name == "cp") return Model::kCp;
  if (name == "sdf") return Model::kSdf;
  if (name == "qs") return Model::kQs;
  if (name == "yu") return Model::kYu;
  throw GraphError("unknown model '" + name + "' (expected cp, sdf, qs or yu)");
}

std::string ModelName(Model model) {
  switch (model) {
    case Model::kCp: return "cp";
    case Model::kSdf: return "sdf";
    case Model::kQs: return "qs";
    case Model::kYu: return "yu";
  }
  return "?";
}

Mode ParseMode(const std::string& name) {
  if (name == "batch") return Mode::kBatch;
  if (name == "incremental") return Mode::kIncremental;
  throw GraphError("unknown mode '" + name + "' (expected batch or incremental)");
}

std::string ModeName(Mode mode) { return mode == Mode::kBatch ? "batch" : "incremental"; }

bool ModelHasForce(Model model) { return model == Model::kQs || model == Model::kYu; }

QuasiStaticGeometry QuasiStaticGeometryFor(const push::Trajectory& traj,
                                           const EstimatorConfig& cfg) {
  QuasiStaticGeometry g;
  if (traj.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  const geometry::Shape& shape = traj.object.shape;
  limit_surface::RegionGeometry s;
  try {
    s = limit_surface::RegionGeometryOf(shape, traj.object.pressure);
  } catch (const std::exception& first) {
    // Rounded polygons are not supported by the limit-surface module: use the core polygons.
    if (shape.radius() > 0.0 && !shape.is_degenerate_core()) {
      s = limit_surface::RegionGeometryOf(shape.WithRadius(0.0), traj.object.pressure);
    } else if (cfg.c > 0.0) {
      s.c = cfg.c;
    } else {
      throw GraphError(std::string("cannot compute the limit surface of the object (set config 'c'): ") +
                       first.what());
    }
  }
  // c = tau_max / f_max is the support's mean distance from its centre of pressure (weighted by
  // the pressure), so no pressure makes it longer than the object's reach from that centre: a
  // given c beyond it is another unit (`{"c": 100}` ran as 100 m).
  const double reach = geometry::RadiusAbout(shape, s.centre_of_pressure);
  if (cfg.c > reach * (1.0 + 1e-9))
    throw GraphError(internal::Format("config: c = %.6g m is longer than the object reaches from its centre of pressure "
                                      "(%.3g m); c = tau_max / f_max is a mean distance of the support from that centre, "
                                      "at most that reach: is it in another unit than metres?",
                                      cfg.c, reach));
  g.c = (cfg.c > 0.0 ? cfg.c : s.c) * cfg.c_scale;
  g.centre_of_pressure = s.centre_of_pressure;
  return g;
}


namespace {

// The shape frame as a static variable of the batch graph (shape_frame.h).
struct FrameSetup {
  Vec2 centroid = Vec2::Zero();  // of the aligned shape, object frame
  double sigma_centroid = 0.01, sigma_theta = 0.2;
  bool rotation = true;
  // Held at its start until the rest has converged, then freed from there (the estimate itself;
  // the placement comparisons free it from the start: their margins were set on those solves).
  bool hold_first = false;
  Pose2 frame;                   // out: the estimate
  std::optional<Eigen::Matrix3d> covariance;  // out
};

// `warm`: the states to start from (an estimate of the same trajectory), instead of the staged
// start from the measurements.
EstimationResult EstimateBatch(const push::Trajectory& traj, Model model, const EstimatorConfig& cfg,
                               FrameSetup* frame = nullptr,
                               std::shared_ptr<const geometry::ShapePairQuerier> querier = nullptr,
                               const EstimationResult* warm = nullptr) {
  internal::GraphBuilder builder(traj, model, cfg, std::move(querier));
  if (frame) builder.EnableShapeFrame(frame->centroid, frame->sigma_centroid, frame->sigma_theta, frame->rotation);
  if (cfg.estimate_c) builder.EnableCEstimation();
  if (cfg.estimate_mu) builder.EnableMuEstimation();
  const int n = static_cast<int>(builder.steps().size());
  const auto start = std::chrono::steady_clock::now();
  auto owned = std::make_unique<ceres::Problem>();
  for (int i = 0; i < n; ++i) builder.Initialize(i, INFINITY);
  int stage_iterations = 0;
  if (warm != nullptr && static_cast<int>(warm->states.size()) == n) {
    for (int i = 0; i < n; ++i) builder.SetState(i, warm->states[i]);
    builder.SetSharedParameters(warm->c, warm->mu);
    for (int i = 0; i < n; ++i) builder.AddFactors(*owned, i, internal::GraphBuilder::kAll);
  } else {
    builder.CarryObjectThroughGaps();
    // One builder, one shape querier, the staging the incremental mode uses too.
    stage_iterations = builder.StageSteps(*owned, 0, n, cfg.max_iterations, cfg.function_tolerance, "batch solve");
  }
  // The shape frame held at its start until the rest has converged, then freed from there: free
  // from the start, it drifted while the contacts were still far from their solution (a real
  // ellip1 push, the true mesh, align_shape "on", CP: the frame 53 mm off, 300 iterations to a
  // cost of 879.6 against 794.2 with the frame held), and a refinement must not end above the
  // placement it starts from.
  double* frame_block = builder.frame_block();
  if (frame != nullptr && frame->hold_first && frame_block != nullptr) {
    owned->SetParameterBlockConstant(frame_block);
    stage_iterations +=
        builder.Solve(*owned, cfg.max_iterations, cfg.function_tolerance, "batch solve, shape frame held").iterations;
    owned->SetParameterBlockVariable(frame_block);
  }
  internal::SolveOutcome summary = builder.Solve(*owned, cfg.max_iterations, cfg.function_tolerance, "batch solve");
  // Contact features fixed at the start that the solution no longer touches: the graph again
  // with the features at the solution (GraphBuilder::FeatureChoicesChanged).
  // Without a contact stream, the steps' contact counts follow the geometry at the solution too.
  for (int round = 0; round < 3 && builder.DetectSecondContacts(0, n) + builder.FeatureChoicesChanged() > 0; ++round) {
    stage_iterations += summary.iterations;
    owned = std::make_unique<ceres::Problem>();
    builder.StartNewProblem();
    for (int i = 0; i < n; ++i) builder.AddFactors(*owned, i, internal::GraphBuilder::kAll);
    summary = builder.Solve(*owned, cfg.max_iterations, cfg.function_tolerance, "batch solve, contact features re-chosen");
  }
  ceres::Problem& problem = *owned;
  EstimationResult r;
  r.model = model;
  r.mode = Mode::kBatch;
  std::vector<int> idx(n);
  for (int i = 0; i < n; ++i) {
    idx[i] = i;
    r.states.push_back(builder.State(i));
  }
  if (cfg.covariance) {
    Eigen::Matrix3d frame_cov = Eigen::Matrix3d::Zero();
    r.solver.covariance_status =
        internal::ComputeCovariances(problem, builder, idx, r.states, cfg.covariance_method, &r, frame ? &frame_cov : nullptr,
                                     summary.chain.get());
    if (frame && r.solver.covariance_status == "ok") frame->covariance = frame_cov;
  }
  if (frame) frame->frame = builder.frame();
  if (ModelHasForce(model)) r.c = builder.c();
  r.c_estimated = builder.c_block() != nullptr;
  if (model == Model::kQs && builder.uses_load_factor()) r.mu = builder.mu();
  r.mu_estimated = builder.mu_block() != nullptr;
  r.c_at_bound = builder.c_at_bound();
  r.mu_at_bound = builder.mu_at_bound();
  if (r.c_at_bound) r.c_sigma.reset();
  if (r.mu_at_bound) r.mu_sigma.reset();
  r.solver.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.solver.iterations = stage_iterations + summary.iterations;
  r.solver.final_cost = summary.final_cost;
  r.solver.name = cfg.solver == EstimatorConfig::Solver::kCeres ? "ceres" : "chain";
  r.solver.evaluation_time_s = summary.evaluation_s;
  r.solver.linear_solve_time_s = summary.linear_solve_s;
  r.solver.factor_flops = summary.factor_flops;
  r.solver.stalled = summary.stalled;
  r.solver.at_iteration_limit = !summary.converged && !summary.stalled;
  if (!summary.converged) {
    // Ceres and the chain solver both say "iteration limit" in their own words: said once.
    const bool at_limit = summary.termination.find("iteration") != std::string::npos;
    // max_iterations bounds each stage (motion only, contacts, the full model); the result's
    // iterations are their sum.
    if (summary.stalled) {
      // The chain solver's stall: a residual that jumps next to the start held every state where
      // it began (an L-shaped finger's forces stayed at their measurements, force RMS 0.74 N
      // against 0.73 raw, with no word).
      r.warnings.push_back("the batch solve's last stage " + summary.termination +
                           "; the states may be left near their starting values (--mode incremental, or another "
                           "finger_angle_resolution, may get past it)");
    } else {
      r.warnings.push_back("the batch solve's last stage stopped at its iteration limit (" + std::to_string(cfg.max_iterations) +
                           " per stage) before converging" + (at_limit ? std::string(" (max_iterations in the config raises it)")
                                                             : ": " + summary.termination));
    }
  }
  r.solver.updates = 1;
  r.solver.max_update_time_s = r.solver.mean_update_time_s = r.solver.time_s;
  builder.DropUnobservableForces(r);
  r.metrics = ComputeMetrics(traj, r.states);
  return r;
}
}  // namespace


namespace {

// `pushgraph footprint` options for a file's units and mirror ("--mirror --scale 0.001"; empty
// when neither), and with the placement after them.
std::string UnitsText(const ShapeTransform& t) {
  std::string s = t.mirrored ? "--mirror" : "";
  if (t.scale != 1.0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "--scale %.6g", t.scale);
    s += (s.empty() ? "" : " ") + std::string(buf);
  }
  return s;
}

// A transform of units (scale, mirror) only: no turn or shift to save.
bool UnitsOnly(const ShapeTransform& t) { return t.pose.x == 0.0 && t.pose.y == 0.0 && t.pose.theta == 0.0; }

std::string TransformText(const ShapeTransform& t) {
  const std::string units = UnitsText(t);
  if (UnitsOnly(t) && !units.empty()) return units;
  char buf[128];
  std::snprintf(buf, sizeof buf, "--transform %.6g,%.6g,%.6g", t.pose.x, t.pose.y, t.pose.theta);
  return units.empty() ? buf : units + " " + buf;
}

// "aligned it: turned by ... (to save it: pushgraph footprint SHAPE_FILE ...)". A file whose
// units (or mirror) were wrong often comes back with a small turn and shift too, within their
// sigmas: saving those bakes an error into the file that later recordings then accept (a rect1
// mesh in millimetres came back turned by 12 degrees, which the saved file kept), so the units
// alone are offered as well.
std::string AlignedText(const RegistrationResult& registration, const ShapeAlignment& alignment) {
  RegistrationResult final_transform = registration;
  final_transform.transform = alignment.transform;
  final_transform.sigma = alignment.settled ? alignment.sigma : Eigen::Vector3d::Zero();
  const ShapeTransform& t = alignment.transform;
  const Eigen::Vector3d& sigma = alignment.sigma;
  std::string s = "aligned it: " + final_transform.Describe();
  // The curvature's sigmas describe the chosen placement alone; where others fit about as well
  // they read as certainty (the notched block turned by 30 degrees "aligned" by -125 degrees with
  // "sigma 1.5 deg, 0.8 and 0.4 mm").
  if (!alignment.settled) s += " (not settled: " + alignment.unsettled_by + ")";
  // Placements the whole graph fits as well: the sigmas above are the curvature at the chosen
  // one and do not show them (rect2 given in millimetres, one sticking push: turned by -88.7
  // degrees "sigma 1.0 deg", with turns of 35 and 63 degrees within 2 in cost; the truth is 0).
  if (!alignment.ties.empty()) {
    s += "; the whole graph fits it about as well";
    for (std::size_t k = 0; k < alignment.ties.size() && k < 3; ++k) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s turned by %.1f deg, shifted by (%.1f, %.1f) mm", k == 0 ? "" : ",",
                    alignment.ties[k].pose.theta * 180.0 / M_PI, alignment.ties[k].pose.x * 1e3, alignment.ties[k].pose.y * 1e3);
      s += buf;
    }
    s += ": this recording does not settle the placement";
  } else if (registration.ambiguous) {
    // The contacts alone leave several placements open (one stretch of the outline touched), and
    // the graph's preference among them is no proof: the notched block turned by 30 degrees, on a
    // simulated 5 cm push, was "aligned" by -125 degrees, the graph's cost 459 there against 557
    // for the true shape. Estimates stay close to the data either way; the frame is what is open.
    s += "; ambiguous: " + registration.ambiguity + ": this recording does not settle the placement, check the shape file's frame";
  }
  // Contacts along one side fix the placement across it only: rect1's mesh at twice its size, or
  // rect3's, was "aligned" on a rect1 recording with contact gaps of 0.14 mm, as the true mesh.
  if (registration.weak_directions.size() >= 2) {
    // Two directions are the whole plane ("along (-1.00, 0.02) or (-0.02, -1.00)" read as a
    // contradiction beside the sigmas, which are the prior's and the mechanics').
    s += "; the contacts fix its position in no direction (a prior on the centroid does, with the pushing mechanics), "
         "and a shape of another size or object would fit them as well";
  } else if (!registration.weak_directions.empty()) {
    s += "; the contacts do not fix its position along (object frame)";
    for (std::size_t k = 0; k < registration.weak_directions.size(); ++k) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s (%.2f, %.2f)", k == 0 ? "" : " or", registration.weak_directions[k].x(),
                    registration.weak_directions[k].y());
      s += buf;
    }
    s += " (a prior on the centroid does), and a shape of another size or object would fit them as well";
  }
  s += " (to save it: pushgraph footprint SHAPE_FILE " + TransformText(t);
  const bool turn_within = !alignment.rotation_observable || std::abs(t.pose.theta) <= 3.0 * sigma.z();
  const bool shift_within = std::abs(t.pose.x) <= 3.0 * sigma.x() && std::abs(t.pose.y) <= 3.0 * sigma.y();
  if (!UnitsText(t).empty() && !UnitsOnly(t) && ((turn_within && shift_within) || !alignment.ties.empty())) {
    s += alignment.ties.empty() ? "; the turn and shift are within three sigmas of none" : "; the turn and shift are unsettled";
    s += ": if the file's frame is otherwise right, pushgraph footprint SHAPE_FILE " + UnitsText(t) + " alone";
  }
  return s + ")";
}

}  // namespace

namespace {

// A force no sensor of this push could have measured (a corrupted byte: 1e5 N in a 1 kg push):
// above 50 times the larger of the stream's 95th percentile and the object's friction limit
// mu m g (when known), and above 1 N. Quasi-static pushing needs at most about f_max; the
// factor leaves room for impacts and miscalibration. Returns the trajectory without them, or
// nullopt when there is none; `note` says how many, the first one and the bound.
std::optional<push::Trajectory> DropForceSpikes(const push::Trajectory& traj, std::string* note) {
  const auto& forces = traj.measured.force;
  if (forces.size() < 8) return std::nullopt;
  std::vector<double> magnitude(forces.size());
  for (std::size_t i = 0; i < forces.size(); ++i) magnitude[i] = forces[i].force.norm();
  const double bound = internal::ForceFaultBound(internal::Percentile95(magnitude), traj.object);
  push::Trajectory out = traj;
  out.measured.force.clear();
  int dropped = 0;
  std::size_t first = 0;
  for (std::size_t i = 0; i < forces.size(); ++i) {
    if (magnitude[i] > bound) {
      if (dropped++ == 0) first = i;
      continue;
    }
    out.measured.force.push_back(forces[i]);
  }
  if (dropped == 0) return std::nullopt;
  char text[320];
  std::snprintf(text, sizeof text,
                "%d force sample%s left out as sensor faults (|f| above %.3g N, 50 times the stream's 95th percentile "
                "or the object's friction limit); the first: force[%zu] at t = %.9g s, |f| = %.3g N",
                dropped, dropped == 1 ? "" : "s", bound, first, forces[first].t, magnitude[first]);
  *note = text;
  return out;
}

// A finger file whose pose origin lies outside its shape, or a disk finger off its origin. Its
// poses are then taken as that origin's, which a marker beside the tip can be; but a tracker of
// the tip's centre with a probe mesh drawn 10 mm off its axis had the object estimated 2.11 mm
// off against 1.23 mm (rect1), the misfit blamed on the object's frame, the finger's unnamed.
// When the contacts fit the finger centred on its origin, and not as given or clearly closer
// (graph::CheckShapeFit, both), "auto" estimates with it centred and says so; otherwise a note
// says where the shape lies when the origin is outside it. Finger 0 only.
std::optional<push::Trajectory> CentredFinger(const push::Trajectory& traj, const EstimatorConfig& config,
                                              std::string* note, geometry::Vec2* shift) {
  const geometry::Shape& finger = traj.finger.shape;
  if (finger.empty() || config.align_shape == EstimatorConfig::AlignShape::kOff) return std::nullopt;
  const double outside = geometry::QueryPoint(finger, geometry::Vec2::Zero()).signed_distance;
  constexpr double kOutside = 1e-3;  // m: beyond a file's rounding and a tessellated disk's facets
  const geometry::Vec2 centre = geometry::CoreCentroid(finger);
  // A disk 3 mm off its origin (of 4.7 mm radius): the ellip1 push estimated 1.43 mm off against 1.09.
  const bool off_centre_disk = finger.num_vertices() == 1 && finger.radius() > 0.0 && centre.norm() > kOutside;
  if (!(outside > kOutside) && !off_centre_disk) return std::nullopt;
  const geometry::Vec2 to_centre = -centre + geometry::Vec2::Zero();  // + 0: no "-0" in the command printed
  const geometry::Shape centred_shape =
      geometry::TransformShape(finger, geometry::Pose2{to_centre.x(), to_centre.y(), 0.0});
  std::optional<ShapeFitCheck> given, moved;
  try {
    const RegistrationOptions options = RegistrationOptionsFor(config);
    // Judged against the object in metres: with a CAD export in millimetres of both, neither
    // reading fitted, and the probe drawn 10 mm off was estimated 1.98 mm off against 0.95 mm.
    push::Trajectory judged = internal::WithObjectInMetres(traj);
    given = CheckShapeFit(judged, options);
    judged.finger.shape = centred_shape;
    moved = CheckShapeFit(judged, options);
  } catch (const std::exception&) {
    // Too few contacts to judge: the note alone.
  }
  // Or both fit, centred clearly better: a probe drawn 10 mm off along the pushed side of rect1
  // left a 2.9 mm median gap (tolerance 3.4 mm), 1.1 mm centred, and was estimated 1.52 mm off
  // against 0.95 mm. A marker's poses beside the tip fit as given and worse centred.
  constexpr double kClearlyCloser = 1e-3;  // m, and half the gap as given
  const bool closer = given && moved && moved->gap_median < 0.5 * given->gap_median &&
                      given->gap_median - moved->gap_median > kClearlyCloser;
  const bool use = config.align_shape == EstimatorConfig::AlignShape::kAuto && given && moved && moved->fits &&
                   (!given->fits || closer);
  std::string text =
      outside > kOutside
          ? internal::Format("finger: its shape lies %.1f mm outside its pose origin (centred at (%.1f, %.1f) mm in the "
                             "finger's frame), so streams.finger_pose is taken as a point %.1f mm beside the finger",
                             outside * 1e3, centre.x() * 1e3, centre.y() * 1e3, outside * 1e3)
          : internal::Format("finger: its disk is centred at (%.1f, %.1f) mm in the finger's frame, so streams.finger_pose "
                             "is taken as a point %.1f mm off its centre",
                             centre.x() * 1e3, centre.y() * 1e3, centre.norm() * 1e3);
  if (use) {
    text += internal::Format(
        "; the contacts %s it so (%s) and fit the finger centred on the tracked point (%s): estimated with "
        "it centred (RESULT.json parameters.finger_transform; to save it: pushgraph footprint FILE --transform "
        "%.6g,%.6g,0 -o finger.json; align_shape \"off\" keeps the file's frame)",
        given->fits ? "fit" : "do not fit", given->Describe().c_str(), moved->Describe().c_str(), to_centre.x(),
        to_centre.y());
    *shift = to_centre;
  } else {
    text += internal::Format(
        ". If the tracker reports the finger's centre, centre the file (pushgraph footprint FILE --transform %.6g,%.6g,0 "
        "-o finger.json)%s",
        to_centre.x(), to_centre.y(),
        given && moved ? internal::Format("; as given the contacts %s it (%s), centred they %s it (%s)",
                                          given->fits ? "fit" : "do not fit", given->Describe().c_str(),
                                          moved->fits ? "fit" : "do not fit", moved->Describe().c_str()).c_str()
                       : "");
  }
  if (use || outside > kOutside) *note = text;
  if (!use) return std::nullopt;
  push::Trajectory centred = traj;
  centred.finger.shape = centred_shape;
  return centred;
}

// `unit_doubt`: what the input checks found of its units ("time stamps that read as
// milliseconds", ...; null: nothing), under which no shape is aligned.
EstimationResult EstimateValidated(const push::Trajectory& trajectory, Model model, Mode mode,
                                   const EstimatorConfig& config, const char* unit_doubt);

// The longest stretch of the trajectory without an object pose (up to the finger stream's end),
// when it is a long gap (internal::LongObjectGap): CP and SDF have no pushing model, so nothing
// moves the object there but the finger's contact point, which may pass through it (a push
// occluded from 20 % of its length on: CP object RMS 28 to 38 mm where QS had 1.3 to 3.2 mm).
std::optional<std::string> UnobservedObjectNote(const push::Trajectory& t, Model model) {
  const double min_gap = internal::LongObjectGap(t);
  if (model == Model::kQs || model == Model::kYu || !std::isfinite(min_gap)) return std::nullopt;
  const auto& s = t.measured.object_pose;
  double end = s.back().t;
  for (const auto& f : t.measured.finger_pose) end = std::max(end, f.t);
  double gap = end - s.back().t, from = s.back().t;
  for (std::size_t k = 1; k < s.size(); ++k) {
    if (s[k].t - s[k - 1].t > gap) { gap = s[k].t - s[k - 1].t; from = s[k - 1].t; }
  }
  if (gap <= min_gap) return std::nullopt;
  char text[400];
  std::snprintf(text, sizeof text,
                "the object is not observed for %.3g s (from t = %.9g s): the %s graph has no pushing model to move it "
                "there, so its estimate in that span rests on the contact alone and may be far off; the qs model "
                "follows the push through an occlusion", gap, from, ModelName(model).c_str());
  return std::string(text);
}

// The recording up to 0.3 s after the object last moved, when it then rests for a second or more
// (the finger left against it): the candidates' graph costs are compared on it. A long rest says
// nothing more of the placement than one point, but its thousands of steps are fitted a little
// differently by each candidate: a push of the notched block followed by a 4.5 s rest, with the
// true shape, "fit better" turned by 1.1 degrees and shifted by (31.8, -49.1) mm (graph cost 2681.8
// against 2870.3 as given; object 0.87 mm against 0.49 mm), which align_shape "on" then applied.
// Moving: a 5-sample running median of the distance from the mean pose of the last 0.5 s beyond
// max(2 mm, 4 tracker noises).
push::Trajectory WithoutFinalRest(const push::Trajectory& traj) {
  const auto& s = traj.measured.object_pose;
  if (s.size() < 10) return traj;
  const double end = s.back().t;
  Eigen::Vector2d final_mean = Eigen::Vector2d::Zero();
  int final_count = 0;
  for (const push::PoseSample& p : s)
    if (p.t >= end - 0.5) final_mean += p.pose.translation(), ++final_count;
  final_mean /= final_count;
  double trans = 0.0, rot = 0.0;
  internal::registration::StreamNoise(s, &trans, &rot);
  const double threshold = std::max(2e-3, 4.0 * trans);
  double last_moving = s.front().t;
  for (std::size_t i = 2; i + 2 < s.size(); ++i) {
    std::vector<double> d;
    for (std::size_t k = i - 2; k <= i + 2; ++k) d.push_back((s[k].pose.translation() - final_mean).norm());
    if (internal::Median(d) > threshold) last_moving = s[i].t;
  }
  const double cut = last_moving + 0.3;
  if (end - cut < 1.0) return traj;
  push::Trajectory out = traj;
  auto trim = [cut](auto& stream) {
    stream.erase(std::find_if(stream.begin(), stream.end(), [cut](const auto& x) { return x.t > cut; }), stream.end());
  };
  auto trim_all = [&](push::Streams& m) {
    trim(m.object_pose), trim(m.finger_pose), trim(m.contact_point), trim(m.force);
  };
  trim_all(out.measured);
  if (out.ground_truth) trim_all(*out.ground_truth);
  for (push::ExtraFinger& f : out.extra_fingers) {
    trim(f.measured.finger_pose), trim(f.measured.contact_point), trim(f.measured.force);
    if (f.ground_truth) trim(f.ground_truth->finger_pose), trim(f.ground_truth->contact_point), trim(f.ground_truth->force);
  }
  return out;
}

// A finger `offset` larger (the registration's size alternative) is the object's outline as much
// smaller on every side: that as a share of its size, 2 area / perimeter (a square's half width,
// a disk's radius). A rect1 mesh 10 % too large read as "the finger 4.5 mm smaller (radius
// 0.2 mm)", a probe no one has, where "the outline about 10 % too large" names the file.
std::string OutlineSizeText(const geometry::Shape& object, double offset) {
  double perimeter = 0.0;
  for (const geometry::Polygon& p : object.polygons()) {
    auto ring_length = [](const geometry::Ring& r) {
      double length = 0.0;
      for (std::size_t i = 0; i < r.size(); ++i) length += (r[(i + 1) % r.size()] - r[i]).norm();
      return length;
    };
    perimeter += ring_length(p.outer);
    for (const geometry::Ring& h : p.holes) perimeter += ring_length(h);
  }
  if (!(perimeter > 0.0) || !(object.core_area() > 0.0)) return "";
  const double half_width = 2.0 * object.core_area() / perimeter + object.radius();
  return internal::Format(" (as an object size: its outline about %.0f %% too %s, %.1f mm on every side)",
                          100.0 * std::abs(offset) / half_width, offset > 0 ? "small" : "large", std::abs(offset) * 1e3);
}

// With RegistrationResult::size_mismatch: the shape against the finger's path, and what to check.
std::string SizeMismatchText(const RegistrationResult& r) {
  if (!r.size_mismatch) return "";
  std::string text = internal::Format(
      ": it is %.3g times the size of the finger's path around the object's origin, and no unit tried (metres, "
      "centimetres, millimetres, inches, 100 or 1000 times larger) makes it fit: check the shape file's size and units, "
      "and that the finger and object pose streams share one frame",
      r.size_ratio);
  // Within a unit's reach, the units may be right and the frame not: an origin on the object's
  // edge, where the finger pushes, puts the path inside a few times the shape's radius (a turned
  // U-shaped block whose origin is on its outer edge was "6.61 times the size" and refused).
  for (double unit : internal::registration::kUnitScales) {
    const double ratio = r.size_ratio * unit;
    if (ratio > 4.0 && ratio <= 30.0) {
      text += internal::Format(
          " (%s, %.3g times: if the object's origin lies on its edge where the finger pushes, the size may be right "
          "and the shape's frame not; --align-shape on places it)",
          unit == 1.0 ? "in the file's units" : internal::Format("at scale %g", unit).c_str(), ratio);
      break;
    }
  }
  return text;
}

}  // namespace

// The noise model's scales set far (100 times or more) from their defaults: they then outweigh
// the measurements or let the state drift, and an estimate worse than the raw data follows while
// the diagnostics blame the sensors (quasi_static_sigma 1e-4: object 30 mm against 7.3 raw;
// contact sigmas 1e-7: 19 mm and "the tracker's noise is larger than its sigma"; accelerations
// of 100 and 1000: rotation 2.75 times the raw error). Said, not refused: a deliberate choice
// may be right for unusual data.
static std::optional<std::string> ConfigScaleNote(const EstimatorConfig& c) {
  const EstimatorConfig d;
  const std::pair<const char*, std::pair<double, double>> keys[] = {
      {"accel_trans", {c.accel_trans, d.accel_trans}},
      {"accel_rot", {c.accel_rot, d.accel_rot}},
      {"contact_object_sigma", {c.contact_object_sigma, d.contact_object_sigma}},
      {"contact_finger_sigma", {c.contact_finger_sigma, d.contact_finger_sigma}},
      {"touching_sigma", {c.touching_sigma, d.touching_sigma}},
      {"intersection_sigma", {c.intersection_sigma, d.intersection_sigma}},
      {"quasi_static_sigma", {c.quasi_static_sigma, d.quasi_static_sigma}},
      {"limit_surface_sigma", {c.limit_surface_sigma, d.limit_surface_sigma}},
      {"force_random_walk", {c.force_random_walk, d.force_random_walk}},
      {"yu_quasi_static_sigma", {c.yu_quasi_static_sigma, d.yu_quasi_static_sigma}},
      {"random_walk_trans", {c.random_walk_trans, d.random_walk_trans}},
      {"random_walk_rot", {c.random_walk_rot, d.random_walk_rot}},
  };
  constexpr double kFar = 100.0;
  std::string far;
  for (const auto& [name, values] : keys) {
    const auto [value, nominal] = values;
    if (!(value > 0.0) || !(nominal > 0.0) || (value < kFar * nominal && value > nominal / kFar)) continue;
    far += internal::Format("%s%s %.3g (%.3g times its default %.3g)", far.empty() ? "" : ", ", name, value,
                            value / nominal, nominal);
  }
  if (far.empty()) return std::nullopt;
  return "config: " + far +
         ": a noise scale this far from its default outweighs the measurements (or lets the states drift), and the "
         "estimate may come out worse than the raw data while the diagnostics below blame the sensors; the defaults "
         "fit the paper's noise and docs/results.md's recordings (docs/estimation.md, Configuration)";
}

// A function tolerance 100 times its default or more stops the solves after their first steps
// (1e10: about one iteration, object 2.2 mm against 1.35 converged, no word). Smaller ones only
// cost time.
static std::optional<std::string> ToleranceNote(const EstimatorConfig& c) {
  const EstimatorConfig d;
  if (!(c.function_tolerance >= 100.0 * d.function_tolerance)) return std::nullopt;
  return internal::Format("config: function_tolerance %.3g (%.3g times its default %.3g): every solve stops once a step "
                          "changes the cost by less than that fraction, so the estimate may stop far from the minimum",
                          c.function_tolerance, c.function_tolerance / d.function_tolerance, d.function_tolerance);
}

// Whether every stream of the ground truth equals the measured one sample for sample.
static bool GroundTruthIsTheMeasurements(const push::Trajectory& t) {
  if (!t.ground_truth) return false;
  auto same_poses = [](const std::vector<push::PoseSample>& a, const std::vector<push::PoseSample>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const push::PoseSample& x, const push::PoseSample& y) {
      return x.t == y.t && x.pose.x == y.pose.x && x.pose.y == y.pose.y && x.pose.theta == y.pose.theta;
    });
  };
  auto same_points = [](const auto& a, const auto& b, auto value) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                      [&](const auto& x, const auto& y) { return x.t == y.t && value(x) == value(y); });
  };
  auto point = [](const push::PointSample& s) { return s.point; };
  auto force = [](const push::ForceSample& s) { return s.force; };
  const push::Streams &m = t.measured, &g = *t.ground_truth;
  bool same = same_poses(m.object_pose, g.object_pose) && same_poses(m.finger_pose, g.finger_pose) &&
              same_points(m.contact_point, g.contact_point, point) && same_points(m.force, g.force, force);
  for (const auto& e : t.extra_fingers) {
    same = same && e.ground_truth && same_poses(e.measured.finger_pose, e.ground_truth->finger_pose) &&
           same_points(e.measured.contact_point, e.ground_truth->contact_point, point) &&
           same_points(e.measured.force, e.ground_truth->force, force);
  }
  return same;
}

EstimationResult Estimate(const push::Trajectory& given_as_recorded, Model model, Mode mode, const EstimatorConfig& config) {
  const auto call_start = std::chrono::steady_clock::now();
  ValidateConfig(config);
  // A finger file in other units, as the object's is under auto and on (the registration finds
  // the object's units): a user's CAD export of both in millimetres was refused for the finger alone.
  // Validated first but for the finger's size, which FingerUnits judges (its smoothing is no
  // place for a NaN or a clock jump).
  internal::ValidateTrajectory(given_as_recorded, /*finger_size=*/false);
  // A tracker's latency (object_delay) first: every check below judges the streams in step. Applied
  // once, here (the incremental mode's IncrementalEstimator, which applies its own, gets none).
  const std::optional<push::Trajectory> delayed =
      config.object_delay != 0.0 ? std::optional<push::Trajectory>(internal::WithObjectDelay(given_as_recorded, config.object_delay))
                                 : std::nullopt;
  const push::Trajectory& given = delayed ? *delayed : given_as_recorded;
  std::string finger_disks;
  const std::optional<push::Trajectory> disk_fingers = internal::TessellatedFingersAsDisks(given, config, &finger_disks);
  const push::Trajectory& as_disks = disk_fingers ? *disk_fingers : given;
  std::string finger_units;
  double finger_scale = 1.0;
  const std::optional<push::Trajectory> finger_scaled =
      config.align_shape == EstimatorConfig::AlignShape::kOff
          ? std::nullopt
          : internal::FingerUnits(as_disks, RegistrationOptionsFor(config), &finger_units, &finger_scale);
  const push::Trajectory& in_metres = finger_scaled ? *finger_scaled : as_disks;
  if (finger_scaled) internal::ValidateTrajectory(in_metres);  // reaches and units with the finger scaled
  else internal::CheckFingerSizes(in_metres);
  std::string finger_origin;
  geometry::Vec2 finger_shift = geometry::Vec2::Zero();
  const std::optional<push::Trajectory> finger_centred = CentredFinger(in_metres, config, &finger_origin, &finger_shift);
  const push::Trajectory& trajectory = finger_centred ? *finger_centred : in_metres;
  std::string note, glitch_note;
  std::optional<push::Trajectory> repaired = DropForceSpikes(trajectory, &note);
  const push::Trajectory* before_glitches = repaired ? &*repaired : &trajectory;
  std::optional<push::Trajectory> cleaned = internal::DropObjectPoseGlitches(*before_glitches, &glitch_note);
  const push::Trajectory& deglitched = cleaned ? *cleaned : *before_glitches;
  // A contact stream off its finger (another frame, an offset): 2 cm off, every model's object
  // estimate was worse than the raw tracker's (CP 14 mm against 3.0), and the shape "aligned".
  std::string contact_note;
  const std::optional<push::Trajectory> without_contacts =
      internal::DropContactStreamsOffTheFinger(deglitched, config.measurement, &contact_note);
  const push::Trajectory& contacts_judged = without_contacts ? *without_contacts : deglitched;
  // Then single corrupt rows of a stream kept (one row 5 m off: 160 mm against 2.8 mm raw).
  std::string contact_fault_note;
  const std::optional<push::Trajectory> without_contact_faults =
      internal::DropContactRowFaults(contacts_judged, config.measurement, &contact_fault_note);
  const push::Trajectory& input = without_contact_faults ? *without_contact_faults : contacts_judged;
  const char* clock_unit = "";
  const std::optional<std::string> time_unit = internal::TimeUnitNote(trajectory, &clock_unit);
  const std::optional<std::string> length_unit = internal::ShapeSizeNote(trajectory);
  // A step of the object's tracker is no placement evidence either: a hostile user's rect1 with a
  // 50 mm step had its true mesh "aligned" by a turn of 18.4 degrees to explain it.
  const std::optional<std::string> tracker_step = internal::TrackerStepNote(trajectory);
  // Nor a yaw in degrees: the correct shape was "aligned" by a turn of -99.9 degrees to fit it.
  const std::optional<std::string> yaw_unit = internal::YawUnitNote(trajectory);
  // Nor a force stream whose direction or offset is off: a force with x and y swapped, or read
  // 1 N high throughout, had the true shape "aligned" by 45 or 36 mm to explain it (a hostile
  // user's session: 3.04 mm against 2.71 mm raw).
  const std::optional<std::string> force_direction = internal::ForceDirectionNote(input);
  const std::optional<internal::ForceOutOfContactNote> force_bias = internal::ForceBiasNote(input);
  const std::string time_doubt = std::string("time stamps that read as ") + clock_unit;
  const char* unit_doubt = time_unit         ? time_doubt.c_str()
                           : length_unit     ? "lengths that read as centimetres or millimetres"
                           : yaw_unit        ? "yaws that read as degrees"
                           : tracker_step    ? "a step of the object's tracker"
                           : force_direction ? "a force whose direction does not fit the finger's motion"
                           : force_bias      ? (force_bias->clock_offset ? "a force stream out of step with the contact stream"
                                                                             : "a force sensor that reads a force out of contact")
                                             : nullptr;
  EstimationResult r = EstimateValidated(input, model, mode, config, unit_doubt);
  r.object_delay = config.object_delay;
  // A covariance failure was only in RESULT.json's solver.covariance (NEES NaN, nothing said).
  if (config.covariance && r.solver.covariance_status.find("failed") != std::string::npos)
    r.warnings.push_back("covariances not computed: " + r.solver.covariance_status +
                         "; the states are estimated, their sigmas and NEES are not (a noise model far from the data's, "
                         "such as sigmas or accelerations near zero, makes the information matrix numerically singular)");
  if (!r.metrics.empty() && GroundTruthIsTheMeasurements(trajectory)) {
    // A recording's "ground truth" that is its own measurements (mit-import, an MIT file read
    // directly) scored the estimate against the raw data: measured_*_rms 0 and the estimate
    // "0.7 mm off". Nothing to score against.
    r.metrics.clear();
    r.warnings.push_back("no metrics: the input's ground_truth is its own measurements (a recording, such as an MIT file "
                         "or its mit-import), so there is nothing to score the estimate against; the paper's protocol "
                         "adds noise to the recording and scores against it (pushgraph estimate --add-noise, pushgraph "
                         "evaluate)");
  }
  if (!r.metrics.empty() && !r.states.empty() && trajectory.ground_truth && !trajectory.ground_truth->object_pose.empty()) {
    // Ground truth over part of the push scores that part only: two truth rows before contact
    // gave an object RMS of 0.635 mm for a 29-sample push, and no word (a hostile user's file).
    std::size_t scored = 0;
    Eigen::Vector3d unused;
    for (const StateEstimate& s : r.states) scored += push::TruthPoseAt(trajectory.ground_truth->object_pose, s.t, &unused);
    if (scored < 0.9 * static_cast<double>(r.states.size())) {  // a truth stream ending a frame early is no matter
      const auto& truth = trajectory.ground_truth->object_pose;
      r.warnings.push_back(internal::Format(
          "metrics: ground_truth.object_pose (%zu sample%s%s) covers %zu of the estimate's %zu steps (t = %.9g to %.9g s; "
          "truth is read at a step's time between samples at most 0.1 s apart): the metrics score those steps only",
          truth.size(), truth.size() == 1 ? "" : "s",
          internal::Format(", t = %.9g to %.9g s", truth.front().t, truth.back().t).c_str(), scored,
          r.states.size(), r.states.front().t, r.states.back().t));
    }
  }
  if (const std::optional<std::string> runaway = internal::UnobservedRunawayNote(input, r.states, model, mode)) r.warnings.push_back(*runaway);
  if (trajectory.ground_truth && trajectory.ground_truth->object_pose.empty()) {
    // The object's metrics were left out with no word (a hostile user's file).
    r.warnings.push_back("metrics: the input's ground_truth has no object_pose, so the object's metrics (object_position_rms, "
                         "object_pose_nees, ...) are absent; what ground truth it has is scored");
  }
  if (cleaned && !r.metrics.empty()) {
    // The raw tracker's errors are the stream as recorded, glitches included.
    for (const auto& [key, value] : ComputeMetrics(*before_glitches, r.states))
      if (key.rfind("measured_object", 0) == 0 || key.rfind("measured_finger", 0) == 0) r.metrics[key] = value;
  }
  // The input's own warnings first, in this order: the clock and units, then what was left out,
  // then what the streams say against the physics of a push.
  std::vector<std::string> front;
  auto add = [&front](const std::optional<std::string>& w) { if (w) front.push_back(*w); };
  add(ConfigScaleNote(config));
  add(ToleranceNote(config));
  add(time_unit);
  add(internal::StreamOverlapNote(trajectory));
  add(internal::StreamCoverageNote(trajectory));
  add(yaw_unit);
  add(tracker_step);
  add(length_unit);
  if (disk_fingers) front.push_back(finger_disks);
  if (finger_scaled) {
    front.push_back(finger_units);
    r.finger_scale = finger_scale;
  }
  if (!finger_origin.empty()) front.push_back(finger_origin);
  r.finger_shift = finger_shift;
  if (!note.empty()) front.push_back(note);
  if (!glitch_note.empty()) front.push_back(glitch_note);
  if (without_contacts) front.push_back(contact_note);
  if (without_contact_faults) front.push_back(contact_fault_note);
  add(force_direction);
  if (force_bias) front.push_back(force_bias->text);
  add(internal::ForceScaleNote(input, config.measurement.force, config.estimate_mu));
  add(internal::MeasurementSigmaNote(input, config.measurement));
  r.warnings.insert(r.warnings.begin(), front.begin(), front.end());
  if (auto unobserved = UnobservedObjectNote(trajectory, model)) r.warnings.push_back(*unobserved);
  if (const std::size_t n = trajectory.measured.object_pose.size(); n < 3) {
    r.warnings.push_back("object_pose: only " + std::to_string(n) + " sample" + (n == 1 ? "" : "s") +
                         ": the object's path between them rests on the contacts" +
                         (model == Model::kQs || model == Model::kYu ? " and the pushing model" : "") +
                         ", and a wrong shape frame or friction cannot be told from the data");
  }
  // Without a force stream the pushing model alone sizes the forces, by mu m g: a wrong mass
  // (50 kg for 0.5) gave forces of 127 N RMS and a force NEES of 3500 with no word.
  const bool forces_estimated =
      std::any_of(r.states.begin(), r.states.end(), [](const StateEstimate& s) { return s.force.has_value(); });
  if (forces_estimated && trajectory.measured.force.empty()) {
    const double scale = trajectory.object.mu_surface * trajectory.object.mass * 9.81;
    r.warnings.push_back(internal::Format(
        "no force stream: the %s model infers the forces from the object's sliding friction alone, which sizes them "
        "by mu_surface x mass x g = %.3g N (mu_surface %g, mass %g kg, as given: nothing in the data checks them)",
        ModelName(model).c_str(), scale, trajectory.object.mu_surface, trajectory.object.mass));
  }
  // The finger likewise (a single finger sample ran with no word, the object 8.3 mm off against
  // 7.35 raw and the warnings blaming the tracker's noise and the shape frame).
  if (const std::size_t n = trajectory.measured.finger_pose.size(); n > 0 && n < 3) {
    r.warnings.push_back("finger_pose: only " + std::to_string(n) + " sample" + (n == 1 ? "" : "s") +
                         ": the finger's path between them rests on the contacts and the motion prior, and the "
                         "diagnostics' other findings may come from that");
  }
  r.solver.total_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - call_start).count();
  return r;
}

namespace {

// A solve whose final cost ranks it: neither stalled at a residual that jumps nor stopped at its limit.
bool Converged(const SolverStats& s) { return !s.stalled && !s.at_iteration_limit; }

EstimationResult EstimateValidated(const push::Trajectory& trajectory, Model model, Mode mode,
                                   const EstimatorConfig& config, const char* unit_doubt) {
  using Align = EstimatorConfig::AlignShape;
  // The shape against the recording: the check, then registration where asked or needed.
  ShapeAlignment alignment;
  std::vector<std::string> warnings;
  RegistrationOptions options = RegistrationOptionsFor(config);
  options.estimate_scale = config.align_scale;
  std::optional<RegistrationResult> registration;
  try {
    // Always: the check's gaps miss a turn that the noise hides, the likelihood ratio does not.
    // The registration's own check is CheckShapeFit's (the same contacts, smoothed once: a
    // separate check smoothed the four streams again, 5 % of a 1000-step QS batch estimate).
    registration = RegisterShape(trajectory, options);
    alignment.check = registration->check;
    alignment.checked = true;
    alignment.check.fits = registration->fits_as_given;
  } catch (const std::exception& e) {
    // Too few contacts with object poses near them to say anything about the shape.
    alignment.notes.push_back(std::string("shape not checked: ") + e.what());
    if (config.align_shape == Align::kOn) throw GraphError(std::string("align_shape \"on\": ") + e.what());
  }
  // The contacts' best placement as the registration found it (the graph may refine it below).
  const std::string contacts_best = registration ? registration->Describe() : std::string();
  // A misfit has several explanations: the registration's best placement, its alternatives
  // (other rotations the contacts of one push leave open), or a wrong finger size (the shape as
  // given with the finger size_offset larger). Contacts alone cannot always tell them apart;
  // the whole graph can (dynamics, smoothing): each is estimated (batch, no covariances) and
  // the lowest final cost wins.
  const bool misfit = registration && !registration->fits_as_given;
  // A shape no unit makes the size of the finger's path is refused: any placement found so is a
  // guess (a finger stream 0.5 m off was "aligned" by a turn of 125 degrees, 9 m and the scale
  // 1000), and without one the contact factors pull the object 0.4 m to the finger. align_shape
  // "on" still aligns, "off" estimates as given.
  if (misfit && registration->size_mismatch && config.align_shape == Align::kAuto) {
    throw GraphError("shape check: the object's shape does not fit this recording as given (" +
                     registration->check.Describe() + ")" + SizeMismatchText(*registration) +
                     "; no placement of it in any unit explains the finger's path, so nothing is estimated "
                     "(--align-shape off, or align_shape \"off\", estimates with the shape as given regardless)");
  }
  const geometry::Shape& finger = trajectory.finger.shape;
  const double sized_radius = finger.radius() + (registration ? registration->size_offset : 0.0);
  const bool size_candidate = misfit && sized_radius > 0.0 &&
                              std::abs(registration->size_offset) <= std::max(5e-3, 3.0 * finger.radius());
  bool size_wins = false, size_ties = false, identity_wins = false, units_win = false;
  double size_cost = 0.0, placement_cost = 0.0;  // the graph's, when a size candidate ran
  constexpr double kTieMargin = 2.0;  // in cost (a log-likelihood)
  // What the graph's frame F (3 parameters with the centroid prior) alone buys in cost on true
  // shapes: up to 17.2 over 125 estimates of a hostile-user session (the frame check below). A
  // candidate estimated with F free must beat one without it by this much.
  constexpr double kFrameMargin = 20.0;
  // On long recordings the model's own error on real data grows with their length: the true
  // ellip1 mesh on its 2061-step 20 mm/s push gained 28.4 with the frame free and was "aligned"
  // by 12 mm (the two pushes at the same spot by 1.5 mm; the other 19 recordings of rect1 and
  // ellip1: at most 11.5, 0.0138 a step at worst, and 0.0056 on the other 2055-step push). A 40 mm
  // shift of rect1's mesh gained 0.23 a step. So the margin is also 0.02 a step.
  constexpr double kFrameMarginPerStep = 0.02;
  // The frame check's solve, warm from the estimate as given, stops here: it only has to tell
  // whether freeing the frame gains the margin (on the 2061-step ellip1 recording it crept from
  // 79.1 to 51.0 over 300 iterations, 5.1 s, against a margin of 41).
  constexpr int kFrameCheckIterations = 60;
  // Within the gap tolerance, but one placement (not several alike) fits the contacts clearly
  // better: the whole graph decides that too, the shape as given winning ties. (A rect1
  // recording with its mesh turned by 37 degrees was only suspected: 1.73 mm against 1.09 mm
  // with the mesh as shipped. The contacts' ratio alone misfired on pushes that break the model,
  // and so does the graph where the contacts leave several placements open: the true notched
  // block in Alignment.MisframedShapesAreAlignedAndEstimatedAsWellAsTheTrueOne's push 4 was
  // "aligned" by a turn of 163 degrees.)
  const bool suspect = registration && registration->fits_as_given && registration->better_elsewhere &&
                       !registration->ambiguous && config.align_shape == Align::kAuto;
  // Too little contact to place a shape by (under three independent samples, 0.15 s): a 4 mm push
  // of rect1 touched for 84 ms, its true shape judged off by 3.4 mm and "aligned" by (6.5, -4.2)
  // mm (3.69 mm against 2.60 as given). Warned, not aligned, under "auto".
  const bool too_little = registration && config.align_shape == Align::kAuto && registration->independent_samples < 3.0;
  // Time stamps that read as milliseconds (TimeUnitNote): the smoothing's and the graph's per-second
  // noise scales are off by 1000, so their placement is no evidence (`pushgraph simulate --seed 7
  // --duration 3` written in ms: its true notched block "aligned" by a turn of 46.5 degrees, 9.4 mm
  // against 6.1 as given). Warned, not aligned, under "auto".
  // The same for a file in centimetres or millimetres throughout (ShapeSizeNote): a notched block in
  // cm was "aligned" by a shift of 0.78 "m" (7.8 mm at its true scale). Both found once, by Estimate's input checks.
  const bool unit_gate = registration && config.align_shape == Align::kAuto && unit_doubt;
  // A misfit or suspicion there is data to place the shape by.
  const bool placeable = (misfit || suspect) && !too_little && !unit_gate;
  const bool will_align =
      registration && (config.align_shape == Align::kOn || (config.align_shape == Align::kAuto && placeable));
  EstimatorConfig quick = config;
  quick.covariance = false;
  quick.diagnostics = false;
  // Ranked at convergence: with the QS stage capped at 25 iterations (as it was) a placement
  // still moving lost to worse ones (a rect1 recording with its mesh turned by 37 degrees:
  // the right turn 462.6 at the cap, 429.2 converged; the finger 4.3 mm larger, 436.7, won).
  // Each placement's graph cost and its transform refined by the graph (the shape frame).
  bool best_stalled = false;     // the winning placement's solve stalled
  // The shape as given beat the contacts' best placement in the whole graph by more than what the
  // graph's frame alone buys (kFrameMargin), both solves converged.
  bool graph_rejects_contacts_best = false;
  std::vector<std::string> stalled_losers;  // turns (deg) of placements that lost on a stalled solve
  std::string best_label;
  // Returns the solve's statistics: its final cost, and whether it stalled or stopped at its limit.
  auto framed_cost = [&](const push::Trajectory& base, const ShapeTransform& t, ShapeTransform* refined,
                         const EstimatorConfig& solve, const EstimationResult* start = nullptr, bool hold_first = false) {
    RegistrationResult r = *registration;
    r.transform = t;
    push::Trajectory framed = base;
    framed.object.shape = r.Apply(trajectory.object.shape);
    FrameSetup frame;
    frame.centroid = geometry::CoreCentroid(framed.object.shape);
    frame.sigma_centroid = options.centroid_prior * geometry::RadiusAbout(framed.object.shape, frame.centroid);
    frame.rotation = registration->rotation_observable;
    frame.hold_first = hold_first;
    const SolverStats stats = EstimateBatch(framed, model, solve, &frame, nullptr, start).solver;
    *refined = t;
    refined->pose = geometry::Compose(frame.frame, t.pose);
    return stats;
  };
  if (registration && (placeable || config.align_shape == Align::kOn) &&
      (size_candidate || !registration->alternatives.empty() || will_align)) {
    const push::Trajectory judged = WithoutFinalRest(trajectory);
    if (judged.measured.object_pose.size() < trajectory.measured.object_pose.size()) {
      alignment.notes.push_back(internal::Format("placements compared up to t = %.9g s, 0.3 s after the object last moved "
                                                 "(the rest after it left out)",
                                                 judged.measured.object_pose.back().t));
    }
    ShapeTransform best, refined;
    ShapeTransform best_candidate = registration->transform;  // the winner before the graph's frame
    std::size_t best_rank = 0;                                  // the winner's entry in `ranked`
    const SolverStats first = framed_cost(judged, registration->transform, &best, quick);
    double best_cost = first.final_cost;
    best_stalled = first.stalled;
    best_label = internal::Format("%.1f", registration->transform.pose.theta * 180.0 / M_PI);
    // A stalled solve ends where a residual jumps, not at a minimum: its cost ranks nothing (the
    // notched block turned by 30 degrees: the placement near the truth stalled at 1994.8 against
    // 460.8 for one turned by -131 degrees, and the true shape itself costs 556.8).
    const std::string stall_note = " (its solve stalled at a residual that jumps: no minimum, no comparison)";
    if (best_stalled) {
      alignment.notes.push_back(internal::Format("the best placement by the contacts, turned by %s deg: graph cost %.1f", best_label.c_str(),
                                                 best_cost) + stall_note);
    }
    std::vector<std::pair<ShapeTransform, double>> ranked{{best, best_cost}};  // every placement's graph cost
    // The shape as given competes too: the contacts alone can misjudge a push the model does
    // not describe (a finger wedged between two walls under bimodal noise misfired so). As
    // given means without the graph's frame: that is what is estimated when it wins (with the
    // frame, a shape 20 mm off along a two-finger push tied with the best placement, the frame
    // absorbing the offset, and the estimate as given was then 7 times worse than the raw data).
    {
      const SolverStats given = EstimateBatch(judged, model, quick).solver;
      const double cost = given.final_cost;
      char text[200];
      std::snprintf(text, sizeof text, "the shape as given: graph cost %.1f against %.1f for the best placement", cost, best_cost);
      alignment.notes.push_back(text);
      // The whole graph's verdict on the contacts' best placement, where both solves converged.
      graph_rejects_contacts_best = Converged(first) && Converged(given) && cost + kFrameMargin < first.final_cost;
      // Ties between placements the data cannot tell apart keep the shape as given: a placement
      // must do better by more than 2 in cost (a log-likelihood).
      if (cost <= best_cost + kTieMargin) {
        identity_wins = true;
        best_cost = cost - kTieMargin;
      }
    }
    char text[240];
    for (const ShapeTransform& alt : registration->alternatives) {
      const SolverStats solve = framed_cost(judged, alt, &refined, quick);
      const double cost = solve.final_cost;
      ranked.emplace_back(refined, cost);
      std::snprintf(text, sizeof text, "alternative placement turned by %.1f deg, shifted by (%.1f, %.1f) mm: graph cost %.1f "
                    "against %.1f", alt.pose.theta * 180.0 / M_PI, alt.pose.x * 1e3, alt.pose.y * 1e3, cost, best_cost);
      alignment.notes.push_back(text + (solve.stalled ? stall_note : std::string()));
      const std::string label = internal::Format("%.1f", alt.pose.theta * 180.0 / M_PI);
      if (cost < best_cost) {
        if (best_stalled && !identity_wins) stalled_losers.push_back(best_label);
        best_cost = cost;
        best = refined;
        best_candidate = alt;
        best_rank = ranked.size() - 1;
        best_stalled = solve.stalled;
        best_label = label;
        identity_wins = false;
      } else if (solve.stalled) {
        stalled_losers.push_back(label);
      }
    }
    // Wrong units (or a mirror) and nothing else is the likelier mistake: the file's frame at the
    // found units competes too. (Files 1000 times too small, and in millimetres, came back with
    // the units and a turn of 9 to 89 degrees that one sticking push does not settle: rect2
    // "turned by 19.1 deg (sigma 1.1 deg)", 0.90 mm against 0.45 mm with the units alone.) It is
    // estimated, and used when it wins, as the shape as given is: without the graph's frame, and
    // winning ties within 2. (With the frame, simulated rect2 and ellip2 pushes at the right
    // units came out at 0.89 and 0.94 mm against 0.45 and 0.59 mm as given: the frame absorbs the
    // limit surface's model error. With a margin of 20, for what the frame's freedom alone buys,
    // rect1 in millimetres and turned by 37 degrees lost its turn on 5 of 10 recordings: one push
    // cannot always tell a turn from that freedom. With the frame free from the units alone, that
    // solve found the turn itself.)
    const ShapeTransform found = registration->transform;
    if (!identity_wins && (found.scale != 1.0 || found.mirrored)) {
      ShapeTransform units;
      units.scale = found.scale;
      units.mirrored = found.mirrored;
      push::Trajectory scaled = judged;
      scaled.object.shape = geometry::TransformShape(trajectory.object.shape, geometry::Pose2{}, units.scale, units.mirrored);
      const double cost = EstimateBatch(scaled, model, quick).solver.final_cost;
      std::snprintf(text, sizeof text, "the units alone (%s): graph cost %.1f against %.1f for the best placement",
                    UnitsText(units).c_str(), cost, best_cost);
      alignment.notes.push_back(text);
      // A best placement that only nudges the shape at these units (its outline moved by at most
      // three fit tolerances) must beat them by what the graph's frame alone buys, as in the frame
      // check below (kFrameMargin): a rect1 mesh in millimetres, pushed and then left resting, was
      // aligned by a 5.2 mm shift (cost 2666.0 against 2673.5 for the units alone; 0.71 mm against
      // 0.42 mm with the true shape). A turn still needs only kTieMargin (37 degrees of rect1:
      // 40 mm at its corners).
      ShapeTransform nudge;
      nudge.pose = best.pose;
      const bool nudge_only = best.mirrored == units.mirrored &&
                              internal::registration::OutlineDisplacement(scaled.object.shape, nudge) <=
                                  3.0 * registration->check.tolerance;
      if (cost <= best_cost + (nudge_only ? kFrameMargin : kTieMargin)) {
        units_win = true;
        best_cost = cost;
        best = units;
        registration->sigma.setZero();  // no placement was fitted
      }
    }
    // The ranking's solves free the frame from the staged start (their costs and margins decide
    // which placement wins), where it can drift: on a real ellip1 push with its mesh shifted 36 mm,
    // CP, the winner's frame ended 47 mm from the truth "(sigma 1.4 mm)". The winner's frame is
    // refined again from its placement, held until the rest has converged, by one more solve.
    // (Starting the final batch solve from the placement itself instead saves that solve, 10.2
    // -> 4.9 s on a 590-step ellip1 recording, but F's prior is centred where a solve starts,
    // and one refinement from the contacts' placement left simulated ellip2 pushes with turned
    // meshes at 0.77 to 0.98 mm against 0.60 to 0.70 with this one and 0.59 as given.)
    if (!identity_wins && !units_win) framed_cost(judged, best_candidate, &best, quick, nullptr, /*hold_first=*/true);
    // The graph-refined placement: the start of the final batch solve, or (incremental) the
    // frame kept fixed while smoothing (from a converged solve: with a capped one the frame
    // depended on where it stopped, and Alignment.IncrementalModeUsesTheAlignedShape's estimate
    // was 3.5 mm against batch's 2.5 mm).
    registration->transform = CanonicalTransform(best, trajectory.object.shape, registration->symmetry_order);
    if (identity_wins) {
      registration->fits_as_given = true;
      alignment.check.fits = true;
      // "on" aligns from the shape as given when the graph prefers it (it applied the placement
      // that lost: the true tri1 shape was turned by 134 degrees, cost 551.8 against 541.3).
      if (config.align_shape == Align::kOn) {
        registration->transform = ShapeTransform{};
        registration->transform.scale = 1.0;
      }
    } else {
      const double winner = best_cost;
      for (std::size_t k = 0; k < ranked.size(); ++k) {
        if (k == best_rank && !units_win) continue;  // the winner's own ranking solve
        const auto& [t, cost] = ranked[k];
        const ShapeTransform c = CanonicalTransform(t, trajectory.object.shape, registration->symmetry_order);
        const double turn = std::abs(geometry::WrapAngle(c.pose.theta - registration->transform.pose.theta));
        const double shift = std::hypot(c.pose.x - registration->transform.pose.x, c.pose.y - registration->transform.pose.y);
        const bool differs = (registration->rotation_observable && turn > 3.0 * M_PI / 180.0) || shift > 3e-3;
        if (cost < winner + kTieMargin && differs) alignment.ties.push_back(c);
      }
    }
    if (size_candidate) {
      push::Trajectory sized = judged;
      sized.finger.shape = finger.WithRadius(sized_radius);
      const double sized_cost = EstimateBatch(sized, model, quick).solver.final_cost;
      // The tie rule of the shape as given (whose best_cost already holds its margin): a finger
      // size must do better than the winner by more than 2 to be blamed. Within 2 of a placement
      // the data cannot tell a frame from a size error; the placement is used (it moves the
      // outline to where the contacts are, which on one push absorbs most of a size error too)
      // and the warning names both.
      size_wins = sized_cost < best_cost - (identity_wins ? 0.0 : kTieMargin);
      // Named beside the placement also where the contacts alone cannot tell the two apart (one
      // side of a block: a shift along its normal is a size change): a 1 mm probe given for the
      // 4.7 mm one was aligned by 4 mm shifts on rect1 recordings and the radius never named.
      // (Not where the whole graph rejects the size outright: "explains the contacts about as
      // well (whole-graph cost 3692.1 against 522.0)" read as a contradiction.)
      size_ties = !identity_wins && !size_wins &&
                  (sized_cost < best_cost + kTieMargin ||
                   (registration->size_explains && sized_cost < best_cost + std::max(10.0, 0.02 * std::abs(best_cost))));
      size_cost = sized_cost;
      placement_cost = best_cost;
      std::snprintf(text, sizeof text, "frame or size: graph cost %.1f with the shape %s, %.1f with the finger %.1f mm %s",
                    identity_wins ? best_cost + kTieMargin : best_cost, identity_wins ? "as given" : "aligned", sized_cost,
                    std::abs(registration->size_offset) * 1e3, registration->size_offset > 0 ? "larger" : "smaller");
      alignment.notes.push_back(text);
    }
  }
  // The contacts of one push leave the position along the pushed side to the centroid prior, so
  // a shape file shifted along that side fits them as given and raises no suspicion; the
  // mechanics (where the support's centroid is) can tell. The shape as given with its frame free
  // in the graph, from the identity, against the shape as given: rect1's mesh shifted 40 mm
  // along the pushed side, on its 10 recordings, 1.43 to 2.47 mm with no warning or a suggestion
  // only, against 0.84 to 1.18 mm when aligned; the graph's cost difference 3.1 to 89.6. The
  // margin: with true shapes (a hostile-user session's 125 estimates of rect1 and ellip1
  // recordings at noise seeds 1 to 5 and simulated pushes of five meshes) the difference reached
  // 17.2, five above 10 (aligned by 10, three better and two worse than as given); shifts of
  // 20 mm along the pushed side gave 25.1 to 124.7 on simulated pushes, -0.2 to 25.1 on rect1.
  // In batch the final estimate as given supplies the cost as given (one extra solve, the
  // framed one, unless the frame wins).
  bool frame_wins = false;
  // QS only: the CP and SDF graphs have no mechanics to place the support by, and on the
  // evaluation set their frame then followed the noise (ellip1 SDF incremental +4.9 %).
  bool frame_check = registration && config.align_shape == Align::kAuto && model == Model::kQs && !too_little && !unit_gate &&
                           registration->fits_as_given && !misfit && !suspect && !registration->weak_directions.empty();
  double frame_given_cost = 0.0, frame_cost = 0.0, frame_moved = 0.0;
  ShapeTransform frame_refined;
  // Decides the frame check from the estimate as given: the frame is freed there (a warm start:
  // its cost can only fall, where a solve from the measurements with the frame free ended worse
  // than the one with it fixed, 403.4 against 386.4, and took as long as the estimate itself);
  // true when the frame wins.
  auto decide_frame = [&](const EstimationResult& given) {
    bool capped = false;
    try {
      EstimatorConfig frame_solve = quick;
      frame_solve.max_iterations = std::min(quick.max_iterations, kFrameCheckIterations);
      const SolverStats solve = framed_cost(trajectory, ShapeTransform{}, &frame_refined, frame_solve, &given);
      frame_cost = solve.final_cost;
      capped = solve.at_iteration_limit;
      frame_moved = internal::registration::OutlineDisplacement(trajectory.object.shape, frame_refined);
    } catch (const std::exception& e) {
      // A check, not the estimate: a solve with the frame free that fails leaves the shape as given.
      alignment.notes.push_back(std::string("frame check skipped: ") + e.what());
      frame_check = false;
      return false;
    }
    const double given_cost = given.solver.final_cost;
    const std::size_t steps = given.states.size();
    frame_given_cost = given_cost;
    const std::string from_there = capped ? internal::Format(" after %d iterations from there", kFrameCheckIterations) : "";
    const double margin = std::max(kFrameMargin, kFrameMarginPerStep * static_cast<double>(steps));
    alignment.notes.push_back(internal::Format(
        "frame check: graph cost %.1f as given, %.1f with the frame free%s (it moves the outline by %.1f mm; "
        "it is used when it gains more than %.1f, on %zu steps, and moves the outline by more than %.1f mm)",
        frame_given_cost, frame_cost, from_there.c_str(),
        frame_moved * 1e3, margin, steps, registration->check.tolerance * 1e3));
    frame_wins = frame_cost < frame_given_cost - margin && frame_moved > registration->check.tolerance;
    if (frame_wins) registration->transform = CanonicalTransform(frame_refined, trajectory.object.shape, registration->symmetry_order);
    return frame_wins;
  };
  if (frame_check && mode != Mode::kBatch) {
    const EstimationResult given = EstimateBatch(trajectory, model, quick);
    decide_frame(given);
  }
  bool align = registration && (config.align_shape == Align::kOn ||
                                (config.align_shape == Align::kAuto && placeable && !size_wins && !identity_wins) ||
                                frame_wins);
  push::Trajectory aligned_trajectory;
  const push::Trajectory* working = &trajectory;
  if (registration) {
    alignment.suggested = true;
    alignment.transform = registration->transform;
    alignment.sigma = registration->sigma;
    alignment.rotation_observable = registration->rotation_observable;
    alignment.notes.insert(alignment.notes.end(), registration->notes.begin(), registration->notes.end());
    if (registration->ambiguous) alignment.notes.push_back("ambiguous: " + registration->ambiguity);
  }
  auto use_alignment = [&] {
    aligned_trajectory = trajectory;
    aligned_trajectory.object.shape = registration->Apply(trajectory.object.shape);
    working = &aligned_trajectory;
    alignment.aligned = true;
    alignment.transform = registration->transform;
  };
  // A placement that puts the object's shape well away from the tracked origin (its centroid
  // beyond 1.5 radii: the origin outside the object) explains the contacts by moving the object
  // to the finger: the finger's stream is in another frame, more likely than the shape file. A
  // finger stream 0.2 m off was "aligned" by shifts of 96 to 163 mm, exit 0, the object 4.3 to
  // 52.7 mm off against 2.9 to 7.2 mm raw. Refused under "auto", as a shape no unit explains is.
  if (align && config.align_shape == Align::kAuto) {
    const geometry::Shape placed = registration->Apply(trajectory.object.shape);
    const Vec2 centroid = geometry::CoreCentroid(placed);
    const double radius = geometry::RadiusAbout(placed, centroid);
    if (centroid.norm() > 1.5 * radius) {
      throw GraphError(internal::Format(
          "shape check: the placement that fits the contacts best puts the object's shape %.1f mm from the object pose's "
          "origin (%.1f times its radius %.1f mm): the tracked origin would lie outside the object. Are the finger and "
          "object pose streams in one frame? Nothing is estimated (--align-shape off estimates with the shape as given, "
          "on with that placement: %s)",
          centroid.norm() * 1e3, centroid.norm() / radius, radius * 1e3, registration->Describe().c_str()));
    }
  }
  if (align) use_alignment();
  // A finger size the whole graph clearly prefers is used, as a placement would be: estimated
  // with the finger as given against a shape it does not touch, the ellip1 recordings given a
  // 9 mm probe (4.7 mm) where the size wins were 1.5 to 2.6 mm off, 0.88 to 0.96 mm with it.
  const bool resize = size_wins && config.align_shape == Align::kAuto;
  if (resize) {
    aligned_trajectory = trajectory;
    aligned_trajectory.finger.shape = finger.WithRadius(sized_radius);
    working = &aligned_trajectory;
    alignment.finger_radius = sized_radius;
  }
  EstimationResult result;
  std::optional<internal::FrameState> frame_state;
  // One querier for the estimate and its diagnostics (batch; the fixed-lag smoother keeps its own).
  std::shared_ptr<const geometry::ShapePairQuerier> querier;
  if (mode == Mode::kBatch) querier = internal::GraphBuilder::MakeQuerier(*working, config);
  if (mode == Mode::kBatch && frame_check) {
    result = EstimateBatch(*working, model, config, nullptr, querier);
    if (decide_frame(result)) {
      align = true;
      use_alignment();
      querier = internal::GraphBuilder::MakeQuerier(*working, config);
    }
  }
  if (mode == Mode::kBatch && (align || !frame_check)) {
    if (align && !units_win) {
      // The frame refined as a static variable: the centroid prior of the registration.
      FrameSetup frame;
      const geometry::Shape& shape = working->object.shape;
      frame.centroid = geometry::CoreCentroid(shape);
      frame.sigma_centroid = options.centroid_prior * geometry::RadiusAbout(shape, frame.centroid);
      frame.rotation = registration->rotation_observable;
      frame.hold_first = true;
      result = EstimateBatch(*working, model, config, &frame, querier);
      frame_state = internal::FrameState{frame.centroid, frame.sigma_centroid, frame.sigma_theta, frame.rotation, frame.frame};
      // Final transform F * T, then its equivalent closest to angle 0 (F * T * C, C constant).
      Eigen::Matrix3d J_refined_frame, J_final_refined;
      ShapeTransform refined = registration->transform;
      refined.pose = geometry::Compose(frame.frame, registration->transform.pose, &J_refined_frame);
      alignment.transform = CanonicalTransform(refined, trajectory.object.shape, registration->symmetry_order);
      geometry::Compose(refined.pose, geometry::Between(refined.pose, alignment.transform.pose), &J_final_refined);
      alignment.refined = true;
      if (frame.covariance) {
        const Eigen::Matrix3d J = J_final_refined * J_refined_frame;
        const Eigen::Matrix3d cov = J * *frame.covariance * J.transpose();
        alignment.sigma = cov.diagonal().cwiseMax(0.0).cwiseSqrt();
        if (!frame.rotation) alignment.sigma.z() = 0.0;
      }
    } else {
      result = EstimateBatch(*working, model, config, nullptr, querier);
    }
  } else if (mode != Mode::kBatch) {
    // Fixed-lag smoothing keeps the registered frame fixed (no static variable in the window).
    EstimatorConfig in_step = config;
    in_step.object_delay = 0.0;  // Estimate applied it to the streams already
    IncrementalEstimator inc(*working, model, in_step);
    while (!inc.Done()) inc.Update();
    result = inc.Finish();
  }
  // Whether the recording settles a placement used or suggested for a misfit, once
  // the frame check (batch: after the estimate as given) has decided (the units alone and
  // the shape as given are the file's own frame, not a placement).
  // The units alone are the file's own frame, yet ties (a rect1 mesh in millimetres: a turn of
  // 7.5 degrees fits about as well) still leave it unsettled (it read settled, sigma [0, 0, 0]).
  alignment.units_only = units_win;
  if (registration && (align || misfit) && (!identity_wins || frame_wins)) {
    std::vector<std::string> open;
    if (registration->ambiguous) open.push_back("the contacts fit other placements about as well");
    if (!alignment.ties.empty()) open.push_back("the whole graph fits others about as well");
    if (!stalled_losers.empty()) {
      std::string which;
      for (std::size_t k = 0; k < stalled_losers.size(); ++k)
        which += (k == 0 ? "" : k + 1 == stalled_losers.size() ? " and " : ", ") + stalled_losers[k];
      open.push_back(internal::Format("the solve%s of the placement%s turned by %s deg stalled, so the graph's cost does not rank %s",
                                      stalled_losers.size() > 1 ? "s" : "", stalled_losers.size() > 1 ? "s" : "",
                                      which.c_str(), stalled_losers.size() > 1 ? "them" : "it"));
    }
    if (best_stalled) open.push_back("this placement's own solve stalled");
    // A size error fits as well: the placement may only stand in for it (rect1.obj 10 % too large
    // was "settled" as a turn of 19.8 degrees, sigma 7.4, on a real recording; the truth is 0).
    if (size_ties && !size_wins) {
      open.push_back(internal::Format("the shape as given with the finger %.1f mm %s (another probe radius or object size) "
                                      "fits about as well",
                                      std::abs(registration->size_offset) * 1e3,
                                      registration->size_offset > 0 ? "larger" : "smaller"));
    }
    alignment.settled = open.empty();
    for (std::size_t k = 0; k < open.size(); ++k) alignment.unsettled_by += (k ? "; " : "") + open[k];
  }
  // The graph's curvature where its solve stopped short of a minimum is no covariance of the
  // frame: a long ellip1 push with its mesh shifted 25 mm across the probe's stretch, align_shape
  // "on", QS, stopped at 300 iterations with the frame at (-8.0, 8.1) mm "(sigma 0.6 and 0.6 mm)";
  // the truth is (-20, 15).
  if (alignment.refined && result.solver.at_iteration_limit) {
    alignment.settled = false;
    alignment.unsettled_by += std::string(alignment.unsettled_by.empty() ? "" : "; ") +
                              "the solve with the frame free stopped at its iteration limit, short of a minimum";
  }
  if (alignment.checked && !alignment.check.fits) {
    std::string what = "the object's shape does not fit this recording as given (" + alignment.check.Describe() + ")";
    what += SizeMismatchText(*registration);
    if (size_wins) {
      char size[160];
      std::snprintf(size, sizeof size, "the finger %.1f mm %s than given (radius %.1f mm instead of %.1f mm)",
                    std::abs(registration->size_offset) * 1e3, registration->size_offset > 0 ? "larger" : "smaller",
                    sized_radius * 1e3, finger.radius() * 1e3);
      // Where the contacts alone fit the placement as well (one stretch of one side: a shift
      // along its normal is a size change), the placement is named too: ellip1.obj shifted 1 cm,
      // with the right 4.7 mm probe, had "the finger 5.4 mm larger" win by 11 in the graph and
      // the frame error went unnamed (the 9 mm probe given for the 4.7 mm one on the same
      // recording wins by 14: the data cannot tell the two apart there).
      std::string placement;
      if (registration->size_explains && !identity_wins && !units_win) {  // the winner was a placement
        placement = "; the shape moved (" + contacts_best + internal::Format(") fits the contacts about as well (whole-graph "
                    "cost %.1f against %.1f with the finger resized): if the probe's radius is right, the shape file's frame "
                    "may be off by that much", placement_cost, size_cost);
      }
      warnings.push_back(what + "; it fits as given with " + size + OutlineSizeText(trajectory.object.shape, registration->size_offset) +
                         ": a wrong probe radius or object size? " +
                         (resize ? "Estimated with that radius (RESULT.json parameters.finger_radius; align_shape \"off\" "
                                   "keeps the finger as given)"
                                 : "(the estimate uses the finger as given)") + placement);
    } else if (align) {
      std::string also;
      if (size_ties) {
        char size[360];
        std::snprintf(size, sizeof size, "; the shape as given with the finger %.1f mm %s (radius %.1f mm) explains the "
                      "contacts about as well (whole-graph cost %.1f against %.1f aligned): if the shape file's frame is right, "
                      "check the probe radius and the object's size", std::abs(registration->size_offset) * 1e3,
                      registration->size_offset > 0 ? "larger" : "smaller", sized_radius * 1e3, size_cost, placement_cost);
        also = size + OutlineSizeText(trajectory.object.shape, registration->size_offset);
      }
      // A tracker running late against the finger misplaces the contacts along the push as a shifted
      // shape does, and one push cannot tell them apart (docs/estimation.md): a simulated push 0.1
      // to 0.3 s late had the true notched block "aligned" by turns of 84 to 108 degrees, and a
      // real rect1 recording 0.15 s late by (2.0, 4.2) mm, settled (2.29 mm against 1.91 raw).
      also += config.object_delay != 0.0
                  ? internal::Format("; the object's time stamps were moved %.6g s earlier (object_delay): if the shape "
                                     "file is right, a wrong delay misplaces the contacts alike", config.object_delay)
                  : std::string("; if the shape file is right, an object tracker running late against the finger (a "
                                "camera's latency) misplaces the contacts alike: --object-delay SECONDS (object_delay) "
                                "shifts its time stamps");
      warnings.push_back(what + "; " + AlignedText(*registration, alignment) + also);
    } else if (misfit && unit_gate) {
      warnings.push_back(what + "; not aligned on " + unit_doubt + " (warned above): fix that, then estimate "
                                "again (estimates may be worse than the raw measurements)");
    } else if (misfit && too_little) {
      warnings.push_back(what + internal::Format("; too little contact to place it by (%.2f s): not aligned, check the shape "
                                                 "file (estimates may be worse than the raw measurements)",
                                                 registration->independent_samples * options.correlation_time));
    } else if (misfit) {
      warnings.push_back(what + "; estimates may be worse than the raw measurements. The contacts suggest " +
                         registration->Describe() + ": --align-shape auto or on aligns it");
    } else {
      warnings.push_back(what + ", and no rigid placement fits it better: a wrong probe radius or object size?");
    }
  }

  if (suspect && alignment.aligned) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the object's shape fits this recording within the tolerance, but the contacts (log-likelihood +%.1f) "
                  "and the whole graph fit it clearly better elsewhere; ",
                  registration->evidence);
    warnings.push_back(text + AlignedText(*registration, alignment));
  }
  if (frame_wins && alignment.aligned) {
    char text[300];
    std::snprintf(text, sizeof text,
                  "the object's shape fits the contacts as given, but they do not fix its position in every direction, "
                  "and the whole graph (the push's mechanics) places it elsewhere (cost %.1f against %.1f as given); ",
                  frame_cost, frame_given_cost);
    warnings.push_back(text + AlignedText(*registration, alignment));
  } else if (alignment.aligned && alignment.check.fits && !suspect) {
    // Asked for (align_shape "on") on a shape that fits: say what was applied, it was silent.
    warnings.push_back(std::string("the object's shape fits this recording as given") +
                       (identity_wins ? " and the whole graph prefers it to the other placements; align_shape \"on\" "
                                        "refined it from there in the graph and "
                                      : "; align_shape \"on\" ") +
                       AlignedText(*registration, alignment));
  }
  // A suspicion the whole graph settled is a note, not a warning: an L-shaped plate's true shape
  // "fit better turned by 110.3 degrees" by the contacts (+16.5), graph cost 797.4 against 529.3
  // as given, and every push of it warned so, suggesting --align-shape on (a hostile user's session).
  // Where the contacts leave several placements open, the same verdict from the whole graph (QS:
  // the CP and SDF graphs have no mechanics to place the support by): true L-shaped plates
  // "fit better turned by 108.7 to 152 degrees" on 5 of 6 simulated pushes, each warned.
  // Only a suspicion (the shape as given within the tolerance; a misfit is warned as one), and
  // only where the placement comparisons above did not run.
  const bool ambiguous_suspicion = registration && !misfit && registration->better_elsewhere && registration->ambiguous &&
                                   !alignment.aligned && config.align_shape == Align::kAuto && !unit_gate && !too_little;
  if (ambiguous_suspicion && model == Model::kQs) {
    try {
      const push::Trajectory judged = WithoutFinalRest(trajectory);
      ShapeTransform refined;
      const SolverStats placed = framed_cost(judged, registration->transform, &refined, quick);
      const SolverStats given = EstimateBatch(judged, model, quick).solver;
      const bool compared = Converged(placed) && Converged(given);
      alignment.notes.push_back(internal::Format("the contacts' best placement: graph cost %.1f against %.1f as given%s",
                                                 placed.final_cost, given.final_cost,
                                                 compared ? "" : " (a solve stalled or stopped at its limit: no comparison)"));
      graph_rejects_contacts_best = compared && given.final_cost + kFrameMargin < placed.final_cost;
    } catch (const std::exception& e) {
      alignment.notes.push_back(std::string("the contacts' best placement not compared in the graph: ") + e.what());
    }
  }
  if (((suspect && identity_wins) || ambiguous_suspicion) && graph_rejects_contacts_best && !alignment.aligned && !unit_gate) {
    alignment.notes.push_back(internal::Format(
        "the contacts fit the shape better %s (log-likelihood +%.1f), but the whole graph rejects that placement "
        "(by more than %.0f in cost): the shape as given is used",
        contacts_best.c_str(), registration->evidence, kFrameMargin));
  } else if (registration && registration->fits_as_given && registration->better_elsewhere && !alignment.aligned) {
    // The gaps are within tolerance, but a different placement explains the contacts clearly
    // better: say so; aligning on this alone misfired on pushes that break the model.
    // Where other placements fit the contacts about as well, "on" would apply the graph's pick
    // among them, no proof (the true notched block, pushed and left resting, was aligned by
    // -117.6 degrees so): the warning says the recording does not settle it instead.
    const std::string advice =
        unit_gate ? std::string("; not aligned on ") + unit_doubt + " (warned above)"
        : registration->ambiguous
            ? "; " + registration->ambiguity + ": this recording does not settle the placement, check the shape file's frame "
                                               "(pushes on several sides, registered together by pushgraph evaluate, fix more)"
            : ": if the shape file's frame is uncertain, --align-shape on aligns it";
    warnings.push_back(internal::Format("the object's shape fits this recording within the tolerance, but the contacts fit it "
                                        "better %s (log-likelihood +%.1f)%s",
                                        registration->Describe().c_str(),
                                        registration->evidence,
                                        suspect && !unit_gate ? ", though the whole graph does not (the estimate uses the shape as given)" : "") +
                       advice);
  }
  if (alignment.checked || !alignment.notes.empty()) result.shape_alignment = alignment;
  if (config.diagnostics) {
    result.diagnostics =
        internal::Diagnose(*working, model, config, result, frame_state ? &*frame_state : nullptr, querier);
    for (const std::string& cause : result.diagnostics->causes) warnings.push_back("diagnostics: " + cause);
  }
  // Ground truth that scores nothing is said, not left as a missing "metrics": a file whose truth
  // was shifted by 100 s (no shared time), or truth too sparse or off the estimate's clock to be
  // read at its times (scoring.h: a sample within 1e-9 s, or two within 0.1 s to interpolate).
  if (trajectory.ground_truth && result.metrics.empty() && !result.states.empty()) {
    const push::Streams& gt = *trajectory.ground_truth;
    double first = INFINITY, last = -INFINITY;
    auto span = [&](const auto& stream) {
      if (stream.empty()) return;
      first = std::min(first, stream.front().t);
      last = std::max(last, stream.back().t);
    };
    span(gt.object_pose);
    span(gt.finger_pose);
    span(gt.contact_point);
    span(gt.force);
    if (first <= last) {
      const double t0 = result.states.front().t, t1 = result.states.back().t;
      char text[400];
      if (last < t0 || first > t1) {
        std::snprintf(text, sizeof text,
                      "the trajectory's ground truth (t = %.9g to %.9g s) shares no time with the estimate (t = %.9g to "
                      "%.9g s): no metrics (are they on one clock?)",
                      first, last, t0, t1);
      } else {
        std::snprintf(text, sizeof text,
                      "the trajectory's ground truth (t = %.9g to %.9g s) could not be read at any of the estimate's "
                      "times (a sample within 1e-9 s, or two at most 0.1 s apart around it): no metrics",
                      first, last);
      }
      warnings.push_back(text);
    }
  }
  result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
  return result;
}

}  // namespace

}  // namespace pushgraph::graph
