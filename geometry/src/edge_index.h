#pragma once
// Spatial index over a shape's edges, so that a point query does not visit every edge.
//
// Two levels: a uniform grid over the shape's neighbourhood (about 16 cells per edge, at most
// 512 x 512) whose cells store a conservative candidate list (every edge that can be closest to
// some point of the cell: those whose distance to the cell is at most the cell's upper bound on
// the nearest-edge distance), and a strip tree (chains of edges in chord-aligned rectangles and,
// where they bend like arcs, annular sectors) searched by branch and bound for points outside the
// grid, in cells whose lists would be long, and for every point until the 256th query builds the
// grid (a shape queried a few times, a Minkowski obstacle at one angle, never pays for it). A query reads O(log n) nodes plus the features tied
// with the nearest to within rounding. A Boost.Geometry R-tree answers box queries (validation).
// Candidate lists are filters only; the final choice among candidates is made with exact
// predicates.
#include <pushgraph/geometry/types.h>

#include <memory>
#include <vector>

namespace pushgraph::geometry {

class EdgeIndex {
 public:
  EdgeIndex();
  ~EdgeIndex();
  EdgeIndex(EdgeIndex&&) noexcept;
  EdgeIndex& operator=(EdgeIndex&&) noexcept;

  /// Edge k runs from vertices[edges[k]] to vertices[next[edges[k]]].
  void Build(const std::vector<Vec2>& vertices, const std::vector<int>& edges, const std::vector<int>& next,
             const Box2& bounds);

  /// Candidate edge numbers (positions in `edges`) that include every edge closest to p.
  /// The span stays valid until the next call on the same thread.
  struct Span {
    const int* data = nullptr;
    int size = 0;
  };
  Span Candidates(const Vec2& p) const;

  /// All edges whose bounding boxes intersect the box (for validation).
  void EdgesInBox(const Box2& box, std::vector<int>* out) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::geometry
