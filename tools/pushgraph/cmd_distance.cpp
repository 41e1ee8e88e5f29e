// pushgraph distance SHAPE.json POINTS.csv: exact signed distance, closest point and normal for
// each point of a CSV file (header x,y), in input order, 17 significant digits.
#include "cli_common.h"

#include <pushgraph/geometry/point_query.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace pushgraph::cli {
namespace {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

std::vector<geometry::Vec2> ReadPointsCsv(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw CliError(path + ": is a directory, not a points file");
  std::ifstream in(path);
  if (!in) throw CliError(path + ": cannot open file");
  std::string line;
  int line_number = 0;
  std::vector<geometry::Vec2> points;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string text = Trim(line);
    if (text.empty()) continue;
    const std::string where = path + ":" + std::to_string(line_number);
    if (!header_seen) {
      std::string compact;
      for (char c : text)
        if (c != ' ' && c != '\t') compact += c;
      if (compact != "x,y") throw CliError(where + ": expected the header 'x,y', got '" + text + "'");
      header_seen = true;
      continue;
    }
    std::vector<double> v;
    try {
      v = ParseNumbers(text, 2, "point");
    } catch (const CliError& e) {
      throw CliError(where + ": " + e.what());
    }
    points.emplace_back(v[0], v[1]);
  }
  if (!header_seen) throw CliError(path + ": empty file (expected the header 'x,y')");
  return points;
}

}  // namespace

void RegisterDistance(CLI::App& app) {
  auto* cmd = app.add_subcommand("distance", "Exact signed distance, closest point and normal for points in a CSV file");
  auto shape_path = std::make_shared<std::string>();
  auto points_path = std::make_shared<std::string>();
  cmd->add_option("SHAPE", *shape_path, "Shape JSON file")->required();
  cmd->add_option("POINTS", *points_path, "CSV file with header x,y (points in the shape's frame)")->required();
  cmd->footer(
      "Prints CSV: x,y,signed_distance,closest_x,closest_y,normal_x,normal_y (one row per input point).\n"
      "Signed distance is negative inside; the normal is the outward unit normal at the closest point.");
  cmd->callback([shape_path, points_path] {
    const geometry::Shape shape = geometry::LoadShapeJson(*shape_path);
    const std::vector<geometry::Vec2> points = ReadPointsCsv(*points_path);
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
