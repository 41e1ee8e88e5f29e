// STL, PLY and OFF meshes (mesh_soup.h): CGAL's polygon-soup readers, so that a CAD export needs
// no conversion to OBJ before `pushgraph footprint` or `estimate --object`.
#include "mesh_soup.h"

#include <pushgraph/io/trajectory_json.h>  // IoError

#include <CGAL/IO/OFF.h>
#include <CGAL/IO/PLY.h>
#include <CGAL/IO/STL.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>

namespace pushgraph::io::internal {

std::optional<MeshSoup> ReadMeshSoup(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  // An ASCII STL under another name is still one ("solid NAME" first); a binary STL's 80-byte
  // header may say anything, so the extension decides there.
  std::string head(80, '\0');
  {
    std::ifstream in(path, std::ios::binary);
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  }
  const std::size_t start = head.find_first_not_of(" \t\r\n");
  const bool ascii_stl = start != std::string::npos && head.compare(start, 6, "solid ") == 0 &&
                         head.find("facet", start) != std::string::npos;
  MeshSoup soup;
  if (extension == ".stl" || ascii_stl) soup.format = "STL";
  else if (extension == ".ply") soup.format = "PLY";
  else if (extension == ".off") soup.format = "OFF";
  else return std::nullopt;

  using Point3 = CGAL::Simple_cartesian<double>::Point_3;
  std::vector<Point3> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    if (soup.format == std::string("STL")) {
      std::vector<std::array<std::size_t, 3>> triangles;
      ok = CGAL::IO::read_STL(path, points, triangles);
      for (const auto& t : triangles) polygons.push_back({t[0], t[1], t[2]});
    } else if (soup.format == std::string("PLY")) {
      std::ifstream in(path, std::ios::binary);
      ok = in && CGAL::IO::read_PLY(in, points, polygons);
    } else {
      std::ifstream in(path);
      ok = in && CGAL::IO::read_OFF(in, points, polygons);
    }
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot read " + soup.format + " mesh: " + e.what());
  }
  if (!ok) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw IoError(path + ": no such file");
    throw IoError(path + ": cannot read " + soup.format + " mesh (truncated, or not " + soup.format + ")");
  }
  if (polygons.empty()) throw IoError(path + ": the mesh has no faces (an empty " + soup.format + " file, or not " + soup.format + ")");
  soup.coordinates.reserve(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double c = points[i][a];
      if (!std::isfinite(c))
        throw IoError(path + ": vertex " + std::to_string(i + 1) + " of the " + soup.format + " mesh has a non-finite coordinate");
      soup.coordinates.push_back(c);
    }
  }
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    std::vector<int> face;
    for (const std::size_t v : polygons[f]) {
      if (v >= points.size())
        throw IoError(path + ": face " + std::to_string(f + 1) + " of the " + soup.format + " mesh refers to missing vertex " +
                      std::to_string(v + 1));
      face.push_back(static_cast<int>(v));
    }
    soup.faces.push_back(std::move(face));
  }
  return soup;
}

}  // namespace pushgraph::io::internal
