#include <pushgraph/graph/config.h>

#include <pushgraph/geometry/json_check.h>
#include <pushgraph/graph/factors.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

namespace pushgraph::graph {
namespace {

using Json = nlohmann::json;

// The numeric keys and where they live (the measurement sigmas are the embedded
// push::MeasurementSigmas).
using DoubleField = double& (*)(EstimatorConfig&);
#define PUSHGRAPH_FIELD(path) [](EstimatorConfig& c) -> double& { return c.path; }

std::map<std::string, DoubleField> DoubleFields() {
  return {
      {"object_pose_sigma_trans", PUSHGRAPH_FIELD(measurement.object_trans)},
      {"object_pose_sigma_rot", PUSHGRAPH_FIELD(measurement.object_rot)},
      {"finger_pose_sigma_trans", PUSHGRAPH_FIELD(measurement.finger_trans)},
      {"finger_pose_sigma_rot", PUSHGRAPH_FIELD(measurement.finger_rot)},
      {"contact_sigma", PUSHGRAPH_FIELD(measurement.contact)},
      {"force_sigma", PUSHGRAPH_FIELD(measurement.force)},
      {"contact_object_sigma", PUSHGRAPH_FIELD(contact_object_sigma)},
      {"contact_finger_sigma", PUSHGRAPH_FIELD(contact_finger_sigma)},
      {"touching_sigma", PUSHGRAPH_FIELD(touching_sigma)},
      {"intersection_sigma", PUSHGRAPH_FIELD(intersection_sigma)},
      {"accel_trans", PUSHGRAPH_FIELD(accel_trans)},
      {"accel_rot", PUSHGRAPH_FIELD(accel_rot)},
      {"quasi_static_sigma", PUSHGRAPH_FIELD(quasi_static_sigma)},
      {"eps_velocity", PUSHGRAPH_FIELD(eps_velocity)},
      {"eps_force", PUSHGRAPH_FIELD(eps_force)},
      {"c", PUSHGRAPH_FIELD(c)},
      {"c_scale", PUSHGRAPH_FIELD(c_scale)},
      {"c_prior_sigma", PUSHGRAPH_FIELD(c_prior_sigma)},
      {"mu_prior_sigma", PUSHGRAPH_FIELD(mu_prior_sigma)},
      {"finger_angle_resolution", PUSHGRAPH_FIELD(finger_angle_resolution)},
      {"force_prior_sigma", PUSHGRAPH_FIELD(force_prior_sigma)},
      {"force_random_walk", PUSHGRAPH_FIELD(force_random_walk)},
      {"limit_surface_sigma", PUSHGRAPH_FIELD(limit_surface_sigma)},
      {"yu_quasi_static_sigma", PUSHGRAPH_FIELD(yu_quasi_static_sigma)},
      {"random_walk_trans", PUSHGRAPH_FIELD(random_walk_trans)},
      {"random_walk_rot", PUSHGRAPH_FIELD(random_walk_rot)},
      {"contact_max_gap", PUSHGRAPH_FIELD(contact_max_gap)},
      {"contact_force_threshold", PUSHGRAPH_FIELD(contact_force_threshold)},
      {"second_contact_tolerance", PUSHGRAPH_FIELD(second_contact_tolerance)},
      {"function_tolerance", PUSHGRAPH_FIELD(function_tolerance)},
  };
}
#undef PUSHGRAPH_FIELD

std::map<std::string, int EstimatorConfig::*> IntFields() {
  return {
      {"max_iterations", &EstimatorConfig::max_iterations},
      {"incremental_update_every", &EstimatorConfig::incremental_update_every},
      {"incremental_max_iterations", &EstimatorConfig::incremental_max_iterations},
  };
}

std::map<std::string, LossConfig EstimatorConfig::*> LossFields() {
  return {
      {"object_pose", &EstimatorConfig::object_pose_loss},
      {"finger_pose", &EstimatorConfig::finger_pose_loss},
      {"contact", &EstimatorConfig::contact_loss},
      {"force", &EstimatorConfig::force_loss},
  };
}

[[noreturn]] void Fail(const std::string& source, const std::string& key, const std::string& what) {
  throw GraphError(source + ": config key '" + key + "': " + what);
}

// A string-valued choice: the value's enum, or an error listing the allowed names.
template <class Enum>
Enum ParseChoice(const Json& value, const std::string& source, const std::string& key,
                 const std::vector<std::pair<std::string, Enum>>& choices) {
  if (value.is_string()) {
    for (const auto& [name, choice] : choices) {
      if (value.get<std::string>() == name) return choice;
    }
  }
  std::string allowed;
  for (std::size_t k = 0; k < choices.size(); ++k) {
    allowed += (k == 0 ? "" : k + 1 == choices.size() ? " or " : ", ") + ("\"" + choices[k].first + "\"");
  }
  Fail(source, key, "expected " + allowed + ", got " + value.dump());
}

LossConfig ParseLoss(const Json& j, const std::string& source, const std::string& key) {
  if (!j.is_object()) Fail(source, key, "expected an object {\"type\": ..., \"scale\": ...}");
  LossConfig loss;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "type") {
      if (!it->is_string()) Fail(source, key + ".type", "expected a string");
      const std::string t = it->get<std::string>();
      if (t == "none") loss.type = LossConfig::Type::kNone;
      else if (t == "huber") loss.type = LossConfig::Type::kHuber;
      else if (t == "cauchy") loss.type = LossConfig::Type::kCauchy;
      else Fail(source, key + ".type", "unknown loss '" + t + "' (none, huber, cauchy)");
    } else if (it.key() == "scale") {
      if (!it->is_number()) Fail(source, key + ".scale", "expected a number");
      loss.scale = it->get<double>();
    } else {
      Fail(source, key + "." + it.key(), "unknown key");
    }
  }
  return loss;
}

// nlohmann's get<int>() wraps silently (4294967297 -> 1); an integer key reads through this.
int GetInt(const Json& j, const std::string& source, const std::string& key) {
  if (!j.is_number_integer()) Fail(source, key, "expected an integer");
  const bool fits = j.is_number_unsigned()
                        ? j.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())
                        : j.get<std::int64_t>() >= std::numeric_limits<int>::min() &&
                              j.get<std::int64_t>() <= std::numeric_limits<int>::max();
  if (!fits) Fail(source, key, "integer " + j.dump() + " out of range (" + std::to_string(std::numeric_limits<int>::min()) +
                                   " to " + std::to_string(std::numeric_limits<int>::max()) + ")");
  return static_cast<int>(j.get<std::int64_t>());
}

void CheckPositive(double v, const std::string& key) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    std::ostringstream text;
    text << v;  // 6 significant digits: 1e-07, not 0.000000
    throw GraphError("config key '" + key + "' must be finite and > 0, got " + text.str());
  }
}

}  // namespace

EstimatorConfig ParseEstimatorConfig(const std::string& json_text, const std::string& source,
                                     const EstimatorConfig& base) {
  Json j;
  try {
    j = Json::parse(json_text);
  } catch (const Json::exception& e) {  // syntax errors, and numbers that overflow a double (1e999)
    throw GraphError(source + ": invalid JSON: " + geometry::JsonSyntaxErrorText(e.what(), json_text));
  }
  if (const std::string dup = geometry::FindDuplicateJsonKey(json_text); !dup.empty()) throw GraphError(source + ": " + dup);
  if (!j.is_object()) throw GraphError(source + ": the configuration must be a JSON object");
  EstimatorConfig cfg = base;
  const auto doubles = DoubleFields();
  const auto ints = IntFields();
  const auto losses = LossFields();
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    if (auto d = doubles.find(key); d != doubles.end()) {
      if (!it->is_number()) Fail(source, key, "expected a number");
      d->second(cfg) = it->get<double>();
    } else if (auto i = ints.find(key); i != ints.end()) {
      cfg.*(i->second) = GetInt(*it, source, key);
    } else if (key == "contact_finger") {
      cfg.contact_finger = ParseChoice<EstimatorConfig::ContactFinger>(
          *it, source, key, {{"witness", EstimatorConfig::ContactFinger::kWitness},
                             {"boundary", EstimatorConfig::ContactFinger::kBoundary}});
    } else if (key == "limit_surface_load") {
      cfg.limit_surface_load = ParseChoice<EstimatorConfig::LimitSurfaceLoad>(
          *it, source, key, {{"auto", EstimatorConfig::LimitSurfaceLoad::kAuto},
                             {"on", EstimatorConfig::LimitSurfaceLoad::kOn},
                             {"off", EstimatorConfig::LimitSurfaceLoad::kOff}});
    } else if (key == "solver") {
      cfg.solver = ParseChoice<EstimatorConfig::Solver>(
          *it, source, key, {{"chain", EstimatorConfig::Solver::kChain}, {"ceres", EstimatorConfig::Solver::kCeres}});
    } else if (key == "incremental_update_every_steps") {
      cfg.incremental_update_every_steps = GetInt(*it, source, key);
      if (cfg.incremental_update_every_steps < 1) Fail(source, key, "must be >= 1");
    } else if (key == "incremental_window") {
      cfg.incremental_window = GetInt(*it, source, key);
      if (cfg.incremental_window < 1) Fail(source, key, "must be >= 1 (leave it out for the default)");
    } else if (key == "incremental_window_steps") {
      cfg.incremental_window_steps = GetInt(*it, source, key);
      if (cfg.incremental_window_steps < 3) Fail(source, key, "must be >= 3 (the V factors span three steps)");
    } else if (key == "incremental_window_iterations") {
      cfg.incremental_window_iterations = GetInt(*it, source, key);
      if (cfg.incremental_window_iterations < 1) Fail(source, key, "must be >= 1");
    } else if (key == "covariance_method") {
      cfg.covariance_method = ParseChoice<EstimatorConfig::CovarianceMethod>(
          *it, source, key, {{"selected_inversion", EstimatorConfig::CovarianceMethod::kSelectedInversion},
                             {"ceres", EstimatorConfig::CovarianceMethod::kCeres}});
    } else if (key == "object_delay") {
      if (!it->is_number()) Fail(source, key, "expected a number (seconds)");
      cfg.object_delay = it->get<double>();
      if (!std::isfinite(cfg.object_delay) || std::abs(cfg.object_delay) > 10.0) Fail(source, key, "must be within +-10 s");
    } else if (key == "align_shape") {
      cfg.align_shape = ParseChoice<EstimatorConfig::AlignShape>(
          *it, source, key, {{"auto", EstimatorConfig::AlignShape::kAuto},
                             {"on", EstimatorConfig::AlignShape::kOn},
                             {"off", EstimatorConfig::AlignShape::kOff}});
    } else if (key == "covariance" || key == "estimate_c" || key == "estimate_mu" || key == "align_scale" ||
               key == "diagnostics" || key == "incremental_smoothing" || key == "tessellated_finger_as_disk") {
      if (!it->is_boolean()) Fail(source, key, "expected true or false");
      (key == "covariance"    ? cfg.covariance
       : key == "estimate_c"  ? cfg.estimate_c
       : key == "estimate_mu" ? cfg.estimate_mu
       : key == "diagnostics" ? cfg.diagnostics
       : key == "incremental_smoothing" ? cfg.incremental_smoothing
       : key == "tessellated_finger_as_disk" ? cfg.tessellated_finger_as_disk
                              : cfg.align_scale) = it->get<bool>();
    } else if (key == "losses") {
      if (!it->is_object()) Fail(source, key, "expected an object");
      for (auto l = it->begin(); l != it->end(); ++l) {
        auto f = losses.find(l.key());
        if (f == losses.end()) {
          Fail(source, "losses." + l.key(), "unknown measurement (object_pose, finger_pose, contact, force)");
        }
        cfg.*(f->second) = ParseLoss(*l, source, "losses." + l.key());
      }
    } else {
      Fail(source, key, "unknown key (see docs/estimation.md)");
    }
  }
  try {
    ValidateConfig(cfg);
  } catch (const GraphError& e) {
    throw GraphError(source + ": " + e.what());
  }
  return cfg;
}

EstimatorConfig LoadEstimatorConfig(const std::string& path, const EstimatorConfig& base) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw GraphError(path + ": is a directory, not a config file");
  std::ifstream in(path);
  if (!in) throw GraphError("cannot open config file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseEstimatorConfig(ss.str(), path, base);
}

// Noise scales outside these are no measurement (a picometre, a piconewton; 1e12 of either).
constexpr double kMinNoiseScale = 1e-12, kMaxNoiseScale = 1e12;

EstimatorConfig ApplyMeasurementSigmas(EstimatorConfig cfg, const push::MeasurementSigmas& s) {
  auto floor_at = [](double sigma, double least, const char* what) {
    if (!std::isfinite(sigma) || sigma < 0.0) {
      throw GraphError(std::string("measurement_sigmas.") + what + " must be finite and >= 0");
    }
    if (sigma > kMaxNoiseScale) {  // named here, not as a config key in ValidateConfig
      std::ostringstream text;
      text << sigma;
      throw GraphError(std::string("measurement_sigmas.") + what + " must be at most 1e12, got " + text.str());
    }
    return std::max(sigma, least);
  };
  push::MeasurementSigmas& m = cfg.measurement;
  m.object_trans = floor_at(s.object_trans, 1e-4, "object_pose (translation)");
  m.object_rot = floor_at(s.object_rot, 1e-3, "object_pose (rotation)");
  m.finger_trans = floor_at(s.finger_trans, 1e-4, "finger_pose (translation)");
  m.finger_rot = floor_at(s.finger_rot, 1e-3, "finger_pose (rotation)");
  m.contact = floor_at(s.contact, 1e-4, "contact_point");
  m.force = floor_at(s.force, 1e-3, "force");
  return cfg;
}

void ValidateConfig(const EstimatorConfig& cfg) {
  EstimatorConfig copy = cfg;  // the field accessors take a mutable config
  for (const auto& [key, field] : DoubleFields()) {
    const double v = field(copy);
    if (key == "c" || key == "finger_angle_resolution" || key == "second_contact_tolerance") {
      if (!(v >= 0.0) || !std::isfinite(v)) {
        throw GraphError("config key '" + key + "' must be finite and >= 0");
      }
    } else {
      CheckPositive(v, key);
    }
    // A noise scale weighs its factor by 1/sigma^2: 1e-320 passed "> 0" and failed inside the
    // solver naming a factor, not the key (1/sigma overflows); 1e-300 overflowed the covariances.
    const bool noise_scale = key.find("sigma") != std::string::npos || key.rfind("accel_", 0) == 0 ||
                             key.find("random_walk") != std::string::npos;
    if (noise_scale && !(v >= kMinNoiseScale && v <= kMaxNoiseScale)) {
      std::ostringstream text;
      text << v;
      throw GraphError("config key '" + key + "' is a noise scale (in its own units): must be within [1e-12, 1e12], got " +
                       text.str());
    }
  }
  for (const auto& [key, member] : LossFields()) CheckPositive((cfg.*member).scale, "losses." + key + ".scale");
  for (const auto& [key, member] : IntFields()) {
    if (cfg.*member < 1) throw GraphError("config key '" + key + "' must be >= 1");
  }
  if (!(std::isfinite(cfg.object_delay) && std::abs(cfg.object_delay) <= 10.0)) {
    throw GraphError("config key 'object_delay' must be a delay in seconds within +-10");
  }
  if (cfg.incremental_update_every_steps < 0) {
    throw GraphError("config key 'incremental_update_every_steps' must be >= 1 (0: unset)");
  }
  if (cfg.incremental_window_iterations < 0) {
    throw GraphError("config key 'incremental_window_iterations' must be >= 1 (0: unset)");
  }
  if (cfg.incremental_window_steps != 0 && cfg.incremental_window_steps < 3) {
    throw GraphError("config key 'incremental_window_steps' must be >= 3 (0: unset)");
  }
  if (cfg.incremental_window < 0) throw GraphError("config key 'incremental_window' must be >= 1 (0: unset)");
  if (cfg.incremental_window > 0 && cfg.incremental_window < cfg.incremental_update_every) {
    // Name both values: the user may have set only one (incremental_window 2 against the default
    // update every 5 was refused naming a key that was not in the file).
    throw GraphError("config: incremental_window (" + std::to_string(cfg.incremental_window) +
                     " object periods) must be >= incremental_update_every (" + std::to_string(cfg.incremental_update_every) +
                     "; its default is 5): the window must hold the samples of one update; lower incremental_update_every "
                     "with it, or leave incremental_window unset");
  }
}

}  // namespace pushgraph::graph
