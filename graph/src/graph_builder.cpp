#include "graph_builder.h"

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

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model, const EstimatorConfig& config,
                           std::shared_ptr<const geometry::ShapePairQuerier> querier)
    : traj_(trajectory), model_(model), cfg_(config) {
  ValidateConfig(cfg_);
  ValidateTrajectory(traj_);
  streams_.contact_point = !traj_.measured.contact_point.empty();
  streams_.force = !traj_.measured.force.empty();
  AppendSteps(INFINITY);
  SetUpShapes(std::move(querier));
}

GraphBuilder::GraphBuilder(const push::Trajectory& trajectory, Model model,
                           const EstimatorConfig& config, const OnlineStreams& streams)
    : traj_(trajectory), model_(model), cfg_(config), streams_(streams) {
  ValidateConfig(cfg_);
  if (traj_.object.shape.empty()) throw GraphError("trajectory: object.shape is missing or empty");
  if (traj_.finger.shape.empty()) throw GraphError("trajectory: finger.shape is missing or empty");
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
  std::sort(events.begin(), events.end());
  const std::size_t first_new = steps_.size();
  for (const auto& [t, stream, index] : events) {
    // (OnlineEstimator only accepts samples more than 1e-9 s after the last update's steps.)
    if (steps_.size() == first_new || t - steps_.back().t > 1e-9) {
      steps_.push_back(Step{});
      steps_.back().t = t;
    }
    Step& s = steps_.back();
    if (stream == 2 && s.contact >= 0) {
      // Two contact rows at one time: a finger touching the object at two points.
      if (s.contact2 >= 0) {
        std::ostringstream text;
        text.precision(17);
        text << "trajectory: streams.contact_point has more than two contacts at t = " << t
             << " s (rows " << s.contact << ", " << s.contact2 << ", " << index
             << "): the estimator models at most two contacts of the finger";
        throw GraphError(text.str());
      }
      s.contact2 = index;
      continue;
    }
    int* slot = stream == 0 ? &s.object : stream == 1 ? &s.finger : stream == 2 ? &s.contact : &s.force;
    *slot = index;
  }
  // Contact gating, on the samples received so far (all of them in batch).
  for (std::size_t i = first_new; i < steps_.size(); ++i) {
    Step& s = steps_[i];
    if (streams_.contact_point) {
      int k = -1;
      s.in_contact = NearestGap(m.contact_point, s.t, &k) <= cfg_.contact_max_gap;
      // Two contacts while the nearest contact time has two rows.
      const auto& c = m.contact_point;
      s.two_contacts = s.in_contact && k >= 0 &&
                       ((k > 0 && c[k - 1].t == c[k].t) || (k + 1 < static_cast<int>(c.size()) && c[k + 1].t == c[k].t));
      if (s.two_contacts && model_ == Model::kYu) {
        // The baseline models one contact, as published: it keeps the first of the two.
        s.two_contacts = false;
        ++second_contacts_ignored_;
      }
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

std::shared_ptr<const geometry::ShapePairQuerier> GraphBuilder::MakeQuerier(const push::Trajectory& trajectory,
                                                                          const EstimatorConfig& config) {
  geometry::ShapePairQuerier::Options pair_options;
  pair_options.angle_cache_resolution = config.finger_angle_resolution;
  pair_options.max_cached_angles = 4096;
  pair_options.check_rounded_depth = false;  // the factors never read depth_exact: no second query
  return std::make_shared<geometry::ShapePairQuerier>(trajectory.object.shape, trajectory.finger.shape, pair_options);
}

void GraphBuilder::SetUpShapes(std::shared_ptr<const geometry::ShapePairQuerier> querier) {
  querier_ = querier ? std::move(querier) : MakeQuerier(traj_, cfg_);
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
  if (warm_start_) return id;
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
    if (s.two_contacts) InitializeSecondContact(i, causal);
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
    if (s.two_contacts) {
      // The measured (net) force shared by both contacts to start.
      v.f2[0] = v.f[0] = 0.5 * v.f[0];
      v.f2[1] = v.f[1] = 0.5 * v.f[1];
    }
  }
}

bool GraphBuilder::TwoContactFeatures(int i, ContactFeature out[2]) const {
  const StepVars& v = vars_[i];
  const Pose2 x{v.x[0], v.x[1], v.x[2]}, e{v.e[0], v.e[1], v.e[2]};
  // Candidates: every object feature the finger is near at the current values (3 sigma of a
  // contact measurement: the values may be that far off), each once, nearest first.
  const double tolerance = 3.0 * cfg_.measurement.contact;
  std::vector<geometry::ContactPoint> found;
  try {
    found = geometry::FindContacts(traj_.object.shape, x, traj_.finger.shape, e, {tolerance, tolerance});
  } catch (const geometry::GeometryError&) {
    return false;
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.separation < b.separation; });
  std::vector<std::pair<ContactFeature, Vec2>> distinct;
  for (const geometry::ContactPoint& c : found) {
    ContactFeature f;
    f.edge = c.object_feature;
    f.vertex = c.kind != geometry::ContactPoint::Kind::kFingerVertexObjectEdge;
    const bool seen = std::any_of(distinct.begin(), distinct.end(), [&](const auto& d) {
      return d.first.vertex == f.vertex && d.first.edge.polygon == f.edge.polygon && d.first.edge.ring == f.edge.ring &&
             d.first.edge.index == f.edge.index;
    });
    if (!seen) distinct.push_back({f, c.object_point});
    if (distinct.size() == 2) break;
  }
  if (distinct.size() < 2) return false;
  // Each contact variable to the feature nearer its current value.
  const Vec2 p1(v.p[0], v.p[1]), p2(v.p2[0], v.p2[1]);
  const bool swap = (p1 - distinct[1].second).norm() + (p2 - distinct[0].second).norm() <
                    (p1 - distinct[0].second).norm() + (p2 - distinct[1].second).norm();
  out[0] = distinct[swap ? 1 : 0].first;
  out[1] = distinct[swap ? 0 : 1].first;
  return true;
}

void GraphBuilder::InitializeSecondContact(int i, bool causal) {
  const auto& m = traj_.measured;
  Step& s = steps_[i];
  StepVars& v = vars_[i];
  const StepVars* prev = i > 0 && steps_[i - 1].two_contacts ? &vars_[i - 1] : nullptr;
  Vec2 a(v.p[0], v.p[1]), b = a;
  if (s.contact >= 0 && s.contact2 >= 0) {
    b = m.contact_point[s.contact2].point;
  } else {
    // The two rows of the nearest contact time (none at this step).
    int k = -1;
    NearestGap(m.contact_point, s.t, &k);
    const auto& c = m.contact_point;
    int first = k;
    while (first > 0 && c[first - 1].t == c[k].t) --first;
    if (!causal || c[first].t <= s.t) {
      a = c[first].point;
      b = first + 1 < static_cast<int>(c.size()) ? c[first + 1].point : a;
    } else if (prev != nullptr) {
      a = Vec2(prev->p[0], prev->p[1]);
      b = Vec2(prev->p2[0], prev->p2[1]);
    }
  }
  // Pair the rows with p and p2 as the previous step's (the sensor's row order may change).
  if (prev != nullptr) {
    const Vec2 p1(prev->p[0], prev->p[1]), p2(prev->p2[0], prev->p2[1]);
    if ((a - p2).norm() + (b - p1).norm() < (a - p1).norm() + (b - p2).norm()) {
      std::swap(a, b);
      if (s.contact >= 0 && s.contact2 >= 0) std::swap(s.contact, s.contact2);
    }
  }
  v.p[0] = a.x(); v.p[1] = a.y();
  v.p2[0] = b.x(); v.p2[1] = b.y();
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

int GraphBuilder::StageSteps(ceres::Problem& problem, int first, int last, int max_iterations,
                             double function_tolerance, const std::string& what) {
  int iterations = SmoothInitialMotion(10, 1e-3, first, last);
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
    iterations += Solve(warm, max_iterations, function_tolerance, (what + ", kinematics first").c_str()).iterations;
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
    if (s.in_contact) problem.AddParameterBlock(v.p, 2);
    if (HasSecondContact(i)) problem.AddParameterBlock(v.p2, 2);
    AddKinematicFactors(problem, i);
  }
  if ((parts & kDynamic) && HasForceVars(i)) {
    problem.AddParameterBlock(v.f, 2);
    if (HasSecondContact(i)) problem.AddParameterBlock(v.f2, 2);
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
    if (s.two_contacts) {
      // Two contacts: each point on the object's boundary and at its own wall's touching pair
      // (the shape-pair witness is the single nearest pair, one of the two: it would pull both
      // points onto the same wall).
      if (s.contact2 >= 0) {
        Add(problem, FactorType::kContactPoint, new VectorMeasurementFactor(m.contact_point[s.contact2].point, cfg_.measurement.contact),
            MakeLoss(cfg_.contact_loss), {v.p2});
      }
      Add(problem, FactorType::kContactOnObject, new BoundaryPointFactor(traj_.object.shape, cfg_.contact_object_sigma), nullptr,
          {v.x, v.p2}, {0});
      ContactFeature features[2];
      const bool on_features = TwoContactFeatures(i, features);
      double* points[2] = {v.p, v.p2};
      for (int k = 0; k < 2; ++k) {
        ceres::CostFunction* cost =
            on_features ? static_cast<ceres::CostFunction*>(new FeatureWitnessFactor(
                              traj_.object.shape, features[k].edge, features[k].vertex, traj_.finger.shape,
                              cfg_.contact_finger_sigma))
                        : new LocalWitnessFactor(traj_.object.shape, traj_.finger.shape, cfg_.contact_finger_sigma);
        Add(problem, FactorType::kContactOnFinger, cost, nullptr, {v.x, v.e, points[k]}, {0});
      }
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
    const bool two = s.two_contacts;
    if (s.force >= 0 && two) {
      // The finger's sensor measures the sum of its contacts' forces.
      Add(problem, FactorType::kForce, new VectorSumMeasurementFactor(m.force[s.force].force, cfg_.measurement.force),
          MakeLoss(cfg_.force_loss), {v.f, v.f2});
    } else if (s.force >= 0) {
      Add(problem, FactorType::kForce, new VectorMeasurementFactor(m.force[s.force].force, cfg_.measurement.force),
          MakeLoss(cfg_.force_loss), {v.f});
    }
    Add(problem, FactorType::kForcePrior, new VectorMeasurementFactor(Vec2::Zero(), cfg_.force_prior_sigma), nullptr, {v.f});
    if (two) {
      Add(problem, FactorType::kForcePrior, new VectorMeasurementFactor(Vec2::Zero(), cfg_.force_prior_sigma), nullptr, {v.f2});
      // Only the sum is measured: each force in its friction cone (sigma a tenth of the force
      // sensor's) keeps the split physical.
      for (const auto& [point, force] : {std::pair{v.p, v.f}, std::pair{v.p2, v.f2}})
        Add(problem, FactorType::kForcePrior,
            new FrictionConeFactor(traj_.object.shape, traj_.finger.mu_contact, 0.1 * cfg_.measurement.force), nullptr,
            {v.x, point, force}, {0});
    }
    if (i >= 1 && HasForceVars(i - 1)) {
      Add(problem, FactorType::kForceContinuity, new VectorRandomWalkFactor(s.t - steps_[i - 1].t, cfg_.force_random_walk),
          nullptr, {vars_[i - 1].f, v.f});
    }
    if (two && i >= 1 && HasForceVars(i - 1) && HasSecondContact(i - 1)) {
      Add(problem, FactorType::kForceContinuity, new VectorRandomWalkFactor(s.t - steps_[i - 1].t, cfg_.force_random_walk),
          nullptr, {vars_[i - 1].f2, v.f2});
    }
    if (i >= 1 && two) {
      // D and the load of both contacts' summed wrench (c and mu at their given values).
      QuasiStaticGeometry g = qs_;
      g.dt = s.t - steps_[i - 1].t;
      const double rate_scale = std::sqrt(0.01 / g.dt);  // per-10-ms sigmas (config.h)
      Add(problem, FactorType::kQuasiStatic,
          new QuasiStaticTwoContactFactor(g, cfg_.eps_velocity, cfg_.eps_force, cfg_.quasi_static_sigma * rate_scale),
          nullptr, {vars_[i - 1].x, v.x, v.p, v.f, v.p2, v.f2}, {0, 1});
      if (use_load_factor_) {
        Add(problem, FactorType::kLimitSurfaceLoad,
            new LimitSurfaceLoadTwoContactFactor(g, f_max_, cfg_.eps_velocity, cfg_.eps_force,
                                                 cfg_.limit_surface_sigma * rate_scale),
            nullptr, {vars_[i - 1].x, v.x, v.p, v.f, v.p2, v.f2}, {0, 1});
      }
    } else if (i >= 1) {
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
  if (HasSecondContact(i)) b.push_back(vars_[i].p2);
  if (HasSecondContact(i) && HasForceVars(i)) b.push_back(vars_[i].f2);
  return b;
}

void GraphBuilder::DropUnobservableForces(EstimationResult& result) const {
  if (second_contacts_ignored_ > 0)
    result.warnings.push_back("the Yu-Rodriguez baseline models one contact: the second contact of " +
                              std::to_string(second_contacts_ignored_) + " steps with two was left out");
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
  if (HasSecondContact(i) && st.contacts.size() == 2) {
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
  if (HasSecondContact(i)) {
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
