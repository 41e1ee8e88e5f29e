#include "graph_builder.h"

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
  g.c = (cfg.c > 0.0 ? cfg.c : s.c) * cfg.c_scale;
  g.centre_of_pressure = s.centre_of_pressure;
  return g;
}

namespace internal {
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

template <class Sample>
void CheckSorted(const std::vector<Sample>& s, const std::string& stream) {
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (!(s[i].t > s[i - 1].t)) {
      throw GraphError("trajectory: streams." + stream + " is not strictly increasing in time at sample " +
                       std::to_string(i));
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
  for (std::size_t i = 1; i < s.size(); ++i) d.push_back(s[i].t - s[i - 1].t);
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

namespace {

void ValidateTrajectory(const push::Trajectory& traj) {
  if (traj.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
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
  CheckSorted(m.contact_point, "contact_point");
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

}  // namespace

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model,
                           const EstimatorConfig& config)
    : traj_(trajectory), model_(model), cfg_(config) {
  ValidateConfig(cfg_);
  ValidateTrajectory(traj_);
  streams_.contact_point = !traj_.measured.contact_point.empty();
  streams_.force = !traj_.measured.force.empty();
  AppendSteps(INFINITY);
  SetUpShapes();
}

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model,
                           const EstimatorConfig& config, const OnlineStreams& streams)
    : traj_(trajectory), model_(model), cfg_(config), streams_(streams) {
  ValidateConfig(cfg_);
  if (traj_.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj_.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
  SetUpShapes();
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
  std::sort(events.begin(), events.end());
  const std::size_t first_new = steps_.size();
  for (const auto& [t, stream, index] : events) {
    // (OnlineEstimator only accepts samples more than 1e-9 s after the last update's steps.)
    if (steps_.size() == first_new || t - steps_.back().t > 1e-9) {
      steps_.push_back(Step{});
      steps_.back().t = t;
    }
    Step& s = steps_.back();
    int* slot = stream == 0 ? &s.object : stream == 1 ? &s.finger : stream == 2 ? &s.contact : &s.force;
    *slot = index;
  }
  // Contact gating, on the samples received so far (all of them in batch).
  for (std::size_t i = first_new; i < steps_.size(); ++i) {
    Step& s = steps_[i];
    if (streams_.contact_point) {
      s.in_contact = NearestGap(m.contact_point, s.t) <= cfg_.contact_max_gap;
    } else if (streams_.force) {
      int k = -1;
      const double gap = NearestGap(m.force, s.t, &k);
      s.in_contact = k >= 0 && gap <= cfg_.contact_max_gap && m.force[k].force.norm() >= cfg_.contact_force_threshold;
    } else {
      s.in_contact = true;
    }
  }
  vars_.resize(steps_.size());
  return static_cast<int>(steps_.size() - first_new);
}

void GraphBuilder::SetUpShapes() {
  geometry::ShapePairQuerier::Options pair_options;
  pair_options.angle_cache_resolution = cfg_.finger_angle_resolution;
  pair_options.max_cached_angles = 4096;
  pair_options.check_rounded_depth = false;  // the factors never read depth_exact: no second query
  querier_ = std::make_shared<geometry::ShapePairQuerier>(traj_.object.shape, traj_.finger.shape, pair_options);
  if (ModelHasForce(model_)) qs_ = QuasiStaticGeometryFor(traj_, cfg_);
  if (traj_.object.mass > 0.0 && traj_.object.mu_surface > 0.0) {
    mu_surface_ = traj_.object.mu_surface;
    normal_load_ = traj_.object.mass * limit_surface::kStandardGravity;
    f_max_ = mu_surface_ * normal_load_;
  }
  using Load = EstimatorConfig::LimitSurfaceLoad;
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
  const auto it = origin_.find(id);
  if (it == origin_.end()) return "a marginal prior or unnamed factor";
  const auto [type, step] = it->second;
  std::string s = std::string(FactorTypeName(type)) + " factor";
  if (step >= 0 && step < static_cast<int>(steps_.size())) {
    char t[48];
    std::snprintf(t, sizeof t, "%.9g", steps_[step].t);
    s += " at step " + std::to_string(step) + " (t = " + t + " s)";
  } else {
    s += " (shared by the trajectory)";
  }
  return s;
}

SolveOutcome GraphBuilder::Solve(ceres::Problem& problem, int max_iterations, double function_tolerance,
                                 const char* what) const {
  SolveOutcome out;
  if (cfg_.solver == EstimatorConfig::Solver::kCeres) {
    ceres::Solver::Summary summary;
    ceres::Solve(SolverOptions(max_iterations, function_tolerance), &problem, &summary);
    LogSummary(what, summary);
    if (summary.termination_type == ceres::FAILURE) throw GraphError(std::string(what) + " failed: " + summary.message);
    out.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
    out.final_cost = summary.final_cost;
    out.converged = summary.termination_type == ceres::CONVERGENCE;
    out.termination = summary.message;
    return out;
  }
  ChainSolverOptions options;
  options.max_iterations = max_iterations;
  options.function_tolerance = function_tolerance;
  options.describe = [this](ceres::ResidualBlockId id) { return Describe(id); };
  options.log_iterations = SolverLogLevel() >= 2;
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
  if (shape_frame_ && !object_pose_blocks.empty()) {
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
    if (s.force >= 0) {
      v.f[0] = m.force[s.force].force.x(); v.f[1] = m.force[s.force].force.y();
    } else if (!m.force.empty() && !causal) {
      const Vec2 f = push::StreamValueClamped(m.force, s.t, [](const push::ForceSample& a) { return Vec2(a.force); });
      v.f[0] = f.x(); v.f[1] = f.y();
    } else if (causal && prev != nullptr && steps_[i - 1].in_contact) {
      v.f[0] = prev->f[0]; v.f[1] = prev->f[1];
    } else {
      // Towards the object's centre, small: D's gradient in f is well defined for any f.
      Vec2 d = Vec2(v.x[0], v.x[1]) - Vec2(v.p[0], v.p[1]);
      d = d.norm() > 0 ? Vec2(0.1 * d.normalized()) : Vec2(0.1, 0.0);
      v.f[0] = d.x(); v.f[1] = d.y();
    }
  }
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
    if (i < first) {
      problem.SetParameterBlockConstant(vars_[i].x);
      problem.SetParameterBlockConstant(vars_[i].e);
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
  return outcome.iterations;
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
    if (s.in_contact) problem.AddParameterBlock(v.p, 2);
    AddKinematicFactors(problem, i);
  }
  if ((parts & kDynamic) && HasForceVars(i)) {
    problem.AddParameterBlock(v.f, 2);
    AddDynamicFactors(problem, i);
  }
}

void GraphBuilder::AddKinematicFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
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
    Add(problem, FactorType::kContactOnObject, new BoundaryPointFactor(traj_.object.shape, cfg_.contact_object_sigma), nullptr,
        {v.x, v.p}, {0});
    if (cfg_.contact_finger == EstimatorConfig::ContactFinger::kWitness) {
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
}

void GraphBuilder::AddDynamicFactors(ceres::Problem& problem, int i) {
  adding_step_ = i;
  const auto& m = traj_.measured;
  const Step& s = steps_[i];
  StepVars& v = vars_[i];
  // Force: measurement, weak prior, quasi-static factor.
  {
    if (s.force >= 0) {
      Add(problem, FactorType::kForce, new VectorMeasurementFactor(m.force[s.force].force, cfg_.measurement.force),
          MakeLoss(cfg_.force_loss), {v.f});
    }
    Add(problem, FactorType::kForcePrior, new VectorMeasurementFactor(Vec2::Zero(), cfg_.force_prior_sigma), nullptr, {v.f});
    if (i >= 1 && HasForceVars(i - 1)) {
      Add(problem, FactorType::kForceContinuity, new VectorRandomWalkFactor(s.t - steps_[i - 1].t, cfg_.force_random_walk),
          nullptr, {vars_[i - 1].f, v.f});
    }
    if (i >= 1) {
      QuasiStaticGeometry g = qs_;
      g.dt = s.t - steps_[i - 1].t;
      const double rate_scale = std::sqrt(0.01 / g.dt);  // per-10-ms sigmas (config.h)
      if (model_ == Model::kQs) {
        if (estimate_c_) {
          Add(problem, FactorType::kQuasiStatic,
                         new QuasiStaticFactorWithC(g, cfg_.eps_velocity, cfg_.eps_force, cfg_.quasi_static_sigma * rate_scale),
                         nullptr, {vars_[i - 1].x, v.x, v.p, v.f, c_var_}, {0, 1});
          // Prior around the geometric value; bounds keep c physical (tau / c in D).
          if (!c_in_problem_) AddSharedParameterPrior(*this, problem, c_var_, qs_.c, cfg_.c_prior_sigma);
          c_in_problem_ = true;
        } else {
          Add(problem, FactorType::kQuasiStatic,
                         new QuasiStaticFactor(g, cfg_.eps_velocity, cfg_.eps_force, cfg_.quasi_static_sigma * rate_scale),
                         nullptr, {vars_[i - 1].x, v.x, v.p, v.f}, {0, 1});
        }
        if (use_load_factor_ && (estimate_c_ || estimate_mu_)) {
          // The same c as D's (estimated) and/or mu as variables.
          std::vector<double*> blocks{vars_[i - 1].x, v.x, v.p, v.f};
          if (estimate_c_) blocks.push_back(c_var_);
          if (estimate_mu_) blocks.push_back(mu_var_);
          Add(problem, FactorType::kLimitSurfaceLoad,
                         new LimitSurfaceLoadFactorWithParameters(g, normal_load_, mu_surface_, {estimate_c_, estimate_mu_},
                                                                  cfg_.eps_velocity, cfg_.eps_force,
                                                                  cfg_.limit_surface_sigma * rate_scale),
                         nullptr, blocks, {0, 1});
          // Prior around the trajectory's mu; bounds keep f_max physical.
          if (estimate_mu_ && !mu_in_problem_) AddSharedParameterPrior(*this, problem, mu_var_, mu_surface_, cfg_.mu_prior_sigma);
          mu_in_problem_ = mu_in_problem_ || estimate_mu_;
        } else if (use_load_factor_) {
          Add(problem, FactorType::kLimitSurfaceLoad,
                         new LimitSurfaceLoadFactor(g, f_max_, cfg_.eps_velocity, cfg_.eps_force,
                                                    cfg_.limit_surface_sigma * rate_scale),
                         nullptr, {vars_[i - 1].x, v.x, v.p, v.f}, {0, 1});
        }
      } else {
        Add(problem, FactorType::kQuasiStatic, new CrossMultipliedQuasiStaticFactor(g, cfg_.yu_quasi_static_sigma * rate_scale), nullptr,
                       {vars_[i - 1].x, v.x, v.p, v.f}, {0, 1});
      }
    }
  }
}

std::vector<double*> GraphBuilder::Blocks(int i) {
  std::vector<double*> b{vars_[i].x, vars_[i].e};
  if (HasContactVars(i)) b.push_back(vars_[i].p);
  if (HasForceVars(i)) b.push_back(vars_[i].f);
  return b;
}

void GraphBuilder::DropUnobservableForces(EstimationResult& result) const {
  if (ForceScaleObservable()) return;
  for (StateEstimate& s : result.states) {
    s.force.reset();
    s.force_cov.reset();
  }
  const std::string how = model_ == Model::kYu
                              ? "the baseline has no limit-surface load"
                              : (f_max_ > 0.0 ? "limit_surface_load is off"
                                              : "the object's mass or mu_surface is missing, so there is no limit-surface load");
  result.warnings.push_back("forces not reported: there is no force stream and " + how +
                            ", so nothing fixes their size (the quasi-static factor fixes only their direction)");
}

void GraphBuilder::SetState(int i, const StateEstimate& st) {
  StepVars& v = vars_[i];
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
  return s;
}

std::string ComputeCovariances(ceres::Problem& problem, GraphBuilder& builder, const std::vector<int>& steps,
                               std::vector<StateEstimate>& states, EstimatorConfig::CovarianceMethod method,
                               EstimationResult* parameters, Eigen::Matrix3d* frame_cov, ChainSolver* chain) {
  // The shared parameters (c, mu) whose sigmas are wanted.
  std::vector<std::pair<double*, std::optional<double>*>> shared;
  if (parameters != nullptr) {
    if (double* c = builder.c_block()) shared.emplace_back(c, &parameters->c_sigma);
    if (double* mu = builder.mu_block()) shared.emplace_back(mu, &parameters->mu_sigma);
  }
  // Either method answers "the covariance of block b" into a row-major buffer.
  std::function<bool(double*, double*)> get;
  SparseMarginals marginals;
  std::unique_ptr<ceres::Covariance> covariance;
  std::string marginals_error;
  if (method == EstimatorConfig::CovarianceMethod::kSelectedInversion) {
    const auto start = std::chrono::steady_clock::now();
    if (chain != nullptr ? marginals.Compute(*chain) : marginals.Compute(problem)) {
      if (SolverLogLevel() >= 1) {
        const SparseMarginals::Timings& t = marginals.timings();
        std::cerr << "pushgraph marginals: " << marginals.num_unknowns() << " unknowns, "
                  << marginals.num_factor_nonzeros() << " factor nonzeros, "
                  << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                  << " s (Jacobian " << t.jacobian << ", J^T J " << t.normal_equations << ", Cholesky "
                  << t.factorization << ", selected inversion " << t.inversion << "), smallest pivot ratio "
                  << marginals.min_pivot_ratio() << "\n";
      }
      get = [&](double* b, double* out) {
        const Eigen::MatrixXd m = marginals.Covariance(b);
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(out, m.rows(), m.cols()) = m;
        return true;
      };
    } else {
      // Name the state, then try the QR on J (it copes with worse conditioning than J^T J).
      marginals_error = marginals.error();
      const double* bad = marginals.failed_block();
      const char* names[] = {"object pose", "finger pose", "contact point", "force"};
      for (int i = 0; bad != nullptr && i < static_cast<int>(builder.steps().size()); ++i) {
        const StepVars& v = builder.vars()[i];
        const double* blocks[] = {v.x, v.e, v.p, v.f};
        for (int q = 0; q < 4; ++q) {
          if (blocks[q] != bad) continue;
          marginals_error += " [step " + std::to_string(i) + ", t = " + std::to_string(builder.steps()[i].t) +
                             ", " + names[q] + "]";
        }
      }
      if (bad != nullptr && bad == builder.c_block()) marginals_error += " [c]";
      if (bad != nullptr && bad == builder.mu_block()) marginals_error += " [mu]";
      if (SolverLogLevel() >= 1) std::cerr << "pushgraph marginals: " << marginals_error << "; trying ceres::Covariance\n";
    }
  }
  if (!get) {
    ceres::Covariance::Options options;
    options.algorithm_type = ceres::SPARSE_QR;
    options.num_threads = 1;
    covariance = std::make_unique<ceres::Covariance>(options);
    std::vector<std::pair<const double*, const double*>> pairs;
    for (int i : steps) {
      for (double* b : builder.Blocks(i)) pairs.emplace_back(b, b);
    }
    for (const auto& sh : shared) pairs.emplace_back(sh.first, sh.first);
    if (frame_cov != nullptr && builder.frame_block() != nullptr) pairs.emplace_back(builder.frame_block(), builder.frame_block());
    if (!covariance->Compute(pairs, &problem)) {
      return "failed (" + (marginals_error.empty() ? std::string("rank-deficient Jacobian") : marginals_error) + ")";
    }
    get = [&](double* b, double* out) { return covariance->GetCovarianceBlock(b, b, out); };
  }
  for (const auto& [block, sigma] : shared) {
    if (double var = 0.0; get(block, &var)) *sigma = std::sqrt(var);
  }
  if (frame_cov != nullptr && builder.frame_block() != nullptr) {
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c3;
    if (get(builder.frame_block(), c3.data())) *frame_cov = c3;
  }
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const int i = steps[k];
    StepVars& v = builder.vars()[i];
    StateEstimate& s = states[k];
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c3;
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> c2;
    get(v.x, c3.data());
    s.object_pose_cov = Eigen::Matrix3d(c3);
    get(v.e, c3.data());
    s.finger_pose_cov = Eigen::Matrix3d(c3);
    if (builder.HasContactVars(i)) {
      get(v.p, c2.data());
      s.contact_cov = Eigen::Matrix2d(c2);
    }
    if (builder.HasForceVars(i)) {
      get(v.f, c2.data());
      s.force_cov = Eigen::Matrix2d(c2);
    }
  }
  return "ok";
}

int SolverLogLevel() {
  static const int level = [] {
    const char* v = std::getenv("PUSHGRAPH_SOLVER_LOG");
    return v == nullptr || *v == '\0' ? 0 : std::atoi(v);
  }();
  return level;
}

void LogSummary(const char* what, const ceres::Solver::Summary& summary) {
  if (SolverLogLevel() >= 1) std::cerr << "pushgraph " << what << ":\n" << summary.FullReport() << "\n";
}

ceres::Solver::Options SolverOptions(int max_iterations, double function_tolerance) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = max_iterations;
  o.function_tolerance = function_tolerance;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = 1e-10;
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  if (SolverLogLevel() >= 2) {
    o.logging_type = ceres::PER_MINIMIZER_ITERATION;  // per-iteration trace, for tuning
    o.minimizer_progress_to_stdout = true;
  }
  return o;
}

}  // namespace internal

namespace {

// The shape frame as a static variable of the batch graph (shape_frame.h).
struct FrameSetup {
  Vec2 centroid = Vec2::Zero();  // of the aligned shape, object frame
  double sigma_centroid = 0.01, sigma_theta = 0.2;
  bool rotation = true;
  Pose2 frame;                   // out: the estimate
  std::optional<Eigen::Matrix3d> covariance;  // out
};

EstimationResult EstimateBatch(const push::Trajectory& traj, Model model, const EstimatorConfig& cfg,
                               FrameSetup* frame = nullptr) {
  internal::GraphBuilder builder(traj, model, cfg);
  if (frame) builder.EnableShapeFrame(frame->centroid, frame->sigma_centroid, frame->sigma_theta, frame->rotation);
  if (cfg.estimate_c) builder.EnableCEstimation();
  if (cfg.estimate_mu) builder.EnableMuEstimation();
  const int n = static_cast<int>(builder.steps().size());
  const auto start = std::chrono::steady_clock::now();
  ceres::Problem problem;
  for (int i = 0; i < n; ++i) builder.Initialize(i, INFINITY);
  int stage_iterations = 0;
  if (ModelHasForce(model)) {
    // Staged start: the kinematic SDF graph first (interpolated measurements are far from
    // satisfying D's per-step velocity directions), then the full graph from its solution.
    internal::GraphBuilder kinematic(traj, Model::kSdf, cfg);
    ceres::Problem pre;
    for (int i = 0; i < n; ++i) kinematic.Initialize(i, INFINITY);
    stage_iterations += kinematic.SmoothInitialMotion(10, 1e-3);
    for (int i = 0; i < n; ++i) kinematic.AddFactors(pre, i);
    stage_iterations += kinematic.Solve(pre, cfg.max_iterations, cfg.function_tolerance, "batch warm start (sdf)").iterations;
    for (int i = 0; i < n; ++i) {
      auto& dst = builder.vars()[i];
      const auto& src = kinematic.vars()[i];
      std::copy(src.x, src.x + 3, dst.x);
      std::copy(src.e, src.e + 3, dst.e);
      std::copy(src.p, src.p + 2, dst.p);
    }
  }
  if (!ModelHasForce(model)) stage_iterations += builder.SmoothInitialMotion(10, 1e-3);
  for (int i = 0; i < n; ++i) builder.AddFactors(problem, i);
  const internal::SolveOutcome summary = builder.Solve(problem, cfg.max_iterations, cfg.function_tolerance, "batch solve");
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
  if (!summary.converged) {
    r.warnings.push_back("the batch solve stopped at its iteration limit (" + std::to_string(cfg.max_iterations) +
                         ") before converging: " + summary.termination);
  }
  r.solver.updates = 1;
  r.solver.max_update_time_s = r.solver.mean_update_time_s = r.solver.time_s;
  builder.DropUnobservableForces(r);
  r.metrics = ComputeMetrics(traj, r.states);
  return r;
}

struct Accumulator {
  double sum = 0.0;
  int n = 0;
  void Add(double sq) { sum += sq; ++n; }
  void Put(std::map<std::string, double>& m, const std::string& key, bool rms = true) const {
    if (n > 0) m[key] = rms ? std::sqrt(sum / n) : sum / n;
  }
};

}  // namespace

std::map<std::string, double> ComputeMetrics(const push::Trajectory& traj,
                                             const std::vector<StateEstimate>& states) {
  std::map<std::string, double> m;
  if (!traj.ground_truth) return m;
  const auto& gt = *traj.ground_truth;
  // Ground truth at the estimate's times, errors and moving rows: push/scoring.h's one rule.
  Accumulator op, orot, op_moving, orot_moving, fp, frot, cp, fo, nees_o, nees_f, nees_c, nees_force;
  // Gauge-free NEES: covariance matrices here are well conditioned, LDLT is enough.
  auto nees = [](const auto& e, const auto& cov) { return e.dot(cov.ldlt().solve(e)); };
  for (const StateEstimate& s : states) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.object_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.object_pose, g);
      op.Add(e.head<2>().squaredNorm());
      orot.Add(e.z() * e.z());
      if (push::ObjectMovingAt(gt.object_pose, s.t)) {
        op_moving.Add(e.head<2>().squaredNorm());
        orot_moving.Add(e.z() * e.z());
      }
      if (s.object_pose_cov) nees_o.Add(nees(e, *s.object_pose_cov));
    }
    if (push::TruthPoseAt(gt.finger_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.finger_pose, g);
      fp.Add(e.head<2>().squaredNorm());
      frot.Add(e.z() * e.z());
      if (s.finger_pose_cov) nees_f.Add(nees(e, *s.finger_pose_cov));
    }
    Vec2 v;
    if (s.contact && push::TruthPointAt(gt.contact_point, s.t, &v)) {
      const Vec2 e = *s.contact - v;
      cp.Add(e.squaredNorm());
      if (s.contact_cov) nees_c.Add(nees(e, *s.contact_cov));
    }
    if (s.force && push::TruthForceAt(gt.force, s.t, &v)) {
      const Vec2 e = *s.force - v;
      fo.Add(e.squaredNorm());
      if (s.force_cov) nees_force.Add(nees(e, *s.force_cov));
    }
  }
  op.Put(m, "object_position_rms");
  orot.Put(m, "object_rotation_rms");
  op_moving.Put(m, "object_position_moving_rms");
  orot_moving.Put(m, "object_rotation_moving_rms");
  fp.Put(m, "finger_position_rms");
  frot.Put(m, "finger_rotation_rms");
  cp.Put(m, "contact_rms");
  fo.Put(m, "force_rms");
  nees_o.Put(m, "object_pose_nees", false);
  nees_f.Put(m, "finger_pose_nees", false);
  nees_c.Put(m, "contact_nees", false);
  nees_force.Put(m, "force_nees", false);
  // The raw measurements against the same ground truth.
  Accumulator mop, morot, mfp, mfrot, mcp, mfo;
  const auto& meas = traj.measured;
  for (const auto& s : meas.object_pose) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.object_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.pose, g);
      mop.Add(e.head<2>().squaredNorm());
      morot.Add(e.z() * e.z());
    }
  }
  for (const auto& s : meas.finger_pose) {
    Eigen::Vector3d g;
    if (push::TruthPoseAt(gt.finger_pose, s.t, &g)) {
      const Eigen::Vector3d e = push::PoseError(s.pose, g);
      mfp.Add(e.head<2>().squaredNorm());
      mfrot.Add(e.z() * e.z());
    }
  }
  for (const auto& s : meas.contact_point) {
    Vec2 v;
    if (push::TruthPointAt(gt.contact_point, s.t, &v)) mcp.Add((s.point - v).squaredNorm());
  }
  for (const auto& s : meas.force) {
    Vec2 v;
    if (push::TruthForceAt(gt.force, s.t, &v)) mfo.Add((s.force - v).squaredNorm());
  }
  mop.Put(m, "measured_object_position_rms");
  morot.Put(m, "measured_object_rotation_rms");
  mfp.Put(m, "measured_finger_position_rms");
  mfrot.Put(m, "measured_finger_rotation_rms");
  mcp.Put(m, "measured_contact_rms");
  mfo.Put(m, "measured_force_rms");
  return m;
}

namespace {

std::string TransformText(const ShapeTransform& t) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.6g,%.6g,%.6g", t.pose.x, t.pose.y, t.pose.theta);
  std::string s = std::string("--transform ") + buf;
  if (t.scale != 1.0) {
    std::snprintf(buf, sizeof buf, "%.6g", t.scale);
    s = std::string("--scale ") + buf + " " + s;
  }
  if (t.mirrored) s = "--mirror " + s;
  return s;
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

EstimationResult EstimateValidated(const push::Trajectory& trajectory, Model model, Mode mode,
                                   const EstimatorConfig& config);

}  // namespace

EstimationResult Estimate(const push::Trajectory& trajectory, Model model, Mode mode,
                          const EstimatorConfig& config) {
  ValidateConfig(config);
  internal::ValidateTrajectory(trajectory);
  std::string note;
  const std::optional<push::Trajectory> repaired = DropForceSpikes(trajectory, &note);
  EstimationResult r = EstimateValidated(repaired ? *repaired : trajectory, model, mode, config);
  if (repaired) r.warnings.insert(r.warnings.begin(), note);
  return r;
}

namespace {

EstimationResult EstimateValidated(const push::Trajectory& trajectory, Model model, Mode mode,
                                   const EstimatorConfig& config) {
  using Align = EstimatorConfig::AlignShape;
  // The shape against the recording: the check, then registration where asked or needed.
  ShapeAlignment alignment;
  std::vector<std::string> warnings;
  RegistrationOptions options = RegistrationOptionsFor(config);
  options.estimate_scale = config.align_scale;
  std::optional<RegistrationResult> registration;
  try {
    alignment.check = CheckShapeFit(trajectory, options);
    alignment.checked = true;
    // Always: the check's gaps miss a turn that the noise hides, the likelihood ratio does not.
    registration = RegisterShape(trajectory, options);
    alignment.check.fits = registration->fits_as_given;
  } catch (const std::exception& e) {
    // Too few contacts with object poses near them to say anything about the shape.
    alignment.notes.push_back(std::string("shape not checked: ") + e.what());
    if (config.align_shape == Align::kOn) throw GraphError(std::string("align_shape \"on\": ") + e.what());
  }
  // A misfit has several explanations: the registration's best placement, its alternatives
  // (other rotations the contacts of one push leave open), or a wrong finger size (the shape as
  // given with the finger size_offset larger). Contacts alone cannot always tell them apart;
  // the whole graph can (dynamics, smoothing): each is estimated (batch, no covariances) and
  // the lowest final cost wins.
  const bool misfit = registration && !registration->fits_as_given;
  const geometry::Shape& finger = trajectory.finger.shape;
  const double sized_radius = finger.radius() + (registration ? registration->size_offset : 0.0);
  const bool size_candidate = misfit && sized_radius > 0.0 &&
                              std::abs(registration->size_offset) <= std::max(5e-3, 3.0 * finger.radius());
  bool size_wins = false, identity_wins = false;
  const bool will_align = registration && (config.align_shape == Align::kOn || (config.align_shape == Align::kAuto && misfit));
  if (registration && (misfit || config.align_shape == Align::kOn) &&
      (size_candidate || !registration->alternatives.empty() || will_align)) {
    EstimatorConfig quick = config;
    quick.covariance = false;
    quick.diagnostics = false;
    quick.max_iterations = std::min(quick.max_iterations, 25);  // ranking, not the final solve
    // Each placement's graph cost and its transform refined by the graph (the shape frame).
    auto framed_cost = [&](const ShapeTransform& t, ShapeTransform* refined) {
      RegistrationResult r = *registration;
      r.transform = t;
      push::Trajectory framed = trajectory;
      framed.object.shape = r.Apply(trajectory.object.shape);
      FrameSetup frame;
      frame.centroid = geometry::CoreCentroid(framed.object.shape);
      frame.sigma_centroid = options.centroid_prior * geometry::RadiusAbout(framed.object.shape, frame.centroid);
      frame.rotation = registration->rotation_observable;
      const double cost = EstimateBatch(framed, model, quick, &frame).solver.final_cost;
      *refined = t;
      refined->pose = geometry::Compose(frame.frame, t.pose);
      return cost;
    };
    ShapeTransform best, refined;
    double best_cost = framed_cost(registration->transform, &best);
    // The shape as given competes too: the contacts alone can misjudge a push the model does
    // not describe (a finger wedged between two walls under bimodal noise misfired so).
    {
      ShapeTransform as_given;
      const double cost = framed_cost(as_given, &refined);
      char text[200];
      std::snprintf(text, sizeof text, "the shape as given: graph cost %.1f against %.1f for the best placement", cost, best_cost);
      alignment.notes.push_back(text);
      // Ties between placements the data cannot tell apart keep the shape as given: a placement
      // must do better by more than 2 in cost (a log-likelihood).
      if (cost <= best_cost + 2.0) {
        identity_wins = true;
        best_cost = cost - 2.0;
      }
    }
    char text[240];
    for (const ShapeTransform& alt : registration->alternatives) {
      const double cost = framed_cost(alt, &refined);
      std::snprintf(text, sizeof text, "alternative placement turned by %.1f deg, shifted by (%.1f, %.1f) mm: graph cost %.1f "
                    "against %.1f", alt.pose.theta * 180.0 / M_PI, alt.pose.x * 1e3, alt.pose.y * 1e3, cost, best_cost);
      alignment.notes.push_back(text);
      if (cost < best_cost) {
        best_cost = cost;
        best = refined;
        identity_wins = false;
      }
    }
    // The graph-refined placement: the start of the final batch solve, or (incremental) the
    // frame kept fixed while smoothing.
    registration->transform = CanonicalTransform(best, trajectory.object.shape, registration->symmetry_order);
    if (identity_wins) {
      registration->fits_as_given = true;
      alignment.check.fits = true;
    }
    if (size_candidate) {
      push::Trajectory sized = trajectory;
      sized.finger.shape = finger.WithRadius(sized_radius);
      const double sized_cost = EstimateBatch(sized, model, quick).solver.final_cost;
      size_wins = sized_cost < best_cost;
      std::snprintf(text, sizeof text, "frame or size: graph cost %.1f with the shape aligned, %.1f with the finger %.1f mm %s",
                    best_cost, sized_cost, std::abs(registration->size_offset) * 1e3,
                    registration->size_offset > 0 ? "larger" : "smaller");
      alignment.notes.push_back(text);
    }
  }
  const bool align = registration && (config.align_shape == Align::kOn ||
                                      (config.align_shape == Align::kAuto && misfit && !size_wins && !identity_wins));
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
  if (align) {
    aligned_trajectory = trajectory;
    aligned_trajectory.object.shape = registration->Apply(trajectory.object.shape);
    working = &aligned_trajectory;
    alignment.aligned = true;
  }
  EstimationResult result;
  std::optional<internal::FrameState> frame_state;
  if (mode == Mode::kBatch) {
    if (align) {
      // The frame refined as a static variable: the centroid prior of the registration.
      FrameSetup frame;
      const geometry::Shape& shape = working->object.shape;
      frame.centroid = geometry::CoreCentroid(shape);
      frame.sigma_centroid = options.centroid_prior * geometry::RadiusAbout(shape, frame.centroid);
      frame.rotation = registration->rotation_observable;
      result = EstimateBatch(*working, model, config, &frame);
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
      result = EstimateBatch(*working, model, config);
    }
  } else {
    // Fixed-lag smoothing keeps the registered frame fixed (no static variable in the window).
    IncrementalEstimator inc(*working, model, config);
    while (!inc.Done()) inc.Update();
    result = inc.Finish();
  }
  if (alignment.checked && !alignment.check.fits) {
    const std::string what = "the object's shape does not fit this recording as given (" + alignment.check.Describe() + ")";
    if (size_wins) {
      char size[160];
      std::snprintf(size, sizeof size, "the finger %.1f mm %s than given (radius %.1f mm instead of %.1f mm)",
                    std::abs(registration->size_offset) * 1e3, registration->size_offset > 0 ? "larger" : "smaller",
                    sized_radius * 1e3, finger.radius() * 1e3);
      warnings.push_back(what + "; it fits as given with " + size +
                         ": a wrong probe radius or object size? (the estimate uses the finger as given)");
    } else if (align) {
      RegistrationResult final_transform = *registration;
      final_transform.transform = alignment.transform;
      warnings.push_back(what + "; aligned it: " + final_transform.Describe() +
                         " (to save it: pushgraph footprint SHAPE_FILE " + TransformText(alignment.transform) + ")");
    } else if (misfit) {
      warnings.push_back(what + "; estimates may be worse than the raw measurements. The contacts suggest " +
                         registration->Describe() + ": --align-shape auto or on aligns it");
    } else {
      warnings.push_back(what + ", and no rigid placement fits it better: a wrong probe radius or object size?");
    }
  }

  if (registration && registration->fits_as_given && registration->better_elsewhere && !alignment.aligned) {
    // The gaps are within tolerance, but a different placement explains the contacts clearly
    // better: say so; aligning on this alone misfired on pushes that break the model.
    char text[400];
    std::snprintf(text, sizeof text,
                  "the object's shape fits this recording within the tolerance, but the contacts fit it better %s "
                  "(log-likelihood +%.1f): if the shape file's frame is uncertain, --align-shape on aligns it",
                  registration->Describe().c_str(), registration->identity_cost - registration->aligned_cost);
    warnings.push_back(text);
  }
  if (alignment.checked || !alignment.notes.empty()) result.shape_alignment = alignment;
  if (config.diagnostics) {
    result.diagnostics = internal::Diagnose(*working, model, config, result, frame_state ? &*frame_state : nullptr);
    for (const std::string& cause : result.diagnostics->causes) warnings.push_back("diagnostics: " + cause);
  }
  result.warnings.insert(result.warnings.begin(), warnings.begin(), warnings.end());
  return result;
}

}  // namespace

}  // namespace pushgraph::graph
