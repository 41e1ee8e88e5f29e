// pushgraph distance SHAPE.json POINTS.csv: exact signed distance, closest point and normal for
// each point of a CSV file (header x,y), in input order, 17 significant digits.
#include "cli_common.h"

#include <pushgraph/geometry/point_query.h>
#include <pushgraph/io/points_csv.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace pushgraph::cli {

void RegisterDistance(CLI::App& app) {
  auto* cmd = app.add_subcommand("distance", "Exact signed distance, closest point and normal for points in a CSV file");
  auto shape_path = std::make_shared<std::string>();
  auto points_path = std::make_shared<std::string>();
  cmd->add_option("SHAPE", *shape_path, "Shape JSON file")->required()
      ->transform(ReadOnceInput());
  cmd->add_option("POINTS", *points_path, "CSV file with header x,y (points in the shape's frame)")->required();
  cmd->footer(
      "Prints CSV: x,y,signed_distance,closest_x,closest_y,normal_x,normal_y (one row per input point).\n"
      "Signed distance is negative inside; the normal is the outward unit normal at the closest point.");
  cmd->callback([shape_path, points_path] {
    const geometry::Shape shape = geometry::LoadShapeJson(*shape_path);
    const std::vector<geometry::Vec2> points = io::ReadPointsCsv(*points_path);
    std::ostringstream out;
    out << "x,y,signed_distance,closest_x,closest_y,normal_x,normal_y\n";
    for (const geometry::Vec2& p : points) {
      const geometry::PointQuery q = geometry::QueryPoint(shape, p);
      out << FormatDouble(p.x()) << ',' << FormatDouble(p.y()) << ',' << FormatDouble(q.signed_distance) << ','
          << FormatDouble(q.closest_point.x()) << ',' << FormatDouble(q.closest_point.y()) << ','
          << FormatDouble(q.normal.x()) << ',' << FormatDouble(q.normal.y()) << '\n';
    }
    std::cout << out.str();
  });
}

}  // namespace pushgraph::cli
