// The evaluation's inputs (inputs.h): file kinds, MIT objects and recordings, the paper's
// noise, simulated pushes, input lists.
#include "internal.h"

#include <pushgraph/evaluation/inputs.h>
#include <pushgraph/geometry/json_check.h>
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/mit_push.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/push/simulator.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <regex>
#include <set>

#include <glob.h>

namespace pushgraph::evaluation {
namespace {

namespace fs = std::filesystem;
using io::UpAxis;
using internal::SplitMix;

// Mesh footprints by path and axis: every recording of an object shares one (the Boolean union
// of a mesh's faces takes up to seconds).
struct Footprint {
  geometry::Shape shape;
  std::vector<UpAxis> prism_axes;  // io::FootprintReport's
};
std::mutex g_footprint_mutex;
std::map<std::string, Footprint> g_footprints;  // mesh path + axis -> footprint

const char* AxisName(UpAxis up) { return up == UpAxis::kX ? "x" : up == UpAxis::kY ? "y" : "z"; }

Footprint CachedFootprint(const std::string& path, UpAxis up) {
  const std::string key = path + "#" + AxisName(up);
  {
    std::lock_guard<std::mutex> lock(g_footprint_mutex);
    auto it = g_footprints.find(key);
    if (it != g_footprints.end()) return it->second;
  }
  io::FootprintOptions o;
  o.up = up;
  io::FootprintReport report;
  Footprint f{io::MeshFootprint(path, o, &report), report.prism_axes};
  std::lock_guard<std::mutex> lock(g_footprint_mutex);
  return g_footprints.emplace(key, std::move(f)).first->second;
}

// The probe's cylinder: its axis is the prism axis whose cross-section is round (the dataset's
// tip.obj lies along y; a y-up export of it stands along z). Bounds as wide as tall and an area
// of pi r^2 within 5 %; y when none is.
UpAxis ProbeAxis(const std::string& path) {
  const Footprint along_y = CachedFootprint(path, UpAxis::kY);
  std::vector<UpAxis> candidates{UpAxis::kY};
  for (const UpAxis a : along_y.prism_axes)
    if (a != UpAxis::kY) candidates.push_back(a);
  for (const UpAxis a : candidates) {
    const Footprint f = CachedFootprint(path, a);
    if (std::find(f.prism_axes.begin(), f.prism_axes.end(), a) == f.prism_axes.end()) continue;
    const geometry::Box2 box = f.shape.bounds();
    const double w = box.max.x() - box.min.x(), h = box.max.y() - box.min.y(), r = 0.25 * (w + h);
    if (std::abs(w - h) <= 0.05 * std::max(w, h) && std::abs(f.shape.core_area() - M_PI * r * r) <= 0.05 * M_PI * r * r)
      return a;
  }
  return UpAxis::kY;
}

// An `obj` folder holding NAME.obj beside or above the recording (the dataset's layout:
// abs/ellip1/recording.h5 and obj/ellip1.obj).
std::string FindMeshDir(const std::string& recording, const std::string& name) {
  fs::path dir = fs::absolute(fs::path(recording)).parent_path();
  for (int up = 0; up < 4 && !dir.empty(); ++up) {
    if (fs::exists(dir / "obj" / (name + ".obj"))) return (dir / "obj").string();
    if (dir == dir.parent_path()) break;
    dir = dir.parent_path();
  }
  return "";
}

template <class Sample>
void Decimate(std::vector<Sample>* v, double t0, double rate) {
  std::vector<Sample> out;
  long long last_bin = std::numeric_limits<long long>::min();
  for (const Sample& s : *v) {
    const long long bin = static_cast<long long>(std::floor((s.t - t0) * rate));
    if (bin != last_bin) out.push_back(s);
    last_bin = bin;
  }
  *v = std::move(out);
}

}  // namespace

namespace internal {

// MIT object name from "..._shape=ellip1_..." or the folder name.
std::string MitGroup(const std::string& path) {
  static const std::regex re("shape=([A-Za-z0-9]+)");
  const std::string base = fs::path(path).filename().string();
  std::smatch m;
  if (std::regex_search(base, m, re)) return m[1];
  const std::string parent = fs::path(path).parent_path().filename().string();
  return parent.empty() ? "." : parent;
}

// An `obj` folder holding NAME.obj beside or above the recording (the dataset's layout:

push::Trajectory LoadCleanTrajectory(const EvaluationItem& item, const EvaluationOptions& o) {
  if (item.source == EvaluationItem::Source::kSimulated)
    return SimulatedPush(item.multi_contact_sim ? o.multi_contact_simulation : o.simulation, item.sim_index, o.seed);
  if (DetectInputKind(item.path) == InputKind::kTrajectory) {
    push::Trajectory t = io::LoadTrajectoryJson(item.path);
    if (t.ground_truth) t.measured = *t.ground_truth;  // the clean streams get the protocol's noise
    t.ground_truth = t.measured;
    return t;
  }
  return ReadMitTrajectory(item.path, *MitItemModel(item, o), o.mit_rate);
}

std::optional<ObjectModel> MitItemModel(const EvaluationItem& item, const EvaluationOptions& o) {
  if (item.source == EvaluationItem::Source::kSimulated || DetectInputKind(item.path) == InputKind::kTrajectory)
    return std::nullopt;
  if (o.object_override) return *o.object_override;
  if (auto it = o.objects.find(item.group); it != o.objects.end()) return it->second;
  std::string dir = o.mesh_dir.empty() ? FindMeshDir(item.path, item.group) : o.mesh_dir;
  if (dir.empty()) {
    throw EvaluationError(item.path + ": no mesh for object '" + item.group +
                  "' (no obj/" + item.group + ".obj beside or above it); give --mesh-dir, --object/--finger/--mass/--mu or an evaluation config");
  }
  return MitObjectModel(item.group, dir);
}

}  // namespace internal

push::Trajectory ReadMitTrajectory(const std::string& path, const ObjectModel& model, double rate,
                                   std::vector<std::string>* notes, bool trim) {
  io::MitReadOptions read;
  read.trim_to_contact = trim;
  read.contact_force = io::MitContactForce(model.object.mass, model.object.mu_surface);
  io::MitRecording rec = io::ReadMitPush(path, read);
  if (notes) notes->insert(notes->end(), rec.notes.begin(), rec.notes.end());
  if (!rec.contact_found) {
    // Nothing was pushed: the contact, force and quasi-static factors would be fitted to a
    // push that never happened (a finger far from a resting object).
    throw EvaluationError(path + ": no contact phase found (no force above the contact threshold and no object "
                          "motion): nothing was pushed, nothing to estimate");
  }
  if (rate > 0.0) {
    double t0 = std::numeric_limits<double>::infinity();
    for (const auto& s : rec.streams.object_pose) t0 = std::min(t0, s.t);
    for (const auto& s : rec.streams.finger_pose) t0 = std::min(t0, s.t);
    for (const auto& s : rec.streams.force) t0 = std::min(t0, s.t);
    Decimate(&rec.streams.object_pose, t0, rate);
    Decimate(&rec.streams.finger_pose, t0, rate);
    Decimate(&rec.streams.force, t0, rate);
  }
  // Time stamps stay the recording's own (unix seconds): ReadMitPush keeps them.
  return io::MitToTrajectory(rec, model.object, model.finger);
}

push::Trajectory LoadEstimationInput(const std::string& path, const InputOverrides& given,
                                     std::vector<std::string>* notes, InputKind* kind_out) {
  const InputKind kind = DetectInputKind(path);
  if (kind_out) *kind_out = kind;
  if (kind == InputKind::kTrajectory) {
    push::Trajectory t = io::LoadTrajectoryJson(path, notes);
    if (given.object_shape) t.object.shape = *given.object_shape;
    if (given.finger_shape) {
      t.finger.shape = *given.finger_shape;
      // Said, not silent: the file's other fingers keep their own shapes.
      if (notes != nullptr && !t.extra_fingers.empty())
        notes->push_back("--finger replaces finger 0's shape only; the file's other fingers keep their shapes");
    }
    if (given.mass) t.object.mass = *given.mass;
    if (given.mu_surface) t.object.mu_surface = *given.mu_surface;
    return t;
  }
  if (!given.object_shape || !given.finger_shape || !given.mass || !given.mu_surface) {
    throw EvaluationError(path + " is an MIT recording: give the object and probe with --object SHAPE.json --finger "
                          "SHAPE.json --mass KG --mu MU (e.g. shapes from `pushgraph footprint`, masses from the "
                          "dataset README)");
  }
  ObjectModel model;
  model.object.shape = *given.object_shape;
  model.object.mass = *given.mass;
  model.object.mu_surface = *given.mu_surface;
  model.finger.shape = *given.finger_shape;
  return ReadMitTrajectory(path, model, /*rate=*/0.0, notes, given.trim_to_contact);
}

push::NoiseModel MakePaperNoise(push::NoiseKind kind, const PaperNoise& s) {
  push::NoiseModel m;
  m.object_pose.position = {kind, s.position};
  m.object_pose.angle = {kind, s.rotation};
  m.finger_pose.position = {kind, s.position};
  m.contact_point.position = {kind, s.position};
  m.force.position = {kind, s.force};
  push::ValidateNoise(m);
  return m;
}

push::Trajectory AddNoise(const push::Trajectory& trajectory, const push::NoiseModel& noise, std::uint64_t seed) {
  if (!trajectory.ground_truth && trajectory.measurement_sigmas) {
    const push::MeasurementSigmas& m = *trajectory.measurement_sigmas;
    if (m.object_trans > 0 || m.object_rot > 0 || m.finger_trans > 0 || m.finger_rot > 0 || m.contact > 0 || m.force > 0) {
      throw EvaluationError("adding noise needs clean streams, but these streams already carry noise (measurement_sigmas) "
                    "and there is no ground_truth: the noise would be added twice and the metrics scored against "
                    "noisy streams");
    }
  }
  push::Trajectory t = trajectory;
  const push::Streams clean = trajectory.ground_truth ? *trajectory.ground_truth : trajectory.measured;
  t.ground_truth = clean;
  t.measured = push::ApplyNoise(clean, noise, seed);
  t.measurement_sigmas = push::SigmasOf(noise);
  // Every other finger's streams: the same noise model, their own draws.
  for (std::size_t k = 0; k < t.extra_fingers.size(); ++k) {
    push::ExtraFinger& e = t.extra_fingers[k];
    const push::FingerStreams truth = e.ground_truth ? *e.ground_truth : e.measured;
    push::Streams streams;
    streams.finger_pose = truth.finger_pose;
    streams.contact_point = truth.contact_point;
    streams.force = truth.force;
    const push::Streams noisy = push::ApplyNoise(streams, noise, SplitMix(seed ^ (0x9e3779b97f4a7c15ULL * (k + 1))));
    e.ground_truth = truth;
    e.measured = {noisy.finger_pose, noisy.contact_point, noisy.force};
  }
  return t;
}

InputKind DetectInputKind(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw EvaluationError(path + ": is a directory, not an input file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw EvaluationError(path + ": cannot open file");
  char magic[8] = {};
  in.read(magic, 8);
  if (in.gcount() == 8 && std::string(magic, 8) == std::string("\x89HDF\r\n\x1a\n", 8)) return InputKind::kMitRecording;
  in.clear();
  in.seekg(0);
  nlohmann::json doc;
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw EvaluationError(path + ": neither an HDF5 file nor valid JSON (" + geometry::JsonSyntaxErrorText(e.what(), text) + ")");
  } catch (const std::exception& e) {
    throw EvaluationError(path + ": cannot read the file (" + e.what() + ")");
  }
  if (doc.is_object() && doc.contains("format")) {
    if (doc["format"] == io::kTrajectoryFormat) return InputKind::kTrajectory;
    throw EvaluationError(path + ": unknown format " + doc["format"].dump() + " (expected \"" + io::kTrajectoryFormat + "\")");
  }
  if (doc.is_object() && doc.contains("tip_pose") && doc.contains("object_pose") && doc.contains("ft_wrench")) {
    if (fs::path(path).extension() != ".json") {
      throw EvaluationError(path + ": an MIT JSON recording must have the .json extension (the reader decides by it)");
    }
    return InputKind::kMitRecording;
  }
  throw EvaluationError(path + ": neither a pushgraph trajectory (\"format\": \"" + io::kTrajectoryFormat +
                "\") nor an MIT recording (HDF5, or JSON with tip_pose, object_pose, ft_wrench)");
}

std::optional<double> MitObjectMass(const std::string& name) {
  static const std::map<std::string, double> kMass = {
      {"rect1", 0.8374},  {"rect2", 1.045},  {"rect3", 1.2508}, {"ellip1", 0.8937}, {"ellip2", 1.1104}, {"ellip3", 1.3338},
      {"tri1", 0.8028},   {"tri2", 0.9826},  {"tri3", 1.1326},  {"hex", 0.9827},    {"butter", 1.1974}};
  auto it = kMass.find(name);
  if (it == kMass.end()) return std::nullopt;
  return it->second;
}

ObjectModel MitObjectModel(const std::string& name, const std::string& mesh_dir) {
  const std::optional<double> mass = MitObjectMass(name);
  if (!mass) {
    throw EvaluationError("unknown MIT object '" + name +
                  "' (known: rect1-3, ellip1-3, tri1-3, hex, butter); give its shape and mass");
  }
  ObjectModel m;
  const std::string mesh = (fs::path(mesh_dir) / (name + ".obj")).string();
  const Footprint top = CachedFootprint(mesh, UpAxis::kZ);
  m.object.shape = top.shape;
  for (const UpAxis a : top.prism_axes) {
    if (a == UpAxis::kZ) continue;
    m.other_readings.push_back(CachedFootprint(mesh, a).shape);
    m.reading_axes.push_back(AxisName(a));
  }
  // The probe is a cylinder: a disk of the mesh's radius (its footprint's vertices lie on the
  // circle). A disk, not the polygon: the intersection factor's obstacle (a Minkowski sum) then
  // does not depend on the relative rotation and is built once instead of at every new angle.
  const std::string probe = (fs::path(mesh_dir) / "tip.obj").string();
  const geometry::Box2 tip = CachedFootprint(probe, ProbeAxis(probe)).shape.bounds();
  m.finger.shape = geometry::Shape::Disk(0.25 * ((tip.max.x() - tip.min.x()) + (tip.max.y() - tip.min.y())));
  m.finger.mu_contact = 0.25;
  m.object.mass = *mass;
  m.object.mu_surface = 0.35;
  return m;
}

MultiContactPushKind MultiContactPushKindOf(int index) {
  switch (index % 4) {
    case 1: return MultiContactPushKind::kTwoFingers;
    case 3: return MultiContactPushKind::kFlatPusher;
    default: return MultiContactPushKind::kOneFinger;
  }
}

const char* MultiContactPushKindName(MultiContactPushKind kind) {
  switch (kind) {
    case MultiContactPushKind::kOneFinger: return "one-finger";
    case MultiContactPushKind::kTwoFingers: return "two-fingers";
    case MultiContactPushKind::kFlatPusher: return "flat-pusher";
  }
  return "?";
}

push::Trajectory SimulatedPush(const SimulationSpec& spec, int index, std::uint64_t seed) {
  push::PushPlan plan;
  plan.object = spec.object;
  plan.finger = spec.finger;
  plan.speed = spec.speed;
  plan.multi_contact = spec.multi_contact;
  const geometry::Box2 b = plan.object.shape.bounds();
  const double half = 0.5 * std::min(b.max.x() - b.min.x(), b.max.y() - b.min.y());
  const MultiContactPushKind kind = spec.multi_contact ? MultiContactPushKindOf(index) : MultiContactPushKind::kOneFinger;
  if (kind == MultiContactPushKind::kFlatPusher) {
    // The pusher frame turns with the push (finger_theta below): its y axis runs across it.
    const geometry::Box2 f = spec.finger.shape.bounds();
    plan.finger.shape = geometry::Shape::Box(std::max(f.max.x() - f.min.x(), 1e-3), 1.6 * half);
  }
  std::mt19937_64 rng(SplitMix(SplitMix(seed) ^ static_cast<std::uint64_t>(index)));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::string last_error;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double angle = 2.0 * M_PI * unit(rng);
    const double offset = spec.offset_fraction * half * (2.0 * unit(rng) - 1.0);
    if (kind != MultiContactPushKind::kOneFinger) plan.finger_theta = angle;
    if (kind == MultiContactPushKind::kTwoFingers) {
      // Two copies of the finger 0.8 half-extents apart, either side of the push line.
      plan.finger.shape = geometry::TransformShape(spec.finger.shape, geometry::Pose2{0.0, 0.4 * half, 0.0});
      plan.extra_fingers = {
          {geometry::TransformShape(spec.finger.shape, geometry::Pose2{0.0, -0.4 * half, 0.0}), spec.finger.mu_contact}};
    }
    try {
      plan.waypoints = push::StraightPushPath(plan, angle, offset, spec.standoff, spec.push_distance);
      push::Trajectory t = push::Simulate(plan).trajectory;
      t.measured = *t.ground_truth;
      t.measurement_sigmas.reset();
      for (push::ExtraFinger& e : t.extra_fingers) e.measured = *e.ground_truth;
      return t;
    } catch (const std::exception& e) {
      // A line that misses the object, or fingers that jam it: the next line.
      last_error = e.what();
    }
  }
  throw EvaluationError("simulated push " + std::to_string(index) + ": no push line hits the object (" + last_error + ")");
}

std::vector<std::string> ExpandInputs(const std::vector<std::string>& patterns) {
  std::set<std::string> files;
  auto add_dir = [&](const fs::path& dir) {
    for (const auto& e : fs::recursive_directory_iterator(dir, fs::directory_options::follow_directory_symlink)) {
      if (!e.is_regular_file()) continue;
      const std::string ext = e.path().extension().string();
      if (ext == ".h5" || ext == ".hdf5" || ext == ".json") files.insert(e.path().lexically_normal().string());
    }
  };
  for (const std::string& p : patterns) {
    if (fs::is_directory(p)) {
      add_dir(p);
    } else if (fs::is_regular_file(p)) {
      files.insert(fs::path(p).lexically_normal().string());
    } else if (p.find_first_of("*?[") != std::string::npos) {
      glob_t g{};
      const int rc = ::glob(p.c_str(), 0, nullptr, &g);
      if (rc != 0) {
        ::globfree(&g);
        throw EvaluationError("input pattern '" + p + "' matches no file");
      }
      for (std::size_t i = 0; i < g.gl_pathc; ++i) {
        const fs::path m(g.gl_pathv[i]);
        if (fs::is_directory(m)) add_dir(m);
        else if (fs::is_regular_file(m)) files.insert(m.lexically_normal().string());
      }
      ::globfree(&g);
    } else {
      throw EvaluationError("input '" + p + "': no such file or directory");
    }
  }
  return {files.begin(), files.end()};
}


}  // namespace pushgraph::evaluation
