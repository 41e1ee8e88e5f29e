// pushgraph demo: the built-in default job, on the project's own shapes (data/shapes/).
// A disk finger and a rounded-square finger sweep across a non-convex block with holes; for
// each position it prints the exact signed separation and penetration depth, checks the
// accelerated queries against the brute-force reference and the distance field against the
// exact query, and draws the scene as SVG.
#include "cli_common.h"

#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>

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

}  // namespace

void RegisterDemo(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run the built-in geometry demo on the project's own shapes");
  auto data_dir = std::make_shared<std::string>(DefaultDataDir());
  auto svg_path = std::make_shared<std::string>("pushgraph-demo.svg");
  cmd->add_option("--data", *data_dir, "Folder with the shipped shapes")->capture_default_str();
  cmd->add_option("--svg", *svg_path, "Where to write the picture")->capture_default_str();
  cmd->callback([data_dir, svg_path] {
    const geometry::Shape object = geometry::LoadShapeJson(*data_dir + "/shapes/notched_block.json");
    const geometry::Shape disk = geometry::LoadShapeJson(*data_dir + "/shapes/disk_finger_5mm.json");
    const geometry::Shape square = geometry::LoadShapeJson(*data_dir + "/shapes/rounded_square_finger.json");
    const geometry::Pose2 object_pose{0.0, 0.0, 0.0};
    const geometry::ShapePairQuerier disk_pair(object, disk), square_pair(object, square);

    std::printf("pushgraph demo: fingers sweeping down through the V-notch of a block with two holes\n");
    std::printf("object: %d vertices, area %.6g m^2 (data/shapes/notched_block.json)\n\n", object.num_vertices(),
                object.core_area());
    std::printf("%9s | %-32s | %-32s\n", "finger y", "disk finger r=5 mm", "rounded square 8+2 mm, turned 0.3 rad");
    std::printf("%9s | %12s %8s %10s | %12s %8s %10s\n", "[mm]", "separation", "depth", "direction", "separation",
                "depth", "direction");
    std::string markers;
    const double scale = 4000.0;
    const Vec2 origin(-0.07, 0.09);
    for (int k = 0; k <= 10; ++k) {
      const double y = 0.075 - 0.007 * k;
      const geometry::Pose2 finger_pose{0.0, y, 0.3};
      const geometry::ShapePairResult a = disk_pair.Query(object_pose, finger_pose);
      const geometry::ShapePairResult b = square_pair.Query(object_pose, finger_pose);
      auto dir = [](const geometry::ShapePairResult& r) {
        char buf[32];
        if (r.intersecting) std::snprintf(buf, sizeof buf, "(%+.2f,%+.2f)", r.normal.x(), r.normal.y());
        else std::snprintf(buf, sizeof buf, "%s", "apart");
        return std::string(buf);
      };
      std::printf("%9.1f | %+12.6f %8.5f %10s | %+12.6f %8.5f %10s\n", y * 1e3, a.signed_distance, a.depth,
                  dir(a).c_str(), b.signed_distance, b.depth, dir(b).c_str());
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

    std::ofstream svg(*svg_path);
    if (!svg) throw CliError(*svg_path + ": cannot open for writing");
    svg << "<svg xmlns='http://www.w3.org/2000/svg' width='" << 0.14 * scale << "' height='" << 0.15 * scale
        << "' style='background:white'>\n<path d='" << SvgPath(object, scale, origin)
        << "' fill='lightsteelblue' stroke='navy' fill-rule='evenodd'/>\n"
        << markers << "<text x='10' y='20' font-family='sans-serif' font-size='13'>disk finger sweep: red overlapping,"
        << " black: witness pairs</text>\n</svg>\n";
    std::printf("picture: %s\n", svg_path->c_str());
    if (mismatches != 0) throw CliError("accelerated queries disagree with the brute-force reference");
  });
}

}  // namespace pushgraph::cli
