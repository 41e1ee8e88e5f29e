#include <pushgraph/geometry/file_output.h>
#include <pushgraph/evaluation/result_json.h>
#include <pushgraph/io/trajectory_json.h>

#include <nlohmann/json.hpp>

#include "internal.h"

#include <fstream>

namespace pushgraph::evaluation {
namespace {

using Json = nlohmann::json;

template <class M>
Json Matrix(const M& m) {
  Json rows = Json::array();
  for (int i = 0; i < m.rows(); ++i) {
    Json row = Json::array();
    for (int j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

Json Pose(const geometry::Pose2& p) { return Json::array({p.x, p.y, p.theta}); }
Json Vec(const geometry::Vec2& v) { return Json::array({v.x(), v.y()}); }

// Fingers 1, 2, ...: their measured contact gaps, as finger 0's "measured_contact_gap".
Json OtherFingerGaps(const graph::Diagnostics& d) {
  Json out = Json::array();
  for (std::size_t k = 0; k < d.other_finger_gaps.size(); ++k) {
    const graph::MeasuredContactGap& g = d.other_finger_gaps[k];
    out.push_back({{"finger", k + 1}, {"median", g.median}, {"mad", g.mad}, {"samples", g.samples}});
  }
  return out;
}

}  // namespace

namespace {

Json ResultJson(const graph::EstimationResult& r, bool with_states) {
  Json j;
  j["model"] = graph::ModelName(r.model);
  j["mode"] = graph::ModeName(r.mode);
  Json states = Json::array();
  const std::vector<graph::StateEstimate> none;
  for (const graph::StateEstimate& s : with_states ? r.states : none) {
    Json o;
    o["t"] = s.t;
    o["object_pose"] = Pose(s.object_pose);
    o["finger_pose"] = Pose(s.finger_pose);
    if (s.contact) o["contact"] = Vec(*s.contact);
    if (s.force) o["force"] = Vec(*s.force);
    if (s.object_pose_cov) o["object_pose_cov"] = Matrix(*s.object_pose_cov);
    if (s.finger_pose_cov) o["finger_pose_cov"] = Matrix(*s.finger_pose_cov);
    if (s.contact_cov) o["contact_cov"] = Matrix(*s.contact_cov);
    if (s.force_cov) o["force_cov"] = Matrix(*s.force_cov);
    if (!s.other_fingers.empty()) {
      // Two-finger pushes: every finger's pose beside finger 0's ("finger_pose").
      Json fingers = Json::array();
      for (const graph::FingerPoseEstimate& f : s.other_fingers) {
        Json e;
        e["finger"] = f.finger;
        e["pose"] = Pose(f.pose);
        if (f.pose_cov) e["pose_cov"] = Matrix(*f.pose_cov);
        fingers.push_back(std::move(e));
      }
      o["fingers"] = std::move(fingers);
    }
    if (!s.contacts.empty()) {
      // Two contacts of finger 0: each with its point, force and covariances ("force" above is
      // their sum); several fingers: every contact, with its finger ("force" is finger 0's own).
      Json contacts = Json::array();
      for (const graph::ContactEstimate& c : s.contacts) {
        Json e;
        e["finger"] = c.finger;
        e["point"] = Vec(c.point);
        if (c.force) e["force"] = Vec(*c.force);
        if (c.point_cov) e["point_cov"] = Matrix(*c.point_cov);
        if (c.force_cov) e["force_cov"] = Matrix(*c.force_cov);
        contacts.push_back(std::move(e));
      }
      o["contacts"] = std::move(contacts);
    }
    states.push_back(std::move(o));
  }
  if (with_states) j["states"] = std::move(states);
  j["solver"] = {{"iterations", r.solver.iterations},
                 {"time_s", r.solver.time_s},
                 {"total_time_s", r.solver.total_time_s},
                 {"final_cost", r.solver.final_cost},
                 {"updates", r.solver.updates},
                 {"max_update_time_s", r.solver.max_update_time_s},
                 {"mean_update_time_s", r.solver.mean_update_time_s},
                 {"name", r.solver.name},
                 {"covariance", r.solver.covariance_status}};
  if (r.mode == graph::Mode::kIncremental) j["solver"]["update_times_s"] = r.solver.update_times_s;
  // The model's shared parameters: c (QS, baseline) and the load factor's mu, estimated or not.
  nlohmann::json parameters = nlohmann::json::object();
  if (r.c) {
    parameters["c"] = *r.c;
    parameters["c_estimated"] = r.c_estimated;
    if (r.c_sigma) parameters["c_sigma"] = *r.c_sigma;
    if (r.c_at_bound) parameters["c_at_bound"] = true;
  }
  if (r.mu) {
    parameters["mu"] = *r.mu;
    parameters["mu_estimated"] = r.mu_estimated;
    if (r.mu_sigma) parameters["mu_sigma"] = *r.mu_sigma;
    if (r.mu_at_bound) parameters["mu_at_bound"] = true;
  }
  if (r.finger_scale != 1.0) parameters["finger_scale"] = r.finger_scale;
  if (r.object_delay != 0.0) parameters["object_delay"] = r.object_delay;
  if (!r.finger_shift.isZero(0.0)) parameters["finger_transform"] = {r.finger_shift.x(), r.finger_shift.y(), 0.0};
  if (r.shape_alignment) {
    const graph::ShapeAlignment& a = *r.shape_alignment;
    // The shape check and, when aligned, the transform used (shape file -> object frame).
    Json shape = Json::object();
    shape["checked"] = a.checked;
    if (a.checked) {
      shape["fits_as_given"] = a.check.fits;
      shape["gap_median"] = a.check.gap_median;
      shape["penetration_share"] = a.check.penetration_share;
      shape["tolerance"] = a.check.tolerance;
      shape["samples"] = a.check.samples;
    }
    shape["aligned"] = a.aligned;
    if (a.suggested) {
      Json t = {a.transform.pose.x, a.transform.pose.y, a.transform.pose.theta};
      Json sigma = {a.sigma.x(), a.sigma.y(), a.rotation_observable ? Json(a.sigma.z()) : Json(nullptr)};
      if (a.units_only) sigma = nullptr;  // no placement fitted: the file's own frame at the units found
      shape["units_only"] = a.units_only;
      // Unsettled, the curvature's sigmas cover the chosen placement alone: kept apart from the
      // transform's sigma, which is then null.
      shape["placement_settled"] = a.settled;
      if (!a.settled) {
        shape["placement_unsettled_by"] = a.unsettled_by;
        if (!a.units_only) shape["local_transform_sigma"] = sigma;
        sigma = nullptr;
      }
      if (a.aligned) {
        parameters["shape_transform"] = t;
        parameters["shape_transform_sigma"] = sigma;
        parameters["shape_scale"] = a.transform.scale;
        parameters["shape_mirrored"] = a.transform.mirrored;
      } else {
        shape["suggested_transform"] = t;
        shape["suggested_transform_sigma"] = sigma;
        shape["suggested_scale"] = a.transform.scale;
        shape["suggested_mirrored"] = a.transform.mirrored;
      }
      shape["rotation_observable"] = a.rotation_observable;
      if (!a.ties.empty()) {
        Json ties = Json::array();
        for (const graph::ShapeTransform& t : a.ties) ties.push_back({t.pose.x, t.pose.y, t.pose.theta});
        shape["tied_transforms"] = ties;
      }
      shape["refined_in_graph"] = a.refined;
    }
    if (a.finger_radius) parameters["finger_radius"] = *a.finger_radius;
    if (!a.notes.empty()) shape["notes"] = a.notes;
    j["shape"] = std::move(shape);
  }
  if (r.diagnostics) {
    const graph::Diagnostics& d = *r.diagnostics;
    Json factors = Json::object();
    for (const graph::FactorStatistics& f : d.factors) {
      factors[f.type] = {{"count", f.count},   {"dof", f.dof},      {"chi2", f.chi2},        {"expected", f.expected},
                         {"ratio", f.Ratio()}, {"worst", f.worst}, {"worst_t", f.worst_t}};
    }
    Json faults = Json::array();
    for (const graph::SensorFault& f : d.faults) faults.push_back({{"stream", f.stream}, {"kind", f.kind}, {"detail", f.detail}});
    j["diagnostics"] = {{"factors", std::move(factors)},
                        {"expected_from_covariance", d.expected_from_covariance},
                        {"score", d.score},
                        {"worst_factor", d.worst_factor},
                        {"contact_steps", d.contact_steps},
                        {"contact_gap", {{"median", d.gap_median}, {"rms", d.gap_rms}, {"p95", d.gap_p95}}},
                        {"penetration_share", d.penetration_share},
                        {"penetration_tolerance", d.penetration_tolerance},
                        {"measured_contact_gap",
                         {{"median", d.measured_gap_median}, {"mad", d.measured_gap_mad}, {"samples", d.measured_samples}}},
                        {"measured_contact_gap_other_fingers", OtherFingerGaps(d)},
                        {"sensor_faults", std::move(faults)},
                        {"causes", d.causes}};
  }
  if (!parameters.empty()) j["parameters"] = std::move(parameters);
  if (!r.warnings.empty()) j["warnings"] = r.warnings;
  if (!r.metrics.empty()) {
    Json m = Json::object();
    for (const auto& [k, v] : r.metrics) m[k] = v;
    j["metrics"] = std::move(m);
  }
  return j;
}

}  // namespace

std::string ResultToJson(const graph::EstimationResult& r, int indent) {
  return internal::DumpJson(ResultJson(r, true), indent);  // warnings quote file names, which need not be UTF-8
}

std::string ResultSummaryJson(const graph::EstimationResult& r, int indent) {
  return internal::DumpJson(ResultJson(r, false), indent);
}

void SaveResultJson(const graph::EstimationResult& result, const std::string& path) {
  if (const std::string error = geometry::WriteFileAtomically(path, ResultToJson(result) + "\n"); !error.empty())
    throw EvaluationError(error);
}

}  // namespace pushgraph::evaluation
