// The evaluation config file (config.h).
#include <pushgraph/evaluation/config.h>
#include <pushgraph/geometry/json_check.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/io/footprint.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace pushgraph::evaluation {
namespace {

namespace fs = std::filesystem;

// A shape in the config: "shape.json", or {"mesh": "x.obj", "up": "z", "scale": 1}. The readers'
// errors (GeometryError, IoError) get the config's place in front.
geometry::Shape ConfigShape(const nlohmann::json& j, const fs::path& base, const std::string& where) {
  auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? p : (base / p).string(); };
  auto named = [&](auto&& read) {
    try {
      return read();
    } catch (const nlohmann::json::exception&) {
      throw;  // a wrong value type: LoadEvaluationConfig names the file
    } catch (const std::exception& e) {
      throw EvaluationError(where + ": " + e.what());
    }
  };
  if (j.is_string()) return named([&] { return geometry::LoadShapeJson(resolve(j.get<std::string>())); });
  if (!j.is_object() || !j.contains("mesh"))
    throw EvaluationError(where + ": expected a shape file name or {\"mesh\": FILE.obj, \"up\": \"z\", \"scale\": 1}");
  for (const auto& [k, v] : j.items()) {
    if (k != "mesh" && k != "up" && k != "scale") throw EvaluationError(where + ": unknown key '" + k + "' (mesh, up, scale)");
  }
  return named([&] {
    io::FootprintOptions o;
    if (j.contains("up")) o.up = io::ParseUpAxis(j["up"].get<std::string>());
    if (j.contains("scale")) o.scale = j["scale"].get<double>();
    return io::MeshFootprint(resolve(j["mesh"].get<std::string>()), o);
  });
}

}  // namespace

void LoadEvaluationConfig(const std::string& path, EvaluationOptions* options) {
  std::ifstream in(path);
  if (!in) throw EvaluationError("--config " + path + ": cannot open file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw EvaluationError("--config " + path + ": malformed JSON: " + e.what());
  }
  if (const std::string dup = geometry::FindDuplicateJsonKey(text); !dup.empty())
    throw EvaluationError("--config " + path + ": " + dup);
  if (!j.is_object()) throw EvaluationError("--config " + path + ": expected a JSON object");
  const fs::path base = fs::path(path).parent_path();
  try {
    for (const auto& [key, value] : j.items()) {
      if (key == "mesh_dir") {
        const std::string d = value.get<std::string>();
        options->mesh_dir = fs::path(d).is_absolute() ? d : (base / d).string();
      } else if (key == "estimator") {
        options->estimator = graph::ParseEstimatorConfig(value.dump(), path + " (estimator)");
      } else if (key == "objects") {
        for (const auto& [name, o] : value.items()) {
          const std::string where = path + ": objects." + name;
          ObjectModel m;
          for (const auto& [k, v] : o.items()) {
            if (k == "shape") m.object.shape = ConfigShape(v, base, where + ".shape");
            else if (k == "finger") m.finger.shape = ConfigShape(v, base, where + ".finger");
            else if (k == "mass") m.object.mass = v.get<double>();
            else if (k == "mu_surface") m.object.mu_surface = v.get<double>();
            else if (k == "mu_contact") m.finger.mu_contact = v.get<double>();
            else throw EvaluationError(where + ": unknown key '" + k + "' (shape, finger, mass, mu_surface, mu_contact)");
          }
          if (m.object.shape.empty() || m.finger.shape.empty())
            throw EvaluationError(where + ": needs both 'shape' and 'finger'");
          if (!(m.object.mass > 0.0) || !std::isfinite(m.object.mass))
            throw EvaluationError(where + ".mass must be a number > 0");
          if (!(m.object.mu_surface >= 0.0) || !(m.finger.mu_contact >= 0.0))
            throw EvaluationError(where + ": friction must be >= 0");
          options->objects[name] = m;
        }
      } else {
        throw EvaluationError(path + ": unknown key '" + key + "' (mesh_dir, estimator, objects)");
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw EvaluationError(path + ": " + e.what());
  }
}

}  // namespace pushgraph::evaluation
