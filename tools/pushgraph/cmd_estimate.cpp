// pushgraph estimate TRAJECTORY.json --model cp|sdf|qs|yu --mode batch|incremental -o RESULT.json
// [--config CONFIG.json]: factor-graph estimation of a push (docs/estimation.md). Prints a
// one-line JSON summary (model, mode, steps, solver statistics, metrics) on stdout.
#include "cli_common.h"

#include <pushgraph/graph/estimator.h>
#include <pushgraph/io/result_json.h>
#include <pushgraph/io/trajectory_json.h>

#include <iostream>
#include <memory>

namespace pushgraph::cli {
namespace {

struct EstimateOptions {
  std::string input;
  std::string model = "qs";
  std::string mode = "batch";
  std::string output;
  std::string config;
};

void RunEstimate(const EstimateOptions& o) {
  const graph::Model model = graph::ParseModel(o.model);
  const graph::Mode mode = graph::ParseMode(o.mode);
  graph::EstimatorConfig config;
  if (!o.config.empty()) config = graph::LoadEstimatorConfig(o.config);
  const limit_surface::Trajectory traj = io::LoadTrajectoryJson(o.input);
  graph::EstimationResult result;
  try {
    result = graph::Estimate(traj, model, mode, config);
  } catch (const graph::GraphError& e) {
    throw CliError(o.input + ": " + e.what());
  }
  io::SaveResultJson(result, o.output);
  nlohmann::json summary = {{"model", o.model},
                            {"mode", o.mode},
                            {"states", result.states.size()},
                            {"iterations", result.solver.iterations},
                            {"time_s", result.solver.time_s},
                            {"final_cost", result.solver.final_cost},
                            {"covariance", result.solver.covariance_status},
                            {"output", o.output}};
  if (!result.metrics.empty()) summary["metrics"] = result.metrics;
  std::cout << DumpJson(summary, -1) << "\n";
}

}  // namespace

void RegisterEstimate(CLI::App& app) {
  auto opts = std::make_shared<EstimateOptions>();
  CLI::App* sub = app.add_subcommand("estimate", "Estimate object/finger poses, contacts and forces of a push (factor graph)");
  sub->add_option("trajectory", opts->input, "Input trajectory (pushgraph-trajectory-1 JSON)")->required();
  sub->add_option("--model", opts->model, "Graph: cp, sdf, qs or yu (Yu-Rodriguez baseline)")->capture_default_str();
  sub->add_option("--mode", opts->mode, "batch or incremental (fixed-lag smoothing)")->capture_default_str();
  sub->add_option("-o,--output", opts->output, "Output RESULT.json")->required();
  sub->add_option("--config", opts->config, "Estimator configuration JSON (sigmas, losses, window; docs/estimation.md)");
  sub->callback([opts]() { RunEstimate(*opts); });
}

}  // namespace pushgraph::cli
