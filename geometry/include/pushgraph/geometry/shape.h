#pragma once
// A planar shape: a set of simple polygons with holes, plus a rounding radius r >= 0.
// The shape is every point within r of the polygons (a disk finger is one point with r > 0,
// a capsule a segment with r > 0, a rounded box a rectangle with r > 0).
//
// Construction validates and normalizes: either orientation is accepted on input; outer
// boundaries are stored counter-clockwise and holes clockwise (interior always on the left).
// Rings must be simple with no zero-length edges and no zero area; holes lie strictly inside
// their outer boundary and are disjoint from each other; polygons are pairwise disjoint; all
// coordinates are finite. Different rings may touch at a vertex they share (a footprint whose
// parts meet at a corner), but never cross or overlap along an edge. Violations throw
// GeometryError naming the polygon, ring and vertex.
//
//   auto finger = Shape::Disk(0.00235);
//   auto block  = Shape::FromPolygons({{{{0,0}, {0.09,0}, {0.09,0.09}, {0,0.09}}, {}}});
//   auto notch  = LoadShapeJson("data/shapes/notched_block.json");
#include <pushgraph/geometry/types.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::geometry {

struct Pose2;  // pose.h
using Ring = std::vector<Vec2>;

struct Polygon {
  Ring outer;               ///< 1 vertex: a point, 2: a segment (both need radius > 0), >= 3: area
  std::vector<Ring> holes;  ///< only for polygons with area
};

/// One edge of a ring: from vertex `index` to vertex `index + 1` (cyclic).
struct EdgeId {
  int polygon = -1;
  int ring = -1;   ///< -1: outer boundary; k >= 0: hole k
  int index = -1;  ///< index of the start vertex within the ring
};

class Shape {
 public:
  /// An empty shape; queries on it throw GeometryError.
  Shape();

  /// Validates and normalizes; throws GeometryError on invalid input.
  static Shape FromPolygons(std::vector<Polygon> polygons, double radius = 0.0);
  static Shape Disk(double radius, const Vec2& centre = Vec2::Zero());
  static Shape Capsule(const Vec2& a, const Vec2& b, double radius);
  /// Axis-aligned rectangle centred at the origin, optionally rounded.
  static Shape Box(double width, double height, double radius = 0.0);
  /// Convex regular n-gon centred at the origin with circumradius `circumradius` (3 <= n <= 1e6).
  static Shape RegularPolygon(int n, double circumradius, double radius = 0.0);

  bool empty() const;
  double radius() const;
  /// The normalized polygons (outer CCW, holes CW).
  const std::vector<Polygon>& polygons() const;
  /// True when the shape's core is a single point or segment (no area before rounding).
  bool is_degenerate_core() const;
  /// True when the core is one convex polygon without holes, a segment or a point.
  bool is_convex() const;
  int num_vertices() const;
  /// Bounding box of the whole shape, rounding included.
  Box2 bounds() const;
  /// Area of the core polygons (rounding not included).
  double core_area() const;
  /// The ring an edge or vertex belongs to.
  const Ring& ring(int polygon, int ring) const;
  /// Same polygons, different rounding radius.
  Shape WithRadius(double radius) const;

  struct Impl;
  const Impl& impl() const;  ///< internal: acceleration structures (opaque to users)

 private:
  friend struct ShapeAccess;  // internal construction without user-input validation
  explicit Shape(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

/// Loads a shape from JSON:
///   {"polygons": [{"outer": [[x, y], ...], "holes": [[[x, y], ...], ...]}, ...], "radius": 0.0}
/// Errors name the file and the offending polygon/vertex, or the unknown/missing field.
Shape LoadShapeJson(const std::string& path);
Shape ParseShapeJson(const std::string& json_text, const std::string& source_name = "<string>");
std::string ShapeToJson(const Shape& shape, int indent = 2);
void SaveShapeJson(const Shape& shape, const std::string& path);

/// The shape mirrored (optionally), scaled about its frame's origin, then placed at `pose`:
/// every point p becomes pose * (scale * M p), M = diag(1, -1) when `mirror` (a footprint seen
/// from below) and the identity otherwise; the rounding radius becomes scale * radius. Moves a
/// shape file into the frame a tracker reports (graph::RegisterShape) or changes its units
/// (scale 0.001: millimetres to metres). Throws GeometryError for a non-finite pose or a scale
/// that is not finite and > 0.
Shape TransformShape(const Shape& shape, const Pose2& pose, double scale = 1.0, bool mirror = false);

/// Area centroid of the core polygons (holes subtracted); the mean of the vertices for a point
/// or segment core.
Vec2 CoreCentroid(const Shape& shape);

/// Largest distance from `centre` to the shape (rounding included): the radius of the smallest
/// disk about `centre` that holds it.
double RadiusAbout(const Shape& shape, const Vec2& centre);

/// A tessellated cylinder's footprint (a round probe exported as a mesh: the MIT tip.obj is a
/// 32-gon of radius 4.7 mm) and the disk it stands for.
struct TessellatedDiskFit {
  Shape disk;               ///< centre the corners' mean, radius their mean distance from it
  std::size_t corners = 0;  ///< of the regular polygon
};
/// The disk a regular polygon of 20 or more corners approximates: one polygon, no holes, no
/// rounding, every corner within 0.5 % of the mean radius and every turn within 20 % of
/// 360 / corners degrees (a 12-gon's inscribed circle is already 3.4 % inside its circumcircle).
/// Seam vertices (duplicates, or points on the line through their neighbours, which an exact
/// union of a re-exported mesh keeps) are no corners. nullopt for any other shape.
std::optional<TessellatedDiskFit> TessellatedDisk(const Shape& shape);

}  // namespace pushgraph::geometry
