// pushgraph footprint MESH.obj|.stl|.ply|.off|SHAPE.json [--up x|y|z] [--object NAME] [--scale S] [--mirror]
// [--transform X,Y,THETA] [-o SHAPE.json]: the exact planar footprint of a mesh as shape JSON,
// optionally moved into another frame (the transform that `pushgraph estimate` reports when it
// aligns a shape: p' = pose * (scale * mirror(p))); a shape JSON input is only transformed.
#include "cli_common.h"

#include <pushgraph/geometry/pose.h>
#include <pushgraph/io/footprint.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>

namespace pushgraph::cli {

void RegisterFootprint(CLI::App& app) {
  auto* cmd = app.add_subcommand("footprint", "Planar footprint of a mesh (exact union of its projected faces) as shape JSON");
  struct Args {
    std::string mesh, up = "z", object, output, transform;
    double scale = 1.0;
    bool quiet = false, mirror = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "Mesh file (Wavefront OBJ, STL, PLY or OFF), or a shape JSON to transform")->required()
      ->transform(ReadOnceInput());
  CLI::Option* up = cmd->add_option("--up", args->up, "Axis to project along: x, y or z")->capture_default_str();
  CLI::Option* object = cmd->add_option("--object", args->object, "Only this object/group of the file (default: all together)");
  cmd->add_option("--scale", args->scale, "Multiply coordinates, e.g. 0.001 for millimetres")
      ->check(FiniteNumber(0.0, false, "> 0"))
      ->capture_default_str();
  cmd->add_flag("--mirror", args->mirror, "Mirror y -> -y (a footprint seen from below), after --scale");
  cmd->add_option("--transform", args->transform,
                  "Then place the shape at the pose X,Y,THETA (m, m, rad), e.g. the shape_transform of RESULT.json");
  cmd->add_option("-o,--output", args->output, "Write the shape JSON here (default: stdout)");
  cmd->add_flag("-q,--quiet", args->quiet, "Do not print the summary on stderr");
  cmd->callback([args, up, object] {
    CheckOutputsAreNew({{"MESH", args->mesh}}, {{"-o", args->output}});
    io::FootprintOptions options;
    options.up = io::ParseUpAxis(args->up);
    options.object = args->object;
    options.scale = args->scale;
    io::FootprintReport report;
    const bool json = std::filesystem::path(args->mesh).extension() == ".json";
    geometry::Shape shape;
    if (json) {
      // A shape JSON is a footprint already: the mesh reading's options do not apply (they were
      // ignored without a word).
      for (const CLI::Option* given : {up, object}) {
        if (given->count() > 0) {
          std::cerr << "footprint: warning: " << given->get_name() << " reads meshes; " << args->mesh
                    << " is a shape JSON (a footprint already): ignored\n";
        }
      }
      shape = geometry::TransformShape(geometry::LoadShapeJson(args->mesh), geometry::Pose2{}, args->scale);
    } else {
      shape = io::MeshFootprint(args->mesh, options, &report);
    }
    if (args->mirror || !args->transform.empty()) {
      const geometry::Pose2 pose = args->transform.empty() ? geometry::Pose2{} : ParsePose(args->transform, "--transform");
      // Degrees and millimetres where radians and metres are meant (a full turn, 6.2832, is fine).
      if (std::abs(pose.theta) > 1.01 * 2.0 * M_PI) {
        std::cerr << "footprint: warning: --transform's THETA " << FormatDouble(pose.theta)
                  << " is taken as radians (more than a full turn): for degrees give " << FormatDouble(pose.theta * M_PI / 180.0)
                  << "\n";
      }
      // Judged against the shape's own size: after --scale 1000 the shape is in millimetres and so
      // is a shift of 20 (the docs' own example was told to give 0.02).
      const geometry::Box2 extent = shape.bounds();
      const double size = std::max(extent.max.x() - extent.min.x(), extent.max.y() - extent.min.y());
      if (std::hypot(pose.x, pose.y) > std::max(1.0, 10.0 * size)) {
        std::cerr << "footprint: warning: --transform's X,Y (" << FormatDouble(pose.x) << ", " << FormatDouble(pose.y)
                  << ") are taken as metres (more than 1 m and ten times the shape's size): for millimetres give "
                  << FormatDouble(pose.x * 1e-3) << "," << FormatDouble(pose.y * 1e-3) << "\n";
      }
      shape = geometry::TransformShape(shape, pose, 1.0, args->mirror);
    }
    if (args->output.empty()) {
      std::cout << geometry::ShapeToJson(shape) << "\n";
    } else {
      geometry::SaveShapeJson(shape, args->output);
    }
    for (const std::string& w : report.warnings) std::cerr << "footprint: warning: " << args->mesh << ": " << w << "\n";
    if (const auto units = io::ShapeUnitsWarning(shape, args->scale)) std::cerr << "footprint: warning: " << *units << "\n";
    if (!args->quiet && !json) {
      int holes = 0;
      for (const geometry::Polygon& p : shape.polygons()) holes += static_cast<int>(p.holes.size());
      std::cerr << "footprint: " << shape.polygons().size() << " polygon(s), " << holes << " hole(s), "
                << shape.num_vertices() << " vertices, area " << FormatDouble(shape.core_area()) << " m^2 from "
                << report.faces_used << " of " << report.faces << " faces\n";
    }
  });
}

}  // namespace pushgraph::cli
