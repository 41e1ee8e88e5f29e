// pushgraph evaluate [INPUTS...] [--simulate N] [--protocol LIST] [-j N] [--shard K/N] --out DIR
// pushgraph evaluate merge DIR... --out DIR
// The paper's evaluation protocols (Tables I, II, Fig. 5, occlusion, consistency, runtime) over
// MIT recordings, trajectory files and simulated pushes, in parallel, sharded for job arrays
// (docs/evaluation.md). The logic is evaluation/evaluation.h; this file parses options, shows progress
// and writes files.
#include "cli_common.h"

#include <pushgraph/geometry/json_check.h>
#include <pushgraph/evaluation/config.h>
#include <pushgraph/evaluation/evaluation.h>
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/trajectory_json.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <set>
#include <sstream>

#include <unistd.h>

namespace pushgraph::cli {
namespace {

namespace fs = std::filesystem;

struct EvaluateOptions {
  std::vector<std::string> inputs;
  int simulate = 0;
  int simulate_multi = 0;  // --simulate-multi-contact
  std::string sim_object = DefaultDataDir() + "/shapes/notched_block.json";
  std::string sim_finger = DefaultDataDir() + "/shapes/disk_finger_5mm.json";
  double sim_mass = 0.5, sim_mu = 0.3, sim_mu_contact = 0.4;
  std::string protocols = "all";
  int plots = 1;  // pictures of the first N pushes of every object
  std::string object, finger;
  double mass = 0.0, mu = -1.0;
  std::string mesh_dir;
  std::string config;
  std::string estimator_config;
  std::uint64_t seed = 1;
  double mit_rate = 100.0;
  double occlusion_fraction = 0.4;
  std::string occlusion_mode = "batch";
  int jobs = 0;
  std::string shard;
  std::string out;
  std::vector<std::string> merge;
  bool quiet = false;
  bool allow_failures = false;
  bool resume = false;
  std::string align_shape;  // empty: the estimator configuration's (default auto)
};

// Progress on stderr: one updating line on a terminal, else a plain line every ~10% or 30 s.
class Progress {
 public:
  explicit Progress(bool quiet) : quiet_(quiet), tty_(::isatty(2) == 1), start_(Clock::now()), last_(start_) {}
  void Update(int done, int total, int failed, const evaluation::EvaluationRow& row) {
    if (!row.error.empty()) {
      if (tty_) std::cerr << "\r\033[K";
      std::cerr << "evaluate: error: " << row.error << "\n";
    }
    if (quiet_) return;
    const double elapsed = Seconds(start_);
    const double eta = done > 0 ? elapsed / done * (total - done) : 0.0;
    char line[200];
    std::snprintf(line, sizeof line, "evaluate: %d/%d trajectories (%d%%), %d failed, %.0f s elapsed, ~%.0f s left, last %s",
                  done, total, total > 0 ? 100 * done / total : 100, failed, elapsed, eta, row.name.c_str());
    if (tty_) {
      std::cerr << "\r\033[K" << line << (done == total ? "\n" : "") << std::flush;
    } else if (done == total || done % std::max(1, total / 10) == 0 || Seconds(last_) > 30.0) {
      std::cerr << line << "\n";
      last_ = Clock::now();
    }
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double Seconds(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
  bool quiet_, tty_;
  Clock::time_point start_, last_;
};

void PrintTables(const std::string& out_dir, const std::vector<evaluation::EvaluationRow>& rows, const std::string& settings) {
  const std::vector<evaluation::Table> tables = evaluation::MakeTables(rows, settings);
  std::cout << evaluation::WriteTables(out_dir, tables, rows);
  std::cerr << "evaluate: tables written to " << out_dir << " (results.md, TABLE.md, TABLE.csv, rows.jsonl)\n";
}

void RunMerge(const std::vector<std::string>& dirs, const std::string& out) {
  if (out.empty()) throw CliError("evaluate merge: --out DIR is required");
  evaluation::RowsHeader header;
  const std::vector<evaluation::EvaluationRow> rows = evaluation::MergeRowsInto(dirs, out, &header);
  PrintTables(out, rows, header.settings_json);
}

void RunEvaluate(const EvaluateOptions& o) {
  if (!o.merge.empty()) return RunMerge(o.merge, o.out);
  evaluation::EvaluationOptions options;
  options.protocols = evaluation::ParseProtocols(o.protocols);
  options.seed = o.seed;
  if (!std::isfinite(o.mit_rate) || o.mit_rate < 0.0) throw CliError("--mit-rate must be >= 0 (0 keeps every sample)");
  options.mit_rate = o.mit_rate;
  if (!(o.occlusion_fraction > 0.0 && o.occlusion_fraction < 1.0)) throw CliError("--occlusion-fraction must be in (0, 1)");
  options.occlusion_fraction = o.occlusion_fraction;
  options.occlusion_mode = graph::ParseMode(o.occlusion_mode);
  options.mesh_dir = o.mesh_dir;
  if (!o.config.empty()) evaluation::LoadEvaluationConfig(o.config, &options);
  if (!o.estimator_config.empty()) options.estimator = graph::LoadEstimatorConfig(o.estimator_config);
  if (!o.align_shape.empty()) options.estimator.align_shape = ParseAlignShape(o.align_shape);
  const bool any_override = !o.object.empty() || !o.finger.empty() || o.mass > 0.0 || o.mu >= 0.0;
  if (any_override) {
    if (o.object.empty() || o.finger.empty() || !(o.mass > 0.0) || !(o.mu >= 0.0))
      throw CliError("--object, --finger, --mass and --mu go together (they describe every MIT recording)");
    evaluation::ObjectModel m;
    MeshReadings readings;
    m.object.shape = LoadShapeArgument(o.object, "--object", nullptr, &readings);
    // Its cross-sections, when it is a prism along x or y: the recordings choose (RegisterGroups).
    m.other_readings = readings.shapes;
    m.reading_axes = readings.up;
    m.object.mass = o.mass;
    m.object.mu_surface = o.mu;
    m.finger.shape = LoadShapeArgument(o.finger, "--finger");
    options.object_override = m;
  }
  if (o.simulate < 0) throw CliError("--simulate must be >= 0");
  if (o.simulate_multi < 0) throw CliError("--simulate-multi-contact must be >= 0");
  options.simulation.count = o.simulate;
  if (o.simulate > 0 || o.simulate_multi > 0) {
    if (!(o.sim_mass > 0.0) || !(o.sim_mu > 0.0) || !(o.sim_mu_contact >= 0.0))
      throw CliError("--sim-mass and --sim-mu must be > 0, --sim-mu-contact >= 0");
    options.simulation.object.shape = LoadShapeArgument(o.sim_object, "--sim-object");
    options.simulation.object.mass = o.sim_mass;
    options.simulation.object.mu_surface = o.sim_mu;
    options.simulation.finger = {LoadShapeArgument(o.sim_finger, "--sim-finger"), o.sim_mu_contact};
    options.simulation.name = "sim:" + fs::path(o.sim_object).stem().string();
    options.multi_contact_simulation = options.simulation;
    options.multi_contact_simulation.count = o.simulate_multi;
    options.multi_contact_simulation.multi_contact = true;
    options.multi_contact_simulation.name = "sim-multi:" + fs::path(o.sim_object).stem().string();
  }
  if (o.out.empty()) throw CliError("--out DIR is required");
  if (o.plots < 0) throw CliError("--plots must be >= 0");
  options.plots_per_group = o.plots;
  if (o.plots > 0) options.plot_dir = (fs::path(o.out) / "plots").string();

  const std::vector<std::string> files = o.inputs.empty() ? std::vector<std::string>{} : evaluation::ExpandInputs(o.inputs);
  std::vector<evaluation::EvaluationItem> all = evaluation::PlanEvaluation(files, options);
  if (all.empty()) throw CliError("nothing to evaluate: give recordings/trajectories or --simulate N");
  // Each object's shape against all of its recordings together, before sharding (every shard
  // then uses the same transforms).
  for (const std::string& line : evaluation::RegisterGroups(all, options)) std::cerr << "evaluate: " << line << "\n";
  int shard = 0, shards = 1;
  if (!o.shard.empty()) std::tie(shard, shards) = evaluation::ParseShard(o.shard);
  const std::vector<evaluation::EvaluationItem> items = evaluation::ShardItems(all, shard, shards);
  const std::string settings = options.SettingsJson();

  std::cerr << "evaluate: " << items.size() << " of " << all.size() << " trajectories";
  if (shards > 1) std::cerr << " (shard " << shard << "/" << shards << ")";
  std::cerr << ", protocols " << o.protocols << "\n";
  Progress progress(o.quiet);
  const evaluation::RowsHeader header{shard, shards, static_cast<int>(all.size()), settings};
  const evaluation::FolderRun run = evaluation::RunIntoFolder(
      o.out, items, header, options, o.jobs, o.resume,
      [&](int done, int total, int failed, const evaluation::EvaluationRow& row) { progress.Update(done, total, failed, row); });
  if (o.resume) std::cerr << "evaluate: --resume: " << run.resumed << " trajectories already done in " << o.out << "\n";
  const std::vector<evaluation::EvaluationRow>& rows = run.rows;
  const int failed = run.failed;
  const std::string& rows_path = run.rows_path;
  if (shards > 1) {
    std::cerr << "evaluate: shard rows written to " << rows_path << "; combine with `pushgraph evaluate merge DIR...`\n";
  } else {
    PrintTables(o.out, rows, settings);
  }
  if (failed > 0) std::cerr << "evaluate: " << failed << " of " << rows.size() << " trajectories failed (listed above)\n";
  if (!rows.empty() && failed == static_cast<int>(rows.size())) throw CliError("every trajectory failed");
  // The tables are written either way; the status says that they miss trajectories.
  if (failed > 0 && !o.allow_failures)
    throw CliError(std::to_string(failed) + " of " + std::to_string(rows.size()) +
                   " trajectories failed; the tables leave them out (--allow-failures accepts that with status 0)");
}

}  // namespace

void RegisterEvaluate(CLI::App& app) {
  auto o = std::make_shared<EvaluateOptions>();
  CLI::App* cmd = app.add_subcommand("evaluate", "Run the paper's evaluation protocols over many pushes (tables as Markdown/CSV)");
  cmd->add_option("inputs", o->inputs, "MIT recordings (.h5/.json) or trajectory files: files, folders (recursive) or globs");
  cmd->add_option("--simulate", o->simulate, "Also evaluate N seeded simulated pushes (varied direction and offset)")
      ->capture_default_str();
  cmd->add_option("--simulate-multi-contact", o->simulate_multi,
                  "Also evaluate N simulated pushes with every contact modelled (group sim-multi), on the push "
                  "lines of --simulate's pushes, in a cycle of four kinds: one finger (pushes 0, 2 mod 4: it may "
                  "wedge in a notch and touch both walls), two fingers side by side (1 mod 4), a flat pusher "
                  "(3 mod 4)")
      ->capture_default_str();
  cmd->add_option("--sim-object", o->sim_object, "Shape of the simulated pushes' object")->capture_default_str();
  cmd->add_option("--sim-finger", o->sim_finger, "Finger of the simulated pushes")->capture_default_str();
  cmd->add_option("--sim-mass", o->sim_mass, "Simulated object's mass (kg)")->check(MassValue())->capture_default_str();
  cmd->add_option("--sim-mu", o->sim_mu, "Simulated object-table friction")->check(FrictionValue(false))->capture_default_str();
  cmd->add_option("--sim-mu-contact", o->sim_mu_contact, "Simulated finger-object friction")
      ->check(FrictionValue(true))
      ->capture_default_str();
  cmd->add_option("--protocol", o->protocols, "table1,table2,fig5,occlusion,consistency,runtime or all")
      ->capture_default_str();
  cmd->add_option("--plots", o->plots,
                  "Pictures of the first N pushes of every object in OUT/plots (Fig. 3, 5, 6 style SVG; 0: none)")
      ->capture_default_str();
  cmd->add_option("--object", o->object, "Object shape JSON or OBJ mesh for every MIT recording (with --finger --mass --mu)");
  cmd->add_option("--finger", o->finger, "Probe shape JSON or OBJ mesh for every MIT recording");
  cmd->add_option("--mass", o->mass, "Object mass (kg) for every MIT recording")->check(MassValue());
  cmd->add_option("--mu", o->mu, "Object-table friction for every MIT recording")->check(FrictionValue(false));
  cmd->add_option("--mesh-dir", o->mesh_dir,
                  "Folder with the dataset's NAME.obj and tip.obj (default: an obj/ folder beside or above each recording)");
  cmd->add_option("--config", o->config, "Evaluation config JSON: objects, mesh_dir, estimator (docs/evaluation.md)");
  cmd->add_option("--estimator-config", o->estimator_config, "Estimator configuration JSON (docs/estimation.md)");
  AddSeedOption(cmd, &o->seed, "Base seed of the added noise and the simulated pushes");
  cmd->add_option("--mit-rate", o->mit_rate, "MIT streams thinned to at most this rate (Hz, the paper's 100; 0: all)")
      ->capture_default_str();
  cmd->add_option("--occlusion-fraction", o->occlusion_fraction, "Occluded middle fraction of each push")
      ->capture_default_str();
  cmd->add_option("--occlusion-mode", o->occlusion_mode, "Solver of the occlusion protocol: batch or incremental")
      ->check(CLI::IsMember({"batch", "incremental"}))
      ->capture_default_str();
  cmd->add_option("-j,--jobs", o->jobs, "Worker threads (default: all cores)");
  cmd->add_option("--shard", o->shard, "Evaluate only items with index % N == K and write their rows (K/N)");
  cmd->add_option("--out", o->out, "Output folder (tables, rows)");
  cmd->add_option("--merge", o->merge, "Merge the rows of shard folders/files instead of evaluating")
      ->expected(1, -1);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress display");
  cmd->add_flag("--resume", o->resume,
                "Continue a killed or partly failed run in the same --out: trajectories already in its rows file are "
                "not run again (the settings, inputs and shard must be the same)");
  cmd->add_flag("--allow-failures", o->allow_failures,
                "Exit with status 0 when some (not all) trajectories fail; they are left out of the tables");
  AddAlignShapeOption(cmd, &o->align_shape);
  cmd->footer("Tables: results.md, TABLE.md and TABLE.csv in --out; see docs/evaluation.md.");
  cmd->callback([o, cmd] {
    if (cmd->got_subcommand("merge")) return;
    RunEvaluate(*o);
  });

  auto m = std::make_shared<std::pair<std::vector<std::string>, std::string>>();
  CLI::App* merge = cmd->add_subcommand("merge", "Combine the rows of shards (folders or rows files) into the tables");
  merge->add_option("shards", m->first, "Shard output folders or rows-K-of-N.jsonl files")->required();
  merge->add_option("--out", m->second, "Output folder")->required();
  merge->callback([m] { RunMerge(m->first, m->second); });
}

}  // namespace pushgraph::cli
