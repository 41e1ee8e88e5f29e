// Reading and writing "pushgraph-trajectory-1" JSON files. Every problem is reported with the
// file name and the JSON path of the offending value.
#include <pushgraph/geometry/file_output.h>
#include <pushgraph/io/trajectory_json.h>

#include <pushgraph/geometry/json_check.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pushgraph::io {
namespace {

using json = nlohmann::json;
using push::ForceSample;
using push::PointSample;
using push::PoseSample;
using push::Streams;
using push::Trajectory;

class Reader {
 public:
  explicit Reader(std::string source, std::vector<std::string>* notes = nullptr)
      : source_(std::move(source)), notes_(notes) {}

  [[noreturn]] void Fail(const std::string& path, const std::string& what) const {
    throw IoError(source_ + ": " + path + ": " + what);
  }

  void CheckKeys(const json& object, std::initializer_list<const char*> allowed, const std::string& path) const {
    if (!object.is_object()) Fail(path, "must be an object");
    for (auto it = object.begin(); it != object.end(); ++it) {
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; }))
        Fail(path, "unknown field \"" + it.key() + "\"");
    }
  }

  const json& Require(const json& object, const char* key, const std::string& path) const {
    if (!object.contains(key)) Fail(path, std::string("missing field \"") + key + "\"");
    return object[key];
  }

  double Number(const json& value, const std::string& path) const {
    if (!value.is_number()) Fail(path, "must be a number, got " + value.dump());
    const double v = value.get<double>();
    if (!std::isfinite(v)) Fail(path, "must be finite");
    return v;
  }

  double NonNegative(const json& value, const std::string& path) const {
    const double v = Number(value, path);
    if (v < 0.0) Fail(path, "must be >= 0, got " + Text(v));
    return v;
  }

  static std::string Text(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  }

  geometry::Shape ShapeOf(const json& value, const std::string& path) const {
    try {
      return geometry::ParseShapeJson(value.dump(), source_ + ": " + path);
    } catch (const geometry::GeometryError& e) {
      throw IoError(e.what());
    }
  }

  // Rows [t, v1, ..., vn]; sorted by time (stable), duplicates rejected.
  template <typename Sample, typename Make>
  std::vector<Sample> Rows(const json& value, std::size_t width, const std::string& path, Make make) const {
    if (!value.is_array()) Fail(path, "must be an array of rows");
    std::vector<Sample> out;
    out.reserve(value.size());
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string row_path = path + "[" + std::to_string(i) + "]";
      const json& row = value[i];
      if (!row.is_array() || row.size() != width)
        Fail(row_path, "must be a row of " + std::to_string(width) + " numbers, got " + row.dump());
      std::vector<double> v(width);
      for (std::size_t k = 0; k < width; ++k) v[k] = Number(row[k], row_path + "[" + std::to_string(k) + "]");
      out.push_back(make(v));  // out[i] is row [i] of the file
    }
    if (notes_ != nullptr) {
      std::size_t late = 0, first = 0;
      double latest = out.empty() ? 0.0 : out[0].t;
      for (std::size_t i = 1; i < out.size(); ++i) {
        if (out[i].t < latest && late++ == 0) first = i;  // after a later stamp
        latest = std::max(latest, out[i].t);
      }
      if (late > 0) {
        notes_->push_back(path + ": sorted " + std::to_string(late) + " row(s) that came after a later time stamp (first: row [" +
                          std::to_string(first) + "])");
      }
    }
    std::vector<std::size_t> order(out.size());  // rows in time order
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return out[a].t < out[b].t; });
    std::vector<Sample> sorted;
    sorted.reserve(out.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      if (i > 0 && out[order[i]].t == out[order[i - 1]].t) {
        std::ostringstream o;
        o.precision(17);
        o << "rows [" << order[i - 1] << "] and [" << order[i] << "] have the same time stamp "
          << out[order[i]].t;
        Fail(path, o.str());
      }
      sorted.push_back(out[order[i]]);
    }
    return sorted;
  }

  Streams StreamsOf(const json& value, const std::string& path) const {
    CheckKeys(value, {"object_pose", "finger_pose", "contact_point", "force"}, path);
    Streams s;
    auto pose = [](const std::vector<double>& v) { return PoseSample{v[0], {v[1], v[2], v[3]}}; };
    if (value.contains("object_pose")) s.object_pose = Rows<PoseSample>(value["object_pose"], 4, path + ".object_pose", pose);
    if (value.contains("finger_pose")) s.finger_pose = Rows<PoseSample>(value["finger_pose"], 4, path + ".finger_pose", pose);
    if (value.contains("contact_point"))
      s.contact_point = Rows<PointSample>(value["contact_point"], 3, path + ".contact_point",
                                          [](const std::vector<double>& v) { return PointSample{v[0], {v[1], v[2]}}; });
    if (value.contains("force"))
      s.force = Rows<ForceSample>(value["force"], 3, path + ".force",
                                  [](const std::vector<double>& v) { return ForceSample{v[0], {v[1], v[2]}}; });
    return s;
  }

  // {"object_pose": [trans, rot], "finger_pose": [trans, rot], "contact_point": s, "force": s}
  push::MeasurementSigmas SigmasOf(const json& value, const std::string& path) const {
    CheckKeys(value, {"object_pose", "finger_pose", "contact_point", "force"}, path);
    push::MeasurementSigmas s;
    auto pair = [&](const char* key, double* trans, double* rot) {
      if (!value.contains(key)) return;
      const json& v = value[key];
      const std::string p = path + "." + key;
      if (!v.is_array() || v.size() != 2) Fail(p, "must be [sigma_trans, sigma_rot], got " + v.dump());
      *trans = NonNegative(v[0], p + "[0]");
      *rot = NonNegative(v[1], p + "[1]");
    };
    pair("object_pose", &s.object_trans, &s.object_rot);
    pair("finger_pose", &s.finger_trans, &s.finger_rot);
    if (value.contains("contact_point")) s.contact = NonNegative(value["contact_point"], path + ".contact_point");
    if (value.contains("force")) s.force = NonNegative(value["force"], path + ".force");
    return s;
  }

 private:
  std::string source_;
  std::vector<std::string>* notes_ = nullptr;
};

json ShapeJson(const geometry::Shape& shape) { return json::parse(geometry::ShapeToJson(shape, -1)); }

json SigmasJson(const push::MeasurementSigmas& s) {
  return {{"object_pose", {s.object_trans, s.object_rot}},
          {"finger_pose", {s.finger_trans, s.finger_rot}},
          {"contact_point", s.contact},
          {"force", s.force}};
}

json StreamsJson(const Streams& s) {
  json out = json::object();
  json op = json::array(), fp = json::array(), cp = json::array(), f = json::array();
  for (const PoseSample& p : s.object_pose) op.push_back({p.t, p.pose.x, p.pose.y, p.pose.theta});
  for (const PoseSample& p : s.finger_pose) fp.push_back({p.t, p.pose.x, p.pose.y, p.pose.theta});
  for (const PointSample& p : s.contact_point) cp.push_back({p.t, p.point.x(), p.point.y()});
  for (const ForceSample& p : s.force) f.push_back({p.t, p.force.x(), p.force.y()});
  out["object_pose"] = op;
  out["finger_pose"] = fp;
  out["contact_point"] = cp;
  out["force"] = f;
  return out;
}

}  // namespace

Trajectory ParseTrajectoryJson(const std::string& text, const std::string& source, std::vector<std::string>* notes) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(source + ": malformed JSON: " + e.what());
  }
  if (const std::string dup = geometry::FindDuplicateJsonKey(text); !dup.empty()) throw IoError(source + ": " + dup);
  const Reader r(source, notes);
  r.CheckKeys(doc, {"format", "object", "finger", "streams", "ground_truth", "measurement_sigmas"}, "top level");
  const json& format = r.Require(doc, "format", "top level");
  if (!format.is_string() || format.get<std::string>() != kTrajectoryFormat)
    r.Fail("format", std::string("expected \"") + kTrajectoryFormat + "\", got " + format.dump());

  Trajectory t;
  const json& object = r.Require(doc, "object", "top level");
  r.CheckKeys(object, {"shape", "mass", "mu_surface", "pressure"}, "object");
  t.object.shape = r.ShapeOf(r.Require(object, "shape", "object"), "object.shape");
  t.object.mass = r.Number(r.Require(object, "mass", "object"), "object.mass");
  if (!(t.object.mass > 0.0)) r.Fail("object.mass", "must be > 0 (kg), got " + r.Text(t.object.mass));
  t.object.mu_surface = r.NonNegative(r.Require(object, "mu_surface", "object"), "object.mu_surface");
  if (object.contains("pressure")) {
    if (!object["pressure"].is_string() || object["pressure"].get<std::string>() != "uniform")
      r.Fail("object.pressure", "only \"uniform\" is supported in trajectory files, got " + object["pressure"].dump());
  }
  const json& finger = r.Require(doc, "finger", "top level");
  r.CheckKeys(finger, {"shape", "mu_contact"}, "finger");
  t.finger.shape = r.ShapeOf(r.Require(finger, "shape", "finger"), "finger.shape");
  t.finger.mu_contact = r.NonNegative(r.Require(finger, "mu_contact", "finger"), "finger.mu_contact");
  if (doc.contains("streams")) t.measured = r.StreamsOf(doc["streams"], "streams");
  if (doc.contains("ground_truth")) t.ground_truth = r.StreamsOf(doc["ground_truth"], "ground_truth");
  if (doc.contains("measurement_sigmas"))
    t.measurement_sigmas = r.SigmasOf(doc["measurement_sigmas"], "measurement_sigmas");
  return t;
}

Trajectory LoadTrajectoryJson(const std::string& path, std::vector<std::string>* notes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, not a trajectory file");
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseTrajectoryJson(buffer.str(), path, notes);
}

// One stream row per line: readable, diff-friendly and still plain JSON.
std::string TrajectoryToJson(const Trajectory& t, int indent) {
  // The format holds what the estimator reads: uniform pressure under standard gravity.
  if (t.object.pressure.kind != limit_surface::PressureKind::kUniform)
    throw IoError("trajectory JSON: object.pressure must be uniform (the format has no other)");
  if (t.object.gravity != limit_surface::kStandardGravity)
    throw IoError("trajectory JSON: object.gravity must be the standard 9.80665 m/s^2 (the format has no field for it)");
  json object = {{"shape", ShapeJson(t.object.shape)},
                 {"mass", t.object.mass},
                 {"mu_surface", t.object.mu_surface},
                 {"pressure", "uniform"}};
  json finger = {{"shape", ShapeJson(t.finger.shape)}, {"mu_contact", t.finger.mu_contact}};
  if (indent < 0) {
    json doc = {{"format", kTrajectoryFormat}, {"object", object}, {"finger", finger}, {"streams", StreamsJson(t.measured)}};
    if (t.ground_truth) doc["ground_truth"] = StreamsJson(*t.ground_truth);
    if (t.measurement_sigmas) doc["measurement_sigmas"] = SigmasJson(*t.measurement_sigmas);
    return doc.dump();
  }
  auto streams = [](const Streams& s) {
    const json j = StreamsJson(s);
    std::string out = "{";
    bool first_stream = true;
    for (const char* key : {"object_pose", "finger_pose", "contact_point", "force"}) {
      out += std::string(first_stream ? "\n" : ",\n") + "  \"" + key + "\": [";
      first_stream = false;
      const json& rows = j[key];
      for (std::size_t i = 0; i < rows.size(); ++i) out += std::string(i == 0 ? "\n    " : ",\n    ") + rows[i].dump();
      out += rows.empty() ? "]" : "\n  ]";
    }
    return out + "\n }";
  };
  std::string out = "{\"format\": \"" + std::string(kTrajectoryFormat) + "\",\n \"object\": " + object.dump() +
                    ",\n \"finger\": " + finger.dump() + ",\n \"streams\": " + streams(t.measured);
  if (t.ground_truth) out += ",\n \"ground_truth\": " + streams(*t.ground_truth);
  if (t.measurement_sigmas) out += ",\n \"measurement_sigmas\": " + SigmasJson(*t.measurement_sigmas).dump();
  return out + "}";
}

void SaveTrajectoryJson(const Trajectory& t, const std::string& path) {
  if (const std::string error = geometry::WriteFileAtomically(path, TrajectoryToJson(t) + "\n"); !error.empty())
    throw IoError(error);
}

}  // namespace pushgraph::io
