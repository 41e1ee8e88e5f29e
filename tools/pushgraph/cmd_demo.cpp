// pushgraph demo: the built-in default job, on the project's own shapes (data/shapes/).
//
// `pushgraph demo` (the estimation demo, when the tool is built with pushgraph::graph): a
// simulated push of the non-convex notched block with two holes by a 5 mm disk finger, with the
// paper's measurement noise and the object tracker losing the object for a window mid-push
// (Lambert et al. 2019, Sec. V-B); the raw measurements and the CP, SDF and QS factor graphs
// (batch) are compared against the simulator's ground truth, and the push is drawn as SVG.
//
// `pushgraph demo --geometry`: fingers sweep across the block; for each position it prints the
// exact signed separation and penetration depth, checks the accelerated queries against the
// brute-force reference and the distance field against the exact query, and draws the scene.
#include "cli_common.h"

#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/file_output.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>
#ifdef PUSHGRAPH_WITH_GRAPH
#include <pushgraph/graph/estimator.h>
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/evaluation/window_error.h>
#include <pushgraph/push/simulator.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <sstream>

namespace pushgraph::cli {
namespace {

using geometry::Vec2;

std::string SvgPath(const geometry::Shape& shape, double scale, const Vec2& origin) {
  std::string d;
  auto ring = [&](const geometry::Ring& r) {
    for (std::size_t i = 0; i < r.size(); ++i) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%.2f,%.2f ", i == 0 ? "M" : "L", (r[i].x() - origin.x()) * scale,
                    (origin.y() - r[i].y()) * scale);
      d += buf;
    }
    d += "Z ";
  };
  for (const geometry::Polygon& p : shape.polygons()) {
    ring(p.outer);
    for (const geometry::Ring& h : p.holes) ring(h);
  }
  return d;
}

// The picture's folder is created when missing (the default is out/demo.svg).
void MakeParentFolder(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code ignored;  // an uncreatable folder is reported when the file is written
  if (!parent.empty()) std::filesystem::create_directories(parent, ignored);
}

void RunGeometryDemo(const std::string& data_dir, const std::string& svg_path) {

  const geometry::Shape object = geometry::LoadShapeJson(data_dir + "/shapes/notched_block.json");
  const geometry::Shape disk = geometry::LoadShapeJson(data_dir + "/shapes/disk_finger_5mm.json");
  const geometry::Shape square = geometry::LoadShapeJson(data_dir + "/shapes/rounded_square_finger.json");
  const geometry::Pose2 object_pose{0.0, 0.0, 0.0};
  const geometry::ShapePairQuerier disk_pair(object, disk), square_pair(object, square);
  geometry::ShapePairQuerier::Options core_depth;  // "core depth + radii", for the `*` marks
  core_depth.exact_rounded_depth = false;
  const geometry::ShapePairQuerier disk_bound(object, disk, core_depth), square_bound(object, square, core_depth);

  std::printf("pushgraph demo: fingers sweeping down through the V-notch of a block with two holes\n");
  std::printf("object: %d vertices, area %.6g m^2 (data/shapes/notched_block.json)\n\n", object.num_vertices(),
              object.core_area());
  std::printf("%9s | %-32s | %-32s\n", "finger y", "disk finger r=5 mm", "rounded square 8+2 mm, turned 0.3 rad");
  std::printf("%9s | %12s %9s %10s | %12s %9s %10s\n", "[mm]", "separation", "depth", "direction", "separation",
              "depth", "direction");
  std::string markers;
  const double scale = 4000.0;
  const Vec2 origin(-0.07, 0.09);
  for (int k = 0; k <= 10; ++k) {
    const double y = 0.075 - 0.007 * k;
    const geometry::Pose2 finger_pose{0.0, y, 0.3};
    const geometry::ShapePairResult a = disk_pair.Query(object_pose, finger_pose);
    const geometry::ShapePairResult b = square_pair.Query(object_pose, finger_pose);
    const bool a_deeper = a.depth > disk_bound.Query(object_pose, finger_pose).depth + 1e-12;
    const bool b_deeper = b.depth > square_bound.Query(object_pose, finger_pose).depth + 1e-12;
    auto dir = [](const geometry::ShapePairResult& r) {
      char buf[32];
      if (r.intersecting) std::snprintf(buf, sizeof buf, "(%+.2f,%+.2f)", r.normal.x(), r.normal.y());
      else std::snprintf(buf, sizeof buf, "%s", "apart");
      return std::string(buf);
    };
    std::printf("%9.1f | %+12.6f %8.5f%s %10s | %+12.6f %8.5f%s %10s\n", y * 1e3, a.signed_distance, a.depth,
                a_deeper ? "*" : " ", dir(a).c_str(), b.signed_distance, b.depth, b_deeper ? "*" : " ",
                dir(b).c_str());
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "<circle cx='%.2f' cy='%.2f' r='%.2f' fill='none' stroke='%s'/>"
                  "<line x1='%.2f' y1='%.2f' x2='%.2f' y2='%.2f' stroke='black'/>\n",
                  (finger_pose.x - origin.x()) * scale, (origin.y() - finger_pose.y) * scale, 0.005 * scale,
                  a.intersecting ? "crimson" : "seagreen", (a.finger_point.x() - origin.x()) * scale,
                  (origin.y() - a.finger_point.y()) * scale, (a.object_point.x() - origin.x()) * scale,
                  (origin.y() - a.object_point.y()) * scale);
    markers += buf;
  }
  std::printf("* deeper than core depth + radius: the rounded finger's obstacle fills the V there, and the exact\n"
              "  depth leaves through the corner where the two walls' offsets cross (docs/geometry.md)\n");

  // Accelerated queries agree bit for bit with the brute-force edge loop.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-0.08, 0.08), uy(-0.06, 0.06);
  int mismatches = 0;
  const int samples = 20000;
  const auto t0 = std::chrono::steady_clock::now();
  double sink = 0.0;
  std::vector<Vec2> points(samples);
  for (Vec2& p : points) p = Vec2(ux(rng), uy(rng));
  for (const Vec2& p : points) sink += geometry::QueryPoint(object, p).signed_distance;
  const double query_ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - t0).count() / samples;
  for (const Vec2& p : points) {
    const auto q = geometry::QueryPoint(object, p);
    const auto r = geometry::QueryPointBruteForce(object, p);
    mismatches += q.signed_distance != r.signed_distance || q.closest_point != r.closest_point;
  }
  const geometry::DistanceField field(object, {0.001, 0.01, 2});
  std::printf("\nexact point query: %.0f ns/query; %d of %d random points differ from brute force (checksum %.3f)\n",
              query_ns, mismatches, samples, sink);
  std::printf("distance field %dx%d at 1 mm: max interpolation error %.3g m (measured against the exact query)\n",
              field.rows(), field.cols(), field.max_error());

  std::ostringstream svg;
  svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << 0.14 * scale << "' height='" << 0.15 * scale
      << "' style='background:white'>\n<path d='" << SvgPath(object, scale, origin)
      << "' fill='lightsteelblue' stroke='navy' fill-rule='evenodd'/>\n"
      << markers << "<text x='10' y='20' font-family='sans-serif' font-size='13'>disk finger sweep: red overlapping,"
      << " black: witness pairs</text>\n</svg>\n";
  if (const std::string error = geometry::WriteFileAtomically(svg_path, svg.str()); !error.empty()) throw CliError(error);
  std::printf("picture: %s\n", svg_path.c_str());
  if (mismatches != 0) throw CliError("accelerated queries disagree with the brute-force reference");
}

#ifdef PUSHGRAPH_WITH_GRAPH

struct DemoOptions {
  std::string data_dir = DefaultDataDir();
  std::string svg_path;
  std::uint64_t seed = 3;
  bool geometry = false;
};

void RunEstimationDemo(const DemoOptions& o) {
  const auto t_start = std::chrono::steady_clock::now();
  push::PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(o.data_dir + "/shapes/notched_block.json");
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.finger = {geometry::LoadShapeJson(o.data_dir + "/shapes/disk_finger_5mm.json"), /*mu_contact=*/0.4};
  MakeParentFolder(o.svg_path);
  evaluation::WriteSvgFile(o.svg_path, "");  // an unwritable picture path fails now, not after the solves
  // Pushed upwards 2 cm left of the centroid: the block slides and turns.
  plan.waypoints = push::StraightPushPath(plan, M_PI / 2, /*offset=*/0.02, /*standoff=*/0.005, /*push=*/0.05);
  plan.speed = 0.05;
  plan.seed = o.seed;
  // The paper's bimodal noise (Sec. V-B); the tracker loses the object mid-push.
  plan.noise = push::DefaultNoise(push::NoiseKind::kBimodal);
  const double occlusion_t0 = 0.55, occlusion_t1 = 0.95;
  plan.noise.occlusions.push_back({occlusion_t0, occlusion_t1, push::OcclusionMode::kStop});
  const push::SimulationResult sim = push::Simulate(plan);
  const push::Trajectory& traj = sim.trajectory;

  graph::EstimatorConfig config;
  if (traj.measurement_sigmas) config = graph::ApplyMeasurementSigmas(config, *traj.measurement_sigmas);
  struct Row {
    std::string name;
    graph::EstimationResult result;
  };
  std::vector<Row> rows;
  for (graph::Model model : {graph::Model::kCp, graph::Model::kSdf, graph::Model::kQs}) {
    std::string name = graph::ModelName(model);
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::toupper(c); });
    rows.push_back({name, graph::Estimate(traj, model, graph::Mode::kBatch, config)});
  }

  std::printf("pushgraph demo: a 5 mm disk finger pushes the notched block with two holes (data/shapes/)\n");
  const push::NoiseModel& noise = plan.noise;
  std::printf("%zu steps over %.2f s; bimodal noise (object %.1f mm / %.2f deg, contact %.1f mm, force %.2f N);\n",
              rows.front().result.states.size(), sim.states.empty() ? 0.0 : sim.states.back().t,
              noise.object_pose.position.sigma * 1e3, noise.object_pose.angle.sigma * 180.0 / M_PI,
              noise.contact_point.position.sigma * 1e3, noise.force.position.sigma);
  std::printf("the object tracker is occluded from %.2f s to %.2f s. RMS errors against ground truth:\n\n",
              occlusion_t0, occlusion_t1);
  std::printf("%-5s %12s %14s %12s %10s %16s %8s\n", "", "object [mm]", "rotation [deg]", "contact [mm]",
              "force [N]", "occluded [mm]", "time [s]");
  auto cell = [](const std::map<std::string, double>& m, const std::string& key, double factor, int width) {
    char buf[32];
    auto it = m.find(key);
    if (it == m.end()) std::snprintf(buf, sizeof buf, "%*s", width, "-");
    else std::snprintf(buf, sizeof buf, "%*.2f", width, it->second * factor);
    return std::string(buf);
  };
  const std::map<std::string, double>& metrics = rows.front().result.metrics;
  std::printf("%-5s %s %s %s %s %16.2f %8s\n", "raw", cell(metrics, "measured_object_position_rms", 1e3, 12).c_str(),
              cell(metrics, "measured_object_rotation_rms", 180.0 / M_PI, 14).c_str(),
              cell(metrics, "measured_contact_rms", 1e3, 12).c_str(), cell(metrics, "measured_force_rms", 1.0, 10).c_str(),
              1e3 * evaluation::MeanHeldRawObjectPositionError(traj, occlusion_t0, occlusion_t1), "-");
  for (const Row& row : rows) {
    const auto& m = row.result.metrics;
    std::printf("%-5s %s %s %s %s %16.2f %8.2f\n", row.name.c_str(), cell(m, "object_position_rms", 1e3, 12).c_str(),
                cell(m, "object_rotation_rms", 180.0 / M_PI, 14).c_str(), cell(m, "contact_rms", 1e3, 12).c_str(),
                cell(m, "force_rms", 1.0, 10).c_str(),
                1e3 * evaluation::MeanObjectPositionError(traj, row.result, occlusion_t0, occlusion_t1), row.result.solver.time_s);
  }
  std::printf("\n(occluded: mean object position error inside the occlusion; raw holds the last measurement)\n");

  const graph::EstimationResult& qs = rows.back().result;
  evaluation::TrajectoryPlotOptions plot;
  plot.title = "QS batch estimate of a push with occlusion (" + std::to_string(qs.states.size()) + " steps)";
  plot.error_panel = false;  // the panel below compares all models
  std::vector<std::pair<std::string, const graph::EstimationResult*>> compared;
  for (const Row& row : rows) compared.emplace_back(row.name, &row.result);
  const std::string svg = evaluation::StackSvgVertically(
      {evaluation::TrajectorySvg(traj, qs, plot),
       evaluation::TimeSeriesSvg(evaluation::ObjectPositionErrorSeries(traj, compared), "object position error over time",
                         "error [mm]", {{occlusion_t0, occlusion_t1}})});
  evaluation::WriteSvgFile(o.svg_path, svg);
  std::printf("picture: %s (%.1f s in all)\n", o.svg_path.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count());
}
#endif

}  // namespace

void RegisterDemo(CLI::App& app) {
#ifdef PUSHGRAPH_WITH_GRAPH
  auto* cmd = app.add_subcommand(
      "demo", "Run the built-in demo: estimate a simulated push with occlusion (raw vs CP vs SDF vs QS)");
  auto o = std::make_shared<DemoOptions>();
  AddSeedOption(cmd, &o->seed, "Noise seed of the simulated push");
  cmd->add_flag("--geometry", o->geometry, "Run the geometry demo instead (exact separations and depths)");
#else
  auto* cmd = app.add_subcommand("demo", "Run the built-in geometry demo (the estimation demo needs pushgraph::graph)");
  struct DemoOptions {
    std::string data_dir = DefaultDataDir();
    std::string svg_path;
    bool geometry = true;
  };
  auto o = std::make_shared<DemoOptions>();
  cmd->add_flag("--geometry", o->geometry, "Run the geometry demo (the only one in this build)");
#endif
  cmd->add_option("--data", o->data_dir, "Folder with the shipped shapes")->capture_default_str();
  cmd->add_option("--svg", o->svg_path, "Where to write the picture (default out/demo.svg, out/demo-geometry.svg)");
  cmd->callback([o] {
    const bool geometry_demo = o->geometry;
    const std::string svg = !o->svg_path.empty() ? o->svg_path : geometry_demo ? "out/demo-geometry.svg" : "out/demo.svg";
    if (geometry_demo) {
      MakeParentFolder(svg);
      RunGeometryDemo(o->data_dir, svg);
      return;
    }
#ifdef PUSHGRAPH_WITH_GRAPH
    DemoOptions run = *o;
    run.svg_path = svg;
    RunEstimationDemo(run);
#endif
  });
}

}  // namespace pushgraph::cli
