// Shape JSON reading and writing (nlohmann_json), with errors that name the file, the JSON
// path and the polygon/vertex.
//   {"polygons": [{"outer": [[x, y], ...], "holes": [[[x, y], ...], ...]}, ...], "radius": 0.0}
#include <pushgraph/geometry/json_check.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/geometry/file_output.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pushgraph::geometry {
namespace {

using json = nlohmann::json;

[[noreturn]] void Fail(const std::string& source, const std::string& what) {
  throw GeometryError(source + ": " + what);
}

Ring ParseRing(const json& value, const std::string& source, const std::string& path) {
  if (!value.is_array()) Fail(source, path + " must be an array of [x, y] pairs");
  Ring ring;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const json& v = value[i];
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      Fail(source, path + "[" + std::to_string(i) + "] must be a pair of numbers [x, y], got " + v.dump());
    ring.emplace_back(v[0].get<double>(), v[1].get<double>());
  }
  return ring;
}

void CheckKeys(const json& object, std::initializer_list<const char*> allowed, const std::string& source,
               const std::string& path) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    bool known = false;
    for (const char* key : allowed) known = known || it.key() == key;
    if (!known) Fail(source, "unknown field \"" + it.key() + "\" in " + path);
  }
}

// A mesh given where a shape file is asked for read as "malformed JSON ... last read: 'o'".
std::string MeshFileHint(const std::string& text) {
  const std::size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string::npos) return "";
  // Any of the first 4 kB's lines.
  auto line_starts_with = [&text](const std::string& word) {
    for (std::size_t at = 0; at < std::min<std::size_t>(text.size(), 4096);) {
      if (text.compare(at, word.size(), word) == 0) return true;
      const std::size_t end = text.find('\n', at);
      if (end == std::string::npos) break;
      at = end + 1;
    }
    return false;
  };
  if (text.compare(start, 6, "solid ") == 0)
    return " (this is an STL mesh: a shape file is JSON; convert the mesh to OBJ and make one with "
           "`pushgraph footprint MESH.obj -o SHAPE.json`)";
  if (text[start] != '{' && text[start] != '[' && (line_starts_with("v ") || line_starts_with("f ")))
    return " (this looks like an OBJ mesh: a shape file is JSON; `pushgraph footprint MESH.obj -o SHAPE.json` makes "
           "one from it)";
  return "";
}

}  // namespace

Shape ParseShapeJson(const std::string& text, const std::string& source) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // syntax errors, and numbers that overflow a double
    Fail(source, "malformed JSON: " + JsonSyntaxErrorText(e.what(), text) + MeshFileHint(text));
  }
  if (const std::string dup = FindDuplicateJsonKey(text); !dup.empty()) Fail(source, dup);
  if (!doc.is_object()) Fail(source, "top level must be an object with \"polygons\"");
  CheckKeys(doc, {"polygons", "radius"}, source, "the shape");
  if (!doc.contains("polygons")) Fail(source, "missing field \"polygons\"");
  const json& polys = doc["polygons"];
  if (!polys.is_array()) Fail(source, "\"polygons\" must be an array");
  double radius = 0.0;
  if (doc.contains("radius")) {
    if (!doc["radius"].is_number()) Fail(source, "\"radius\" must be a number");
    radius = doc["radius"].get<double>();
  }
  std::vector<Polygon> polygons;
  for (std::size_t p = 0; p < polys.size(); ++p) {
    const std::string path = "polygons[" + std::to_string(p) + "]";
    const json& pj = polys[p];
    if (!pj.is_object()) Fail(source, path + " must be an object with \"outer\"");
    CheckKeys(pj, {"outer", "holes"}, source, path);
    if (!pj.contains("outer")) Fail(source, path + " is missing \"outer\"");
    Polygon polygon;
    polygon.outer = ParseRing(pj["outer"], source, path + ".outer");
    if (pj.contains("holes")) {
      const json& holes = pj["holes"];
      if (!holes.is_array()) Fail(source, path + ".holes must be an array of rings");
      for (std::size_t h = 0; h < holes.size(); ++h)
        polygon.holes.push_back(ParseRing(holes[h], source, path + ".holes[" + std::to_string(h) + "]"));
    }
    polygons.push_back(std::move(polygon));
  }
  try {
    return Shape::FromPolygons(std::move(polygons), radius);
  } catch (const GeometryError& e) {
    throw GeometryError(source + ": " + e.what(), e.polygon(), e.ring(), e.vertex());
  }
}

Shape LoadShapeJson(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw GeometryError(path + ": is a directory, not a shape file");
  std::ifstream in(path);
  if (!in) throw GeometryError(path + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return ParseShapeJson(buffer.str(), path);
}

std::string ShapeToJson(const Shape& shape, int indent) {
  auto ring_json = [](const Ring& ring) {
    json out = json::array();
    for (const Vec2& v : ring) out.push_back({v.x(), v.y()});
    return out;
  };
  json polygons = json::array();
  for (const Polygon& p : shape.polygons()) {
    json pj = {{"outer", ring_json(p.outer)}};
    if (!p.holes.empty()) {
      json holes = json::array();
      for (const Ring& h : p.holes) holes.push_back(ring_json(h));
      pj["holes"] = holes;
    }
    polygons.push_back(pj);
  }
  return json{{"polygons", polygons}, {"radius", shape.radius()}}.dump(indent);
}

void SaveShapeJson(const Shape& shape, const std::string& path) {
  if (const std::string error = WriteFileAtomically(path, ShapeToJson(shape) + "\n"); !error.empty())
    throw GeometryError(error);
}

}  // namespace pushgraph::geometry
