// The evaluation workflow (evaluation.h): inputs, noise, per-trajectory statistics, tables,
// shards.
#include <pushgraph/geometry/file_output.h>
#include <pushgraph/io/evaluation.h>
#include <pushgraph/io/plot_svg.h>

#include <pushgraph/io/footprint.h>
#include <pushgraph/io/mit_push.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/limit_surface/simulator.h>

#include <Eigen/Cholesky>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <glob.h>
#include <unistd.h>

namespace pushgraph::io {
namespace {

namespace fs = std::filesystem;
namespace ls = limit_surface;
using geometry::Pose2;
using geometry::Vec2;

constexpr const char* kProtocolNames[] = {"table1", "table2", "fig5", "occlusion", "consistency", "runtime"};
constexpr double kGroundTruthGap = 0.1;      // s: interpolate ground truth only between closer samples
constexpr double kMovingSpeed = 2e-3;        // m/s (as io::MitReadOptions::moving_speed)
constexpr double kMovingAngularSpeed = 0.02; // rad/s
constexpr double kDirectionMinForce = 0.25;  // N: force directions below this are not compared

// Two-sided 95% interval of a chi-square variable with 2 and 3 degrees of freedom
// (quantiles 0.025 and 0.975; e.g. Bar-Shalom, Li, Kirubarajan 2001, Table 5.2 style values).
constexpr double kChi2Lo[4] = {0.0, 0.000982, 0.05064, 0.2158};
constexpr double kChi2Hi[4] = {0.0, 5.0239, 7.3778, 9.3484};

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

std::uint64_t Fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

bool HasProtocol(const std::vector<Protocol>& ps, Protocol p) { return std::find(ps.begin(), ps.end(), p) != ps.end(); }

// ---------------------------------------------------------------------------------------------
// Ground truth at a time: linear interpolation between samples at most kGroundTruthGap apart.
template <class Sample, class Get>
bool TruthAt(const std::vector<Sample>& s, double t, Get get, decltype(get(s[0]))* out) {
  return ls::StreamValueAt(s, t, kGroundTruthGap, get, out);
}

Eigen::Vector3d PoseVec(const ls::PoseSample& s) { return s.pose.vector(); }
Vec2 PointVec(const ls::PointSample& s) { return s.point; }
Vec2 ForceVec(const ls::ForceSample& s) { return s.force; }

bool ObjectMoving(const std::vector<ls::PoseSample>& gt, double t) {
  const double h = 0.01;
  Eigen::Vector3d a, b;
  double ta = t - h, tb = t + h;
  if (!TruthAt(gt, ta, PoseVec, &a)) {
    ta = t;
    if (!TruthAt(gt, ta, PoseVec, &a)) return false;
  }
  if (!TruthAt(gt, tb, PoseVec, &b)) {
    tb = t;
    if (!TruthAt(gt, tb, PoseVec, &b)) return false;
  }
  if (tb - ta <= 0.0) return false;
  const Eigen::Vector3d v = (b - a) / (tb - ta);
  return v.head<2>().norm() > kMovingSpeed || std::abs(v.z()) > kMovingAngularSpeed;
}

// ---------------------------------------------------------------------------------------------
// Sufficient statistics, stored as "PREFIX/QUANTITY/STAT".
class StatSink {
 public:
  explicit StatSink(std::map<std::string, double>* stats) : stats_(stats) {}
  void Error(const std::string& key, double e) {
    Add(key + "/n", 1.0);
    Add(key + "/sum", e);
    Add(key + "/abs", std::abs(e));
    Add(key + "/sq", e * e);
  }
  void Variance(const std::string& key, double var) {
    Add(key + "/var", var);
    Add(key + "/nvar", 1.0);
  }
  void Nees(const std::string& key, double nees, int dim) {
    Add(key + "/nees", nees);
    Add(key + "/nees_n", 1.0);
    Add(key + "/nees_in", (nees >= kChi2Lo[dim] && nees <= kChi2Hi[dim]) ? 1.0 : 0.0);
    (*stats_)[key + "/dim"] = dim;  // constant: aggregated as max
  }
  void Add(const std::string& key, double v) { (*stats_)[key] += v; }
  void Max(const std::string& key, double v) {
    auto [it, inserted] = stats_->emplace(key, v);
    if (!inserted) it->second = std::max(it->second, v);
  }

 private:
  std::map<std::string, double>* stats_;
};

template <int N>
double NeesOf(const Eigen::Matrix<double, N, 1>& e, const Eigen::Matrix<double, N, N>& cov) {
  return e.dot(cov.ldlt().solve(e));
}

double SignedAngle(const Vec2& a, const Vec2& b) {  // from b to a
  return std::atan2(b.x() * a.y() - b.y() * a.x(), b.dot(a));
}

struct Window {
  double t0 = 0.0, t1 = -1.0;
  bool Contains(double t) const { return t >= t0 && t <= t1; }
};

void AccumulateRun(const ls::Trajectory& traj, const graph::EstimationResult& r, const std::string& prefix,
                   const Window& occluded, StatSink& sink) {
  const ls::Streams& gt = *traj.ground_truth;
  for (const graph::StateEstimate& s : r.states) {
    Eigen::Vector3d g;
    if (TruthAt(gt.object_pose, s.t, PoseVec, &g)) {
      Eigen::Vector3d e(s.object_pose.x - g.x(), s.object_pose.y - g.y(), geometry::WrapAngle(s.object_pose.theta - g.z()));
      const double ep = e.head<2>().norm(), er = std::abs(e.z());
      sink.Error(prefix + "/object_position", ep);
      sink.Error(prefix + "/object_rotation", er);
      const bool moving = ObjectMoving(gt.object_pose, s.t);
      if (moving) {
        sink.Error(prefix + "/object_position_moving", ep);
        sink.Error(prefix + "/object_rotation_moving", er);
      }
      if (occluded.Contains(s.t)) {
        sink.Error(prefix + "/object_position_occluded", ep);
        sink.Error(prefix + "/object_rotation_occluded", er);
      } else if (occluded.t1 >= occluded.t0) {
        sink.Error(prefix + "/object_position_visible", ep);
        sink.Error(prefix + "/object_rotation_visible", er);
      }
      if (s.object_pose_cov) {
        const Eigen::Matrix3d& P = *s.object_pose_cov;
        sink.Variance(prefix + "/object_position", P(0, 0) + P(1, 1));
        sink.Variance(prefix + "/object_rotation", P(2, 2));
        if (moving) {
          sink.Variance(prefix + "/object_position_moving", P(0, 0) + P(1, 1));
          sink.Variance(prefix + "/object_rotation_moving", P(2, 2));
        }
        sink.Nees(prefix + "/object_pose", NeesOf<3>(e, P), 3);
      }
    }
    if (TruthAt(gt.finger_pose, s.t, PoseVec, &g)) {
      const Eigen::Vector2d e(s.finger_pose.x - g.x(), s.finger_pose.y - g.y());
      sink.Error(prefix + "/finger_position", e.norm());
      if (s.finger_pose_cov) {
        // Position block only: the finger's angle is not measured meaningfully (pinned).
        const Eigen::Matrix2d P = s.finger_pose_cov->topLeftCorner<2, 2>();
        sink.Variance(prefix + "/finger_position", P.trace());
        sink.Nees(prefix + "/finger_position", NeesOf<2>(e, P), 2);
      }
    }
    Vec2 v;
    if (s.contact && TruthAt(gt.contact_point, s.t, PointVec, &v)) {
      const Eigen::Vector2d e = *s.contact - v;
      sink.Error(prefix + "/contact", e.norm());
      if (s.contact_cov) {
        sink.Variance(prefix + "/contact", s.contact_cov->trace());
        sink.Nees(prefix + "/contact", NeesOf<2>(e, *s.contact_cov), 2);
      }
    }
    if (s.force && TruthAt(gt.force, s.t, ForceVec, &v)) {
      const Eigen::Vector2d e = *s.force - v;
      sink.Error(prefix + "/force", e.norm());
      sink.Error(prefix + "/force_magnitude", s.force->norm() - v.norm());
      if (v.norm() >= kDirectionMinForce) sink.Error(prefix + "/force_direction", SignedAngle(*s.force, v) * 180.0 / M_PI);
      if (s.force_cov) {
        sink.Variance(prefix + "/force", s.force_cov->trace());
        sink.Nees(prefix + "/force", NeesOf<2>(e, *s.force_cov), 2);
      }
    }
  }
  const graph::SolverStats& st = r.solver;
  sink.Add(prefix + "/time/sum", st.time_s);
  sink.Add(prefix + "/time/n", 1.0);
  sink.Max(prefix + "/time/max", st.time_s);
  sink.Add(prefix + "/steps/sum", static_cast<double>(r.states.size()));
  if (r.mode == graph::Mode::kIncremental && st.updates > 0) {
    sink.Add(prefix + "/update_time/sum", st.mean_update_time_s * st.updates);
    sink.Add(prefix + "/update_time/n", st.updates);
    sink.Max(prefix + "/update_time/max", st.max_update_time_s);
  }
}

// The raw measurements against the same ground truth.
void AccumulateRaw(const ls::Trajectory& traj, const std::string& prefix, StatSink& sink) {
  const ls::Streams& gt = *traj.ground_truth;
  const ls::Streams& m = traj.measured;
  for (const ls::PoseSample& s : m.object_pose) {
    Eigen::Vector3d g;
    if (!TruthAt(gt.object_pose, s.t, PoseVec, &g)) continue;
    const double ep = std::hypot(s.pose.x - g.x(), s.pose.y - g.y());
    const double er = std::abs(geometry::WrapAngle(s.pose.theta - g.z()));
    sink.Error(prefix + "/object_position", ep);
    sink.Error(prefix + "/object_rotation", er);
    if (ObjectMoving(gt.object_pose, s.t)) {
      sink.Error(prefix + "/object_position_moving", ep);
      sink.Error(prefix + "/object_rotation_moving", er);
    }
  }
  for (const ls::PoseSample& s : m.finger_pose) {
    Eigen::Vector3d g;
    if (TruthAt(gt.finger_pose, s.t, PoseVec, &g)) sink.Error(prefix + "/finger_position", std::hypot(s.pose.x - g.x(), s.pose.y - g.y()));
  }
  for (const ls::PointSample& s : m.contact_point) {
    Vec2 v;
    if (TruthAt(gt.contact_point, s.t, PointVec, &v)) sink.Error(prefix + "/contact", (s.point - v).norm());
  }
  for (const ls::ForceSample& s : m.force) {
    Vec2 v;
    if (!TruthAt(gt.force, s.t, ForceVec, &v)) continue;
    sink.Error(prefix + "/force", (s.force - v).norm());
    sink.Error(prefix + "/force_magnitude", s.force.norm() - v.norm());
    if (v.norm() >= kDirectionMinForce) sink.Error(prefix + "/force_direction", SignedAngle(s.force, v) * 180.0 / M_PI);
  }
}

// ---------------------------------------------------------------------------------------------
// Inputs.

std::mutex g_footprint_mutex;
std::map<std::string, geometry::Shape> g_footprints;  // mesh path + axis -> footprint

geometry::Shape CachedFootprint(const std::string& path, UpAxis up) {
  const std::string key = path + (up == UpAxis::kY ? "#y" : "#z");
  {
    std::lock_guard<std::mutex> lock(g_footprint_mutex);
    auto it = g_footprints.find(key);
    if (it != g_footprints.end()) return it->second;
  }
  FootprintOptions o;
  o.up = up;
  geometry::Shape s = MeshFootprint(path, o);
  std::lock_guard<std::mutex> lock(g_footprint_mutex);
  return g_footprints.emplace(key, std::move(s)).first->second;
}

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

ls::Trajectory LoadCleanTrajectory(const EvaluationItem& item, const EvaluationOptions& o) {
  if (item.source == EvaluationItem::Source::kSimulated) return SimulatedPush(o.simulation, item.sim_index, o.seed);
  if (DetectInputKind(item.path) == InputKind::kTrajectory) {
    ls::Trajectory t = LoadTrajectoryJson(item.path);
    if (t.ground_truth) t.measured = *t.ground_truth;  // the clean streams get the protocol's noise
    t.ground_truth = t.measured;
    return t;
  }
  MitReadOptions ro;
  ro.trim_to_contact = true;
  MitRecording rec = ReadMitPush(item.path, ro);
  if (!rec.contact_found) throw IoError(item.path + ": no contact phase found (no force above 0.3 N, no object motion)");
  if (o.mit_rate > 0.0) {
    double t0 = std::numeric_limits<double>::infinity();
    for (const auto& s : rec.streams.object_pose) t0 = std::min(t0, s.t);
    for (const auto& s : rec.streams.finger_pose) t0 = std::min(t0, s.t);
    for (const auto& s : rec.streams.force) t0 = std::min(t0, s.t);
    Decimate(&rec.streams.object_pose, t0, o.mit_rate);
    Decimate(&rec.streams.finger_pose, t0, o.mit_rate);
    Decimate(&rec.streams.force, t0, o.mit_rate);
  }
  ObjectModel model;
  if (o.object_override) {
    model = *o.object_override;
  } else if (auto it = o.objects.find(item.group); it != o.objects.end()) {
    model = it->second;
  } else {
    std::string dir = o.mesh_dir.empty() ? FindMeshDir(item.path, item.group) : o.mesh_dir;
    if (dir.empty()) {
      throw IoError(item.path + ": no mesh for object '" + item.group +
                    "' (no obj/" + item.group + ".obj beside or above it); give --mesh-dir, --object/--finger/--mass/--mu or an evaluation config");
    }
    model = MitObjectModel(item.group, dir);
  }
  ls::ObjectDescription object{model.shape, model.mass, model.mu_surface, "uniform"};
  ls::FingerDescription finger{model.finger, model.mu_contact};
  return MitToTrajectory(rec, object, finger);
}

Window OcclusionWindow(const ls::Trajectory& clean, double fraction) {
  const ls::Streams& gt = *clean.ground_truth;
  double a = 0.0, b = -1.0;
  if (!gt.contact_point.empty()) {
    a = gt.contact_point.front().t;
    b = gt.contact_point.back().t;
  } else if (!gt.object_pose.empty()) {
    a = gt.object_pose.front().t;
    b = gt.object_pose.back().t;
  }
  const double mid = 0.5 * (a + b), half = 0.5 * fraction * (b - a);
  return {mid - half, mid + half};
}

struct RunSpec {
  std::string noise;  // "gauss", "bimodal", "occluded"
  graph::Model model;
  graph::Mode mode;
  bool covariance;
  std::string Prefix() const { return noise + "." + graph::ModelName(model) + "." + graph::ModeName(mode); }
};

std::vector<RunSpec> RunsFor(const std::vector<Protocol>& ps, graph::Mode occlusion_mode) {
  using graph::Mode;
  using graph::Model;
  const bool t1 = HasProtocol(ps, Protocol::kTable1), t2 = HasProtocol(ps, Protocol::kTable2),
             f5 = HasProtocol(ps, Protocol::kFig5), oc = HasProtocol(ps, Protocol::kOcclusion),
             cons = HasProtocol(ps, Protocol::kConsistency), rt = HasProtocol(ps, Protocol::kRuntime);
  std::vector<RunSpec> runs;
  auto add = [&](const std::string& noise, Model model, Mode mode, bool cov) {
    for (RunSpec& r : runs) {
      if (r.noise == noise && r.model == model && r.mode == mode) {
        r.covariance = r.covariance || cov;
        return;
      }
    }
    runs.push_back({noise, model, mode, cov});
  };
  const Model all[] = {Model::kCp, Model::kSdf, Model::kQs, Model::kYu};
  if (t1) add("gauss", Model::kQs, Mode::kBatch, true);
  if (f5) {
    for (Model m : all) add("gauss", m, Mode::kBatch, cons);
    for (Model m : all) add("gauss", m, Mode::kIncremental, cons);
  }
  if (cons && !f5) {
    for (Model m : all) add("gauss", m, Mode::kBatch, true);
  }
  if (rt && !f5) {
    add("gauss", Model::kQs, Mode::kBatch, false);
    add("gauss", Model::kQs, Mode::kIncremental, false);
  }
  if (t2) add("bimodal", Model::kQs, Mode::kBatch, false);
  if (oc) {
    for (Model m : all) add("occluded", m, occlusion_mode, false);
  }
  return runs;
}

std::string Fmt(double v, int digits = 4) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

std::vector<Protocol> ParseProtocols(const std::string& list) {
  std::set<int> chosen;
  std::stringstream ss(list);
  std::string item;
  bool any = false;
  while (std::getline(ss, item, ',')) {
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty()) continue;
    any = true;
    if (item == "all") {
      for (int i = 0; i < 6; ++i) chosen.insert(i);
      continue;
    }
    int found = -1;
    for (int i = 0; i < 6; ++i) {
      if (item == kProtocolNames[i]) found = i;
    }
    if (found < 0) {
      throw IoError("unknown protocol '" + item + "' (known: table1, table2, fig5, occlusion, consistency, runtime, all)");
    }
    chosen.insert(found);
  }
  if (!any) throw IoError("no protocol given (known: table1, table2, fig5, occlusion, consistency, runtime, all)");
  std::vector<Protocol> out;
  for (int i : chosen) out.push_back(static_cast<Protocol>(i));
  return out;
}

std::string ProtocolName(Protocol p) { return kProtocolNames[static_cast<int>(p)]; }

ls::NoiseModel MakePaperNoise(ls::NoiseKind kind, const PaperNoise& s) {
  ls::NoiseModel m;
  m.object_pose.position = {kind, s.position};
  m.object_pose.angle = {kind, s.rotation};
  m.finger_pose.position = {kind, s.position};
  m.contact_point.position = {kind, s.position};
  m.force.position = {kind, s.force};
  ls::ValidateNoise(m);
  return m;
}

ls::Trajectory AddNoise(const ls::Trajectory& trajectory, const ls::NoiseModel& noise, std::uint64_t seed) {
  if (!trajectory.ground_truth && trajectory.measurement_sigmas) {
    const ls::MeasurementSigmas& m = *trajectory.measurement_sigmas;
    if (m.object_trans > 0 || m.object_rot > 0 || m.finger_trans > 0 || m.finger_rot > 0 || m.contact > 0 || m.force > 0) {
      throw IoError("adding noise needs clean streams, but these streams already carry noise (measurement_sigmas) "
                    "and there is no ground_truth: the noise would be added twice and the metrics scored against "
                    "noisy streams");
    }
  }
  ls::Trajectory t = trajectory;
  const ls::Streams clean = trajectory.ground_truth ? *trajectory.ground_truth : trajectory.measured;
  t.ground_truth = clean;
  t.measured = ls::ApplyNoise(clean, noise, seed);
  t.measurement_sigmas = ls::SigmasOf(noise);
  return t;
}

InputKind DetectInputKind(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, not an input file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open file");
  char magic[8] = {};
  in.read(magic, 8);
  if (in.gcount() == 8 && std::string(magic, 8) == std::string("\x89HDF\r\n\x1a\n", 8)) return InputKind::kMitRecording;
  in.clear();
  in.seekg(0);
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path + ": neither an HDF5 file nor valid JSON (" + e.what() + ")");
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot read the file (" + e.what() + ")");
  }
  if (doc.is_object() && doc.contains("format")) {
    if (doc["format"] == kTrajectoryFormat) return InputKind::kTrajectory;
    throw IoError(path + ": unknown format " + doc["format"].dump() + " (expected \"" + kTrajectoryFormat + "\")");
  }
  if (doc.is_object() && doc.contains("tip_pose") && doc.contains("object_pose") && doc.contains("ft_wrench")) {
    if (fs::path(path).extension() != ".json") {
      throw IoError(path + ": an MIT JSON recording must have the .json extension (the reader decides by it)");
    }
    return InputKind::kMitRecording;
  }
  throw IoError(path + ": neither a pushgraph trajectory (\"format\": \"" + kTrajectoryFormat +
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
    throw IoError("unknown MIT object '" + name +
                  "' (known: rect1-3, ellip1-3, tri1-3, hex, butter); give its shape and mass");
  }
  ObjectModel m;
  m.shape = CachedFootprint((fs::path(mesh_dir) / (name + ".obj")).string(), UpAxis::kZ);
  // The probe is a cylinder: a disk of the mesh's radius (its footprint's vertices lie on the
  // circle). A disk, not the polygon: the intersection factor's obstacle (a Minkowski sum) then
  // does not depend on the relative rotation and is built once instead of at every new angle.
  const geometry::Box2 tip = CachedFootprint((fs::path(mesh_dir) / "tip.obj").string(), UpAxis::kY).bounds();
  m.finger = geometry::Shape::Disk(0.25 * ((tip.max.x() - tip.min.x()) + (tip.max.y() - tip.min.y())));
  m.mass = *mass;
  m.mu_surface = 0.35;
  m.mu_contact = 0.25;
  return m;
}

ls::Trajectory SimulatedPush(const SimulationSpec& spec, int index, std::uint64_t seed) {
  ls::PushPlan plan;
  plan.object = spec.object.shape;
  plan.finger = spec.object.finger;
  plan.mass = spec.object.mass;
  plan.mu_surface = spec.object.mu_surface;
  plan.mu_contact = spec.object.mu_contact;
  plan.speed = spec.speed;
  const geometry::Box2 b = plan.object.bounds();
  const double half = 0.5 * std::min(b.max.x() - b.min.x(), b.max.y() - b.min.y());
  std::mt19937_64 rng(SplitMix(SplitMix(seed) ^ static_cast<std::uint64_t>(index)));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::string last_error;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const double angle = 2.0 * M_PI * unit(rng);
    const double offset = spec.offset_fraction * half * (2.0 * unit(rng) - 1.0);
    try {
      plan.waypoints = ls::StraightPushPath(plan, angle, offset, spec.standoff, spec.push_distance);
    } catch (const std::exception& e) {
      last_error = e.what();
      continue;
    }
    ls::Trajectory t = ls::Simulate(plan).trajectory;
    t.measured = *t.ground_truth;
    t.measurement_sigmas.reset();
    return t;
  }
  throw IoError("simulated push " + std::to_string(index) + ": no push line hits the object (" + last_error + ")");
}

std::string EvaluationOptions::SettingsJson() const {
  nlohmann::json j;
  std::vector<std::string> ps;
  for (Protocol p : protocols) ps.push_back(ProtocolName(p));
  j["protocols"] = ps;
  j["noise"] = {{"position_m", noise.position}, {"rotation_rad", noise.rotation}, {"force_N", noise.force}};
  j["seed"] = seed;
  j["mit_rate_hz"] = mit_rate;
  j["occlusion_fraction"] = occlusion_fraction;
  j["occlusion_mode"] = graph::ModeName(occlusion_mode);
  const char* align[] = {"auto", "on", "off"};
  j["align_shape"] = align[static_cast<int>(estimator.align_shape)];
  j["simulate"] = {{"count", simulation.count},          {"name", simulation.name},
                   {"push_distance", simulation.push_distance}, {"speed", simulation.speed},
                   {"offset_fraction", simulation.offset_fraction}, {"mass", simulation.object.mass},
                   {"mu_surface", simulation.object.mu_surface}, {"mu_contact", simulation.object.mu_contact}};
  return j.dump();
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
        throw IoError("input pattern '" + p + "' matches no file");
      }
      for (std::size_t i = 0; i < g.gl_pathc; ++i) {
        const fs::path m(g.gl_pathv[i]);
        if (fs::is_directory(m)) add_dir(m);
        else if (fs::is_regular_file(m)) files.insert(m.lexically_normal().string());
      }
      ::globfree(&g);
    } else {
      throw IoError("input '" + p + "': no such file or directory");
    }
  }
  return {files.begin(), files.end()};
}

std::vector<EvaluationItem> PlanEvaluation(const std::vector<std::string>& files, const EvaluationOptions& options) {
  std::vector<EvaluationItem> items;
  std::map<std::string, int> basenames;
  for (const std::string& f : files) ++basenames[fs::path(f).filename().string()];
  for (const std::string& f : files) {
    EvaluationItem it;
    it.index = static_cast<int>(items.size());
    const std::string base = fs::path(f).filename().string();
    it.name = basenames[base] > 1 ? f : base;
    it.path = f;
    it.group = MitGroup(f);
    it.source = EvaluationItem::Source::kFile;
    items.push_back(it);
  }
  for (int i = 0; i < options.simulation.count; ++i) {
    EvaluationItem it;
    it.index = static_cast<int>(items.size());
    char name[32];
    std::snprintf(name, sizeof name, "sim-%04d", i);
    it.name = name;
    it.group = options.simulation.name;
    it.source = EvaluationItem::Source::kSimulated;
    it.sim_index = i;
    items.push_back(it);
  }
  std::map<std::string, int> plotted;
  for (EvaluationItem& it : items) it.plot = plotted[it.group]++ < options.plots_per_group;
  return items;
}

std::vector<std::string> RegisterGroups(std::vector<EvaluationItem>& items, const EvaluationOptions& options) {
  using Align = graph::EstimatorConfig::AlignShape;
  std::vector<std::string> lines;
  if (options.estimator.align_shape == Align::kOff) return lines;
  std::map<std::string, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (items[i].source == EvaluationItem::Source::kFile) groups[items[i].group].push_back(i);
  }
  for (const auto& [group, members] : groups) {
    std::vector<ls::Trajectory> clean;
    for (std::size_t i : members) {
      try {
        clean.push_back(LoadCleanTrajectory(items[i], options));
      } catch (const std::exception&) {
        // Unreadable: its own row will say so.
      }
    }
    if (clean.empty()) continue;
    std::vector<const ls::Trajectory*> pooled;
    for (const ls::Trajectory& t : clean) pooled.push_back(&t);
    graph::RegistrationOptions ro = graph::RegistrationOptionsFor(options.estimator);
    ro.estimate_scale = options.estimator.align_scale;
    try {
      const graph::RegistrationResult r = graph::RegisterShape(pooled, ro);
      const bool align = options.estimator.align_shape == Align::kOn || !r.fits_as_given;
      char head[160];
      std::snprintf(head, sizeof head, "%s: shape checked against %zu recordings together: ", group.c_str(), pooled.size());
      if (align) {
        for (std::size_t i : members) items[i].shape_transform = r.transform;
        lines.push_back(head + std::string(r.fits_as_given ? "fits as given; aligned anyway (align_shape on): "
                                                           : "does not fit as given (" + r.check.Describe() + "); aligned: ") +
                        r.Describe());
      } else {
        lines.push_back(head + std::string("fits as given (") + r.check.Describe() + ")");
      }
    } catch (const std::exception& e) {
      // Different shapes in one group (trajectory files), or too few contacts: each estimate
      // still checks its own shape.
      lines.push_back(group + ": no group registration (" + e.what() + "); each trajectory is checked on its own");
    }
  }
  return lines;
}

std::pair<int, int> ParseShard(const std::string& text) {
  static const std::regex re("^([0-9]+)/([0-9]+)$");
  std::smatch m;
  if (!std::regex_match(text, m, re)) throw IoError("bad shard '" + text + "': expected K/N with 0 <= K < N, e.g. 0/4");
  const long k = std::stol(m[1]), n = std::stol(m[2]);
  if (n < 1 || k >= n || n > 1000000) throw IoError("bad shard '" + text + "': expected K/N with 0 <= K < N, e.g. 0/4");
  return {static_cast<int>(k), static_cast<int>(n)};
}

std::vector<EvaluationItem> ShardItems(const std::vector<EvaluationItem>& items, int shard, int shards) {
  std::vector<EvaluationItem> out;
  for (const EvaluationItem& it : items) {
    if (it.index % shards == shard) out.push_back(it);
  }
  return out;
}

namespace {

// The paper's Fig. 3 / Fig. 5 (and Fig. 6 for the occluded push) for one item: the QS trajectory
// above the object error over time of raw and every model that ran in batch.
void WriteItemPlots(const EvaluationItem& item, const std::string& dir, const std::map<std::string, ls::Trajectory>& noisy,
                    const std::map<std::string, graph::EstimationResult>& results, const Window& window) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir + ": cannot create the plot folder (" + ec.message() + ")");
  std::string group = item.group;
  for (char& c : group) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  for (const auto& [noise, suffix] : {std::pair<std::string, std::string>{"gauss", "fig3"}, {"occluded", "occlusion"}}) {
    const auto qs = results.find(noise + ".qs.batch");
    if (qs == results.end()) continue;
    const ls::Trajectory& traj = noisy.at(noise);
    std::vector<std::pair<std::string, const graph::EstimationResult*>> models;
    for (const auto& [model, label] : {std::pair<const char*, const char*>{"cp", "CP"}, {"sdf", "SDF"}, {"qs", "QS"},
                                        {"yu", "Yu-Rodriguez"}}) {
      const auto it = results.find(noise + "." + model + ".batch");
      if (it != results.end()) models.emplace_back(label, &it->second);
    }
    TrajectoryPlotOptions options;
    options.error_panel = false;
    options.title = item.group + " push " + std::to_string(item.index) + ": QS batch" +
                    (noise == "occluded" ? ", object stream occluded" : "");
    // Unix time stamps (MIT recordings) are plotted from the first sample by TimeSeriesSvg itself.
    std::vector<std::pair<double, double>> shaded;
    if (noise == "occluded") shaded.emplace_back(window.t0, window.t1);
    const std::string svg = StackSvgVertically(
        {TrajectorySvg(traj, qs->second, options),
         TimeSeriesSvg(ObjectPositionErrorSeries(traj, models), "object position error over time", "error [mm]",
                       shaded)});
    const std::string name = group + "-" + std::to_string(item.index) + "-" + suffix + ".svg";
    WriteSvgFile((fs::path(dir) / name).string(), svg);
  }
}

}  // namespace

EvaluationRow EvaluateItem(const EvaluationItem& item, const EvaluationOptions& o) {
  EvaluationRow row;
  row.index = item.index;
  row.name = item.name;
  row.group = item.group;
  const std::string where = item.path.empty() ? item.name : item.path;
  std::string stage = "reading";
  try {
    ls::Trajectory clean = LoadCleanTrajectory(item, o);
    if (item.shape_transform) {
      const graph::ShapeTransform& t = *item.shape_transform;
      clean.object.shape = geometry::TransformShape(clean.object.shape, t.pose, t.scale, t.mirrored);
      row.stats["shape/group_aligned/sum"] = 1.0;
    }
    const std::uint64_t item_seed = SplitMix(o.seed ^ Fnv1a(item.name));
    const std::vector<RunSpec> runs = RunsFor(o.protocols, o.occlusion_mode);
    StatSink sink(&row.stats);
    std::map<std::string, ls::Trajectory> noisy;
    Window window;
    for (const RunSpec& run : runs) {
      if (noisy.count(run.noise)) continue;
      if (run.noise == "bimodal") {
        noisy[run.noise] = AddNoise(clean, MakePaperNoise(ls::NoiseKind::kBimodal, o.noise), SplitMix(item_seed + 2));
      } else {
        ls::Trajectory t = AddNoise(clean, MakePaperNoise(ls::NoiseKind::kGaussian, o.noise), SplitMix(item_seed + 1));
        if (run.noise == "occluded") {
          window = OcclusionWindow(clean, o.occlusion_fraction);
          auto& v = t.measured.object_pose;
          v.erase(std::remove_if(v.begin(), v.end(), [&](const ls::PoseSample& s) { return window.Contains(s.t); }), v.end());
        }
        noisy[run.noise] = std::move(t);
      }
      AccumulateRaw(noisy[run.noise], run.noise + ".raw", sink);
    }
    const bool plot = item.plot && !o.plot_dir.empty();
    std::map<std::string, graph::EstimationResult> kept;  // batch results, for the pictures
    for (const RunSpec& run : runs) {
      stage = run.Prefix();
      const ls::Trajectory& t = noisy.at(run.noise);
      graph::EstimatorConfig cfg = graph::ApplyMeasurementSigmas(o.estimator, *t.measurement_sigmas);
      cfg.covariance = run.covariance;
      if (run.mode == graph::Mode::kIncremental) cfg.estimate_c = cfg.estimate_mu = false;  // batch only
      // One self-diagnosis per trajectory: of the QS batch Gaussian run, else of the first run.
      const bool diagnosed = run.Prefix() == "gauss.qs.batch" ||
                             (&run == &runs.front() && std::none_of(runs.begin(), runs.end(), [](const RunSpec& x) {
                                return x.Prefix() == "gauss.qs.batch";
                              }));
      cfg.diagnostics = diagnosed;
      graph::EstimationResult r = graph::Estimate(t, run.model, run.mode, cfg);
      if (diagnosed) {
        if (r.diagnostics) {
          row.health = r.diagnostics->score;
          row.worst_factor = r.diagnostics->worst_factor;
        }
        row.notes = r.warnings;
        if (r.shape_alignment && r.shape_alignment->aligned) row.stats["shape/run_aligned/sum"] = 1.0;
      }
      if (r.shape_alignment && r.shape_alignment->aligned) row.stats[run.Prefix() + "/aligned/sum"] = 1.0;
      AccumulateRun(t, r, run.Prefix(), run.noise == "occluded" ? window : Window{}, sink);
      if (row.steps == 0) row.steps = static_cast<int>(r.states.size());
      if (plot && run.mode == graph::Mode::kBatch) kept.emplace(run.Prefix(), std::move(r));
    }
    if (plot) {
      stage = "plots";
      WriteItemPlots(item, o.plot_dir, noisy, kept, window);
    }
  } catch (const std::exception& e) {
    row.stats.clear();
    const std::string what = e.what();
    // Most messages already name the file; add it when they do not.
    row.error = (what.find(where) == std::string::npos ? where + ": " : std::string()) + stage + ": " + what;
  }
  return row;
}

std::vector<EvaluationRow> RunEvaluation(const std::vector<EvaluationItem>& items, const EvaluationOptions& options,
                                         int threads, const EvaluationProgress& progress) {
  std::vector<EvaluationRow> rows(items.size());
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  threads = std::min<int>(threads, std::max<std::size_t>(1, items.size()));
  std::atomic<std::size_t> next{0};
  std::mutex mutex;
  int finished = 0, failed = 0;
  auto worker = [&] {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= items.size()) return;
      rows[i] = EvaluateItem(items[i], options);
      std::lock_guard<std::mutex> lock(mutex);
      ++finished;
      if (!rows[i].error.empty()) ++failed;
      if (progress) progress(finished, static_cast<int>(items.size()), failed, rows[i]);
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  return rows;
}

// ---------------------------------------------------------------------------------------------
// Rows files.

namespace {
nlohmann::json RowJson(const EvaluationRow& r) {
  nlohmann::json j = {{"index", r.index}, {"name", r.name}, {"group", r.group}, {"steps", r.steps}};
  if (!r.error.empty()) j["error"] = r.error;
  j["stats"] = r.stats;
  if (r.health > 0.0) j["health"] = r.health;
  if (!r.worst_factor.empty()) j["worst_factor"] = r.worst_factor;
  if (!r.notes.empty()) j["notes"] = r.notes;
  return j;
}
}  // namespace

void AppendRow(const std::string& path, const EvaluationRow& row) {
  const std::string line = RowJson(row).dump() + "\n";
  FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) throw IoError(path + ": cannot append a row");
  const bool ok = std::fwrite(line.data(), 1, line.size(), f) == line.size() && std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  std::fclose(f);
  if (!ok) throw IoError(path + ": cannot append a row (disk full?)");
}

void WriteRows(const std::string& path, const RowsHeader& header, const std::vector<EvaluationRow>& rows) {
  std::ostringstream out;
  nlohmann::json h = {{"pushgraph_evaluation_rows", 1},
                      {"shard", header.shard},
                      {"shards", header.shards},
                      {"items_total", header.items_total},
                      {"settings", nlohmann::json::parse(header.settings_json)}};
  out << h.dump() << "\n";
  for (const EvaluationRow& r : rows) out << RowJson(r).dump() << "\n";
  if (const std::string error = geometry::WriteFileAtomically(path, out.str()); !error.empty()) throw IoError(error);
}

std::vector<EvaluationRow> ReadRows(const std::string& path, RowsHeader* header, bool cut_last_line_ok) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot open rows file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (cut_last_line_ok && !text.empty() && text.back() != '\n') {
    // A kill during an append leaves a partial last line: drop it unless it is complete JSON.
    const std::size_t start = text.rfind('\n') + 1;  // npos + 1 == 0: a single line
    if (start > 0 && !nlohmann::json::accept(text.substr(start))) text.erase(start);
  }
  std::istringstream lines(text);
  std::vector<EvaluationRow> rows;
  std::string line;
  int line_no = 0;
  while (std::getline(lines, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::string at = path + ":" + std::to_string(line_no) + ": ";
    try {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (line_no == 1) {
        if (!j.contains("pushgraph_evaluation_rows")) throw IoError(at + "not a pushgraph evaluation rows file (no header)");
        header->shard = j.at("shard").get<int>();
        header->shards = j.at("shards").get<int>();
        header->items_total = j.at("items_total").get<int>();
        header->settings_json = j.at("settings").dump();
        continue;
      }
      EvaluationRow r;
      r.index = j.at("index").get<int>();
      r.name = j.at("name").get<std::string>();
      r.group = j.at("group").get<std::string>();
      r.steps = j.at("steps").get<int>();
      if (j.contains("error")) r.error = j["error"].get<std::string>();
      r.stats = j.at("stats").get<std::map<std::string, double>>();
      if (j.contains("health")) r.health = j["health"].get<double>();
      if (j.contains("worst_factor")) r.worst_factor = j["worst_factor"].get<std::string>();
      if (j.contains("notes")) r.notes = j["notes"].get<std::vector<std::string>>();
      rows.push_back(std::move(r));
    } catch (const nlohmann::json::exception& e) {
      throw IoError(at + e.what());
    }
  }
  if (line_no == 0) throw IoError(path + ": empty rows file");
  return rows;
}

std::vector<EvaluationRow> MergeRows(const std::vector<std::string>& paths, RowsHeader* header) {
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    if (fs::is_directory(p)) {
      std::vector<std::string> found;
      for (const auto& e : fs::directory_iterator(p)) {
        const std::string n = e.path().filename().string();
        if (e.is_regular_file() && n.rfind("rows", 0) == 0 && e.path().extension() == ".jsonl") found.push_back(e.path().string());
      }
      if (found.empty()) throw IoError(p + ": no rows*.jsonl file in this folder");
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(p)) {
      files.push_back(p);
    } else {
      throw IoError(p + ": no such file or folder");
    }
  }
  if (files.empty()) throw IoError("merge: no rows files given");
  std::vector<EvaluationRow> all;
  std::map<int, std::string> shard_file;
  RowsHeader first;
  for (std::size_t i = 0; i < files.size(); ++i) {
    RowsHeader h;
    std::vector<EvaluationRow> rows = ReadRows(files[i], &h);
    if (i == 0) {
      first = h;
    } else {
      if (h.settings_json != first.settings_json)
        throw IoError(files[i] + ": its settings differ from " + files[0] + "'s (different runs cannot be merged)");
      if (h.shards != first.shards || h.items_total != first.items_total)
        throw IoError(files[i] + ": shard count or item count differs from " + files[0] + "'s");
    }
    if (auto [it, inserted] = shard_file.emplace(h.shard, files[i]); !inserted)
      throw IoError("shard " + std::to_string(h.shard) + "/" + std::to_string(h.shards) + " given twice: " + it->second + " and " + files[i]);
    for (const EvaluationRow& r : rows) {
      if (r.index % h.shards != h.shard)
        throw IoError(files[i] + ": item " + std::to_string(r.index) + " does not belong to shard " + std::to_string(h.shard));
    }
    all.insert(all.end(), rows.begin(), rows.end());
  }
  for (int k = 0; k < first.shards; ++k) {
    if (!shard_file.count(k))
      throw IoError("shard " + std::to_string(k) + "/" + std::to_string(first.shards) + " is missing");
  }
  std::sort(all.begin(), all.end(), [](const EvaluationRow& a, const EvaluationRow& b) { return a.index < b.index; });
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].index == all[i - 1].index) throw IoError("item " + std::to_string(all[i].index) + " appears twice");
  }
  if (static_cast<int>(all.size()) != first.items_total)
    throw IoError("merge: " + std::to_string(all.size()) + " rows but the run had " + std::to_string(first.items_total) + " items");
  first.shard = 0;
  *header = first;
  return all;
}

// ---------------------------------------------------------------------------------------------
// Tables.
namespace {

struct Agg {
  const std::map<std::string, double>* s;
  double Get(const std::string& k) const {
    auto it = s->find(k);
    return it == s->end() ? 0.0 : it->second;
  }
  bool Has(const std::string& k) const { return Get(k + "/n") > 0.0; }
  double N(const std::string& k) const { return Get(k + "/n"); }
  double Rms(const std::string& k) const { return std::sqrt(Get(k + "/sq") / N(k)); }
  double Mae(const std::string& k) const { return Get(k + "/abs") / N(k); }
  double Mean(const std::string& k) const { return Get(k + "/sum") / N(k); }
  double Std(const std::string& k) const {
    const double m = Mean(k);
    return std::sqrt(std::max(0.0, Get(k + "/sq") / N(k) - m * m));
  }
  bool HasSigma(const std::string& k) const { return Get(k + "/nvar") > 0.0; }
  double Sigma(const std::string& k) const { return std::sqrt(Get(k + "/var") / Get(k + "/nvar")); }
};

}  // namespace

std::vector<Table> MakeTables(std::vector<EvaluationRow> rows, const std::string& settings_json) {
  const nlohmann::json settings = nlohmann::json::parse(settings_json);
  std::vector<Protocol> protocols;
  for (const auto& p : settings.at("protocols")) protocols.push_back(ParseProtocols(p.get<std::string>()).front());
  std::sort(rows.begin(), rows.end(), [](const EvaluationRow& a, const EvaluationRow& b) { return a.index < b.index; });

  // Sum (or max) per group, in item order: the same order for any sharding.
  std::map<std::string, std::map<std::string, double>> groups;
  std::map<std::string, int> ok, failed;
  for (const EvaluationRow& r : rows) {
    if (!r.error.empty()) {
      ++failed[r.group];
      groups[r.group];
      continue;
    }
    ++ok[r.group];
    auto& g = groups[r.group];
    for (const auto& [k, v] : r.stats) {
      const bool is_max = k.size() >= 4 && (k.compare(k.size() - 4, 4, "/max") == 0 || k.compare(k.size() - 4, 4, "/dim") == 0);
      auto [it, inserted] = g.emplace(k, v);
      if (!inserted) it->second = is_max ? std::max(it->second, v) : it->second + v;
    }
  }
  int total_failed = 0;
  for (const auto& [g, n] : failed) total_failed += n;
  const std::string noise_note =
      "Noise added per axis: " + Fmt(1e3 * settings["noise"]["position_m"].get<double>()) + " mm (object, finger, contact), " +
      Fmt(settings["noise"]["rotation_rad"].get<double>()) + " rad (object orientation), " +
      Fmt(settings["noise"]["force_N"].get<double>()) + " N (force); seed " + settings["seed"].dump() +
      "; the estimator's measurement sigmas equal the added noise.";
  auto common_notes = [&](Table& t) {
    t.notes.push_back(noise_note);
    if (total_failed > 0) t.notes.push_back(std::to_string(total_failed) + " trajectories failed and are left out (see results.md)");
  };
  auto count = [&](const std::string& g) { return std::to_string(ok[g]); };

  std::vector<Table> tables;
  const std::string qs = "gauss.qs.batch";
  if (HasProtocol(protocols, Protocol::kTable1)) {
    Table t{"table1", "Table I: RMS error and mean marginal 1-sigma, QS batch, Gaussian noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "quantity", "unit", "raw RMS", "RMS", "1-sigma", "samples"};
    struct Q {
      const char* key;
      const char* label;
      const char* unit;
      double scale;
    };
    const Q qs_list[] = {{"object_position_moving", "object position (moving)", "mm", 1e3},
                         {"object_rotation_moving", "object rotation (moving)", "rad", 1.0},
                         {"finger_position", "finger position", "mm", 1e3},
                         {"force", "force", "N", 1.0},
                         {"contact", "contact point", "mm", 1e3}};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const Q& q : qs_list) {
        const std::string k = qs + "/" + q.key;
        if (!a.Has(k)) continue;
        const std::string raw = "gauss.raw/" + std::string(q.key);
        t.rows.push_back({g, count(g), q.label, q.unit, a.Has(raw) ? Fmt(q.scale * a.Rms(raw)) : "",
                          Fmt(q.scale * a.Rms(k)), a.HasSigma(k) ? Fmt(q.scale * a.Sigma(k)) : "", Fmt(a.N(k), 10)});
      }
    }
    t.notes.push_back("RMS over every estimated step (object pose: only while the object moves, as in the paper); "
                      "positions are 2-D errors |e|, 1-sigma = sqrt(mean(var_x + var_y)) is the RMS the marginal "
                      "covariances predict. Rows without ground truth are absent (MIT recordings have no contact "
                      "stream; rect1's force sensor is frozen, so its force stream is dropped).");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kTable2)) {
    Table t{"table2", "Table II: force and contact recovery, QS batch, bimodal noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "component", "unit", "raw RMSE", "RMSE", "MAE", "sigma", "samples"};
    struct Q {
      const char* key;
      const char* label;
      const char* unit;
      double scale;
    };
    const Q qs_list[] = {{"force_magnitude", "force magnitude", "N", 1.0},
                         {"force_direction", "force direction", "deg", 1.0},
                         {"contact", "contact location", "mm", 1e3}};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const Q& q : qs_list) {
        const std::string k = "bimodal.qs.batch/" + std::string(q.key);
        if (!a.Has(k)) continue;
        const std::string raw = "bimodal.raw/" + std::string(q.key);
        t.rows.push_back({g, count(g), q.label, q.unit, a.Has(raw) ? Fmt(q.scale * a.Rms(raw)) : "", Fmt(q.scale * a.Rms(k)),
                          Fmt(q.scale * a.Mae(k)), Fmt(q.scale * a.Std(k)), Fmt(a.N(k), 10)});
      }
    }
    t.notes.push_back("Bimodal noise (mixture of two triangular densities, same sigma) on every stream. Magnitude "
                      "error |f| - |f_true| and direction error (signed angle, only where |f_true| >= 0.25 N); sigma "
                      "is the standard deviation of the signed error (of the distance for contacts).");
    common_notes(t);
    tables.push_back(t);
  }
  const std::string models[] = {"cp", "sdf", "qs", "yu"};
  if (HasProtocol(protocols, Protocol::kFig5)) {
    Table t{"fig5", "Fig. 5: object pose error, mean +- standard deviation over steps, Gaussian noise", {}, {}, {}};
    t.columns = {"object", "trajectories", "method", "mode", "position (mm)", "rotation (rad)", "samples"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      auto add = [&](const std::string& prefix, const std::string& method, const std::string& mode) {
        const std::string p = prefix + "/object_position", r = prefix + "/object_rotation";
        if (!a.Has(p)) return;
        t.rows.push_back({g, count(g), method, mode, Fmt(1e3 * a.Mean(p)) + " +- " + Fmt(1e3 * a.Std(p)),
                          Fmt(a.Mean(r)) + " +- " + Fmt(a.Std(r)), Fmt(a.N(p), 10)});
      };
      add("gauss.raw", "raw", "-");
      for (const std::string mode : {"batch", "incremental"}) {
        for (const std::string& m : models) add("gauss." + m + "." + mode, m == "yu" ? "yu (Yu-Rodriguez)" : m, mode);
      }
    }
    t.notes.push_back("Raw: the noisy object-pose measurements (at their own rate); models: every estimated step.");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kOcclusion)) {
    Table t{"occlusion", "Occlusion: object pose error inside and outside the occluded window", {}, {}, {}};
    t.columns = {"object", "trajectories", "model", "mode", "occluded position RMS (mm)", "occluded rotation RMS (rad)",
                 "visible position RMS (mm)", "visible rotation RMS (rad)", "occluded steps"};
    const std::string mode = settings.value("occlusion_mode", "batch");
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const std::string& m : models) {
        const std::string p = "occluded." + m + "." + mode;
        if (!a.Has(p + "/object_position_occluded")) continue;
        t.rows.push_back({g, count(g), m, mode, Fmt(1e3 * a.Rms(p + "/object_position_occluded")),
                          Fmt(a.Rms(p + "/object_rotation_occluded")),
                          a.Has(p + "/object_position_visible") ? Fmt(1e3 * a.Rms(p + "/object_position_visible")) : "",
                          a.Has(p + "/object_rotation_visible") ? Fmt(a.Rms(p + "/object_rotation_visible")) : "",
                          Fmt(a.N(p + "/object_position_occluded"), 10)});
      }
    }
    t.notes.push_back("The object stream is removed for the middle " +
                      Fmt(100.0 * settings["occlusion_fraction"].get<double>()) +
                      "% of each push's contact phase (the paper's mid-trajectory occlusion); Gaussian noise elsewhere.");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kConsistency)) {
    Table t{"consistency", "Consistency: mean NEES against its dimension (Gaussian noise)", {}, {}, {}};
    t.columns = {"object", "trajectories", "model", "mode", "quantity", "dimension", "mean NEES", "inside 95% interval", "samples"};
    const std::string quantities[] = {"object_pose", "finger_position", "contact", "force"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      for (const std::string mode : {"batch", "incremental"}) {
        for (const std::string& m : models) {
          for (const std::string& q : quantities) {
            const std::string k = "gauss." + m + "." + mode + "/" + q;
            const double n = a.Get(k + "/nees_n");
            if (n <= 0.0) continue;
            t.rows.push_back({g, count(g), m, mode, q, Fmt(a.Get(k + "/dim")), Fmt(a.Get(k + "/nees") / n),
                              Fmt(100.0 * a.Get(k + "/nees_in") / n, 3) + "%", Fmt(n, 10)});
          }
        }
      }
    }
    t.notes.push_back("NEES = e^T P^-1 e per step; a consistent estimator has mean NEES = dimension and 95% of the steps "
                      "inside the two-sided 95% chi-square interval (dim 2: [0.0506, 7.38], dim 3: [0.216, 9.35]). "
                      "Finger: position block only (its angle is not measured).");
    common_notes(t);
    tables.push_back(t);
  }
  if (HasProtocol(protocols, Protocol::kRuntime)) {
    Table t{"runtime", "Runtime per trajectory and per incremental update", {}, {}, {}};
    t.columns = {"object", "trajectories", "run", "mean steps", "mean solve (s)", "max solve (s)", "updates",
                 "mean update (s)", "max update (s)"};
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      std::set<std::string> prefixes;
      for (const auto& [k, v] : s) {
        const auto pos = k.find("/time/n");
        if (pos != std::string::npos && pos + 7 == k.size()) prefixes.insert(k.substr(0, pos));
      }
      for (const std::string& p : prefixes) {
        const double n = a.Get(p + "/time/n"), nu = a.Get(p + "/update_time/n");
        t.rows.push_back({g, count(g), p, Fmt(a.Get(p + "/steps/sum") / n), Fmt(a.Get(p + "/time/sum") / n, 3),
                          Fmt(a.Get(p + "/time/max"), 3), nu > 0 ? Fmt(nu, 10) : "",
                          nu > 0 ? Fmt(a.Get(p + "/update_time/sum") / nu, 3) : "",
                          nu > 0 ? Fmt(a.Get(p + "/update_time/max"), 3) : ""});
      }
    }
    t.notes.push_back("Wall time of each graph::Estimate call (single-threaded; trajectories run in parallel, so "
                      "times include contention for cores and memory), covariances included where computed "
                      "(gauss.*.batch with table1/consistency). Run names: NOISE.MODEL.MODE. Times differ from run to run.");
    tables.push_back(t);
  }
  {
    // Self-diagnosis: per group the shape alignment and the health figures, then the worst
    // trajectories with their probable causes.
    Table t{"diagnostics", "Diagnostics: the worst trajectories by their estimate's self-diagnosis", {}, {}, {}};
    t.columns = {"object", "trajectory", "score", "worst factor", "notes"};
    std::vector<const EvaluationRow*> ranked;
    for (const EvaluationRow& r : rows) {
      if (r.error.empty()) ranked.push_back(&r);
    }
    std::stable_sort(ranked.begin(), ranked.end(), [](const EvaluationRow* a, const EvaluationRow* b) { return a->health > b->health; });
    for (std::size_t k = 0; k < ranked.size() && k < 10; ++k) {
      const EvaluationRow& r = *ranked[k];
      std::string notes;
      for (const std::string& n : r.notes) notes += (notes.empty() ? "" : "; ") + n;
      for (char& c : notes) c = c == '|' ? '/' : c;
      t.rows.push_back({r.group, r.name, Fmt(r.health, 3), r.worst_factor, notes});
    }
    for (const auto& [g, s] : groups) {
      const Agg a{&s};
      std::vector<double> scores;
      for (const EvaluationRow& r : rows) {
        if (r.group == g && r.error.empty()) scores.push_back(r.health);
      }
      std::sort(scores.begin(), scores.end());
      const double median = scores.empty() ? 0.0 : scores[scores.size() / 2];
      std::string line = g + ": median score " + Fmt(median, 3) + " over " + count(g) + " trajectories";
      const double group_aligned = a.Get("shape/group_aligned/sum"), run_aligned = a.Get("shape/run_aligned/sum");
      if (group_aligned > 0) line += "; shape aligned for the group (all its recordings together) in " + Fmt(group_aligned, 6);
      if (run_aligned > 0) line += "; shape aligned by the estimate itself in " + Fmt(run_aligned, 6);
      t.notes.push_back(line + ".");
    }
    t.notes.push_back("Score: the largest chi-square / expected value over the measurement, touching, intersection and "
                      "quasi-static factors of the trajectory's QS batch estimate (Gaussian noise); about 1 is healthy "
                      "(docs/estimation.md, Self-diagnosis). Notes: the estimate's warnings.");
    tables.push_back(t);
  }
  return tables;
}

std::string TableMarkdown(const Table& t) {
  std::ostringstream out;
  out << "### " << t.title << "\n\n|";
  for (const std::string& c : t.columns) out << " " << c << " |";
  out << "\n|";
  for (std::size_t i = 0; i < t.columns.size(); ++i) out << "---|";
  out << "\n";
  for (const auto& r : t.rows) {
    out << "|";
    for (const std::string& c : r) out << " " << c << " |";
    out << "\n";
  }
  if (t.rows.empty()) out << "| (no data) |\n";
  out << "\n";
  for (const std::string& n : t.notes) out << n << "\n\n";
  return out.str();
}

std::string TableCsv(const Table& t) {
  auto quote = [](const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::ostringstream out;
  for (std::size_t i = 0; i < t.columns.size(); ++i) out << (i ? "," : "") << quote(t.columns[i]);
  out << "\n";
  for (const auto& r : t.rows) {
    for (std::size_t i = 0; i < r.size(); ++i) out << (i ? "," : "") << quote(r[i]);
    out << "\n";
  }
  return out.str();
}

std::string WriteTables(const std::string& dir, const std::vector<Table>& tables, const std::vector<EvaluationRow>& rows) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw IoError(dir + ": cannot create folder (" + ec.message() + ")");
  auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (fs::path(dir) / name).string();
    if (const std::string error = geometry::WriteFileAtomically(path, text); !error.empty()) throw IoError(error);
  };
  std::ostringstream all;
  for (const Table& t : tables) {
    const std::string md = TableMarkdown(t);
    write(t.id + ".md", md);
    write(t.id + ".csv", TableCsv(t));
    all << md;
  }
  int failed = 0;
  std::ostringstream errors;
  for (const EvaluationRow& r : rows) {
    if (r.error.empty()) continue;
    ++failed;
    errors << "- " << r.error << "\n";
  }
  all << "### Trajectories: " << rows.size() - failed << " evaluated, " << failed << " failed\n\n" << errors.str();
  if (failed > 0) all << "\n";
  write("results.md", all.str());
  return all.str();
}

}  // namespace pushgraph::io
