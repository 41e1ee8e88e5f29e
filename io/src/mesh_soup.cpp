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
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace pushgraph::io::internal {

namespace {

// CGAL's OFF and PLY readers size their vectors by the counts a file claims: a 90-byte OFF whose
// one face claims 2e9 vertices took 15.6 GB and 55 s before "cannot read". So the counts of an
// ASCII file are checked first against what it holds: an element count against its bytes (a
// number takes two at least), a face's vertex count against the numbers on its line.
void CheckClaimedCounts(const std::string& path, const std::string& format) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;  // the reader says why
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) return;
  auto fail = [&](const std::string& what) { throw IoError(path + ": cannot read " + format + " mesh: " + what); };
  // A token's value as a whole number >= 0, or -1 when it is none.
  auto whole = [](const std::string& token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    return end == token.c_str() || *end != '\0' || !(v >= 0.0) || v != std::floor(v) ? -1.0 : v;
  };
  auto count_at = [&](const std::string& token, const std::string& what, std::size_t line) {
    const double v = whole(token);
    if (v < 0.0) fail(what + " at line " + std::to_string(line) + " is '" + token + "', not a count");
    if (v > static_cast<double>(bytes) / 2.0)
      fail(what + " at line " + std::to_string(line) + " claims " + token + ", more than the file's " + std::to_string(bytes) +
           " bytes could hold (truncated, or a corrupt count)");
    return static_cast<std::size_t>(v);
  };
  auto tokens_of = [](const std::string& line) {
    std::vector<std::string> t;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i >= line.size() || line[i] == '#') break;
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
      t.push_back(line.substr(i, j - i));
      i = j;
    }
    return t;
  };
  // A face line: its vertex count within the numbers after it, its indices within `vertices`
  // (counted from 0, as OFF and PLY count).
  auto check_face = [&](const std::vector<std::string>& t, std::size_t face, std::size_t line, std::size_t vertices) {
    if (t.empty()) return;
    const std::string which = "face " + std::to_string(face + 1) + " at line " + std::to_string(line);
    const std::size_t n = count_at(t[0], "face " + std::to_string(face + 1) + "'s vertex count", line);
    if (n + 1 > t.size())
      fail(which + " lists " + t[0] + " vertices but its line holds " + std::to_string(t.size() - 1) + " numbers after the count");
    for (std::size_t k = 1; k <= n; ++k) {
      const double index = whole(t[k]);
      if (index < 0.0 || index >= static_cast<double>(vertices))
        fail(which + " refers to vertex '" + t[k] + "', but the file has " + std::to_string(vertices) +
             " vertices, indexed from 0 to " + std::to_string(vertices == 0 ? 0 : vertices - 1));
    }
  };
  std::string line;
  std::size_t number = 0;
  auto next = [&](std::vector<std::string>* t) {
    while (std::getline(in, line)) {
      ++number;
      *t = tokens_of(line);
      if (!t->empty()) return true;
    }
    return false;
  };
  std::vector<std::string> t;
  if (format == "OFF") {
    if (!next(&t)) return;
    // "OFF", "COFF", "NOFF", ... possibly with the counts on the same line; binary OFF is not scanned.
    if (t[0].find("OFF") == std::string::npos) return;
    if (line.find("BINARY") != std::string::npos) return;
    t.erase(t.begin());
    if (t.empty() && !next(&t)) return;
    if (t.size() < 2) return;
    const std::size_t vertices = count_at(t[0], "the vertex count", number);
    const std::size_t faces = count_at(t[1], "the face count", number);
    for (std::size_t v = 0; v < vertices; ++v)
      if (!next(&t)) return;
    for (std::size_t f = 0; f < faces && next(&t); ++f) check_face(t, f, number, vertices);
    return;
  }
  // PLY: the header's elements in order; ASCII data only (one element per line).
  if (!next(&t) || t[0] != "ply") return;
  bool ascii = false;
  struct Element {
    std::string name;
    std::size_t count = 0;
    bool list_first = false;  // its first property is a list (a face's vertex indices)
    std::size_t properties = 0;
  };
  std::vector<Element> elements;
  while (next(&t)) {
    if (t[0] == "end_header") break;
    if (t[0] == "format" && t.size() > 1) ascii = t[1] == "ascii";
    if (t[0] == "element" && t.size() > 2) elements.push_back({t[1], count_at(t[2], "element " + t[1] + "'s count", number)});
    if (t[0] == "property" && !elements.empty()) {
      if (elements.back().properties++ == 0) elements.back().list_first = t.size() > 1 && t[1] == "list";
    }
  }
  if (!ascii) return;
  std::size_t vertices = 0;
  for (const Element& e : elements)
    if (e.name == "vertex") vertices = e.count;
  for (const Element& e : elements) {
    for (std::size_t k = 0; k < e.count; ++k) {
      if (!next(&t)) return;
      if (e.name == "face" && e.list_first && e.properties == 1) check_face(t, k, number, vertices);
    }
  }
}

}  // namespace

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
  if (soup.format != std::string("STL")) CheckClaimedCounts(path, soup.format);
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
        throw IoError(path + ": face " + std::to_string(f + 1) + " of the " + soup.format + " mesh refers to vertex " +
                      std::to_string(v) + ", but the mesh has " + std::to_string(points.size()) + " vertices, indexed from 0");
      face.push_back(static_cast<int>(v));
    }
    soup.faces.push_back(std::move(face));
  }
  return soup;
}

}  // namespace pushgraph::io::internal
