// pushgraph footprint MESH.obj [--up x|y|z] [--object NAME] [--scale S] [-o SHAPE.json]: the exact
// planar footprint of a mesh as shape JSON.
#include "cli_common.h"

#include <pushgraph/io/footprint.h>

#include <iostream>

namespace pushgraph::cli {

void RegisterFootprint(CLI::App& app) {
  auto* cmd = app.add_subcommand("footprint", "Planar footprint of a mesh (exact union of its projected faces) as shape JSON");
  struct Args {
    std::string mesh, up = "z", object, output;
    double scale = 1.0;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("MESH", args->mesh, "Mesh file (Wavefront OBJ)")->required();
  cmd->add_option("--up", args->up, "Axis to project along: x, y or z")->capture_default_str();
  cmd->add_option("--object", args->object, "Only this object/group of the file (default: all together)");
  cmd->add_option("--scale", args->scale, "Multiply coordinates, e.g. 0.001 for millimetres")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Write the shape JSON here (default: stdout)");
  cmd->add_flag("-q,--quiet", args->quiet, "Do not print the summary on stderr");
  cmd->callback([args] {
    io::FootprintOptions options;
    options.up = io::ParseUpAxis(args->up);
    options.object = args->object;
    options.scale = args->scale;
    io::FootprintReport report;
    const geometry::Shape shape = io::MeshFootprint(args->mesh, options, &report);
    if (args->output.empty()) {
      std::cout << geometry::ShapeToJson(shape) << "\n";
    } else {
      geometry::SaveShapeJson(shape, args->output);
    }
    if (!args->quiet) {
      int holes = 0;
      for (const geometry::Polygon& p : shape.polygons()) holes += static_cast<int>(p.holes.size());
      std::cerr << "footprint: " << shape.polygons().size() << " polygon(s), " << holes << " hole(s), "
                << shape.num_vertices() << " vertices, area " << FormatDouble(shape.core_area()) << " m^2 from "
                << report.faces_used << " of " << report.faces << " faces\n";
    }
  });
}

}  // namespace pushgraph::cli
