#include "graph_builder.h"
#include "text.h"

#include <ceres/normal_prior.h>

#include <pushgraph/geometry/contacts.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/graph/marginals.h>
#include <pushgraph/graph/shape_frame.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <set>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <sstream>
#include <tuple>


// GraphBuilder (graph_builder.h): the paper's graphs step by step, shared by the batch and
// incremental estimators.
namespace pushgraph::graph::internal {
namespace {

Pose2 InterpolatePose(const std::vector<push::PoseSample>& all, double t, double limit) {
  // Only the samples up to `limit`.
  const auto end = std::upper_bound(all.begin(), all.end(), limit,
                                    [](double tt, const push::PoseSample& a) { return tt < a.t; });
  if (end == all.begin()) return all.front().pose;
  return push::PoseAtClamped(all.begin(), end, t);
}

template <class Sample>
double NearestGap(const std::vector<Sample>& s, double t, int* index = nullptr) {
  if (s.empty()) return INFINITY;
  auto it = std::lower_bound(s.begin(), s.end(), t, [](const Sample& a, double tt) { return a.t < tt; });
  double best = INFINITY;
  int bi = -1;
  if (it != s.end()) { best = it->t - t; bi = static_cast<int>(it - s.begin()); }
  if (it != s.begin() && t - (it - 1)->t < best) { best = t - (it - 1)->t; bi = static_cast<int>(it - s.begin()) - 1; }
  if (index != nullptr) *index = bi;
  return best;
}

}  // namespace

// The object's random walk where the finger is measured at rest (QS): 2 mm and 0.02 rad over a
// second, a fraction of a tracker's noise; a slow creep under PoseStreamAtRest's bound (8 mm/s)
// is not held still by more than that.
constexpr double kRestWalkTrans = 2e-3;  // m / sqrt(s)
constexpr double kRestWalkRot = 2e-2;    // rad / sqrt(s)

bool ObjectSeenMoving(const std::vector<push::PoseSample>& poses, double sigma, std::size_t* scanned) {
  if (poses.size() < 10) return false;
  auto median_at = [&](std::size_t last) {  // of poses[last - 4 .. last]
    std::vector<double> x, y;
    for (std::size_t k = last - 4; k <= last; ++k) x.push_back(poses[k].pose.x), y.push_back(poses[k].pose.y);
    return Vec2(Median(x), Median(y));
  };
  const Vec2 start = median_at(4);
  const double bound = std::max(0.02, 4.0 * sigma);
  for (std::size_t& i = *scanned; i < poses.size(); ++i)
    if (i >= 9 && (median_at(i) - start).norm() > bound) return true;
  return false;
}

bool PoseStreamAtRest(const std::vector<push::PoseSample>& poses, double t, double sigma) {
  return PoseStreamRest(poses, t, sigma) == Rest::kAtRest;
}

Rest PoseStreamRest(const std::vector<push::PoseSample>& poses, double t, double sigma) {
  // The window: long enough that 8 mm/s moves the stream by its bound below (200 sigma s/m),
  // from 0.1 s to 1 s (0.1 s under a 0.5 mm tracker, 1 s under 5 mm): a slow push is not taken
  // for rest, and a rest is found only where it lasts longer than the window's half.
  const double half_window = std::clamp(200.0 * sigma, 0.1, 1.0);
  const auto a = std::lower_bound(poses.begin(), poses.end(), t - half_window,
                                  [](const push::PoseSample& p, double tt) { return p.t < tt; });
  const auto b = std::upper_bound(poses.begin(), poses.end(), t + half_window,
                                  [](double tt, const push::PoseSample& p) { return tt < p.t; });
  const std::ptrdiff_t n = b - a;
  if (n < 4 || (b - 1)->t - a->t < half_window) return Rest::kUnknown;  // too little to tell (a stream's ends, a gap)
  const std::ptrdiff_t k = std::min<std::ptrdiff_t>(5, n / 2);  // samples in each end's median
  auto median_of = [k](auto first) {
    std::vector<double> x, y;
    for (std::ptrdiff_t j = 0; j < k; ++j, ++first) x.push_back(first->pose.x), y.push_back(first->pose.y);
    return Vec2(Median(x), Median(y));
  };
  // Two medians of k samples differ by about 1.25 sigma sqrt(2 / k) under Gaussian noise: four
  // of those, and at least 1 mm.
  const double bound = std::max(1e-3, 4.0 * 1.25 * sigma * std::sqrt(2.0 / static_cast<double>(k)));
  return (median_of(b - k) - median_of(a)).norm() < bound ? Rest::kAtRest : Rest::kMoving;
}

bool ForceSaysTouching(const std::vector<push::ForceSample>& force, double t, double max_gap, double threshold,
                       double sigma) {
  int k = -1;
  const double gap = NearestGap(force, t, &k);
  if (k < 0 || gap > max_gap) return false;
  const double half = std::max(0.02, gap);
  auto it = std::lower_bound(force.begin(), force.end(), t - half - 1e-12,
                             [](const push::ForceSample& a, double tt) { return a.t < tt; });
  std::vector<double> x, y;
  for (; it != force.end() && it->t <= t + half + 1e-12; ++it) x.push_back(it->force.x()), y.push_back(it->force.y());
  if (x.empty()) return false;
  // The component-wise median: the simulator's bimodal noise has outliers that a mean follows.
  // Its spread is about 1.25 sigma / sqrt(n) under Gaussian noise: 4 of those (at 3, a free
  // finger's median still crossed it on 8 of 500 steps of two pushes, its noise over its sigma).
  const double n = static_cast<double>(x.size());
  return Vec2(Median(x), Median(y)).norm() >= std::max(threshold, 5.0 * sigma / std::sqrt(n));
}

bool ForceContactHeld(const std::vector<push::ForceSample>& force, double t, double max_gap, double threshold,
                      double sigma) {
  constexpr double kHold = 0.05;  // s: three windows 0.1 s apart in all, each of +-20 ms
  auto says = [&](double at) { return ForceSaysTouching(force, at, max_gap, threshold, sigma); };
  return says(t) && ((says(t + kHold) && says(t + 2.0 * kHold)) || (says(t - kHold) && says(t - 2.0 * kHold)));
}

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model, const EstimatorConfig& config,
                           std::shared_ptr<const geometry::ShapePairQuerier> querier)
    : traj_(trajectory), model_(model), cfg_(config) {
  ValidateConfig(cfg_);
  ValidateTrajectory(traj_);
  // Which sensors exist: any finger's non-empty stream (a finger whose stream is empty while
  // another's is not never touched).
  streams_.contact_point = !traj_.measured.contact_point.empty();
  streams_.force = !traj_.measured.force.empty();
  for (const push::ExtraFinger& f : traj_.extra_fingers) {
    streams_.contact_point = streams_.contact_point || !f.measured.contact_point.empty();
    streams_.force = streams_.force || !f.measured.force.empty();
  }
  // Several fingers: estimated by CP, SDF and QS; the baseline (one contact, as published)
  // leaves fingers 1, 2, ... out and says so.
  other_fingers_ = model_ == Model::kYu ? 0 : static_cast<int>(traj_.extra_fingers.size());
  fingers_ignored_ = !traj_.extra_fingers.empty() && model_ == Model::kYu;
  used_.assign(4 + 3 * other_fingers_, 0);
  AppendSteps(INFINITY);
  SetUpShapes(std::move(querier));
}

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model,
                           const EstimatorConfig& config, const OnlineStreams& streams)
    : traj_(trajectory), model_(model), cfg_(config), streams_(streams) {
  ValidateConfig(cfg_);
  if (traj_.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj_.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
  ValidateFingers(traj_);
  other_fingers_ = model_ == Model::kYu ? 0 : static_cast<int>(traj_.extra_fingers.size());
  fingers_ignored_ = !traj_.extra_fingers.empty() && model_ == Model::kYu;
  used_.assign(4 + 3 * other_fingers_, 0);
  SetUpShapes(nullptr);
}

int GraphBuilder::AppendSteps(double until) {
  const auto& m = traj_.measured;
  // Steps: the union of all time stamps (merged when closer than 1e-9 s).
  std::vector<std::tuple<double, int, int>> events;  // t, stream, index
  auto take = [&](const auto& stream, int id) {
    std::size_t& i = used_[id];
    for (; i < stream.size() && stream[i].t <= until; ++i) events.emplace_back(stream[i].t, id, int(i));
  };
  take(m.object_pose, 0);
  take(m.finger_pose, 1);
  take(m.contact_point, 2);
  take(m.force, 3);
  for (int k = 1; k <= other_fingers_; ++k) {
    take(FingerPoseRows(k), 3 * k + 1);
    take(ContactRows(k), 3 * k + 2);
    take(ForceRows(k), 3 * k + 3);
  }
  std::sort(events.begin(), events.end());
  const std::size_t first_new = steps_.size();
  for (const auto& [t, stream, index] : events) {
    // (OnlineEstimator only accepts samples more than 1e-9 s after the last update's steps.)
    if (steps_.size() == first_new || t - steps_.back().t > 1e-9) {
      steps_.push_back(Step{});
      steps_.back().t = t;
      steps_.back().others.resize(other_fingers_);
    }
    Step& s = steps_.back();
    if (stream == 2 && s.contact >= 0) {
      // Two contact rows at one time: a finger touching the object at two points. More: the
      // two farthest apart (below).
      if (s.contact2 < 0) s.contact2 = index;
      continue;
    }
    if (stream < 4) {
      int* slots[] = {&s.object, &s.finger, &s.contact, &s.force};
      *slots[stream] = index;
    } else {
      Step::OtherFinger& o = s.others[(stream - 1) / 3 - 1];
      if ((stream - 1) % 3 == 1 && o.contact >= 0) {  // finger k's second row at this time
        if (o.contact2 < 0) o.contact2 = index;
        continue;
      }
      int* slots[] = {&o.finger, &o.contact, &o.force};
      *slots[(stream - 1) % 3] = index;
    }
  }
  // Three or more contact rows at one time (a flat pusher face along a face broken by a notch):
  // the two farthest apart. For contacts along one straight finger face, which share its normal,
  // they span every wrench the others can apply (a force at a point between them is a convex
  // combination of the same force at the two); for others it is an approximation, and the
  // result's warnings count those steps.
  for (std::size_t i = first_new; i < steps_.size(); ++i) {
    for (int k = 0; k < num_fingers(); ++k) {
      if (SecondContactRow(i, k) < 0) continue;
      const auto& rows = ContactRows(k);
      const auto [first, last] = ContactRowsAt(rows, ContactRow(i, k));
      if (last - first + 1 <= 2) continue;
      ++steps_with_more_contacts_;
      const auto [a, b] = FarthestContactRows(rows, ContactRow(i, k));
      ContactRow(i, k) = a;
      SecondContactRow(i, k) = b;
    }
  }
  // Contact gating, on the samples received so far (all of them in batch): a finger touches
  // while its nearest contact sample is within contact_max_gap, or, without a contact stream,
  // while its nearest force sample is at least contact_force_threshold, once its force stream
  // has shown a contact above its noise (ForceSaysTouching) anywhere or the object has been seen
  // to move (ObjectSeenMoving); with neither stream, always.
  // The sensors are the trajectory's: a finger whose contact stream is empty while another
  // finger's is not never touched (its own force noise must not gate it in).
  force_contact_seen_.resize(num_fingers(), 0);
  force_samples_seen_.resize(num_fingers(), 0);
  force_contact_first_.resize(num_fingers(), INFINITY);
  force_contact_last_.resize(num_fingers(), -INFINITY);
  if (!streams_.contact_point && !object_moving_seen_)
    object_moving_seen_ = ObjectSeenMoving(m.object_pose, cfg_.measurement.object_trans, &object_poses_seen_);
  force_contact_held_.resize(num_fingers(), 0);
  for (int k = 0; k < num_fingers() && !streams_.contact_point; ++k) {
    const auto& force = ForceRows(k);
    for (std::size_t& j = force_samples_seen_[k]; j < force.size(); ++j) {
      if (!ForceSaysTouching(force, force[j].t, cfg_.contact_max_gap, cfg_.contact_force_threshold, cfg_.measurement.force))
        continue;
      force_contact_first_[k] = std::min(force_contact_first_[k], force[j].t);
      force_contact_last_[k] = force[j].t;
      // A contact is seen only where the force holds it for 0.1 s somewhere (ForceContactHeld);
      // the span it opens still starts at the first crossing (a contact's onset crosses on and off).
      if (!force_contact_held_[k] &&
          ForceContactHeld(force, force[j].t, cfg_.contact_max_gap, cfg_.contact_force_threshold, cfg_.measurement.force))
        force_contact_held_[k] = 1;
    }
    force_contact_seen_[k] = force_contact_held_[k] || object_moving_seen_;
  }
  auto touching = [&](const std::vector<push::PointSample>& contact, const std::vector<push::ForceSample>& force,
                      double t, int finger) {
    if (streams_.contact_point) return NearestGap(contact, t) <= cfg_.contact_max_gap;
    if (force.empty()) return !streams_.force;
    if (!force_contact_seen_[finger]) return false;
    // Before the first and after the last contact above the force's noise (with 0.1 s to spare),
    // the finger approaches or leaves: an 8 cm approach had 243 of its 400 free steps gated in by
    // the noise and the object dragged 67 mm to the finger (38.5 mm RMS against 7.1 raw; now
    // 2.8). Between them the single sample gates, light touches included (gating every step on
    // the median cost the MIT ellip1 set 10 % in object RMS; this span gains 0.6 %).
    if (std::isfinite(force_contact_first_[finger]) &&
        (t < force_contact_first_[finger] - 0.1 || t > force_contact_last_[finger] + 0.1))
      return false;
    int k = -1;
    const double gap = NearestGap(force, t, &k);
    return k >= 0 && gap <= cfg_.contact_max_gap && force[k].force.norm() >= cfg_.contact_force_threshold;
  };
  // A touching finger has two contacts while its nearest contact time has two rows.
  auto two_rows_nearest = [&](const std::vector<push::PointSample>& contact, double t) {
    if (!streams_.contact_point) return false;
    int row = -1;
    NearestGap(contact, t, &row);
    const auto [first, last] = ContactRowsAt(contact, row);
    return last > first;
  };
  for (std::size_t i = first_new; i < steps_.size(); ++i) {
    Step& s = steps_[i];
    for (int k = 1; k <= other_fingers_; ++k) {
      Step::OtherFinger& o = s.others[k - 1];
      o.in_contact = touching(ContactRows(k), ForceRows(k), s.t, k);
      o.two_contacts = o.in_contact && two_rows_nearest(ContactRows(k), s.t);
    }
    s.in_contact = touching(m.contact_point, m.force, s.t, 0);
    if (s.in_contact && streams_.contact_point) {
      s.two_contacts = two_rows_nearest(m.contact_point, s.t);
      if (s.two_contacts && model_ == Model::kYu) {
        // The baseline models one contact, as published: it keeps the first of the two.
        s.two_contacts = false;
        ++second_contacts_ignored_;
      }
    }
  }
  vars_.resize(steps_.size());
  if (other_fingers_ > 1) more_vars_.resize(steps_.size() * (other_fingers_ - 1));
  if (other_fingers_ > 0) second_vars_.resize(steps_.size() * num_fingers());
  return static_cast<int>(steps_.size() - first_new);
}

std::shared_ptr<const geometry::ShapePairQuerier> GraphBuilder::MakeQuerier(const push::Trajectory& trajectory,
                                                                          const EstimatorConfig& config) {
  return MakeQuerier(trajectory, trajectory.finger.shape, config);
}

std::shared_ptr<const geometry::ShapePairQuerier> GraphBuilder::MakeQuerier(const push::Trajectory& trajectory,
                                                                          const geometry::Shape& finger,
                                                                          const EstimatorConfig& config) {
  geometry::ShapePairQuerier::Options pair_options;
  pair_options.angle_cache_resolution = config.finger_angle_resolution;
  pair_options.max_cached_angles = 4096;
  pair_options.check_rounded_depth = false;  // the factors never read depth_exact: no second query
  return std::make_shared<geometry::ShapePairQuerier>(trajectory.object.shape, finger, pair_options);
}

void GraphBuilder::SetUpShapes(std::shared_ptr<const geometry::ShapePairQuerier> querier) {
  querier_ = querier ? std::move(querier) : MakeQuerier(traj_, cfg_);
  object_outer_ = traj_.object.shape;
  std::vector<geometry::Polygon> outer;
  for (const geometry::Polygon& polygon : traj_.object.shape.polygons()) {
    object_has_holes_ = object_has_holes_ || !polygon.holes.empty();
    outer.push_back({polygon.outer, {}});
  }
  if (object_has_holes_) object_outer_ = geometry::Shape::FromPolygons(outer, traj_.object.shape.radius());
  for (int k = 0; k < num_fingers(); ++k)
    finger_has_faces_.push_back(!(FingerShape(k).is_degenerate_core() && FingerShape(k).num_vertices() <= 1));
  for (int k = 1; k <= other_fingers_; ++k) other_queriers_.push_back(MakeQuerier(traj_, FingerShape(k), cfg_));
  if (ModelHasForce(model_)) qs_ = QuasiStaticGeometryFor(traj_, cfg_);
  if (traj_.object.mass > 0.0 && traj_.object.mu_surface > 0.0) {
    mu_surface_ = traj_.object.mu_surface;
    normal_load_ = traj_.object.mass * limit_surface::kStandardGravity;
    f_max_ = mu_surface_ * normal_load_;
  }
  // The force model's fixed scales (eps_force's cap aside, force_random_walk in N/sqrt(s), the
  // solver's tolerances) assume loads of a millinewton or more: below that the estimate was broken
  // (a 1e-5 kg object without a force stream: forces stuck near 0.1 N, object RMS 1.6 mm against
  // 0.6 with its true 0.5 kg) while the exit status said nothing.
  constexpr double kMinFrictionLoad = 1e-3;  // N
  if (ModelHasForce(model_) && f_max_ > 0.0 && f_max_ < kMinFrictionLoad) {
    throw GraphError(Format("object: its friction load mu_surface m g = %.3g N (mu_surface %.3g, mass %.3g kg) is below "
                            "the %.0e N the force model supports: is the mass in kg?",
                            f_max_, mu_surface_, traj_.object.mass, kMinFrictionLoad));
  }
  // eps_force regularizes |g'| (N) in D and the load; against a light object's f_max a fixed 0.05 N
  // would dominate the wrench (a 10 g block: f_max 0.03 N, so |g'|_eps / f_max >= 1.7 and the load
  // factor could never hold). Capped at f_max / 20, it stays a small fraction of any load.
  eps_force_ = f_max_ > 0.0 ? std::min(cfg_.eps_force, f_max_ / 20.0) : cfg_.eps_force;
  using Load = EstimatorConfig::LimitSurfaceLoad;
  {
    std::vector<double> d;
    const auto& force = traj_.measured.force;
    for (std::size_t k = 1; k < force.size(); ++k) d.push_back(force[k].t - force[k - 1].t);
    force_period_ = d.empty() ? 0.0 : Median(d);
  }
  use_load_factor_ = f_max_ > 0.0 && (cfg_.limit_surface_load == Load::kOn ||
                                      (cfg_.limit_surface_load == Load::kAuto && !streams_.force));
}

void GraphBuilder::EnableCEstimation() {
  if (model_ != Model::kQs) return;
  estimate_c_ = true;
  c_var_[0] = qs_.c;
}

namespace {
// A shared scalar parameter (c, mu): a Gaussian prior of relative sigma around its nominal
// value and bounds [0.2, 5] times it.
void AddSharedParameterPrior(GraphBuilder& builder, ceres::Problem& problem, double* parameter, double nominal,
                             double relative_sigma) {
  ceres::Matrix A(1, 1);
  ceres::Vector b(1);
  A(0, 0) = 1.0 / (relative_sigma * nominal);
  b(0) = nominal;
  builder.Add(problem, FactorType::kPrior, new ceres::NormalPrior(A, b), nullptr, {parameter});
  problem.SetParameterLowerBound(parameter, 0, 0.2 * nominal);
  problem.SetParameterUpperBound(parameter, 0, 5.0 * nominal);
}
}  // namespace

const char* FactorTypeName(FactorType t) {
  switch (t) {
    case FactorType::kObjectPose: return "object_pose";
    case FactorType::kFingerPose: return "finger_pose";
    case FactorType::kContactPoint: return "contact_point";
    case FactorType::kForce: return "force";
    case FactorType::kContactOnObject: return "contact_on_object";
    case FactorType::kContactOnFinger: return "contact_on_finger";
    case FactorType::kTouching: return "touching";
    case FactorType::kIntersection: return "intersection";
    case FactorType::kConstantVelocity: return "constant_velocity";
    case FactorType::kZeroVelocity: return "zero_velocity";
    case FactorType::kForceContinuity: return "force_continuity";
    case FactorType::kForcePrior: return "force_prior";
    case FactorType::kQuasiStatic: return "quasi_static";
    case FactorType::kLimitSurfaceLoad: return "limit_surface_load";
    case FactorType::kPrior: return "priors";
  }
  return "?";
}

std::string GraphBuilder::Describe(ceres::ResidualBlockId id) const {
  auto it = origin_.find(id);
  if (it == origin_.end()) {
    it = warm_origin_.find(id);
    if (it == warm_origin_.end()) return "a marginal prior or unnamed factor";
  }
  const auto [type, step] = it->second;
  std::string s = std::string(FactorTypeName(type)) + " factor";
  if (step >= 0 && step < static_cast<int>(steps_.size())) {
    s += " at step " + std::to_string(step) + " (t = " + internal::StepTime(steps_[step].t, steps_.front().t) + ")";
  } else {
    s += " (shared by the trajectory)";
  }
  return s;
}

SolveOutcome GraphBuilder::Solve(ceres::Problem& problem, int max_iterations, double function_tolerance,
                                 const char* what, int soft_iteration_limit, double soft_tolerance) const {
  SolveOutcome out;
  const bool soft = soft_iteration_limit > 0 && soft_iteration_limit < max_iterations;
  if (!(soft_tolerance > 0.0)) soft_tolerance = ChainSolverOptions().soft_function_tolerance;
  if (cfg_.solver == EstimatorConfig::Solver::kCeres) {
    // The soft limit as two solves: soft_iteration_limit - 1 iterations at the tolerance, then
    // the rest at soft_tolerance, so that iteration soft_iteration_limit is the first that can
    // stop on it. Ceres tests the cost change of a step before it accepts it, so a rejected step
    // that changes the cost that little ends the second solve too; and any end of the second
    // solve counts as unconverged (Finish() then re-solves the last window once).
    const int first_iterations = soft ? soft_iteration_limit - 1 : max_iterations;
    ceres::Solver::Summary summary;
    if (first_iterations > 0) {
      ceres::Solve(SolverOptions(first_iterations, function_tolerance), &problem, &summary);
      LogSummary(what, summary);
      if (summary.termination_type == ceres::FAILURE) throw GraphError(std::string(what) + " failed: " + summary.message);
      out.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
    }
    bool soft_stop = false;
    if (soft && (first_iterations == 0 || summary.termination_type == ceres::NO_CONVERGENCE)) {
      ceres::Solver::Summary rest;
      // Never tighter than the ordinary tolerance, on which the chain solver stops first.
      ceres::Solve(SolverOptions(max_iterations - first_iterations, std::max(soft_tolerance, function_tolerance)), &problem, &rest);
      LogSummary(what, rest);
      if (rest.termination_type == ceres::FAILURE) throw GraphError(std::string(what) + " failed: " + rest.message);
      // Both summaries count Ceres' iteration 0 (the evaluation at the start) as a step.
      out.iterations += rest.num_successful_steps + rest.num_unsuccessful_steps - (first_iterations > 0 ? 1 : 0);
      soft_stop = true;
      summary = rest;
    }
    out.final_cost = summary.final_cost;
    out.converged = !soft_stop && summary.termination_type == ceres::CONVERGENCE;
    out.termination = summary.message;
    return out;
  }
  ChainSolverOptions options;
  options.max_iterations = max_iterations;
  options.function_tolerance = function_tolerance;
  if (soft) {
    options.soft_iteration_limit = soft_iteration_limit;
    options.soft_function_tolerance = soft_tolerance;
  }
  options.describe = [this](ceres::ResidualBlockId id) { return Describe(id); };
  options.log_iterations = SolverLogLevel() >= 2;
  options.model_confirms_convergence = !incremental_;
  out.chain = std::make_unique<ChainSolver>(problem);
  ChainSolverSummary summary;
  try {
    summary = out.chain->Solve(options);
  } catch (const GraphError& e) {
    throw GraphError(std::string(what) + ": " + e.what());
  }
  if (SolverLogLevel() >= 1) {
    std::fprintf(stderr,
                 "pushgraph %s (chain solver): %d unknowns, %d iterations (%d successful), cost %.6e -> %.6e, %s; "
                 "%.3f ms (evaluation %.3f, linear %.3f), J^T J nonzeros %ld, factor nonzeros %ld, %.3g flops per "
                 "factorization\n",
                 what, summary.unknowns, summary.iterations, summary.successful_steps, summary.initial_cost,
                 summary.final_cost, summary.termination.c_str(), 1e3 * summary.total_s, 1e3 * summary.evaluate_s,
                 1e3 * summary.linear_solve_s, summary.hessian_nonzeros, summary.factor_nonzeros, summary.factor_flops);
  }
  out.iterations = summary.iterations;
  out.final_cost = summary.final_cost;
  out.converged = summary.converged;
  out.stalled = summary.stalled;
  out.termination = summary.termination;
  out.evaluation_s = summary.evaluate_s;
  out.linear_solve_s = summary.linear_solve_s;
  out.factor_flops = summary.factor_flops;
  return out;
}

void GraphBuilder::EnableShapeFrame(const Vec2& centroid, double sigma_centroid, double sigma_theta, bool rotation) {
  shape_frame_ = true;
  frame_centroid_ = centroid;
  frame_sigma_centroid_ = sigma_centroid;
  frame_sigma_theta_ = sigma_theta;
  frame_rotation_ = rotation;
}

ceres::ResidualBlockId GraphBuilder::Add(ceres::Problem& problem, FactorType type, ceres::CostFunction* cost,
                                         ceres::LossFunction* loss, std::vector<double*> blocks,
                                         std::vector<int> object_pose_blocks) {
  if (shape_frame_ && !warm_start_ && !object_pose_blocks.empty()) {
    blocks.push_back(frame_);
    cost = new ShapeFrameFactor(cost, std::move(object_pose_blocks));
    if (!frame_in_problem_) {
      frame_in_problem_ = true;
      // A circular outline's angle is unobservable: a stiff prior holds it (SparseMarginals takes
      // no manifolds), and its sigma is not reported.
      const double sigma_theta = frame_rotation_ ? frame_sigma_theta_ : 1e-6;
      Add(problem, FactorType::kPrior, new ShapeFramePrior(frame_centroid_, frame_sigma_centroid_, sigma_theta), nullptr,
          {frame_});
    }
  }
  const ceres::ResidualBlockId id = problem.AddResidualBlock(cost, loss, blocks);
  if (warm_start_) {
    warm_origin_[id] = {type, type == FactorType::kPrior ? -1 : adding_step_};
    return id;
  }
  if (tags_ != nullptr) tags_->push_back({type, id});
  origin_[id] = {type, type == FactorType::kPrior ? -1 : adding_step_};
  return id;
}

void GraphBuilder::EnableMuEstimation() {
  if (model_ != Model::kQs) return;
  if (!(f_max_ > 0.0)) {
    throw GraphError("estimate_mu needs the object's mass and mu_surface in the trajectory");
  }
  if (!streams_.force) {
    // Scaling every force and mu together leaves D and the load factor unchanged: only the
    // force priors would decide, and they pull mu down (measured: to its lower bound, with a
    // confident sigma). Refuse rather than report that.
    throw GraphError("estimate_mu needs a force stream: without force measurements mu is not observable");
  }
  estimate_mu_ = true;
  use_load_factor_ = true;
  mu_var_[0] = mu_surface_;
}

void GraphBuilder::Initialize(int i, double limit) {
  const bool causal = std::isfinite(limit);
  const auto& m = traj_.measured;
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  const StepVars* prev = i > 0 ? &vars_[i - 1] : nullptr;
  auto set_pose = [](double* dst, const Pose2& p) { dst[0] = p.x; dst[1] = p.y; dst[2] = p.theta; };
  auto continuous = [](double* dst, const double* ref) {  // keep theta continuous with ref
    dst[2] = ref[2] + geometry::WrapAngle(dst[2] - ref[2]);
  };
  // Measurements interpolated, using only samples up to `limit` (causal in incremental mode;
  // beyond the newest sample its value is held).
  if (s.object >= 0) set_pose(v.x, m.object_pose[s.object].pose);
  else set_pose(v.x, InterpolatePose(m.object_pose, s.t, limit));
  if (s.finger >= 0) set_pose(v.e, m.finger_pose[s.finger].pose);
  else set_pose(v.e, InterpolatePose(m.finger_pose, s.t, limit));
  if (prev != nullptr) {
    continuous(v.x, prev->x);
    continuous(v.e, prev->e);
  }
  for (int k = 1; k <= other_fingers_; ++k) InitializeOtherFinger(i, k, limit);
  if (s.in_contact) {
    if (s.contact >= 0) {
      const Vec2 c = m.contact_point[s.contact].point;
      v.p[0] = c.x(); v.p[1] = c.y();
    } else if (!m.contact_point.empty() && !causal) {
      const Vec2 c = push::StreamValueClamped(m.contact_point, s.t, [](const push::PointSample& a) { return Vec2(a.point); });
      v.p[0] = c.x(); v.p[1] = c.y();
    } else if (causal && prev != nullptr && steps_[i - 1].in_contact) {
      v.p[0] = prev->p[0]; v.p[1] = prev->p[1];
    } else {
      // The object boundary point closest to the finger's reference point.
      const auto q = geometry::QueryPoint(traj_.object.shape, Pose2{v.x[0], v.x[1], v.x[2]}, Vec2(v.e[0], v.e[1]));
      v.p[0] = q.closest_point.x(); v.p[1] = q.closest_point.y();
    }
    if (s.two_contacts) InitializeSecondContact(i, 0, causal);
    if (s.force >= 0) {
      v.f[0] = m.force[s.force].force.x(); v.f[1] = m.force[s.force].force.y();
    } else if (!m.force.empty() && !causal) {
      const Vec2 f = push::StreamValueClamped(m.force, s.t, [](const push::ForceSample& a) { return Vec2(a.force); });
      v.f[0] = f.x(); v.f[1] = f.y();
    } else if (causal && prev != nullptr && steps_[i - 1].in_contact) {
      v.f[0] = prev->f[0]; v.f[1] = prev->f[1];
    } else {
      // Small, into the object along its inward normal at the contact (D's gradient in f is
      // defined for any f, but not its sign: towards the object's origin, as it was, pointed
      // outwards from a contact beside an origin at a corner).
      const auto q = geometry::QueryPoint(traj_.object.shape, Pose2{v.x[0], v.x[1], v.x[2]}, Vec2(v.p[0], v.p[1]));
      const Vec2 d = q.normal.allFinite() && q.normal.norm() > 0.5 ? Vec2(-0.1 * q.normal) : Vec2(0.1, 0.0);
      v.f[0] = d.x(); v.f[1] = d.y();
    }
    if (s.two_contacts) {
      // The measured (net) force shared by both contacts to start.
      double* f2 = SecondContactForce(i, 0);
      f2[0] = v.f[0] = 0.5 * v.f[0];
      f2[1] = v.f[1] = 0.5 * v.f[1];
    }
  }
}

std::vector<std::pair<GraphBuilder::ContactFeature, Vec2>> GraphBuilder::NearbyContactFeatures(int i, int k) const {
  const StepVars& v = vars_[i];
  const double* pose = FingerPose(i, k);
  const Pose2 x{v.x[0], v.x[1], v.x[2]}, e{pose[0], pose[1], pose[2]};
  // Candidates: every object feature the finger is near at the current values (3 sigma of a
  // contact measurement: the values may be that far off), each once.
  const double tolerance = 3.0 * cfg_.measurement.contact;
  std::vector<geometry::ContactPoint> found;
  try {
    found = geometry::FindContacts(traj_.object.shape, x, FingerShape(k), e, {tolerance, tolerance});
  } catch (const geometry::GeometryError&) {
    return {};
  }
  std::vector<std::pair<ContactFeature, Vec2>> distinct;
  // Each feature once, in the order found (a set: a detailed object near the finger has
  // thousands of features within the tolerance, and a linear search made this quadratic).
  std::set<std::tuple<bool, int, int, int>> seen;
  for (const geometry::ContactPoint& c : found) {
    ContactFeature f;
    f.edge = c.object_feature;
    f.vertex = c.kind != geometry::ContactPoint::Kind::kFingerVertexObjectEdge;
    if (seen.insert({f.vertex, f.edge.polygon, f.edge.ring, f.edge.index}).second) distinct.push_back({f, c.object_point});
  }
  return distinct;
}

bool GraphBuilder::TwoContactFeatures(int i, int finger, ContactFeature out[2]) const {
  const std::vector<std::pair<ContactFeature, Vec2>> distinct = NearbyContactFeatures(i, finger);
  const double* pa = FingerContact(i, finger);
  const double* pb = SecondContactPoint(i, finger);
  if (finger_has_faces_[finger]) {
    // A finger with straight faces touches one object edge at two points (a flat pusher face on
    // an object face): each contact to the feature nearest it, the same one or not.
    if (distinct.empty()) return false;
    for (int k = 0; k < 2; ++k) {
      const Vec2 p = k == 0 ? Vec2(pa[0], pa[1]) : Vec2(pb[0], pb[1]);
      out[k] = std::min_element(distinct.begin(), distinct.end(), [&](const auto& a, const auto& b) {
                 return (p - a.second).squaredNorm() < (p - b.second).squaredNorm();
               })->first;
    }
    return true;
  }
  // A disk touches an edge at one point: two contacts are on two distinct features (two walls).
  if (distinct.size() < 2) return false;
  // Each contact variable to its own feature: the pair of distinct features nearest the two
  // current values (a flat pusher across a notch touches four features; the rows kept are the
  // outer two, which the features nearest them match, not the nearest by separation).
  const Vec2 p1(pa[0], pa[1]), p2(pb[0], pb[1]);
  double best = INFINITY;
  for (std::size_t a = 0; a < distinct.size(); ++a) {
    for (std::size_t b = 0; b < distinct.size(); ++b) {
      if (a == b) continue;
      const double cost = (p1 - distinct[a].second).norm() + (p2 - distinct[b].second).norm();
      if (cost < best) best = cost, out[0] = distinct[a].first, out[1] = distinct[b].first;
    }
  }
  return true;
}

bool GraphBuilder::BetweenWalls(int i) const {
  Vec2 points[2];
  return FacingWalls(i, 3.0 * cfg_.measurement.contact, points);
}

int GraphBuilder::DetectSecondContacts(int first, int last) {
  if (streams_.contact_point || model_ == Model::kYu || other_fingers_ > 0 || !(cfg_.second_contact_tolerance > 0.0)) return 0;
  int changed = 0;
  for (int i = first; i < last; ++i) {
    Step& s = steps_[i];
    if (!s.in_contact) continue;
    Vec2 points[2];
    const bool two = FacingWalls(i, cfg_.second_contact_tolerance, points);
    if (two == s.two_contacts) continue;
    ++changed;
    s.two_contacts = two;
    StepVars& v = vars_[i];
    if (two) {
      // Each contact on its wall, p the one nearer its current value; the force shared.
      const Vec2 p(v.p[0], v.p[1]);
      if ((points[1] - p).norm() < (points[0] - p).norm()) std::swap(points[0], points[1]);
      v.p[0] = points[0].x(); v.p[1] = points[0].y();
      v.p2[0] = points[1].x(); v.p2[1] = points[1].y();
      v.f2[0] = v.f[0] = 0.5 * v.f[0];
      v.f2[1] = v.f[1] = 0.5 * v.f[1];
    } else {
      v.f[0] += v.f2[0];  // back to one contact: the net force
      v.f[1] += v.f2[1];
    }
  }
  return changed;
}

bool GraphBuilder::FacingWalls(int i, double tolerance, Vec2 points[2]) const {
  // Two object edges within reach, each in front of the other (a concave pair: the walls of a
  // notch, an inside corner). Edges of a convex part (a finely tessellated ellipse) lie behind
  // each other's lines however many are within reach; vertex pairs have no wall normal.
  const StepVars& v = vars_[i];
  std::vector<geometry::ContactPoint> found;
  try {
    found = geometry::FindContacts(traj_.object.shape, Pose2{v.x[0], v.x[1], v.x[2]}, traj_.finger.shape,
                                   Pose2{v.e[0], v.e[1], v.e[2]}, {tolerance, tolerance});
  } catch (const geometry::GeometryError&) {
    return false;
  }
  using Kind = geometry::ContactPoint::Kind;
  const double margin = 1e-3 * tolerance;
  for (std::size_t a = 0; a < found.size(); ++a) {
    for (std::size_t b = a + 1; b < found.size(); ++b) {
      const geometry::ContactPoint &p = found[a], &q = found[b];
      if (p.kind != Kind::kFingerVertexObjectEdge || q.kind != Kind::kFingerVertexObjectEdge) continue;
      if ((q.object_point - p.object_point).dot(p.normal) > margin &&
          (p.object_point - q.object_point).dot(q.normal) > margin) {
        points[0] = p.object_point;
        points[1] = q.object_point;
        return true;
      }
    }
  }
  return false;
}

std::array<long long, 2> GraphBuilder::FixedFeatureKeys(bool on_features, const ContactFeature features[2]) {
  // Vertices are not kept as fixed features (AddKinematicFactors).
  std::array<long long, 2> keys{-1, -1};
  for (int k = 0; k < 2 && on_features; ++k)
    if (!features[k].vertex) keys[k] = FeatureKey(features[k]);
  return keys;
}

std::array<long long, 2> GraphBuilder::FeatureChoice(int i, int k) const {
  if (!FingerTwoContacts(i, k)) return {-1, -1};
  ContactFeature f[2];
  const bool on_features = TwoContactFeatures(i, k, f);
  return FixedFeatureKeys(on_features, f);
}

int GraphBuilder::FeatureChoicesChanged() const {
  int changed = 0;
  const int fingers = num_fingers();
  for (int i = 0; i < static_cast<int>(steps_.size()) && (i + 1) * fingers <= static_cast<int>(feature_choices_.size()); ++i)
    for (int k = 0; k < fingers; ++k) changed += FeatureChoice(i, k) != feature_choices_[i * fingers + k];
  return changed;
}

std::pair<int, int> GraphBuilder::ContactRowsAt(const std::vector<push::PointSample>& c, int k) {
  int first = k, last = k;
  while (first > 0 && c[first - 1].t == c[k].t) --first;
  while (last + 1 < static_cast<int>(c.size()) && c[last + 1].t == c[k].t) ++last;
  return {first, last};
}

std::pair<int, int> GraphBuilder::FarthestContactRows(const std::vector<push::PointSample>& c, int k) {
  const auto [first, last] = ContactRowsAt(c, k);
  std::pair<int, int> best{first, std::min(first + 1, last)};
  double farthest = -1.0;
  for (int a = first; a <= last; ++a)
    for (int b = a + 1; b <= last; ++b)
      if (const double d = (c[a].point - c[b].point).squaredNorm(); d > farthest) farthest = d, best = {a, b};
  return best;
}

const geometry::Shape& GraphBuilder::ContactBoundary(int i, int finger) const {
  if (!object_has_holes_) return traj_.object.shape;
  const StepVars& v = vars_[i];
  const double* e = FingerPose(i, finger);
  const Vec2 local = geometry::InverseAct(Pose2{v.x[0], v.x[1], v.x[2]}, Vec2(e[0], e[1]));
  return geometry::QueryPoint(object_outer_, local).signed_distance < 0.0 ? traj_.object.shape : object_outer_;
}

Vec2 GraphBuilder::FingerNearestObjectPoint(int i, int k) const {
  // The object point nearest finger k's shape (its reference point may lie off the shape).
  const StepVars& v = vars_[i];
  const double* e = FingerPose(i, k);
  return finger_querier(k).Query(Pose2{v.x[0], v.x[1], v.x[2]}, Pose2{e[0], e[1], e[2]}).object_point;
}

void GraphBuilder::InitializeOtherFinger(int i, int k, double limit) {
  const bool causal = std::isfinite(limit);
  const Step::OtherFinger& s = steps_[i].others[k - 1];
  const std::vector<push::PoseSample>& poses = FingerPoseRows(k);
  const std::vector<push::PointSample>& contacts = ContactRows(k);
  const std::vector<push::ForceSample>& forces = ForceRows(k);
  const StepVars& v = vars_[i];
  double* pose = FingerPose(i, k);
  const double* prev_pose = i > 0 ? FingerPose(i - 1, k) : nullptr;
  const Pose2 e = s.finger >= 0 ? poses[s.finger].pose : InterpolatePose(poses, steps_[i].t, limit);
  pose[0] = e.x;
  pose[1] = e.y;
  pose[2] = prev_pose != nullptr ? prev_pose[2] + geometry::WrapAngle(e.theta - prev_pose[2]) : e.theta;
  if (!s.in_contact) return;
  const bool prev_touching = causal && i > 0 && FingerTouches(i - 1, k);
  Vec2 c;
  if (s.contact >= 0) {
    c = contacts[s.contact].point;
  } else if (!contacts.empty() && !causal) {
    c = push::StreamValueClamped(contacts, steps_[i].t, [](const push::PointSample& a) { return Vec2(a.point); });
  } else if (prev_touching) {
    c = Vec2(FingerContact(i - 1, k)[0], FingerContact(i - 1, k)[1]);
  } else {
    c = FingerNearestObjectPoint(i, k);
  }
  FingerContact(i, k)[0] = c.x();
  FingerContact(i, k)[1] = c.y();
  Vec2 f;
  if (s.force >= 0) {
    f = forces[s.force].force;
  } else if (!forces.empty() && !causal) {
    f = push::StreamValueClamped(forces, steps_[i].t, [](const push::ForceSample& a) { return Vec2(a.force); });
  } else if (prev_touching) {
    f = Vec2(FingerForce(i - 1, k)[0], FingerForce(i - 1, k)[1]);
  } else {
    const Vec2 d = Vec2(v.x[0], v.x[1]) - c;
    f = d.norm() > 0 ? Vec2(0.1 * d.normalized()) : Vec2(0.1, 0.0);
  }
  FingerForce(i, k)[0] = f.x();
  FingerForce(i, k)[1] = f.y();
  if (s.two_contacts) {
    InitializeSecondContact(i, k, causal);
    double* f1 = FingerForce(i, k);
    double* f2 = SecondContactForce(i, k);
    f2[0] = f1[0] = 0.5 * f1[0];  // the finger's measured (net) force shared to start
    f2[1] = f1[1] = 0.5 * f1[1];
  }
}

void GraphBuilder::InitializeSecondContact(int i, int finger, bool causal) {
  const std::vector<push::PointSample>& c = ContactRows(finger);
  int& row = ContactRow(i, finger);
  int& row2 = SecondContactRow(i, finger);
  double* pa = FingerContact(i, finger);
  double* pb = SecondContactPoint(i, finger);
  const bool paired = i > 0 && FingerTwoContacts(i - 1, finger);
  const double* prev_a = paired ? FingerContact(i - 1, finger) : nullptr;
  const double* prev_b = paired ? SecondContactPoint(i - 1, finger) : nullptr;
  Vec2 a(pa[0], pa[1]), b = a;
  if (row >= 0 && row2 >= 0) {
    b = c[row2].point;
  } else {
    // The two rows of the nearest contact time (none at this step).
    int k = -1;
    NearestGap(c, steps_[i].t, &k);
    const auto [first, second] = FarthestContactRows(c, k);
    if (!causal || c[first].t <= steps_[i].t) {
      a = c[first].point;
      b = c[second].point;
    } else if (paired) {
      a = Vec2(prev_a[0], prev_a[1]);
      b = Vec2(prev_b[0], prev_b[1]);
    }
  }
  // Pair the rows with the two contacts as the previous step's (the sensor's row order may change).
  if (paired) {
    const Vec2 p1(prev_a[0], prev_a[1]), p2(prev_b[0], prev_b[1]);
    if ((a - p2).norm() + (b - p1).norm() < (a - p1).norm() + (b - p2).norm()) {
      std::swap(a, b);
      if (row >= 0 && row2 >= 0) std::swap(row, row2);
    }
  }
  pa[0] = a.x(); pa[1] = a.y();
  pb[0] = b.x(); pb[1] = b.y();
}

int GraphBuilder::CarryObjectThroughGaps() {
  // Beyond the last object pose (or before the first) its value is held: the object is left
  // behind while the finger moves on, the batch solve starts with the finger deep inside it and
  // settles in a wrong minimum (a push occluded from 20 % of its length on, seeds 1-6: object
  // RMS 22 to 30 mm, NEES above 10^4, where the incremental mode, which follows the gap step by
  // step, had 1.3 to 3.2 mm). Gaps between two poses keep the linear interpolation: carrying
  // there too and blending onto the pose after the gap was worse on docs/results.md's occlusion
  // protocol (notched block QS 1.73 -> 2.29 mm).
  const int n = static_cast<int>(steps_.size());
  const double min_gap = LongObjectGap(traj_);
  if (n < 3 || !std::isfinite(min_gap)) return 0;
  // The translation of the first finger in contact over both steps j and k (none: the object rests).
  auto finger_move = [&](int j, int k) -> Vec2 {
    for (int f = 0; f <= other_fingers_; ++f) {
      if (!FingerTouches(j, f) || !FingerTouches(k, f)) continue;
      const double *a = FingerPose(j, f), *b = FingerPose(k, f);
      return Vec2(b[0] - a[0], b[1] - a[1]);
    }
    return Vec2::Zero();
  };
  int first = -1, last = -1;  // steps with an object measurement
  for (int i = 0; i < n; ++i) {
    if (steps_[i].object < 0) continue;
    if (first < 0) first = i;
    last = i;
  }
  if (first < 0) return 0;
  int moved = 0;
  auto carry = [&](int from, int to, int dir) {  // from an anchor step, dir = +1 forwards, -1 back
    for (int j = from + dir; j != to + dir; j += dir) {
      const Vec2 d = finger_move(j - dir, j);
      vars_[j].x[0] = vars_[j - dir].x[0] + d.x();
      vars_[j].x[1] = vars_[j - dir].x[1] + d.y();
      ++moved;
    }
  };
  if (last < n - 1 && steps_[n - 1].t - steps_[last].t > min_gap) carry(last, n - 1, +1);
  if (first > 0 && steps_[first].t - steps_[0].t > min_gap) carry(first, 0, -1);
  return moved;
}

int GraphBuilder::SmoothInitialMotion(int max_iterations, double function_tolerance, int first, int last) {
  ceres::Problem problem;
  const int n = last < 0 ? static_cast<int>(steps_.size()) : last;
  for (int i = first; i < n; ++i) {
    AddPoseMeasurementFactors(problem, i);
    AddConstantVelocityFactors(problem, i);
  }
  // A pose with neither measurement nor neighbours (a one- or two-step input) keeps its value;
  // steps before `first` (already estimated, incremental mode) are held fixed.
  for (int i = std::max(0, first - 2); i < n; ++i) {
    if (!problem.HasParameterBlock(vars_[i].x)) problem.AddParameterBlock(vars_[i].x, 3);
    if (!problem.HasParameterBlock(vars_[i].e)) problem.AddParameterBlock(vars_[i].e, 3);
    for (int k = 1; k <= other_fingers_; ++k)
      if (!problem.HasParameterBlock(FingerPose(i, k))) problem.AddParameterBlock(FingerPose(i, k), 3);
    if (i < first) {
      problem.SetParameterBlockConstant(vars_[i].x);
      problem.SetParameterBlockConstant(vars_[i].e);
      for (int k = 1; k <= other_fingers_; ++k) problem.SetParameterBlockConstant(FingerPose(i, k));
    }
  }
  const SolveOutcome outcome = Solve(problem, max_iterations, function_tolerance, "motion-only initialization");
  if (!streams_.contact_point) {
    for (int i = first; i < n; ++i) {
      if (!steps_[i].in_contact) continue;
      StepVars& v = vars_[i];
      const auto q = geometry::QueryPoint(traj_.object.shape, Pose2{v.x[0], v.x[1], v.x[2]}, Vec2(v.e[0], v.e[1]));
      v.p[0] = q.closest_point.x();
      v.p[1] = q.closest_point.y();
    }
  }
  for (int k = 1; k <= other_fingers_ && !streams_.contact_point; ++k) {  // no finger has a tactile sensor
    for (int i = first; i < n; ++i) {
      if (!FingerTouches(i, k)) continue;
      const Vec2 c = FingerNearestObjectPoint(i, k);
      FingerContact(i, k)[0] = c.x();
      FingerContact(i, k)[1] = c.y();
    }
  }
  return outcome.iterations;
}

int GraphBuilder::StageSteps(ceres::Problem& problem, int first, int last, int max_iterations,
                             double function_tolerance, const std::string& what, int kinematic_iterations) {
  int iterations = SmoothInitialMotion(10, 1e-3, first, last);
  DetectSecondContacts(first, last);
  if (ModelHasForce(model_)) {
    ceres::Problem warm;
    warm_start_ = true;
    for (int i = first; i < last; ++i) AddFactors(warm, i, kKinematic);
    warm_start_ = false;
    // The two steps before `first` enter the new steps' V factors as constants.
    for (int i = std::max(0, first - 2); i < first; ++i) {
      for (double* b : Blocks(i)) {
        if (warm.HasParameterBlock(b)) warm.SetParameterBlockConstant(b);
      }
    }
    iterations += Solve(warm, kinematic_iterations > 0 ? kinematic_iterations : max_iterations, function_tolerance,
                        (what + ", kinematics first").c_str())
                      .iterations;
    warm_origin_.clear();
  }
  for (int i = first; i < last; ++i) AddFactors(problem, i, kAll);
  return iterations;
}

ceres::LossFunction* GraphBuilder::MakeLoss(const LossConfig& loss) const {
  switch (loss.type) {
    case LossConfig::Type::kNone: return nullptr;
    case LossConfig::Type::kHuber: return new ceres::HuberLoss(loss.scale);
    case LossConfig::Type::kCauchy: return new ceres::CauchyLoss(loss.scale);
  }
  return nullptr;
}

void GraphBuilder::AddFactors(ceres::Problem& problem, int i, int parts) {
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  if (parts & kKinematic) {
    problem.AddParameterBlock(v.x, 3);
    problem.AddParameterBlock(v.e, 3);
    for (int k = 1; k <= other_fingers_; ++k) problem.AddParameterBlock(FingerPose(i, k), 3);
    if (s.in_contact) problem.AddParameterBlock(v.p, 2);
    if (HasSecondContact(i)) problem.AddParameterBlock(v.p2, 2);
    for (int k = 2; k <= other_fingers_; ++k)
      if (FingerTouches(i, k)) problem.AddParameterBlock(FingerContact(i, k), 2);
    for (int k = 0; k <= other_fingers_ && other_fingers_ > 0; ++k)
      if (FingerTwoContacts(i, k)) problem.AddParameterBlock(SecondContactPoint(i, k), 2);
    AddKinematicFactors(problem, i);
  }
  bool touches = false;  // any finger: then every touching finger has its force blocks
  for (int k = 0; k <= other_fingers_; ++k) touches = touches || FingerTouches(i, k);
  if ((parts & kDynamic) && touches && ModelHasForce(model_)) {
    if (HasForceVars(i)) problem.AddParameterBlock(v.f, 2);
    if (HasSecondForceVars(i)) problem.AddParameterBlock(v.f2, 2);
    for (int k = 2; k <= other_fingers_; ++k)
      if (FingerTouches(i, k)) problem.AddParameterBlock(FingerForce(i, k), 2);
    for (int k = 0; k <= other_fingers_ && other_fingers_ > 0; ++k)
      if (FingerTwoContacts(i, k)) problem.AddParameterBlock(SecondContactForce(i, k), 2);
    AddDynamicFactors(problem, i);
  }
}

void GraphBuilder::AddKinematicFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
  const std::size_t fingers = num_fingers();
  if (feature_choices_.size() < steps_.size() * fingers) feature_choices_.resize(steps_.size() * fingers, {-1, -1});
  for (std::size_t k = 0; k < fingers; ++k) feature_choices_[i * fingers + k] = {-1, -1};
  const auto& m = traj_.measured;
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  AddPoseMeasurementFactors(problem, i);  // M
  if (s.in_contact) {
    if (s.contact >= 0) {
      Add(problem, FactorType::kContactPoint, new VectorMeasurementFactor(m.contact_point[s.contact].point, cfg_.measurement.contact),
          MakeLoss(cfg_.contact_loss), {v.p});
    }
    // C: contact point on both boundaries, finger touching the object.
    Add(problem, FactorType::kContactOnObject, new BoundaryPointFactor(ContactBoundary(i, 0), cfg_.contact_object_sigma),
        nullptr, {v.x, v.p}, {0});
    if (s.two_contacts) {
      AddTwoContactFactors(problem, i, 0);
    } else if (cfg_.contact_finger == EstimatorConfig::ContactFinger::kWitness &&
               (finger_has_faces_[0] || BetweenWalls(i))) {
      // A finger with straight faces (a flat pusher: along a parallel object face the nearest
      // pair is any pair of the overlap, and the shape-pair query returns a vertex's), or a disk
      // between two walls (the nearest pair may jump to the other wall): the local witness of p
      // instead, the touching pair near p.
      Add(problem, FactorType::kContactOnFinger,
          new LocalWitnessFactor(traj_.object.shape, traj_.finger.shape, cfg_.contact_finger_sigma), nullptr,
          {v.x, v.e, v.p}, {0});
    } else if (cfg_.contact_finger == EstimatorConfig::ContactFinger::kWitness) {
      Add(problem, FactorType::kContactOnFinger, new ContactWitnessFactor(querier_, cfg_.contact_finger_sigma), nullptr,
          {v.x, v.e, v.p}, {0});
    } else {
      Add(problem, FactorType::kContactOnFinger, new BoundaryPointFactor(traj_.finger.shape, cfg_.contact_finger_sigma), nullptr,
          {v.e, v.p});
    }
    // The finger touches the object (signed separation 0): in QS and the baseline (Yu and
    // Rodriguez's contact factor). CP and SDF link finger and object through p only (Fig. 2a-b).
    if (model_ == Model::kQs || model_ == Model::kYu) {
      Add(problem, FactorType::kTouching, new TouchingFactor(querier_, cfg_.touching_sigma), nullptr, {v.x, v.e}, {0});
    }
  }
  // S
  if (model_ == Model::kSdf || model_ == Model::kQs) {
    Add(problem, FactorType::kIntersection, new IntersectionFactor(querier_, cfg_.intersection_sigma), nullptr, {v.x, v.e}, {0});
  }
  // V or the baseline's zero-velocity priors.
  if (model_ == Model::kYu) {
    if (i >= 1) {
      const double dt = s.t - steps_[i - 1].t;
      Add(problem, FactorType::kZeroVelocity, new RandomWalkFactor(dt, cfg_.random_walk_trans, cfg_.random_walk_rot), nullptr,
          {vars_[i - 1].x, v.x});
      Add(problem, FactorType::kZeroVelocity, new RandomWalkFactor(dt, cfg_.random_walk_trans, cfg_.random_walk_rot), nullptr,
          {vars_[i - 1].e, v.e});
    }
  } else {
    AddConstantVelocityFactors(problem, i);
    // QS: the object moves only while the finger pushes it, so where the finger is measured at
    // rest the object rests too (friction holds it): a tight random walk between its poses. The
    // constant-velocity factor alone let a resting object wander with its tracker's noise, which
    // the load factor had held still by accident (s3 of `simulate --seed 3 --duration 3`, the
    // push ending at 1.1 s, without its force stream: 0.95 mm RMS at rest against 0.3 mm).
    if (model_ == Model::kQs && i >= 1 && MeasuredAtRest(i) && MeasuredAtRest(i - 1)) {
      const double dt = s.t - steps_[i - 1].t;
      Add(problem, FactorType::kZeroVelocity, new RandomWalkFactor(dt, kRestWalkTrans, kRestWalkRot), nullptr,
          {vars_[i - 1].x, v.x});
    }
  }
  for (int k = 1; k <= other_fingers_; ++k) AddOtherFingerKinematicFactors(problem, i, k);
}

void GraphBuilder::AddTwoContactFactors(ceres::Problem& problem, int i, int finger) {
  // Two contacts: each point on the object's boundary and at its own wall's touching pair (the
  // shape-pair witness is the single nearest pair, one of the two: it would pull both points
  // onto the same wall). The first contact's M and C are the finger's own (added before).
  StepVars& v = vars_[i];
  double* second = SecondContactPoint(i, finger);
  const int row2 = SecondContactRow(i, finger);
  if (row2 >= 0) {
    Add(problem, FactorType::kContactPoint, new VectorMeasurementFactor(ContactRows(finger)[row2].point, cfg_.measurement.contact),
        MakeLoss(cfg_.contact_loss), {second});
  }
  Add(problem, FactorType::kContactOnObject, new BoundaryPointFactor(ContactBoundary(i, finger), cfg_.contact_object_sigma),
      nullptr, {v.x, second}, {0});
  ContactFeature features[2];
  const bool on_features = TwoContactFeatures(i, finger, features);
  std::array<long long, 2>& choice = feature_choices_[static_cast<std::size_t>(i) * num_fingers() + finger];
  choice = FixedFeatureKeys(on_features, features);
  double* points[2] = {FingerContact(i, finger), second};
  const geometry::Shape& shape = FingerShape(finger);
  // A flat face along an object face (a line contact): each contact at its own end of the
  // overlap, the one away from the other contact (the rows are the contact's two end points).
  int overlap_end[2] = {0, 0};
  if (finger_has_faces_[finger]) {
    const Pose2 x{v.x[0], v.x[1], v.x[2]};
    for (int k = 0; k < 2 && on_features; ++k) {
      if (choice[k] < 0 || features[k].vertex) continue;
      const geometry::Ring& ring = traj_.object.shape.ring(features[k].edge.polygon, features[k].edge.ring);
      const Vec2 a = ring[features[k].edge.index], b = ring[(features[k].edge.index + 1) % ring.size()];
      const Vec2 own = geometry::InverseAct(x, Vec2(points[k][0], points[k][1]));
      const Vec2 other = geometry::InverseAct(x, Vec2(points[1 - k][0], points[1 - k][1]));
      overlap_end[k] = (other - own).dot(b - a) > 0.0 ? -1 : 1;
    }
  }
  for (int k = 0; k < 2; ++k) {
    // An object vertex is never a fixed feature: pinned to a corner at the start, a contact
    // that is really on the adjacent edge (a flat pusher's end near the corner) holds the
    // object shifted along that edge, and the corner is then the nearest feature at the
    // solution too. The local witness follows p instead.
    ceres::CostFunction* cost =
        choice[k] >= 0 ? static_cast<ceres::CostFunction*>(new FeatureWitnessFactor(
                             traj_.object.shape, features[k].edge, features[k].vertex, shape, cfg_.contact_finger_sigma,
                             overlap_end[k]))
                       : new LocalWitnessFactor(traj_.object.shape, shape, cfg_.contact_finger_sigma);
    Add(problem, FactorType::kContactOnFinger, cost, nullptr, {v.x, FingerPose(i, finger), points[k]}, {0});
  }
  if (overlap_end[0] != 0 || overlap_end[1] != 0) AddInnerEndRows(problem, i, finger, features, points, overlap_end);
}

void GraphBuilder::AddInnerEndRows(ceres::Problem& problem, int i, int finger, const ContactFeature features[2],
                                   double* const points[2], const int overlap_end[2]) {
  // A step's rows beyond the two kept (a flat face across a notch: the notch's corners between
  // the face's ends) measure the other end of a contact's overlap, which places the object
  // along its face (OverlapEndMeasurementFactor).
  const std::vector<push::PointSample>& rows = ContactRows(finger);
  const int kept[2] = {ContactRow(i, finger), SecondContactRow(i, finger)};
  if (kept[0] < 0 || kept[1] < 0) return;
  const auto [first, last] = ContactRowsAt(rows, kept[0]);
  if (last - first + 1 <= 2) return;
  StepVars& v = vars_[i];
  double* e = FingerPose(i, finger);
  const geometry::Shape& shape = FingerShape(finger);
  geometry::EdgeId finger_edge[2];
  bool facing[2] = {false, false};
  const Pose2 x{v.x[0], v.x[1], v.x[2]}, pose_e{e[0], e[1], e[2]};
  for (int k = 0; k < 2; ++k) {
    if (overlap_end[k] == 0) continue;
    // The finger's face along the object edge: of the finger edges at its closest feature to
    // the contact (a contact at the face's end is nearest the corner, whose other edge is the
    // finger's end face), the one most nearly antiparallel to the object edge.
    geometry::PointQuery q;
    try {
      q = geometry::QueryPoint(shape, pose_e, Vec2(points[k][0], points[k][1]));
    } catch (const geometry::GeometryError&) {
      continue;
    }
    const geometry::Ring& oring = traj_.object.shape.ring(features[k].edge.polygon, features[k].edge.ring);
    const Vec2 d = geometry::Act(x, oring[(features[k].edge.index + 1) % oring.size()]) -
                   geometry::Act(x, oring[features[k].edge.index]);
    const geometry::Ring& fring = shape.ring(q.feature.edge.polygon, q.feature.edge.ring);
    const int n = static_cast<int>(fring.size());
    if (n < 2) continue;
    double best_cos = -std::sqrt(0.5);
    const int j = q.feature.edge.index;
    for (const int index : {j, (j + n - 1) % n, (j + 1) % n}) {
      const Vec2 fd = geometry::Act(pose_e, fring[(index + 1) % n]) - geometry::Act(pose_e, fring[index]);
      const double c = d.dot(fd) / (d.norm() * fd.norm());
      if (c < best_cos) best_cos = c, finger_edge[k] = {q.feature.edge.polygon, q.feature.edge.ring, index}, facing[k] = true;
    }
  }
  // Each contact's other end takes the nearest extra row, within three sigmas of the row and
  // the object pose together (a row across the notch, 3 cm away, is the other contact's).
  const double gate = 3.0 * std::hypot(cfg_.measurement.contact, cfg_.measurement.object_trans);
  const double* values[2] = {v.x, e};
  for (int k = 0; k < 2; ++k) {
    if (!facing[k]) continue;
    std::unique_ptr<OverlapEndMeasurementFactor> best;
    double best_distance = INFINITY;
    for (int r = first; r <= last; ++r) {
      if (r == kept[0] || r == kept[1]) continue;
      auto factor = std::make_unique<OverlapEndMeasurementFactor>(traj_.object.shape, features[k].edge, shape, finger_edge[k],
                                                                  -overlap_end[k], rows[r].point, cfg_.measurement.contact);
      Eigen::Vector2d residual;
      if (!factor->Evaluate(values, residual.data(), nullptr)) continue;
      const double distance = residual.norm() * cfg_.measurement.contact;
      if (distance < best_distance && distance <= gate) best_distance = distance, best = std::move(factor);
    }
    if (best) Add(problem, FactorType::kContactPoint, best.release(), MakeLoss(cfg_.contact_loss), {v.x, e}, {0});
  }
}

void GraphBuilder::AddOtherFingerKinematicFactors(ceres::Problem& problem, int i, int k) {
  // Finger k's own M of its contact, C, S and touching, with its own shape and querier.
  adding_step_ = i;
  const Step::OtherFinger& s = steps_[i].others[k - 1];
  const std::shared_ptr<const geometry::ShapePairQuerier>& querier = other_queriers_[k - 1];
  StepVars& v = vars_[i];
  double* e = FingerPose(i, k);
  double* p = FingerContact(i, k);
  if (s.in_contact) {
    if (s.contact >= 0) {
      Add(problem, FactorType::kContactPoint, new VectorMeasurementFactor(ContactRows(k)[s.contact].point, cfg_.measurement.contact),
          MakeLoss(cfg_.contact_loss), {p});
    }
    Add(problem, FactorType::kContactOnObject, new BoundaryPointFactor(ContactBoundary(i, k), cfg_.contact_object_sigma),
        nullptr, {v.x, p}, {0});
    if (s.two_contacts) {
      AddTwoContactFactors(problem, i, k);
    } else if (cfg_.contact_finger == EstimatorConfig::ContactFinger::kWitness && finger_has_faces_[k]) {
      // A finger with straight faces: the local witness of p (as finger 0's, AddKinematicFactors).
      Add(problem, FactorType::kContactOnFinger, new LocalWitnessFactor(traj_.object.shape, FingerShape(k), cfg_.contact_finger_sigma),
          nullptr, {v.x, e, p}, {0});
    } else if (cfg_.contact_finger == EstimatorConfig::ContactFinger::kWitness) {
      Add(problem, FactorType::kContactOnFinger, new ContactWitnessFactor(querier, cfg_.contact_finger_sigma), nullptr,
          {v.x, e, p}, {0});
    } else {
      Add(problem, FactorType::kContactOnFinger, new BoundaryPointFactor(FingerShape(k), cfg_.contact_finger_sigma), nullptr, {e, p});
    }
    if (model_ == Model::kQs) {
      Add(problem, FactorType::kTouching, new TouchingFactor(querier, cfg_.touching_sigma), nullptr, {v.x, e}, {0});
    }
  }
  if (model_ == Model::kSdf || model_ == Model::kQs) {
    Add(problem, FactorType::kIntersection, new IntersectionFactor(querier, cfg_.intersection_sigma), nullptr, {v.x, e}, {0});
  }
}

void GraphBuilder::AddPoseMeasurementFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
  const auto& m = traj_.measured;
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  if (s.object >= 0) {
    Add(problem, FactorType::kObjectPose,
        new PoseMeasurementFactor(m.object_pose[s.object].pose, cfg_.measurement.object_trans, cfg_.measurement.object_rot),
        MakeLoss(cfg_.object_pose_loss), {v.x});
  }
  if (s.finger >= 0) {
    Add(problem, FactorType::kFingerPose,
        new PoseMeasurementFactor(m.finger_pose[s.finger].pose, cfg_.measurement.finger_trans, cfg_.measurement.finger_rot),
        MakeLoss(cfg_.finger_pose_loss), {v.e});
  }
  for (int k = 1; k <= other_fingers_; ++k) {
    if (s.others[k - 1].finger < 0) continue;
    Add(problem, FactorType::kFingerPose,
        new PoseMeasurementFactor(FingerPoseRows(k)[s.others[k - 1].finger].pose, cfg_.measurement.finger_trans,
                                  cfg_.measurement.finger_rot),
        MakeLoss(cfg_.finger_pose_loss), {FingerPose(i, k)});
  }
}

void GraphBuilder::AddConstantVelocityFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
  if (i < 2) return;
  const double dt1 = steps_[i - 1].t - steps_[i - 2].t, dt2 = steps_[i].t - steps_[i - 1].t;
  const double st = ConstantVelocitySigma(cfg_.accel_trans, dt1, dt2);
  const double sr = ConstantVelocitySigma(cfg_.accel_rot, dt1, dt2);
  Add(problem, FactorType::kConstantVelocity, new ConstantVelocityFactor(dt1, dt2, st, sr), nullptr,
      {vars_[i - 2].x, vars_[i - 1].x, vars_[i].x});
  Add(problem, FactorType::kConstantVelocity, new ConstantVelocityFactor(dt1, dt2, st, sr), nullptr,
      {vars_[i - 2].e, vars_[i - 1].e, vars_[i].e});
  for (int k = 1; k <= other_fingers_; ++k) {
    Add(problem, FactorType::kConstantVelocity, new ConstantVelocityFactor(dt1, dt2, st, sr), nullptr,
        {FingerPose(i - 2, k), FingerPose(i - 1, k), FingerPose(i, k)});
  }
}

void GraphBuilder::AddDynamicFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  // The step's contacts with a force: each touching finger's one or two (finger 0's first),
  // each with its finger (whose friction it takes) and the same contact's force at step i - 1.
  struct Contact {
    double* p;
    double* f;
    int finger;
    double* before;  // the same contact's force at step i - 1 (null: none)
  };
  std::vector<Contact> contacts;
  for (int k = 0; k <= other_fingers_ && ModelHasForce(model_); ++k) {
    if (!FingerTouches(i, k)) continue;
    const bool previous = i >= 1 && FingerTouches(i - 1, k);
    contacts.push_back({FingerContact(i, k), FingerForce(i, k), k, previous ? FingerForce(i - 1, k) : nullptr});
    if (!FingerTwoContacts(i, k)) continue;
    const bool previous2 = i >= 1 && FingerTwoContacts(i - 1, k);
    contacts.push_back({SecondContactPoint(i, k), SecondContactForce(i, k), k, previous2 ? SecondContactForce(i - 1, k) : nullptr});
  }
  // Force: each finger's sensor (one touching at two points measures the sum of both).
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const int k = contacts[c].finger;
    if (c > 0 && contacts[c - 1].finger == k) continue;  // a finger's second contact
    const int row = k == 0 ? s.force : s.others[k - 1].force;
    if (row < 0) continue;
    const Vec2& measured = ForceRows(k)[row].force;
    if (FingerTwoContacts(i, k)) {
      Add(problem, FactorType::kForce, new VectorSumMeasurementFactor(measured, cfg_.measurement.force),
          MakeLoss(cfg_.force_loss), {contacts[c].f, contacts[c + 1].f});
    } else {
      Add(problem, FactorType::kForce, new VectorMeasurementFactor(measured, cfg_.measurement.force),
          MakeLoss(cfg_.force_loss), {contacts[c].f});
    }
  }
  // The weak prior; with several contacts each force in its friction cone (sigma a tenth of
  // the force sensor's): a wedged finger's sensor measures only the sum, and the cone keeps
  // the split physical.
  for (const Contact& c : contacts)
    Add(problem, FactorType::kForcePrior, new VectorMeasurementFactor(Vec2::Zero(), cfg_.force_prior_sigma), nullptr, {c.f});
  for (std::size_t k = 0; contacts.size() >= 2 && k < contacts.size(); ++k)
    Add(problem, FactorType::kForcePrior,
        new FrictionConeFactor(traj_.object.shape, FingerMu(contacts[k].finger), 0.1 * cfg_.measurement.force), nullptr,
        {v.x, contacts[k].p, contacts[k].f}, {0});
  if (i < 1) return;
  for (const Contact& c : contacts) {
    if (c.before == nullptr) continue;
    Add(problem, FactorType::kForceContinuity, new VectorRandomWalkFactor(s.t - steps_[i - 1].t, cfg_.force_random_walk),
        nullptr, {c.before, c.f});
  }
  if (contacts.size() == 1) {
    AddOneContactQuasiStatic(problem, i, contacts[0].p, contacts[0].f);
    return;
  }
  // D and the load of every contact's summed wrench (c and mu at their given values).
  QuasiStaticGeometry g = qs_;
  g.dt = s.t - steps_[i - 1].t;
  const double rate_scale = std::sqrt(0.01 / g.dt);  // per-10-ms sigmas (config.h)
  std::vector<double*> blocks{vars_[i - 1].x, v.x};
  for (const Contact& c : contacts) {
    blocks.push_back(c.p);
    blocks.push_back(c.f);
  }
  if (contacts.size() == 2) {
    Add(problem, FactorType::kQuasiStatic,
        new QuasiStaticTwoContactFactor(g, cfg_.eps_velocity, eps_force_, cfg_.quasi_static_sigma * rate_scale),
        nullptr, blocks, {0, 1});
    if (LoadFactorAt(i)) {
      Add(problem, FactorType::kLimitSurfaceLoad,
          new LimitSurfaceLoadTwoContactFactor(g, f_max_, cfg_.eps_velocity, eps_force_,
                                               cfg_.limit_surface_sigma * rate_scale),
          nullptr, blocks, {0, 1});
    }
    return;
  }
  const int n = static_cast<int>(contacts.size());
  Add(problem, FactorType::kQuasiStatic,
      new QuasiStaticMultiContactFactor(g, n, cfg_.eps_velocity, eps_force_, cfg_.quasi_static_sigma * rate_scale),
      nullptr, blocks, {0, 1});
  if (LoadFactorAt(i)) {
    Add(problem, FactorType::kLimitSurfaceLoad,
        new LimitSurfaceLoadMultiContactFactor(g, n, f_max_, cfg_.eps_velocity, eps_force_,
                                               cfg_.limit_surface_sigma * rate_scale),
        nullptr, blocks, {0, 1});
  }
}

void GraphBuilder::AddOneContactQuasiStatic(ceres::Problem& problem, int i, double* p, double* f) {
  StepVars& v = vars_[i];
  QuasiStaticGeometry g = qs_;
  g.dt = steps_[i].t - steps_[i - 1].t;
  const double rate_scale = std::sqrt(0.01 / g.dt);  // per-10-ms sigmas (config.h)
  if (model_ != Model::kQs) {
    Add(problem, FactorType::kQuasiStatic, new CrossMultipliedQuasiStaticFactor(g, cfg_.yu_quasi_static_sigma * rate_scale),
        nullptr, {vars_[i - 1].x, v.x, p, f}, {0, 1});
    return;
  }
  if (estimate_c_) {
    Add(problem, FactorType::kQuasiStatic,
        new QuasiStaticFactorWithC(g, cfg_.eps_velocity, eps_force_, cfg_.quasi_static_sigma * rate_scale), nullptr,
        {vars_[i - 1].x, v.x, p, f, c_var_}, {0, 1});
    // Prior around the geometric value; bounds keep c physical (tau / c in D).
    if (!c_in_problem_) AddSharedParameterPrior(*this, problem, c_var_, qs_.c, cfg_.c_prior_sigma);
    c_in_problem_ = true;
  } else {
    Add(problem, FactorType::kQuasiStatic,
        new QuasiStaticFactor(g, cfg_.eps_velocity, eps_force_, cfg_.quasi_static_sigma * rate_scale), nullptr,
        {vars_[i - 1].x, v.x, p, f}, {0, 1});
  }
  const bool load = LoadFactorAt(i);
  if (load && (estimate_c_ || estimate_mu_)) {
    // The same c as D's (estimated) and/or mu as variables.
    std::vector<double*> blocks{vars_[i - 1].x, v.x, p, f};
    if (estimate_c_) blocks.push_back(c_var_);
    if (estimate_mu_) blocks.push_back(mu_var_);
    Add(problem, FactorType::kLimitSurfaceLoad,
        new LimitSurfaceLoadFactorWithParameters(g, normal_load_, mu_surface_, {estimate_c_, estimate_mu_},
                                                 cfg_.eps_velocity, eps_force_, cfg_.limit_surface_sigma * rate_scale),
        nullptr, blocks, {0, 1});
    // Prior around the trajectory's mu; bounds keep f_max physical.
    if (estimate_mu_ && !mu_in_problem_) AddSharedParameterPrior(*this, problem, mu_var_, mu_surface_, cfg_.mu_prior_sigma);
    mu_in_problem_ = mu_in_problem_ || estimate_mu_;
  } else if (load) {
    Add(problem, FactorType::kLimitSurfaceLoad,
        new LimitSurfaceLoadFactor(g, f_max_, cfg_.eps_velocity, eps_force_, cfg_.limit_surface_sigma * rate_scale),
        nullptr, {vars_[i - 1].x, v.x, p, f}, {0, 1});
  }
}

bool GraphBuilder::MeasuredAtRest(int i) const {
  // Quasi-statically the object moves only while a finger does: at rest where no finger with a
  // pose stream is measured moving and one is measured at rest (finger 0 alone decided before:
  // an idle finger 0 beside the pusher held the pushed object by 274 zero-velocity factors). A
  // finger whose stream cannot tell there (its ends, a gap) does not count. No finger stream:
  // the object's own.
  const auto& m = traj_.measured;
  const double t = steps_[i].t;
  bool any_finger = false, seen_at_rest = false;
  auto moving = [&](const std::vector<push::PoseSample>& poses) {
    if (poses.empty()) return false;
    any_finger = true;
    const Rest rest = PoseStreamRest(poses, t, cfg_.measurement.finger_trans);
    seen_at_rest = seen_at_rest || rest == Rest::kAtRest;
    return rest == Rest::kMoving;
  };
  if (moving(m.finger_pose)) return false;
  if (other_fingers_ > 0)
    for (const push::ExtraFinger& f : traj_.extra_fingers)
      if (moving(f.measured.finger_pose)) return false;
  if (any_finger) return seen_at_rest;
  return PoseStreamAtRest(m.object_pose, t, cfg_.measurement.object_trans);
}

bool GraphBuilder::LoadFactorAt(int i) const {
  // The load lies on the limit surface only while the object slides. The factor's own gate
  // (|V'| against eps_velocity) cannot tell rest from the estimate's jitter there (5 to 15 mm/s
  // on a resting object under a 2 mm tracker): a finger resting against the object after its
  // push, with no force stream, had its force driven to mu m g (1.13 N RMS against 0 N, NEES
  // 41). Quasi-statically the object moves only while the finger does: where the finger is
  // measured at rest (the object, without a finger stream), no load factor.
  if (MeasuredAtRest(i)) return false;
  if (use_load_factor_) return true;
  // limit_surface_load "auto" with a force stream: where no force sample covers the step (a
  // stream that stops halfway, or a tactile sensor silent while a contact sensor still reports
  // contact), the load gives the force its size; without it a stream that ended at 0.85 s left
  // the forces after it at 0 N with sigmas of 0.02 to 0.09 N (truth about 1.4 N, NEES 724).
  if (f_max_ <= 0.0 || cfg_.limit_surface_load != EstimatorConfig::LimitSurfaceLoad::kAuto) return false;
  const auto& force = traj_.measured.force;
  if (force.empty()) return false;
  return NearestGap(force, steps_[i].t) > std::max(cfg_.contact_max_gap, 1.5 * force_period_);
}

std::vector<double*> GraphBuilder::Blocks(int i) {
  std::vector<double*> b{vars_[i].x, vars_[i].e};
  if (HasContactVars(i)) b.push_back(vars_[i].p);
  if (HasForceVars(i)) b.push_back(vars_[i].f);
  if (HasSecondContact(i)) b.push_back(vars_[i].p2);
  if (HasSecondForceVars(i)) b.push_back(vars_[i].f2);
  if (other_fingers_ > 0) b.push_back(vars_[i].e2);
  for (int k = 2; k <= other_fingers_; ++k) {
    b.push_back(FingerPose(i, k));
    if (FingerTouches(i, k)) b.push_back(FingerContact(i, k));
    if (FingerTouches(i, k) && ModelHasForce(model_)) b.push_back(FingerForce(i, k));
  }
  for (int k = 0; k <= other_fingers_ && other_fingers_ > 0; ++k) {
    if (!FingerTwoContacts(i, k)) continue;
    b.push_back(SecondContactPoint(i, k));
    if (ModelHasForce(model_)) b.push_back(SecondContactForce(i, k));
  }
  return b;
}

void GraphBuilder::DropUnobservableForces(EstimationResult& result) const {
  if (streams_.force && !streams_.contact_point && other_fingers_ == 0 && !steps_.empty() &&
      std::none_of(steps_.begin(), steps_.end(), [](const Step& s) { return s.in_contact; })) {
    result.warnings.push_back(Format(
        "no step is in contact: the force stream's median over +-20 ms never rises above max(%.3g N, its noise: 5 force "
        "sigmas of %.3g N over the root of the samples' count), so the finger is taken as never touching and no contact "
        "point or force is estimated (contact_force_threshold and force_sigma set the gate)",
        cfg_.contact_force_threshold, cfg_.measurement.force));
  }
  if (second_contacts_ignored_ > 0)
    result.warnings.push_back("the Yu-Rodriguez baseline models one contact: the second contact of " +
                              std::to_string(second_contacts_ignored_) + " steps with two was left out");
  if (steps_with_more_contacts_ > 0)
    result.warnings.push_back(std::to_string(steps_with_more_contacts_) +
                              " steps have three or more contact rows at one time: each is modelled by its two rows "
                              "farthest apart (exact for contacts along one straight finger face, an approximation "
                              "otherwise); a flat finger face's other rows measure the ends of its overlaps with the "
                              "object between them (a notch's corners)");
  if (fingers_ignored_)
    result.warnings.push_back(traj_.extra_fingers.size() == 1
                                  ? "the Yu-Rodriguez baseline models one finger: finger 1 of this two-finger push was left "
                                    "out (its pose, contacts and forces are not estimated)"
                                  : "the Yu-Rodriguez baseline models one finger: fingers 1 to " +
                                        std::to_string(traj_.extra_fingers.size()) + " of this push were left out "
                                        "(their poses, contacts and forces are not estimated)");
  if (other_fingers_ > 0) {
    // A finger without the sensor another has: said, not left silent.
    for (int finger = 0; finger < num_fingers(); ++finger) {
      const auto& contact = ContactRows(finger);
      const auto& force = ForceRows(finger);
      if (streams_.contact_point && contact.empty()) {
        // Pushing rows: above the contact threshold and three force sigmas (the noise of a finger
        // that never touched: 1% of its rows), in more than a tenth of its rows.
        const double bound = std::max(cfg_.contact_force_threshold, 3.0 * cfg_.measurement.force);
        const auto pushing = std::count_if(force.begin(), force.end(), [&](const push::ForceSample& f) {
          return f.force.norm() >= bound;
        });
        if (pushing > 0 && 10 * pushing > static_cast<long>(force.size())) {
          char text[240];
          std::snprintf(text, sizeof text,
                        "finger %d has no contact rows while another finger has: it is taken as never touching, and its "
                        "%d force rows of at least %.3g N were left out",
                        finger, static_cast<int>(pushing), bound);
          result.warnings.push_back(text);
        }
      }
      if (streams_.force && force.empty() && ModelHasForce(model_))
        result.warnings.push_back("finger " + std::to_string(finger) + " has no force rows while another finger has: its "
                                  "force comes from the motion alone (the quasi-static factor fixes the direction of the "
                                  "summed wrench), so its size is weakly determined");
    }
  }
  if (ForceScaleObservable()) return;
  for (StateEstimate& s : result.states) {
    s.force.reset();
    s.force_cov.reset();
    for (ContactEstimate& c : s.contacts) {
      c.force.reset();
      c.force_cov.reset();
    }
  }
  const std::string how = model_ == Model::kYu
                              ? "the baseline has no limit-surface load"
                              : (f_max_ > 0.0 ? "limit_surface_load is off"
                                              : "the object's mass or mu_surface is missing or zero, so there is no limit-surface load");
  result.warnings.push_back("forces not reported: there is no force stream and " + how +
                            ", so nothing fixes their size (the quasi-static factor fixes only their direction)");
}

void GraphBuilder::SetState(int i, const StateEstimate& st) {
  StepVars& v = vars_[i];
  // Without a contact stream the estimate, not the rows, said which steps have two contacts.
  if (!streams_.contact_point && other_fingers_ == 0 && model_ != Model::kYu && steps_[i].in_contact)
    steps_[i].two_contacts = st.contacts.size() == 2;
  v.x[0] = st.object_pose.x; v.x[1] = st.object_pose.y; v.x[2] = st.object_pose.theta;
  v.e[0] = st.finger_pose.x; v.e[1] = st.finger_pose.y; v.e[2] = st.finger_pose.theta;
  if (st.contact) {
    v.p[0] = st.contact->x(); v.p[1] = st.contact->y();
  } else if (HasContactVars(i)) {
    const auto q = geometry::QueryPoint(traj_.object.shape, Pose2{v.x[0], v.x[1], v.x[2]}, Vec2(v.e[0], v.e[1]));
    v.p[0] = q.closest_point.x(); v.p[1] = q.closest_point.y();
  }
  v.f[0] = st.force ? st.force->x() : 0.0;
  v.f[1] = st.force ? st.force->y() : 0.0;
  if (other_fingers_ > 0) {
    // Each other finger's pose and its contact (its entry in contacts).
    for (const FingerPoseEstimate& o : st.other_fingers) {
      if (o.finger < 1 || o.finger > other_fingers_) continue;
      double* e = FingerPose(i, o.finger);
      e[0] = o.pose.x; e[1] = o.pose.y; e[2] = o.pose.theta;
    }
    // Each finger's first contact entry, then its second (finger 0's first is contact above).
    std::vector<int> seen(num_fingers(), 0);
    for (const ContactEstimate& c : st.contacts) {
      if (c.finger < 0 || c.finger > other_fingers_) continue;
      const int nth = seen[c.finger]++;
      if (nth > 1 || (c.finger == 0 && nth == 0)) continue;
      double* p = nth == 0 ? FingerContact(i, c.finger) : SecondContactPoint(i, c.finger);
      double* f = nth == 0 ? FingerForce(i, c.finger) : SecondContactForce(i, c.finger);
      p[0] = c.point.x(); p[1] = c.point.y();
      const Vec2 force = c.force.value_or(Vec2::Zero());
      f[0] = force.x(); f[1] = force.y();
    }
    if (seen[0] == 2 && st.contacts.front().force) {  // finger 0's first force: its own entry's
      v.f[0] = st.contacts.front().force->x(); v.f[1] = st.contacts.front().force->y();
    }
  } else if (HasSecondContact(i) && st.contacts.size() == 2) {
    v.p2[0] = st.contacts[1].point.x(); v.p2[1] = st.contacts[1].point.y();
    const Vec2 f1 = st.contacts[0].force.value_or(Vec2::Zero()), f2 = st.contacts[1].force.value_or(Vec2::Zero());
    v.f[0] = f1.x(); v.f[1] = f1.y();
    v.f2[0] = f2.x(); v.f2[1] = f2.y();
  } else if (HasSecondContact(i)) {
    v.p2[0] = v.p[0]; v.p2[1] = v.p[1];
    v.f2[0] = v.f[0] = 0.5 * v.f[0];
    v.f2[1] = v.f[1] = 0.5 * v.f[1];
  }
}

void GraphBuilder::SetSharedParameters(std::optional<double> c, std::optional<double> mu) {
  if (c && estimate_c_) c_var_[0] = *c;
  if (mu && estimate_mu_) mu_var_[0] = *mu;
}

StateEstimate GraphBuilder::State(int i) const {
  StateEstimate s;
  const StepVars& v = vars_[i];
  s.t = steps_[i].t;
  s.object_pose = {v.x[0], v.x[1], v.x[2]};
  s.finger_pose = {v.e[0], v.e[1], v.e[2]};
  if (HasContactVars(i)) s.contact = Vec2(v.p[0], v.p[1]);
  if (HasForceVars(i)) s.force = Vec2(v.f[0], v.f[1]);
  if (other_fingers_ > 0) {
    // Every finger's pose and contact; contact and force stay finger 0's own.
    for (int k = 1; k <= other_fingers_; ++k) {
      const double* e = FingerPose(i, k);
      s.other_fingers.push_back({k, Pose2{e[0], e[1], e[2]}, std::nullopt});
    }
    for (int k = 0; k <= other_fingers_; ++k) {
      if (!FingerTouches(i, k)) continue;
      for (int nth = 0; nth < (FingerTwoContacts(i, k) ? 2 : 1); ++nth) {
        const double* p = nth == 0 ? FingerContact(i, k) : SecondContactPoint(i, k);
        const double* f = nth == 0 ? FingerForce(i, k) : SecondContactForce(i, k);
        ContactEstimate c;
        c.finger = k;
        c.point = Vec2(p[0], p[1]);
        if (ModelHasForce(model_)) c.force = Vec2(f[0], f[1]);
        s.contacts.push_back(c);
      }
    }
    // Finger 0 touching at two points: force is their sum, as with one finger.
    if (FingerTwoContacts(i, 0) && ModelHasForce(model_)) s.force = *s.contacts[0].force + *s.contacts[1].force;
  } else if (HasSecondContact(i)) {
    s.contacts.resize(2);
    s.contacts[0].point = Vec2(v.p[0], v.p[1]);
    s.contacts[1].point = Vec2(v.p2[0], v.p2[1]);
    if (HasForceVars(i)) {
      s.contacts[0].force = Vec2(v.f[0], v.f[1]);
      s.contacts[1].force = Vec2(v.f2[0], v.f2[1]);
      s.force = *s.contacts[0].force + *s.contacts[1].force;
    }
  }
  return s;
}

}  // namespace pushgraph::graph::internal
