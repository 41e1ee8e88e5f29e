#include <pushgraph/io/result_json.h>
#include <pushgraph/io/trajectory_json.h>

#include <nlohmann/json.hpp>

#include <fstream>

namespace pushgraph::io {
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

}  // namespace

std::string ResultToJson(const graph::EstimationResult& r, int indent) {
  Json j;
  j["model"] = graph::ModelName(r.model);
  j["mode"] = graph::ModeName(r.mode);
  Json states = Json::array();
  for (const graph::StateEstimate& s : r.states) {
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
    states.push_back(std::move(o));
  }
  j["states"] = std::move(states);
  j["solver"] = {{"iterations", r.solver.iterations},
                 {"time_s", r.solver.time_s},
                 {"final_cost", r.solver.final_cost},
                 {"updates", r.solver.updates},
                 {"max_update_time_s", r.solver.max_update_time_s},
                 {"mean_update_time_s", r.solver.mean_update_time_s},
                 {"covariance", r.solver.covariance_status}};
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
  if (!parameters.empty()) j["parameters"] = std::move(parameters);
  if (!r.warnings.empty()) j["warnings"] = r.warnings;
  if (!r.metrics.empty()) {
    Json m = Json::object();
    for (const auto& [k, v] : r.metrics) m[k] = v;
    j["metrics"] = std::move(m);
  }
  return j.dump(indent);
}

void SaveResultJson(const graph::EstimationResult& result, const std::string& path) {
  const std::string text = ResultToJson(result);
  std::ofstream out(path);
  if (!out) throw IoError(path + ": cannot open file for writing");
  out << text << "\n";
  if (!out) throw IoError(path + ": write failed");
}

}  // namespace pushgraph::io
