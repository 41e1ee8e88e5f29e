#pragma once
// Internal representation of a Shape: flattened rings and edges plus the edge index.
#include <pushgraph/geometry/shape.h>

#include "edge_index.h"

#include <memory>
#include <vector>

namespace pushgraph::geometry {

struct RingInfo {
  int polygon = 0;
  int ring = -1;   // -1 outer, k hole k
  int first = 0;   // first global vertex
  int size = 0;    // number of vertices
};

struct Shape::Impl {
  std::vector<Polygon> polygons;  // normalized: outer CCW, holes CW
  double radius = 0.0;
  bool degenerate_core = false;   // a single point or segment
  bool convex = false;
  // Per vertex: another ring has a vertex at the same position (rings touching at a corner, as
  // in exact footprints and Minkowski obstacles); the side there is decided by parity.
  std::vector<char> shared_vertex;

  // Flattened vertices of all rings; edge i runs from vertex i to vertex next[i]. For a segment
  // core there is one edge (0 -> 1); for a point core none.
  std::vector<Vec2> vertices;
  std::vector<int> next, prev, vertex_ring;
  std::vector<RingInfo> rings;
  std::vector<int> edges;  // global start-vertex index of every edge
  Box2 core_bounds;
  double core_area = 0.0;
  // Depends on the core only: shapes that differ in the rounding radius share it.
  std::shared_ptr<const EdgeIndex> index;

  EdgeId edge_id(int global_vertex) const {
    const RingInfo& r = rings[vertex_ring[global_vertex]];
    return {r.polygon, r.ring, global_vertex - r.first};
  }
};

// Builds an Impl from polygons already in normalized orientation; validation is done by the
// caller (Shape::FromPolygons validates user input; internal obstacles from CGAL are valid
// by construction but may touch at isolated vertices).
std::shared_ptr<Shape::Impl> BuildShapeImpl(std::vector<Polygon> polygons, double radius);

// Internal factory used by obstacle construction: orients rings, skips user-facing validation.
struct ShapeAccess {
  static Shape MakeUnchecked(std::vector<Polygon> polygons, double radius);
  static Shape FromImpl(std::shared_ptr<const Shape::Impl> impl) { return Shape(std::move(impl)); }
};

}  // namespace pushgraph::geometry
