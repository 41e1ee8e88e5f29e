// Reading and writing "pushgraph-trajectory-1" JSON files. Every problem is reported with the
// file name and the JSON path of the offending value.
#include <pushgraph/geometry/file_output.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/limit_surface/support.h>

#include <pushgraph/geometry/json_check.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>

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

  // A friction coefficient: [0, 10], the command line's range (mu_surface 50 in a file ran, the
  // forces of a push without a force stream sized by it to 157 N against a true 1.5 N).
  double Friction(const json& value, const std::string& path) const {
    const double v = NonNegative(value, path);
    if (v > 10.0)
      Fail(path, "must be at most 10 (a friction coefficient: rubber on rubber is about 1; the command line's --mu "
                 "takes [0, 10]), got " + Text(v));
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

  // Rows [t, v1, ..., vn], or [t, i, v1, ..., vn] with a finger index i when `fingers` > 1: one
  // time-sorted (stable) list per finger; a repeated time is an error unless `repeats` (several
  // contacts of one finger at once).
  template <typename Sample, typename Make>
  std::vector<std::vector<Sample>> Rows(const json& value, std::size_t width, const std::string& path, Make make,
                                        int fingers = 1, bool repeats = false) const {
    if (!value.is_array()) Fail(path, "must be an array of rows");
    const bool indexed = fingers > 1;
    const std::size_t row_width = width + (indexed ? 1 : 0);
    std::vector<std::vector<Sample>> out(static_cast<std::size_t>(fingers));
    std::vector<std::vector<std::size_t>> row_of(out.size());  // file row of each sample
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string row_path = path + "[" + std::to_string(i) + "]";
      const json& row = value[i];
      if (!row.is_array() || row.size() != row_width)
        Fail(row_path, "must be a row of " + std::to_string(row_width) + " numbers" +
                           (indexed ? " [t, finger, ...]" : "") + ", got " + row.dump() +
                           (!indexed && row.is_array() && row.size() == row_width + 1 &&
                                    path.find("object_pose") == std::string::npos
                                ? " (with one finger the rows carry no finger index)"
                                : ""));
      std::vector<double> v;
      v.reserve(width);
      std::size_t finger = 0;
      for (std::size_t k = 0; k < row_width; ++k) {
        const double x = Number(row[k], row_path + "[" + std::to_string(k) + "]");
        if (indexed && k == 1) {
          if (x != std::floor(x) || x < 0.0 || x >= fingers)
            Fail(row_path + "[1]", "finger index " + Text(x) + " is not one of the " + std::to_string(fingers) +
                                       " fingers (0 to " + std::to_string(fingers - 1) + ")");
          finger = static_cast<std::size_t>(x);
        } else {
          v.push_back(x);
        }
      }
      out[finger].push_back(make(v));
      row_of[finger].push_back(i);
    }
    for (std::size_t f = 0; f < out.size(); ++f) out[f] = Sorted(std::move(out[f]), row_of[f], path, repeats, indexed ? static_cast<int>(f) : -1);
    return out;
  }

  template <typename Sample>
  std::vector<Sample> Sorted(std::vector<Sample> rows, std::vector<std::size_t> row_of, const std::string& path,
                             bool repeats, int finger) const {
    const std::string whose = finger >= 0 ? " of finger " + std::to_string(finger) : "";
    // A stream logged newest first (its last row before its first, and nine in ten steps between
    // rows going back) is one push read backwards: reversed, and said so (it was refused as "two
    // recordings joined"); rows still out of order after that are sorted below, as in any stream
    // (one swapped pair had the whole stream refused again).
    std::size_t back_steps = 0, forward_steps = 0;
    for (std::size_t i = 1; i < rows.size(); ++i) {
      back_steps += rows[i].t < rows[i - 1].t;
      forward_steps += rows[i].t > rows[i - 1].t;
    }
    const bool newest_first = rows.size() >= 2 && rows.back().t < rows.front().t && back_steps >= 9 * forward_steps;
    if (newest_first) {
      std::reverse(rows.begin(), rows.end());
      std::reverse(row_of.begin(), row_of.end());
      // Rows of one time (contact_point: one per contact) keep their file order.
      for (std::size_t a = 0, b = 0; a < rows.size(); a = b) {
        for (b = a + 1; b < rows.size() && rows[b].t == rows[a].t;) ++b;
        std::reverse(rows.begin() + a, rows.begin() + b);
        std::reverse(row_of.begin() + a, row_of.begin() + b);
      }
      if (notes_ != nullptr) notes_->push_back(path + whose + ": rows logged newest first, read in reverse");
    }
    // Rows a little out of order (a logger's buffers) are sorted; a stream whose clock goes back
    // by more than max(1 s, 100 median periods) is two recordings joined or a clock reset, which
    // sorting would interleave into one nonsense push (a concatenated file ran, its shape
    // "aligned" by a turn of 132 degrees, object NEES 2887).
    if (rows.size() >= 3) {
      // The period from the time stamps in order (the rows' own order may be any).
      std::vector<double> times(rows.size()), steps;
      for (std::size_t i = 0; i < rows.size(); ++i) times[i] = rows[i].t;
      std::sort(times.begin(), times.end());
      for (std::size_t i = 1; i < times.size(); ++i)
        if (times[i] > times[i - 1]) steps.push_back(times[i] - times[i - 1]);
      double period = 0.0;
      if (!steps.empty()) {
        std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
        period = steps[steps.size() / 2];
      }
      const double limit = std::max(1.0, 100.0 * period);
      double latest = rows[0].t;
      for (std::size_t i = 1; i < rows.size(); ++i) {
        if (latest - rows[i].t > limit) {
          std::ostringstream o;
          o.precision(10);
          o << "row [" << row_of[i] << "]" << whose << " goes back in time by " << latest - rows[i].t << " s (to t = "
            << rows[i].t << " after t = " << latest << "; the stream's median period is " << period
            << " s): are two recordings joined, or was the clock reset? A trajectory file holds one push";
          Fail(path, o.str());
        }
        latest = std::max(latest, rows[i].t);
      }
    }
    if (notes_ != nullptr) {
      std::size_t late = 0, first = 0;
      double latest = rows.empty() ? 0.0 : rows[0].t;
      for (std::size_t i = 1; i < rows.size(); ++i) {
        if (rows[i].t < latest && late++ == 0) first = row_of[i];  // after a later stamp
        latest = std::max(latest, rows[i].t);
      }
      if (late > 0) {
        notes_->push_back(path + ": sorted " + std::to_string(late) + " row(s)" + whose +
                          " that came after a later time stamp (first: row [" + std::to_string(first) + "])");
      }
    }
    std::vector<std::size_t> order(rows.size());  // rows in time order
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return rows[a].t < rows[b].t; });
    std::vector<Sample> sorted;
    sorted.reserve(rows.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
      // Less than a nanosecond apart is the same time stamp too (two rows 1e-12 s apart and 3 cm
      // different were read as a 30 km/s jump); no sensor samples that fast, and a clock near
      // 1e9 s (Unix time) cannot even tell such times apart.
      constexpr double kSameTime = 1e-9;  // s
      if (!repeats && i > 0 && rows[order[i]].t - rows[order[i - 1]].t < kSameTime) {
        std::ostringstream o;
        o.precision(17);
        o << "rows [" << row_of[order[i - 1]] << "] and [" << row_of[order[i]] << "]" << whose;
        if (rows[order[i]].t == rows[order[i - 1]].t) {
          o << " have the same time stamp " << rows[order[i]].t;
        } else {
          char gap[32];
          std::snprintf(gap, sizeof gap, "%.3g", rows[order[i]].t - rows[order[i - 1]].t);
          o << " are " << gap << " s apart (t = " << rows[order[i - 1]].t << " and "
            << rows[order[i]].t << "): less than 1 ns, the same time stamp written twice?";
        }
        Fail(path, o.str());
      }
      if constexpr (std::is_same_v<Sample, PointSample>) {
        // Several contacts at one time are allowed; the same contact twice is a row written twice
        // (duplicated rows became two contacts at one point, each with its own force).
        for (std::size_t j = i; repeats && j-- > 0 && rows[order[i]].t - rows[order[j]].t < kSameTime;) {
          if (rows[order[j]].point == rows[order[i]].point) {
            std::ostringstream o;
            o.precision(17);
            o << "rows [" << row_of[order[j]] << "] and [" << row_of[order[i]] << "]" << whose
              << " are the same contact point (" << rows[order[i]].point.x() << ", " << rows[order[i]].point.y()
              << ") at t = " << rows[order[i]].t
              << ": a row written twice? (Rows at one time are several contacts, each at its own point)";
            Fail(path, o.str());
          }
        }
      }
      sorted.push_back(rows[order[i]]);
    }
    return sorted;
  }

  // The object's and finger 0's streams; `extra` receives fingers 1.. (rows carry the finger
  // index when there are several fingers).
  Streams StreamsOf(const json& value, const std::string& path, int fingers = 1,
                    std::vector<push::FingerStreams>* extra = nullptr) const {
    CheckKeys(value, {"object_pose", "finger_pose", "contact_point", "force"}, path);
    Streams s;
    std::vector<push::FingerStreams> others(static_cast<std::size_t>(fingers - 1));
    auto pose = [](const std::vector<double>& v) { return PoseSample{v[0], {v[1], v[2], v[3]}}; };
    if (value.contains("object_pose")) s.object_pose = Rows<PoseSample>(value["object_pose"], 4, path + ".object_pose", pose)[0];
    if (value.contains("finger_pose")) {
      auto rows = Rows<PoseSample>(value["finger_pose"], 4, path + ".finger_pose", pose, fingers);
      s.finger_pose = std::move(rows[0]);
      for (std::size_t k = 1; k < rows.size(); ++k) others[k - 1].finger_pose = std::move(rows[k]);
    }
    if (value.contains("contact_point")) {
      auto rows = Rows<PointSample>(value["contact_point"], 3, path + ".contact_point",
                                    [](const std::vector<double>& v) { return PointSample{v[0], {v[1], v[2]}}; }, fingers,
                                    /*repeats=*/true);
      s.contact_point = std::move(rows[0]);
      for (std::size_t k = 1; k < rows.size(); ++k) others[k - 1].contact_point = std::move(rows[k]);
    }
    if (value.contains("force")) {
      auto rows = Rows<ForceSample>(value["force"], 3, path + ".force",
                                    [](const std::vector<double>& v) { return ForceSample{v[0], {v[1], v[2]}}; }, fingers);
      s.force = std::move(rows[0]);
      for (std::size_t k = 1; k < rows.size(); ++k) others[k - 1].force = std::move(rows[k]);
    }
    if (extra) *extra = std::move(others);
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

// With extra fingers, finger rows carry the finger's index after the time, in time order.
json StreamsJson(const Streams& s, const std::vector<const push::FingerStreams*>& extra = {}) {
  const bool indexed = !extra.empty();
  auto rows = [&](auto finger_0, auto of_extra, auto values) {
    std::vector<std::pair<double, json>> all;
    auto add = [&](const auto& samples, int finger) {
      for (const auto& p : samples) {
        json row = json::array({p.t});
        if (indexed) row.push_back(finger);
        for (double v : values(p)) row.push_back(v);
        all.emplace_back(p.t, std::move(row));
      }
    };
    add(finger_0, 0);
    for (std::size_t k = 0; k < extra.size(); ++k) add(of_extra(*extra[k]), static_cast<int>(k + 1));
    std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    json out = json::array();
    for (auto& r : all) out.push_back(std::move(r.second));
    return out;
  };
  auto pose = [](const PoseSample& p) { return std::vector<double>{p.pose.x, p.pose.y, p.pose.theta}; };
  json out = json::object();
  json op = json::array();
  for (const PoseSample& p : s.object_pose) op.push_back({p.t, p.pose.x, p.pose.y, p.pose.theta});
  out["object_pose"] = op;
  out["finger_pose"] = rows(s.finger_pose, [](const push::FingerStreams& f) -> const auto& { return f.finger_pose; }, pose);
  out["contact_point"] = rows(s.contact_point, [](const push::FingerStreams& f) -> const auto& { return f.contact_point; },
                              [](const PointSample& p) { return std::vector<double>{p.point.x(), p.point.y()}; });
  out["force"] = rows(s.force, [](const push::FingerStreams& f) -> const auto& { return f.force; },
                      [](const ForceSample& p) { return std::vector<double>{p.force.x(), p.force.y()}; });
  return out;
}

}  // namespace

Trajectory ParseTrajectoryJson(const std::string& text, const std::string& source, std::vector<std::string>* notes) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw IoError(source + ": malformed JSON: " + geometry::JsonSyntaxErrorText(e.what(), text));
  }
  if (const std::string dup = geometry::FindDuplicateJsonKey(text); !dup.empty()) throw IoError(source + ": " + dup);
  const Reader r(source, notes);
  r.CheckKeys(doc, {"format", "object", "finger", "fingers", "streams", "ground_truth", "measurement_sigmas"}, "top level");
  const json& format = r.Require(doc, "format", "top level");
  if (!format.is_string() || format.get<std::string>() != kTrajectoryFormat)
    r.Fail("format", std::string("expected \"") + kTrajectoryFormat + "\", got " + format.dump());

  Trajectory t;
  const json& object = r.Require(doc, "object", "top level");
  r.CheckKeys(object, {"shape", "mass", "mu_surface", "pressure"}, "object");
  t.object.shape = r.ShapeOf(r.Require(object, "shape", "object"), "object.shape");
  t.object.mass = r.Number(r.Require(object, "mass", "object"), "object.mass");
  if (!(t.object.mass > 0.0)) r.Fail("object.mass", "must be > 0 (kg), got " + r.Text(t.object.mass));
  t.object.mu_surface = r.Friction(r.Require(object, "mu_surface", "object"), "object.mu_surface");
  if (object.contains("pressure")) {
    if (!object["pressure"].is_string() || object["pressure"].get<std::string>() != "uniform")
      r.Fail("object.pressure", "only \"uniform\" is supported in trajectory files, got " + object["pressure"].dump());
  }
  // "finger": one finger; "fingers": [finger 0, finger 1, ...] (not both).
  if (doc.contains("finger") == doc.contains("fingers"))
    r.Fail("top level", doc.contains("finger") ? "has both \"finger\" and \"fingers\": give one"
                                                : "missing field \"finger\" (or \"fingers\")");
  std::vector<push::FingerDescription> fingers;
  auto finger_of = [&](const json& finger, const std::string& path) {
    r.CheckKeys(finger, {"shape", "mu_contact"}, path);
    push::FingerDescription f;
    f.shape = r.ShapeOf(r.Require(finger, "shape", path), path + ".shape");
    f.mu_contact = r.Friction(r.Require(finger, "mu_contact", path), path + ".mu_contact");
    return f;
  };
  if (doc.contains("finger")) {
    fingers.push_back(finger_of(doc["finger"], "finger"));
  } else {
    const json& list = doc["fingers"];
    if (!list.is_array() || list.empty()) r.Fail("fingers", "must be a non-empty array of fingers");
    for (std::size_t i = 0; i < list.size(); ++i) fingers.push_back(finger_of(list[i], "fingers[" + std::to_string(i) + "]"));
  }
  t.finger = fingers[0];
  const int count = static_cast<int>(fingers.size());
  std::vector<push::FingerStreams> measured_extra, truth_extra;
  if (doc.contains("streams")) t.measured = r.StreamsOf(doc["streams"], "streams", count, &measured_extra);
  if (doc.contains("ground_truth")) t.ground_truth = r.StreamsOf(doc["ground_truth"], "ground_truth", count, &truth_extra);
  for (int k = 1; k < count; ++k) {
    push::ExtraFinger e;
    e.finger = fingers[k];
    if (!measured_extra.empty()) e.measured = std::move(measured_extra[k - 1]);
    if (t.ground_truth) e.ground_truth = std::move(truth_extra[k - 1]);
    t.extra_fingers.push_back(std::move(e));
  }
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

namespace {
// JSON has no NaN or infinity (a writer would put null, which no reader takes back): a
// non-finite sample is refused by its stream and row before anything is written.
void RequireFiniteRows(const std::vector<push::PoseSample>& pose, const std::vector<push::PointSample>& point,
                       const std::vector<push::ForceSample>& force, const std::string& where) {
  auto fail = [&](const char* stream, std::size_t i) {
    throw IoError("trajectory JSON: " + where + stream + "[" + std::to_string(i) +
                  "] is not finite (JSON has no NaN or infinity: the row would be written as null, which no reader "
                  "takes back); drop the sample instead");
  };
  for (std::size_t i = 0; i < pose.size(); ++i)
    if (!std::isfinite(pose[i].t) || !pose[i].pose.vector().allFinite()) fail("finger_pose", i);
  for (std::size_t i = 0; i < point.size(); ++i)
    if (!std::isfinite(point[i].t) || !point[i].point.allFinite()) fail("contact_point", i);
  for (std::size_t i = 0; i < force.size(); ++i)
    if (!std::isfinite(force[i].t) || !force[i].force.allFinite()) fail("force", i);
}
void RequireFiniteStreams(const Streams& s, const std::vector<push::ExtraFinger>& extra, bool truth) {
  const std::string base = truth ? "ground_truth." : "streams.";
  for (std::size_t i = 0; i < s.object_pose.size(); ++i)
    if (!std::isfinite(s.object_pose[i].t) || !s.object_pose[i].pose.vector().allFinite())
      throw IoError("trajectory JSON: " + base + "object_pose[" + std::to_string(i) +
                    "] is not finite (JSON has no NaN or infinity: the row would be written as null, which no reader "
                    "takes back); drop the sample instead");
  RequireFiniteRows(s.finger_pose, s.contact_point, s.force, base);
  for (std::size_t k = 0; k < extra.size(); ++k) {
    const push::FingerStreams* f = truth ? (extra[k].ground_truth ? &*extra[k].ground_truth : nullptr) : &extra[k].measured;
    if (f != nullptr)
      RequireFiniteRows(f->finger_pose, f->contact_point, f->force, base + "fingers[" + std::to_string(k + 1) + "].");
  }
}
}  // namespace

// One stream row per line: readable, diff-friendly and still plain JSON.
std::string TrajectoryToJson(const Trajectory& t, int indent) {
  RequireFiniteStreams(t.measured, t.extra_fingers, false);
  if (t.ground_truth) RequireFiniteStreams(*t.ground_truth, t.extra_fingers, true);
  // The format holds what the estimator reads: uniform pressure under standard gravity.
  if (t.object.pressure.kind != limit_surface::PressureKind::kUniform)
    throw IoError("trajectory JSON: object.pressure must be uniform (the format has no other)");
  if (t.object.gravity != limit_surface::kStandardGravity)
    throw IoError("trajectory JSON: object.gravity must be the standard 9.80665 m/s^2 (the format has no field for it)");
  // What the reader requires, refused here rather than written into a file it then refuses.
  auto friction_ok = [](double mu) { return std::isfinite(mu) && mu >= 0.0 && mu <= limit_surface::kMaxFriction; };
  if (!(std::isfinite(t.object.mass) && t.object.mass > 0.0))
    throw IoError("trajectory JSON: object.mass must be > 0 kg (the format has no unknown mass), got " + std::to_string(t.object.mass));
  if (!friction_ok(t.object.mu_surface))
    throw IoError("trajectory JSON: object.mu_surface must be in [0, 10], got " + std::to_string(t.object.mu_surface));
  if (!friction_ok(t.finger.mu_contact))
    throw IoError("trajectory JSON: finger.mu_contact must be in [0, 10], got " + std::to_string(t.finger.mu_contact));
  json object = {{"shape", ShapeJson(t.object.shape)},
                 {"mass", t.object.mass},
                 {"mu_surface", t.object.mu_surface},
                 {"pressure", "uniform"}};
  auto finger_json = [](const push::FingerDescription& f) {
    return json{{"shape", ShapeJson(f.shape)}, {"mu_contact", f.mu_contact}};
  };
  const bool several = !t.extra_fingers.empty();
  const char* finger_key = several ? "fingers" : "finger";
  json finger = finger_json(t.finger);
  std::vector<const push::FingerStreams*> measured_extra, truth_extra;
  if (several) {
    finger = json::array({finger});
    for (const push::ExtraFinger& e : t.extra_fingers) {
      finger.push_back(finger_json(e.finger));
      measured_extra.push_back(&e.measured);
      if (t.ground_truth && !e.ground_truth)
        throw IoError("trajectory JSON: extra finger " + std::to_string(measured_extra.size()) +
                      " has no ground truth while the trajectory has");
      if (e.ground_truth) truth_extra.push_back(&*e.ground_truth);
    }
  }
  if (indent < 0) {
    json doc = {{"format", kTrajectoryFormat}, {"object", object}, {finger_key, finger},
                {"streams", StreamsJson(t.measured, measured_extra)}};
    if (t.ground_truth) doc["ground_truth"] = StreamsJson(*t.ground_truth, truth_extra);
    if (t.measurement_sigmas) doc["measurement_sigmas"] = SigmasJson(*t.measurement_sigmas);
    return doc.dump();
  }
  auto streams = [](const Streams& s, const std::vector<const push::FingerStreams*>& extra) {
    const json j = StreamsJson(s, extra);
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
                    ",\n \"" + finger_key + "\": " + finger.dump() + ",\n \"streams\": " + streams(t.measured, measured_extra);
  if (t.ground_truth) out += ",\n \"ground_truth\": " + streams(*t.ground_truth, truth_extra);
  if (t.measurement_sigmas) out += ",\n \"measurement_sigmas\": " + SigmasJson(*t.measurement_sigmas).dump();
  return out + "}";
}

void SaveTrajectoryJson(const Trajectory& t, const std::string& path) {
  if (const std::string error = geometry::WriteFileAtomically(path, TrajectoryToJson(t) + "\n"); !error.empty())
    throw IoError(error);
}

}  // namespace pushgraph::io
