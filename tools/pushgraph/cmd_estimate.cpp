// pushgraph estimate INPUT --model cp|sdf|qs|yu --mode batch|incremental -o RESULT.json
// [--config CONFIG.json] [--object SHAPE.json --finger SHAPE.json --mass KG --mu MU]
// [--add-noise gaussian|bimodal [--seed N]] [--svg PLOT.svg] [--no-trim]: factor-graph estimation of a push
// (docs/estimation.md). INPUT is a pushgraph trajectory file or an MIT recording (HDF5 or the
// dataset's JSON), told apart by content. Prints a one-line JSON summary on stdout.
#include "cli_common.h"

#include <pushgraph/graph/estimator.h>
#include <pushgraph/evaluation/evaluation.h>
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/evaluation/result_json.h>
#include <pushgraph/io/trajectory_json.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <optional>

namespace pushgraph::cli {
namespace {

struct EstimateOptions {
  std::string input;
  std::string model = "qs";
  std::string mode = "batch";
  std::string solver;
  std::string output;
  std::string config;
  std::string object, finger;
  double mass = 0.0, mu = -1.0;
  std::string add_noise;
  std::uint64_t seed = 1;
  std::string svg;
  std::string align_shape;  // empty: the configuration's (default auto)
  std::optional<double> object_delay;  // unset: the configuration's (default 0)
  bool trim = true;         // an MIT recording: its contact phase only
};

// `mesh_warnings`: what reading the --object and --finger meshes warned of (a side view, several
// objects united), for RESULT.json too: on stderr alone, a reader of the result never saw them.
push::Trajectory LoadInput(const EstimateOptions& o, std::string* source, std::vector<std::string>* mesh_warnings,
                           MeshReadings* object_readings) {
  evaluation::InputOverrides given;
  if (!o.object.empty()) given.object_shape = LoadShapeArgument(o.object, "--object", mesh_warnings, object_readings);
  if (!o.finger.empty()) given.finger_shape = LoadShapeArgument(o.finger, "--finger", mesh_warnings);
  if (o.mass > 0.0) given.mass = o.mass;
  if (o.mu >= 0.0) given.mu_surface = o.mu;
  given.trim_to_contact = o.trim;
  std::vector<std::string> notes;
  evaluation::InputKind kind;
  push::Trajectory t = evaluation::LoadEstimationInput(o.input, given, &notes, &kind);
  if (!o.trim && kind == evaluation::InputKind::kTrajectory)
    throw CliError(o.input + ": --no-trim applies to MIT recordings; a trajectory file is estimated as it is");
  for (const std::string& note : notes) std::cerr << "estimate: " << o.input << ": " << note << "\n";
  *source = kind == evaluation::InputKind::kTrajectory ? "trajectory" : "mit";
  return t;
}

void RunEstimate(const EstimateOptions& o) {
  CheckOutputsAreNew({{"INPUT", o.input}, {"--config", o.config}, {"--object", o.object}, {"--finger", o.finger}},
                     {{"-o", o.output}, {"--svg", o.svg}});
  const graph::Model model = graph::ParseModel(o.model);
  const graph::Mode mode = graph::ParseMode(o.mode);
  // A bad configuration file is reported before any input is read.
  if (!o.config.empty()) graph::LoadEstimatorConfig(o.config);
  std::string source;
  std::vector<std::string> mesh_warnings;
  MeshReadings object_readings;
  push::Trajectory traj = LoadInput(o, &source, &mesh_warnings, &object_readings);
  if (!o.add_noise.empty()) {
    // The paper's Sec. IV noise on the clean streams (the recording, or the file's ground truth);
    // the clean streams stay as ground truth, so metrics are computed.
    const push::NoiseKind kind =
        o.add_noise == "bimodal" ? push::NoiseKind::kBimodal : push::NoiseKind::kGaussian;
    try {
      traj = evaluation::AddNoise(traj, evaluation::MakePaperNoise(kind), o.seed);
    } catch (const evaluation::EvaluationError& e) {
      throw CliError(o.input + ": --add-noise: " + e.what());
    }
  }
  // Measurement factors weighted by the known noise (added here, or recorded by the simulator).
  // The data's sigmas first, then the configuration file's keys on top (docs/estimation.md).
  graph::EstimatorConfig config;
  if (traj.measurement_sigmas) config = graph::ApplyMeasurementSigmas(config, *traj.measurement_sigmas);
  if (!o.config.empty()) config = graph::LoadEstimatorConfig(o.config, config);
  if (!o.align_shape.empty()) config.align_shape = ParseAlignShape(o.align_shape);
  if (o.object_delay) config.object_delay = *o.object_delay;
  if (!o.solver.empty()) {
    config.solver = o.solver == "ceres" ? graph::EstimatorConfig::Solver::kCeres : graph::EstimatorConfig::Solver::kChain;
  }
  if (mode == graph::Mode::kIncremental && (config.estimate_c || config.estimate_mu)) {
    throw CliError(o.config + ": estimate_c and estimate_mu are batch only (the incremental mode keeps c and mu "
                   "fixed): use --mode batch or drop them");
  }
  graph::EstimationResult result;
  std::string object_up;  // the mesh's reading, when not along z
  try {
    object_up = ChooseObjectReading(o.object, object_readings, config, &traj, &mesh_warnings);
    result = graph::Estimate(traj, model, mode, config);
  } catch (const graph::GraphError& e) {
    // A config value judged against the trajectory (c against the object's reach) is the config
    // file's error: it was named after the trajectory.
    const std::string what = e.what();
    constexpr const char* kConfig = "config: ";
    if (!o.config.empty() && what.rfind(kConfig, 0) == 0) throw CliError(o.config + ": " + what.substr(8));
    throw CliError(o.input + ": " + what);
  }
  // The library names the shape file SHAPE_FILE in its "to save it" commands; here it is known,
  // and so is the axis it was read along (a y-up export in millimetres: "--scale 0.001" alone
  // saved its side view).
  if (!o.object.empty()) {
    const std::string file = (o.object.find_first_of(" '\"") == std::string::npos ? o.object : "'" + o.object + "'") +
                             (object_up.empty() ? "" : " --up " + object_up);
    for (std::string& w : result.warnings) {
      for (std::size_t at = w.find("SHAPE_FILE"); at != std::string::npos; at = w.find("SHAPE_FILE", at + file.size())) {
        w.replace(at, 10, file);
      }
    }
  }
  for (const std::string& w : result.warnings) std::cerr << "estimate: warning: " << w << "\n";
  result.warnings.insert(result.warnings.begin(), mesh_warnings.begin(), mesh_warnings.end());
  evaluation::SaveResultJson(result, o.output);
  if (!o.svg.empty()) {
    evaluation::TrajectoryPlotOptions plot;
    plot.title = graph::ModelName(model) + " " + graph::ModeName(mode);
    evaluation::WriteTrajectorySvg(o.svg, traj, result, plot);
  }
  nlohmann::json summary = {{"input", source},
                            {"model", o.model},
                            {"mode", o.mode},
                            {"states", result.states.size()},
                            {"iterations", result.solver.iterations},
                            {"time_s", result.solver.time_s},
                            {"final_cost", result.solver.final_cost},
                            {"covariance", result.solver.covariance_status},
                            {"output", o.output}};
  if (!result.states.empty()) summary["t_range"] = {result.states.front().t, result.states.back().t};
  if (!o.add_noise.empty()) summary["noise"] = {{"kind", o.add_noise}, {"seed", o.seed}};
  if (!o.svg.empty()) summary["svg"] = o.svg;
  if (!result.metrics.empty()) summary["metrics"] = result.metrics;
  // Jointly estimated parameters are a result in their own right: echo them.
  if (result.c_estimated && result.c) {
    summary["c"] = *result.c;
    if (result.c_sigma) summary["c_sigma"] = *result.c_sigma;
  }
  if (result.mu_estimated && result.mu) {
    summary["mu"] = *result.mu;
    if (result.mu_sigma) summary["mu_sigma"] = *result.mu_sigma;
  }
  if (result.shape_alignment && result.shape_alignment->aligned) {
    const auto& t = result.shape_alignment->transform;
    summary["shape_transform"] = {t.pose.x, t.pose.y, t.pose.theta};
    if (t.scale != 1.0) summary["shape_scale"] = t.scale;
    if (t.mirrored) summary["shape_mirrored"] = true;
  }
  std::cout << DumpJson(summary, -1) << "\n";
}

}  // namespace

void RegisterEstimate(CLI::App& app) {
  auto opts = std::make_shared<EstimateOptions>();
  CLI::App* sub = app.add_subcommand("estimate", "Estimate object/finger poses, contacts and forces of a push (factor graph)");
  sub->add_option("input", opts->input,
                  "Input: trajectory (pushgraph-trajectory-1 JSON) or MIT recording (.h5, or the dataset's JSON)")
      ->required()
      ->transform(ReadOnceInput());
  sub->add_option("--model", opts->model, "Graph: cp, sdf, qs or yu (Yu-Rodriguez baseline)")->capture_default_str();
  sub->add_option("--mode", opts->mode, "batch or incremental (fixed-lag smoothing)")->capture_default_str();
  sub->add_option("-o,--output", opts->output, "Output RESULT.json")->required();
  sub->add_option("--solver", opts->solver,
                  "chain (the default: banded Levenberg-Marquardt, chain_solver.h) or ceres (the reference); overrides the config's")
      ->check(CLI::IsMember({"chain", "ceres"}));
  sub->add_option("--config", opts->config, "Estimator configuration JSON (sigmas, losses, window; docs/estimation.md)")
      ->transform(ReadOnceInput());
  sub->add_option("--object", opts->object, "Object shape JSON or OBJ mesh (required for MIT recordings; overrides a trajectory's)")
      ->transform(ReadOnceInput());
  sub->add_option("--finger", opts->finger, "Finger (probe) shape JSON or OBJ mesh (required for MIT recordings)")
      ->transform(ReadOnceInput());
  sub->add_option("--mass", opts->mass, "Object mass in kg (required for MIT recordings)")->check(MassValue());
  sub->add_option("--mu", opts->mu, "Object-table friction coefficient (required for MIT recordings)")
      ->check(FrictionValue(true));
  sub->add_option("--add-noise", opts->add_noise,
                  "Add the paper's noise (5 mm, 0.05 rad, 0.5 N per axis) to the clean streams, which stay as ground truth")
      ->check(CLI::IsMember({"gaussian", "bimodal"}));
  AddSeedOption(sub, &opts->seed, "Seed of --add-noise");
  sub->add_option("--svg", opts->svg, "Also write a picture of the estimate (SVG)");
  sub->add_flag("--trim,!--no-trim", opts->trim,
                "An MIT recording: keep only its contact phase (the default); --no-trim keeps every sample");
  AddAlignShapeOption(sub, &opts->align_shape);
  sub->add_option("--object-delay", opts->object_delay,
                  "The object tracker's latency (s): its time stamps minus the finger's clock, subtracted from the "
                  "object_pose stream before estimating (default: the config's object_delay, 0)")
      ->check(FiniteNumber(-10.0, true, "within +-10 s", 10.0));
  sub->callback([opts]() { RunEstimate(*opts); });
}

}  // namespace pushgraph::cli
