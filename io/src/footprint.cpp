// Mesh footprints: tinyobjloader for the mesh, CGAL Polygon_set_2 (Epeck) for the exact union
// of the projected faces (aggregated divide-and-conquer join). This is the io module's only
// CGAL Boolean-operations translation unit.
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/trajectory_json.h>  // IoError

#include "mesh_soup.h"

#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_set_2.h>

#include <tiny_obj_loader.h>

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <unordered_map>

namespace pushgraph::io {
namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = K::Point_2;
using Polygon2 = CGAL::Polygon_2<K>;
using PolygonWithHoles = CGAL::Polygon_with_holes_2<K>;

// Drops vertices equal to their predecessor or collinear with their neighbours (exactly).
std::vector<Point> CleanRing(const Polygon2& ring, int* removed) {
  std::vector<Point> pts(ring.vertices_begin(), ring.vertices_end());
  bool changed = true;
  while (changed && pts.size() >= 3) {
    changed = false;
    for (std::size_t i = 0; i < pts.size() && pts.size() >= 3; ++i) {
      const Point& prev = pts[(i + pts.size() - 1) % pts.size()];
      const Point& next = pts[(i + 1) % pts.size()];
      if (pts[i] == prev || CGAL::collinear(prev, pts[i], next)) {
        pts.erase(pts.begin() + static_cast<long>(i));
        ++*removed;
        changed = true;
        --i;
      }
    }
  }
  return pts;
}

geometry::Ring ToRing(const std::vector<Point>& pts) {
  geometry::Ring ring;
  for (const Point& p : pts) {
    const geometry::Vec2 v(CGAL::to_double(p.x()), CGAL::to_double(p.y()));
    if (ring.empty() || ring.back() != v) ring.push_back(v);
  }
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  return ring;
}

// CGAL returns parts that touch at a vertex as one "relatively simple" ring passing through that
// vertex twice; split such a ring into simple loops (each visiting every position once).
void SplitPinchedRing(const geometry::Ring& ring, std::vector<geometry::Ring>* loops) {
  for (std::size_t i = 0; i < ring.size(); ++i) {
    for (std::size_t j = i + 1; j < ring.size(); ++j) {
      if (ring[i] != ring[j]) continue;
      geometry::Ring inner(ring.begin() + static_cast<long>(i), ring.begin() + static_cast<long>(j));
      geometry::Ring outer(ring.begin() + static_cast<long>(j), ring.end());
      outer.insert(outer.end(), ring.begin(), ring.begin() + static_cast<long>(i));
      SplitPinchedRing(inner, loops);
      SplitPinchedRing(outer, loops);
      return;
    }
  }
  if (ring.size() >= 3) loops->push_back(ring);
}

double TwiceSignedArea(const geometry::Ring& r) {
  double a = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    const geometry::Vec2& p = r[i];
    const geometry::Vec2& q = r[(i + 1) % r.size()];
    a += (p.x() - r[0].x()) * (q.y() - r[0].y()) - (q.x() - r[0].x()) * (p.y() - r[0].y());
  }
  return a;
}

// Counter-clockwise loops are parts, clockwise loops holes; each hole goes to the smallest part
// that contains one of its vertices not on that part's boundary.
std::vector<geometry::Polygon> AssemblePolygons(const std::vector<geometry::Ring>& loops) {
  using Ki = CGAL::Exact_predicates_exact_constructions_kernel;
  std::vector<geometry::Polygon> parts;
  std::vector<std::vector<Ki::Point_2>> outlines;
  std::vector<double> areas;
  for (const geometry::Ring& loop : loops) {
    if (TwiceSignedArea(loop) <= 0.0) continue;
    parts.push_back({loop, {}});
    std::vector<Ki::Point_2> pts;
    for (const geometry::Vec2& v : loop) pts.emplace_back(v.x(), v.y());
    outlines.push_back(std::move(pts));
    areas.push_back(TwiceSignedArea(loop));
  }
  for (const geometry::Ring& loop : loops) {
    if (TwiceSignedArea(loop) > 0.0) continue;
    int owner = -1;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      for (const geometry::Vec2& v : loop) {
        const auto side = CGAL::bounded_side_2(outlines[k].begin(), outlines[k].end(), Ki::Point_2(v.x(), v.y()), Ki());
        if (side == CGAL::ON_BOUNDARY) continue;
        if (side == CGAL::ON_BOUNDED_SIDE && (owner < 0 || areas[k] < areas[owner])) owner = static_cast<int>(k);
        break;
      }
    }
    if (owner < 0) throw IoError("internal: a hole of the footprint lies in no part");
    parts[owner].holes.push_back(loop);
  }
  return parts;
}

// tinyobjloader's number parser is not correctly rounded (it can be 1 ulp off); re-read the
// vertex lines with strtod, which is. Returns empty if the file's vertex count differs.
// A polygon face (4+ vertices) whose outline crosses itself in its own plane (a bow-tie quad):
// its fan triangulation (below) then covers neither what the outline encloses nor its hull.
// The plane's normal by Newell's method; the outline projected along its largest component and
// every pair of non-adjacent edges tested for a proper crossing (orientation signs).
bool FaceCrossesItself(const std::vector<double>& xyz, const std::vector<long>& face) {
  const std::size_t n = face.size();
  double normal[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    const double* a = &xyz[3 * face[i]];
    const double* b = &xyz[3 * face[(i + 1) % n]];
    normal[0] += (a[1] - b[1]) * (a[2] + b[2]);
    normal[1] += (a[2] - b[2]) * (a[0] + b[0]);
    normal[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  // A bow-tie's two lobes cancel in Newell's sum: with no normal left, the plane is the one across
  // the axis of least extent.
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (long k : face)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], xyz[3 * k + a]), hi[a] = std::max(hi[a], xyz[3 * k + a]);
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  double weight[3];
  const bool flat = std::abs(normal[0]) + std::abs(normal[1]) + std::abs(normal[2]) <= 1e-9 * extent * extent;
  for (int a = 0; a < 3; ++a) weight[a] = flat ? -(hi[a] - lo[a]) : std::abs(normal[a]);
  const int drop = weight[0] >= weight[1] && weight[0] >= weight[2] ? 0 : weight[1] >= weight[2] ? 1 : 2;
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  auto point = [&](std::size_t i) { return std::pair<double, double>{xyz[3 * face[i % n] + u], xyz[3 * face[i % n] + v]}; };
  auto orient = [](std::pair<double, double> a, std::pair<double, double> b, std::pair<double, double> c) {
    const double d = (b.first - a.first) * (c.second - a.second) - (b.second - a.second) * (c.first - a.first);
    return (d > 0.0) - (d < 0.0);
  };
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      const auto a = point(i), b = point(i + 1), c = point(j), d = point(j + 1);
      if (orient(a, b, c) * orient(a, b, d) < 0 && orient(c, d, a) * orient(c, d, b) < 0) return true;
    }
  }
  return false;
}

// What ReadVertexCoordinates finds that the parser passes over: lines of a kind the OBJ format
// does not define (a corrupted or mislabelled file) and faces that cross themselves; the first
// of each named by its line.
struct ObjLineFindings {
  int unknown = 0, crossing = 0;
  std::string first_unknown, first_crossing;
};

std::vector<double> ReadVertexCoordinates(const std::string& path, std::size_t expected, ObjLineFindings* found) {
  std::vector<long> face;
  std::ifstream in(path);
  std::vector<double> out;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    // A NUL byte: a binary or corrupt file that the OBJ parser would read as another shape.
    if (const std::size_t nul = line.find('\0'); nul != std::string::npos) {
      throw IoError(path + ":" + std::to_string(line_number) + ": a NUL byte at column " + std::to_string(nul + 1) +
                    " (a binary or corrupt file, not a text OBJ)");
    }
    const char* c = line.c_str();
    while (*c == ' ' || *c == '\t') ++c;
    if (c[0] == 'f' && (c[1] == ' ' || c[1] == '\t')) {
      // Faces: at least three vertex references, each an existing vertex (1-based, or negative
      // from the end); a file cut mid-face would otherwise become a different mesh.
      std::istringstream refs(c + 2);
      std::string ref;
      int count = 0;
      const long vertices = static_cast<long>(out.size() / 3);
      while (refs >> ref && ref[0] != '#') {
        char* end = nullptr;
        const long index = std::strtol(ref.c_str(), &end, 10);
        const bool ok = end != ref.c_str() && (*end == '\0' || *end == '/') && index != 0 &&
                        (index > 0 ? index <= vertices : -index <= vertices);
        if (!ok) {
          throw IoError(path + ":" + std::to_string(line_number) + ": face vertex '" + ref + "' is not one of the " +
                        std::to_string(vertices) + " vertices defined before it: '" + line + "'");
        }
        ++count;
        face.push_back(index > 0 ? index - 1 : vertices + index);
      }
      if (count < 3) {
        throw IoError(path + ":" + std::to_string(line_number) + ": a face needs at least 3 vertices, this one has " +
                      std::to_string(count) + " (a truncated file?): '" + line + "'");
      }
      if (count >= 4 && FaceCrossesItself(out, face) && ++found->crossing == 1)
        found->first_crossing = std::to_string(line_number);
      face.clear();
      continue;
    }
    if (c[0] != 'v' || (c[1] != ' ' && c[1] != '\t')) {
      std::string keyword;
      for (const char* k = c; *k != '\0' && *k != ' ' && *k != '\t' && *k != '\r'; ++k) keyword += *k;
      // OBJ's statements (vertex data, elements, grouping, display; free-form geometry's too).
      static const char* const kKnown[] = {"vt", "vn", "vp", "v", "l", "p", "o", "g", "s", "mg", "usemtl", "mtllib",
                                           "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim",
                                           "hole", "scrv", "sp", "end", "con", "bevel", "c_interp", "d_interp",
                                           "lod", "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap"};
      const bool known = keyword.empty() || keyword[0] == '#' ||
                         std::any_of(std::begin(kKnown), std::end(kKnown), [&](const char* k) { return keyword == k; });
      if (!known && ++found->unknown == 1) {
        found->first_unknown = std::to_string(line_number) + ": '" + line.substr(0, 60) + (line.size() > 60 ? "...'" : "'");
      }
      continue;
    }
    c += 2;
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      const double v = std::strtod(c, &end);
      // tinyobjloader reads a bad number as 0 and NaN as NaN: both would be silent wrong answers.
      const std::string where = path + ":" + std::to_string(line_number) + ": vertex coordinate " + std::to_string(k + 1);
      if (end == c) throw IoError(where + " is missing or not a number: '" + line + "'");
      if (!std::isfinite(v)) throw IoError(where + " is not finite: '" + line + "'");
      out.push_back(v);
      c = end;
    }
    while (*c == ' ' || *c == '\t' || *c == '\r') ++c;
    if (*c != '\0' && *c != '#') {
      // An optional fourth (weight) or vertex colours may follow; they must be numbers too.
      char* end = nullptr;
      std::strtod(c, &end);
      if (end == c) {
        throw IoError(path + ":" + std::to_string(line_number) + ": unexpected text after the vertex coordinates: '" +
                      line + "'");
      }
    }
  }
  if (out.size() != expected) return {};
  return out;
}

}  // namespace

UpAxis ParseUpAxis(const std::string& text) {
  if (text == "x") return UpAxis::kX;
  if (text == "y") return UpAxis::kY;
  if (text == "z") return UpAxis::kZ;
  throw IoError("up axis must be x, y or z, got '" + text + "'");
}

namespace {

// Seams written with rounded coordinates, or parts modelled separately, leave the two sides of a
// seam a rounding error apart: a ring of quads closed at angle 2 pi (sin 2 pi = -1.2e-17 against
// 0), a U of five boxes turned by 37 degrees and written to 9 digits (a box's corner 1e-11 off its
// neighbour's side). Their exact union keeps such a seam as a slit of that width: the ring lost its
// hole to a slit open to the outside, and a point query then said 0 deep inside the material; the
// U fell into 4 parts. So before the union, vertices within kSnapRelative of the footprint's size
// of a vertex met before are moved onto it (the first of a cluster stays: every kept coordinate is
// one the file gives), and such a vertex that close to a face's edge, strictly between its ends, is
// inserted into that edge (a T-junction made conforming). Faces come back as vertex indices, the
// welded ones replaced by their representatives; *snapped counts the vertices moved, or inserted
// into an edge they were not exactly on.
constexpr double kSnapRelative = 1e-7;

template <class Project>
std::vector<std::vector<int>> SnapSeams(const std::vector<std::vector<int>>& faces, int nv, const Project& project,
                                        int* snapped) {
  namespace bg = boost::geometry;
  namespace bgi = boost::geometry::index;
  using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
  using BBox = bg::model::box<BPoint>;
  *snapped = 0;
  std::vector<std::array<double, 2>> uv(nv);
  std::vector<char> used(nv, 0);
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (const auto& face : faces) {
    for (int v : face) {
      if (used[v]) continue;
      used[v] = 1;
      uv[v] = project(v);
      for (int a = 0; a < 2; ++a) lo[a] = std::min(lo[a], uv[v][a]), hi[a] = std::max(hi[a], uv[v][a]);
    }
  }
  const double tol = kSnapRelative * std::max(hi[0] - lo[0], hi[1] - lo[1]);
  if (!(tol > 0.0) || !std::isfinite(tol)) return faces;
  for (int v = 0; v < nv; ++v)
    if (used[v] && !(std::isfinite(uv[v][0]) && std::isfinite(uv[v][1]))) return faces;  // nothing to snap by
  // Welding: a hash grid of cell size tol; a vertex goes to the first representative within tol.
  std::vector<int> rep(nv, -1);
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  auto cell_key = [](std::int64_t i, std::int64_t j) {
    return static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(j);
  };
  std::vector<int> representatives;
  for (int v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    const std::int64_t ci = static_cast<std::int64_t>(std::floor((uv[v][0] - lo[0]) / tol));
    const std::int64_t cj = static_cast<std::int64_t>(std::floor((uv[v][1] - lo[1]) / tol));
    int found = -1;
    double best = INFINITY;
    for (std::int64_t di = -1; di <= 1; ++di) {
      for (std::int64_t dj = -1; dj <= 1; ++dj) {
        const auto it = grid.find(cell_key(ci + di, cj + dj));
        if (it == grid.end()) continue;
        for (int r : it->second) {
          const double d = std::hypot(uv[r][0] - uv[v][0], uv[r][1] - uv[v][1]);
          if (d <= tol && d < best) best = d, found = r;
        }
      }
    }
    if (found >= 0) {
      rep[v] = found;
      if (best > 0.0) ++*snapped;
    } else {
      rep[v] = v;
      grid[cell_key(ci, cj)].push_back(v);
      representatives.push_back(v);
    }
  }
  // T-junctions: the representatives (pairwise more than tol apart) near each edge.
  std::vector<std::pair<BPoint, int>> points;
  points.reserve(representatives.size());
  for (int r : representatives) points.emplace_back(BPoint(uv[r][0], uv[r][1]), r);
  const bgi::rtree<std::pair<BPoint, int>, bgi::rstar<16>> tree(points.begin(), points.end());
  std::vector<char> inserted(nv, 0);
  std::vector<std::vector<int>> out;
  out.reserve(faces.size());
  std::vector<std::pair<BPoint, int>> near;
  std::vector<std::pair<double, int>> on_edge;
  for (const auto& face : faces) {
    std::vector<int> ring;
    for (std::size_t k = 0; k < face.size(); ++k) {
      const int a = rep[face[k]], b = rep[face[(k + 1) % face.size()]];
      ring.push_back(a);
      if (a == b) continue;
      const double ax = uv[a][0], ay = uv[a][1], ex = uv[b][0] - ax, ey = uv[b][1] - ay;
      const double length2 = ex * ex + ey * ey;
      near.clear();
      tree.query(bgi::intersects(BBox(BPoint(std::min(ax, uv[b][0]) - tol, std::min(ay, uv[b][1]) - tol),
                                      BPoint(std::max(ax, uv[b][0]) + tol, std::max(ay, uv[b][1]) + tol))),
                 std::back_inserter(near));
      on_edge.clear();
      for (const auto& [point, c] : near) {
        if (c == a || c == b) continue;
        const double px = uv[c][0] - ax, py = uv[c][1] - ay;
        const double t = (px * ex + py * ey) / length2;
        if (!(t > 0.0 && t < 1.0)) continue;
        if (std::abs(px * ey - py * ex) > tol * std::sqrt(length2)) continue;
        on_edge.emplace_back(t, c);
      }
      std::sort(on_edge.begin(), on_edge.end());
      for (const auto& [t, c] : on_edge) {
        ring.push_back(c);
        // One exactly on the edge changes nothing (a box's corner on an axis-aligned side): not counted.
        const bool off = CGAL::orientation(Point(ax, ay), Point(uv[b][0], uv[b][1]), Point(uv[c][0], uv[c][1])) !=
                         CGAL::COLLINEAR;
        if (off && !inserted[c]) inserted[c] = 1, ++*snapped;
      }
    }
    out.push_back(std::move(ring));
  }
  return out;
}

// A closed surface covers every point of its footprint an even number of times (a line along the
// up axis leaves it as often as it enters: above and below), whatever its T-junctions, winding or
// number of parts. At sample points (a point inside each of up to 200 projected faces, on no
// face's edge) the projected faces are counted exactly; an odd count means faces are missing
// there, and the footprint lacks whatever they alone covered (a block whose bottom and some top
// faces were lost read as a smaller block, without a word), or a face inside the solid (two boxes
// sharing one face written once). nullopt when every sample is even. A flat outline (one sheet)
// is meant to cover once and is not asked, nor a mesh with a face crossing itself (united as a
// fan of overlapping triangles): the caller skips both.
std::optional<std::string> OddCoverage(const std::vector<Polygon2>& faces) {
  namespace bg = boost::geometry;
  namespace bgi = boost::geometry::index;
  using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
  using BBox = bg::model::box<BPoint>;
  std::vector<std::pair<BBox, std::size_t>> boxes;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const CGAL::Bbox_2 b = faces[f].bbox();
    boxes.emplace_back(BBox(BPoint(b.xmin(), b.ymin()), BPoint(b.xmax(), b.ymax())), f);
  }
  const bgi::rtree<std::pair<BBox, std::size_t>, bgi::rstar<16>> tree(boxes.begin(), boxes.end());
  const std::size_t stride = std::max<std::size_t>(1, (faces.size() + 199) / 200);
  int samples = 0, odd = 0, first_count = 0;
  Point first;
  std::vector<std::pair<BBox, std::size_t>> near;
  for (std::size_t f = 0; f < faces.size(); f += stride) {
    const Polygon2& face = faces[f];
    const Point c = CGAL::centroid(face[0], face[1], face[2]);
    if (face.bounded_side(c) != CGAL::ON_BOUNDED_SIDE) continue;
    const double x = CGAL::to_double(c.x()), y = CGAL::to_double(c.y());
    near.clear();
    tree.query(bgi::intersects(BPoint(x, y)), std::back_inserter(near));
    int count = 0;
    bool on_edge = false;
    for (const auto& [box, g] : near) {
      const CGAL::Bounded_side side = faces[g].bounded_side(c);
      on_edge = on_edge || side == CGAL::ON_BOUNDARY;
      count += side == CGAL::ON_BOUNDED_SIDE;
    }
    if (on_edge) continue;
    ++samples;
    if (count % 2 == 1 && odd++ == 0) first = c, first_count = count;
  }
  if (odd == 0) return std::nullopt;
  std::ostringstream text;
  text.precision(6);
  text << "the mesh is not closed, or holds inner or duplicate faces: the point (" << CGAL::to_double(first.x()) << ", "
       << CGAL::to_double(first.y()) << ") of its footprint is covered by " << first_count << " face"
       << (first_count == 1 ? "" : "s") << ", and " << odd << " of " << samples
       << " sample points an odd number of times (a closed surface covers each point an even number of times, from above "
       << "and below): where faces are missing, the footprint lacks what they alone covered";
  return text.str();
}

// tinyobjloader reads any text and skips what it does not know: a glTF file read as "the mesh
// has no faces", with no word of the format. (STL, PLY and OFF are read: mesh_soup.h.)
void RefuseOtherMeshFormats(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  const char* format = extension == ".3mf"                           ? "3MF"
                       : extension == ".dae"                         ? "COLLADA"
                       : extension == ".gltf" || extension == ".glb" ? "glTF"
                                                                     : nullptr;
  if (format != nullptr)
    throw IoError(path + ": " + format + " meshes are not read, only Wavefront OBJ, STL, PLY and OFF (export it as one of them, e.g. with "
                  "MeshLab, Blender or assimp: assimp export " + std::filesystem::path(path).filename().string() + " MESH.obj)");
}

}  // namespace

geometry::Shape MeshFootprint(const std::string& path, const FootprintOptions& options, FootprintReport* report) {
  if (!(options.scale > 0.0) || !std::isfinite(options.scale)) throw IoError(path + ": scale must be finite and > 0");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, not a mesh file");
  RefuseOtherMeshFormats(path);
  // The mesh's vertices and faces by object or group (an STL, PLY or OFF file: one, unnamed).
  struct Group {
    std::string name;
    std::vector<std::vector<int>> faces;  // vertex indices, as the file lists them
  };
  std::vector<Group> groups;
  std::vector<double> coordinates;
  FootprintReport local;
  FootprintReport& rep = report ? *report : local;
  rep = FootprintReport{};
  if (std::optional<internal::MeshSoup> soup = internal::ReadMeshSoup(path)) {
    coordinates = std::move(soup->coordinates);
    groups.push_back({"", std::move(soup->faces)});
    if (!options.object.empty())
      throw IoError(path + ": no object named '" + options.object + "' (" + soup->format +
                    " files hold one unnamed mesh: leave out the object name)");
  } else {
    tinyobj::ObjReaderConfig config;
    // Faces as the file gives them: tinyobjloader's triangulation of a polygon face depends on the
    // vertex it starts at (a U-shaped 8-gon listed from its fourth vertex had its notch filled).
    config.triangulate = false;
    config.vertex_color = false;
    config.mtl_search_path = "";  // materials are irrelevant to a footprint
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config)) {
      std::string message = reader.Error();
      while (!message.empty() && (message.back() == '\n' || message.back() == '\r')) message.pop_back();
      std::replace(message.begin(), message.end(), '\n', ' ');
      // tinyobjloader says "e.g. zero value for face index" of any face it cannot read ("f a b c").
      if (message.find("Failed parse `f' line") != std::string::npos)
        message += " (each of a face's entries must be a vertex number: from 1, or negative counting back from the last vertex)";
      throw IoError(path + ": cannot read mesh: " + (message.empty() ? std::string("unknown error") : message));
    }
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    for (const tinyobj::shape_t& s : reader.GetShapes()) rep.objects.push_back(s.name);
    if (!options.object.empty() && std::find(rep.objects.begin(), rep.objects.end(), options.object) == rep.objects.end()) {
      std::string names;
      for (const std::string& n : rep.objects) {
        if (!n.empty()) names += (names.empty() ? "" : ", ") + n;
      }
      throw IoError(path + ": no object named '" + options.object + "' (" +
                    (names.empty() ? std::string("the file has no named objects or groups ('o' or 'g' lines)")
                                   : "the file has: " + names) +
                    ")");
    }
    ObjLineFindings found;
    coordinates = ReadVertexCoordinates(path, attrib.vertices.size(), &found);
    if (found.crossing > 0) {
      rep.warnings.push_back(std::to_string(found.crossing) + " face(s) cross themselves (the first at line " + found.first_crossing +
                             "): such a face is triangulated as a fan, which covers neither its outline's inside nor its "
                             "hull; split it into simple faces");
    }
    if (found.unknown > 0) {
      rep.warnings.push_back(std::to_string(found.unknown) + " line(s) that are no OBJ statement were skipped (the first at line " +
                             found.first_unknown + "): is it an OBJ file, and complete?");
    }
    if (coordinates.empty()) coordinates.assign(attrib.vertices.begin(), attrib.vertices.end());
    const int count = static_cast<int>(attrib.vertices.size() / 3);
    for (const tinyobj::shape_t& s : reader.GetShapes()) {
      Group group{s.name, {}};
      const auto& idx = s.mesh.indices;
      std::size_t first = 0;
      for (std::size_t f = 0; f < s.mesh.num_face_vertices.size(); first += s.mesh.num_face_vertices[f], ++f) {
        const std::size_t n = s.mesh.num_face_vertices[f];
        if (n < 3 || first + n > idx.size()) continue;
        std::vector<int> face;
        for (std::size_t k = 0; k < n; ++k) {
          const int vi = idx[first + k].vertex_index;
          if (vi < 0 || vi >= count)
            throw IoError(path + ": object '" + s.name + "' face " + std::to_string(f) + " refers to missing vertex " +
                          std::to_string(vi + 1));
          face.push_back(vi);
        }
        group.faces.push_back(std::move(face));
      }
      groups.push_back(std::move(group));
    }
  }
  const int nv = static_cast<int>(coordinates.size() / 3);
  auto project = [&](int index) -> std::array<double, 2> {
    const double x = coordinates[3 * index] * options.scale, y = coordinates[3 * index + 1] * options.scale,
                 z = coordinates[3 * index + 2] * options.scale;
    switch (options.up) {
      case UpAxis::kX: return {y, z};
      case UpAxis::kY: return {x, -z};  // a y-up export (x, z, -y) of a z-up model: its (x, y) again
      default: return {x, y};
    }
  };
  std::vector<std::vector<int>> faces;  // of the chosen object (all when none is named)
  for (const Group& g : groups) {
    if (!options.object.empty() && g.name != options.object) continue;
    rep.faces += static_cast<int>(g.faces.size());
    faces.insert(faces.end(), g.faces.begin(), g.faces.end());
  }
  const std::vector<std::vector<int>> snapped = SnapSeams(faces, nv, project, &rep.vertices_snapped);
  if (rep.vertices_snapped > 0) {
    rep.warnings.push_back(std::to_string(rep.vertices_snapped) +
                           " vertex(es) within 1e-7 of the footprint's size of another vertex or of a face's edge were "
                           "snapped to it (seams written with rounded coordinates or parts modelled separately; "
                           "united as they are, they leave slits of that width)");
  }
  // Each face's projection: a planar simple face seen along a direction not in its plane is a
  // simple polygon, united as it is (exactly); a projection that is not simple (a face crossing
  // itself, or a nearly vertical one folded by its vertices' rounding) is united as the fan of
  // triangles from its first vertex, as a triangulating reader would. A face that snapping made
  // not simple (two of its own vertices welded, a slit narrower than the tolerance) is united as
  // the file gives it: its fan would fill a notch.
  auto points_of = [&](const std::vector<int>& face) {
    std::vector<Point> p;
    for (int vi : face) {
      const std::array<double, 2> uv = project(vi);
      p.emplace_back(uv[0], uv[1]);
    }
    return p;
  };
  // The face's outline without consecutive repeats, when it is simple (a polygon's vertices must differ).
  auto simple_polygon = [](const std::vector<Point>& p, Polygon2* out) {
    std::vector<Point> ring;
    for (const Point& q : p)
      if (ring.empty() || q != ring.back()) ring.push_back(q);
    while (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
    if (ring.size() < 3) return false;
    Polygon2 polygon(ring.begin(), ring.end());
    if (!polygon.is_simple()) return false;
    *out = std::move(polygon);
    return true;
  };
  std::vector<Polygon2> projected;
  bool fanned = false;  // a face crossing itself was united as its fan of triangles
  for (std::size_t f = 0; f < faces.size(); ++f) {
    bool used = false;
    auto add = [&](Polygon2 polygon) {
      const CGAL::Orientation o = polygon.orientation();
      if (o == CGAL::COLLINEAR) return;
      if (o == CGAL::CLOCKWISE) polygon.reverse_orientation();
      projected.push_back(std::move(polygon));
      used = true;
    };
    Polygon2 polygon;
    if (simple_polygon(points_of(snapped[f]), &polygon)) {
      if (polygon.area() != 0) add(std::move(polygon));
    } else {
      const std::vector<Point> p = points_of(faces[f]);
      if (simple_polygon(p, &polygon)) {
        if (polygon.area() != 0) add(std::move(polygon));
      } else {
        for (std::size_t k = 1; k + 1 < p.size(); ++k)
          if (CGAL::orientation(p[0], p[k], p[k + 1]) != CGAL::COLLINEAR) {
            fanned = true;
            const Point tri[3] = {p[0], p[k], p[k + 1]};
            add(Polygon2(tri, tri + 3));
          }
      }
    }
    rep.faces_used += used;
  }
  int flat_axis = -1;  // the axis across which every used vertex lies in one plane, if any
  // Within 1e-6 of its size along the up axis: a sheet (an outline drawn flat, or tilted by a
  // rounding: 1e-7 across 0.1 m), whose faces cover the footprint once by design.
  bool thin_along_up = false;
  {
    std::vector<std::string> with_faces;
    std::vector<char> used(nv, 0);
    for (const Group& g : groups) {
      if (!options.object.empty() && g.name != options.object) continue;
      if (!g.faces.empty()) with_faces.push_back(g.name.empty() ? "(unnamed)" : g.name);
      for (const std::vector<int>& face : g.faces)
        for (const int v : face) used[v] = 1;
    }
    if (options.object.empty() && with_faces.size() > 1) {
      std::string names;
      for (std::size_t k = 0; k < with_faces.size() && k < 6; ++k) names += (k ? ", " : "") + with_faces[k];
      if (with_faces.size() > 6) names += ", ...";
      rep.warnings.push_back("the file holds " + std::to_string(with_faces.size()) + " objects or groups (" + names +
                             "): their footprints are united; if they are separate objects, --object NAME takes one");
    }
    // A prism along an axis has every vertex on its two end planes (an extruded outline: the
    // MIT blocks along z, the probe's cylinder along y). Along another axis than `up`, the
    // footprint is the prism's side view.
    const char* axis_names[3] = {"x", "y", "z"};
    const int up = options.up == UpAxis::kX ? 0 : options.up == UpAxis::kY ? 1 : 2;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int v = 0; v < nv; ++v) {
      if (!used[v]) continue;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], coordinates[3 * v + a]);
        hi[a] = std::max(hi[a], coordinates[3 * v + a]);
      }
    }
    const double tolerance = 1e-9 * std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 0.0});
    // A flat mesh (an outline drawn in one plane) is no prism along any axis: its four corners
    // lie on two planes across each in-plane axis.
    for (int a = 0; a < 3 && flat_axis < 0; ++a) {
      if (hi[a] - lo[a] <= tolerance && hi[a] >= lo[a]) flat_axis = a;
    }
    if (flat_axis >= 0) rep.flat_axis = flat_axis == 0 ? UpAxis::kX : flat_axis == 1 ? UpAxis::kY : UpAxis::kZ;
    thin_along_up = !(hi[up] - lo[up] > 1e3 * tolerance);  // tolerance is 1e-9 of the size
    for (int a = 0; a < 3 && flat_axis < 0; ++a) {
      bool on_ends = hi[a] > lo[a];
      int at_lo = 0, at_hi = 0;  // an end face needs three vertices (a lone triangle is no prism)
      for (int v = 0; v < nv && on_ends; ++v) {
        if (!used[v]) continue;
        const double c = coordinates[3 * v + a];
        at_lo += std::abs(c - lo[a]) <= tolerance;
        at_hi += std::abs(c - hi[a]) <= tolerance;
        on_ends = std::abs(c - lo[a]) <= tolerance || std::abs(c - hi[a]) <= tolerance;
      }
      if (on_ends && at_lo >= 3 && at_hi >= 3) {
        rep.prism_axes.push_back(a == 0 ? UpAxis::kX : a == 1 ? UpAxis::kY : UpAxis::kZ);
      }
    }
    const auto& prisms = rep.prism_axes;
    if (!prisms.empty() && std::find(prisms.begin(), prisms.end(), options.up) == prisms.end()) {
      const char* axis = axis_names[static_cast<int>(prisms.front())];
      rep.warnings.push_back(std::string("every vertex lies on one of two planes across ") + axis + ": the mesh is a prism along " +
                             axis + ", and seen along " + axis_names[up] + " its footprint is its side view; --up " + axis +
                             " gives its cross-section");
    }
  }
  if (rep.faces == 0) throw IoError(path + ": the mesh has no faces");
  if (projected.empty()) {
    // No face spans an area in 3-D (Newell's normal of every face zero: collinear or repeated
    // vertices): no up axis would read it, and --up must not be suggested.
    bool any_area = false;
    for (std::size_t f = 0; f < faces.size() && !any_area; ++f) {
      double n[3] = {0.0, 0.0, 0.0};
      const std::vector<int>& face = faces[f];
      for (std::size_t k = 0; k < face.size(); ++k) {
        const double* a = &coordinates[3 * static_cast<std::size_t>(face[k])];
        const double* b = &coordinates[3 * static_cast<std::size_t>(face[(k + 1) % face.size()])];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
      }
      any_area = n[0] != 0.0 || n[1] != 0.0 || n[2] != 0.0;
    }
    if (!any_area) {
      throw IoError(path + ": every face is degenerate (its vertices collinear or repeated: zero area in 3-D), so "
                           "the mesh has no footprint along any up axis");
    }
    const char* axis_names[3] = {"x", "y", "z"};
    const int up = options.up == UpAxis::kX ? 0 : options.up == UpAxis::kY ? 1 : 2;
    if (flat_axis >= 0 && flat_axis != up) {
      throw IoError(path + ": the mesh is flat, drawn in a plane across " + axis_names[flat_axis] +
                    ", so seen along the up axis every face has zero area; --up " + axis_names[flat_axis] + " reads it");
    }
    throw IoError(path + ": every face has zero area seen along the up axis (wrong --up?)");
  }
  if (!thin_along_up && !fanned) {
    if (const std::optional<std::string> open = OddCoverage(projected)) rep.warnings.push_back(*open);
  } else if (!thin_along_up) {
    // A fan's triangles overlap where the outline crosses itself, so coverage parity says nothing.
    rep.warnings.push_back("whether the mesh is closed was not checked: a face crossing itself (its fan of triangles "
                           "overlaps itself) spoils the count of faces over each footprint point; a face missing "
                           "elsewhere would go unseen");
  }
  CGAL::Polygon_set_2<K> set;
  set.join(projected.begin(), projected.end());
  std::vector<PolygonWithHoles> parts;
  set.polygons_with_holes(std::back_inserter(parts));
  std::vector<geometry::Ring> loops;
  for (const PolygonWithHoles& pwh : parts) {
    SplitPinchedRing(ToRing(CleanRing(pwh.outer_boundary(), &rep.vertices_removed)), &loops);
    for (auto h = pwh.holes_begin(); h != pwh.holes_end(); ++h)
      SplitPinchedRing(ToRing(CleanRing(*h, &rep.vertices_removed)), &loops);
  }
  std::vector<geometry::Polygon> polygons;
  try {
    polygons = AssemblePolygons(loops);
  } catch (const IoError& e) {
    throw IoError(path + ": " + e.what());
  }
  try {
    return geometry::Shape::FromPolygons(std::move(polygons));
  } catch (const geometry::GeometryError& e) {
    throw IoError(path + ": footprint is not a valid shape: " + e.what());
  }
}

std::optional<std::string> ShapeUnitsWarning(const geometry::Shape& shape, double scale_given, const std::string& scale_is) {
  if (shape.empty()) return std::nullopt;
  const geometry::Box2 box = shape.bounds();
  const double across = std::max(box.max.x() - box.min.x(), box.max.y() - box.min.y());
  if (!(across > 2.0 || across < 1e-3)) return std::nullopt;
  char text[200];
  // Several parts whose largest is within 1 cm to 1 m across but that together span over 10
  // times it: a stray part far away, not other units (a block with a sliver 5 m off was asked
  // "centimetres or inches?").
  if (shape.polygons().size() > 1) {
    double largest = 0.0;
    for (const geometry::Polygon& p : shape.polygons()) {
      Eigen::Vector2d lo = p.outer.front(), hi = p.outer.front();
      for (const geometry::Vec2& v : p.outer) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      largest = std::max(largest, (hi - lo).maxCoeff() + 2.0 * shape.radius());
    }
    if (largest >= 0.01 && largest <= 1.0 && across > 10.0 * largest) {
      std::snprintf(text, sizeof text,
                    "the shape's %zu parts span %.6g m, but the largest is %.3g m across: a stray part far from the others "
                    "(a footprint unites every face of the file)?",
                    shape.polygons().size(), across, largest);
      return std::string(text);
    }
  }
  // The units that would make it 1 cm to 1 m across (a centimetre mesh was told "millimetres").
  std::string units;
  if (across > 2.0) {
    for (const auto& [name, scale] :
         {std::pair<const char*, double>{"millimetres", 1e-3}, {"centimetres", 1e-2}, {"inches", 0.0254}}) {
      if (across * scale < 0.01 || across * scale > 1.0) continue;
      std::snprintf(text, sizeof text, "%s%s (%s%g%s: %.3g m across)", units.empty() ? "" : " or ", name, scale_is.c_str(),
                    scale * scale_given, scale_given != 1.0 ? " in place of the scale given" : "", across * scale);
      units += text;
    }
  }
  std::snprintf(text, sizeof text, "the shape is %.6g m across: shapes are in metres (", across);
  std::string out = text;
  if (across > 2.0) {
    out += units.empty() ? "is it in other units? " + scale_is + "S converts" : "is the file in " + units + "?";
  } else {
    out += "was it scaled twice, or is it in other units?";
  }
  return out + ")";
}

}  // namespace pushgraph::io
