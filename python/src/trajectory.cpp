// Trajectories as dicts of NumPy arrays, their files (pushgraph-trajectory-1 JSON, MIT HDF5) and
// the simulator.
#include "common.h"
#include "convert.h"

#include <pushgraph/io/mit_push.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>

#include <algorithm>
#include <cstring>
#include <fstream>

namespace pushgraph::python {
namespace {

using namespace push;

template <class Sample, class Get>
py::dict StreamDict(const std::vector<Sample>& samples, const char* value_name, int columns, Get get) {
  const py::ssize_t n = static_cast<py::ssize_t>(samples.size());
  py::array_t<double> t = NewArray({n});
  py::array_t<double> v = NewArray({n, columns});
  for (py::ssize_t i = 0; i < n; ++i) {
    t.mutable_data()[i] = samples[i].t;
    get(samples[i], v.mutable_data() + columns * i);
  }
  py::dict d;
  d["t"] = t;
  d[value_name] = v;
  return d;
}

py::dict StreamsDict(const Streams& s) {
  py::dict d;
  d["object_pose"] = StreamDict(s.object_pose, "pose", 3, [](const PoseSample& a, double* o) {
    o[0] = a.pose.x;
    o[1] = a.pose.y;
    o[2] = a.pose.theta;
  });
  d["finger_pose"] = StreamDict(s.finger_pose, "pose", 3, [](const PoseSample& a, double* o) {
    o[0] = a.pose.x;
    o[1] = a.pose.y;
    o[2] = a.pose.theta;
  });
  d["contact_point"] = StreamDict(s.contact_point, "point", 2, [](const PointSample& a, double* o) {
    o[0] = a.point.x();
    o[1] = a.point.y();
  });
  d["force"] = StreamDict(s.force, "force", 2, [](const ForceSample& a, double* o) {
    o[0] = a.force.x();
    o[1] = a.force.y();
  });
  return d;
}

// A stream from {"t": (N,), value_name: (N, columns)}; a missing stream is empty.
template <class Sample, class Set>
std::vector<Sample> StreamFrom(const py::dict& streams, const char* name, const char* value_name, int columns,
                               const std::string& where, Set set) {
  std::vector<Sample> out;
  if (!streams.contains(name) || streams[name].is_none()) return out;
  const std::string at = where + "['" + name + "']";
  if (!py::isinstance<py::dict>(streams[name])) throw py::type_error(at + ": expected a dict {'t': ..., '" + value_name + "': ...}");
  const py::dict d = streams[name];
  for (const auto& item : d) {
    const std::string key = py::str(item.first);
    if (key != "t" && key != value_name) throw py::value_error(at + ": unknown key '" + key + "' (t, " + value_name + ")");
  }
  if (!d.contains("t") || !d.contains(value_name)) throw py::value_error(at + ": needs 't' and '" + value_name + "'");
  const Array t = Vector(d["t"], (at + "['t']").c_str());
  const Array v = Rows(d[value_name], columns, (at + "['" + value_name + "']").c_str(), false);
  if (v.shape(0) != t.shape(0)) {
    throw py::value_error(at + ": " + std::to_string(t.shape(0)) + " times and " + std::to_string(v.shape(0)) + " values");
  }
  for (py::ssize_t i = 0; i < t.shape(0); ++i) {
    Sample s;
    s.t = t.data()[i];
    set(s, v.data() + columns * i);
    out.push_back(s);
  }
  return out;
}

Streams StreamsFrom(const py::handle& object, const std::string& where) {
  if (!py::isinstance<py::dict>(object)) throw py::type_error(where + ": expected a dict of streams");
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  for (const auto& item : d) {
    const std::string key = py::str(item.first);
    if (key != "object_pose" && key != "finger_pose" && key != "contact_point" && key != "force") {
      throw py::value_error(where + ": unknown stream '" + key + "' (object_pose, finger_pose, contact_point, force)");
    }
  }
  Streams s;
  s.object_pose = StreamFrom<PoseSample>(d, "object_pose", "pose", 3, where,
                                         [](PoseSample& a, const double* v) { a.pose = {v[0], v[1], v[2]}; });
  s.finger_pose = StreamFrom<PoseSample>(d, "finger_pose", "pose", 3, where,
                                         [](PoseSample& a, const double* v) { a.pose = {v[0], v[1], v[2]}; });
  s.contact_point = StreamFrom<PointSample>(d, "contact_point", "point", 2, where,
                                            [](PointSample& a, const double* v) { a.point = Vec2(v[0], v[1]); });
  s.force = StreamFrom<ForceSample>(d, "force", "force", 2, where,
                                    [](ForceSample& a, const double* v) { a.force = Vec2(v[0], v[1]); });
  return s;
}

double Number(const py::dict& d, const char* key, const std::string& where, double fallback) {
  if (!d.contains(key) || d[key].is_none()) return fallback;
  // pybind11 casts True to 1.0: a mass of True ran as 1 kg.
  if (py::isinstance<py::bool_>(d[key]) || std::string(py::str(py::type::of(d[key]).attr("__name__"))) == "bool_")
    throw py::type_error(where + "['" + key + "']: expected a number, not a boolean");
  try {
    return d[key].cast<double>();
  } catch (const py::cast_error&) {
    throw py::type_error(where + "['" + key + "']: expected a number");
  }
}

void CheckKeys(const py::dict& d, const std::vector<std::string>& allowed, const std::string& where) {
  for (const auto& item : d) {
    const std::string key = py::str(item.first);
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw py::value_error(where + ": unknown key '" + key + "' (" + list + ")");
    }
  }
}

}  // namespace

// Finger k >= 1's streams (no object pose) as a Streams dict and back.
py::dict FingerStreamsDict(const pushgraph::push::FingerStreams& f) {
  Streams s;
  s.finger_pose = f.finger_pose;
  s.contact_point = f.contact_point;
  s.force = f.force;
  py::dict d = StreamsDict(s);
  PyDict_DelItemString(d.ptr(), "object_pose");
  return d;
}

pushgraph::push::FingerStreams FingerStreamsFrom(const py::handle& object, const std::string& where) {
  if (py::isinstance<py::dict>(object) && py::reinterpret_borrow<py::dict>(object).contains("object_pose"))
    throw py::value_error(where + ": a finger's streams have no 'object_pose' (finger_pose, contact_point, force)");
  const Streams s = StreamsFrom(object, where);
  return {s.finger_pose, s.contact_point, s.force};
}

py::dict TrajectoryToDict(const Trajectory& t) {
  py::dict d;
  py::dict object, finger;
  object["shape"] = t.object.shape;
  object["mass"] = t.object.mass;
  object["mu_surface"] = t.object.mu_surface;
  object["pressure"] = "uniform";  // the only pressure trajectories carry
  finger["shape"] = t.finger.shape;
  finger["mu_contact"] = t.finger.mu_contact;
  d["object"] = object;
  d["finger"] = finger;
  d["measured"] = StreamsDict(t.measured);
  d["ground_truth"] = t.ground_truth ? py::object(StreamsDict(*t.ground_truth)) : py::none();
  if (!t.extra_fingers.empty()) {
    // Fingers 1, 2, ... of a push with several fingers, each with its own streams.
    py::list fingers;
    for (const pushgraph::push::ExtraFinger& e : t.extra_fingers) {
      py::dict f;
      f["shape"] = e.finger.shape;
      f["mu_contact"] = e.finger.mu_contact;
      f["measured"] = FingerStreamsDict(e.measured);
      f["ground_truth"] = e.ground_truth ? py::object(FingerStreamsDict(*e.ground_truth)) : py::none();
      fingers.append(f);
    }
    d["fingers"] = fingers;
  }
  if (t.measurement_sigmas) {
    const MeasurementSigmas& s = *t.measurement_sigmas;
    py::dict m;
    m["object_trans"] = s.object_trans;
    m["object_rot"] = s.object_rot;
    m["finger_trans"] = s.finger_trans;
    m["finger_rot"] = s.finger_rot;
    m["contact"] = s.contact;
    m["force"] = s.force;
    d["measurement_sigmas"] = m;
  } else {
    d["measurement_sigmas"] = py::none();
  }
  return d;
}

Trajectory TrajectoryFromDict(const py::handle& object) {
  if (!py::isinstance<py::dict>(object)) throw py::type_error("trajectory: expected a dict (see pushgraph.load_trajectory)");
  const py::dict d = py::reinterpret_borrow<py::dict>(object);
  CheckKeys(d, {"object", "finger", "measured", "ground_truth", "measurement_sigmas", "fingers"}, "trajectory");
  Trajectory t;
  for (const char* part : {"object", "finger"}) {
    if (!d.contains(part) || !py::isinstance<py::dict>(d[part])) {
      throw py::value_error(std::string("trajectory['") + part + "']: expected a dict with a 'shape'");
    }
  }
  const py::dict o = d["object"], f = d["finger"];
  CheckKeys(o, {"shape", "mass", "mu_surface", "pressure"}, "trajectory['object']");
  CheckKeys(f, {"shape", "mu_contact"}, "trajectory['finger']");
  try {
    t.object.shape = o["shape"].cast<geometry::Shape>();
    t.finger.shape = f["shape"].cast<geometry::Shape>();
  } catch (const py::cast_error&) {
    throw py::type_error("trajectory: 'shape' of the object and the finger must be pushgraph.Shape");
  }
  t.object.mass = Number(o, "mass", "trajectory['object']", 0.0);
  t.object.mu_surface = Number(o, "mu_surface", "trajectory['object']", 0.0);
  if (o.contains("pressure") && py::str(o["pressure"]).cast<std::string>() != "uniform")
    throw py::value_error("trajectory['object']['pressure']: only 'uniform' is supported");
  t.finger.mu_contact = Number(f, "mu_contact", "trajectory['finger']", 0.0);
  if (!d.contains("measured")) throw py::value_error("trajectory: missing 'measured'");
  t.measured = StreamsFrom(d["measured"], "trajectory['measured']");
  if (d.contains("ground_truth") && !d["ground_truth"].is_none()) {
    t.ground_truth = StreamsFrom(d["ground_truth"], "trajectory['ground_truth']");
  }
  if (d.contains("fingers") && !d["fingers"].is_none()) {
    if (!py::isinstance<py::list>(d["fingers"]))
      throw py::type_error("trajectory['fingers']: expected a list of finger dicts (fingers 1, 2, ...)");
    const py::list fingers = d["fingers"];
    for (std::size_t k = 0; k < fingers.size(); ++k) {
      const std::string at = "trajectory['fingers'][" + std::to_string(k) + "]";
      if (!py::isinstance<py::dict>(fingers[k])) throw py::type_error(at + ": expected a dict with a 'shape'");
      const py::dict f = fingers[k];
      CheckKeys(f, {"shape", "mu_contact", "measured", "ground_truth"}, at);
      pushgraph::push::ExtraFinger e;
      try {
        e.finger.shape = f["shape"].cast<geometry::Shape>();
      } catch (const py::cast_error&) {
        throw py::type_error(at + "['shape']: expected a pushgraph.Shape");
      }
      e.finger.mu_contact = Number(f, "mu_contact", at, 0.0);
      if (!f.contains("measured")) throw py::value_error(at + ": missing 'measured'");
      e.measured = FingerStreamsFrom(f["measured"], at + "['measured']");
      if (f.contains("ground_truth") && !f["ground_truth"].is_none())
        e.ground_truth = FingerStreamsFrom(f["ground_truth"], at + "['ground_truth']");
      t.extra_fingers.push_back(std::move(e));
    }
  }
  if (d.contains("measurement_sigmas") && !d["measurement_sigmas"].is_none()) {
    if (!py::isinstance<py::dict>(d["measurement_sigmas"])) throw py::type_error("trajectory['measurement_sigmas']: expected a dict");
    const py::dict m = d["measurement_sigmas"];
    const std::string at = "trajectory['measurement_sigmas']";
    MeasurementSigmas s;
    // The dict's own keys, or the trajectory file's ({"object_pose": [trans, rot], "finger_pose":
    // [trans, rot], "contact_point": s, "force": s}, docs/formats.md), not mixed.
    const bool file_keys = m.contains("object_pose") || m.contains("finger_pose") || m.contains("contact_point");
    if (file_keys) {
      CheckKeys(m, {"object_pose", "finger_pose", "contact_point", "force"},
                at + " (the trajectory file's keys; the dict's own are object_trans, object_rot, finger_trans, "
                     "finger_rot, contact, force)");
      auto pair = [&](const char* key, double* trans, double* rot) {
        if (!m.contains(key) || m[key].is_none()) return;
        std::vector<double> v;
        try {
          v = m[key].cast<std::vector<double>>();
        } catch (const py::cast_error&) {
          throw py::type_error(at + "['" + key + "']: expected [sigma_trans, sigma_rot]");
        }
        if (v.size() != 2) throw py::value_error(at + "['" + key + "']: expected [sigma_trans, sigma_rot], got " +
                                                 std::to_string(v.size()) + " numbers");
        *trans = v[0];
        *rot = v[1];
      };
      pair("object_pose", &s.object_trans, &s.object_rot);
      pair("finger_pose", &s.finger_trans, &s.finger_rot);
      s.contact = Number(m, "contact_point", at, 0.0);
      s.force = Number(m, "force", at, 0.0);
    } else {
      CheckKeys(m, {"object_trans", "object_rot", "finger_trans", "finger_rot", "contact", "force"}, at);
      s.object_trans = Number(m, "object_trans", at, 0.0);
      s.object_rot = Number(m, "object_rot", at, 0.0);
      s.finger_trans = Number(m, "finger_trans", at, 0.0);
      s.finger_rot = Number(m, "finger_rot", at, 0.0);
      s.contact = Number(m, "contact", at, 0.0);
      s.force = Number(m, "force", at, 0.0);
    }
    t.measurement_sigmas = s;
  }
  return t;
}

void RegisterTrajectory(py::module_& m) {
  using namespace pybind11::literals;
  m.def(
      "load_trajectory",
      [](const std::filesystem::path& file) {
        const std::string path = file.string();
        // An MIT recording given here was "malformed JSON ... invalid literal": say what it is.
        char signature[8] = {};
        std::ifstream(path, std::ios::binary).read(signature, sizeof signature);
        if (std::memcmp(signature, "\x89HDF\r\n\x1a\n", 8) == 0)
          throw io::IoError(path + ": an HDF5 file: load_trajectory reads trajectory JSON (docs/formats.md); an MIT "
                            "pushing recording is read by read_mit_push");
        Trajectory t;
        std::vector<std::string> notes;
        {
          py::gil_scoped_release release;
          t = io::LoadTrajectoryJson(path, &notes);
        }
        // What the reader repaired (rows sorted, a stream read newest first), as the tool prints it.
        for (const std::string& note : notes) WarnUser(path + ": " + note);
        return TrajectoryToDict(t);
      },
      "path"_a, R"doc(
A pushgraph-trajectory-1 JSON file as a dict:
{'object': {'shape', 'mass', 'mu_surface', 'pressure'}, 'finger': {'shape', 'mu_contact'},
 'measured': {'object_pose': {'t': (N,), 'pose': (N, 3)}, 'finger_pose': {...},
              'contact_point': {'t', 'point': (N, 2)}, 'force': {'t', 'force': (N, 2)}},
 'ground_truth': the same streams or None, 'measurement_sigmas': dict or None}.
A push with several fingers also has 'fingers': [{'shape', 'mu_contact', 'measured': {'finger_pose',
'contact_point', 'force'}, 'ground_truth': ... or None}, ...] (fingers 1, 2, ...; 'finger' is finger 0).
Rows are sorted by time; what was repaired so (and other notes of the reader) comes as a UserWarning.
Raises IoError naming the file and the field.)doc");
  m.def(
      "save_trajectory",
      [](const py::handle& t, const std::filesystem::path& path) { io::SaveTrajectoryJson(TrajectoryFromDict(t), path.string()); },
      "trajectory"_a, "path"_a, "Writes the dict (as load_trajectory returns it) atomically.");
  m.def(
      "read_mit_push",
      [](const std::filesystem::path& file, const geometry::Shape& object, double mass, double mu_surface,
         const geometry::Shape& finger, double mu_contact, bool trim_to_contact) {
        const std::string path = file.string();
        // The tool's bounds (mit-import --mass, --mu-surface, --mu-contact): they also set the
        // contact phase's force threshold, and a mass of -1 or a NaN mu was taken without a word.
        auto check = [](double v, bool ok, const char* name, const char* range) {
          if (!ok) throw py::value_error(std::string("read_mit_push: ") + name + " = " + py::repr(py::float_(v)).cast<std::string>() +
                                         " is outside " + range);
        };
        check(mass, mass > 0.0 && mass <= 1e6, "mass", "(0, 1e6] kg");
        check(mu_surface, mu_surface > 0.0 && mu_surface <= 10.0, "mu_surface", "(0, 10]");
        check(mu_contact, mu_contact >= 0.0 && mu_contact <= 10.0, "mu_contact", "[0, 10]");
        io::MitReadOptions options;
        options.trim_to_contact = trim_to_contact;
        options.contact_force = io::MitContactForce(mass, mu_surface);  // as `pushgraph estimate` reads it
        Trajectory t;
        std::string fault;
        {
          py::gil_scoped_release release;
          const io::MitRecording rec = io::ReadMitPush(path, options);
          ObjectDescription o;
          o.shape = object;
          o.mass = mass;
          o.mu_surface = mu_surface;
          FingerDescription f;
          f.shape = finger;
          f.mu_contact = mu_contact;
          t = io::MitToTrajectory(rec, o, f);
          fault = rec.force_fault;
        }
        py::dict d = TrajectoryToDict(t);
        return py::make_tuple(d, fault);
      },
      "path"_a, "object"_a, "mass"_a, "mu_surface"_a, "finger"_a, "mu_contact"_a = 0.25, "trim_to_contact"_a = true,
      "An MIT pushing recording (HDF5) as (trajectory dict, force fault: '' or why the force stream was dropped).");
  m.def(
      "simulate",
      [](const geometry::Shape& object, const geometry::Shape& finger, double mass, double mu_surface, double mu_contact,
         double push_angle, double offset, double standoff, double distance, double speed, const py::handle& object_pose,
         const std::string& surface, const std::string& noise, double object_rate, double finger_rate, double contact_rate,
         double force_rate, std::uint64_t seed, const py::object& waypoints, double duration, const py::object& sigmas,
         const py::object& occlusions) {
        PushPlan plan;
        plan.object = {object, mass, mu_surface};
        plan.finger = {finger, mu_contact};
        plan.object_pose = ToPose(object_pose, "object_pose");
        if (surface == "exact") plan.surface = SurfaceModel::kExact;
        else if (surface == "ellipsoid") plan.surface = SurfaceModel::kEllipsoid;
        else throw py::value_error("surface: expected 'exact' or 'ellipsoid', got '" + surface + "'");
        if (noise == "gaussian") plan.noise = DefaultNoise(NoiseKind::kGaussian);
        else if (noise == "bimodal") plan.noise = DefaultNoise(NoiseKind::kBimodal);
        else if (noise != "none") throw py::value_error("noise: expected 'gaussian', 'bimodal' or 'none', got '" + noise + "'");
        plan.speed = speed;
        plan.duration = duration;
        plan.rates = {object_rate, finger_rate, contact_rate, force_rate};
        plan.seed = seed;
        if (!sigmas.is_none()) {
          // Per-stream sigmas, as `pushgraph simulate --sigma-*`: object (m, rad), finger, contact (m), force (N).
          if (noise == "none") throw py::value_error("sigmas: the noise is 'none' (choose 'gaussian' or 'bimodal')");
          if (!py::isinstance<py::dict>(sigmas)) throw py::type_error("sigmas: expected a dict {object: (m, rad), finger: m, contact: m, force: N}");
          for (const auto& item : py::reinterpret_borrow<py::dict>(sigmas)) {
            const std::string key = py::str(item.first);
            const py::handle v = item.second;
            auto positive = [&](double x, const std::string& what) {
              if (!(x >= 0.0) || !std::isfinite(x)) throw py::value_error("sigmas['" + key + "']: " + what + " must be finite and >= 0");
              return x;
            };
            // A value of another form is named with what is expected (a bare "Unable to cast Python
            // instance to C++ type" came of sigmas={"finger": (0.0005, 0.0)}).
            auto number = [&](const char* expected) {
              try {
                return v.cast<double>();
              } catch (const py::cast_error&) {
                throw py::type_error("sigmas['" + key + "']: expected " + expected + ", got " + py::repr(v).cast<std::string>());
              }
            };
            if (key == "object") {
              std::pair<double, double> pair;
              try {
                pair = v.cast<std::pair<double, double>>();
              } catch (const py::cast_error&) {
                throw py::type_error("sigmas['object']: expected a pair (position m, angle rad), got " + py::repr(v).cast<std::string>());
              }
              plan.noise.object_pose.position.sigma = positive(pair.first, "the position sigma");
              plan.noise.object_pose.angle.sigma = positive(pair.second, "the angle sigma");
            } else if (key == "finger") {
              plan.noise.finger_pose.position.sigma = positive(number("one number (the position sigma, m; the finger's angle is not noised)"), "the sigma");
            } else if (key == "contact") {
              plan.noise.contact_point.position.sigma = positive(number("one number (m)"), "the sigma");
            } else if (key == "force") {
              plan.noise.force.position.sigma = positive(number("one number (N)"), "the sigma");
            } else {
              throw py::value_error("sigmas: unknown key '" + key + "' (object, finger, contact, force)");
            }
          }
        }
        if (!occlusions.is_none()) {
          const Array w = Rows(occlusions, 2, "occlusions");
          CheckFinite(w, "occlusions");
          for (py::ssize_t i = 0; i < w.shape(0); ++i) {
            OcclusionWindow o;
            o.t0 = w.data()[2 * i];
            o.t1 = w.data()[2 * i + 1];
            plan.noise.occlusions.push_back(o);
          }
        }
        std::vector<Vec2> path;
        if (!waypoints.is_none()) {
          const Array w = Rows(waypoints, 2, "waypoints", false);
          CheckFinite(w, "waypoints");
          for (py::ssize_t i = 0; i < w.shape(0); ++i) path.emplace_back(w.data()[2 * i], w.data()[2 * i + 1]);
        }
        Trajectory t;
        {
          py::gil_scoped_release release;
          plan.waypoints = path.empty() ? StraightPushPath(plan, push_angle, offset, standoff, distance) : path;
          t = Simulate(plan).trajectory;
        }
        return TrajectoryToDict(t);
      },
      "object"_a, "finger"_a, "mass"_a = 0.5, "mu_surface"_a = 0.3, "mu_contact"_a = 0.4, "push_angle"_a = 1.5707963267948966,
      "offset"_a = 0.01, "standoff"_a = 0.005, "distance"_a = 0.05, "speed"_a = 0.05,
      "object_pose"_a = py::make_tuple(0.0, 0.0, 0.0), "surface"_a = "exact", "noise"_a = "gaussian", "object_rate"_a = 25.0,
      "finger_rate"_a = 250.0, "contact_rate"_a = 250.0, "force_rate"_a = 250.0, "seed"_a = 1, "waypoints"_a = py::none(),
      "duration"_a = 0.0, "sigmas"_a = py::none(), "occlusions"_a = py::none(), R"doc(
A straight quasi-static push simulated as `pushgraph simulate` does (the same defaults): the
finger starts `standoff` m from the object on the line at `push_angle` through its centroid
shifted `offset` m to the left, reaches it and pushes `distance` m further at `speed` m/s; or
along `waypoints` ((N, 2), world) instead. `duration` > 0 simulates that long (the finger rests
after its path). `sigmas` overrides the noise per stream: {'object': (m, rad), 'finger': m,
'contact': m, 'force': N}; `occlusions` (K, 2) are [t0, t1] windows without object poses.
Returns the trajectory dict with ground truth and the noise's measurement sigmas.)doc");
}

}  // namespace pushgraph::python
