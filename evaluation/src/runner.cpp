// The evaluation runner (evaluation.h): protocols, the plan of items, group registration,
// shards, one item's estimates per protocol, and the worker threads.
#include "internal.h"

#include <pushgraph/evaluation/evaluation.h>
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/geometry/file_output.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

namespace pushgraph::evaluation {
namespace {

namespace fs = std::filesystem;
using namespace internal;  // this file is the runner of internal.h's pieces

constexpr const char* kProtocolNames[] = {"table1", "table2", "fig5", "occlusion", "consistency", "runtime"};

Window OcclusionWindow(const push::Trajectory& clean, double fraction) {
  const push::Streams& gt = *clean.ground_truth;
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

}  // namespace

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
      throw EvaluationError("unknown protocol '" + item + "' (known: table1, table2, fig5, occlusion, consistency, runtime, all)");
    }
    chosen.insert(found);
  }
  if (!any) throw EvaluationError("no protocol given (known: table1, table2, fig5, occlusion, consistency, runtime, all)");
  std::vector<Protocol> out;
  for (int i : chosen) out.push_back(static_cast<Protocol>(i));
  return out;
}

std::string ProtocolName(Protocol p) { return kProtocolNames[static_cast<int>(p)]; }

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
  if (estimator.object_delay != 0.0) j["object_delay"] = estimator.object_delay;
  j["simulate"] = {{"count", simulation.count},          {"name", simulation.name},
                   {"push_distance", simulation.push_distance}, {"speed", simulation.speed},
                   {"offset_fraction", simulation.offset_fraction}, {"mass", simulation.object.mass},
                   {"mu_surface", simulation.object.mu_surface}, {"mu_contact", simulation.finger.mu_contact}};
  if (multi_contact_simulation.count > 0)
    j["simulate_multi_contact"] = {{"count", multi_contact_simulation.count}, {"name", multi_contact_simulation.name}};
  return internal::DumpJson(j);
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
  for (const SimulationSpec* spec : {&options.simulation, &options.multi_contact_simulation}) {
    const bool multi = spec == &options.multi_contact_simulation;
    for (int i = 0; i < spec->count; ++i) {
      EvaluationItem it;
      it.index = static_cast<int>(items.size());
      char name[64];
      if (multi) {
        // The push's kind in its name: the tables list pushes by name.
        std::snprintf(name, sizeof name, "sim-multi-%04d-%s", i, MultiContactPushKindName(MultiContactPushKindOf(i)));
      } else {
        std::snprintf(name, sizeof name, "sim-%04d", i);
      }
      it.name = name;
      it.group = spec->name;
      it.source = EvaluationItem::Source::kSimulated;
      it.sim_index = i;
      it.multi_contact_sim = multi;
      items.push_back(it);
    }
  }
  std::map<std::string, int> plotted;
  for (EvaluationItem& it : items) it.plot = plotted[it.group]++ < options.plots_per_group;
  return items;
}

std::vector<std::string> RegisterGroups(std::vector<EvaluationItem>& items, const EvaluationOptions& options) {
  using Align = graph::EstimatorConfig::AlignShape;
  std::vector<std::string> lines;
  std::map<std::string, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (items[i].source == EvaluationItem::Source::kFile) groups[items[i].group].push_back(i);
  }
  for (const auto& [group, members] : groups) {
    // The object's mesh and its other readings (a prism along x or y).
    std::optional<ObjectModel> model;
    try {
      model = MitItemModel(items[members.front()], options);
    } catch (const std::exception&) {
    }
    if (options.estimator.align_shape == Align::kOff) {
      if (model && !model->other_readings.empty())
        lines.push_back(group + ": warning: the object's mesh is a prism along " + model->reading_axes.front() +
                        ", and seen along z its footprint is its side view (align_shape off: used as it is)");
      continue;
    }
    std::vector<push::Trajectory> clean;
    for (std::size_t i : members) {
      try {
        clean.push_back(LoadCleanTrajectory(items[i], options));
      } catch (const std::exception&) {
        // Unreadable: its own row will say so.
      }
    }
    if (clean.empty()) continue;
    std::vector<const push::Trajectory*> pooled;
    for (const push::Trajectory& t : clean) pooled.push_back(&t);
    graph::RegistrationOptions ro = graph::RegistrationOptionsFor(options.estimator);
    ro.estimate_scale = options.estimator.align_scale;
    // Which reading of the object's mesh the recordings fit: a y-up export read along z is its
    // side view (rect1: 90 x 12.7 mm).
    if (model && !model->other_readings.empty()) {
      std::vector<geometry::Shape> readings{clean.front().object.shape};
      readings.insert(readings.end(), model->other_readings.begin(), model->other_readings.end());
      std::vector<std::string> names{"along z"};
      for (const std::string& axis : model->reading_axes) names.push_back("along " + axis);
      const graph::ShapeReadingChoice choice = graph::ChooseShapeReading(pooled, readings, ro, names);
      const std::string& reason = choice.reason;
      if (choice.index > 0) {
        const std::string& up = model->reading_axes[choice.index - 1];
        for (std::size_t i : members) items[i].object_shape = readings[choice.index];
        for (push::Trajectory& t : clean) t.object.shape = readings[choice.index];
        lines.push_back(group + ": the object's mesh is a prism along " + up + " (a y-up export, or an object lying on its "
                        "side), and its recordings' contacts fit its cross-section along " + up +
                        ", not its footprint along z (its side view): used for every recording (" + reason + ")");
      } else if (!choice.reason.empty()) {
        lines.push_back(group + ": warning: the object's mesh is a prism along " + model->reading_axes.front() +
                        ", and seen along z its footprint is its side view; its recordings fit no other reading "
                        "clearly better (" + reason + ")");
      }
    }
    try {
      const graph::RegistrationResult r = graph::RegisterShape(pooled, ro);
      // A shape no unit makes the size of the paths is not placed (each estimate refuses it).
      const bool align = options.estimator.align_shape == Align::kOn || (!r.fits_as_given && !r.size_mismatch);
      char head[160];
      std::snprintf(head, sizeof head, "%s: shape checked against %zu recordings together: ", group.c_str(), pooled.size());
      if (align) {
        for (std::size_t i : members) items[i].shape_transform = r.transform;
        lines.push_back(head + std::string(r.fits_as_given ? "fits as given; aligned anyway (align_shape on): "
                                                           : "does not fit as given (" + r.check.Describe() + "); aligned: ") +
                        r.Describe());
      } else if (!r.fits_as_given) {
        lines.push_back(std::string(head) + "does not fit as given (" + r.check.Describe() +
                        ") and no unit makes it the size of the finger's paths: not aligned");
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
  if (!std::regex_match(text, m, re)) throw EvaluationError("bad shard '" + text + "': expected K/N with 0 <= K < N, e.g. 0/4");
  const long k = std::stol(m[1]), n = std::stol(m[2]);
  if (n < 1 || k >= n || n > 1000000) throw EvaluationError("bad shard '" + text + "': expected K/N with 0 <= K < N, e.g. 0/4");
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
void WriteItemPlots(const EvaluationItem& item, const std::string& dir, const std::map<std::string, push::Trajectory>& noisy,
                    const std::map<std::string, graph::EstimationResult>& results, const Window& window) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw EvaluationError(dir + ": cannot create the plot folder (" + ec.message() + ")");
  std::string group = item.group;
  for (char& c : group) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  for (const auto& [noise, suffix] : {std::pair<std::string, std::string>{"gauss", "fig3"}, {"occluded", "occlusion"}}) {
    const auto qs = results.find(noise + ".qs.batch");
    if (qs == results.end()) continue;
    const push::Trajectory& traj = noisy.at(noise);
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
    push::Trajectory clean = LoadCleanTrajectory(item, o);
    if (item.object_shape) clean.object.shape = *item.object_shape;
    if (item.shape_transform) {
      const graph::ShapeTransform& t = *item.shape_transform;
      clean.object.shape = geometry::TransformShape(clean.object.shape, t.pose, t.scale, t.mirrored);
      row.stats["shape/group_aligned/sum"] = 1.0;
    }
    // The multi-contact group's push i takes the noise seed of the single-contact group's push i
    // (the same push line): the two groups compare push by push.
    char sim_name[32];
    std::snprintf(sim_name, sizeof sim_name, "sim-%04d", item.sim_index);
    const std::uint64_t item_seed = SplitMix(o.seed ^ Fnv1a(item.multi_contact_sim ? std::string(sim_name) : item.name));
    const std::vector<RunSpec> runs = RunsFor(o.protocols, o.occlusion_mode);
    StatSink sink(&row.stats);
    std::map<std::string, push::Trajectory> noisy;
    Window window;
    for (const RunSpec& run : runs) {
      if (noisy.count(run.noise)) continue;
      if (run.noise == "bimodal") {
        noisy[run.noise] = AddNoise(clean, MakePaperNoise(push::NoiseKind::kBimodal, o.noise), SplitMix(item_seed + 2));
      } else {
        push::Trajectory t = AddNoise(clean, MakePaperNoise(push::NoiseKind::kGaussian, o.noise), SplitMix(item_seed + 1));
        if (run.noise == "occluded") {
          window = OcclusionWindow(clean, o.occlusion_fraction);
          auto& v = t.measured.object_pose;
          v.erase(std::remove_if(v.begin(), v.end(), [&](const push::PoseSample& s) { return window.Contains(s.t); }), v.end());
        }
        noisy[run.noise] = std::move(t);
      }
      AccumulateRaw(noisy[run.noise], run.noise + ".raw", sink);
    }
    const bool plot = item.plot && !o.plot_dir.empty();
    std::map<std::string, graph::EstimationResult> kept;  // batch results, for the pictures
    std::vector<std::string> covariance_notes;  // runs whose covariances failed: said, not dropped silently
    for (const RunSpec& run : runs) {
      stage = run.Prefix();
      const push::Trajectory& t = noisy.at(run.noise);
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
      if (run.covariance && r.solver.covariance_status != "ok")
        covariance_notes.push_back(run.Prefix() + ": no covariances (" + r.solver.covariance_status +
                                   "): the consistency tables leave this run out");
      AccumulateRun(t, r, run.Prefix(), run.noise == "occluded" ? window : Window{}, sink);
      if (row.steps == 0) row.steps = static_cast<int>(r.states.size());
      if (plot && run.mode == graph::Mode::kBatch) kept.emplace(run.Prefix(), std::move(r));
    }
    row.notes.insert(row.notes.end(), covariance_notes.begin(), covariance_notes.end());
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

std::string RowsFileName(int shard, int shards) {
  return shards > 1 ? "rows-" + std::to_string(shard) + "-of-" + std::to_string(shards) + ".jsonl" : "rows.jsonl";
}

FolderRun RunIntoFolder(const std::string& out_dir, const std::vector<EvaluationItem>& items, const RowsHeader& header,
                        const EvaluationOptions& options, int threads, bool resume, const EvaluationProgress& progress) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw EvaluationError(out_dir + ": cannot create folder (" + ec.message() + ")");
  FolderRun run;
  run.rows_path = (fs::path(out_dir) / RowsFileName(header.shard, header.shards)).string();
  const std::string partial_path = run.rows_path + ".partial";
  std::vector<EvaluationRow> done_rows;
  std::vector<EvaluationItem> pending = items;
  if (resume) {
    for (const std::string& path : {partial_path, run.rows_path}) {
      if (!fs::exists(path)) continue;
      RowsHeader previous;
      std::vector<EvaluationRow> previous_rows = ReadRows(path, &previous, /*cut_last_line_ok=*/path == partial_path);
      if (previous.settings_json != header.settings_json || previous.shard != header.shard ||
          previous.shards != header.shards) {
        throw EvaluationError("--resume: " + path + " was written by a run with other settings, inputs or shards; "
                              "run without --resume (or with another --out) to start over");
      }
      for (EvaluationRow& r : previous_rows) {
        if (r.error.empty()) done_rows.push_back(std::move(r));  // failed ones run again
      }
      break;
    }
    std::set<int> done;
    for (const EvaluationRow& r : done_rows) done.insert(r.index);
    pending.clear();
    for (const EvaluationItem& item : items) {
      if (!done.count(item.index)) pending.push_back(item);
    }
  }
  run.resumed = static_cast<int>(done_rows.size());
  WriteRows(partial_path, header, done_rows);
  const std::vector<EvaluationRow> new_rows =
      RunEvaluation(pending, options, threads, [&](int done, int total, int failed, const EvaluationRow& row) {
        if (progress) progress(done, total, failed, row);
        AppendRow(partial_path, row);
      });
  run.rows = std::move(done_rows);
  run.rows.insert(run.rows.end(), new_rows.begin(), new_rows.end());
  std::sort(run.rows.begin(), run.rows.end(),
            [](const EvaluationRow& a, const EvaluationRow& b) { return a.index < b.index; });
  for (const EvaluationRow& r : run.rows) run.failed += r.error.empty() ? 0 : 1;
  WriteRows(run.rows_path, header, run.rows);
  fs::remove(partial_path, ec);
  return run;
}

}  // namespace pushgraph::evaluation
