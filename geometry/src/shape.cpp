// Shape construction: validation, normalization, and the flattened edge representation.
// Simplicity and disjointness are decided with CGAL Epick's exact predicates on candidate edge
// pairs found with the edge index (an R-tree), so validation is O(n log n) on typical input.
#include "shape_impl.h"

#include "exact.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace pushgraph::geometry {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

std::string Where(int polygon, int ring, int vertex = -1) {
  std::ostringstream out;
  out << "polygon " << polygon << ", " << (ring < 0 ? std::string("outer boundary") : "hole " + std::to_string(ring));
  if (vertex >= 0) out << ", vertex " << vertex;
  return out.str();
}

[[noreturn]] void Fail(const std::string& what, int polygon, int ring, int vertex = -1) {
  throw GeometryError(Where(polygon, ring, vertex) + ": " + what, polygon, ring, vertex);
}

std::vector<K::Point_2> ToCgal(const Ring& ring) {
  std::vector<K::Point_2> out;
  out.reserve(ring.size());
  for (const Vec2& v : ring) out.emplace_back(v.x(), v.y());
  return out;
}

// Exact orientation of a simple ring from the turn at its lexicographically smallest vertex.
int RingOrientation(const Ring& ring) {
  const int n = static_cast<int>(ring.size());
  int m = 0;
  for (int i = 1; i < n; ++i) {
    if (ring[i].x() < ring[m].x() || (ring[i].x() == ring[m].x() && ring[i].y() < ring[m].y())) m = i;
  }
  return exact::OrientationSign(ring[(m + n - 1) % n], ring[m], ring[(m + 1) % n]);
}

double SignedArea(const Ring& ring) {
  double twice = 0.0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    twice += (a.x() - ring[0].x()) * (b.y() - ring[0].y()) - (b.x() - ring[0].x()) * (a.y() - ring[0].y());
  }
  return 0.5 * twice;
}

// Drops an explicit closing vertex (last == first), checks finiteness and zero-length edges.
void CleanRing(Ring* ring, int polygon, int ring_index) {
  for (std::size_t i = 0; i < ring->size(); ++i) {
    if (!std::isfinite((*ring)[i].x()) || !std::isfinite((*ring)[i].y()))
      Fail("coordinate is not finite", polygon, ring_index, static_cast<int>(i));
    if (std::abs((*ring)[i].x()) > kMaxCoordinate || std::abs((*ring)[i].y()) > kMaxCoordinate) {
      std::ostringstream text;
      text << std::setprecision(17) << "coordinate (" << (*ring)[i].x() << ", " << (*ring)[i].y() << ") is outside the supported range +-"
           << kMaxCoordinate << " (scale the shape: docs/geometry.md, Limits)";
      Fail(text.str(), polygon, ring_index, static_cast<int>(i));
    }
  }
  if (ring->size() >= 4 && ring->front() == ring->back()) ring->pop_back();
  const int n = static_cast<int>(ring->size());
  if (n < 3) return;
  for (int i = 0; i < n; ++i) {
    if ((*ring)[i] == (*ring)[(i + 1) % n])
      Fail("repeated vertex (zero-length edge to vertex " + std::to_string((i + 1) % n) + ")", polygon, ring_index, i);
  }
}

bool AllCollinear(const Ring& ring) {
  for (std::size_t i = 2; i < ring.size(); ++i)
    if (exact::OrientationSign(ring[0], ring[1], ring[i]) != 0) return false;
  return true;
}

// Strictly inside / on boundary / outside a ring, exactly.
CGAL::Bounded_side SideOfRing(const std::vector<K::Point_2>& ring, const Vec2& p) {
  return CGAL::bounded_side_2(ring.begin(), ring.end(), K::Point_2(p.x(), p.y()), K());
}

// Segments a-b and c-d that share an endpoint and meet nowhere else (not collinear overlapping).
bool TouchOnlyAtSharedVertex(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const Vec2* shared = nullptr;
  const Vec2 *other1 = nullptr, *other2 = nullptr;
  if (a == c) shared = &a, other1 = &b, other2 = &d;
  else if (a == d) shared = &a, other1 = &b, other2 = &c;
  else if (b == c) shared = &b, other1 = &a, other2 = &d;
  else if (b == d) shared = &b, other1 = &a, other2 = &c;
  if (!shared) return false;
  const bool collinear = exact::OrientationSign(*shared, *other1, *other2) == 0;
  return !collinear || exact::DotSign(*other2, *shared, *other1) < 0;  // collinear but pointing apart
}

// Is direction x strictly inside the sector swept counter-clockwise from direction a to b?
bool InSector(const Vec2& x, const Vec2& a, const Vec2& b) {
  const Vec2 o(0.0, 0.0);
  const int ab = exact::OrientationSign(o, a, b);
  if (ab > 0) return exact::OrientationSign(o, a, x) > 0 && exact::OrientationSign(o, x, b) > 0;
  if (ab == 0 && exact::DotSign(b, o, a) < 0) return exact::OrientationSign(o, a, x) > 0;  // half plane
  return !(exact::OrientationSign(o, b, x) >= 0 && exact::OrientationSign(o, x, a) >= 0);
}

// Two rings meeting at a shared vertex (global vertices i and j, same position) must not cross
// there: ring j's two edges at the vertex lie in one sector between ring i's two edges.
void CheckNoCrossingAt(const Shape::Impl& impl, int i, int j) {
  const Vec2& v = impl.vertices[i];
  const Vec2 a = impl.vertices[impl.prev[i]] - v, b = impl.vertices[impl.next[i]] - v;
  const Vec2 c = impl.vertices[impl.prev[j]] - v, d = impl.vertices[impl.next[j]] - v;
  const Vec2 o(0.0, 0.0);
  for (const Vec2* x : {&c, &d}) {
    for (const Vec2* y : {&a, &b}) {
      if (exact::OrientationSign(o, *x, *y) != 0 || exact::DotSign(*x, o, *y) <= 0) continue;
      // Edges of two rings leaving the vertex in one direction overlap: the rings touch along a
      // segment (two squares side by side), which no sector test can call a crossing or not.
      const EdgeId ei = impl.edge_id(i), ej = impl.edge_id(j);
      std::ostringstream text;
      text << "boundary runs along " << Where(ej.polygon, ej.ring) << " from their shared vertex (" << v.x() << ", " << v.y()
           << ", its vertex " << ej.index << "): rings may touch at points, not along edges; unite the two into one "
           << "polygon, or leave a gap";
      Fail(text.str(), ei.polygon, ei.ring, ei.index);
    }
  }
  if (InSector(c, a, b) != InSector(d, a, b)) {
    const EdgeId ei = impl.edge_id(i), ej = impl.edge_id(j);
    Fail("boundary crosses " + Where(ej.polygon, ej.ring) + " at their shared vertex (its vertex " +
             std::to_string(ej.index) + ")",
         ei.polygon, ei.ring, ei.index);
  }
}

// No two edges of any rings may meet, except consecutive edges of a ring at their shared vertex
// (and those must not fold back onto each other), and edges of different rings that touch only at
// a vertex both rings share (a polygon touching another, or its hole, at one point).
void CheckEdgeIntersections(const Shape::Impl& impl) {
  std::vector<int> nearby;
  const int n = static_cast<int>(impl.edges.size());
  for (int k = 0; k < n; ++k) {
    const int i = impl.edges[k];
    const Vec2& a = impl.vertices[i];
    const Vec2& b = impl.vertices[impl.next[i]];
    Box2 box{a.cwiseMin(b), a.cwiseMax(b)};
    impl.index->EdgesInBox(box, &nearby);
    const K::Segment_2 s(K::Point_2(a.x(), a.y()), K::Point_2(b.x(), b.y()));
    for (int l : nearby) {
      if (l <= k) continue;
      const int j = impl.edges[l];
      const Vec2& c = impl.vertices[j];
      const Vec2& d = impl.vertices[impl.next[j]];
      const EdgeId ei = impl.edge_id(i), ej = impl.edge_id(j);
      const bool same_ring = impl.vertex_ring[i] == impl.vertex_ring[j];
      if (same_ring && (impl.next[i] == j || impl.next[j] == i)) {
        // Adjacent edges share one vertex; they are invalid only if they overlap (a spike).
        const bool i_first = impl.next[i] == j;
        const Vec2& u = i_first ? a : c;  // u -> v -> w
        const Vec2& v = i_first ? b : d;
        const Vec2& w = i_first ? d : b;
        const bool also_other_end = impl.next[i] == j && impl.next[j] == i;  // a 2-edge ring
        if (also_other_end || (exact::OrientationSign(u, v, w) == 0 && exact::DotSign(w, v, u) > 0)) {
          const EdgeId at = impl.edge_id(i_first ? impl.next[i] : impl.next[j]);
          Fail("edges fold back onto each other (zero-width spike)", at.polygon, at.ring, at.index);
        }
        continue;
      }
      const K::Segment_2 t(K::Point_2(c.x(), c.y()), K::Point_2(d.x(), d.y()));
      if (!CGAL::do_intersect(s, t)) continue;
      if (!same_ring && TouchOnlyAtSharedVertex(a, b, c, d)) {
        const int vi = (a == c || a == d) ? i : impl.next[i];
        const int vj = (c == a || c == b) ? j : impl.next[j];
        CheckNoCrossingAt(impl, vi, vj);
        continue;
      }
      if (same_ring) {
        Fail("ring is not simple: edge " + std::to_string(ei.index) + " meets edge " + std::to_string(ej.index),
             ei.polygon, ei.ring, ei.index);
      }
      Fail("boundary touches or crosses " + Where(ej.polygon, ej.ring) + " (edge " + std::to_string(ei.index) +
               " meets its edge " + std::to_string(ej.index) + ")",
           ei.polygon, ei.ring, ei.index);
    }
  }
}

// A vertex of `ring` that is not on the boundary `other` (rings may share touching vertices).
const Vec2& VertexOffRing(const Ring& ring, const std::vector<K::Point_2>& other) {
  for (const Vec2& v : ring)
    if (SideOfRing(other, v) != CGAL::ON_BOUNDARY) return v;
  return ring[0];
}

// With no boundary crossings, nesting is decided by one vertex per ring (one not shared with the
// other ring).
void CheckNesting(const std::vector<Polygon>& polygons) {
  const int np = static_cast<int>(polygons.size());
  std::vector<std::vector<std::vector<K::Point_2>>> rings(np);  // [polygon][0: outer, 1+: holes]
  for (int p = 0; p < np; ++p) {
    rings[p].push_back(ToCgal(polygons[p].outer));
    for (const Ring& h : polygons[p].holes) rings[p].push_back(ToCgal(h));
  }
  for (int p = 0; p < np; ++p) {
    const int nh = static_cast<int>(polygons[p].holes.size());
    for (int h = 0; h < nh; ++h) {
      if (SideOfRing(rings[p][0], VertexOffRing(polygons[p].holes[h], rings[p][0])) != CGAL::ON_BOUNDED_SIDE)
        Fail("hole is not inside its outer boundary", p, h, 0);
      for (int g = 0; g < nh; ++g) {
        if (g != h && SideOfRing(rings[p][g + 1], VertexOffRing(polygons[p].holes[h], rings[p][g + 1])) == CGAL::ON_BOUNDED_SIDE)
          Fail("hole lies inside hole " + std::to_string(g) + " of the same polygon", p, h, 0);
      }
    }
  }
  // Polygon p's outer boundary must not start inside polygon q's region (inside q's outer
  // boundary and not inside one of q's holes).
  for (int p = 0; p < np; ++p) {
    for (int q = 0; q < np; ++q) {
      if (p == q) continue;
      const Vec2& v = VertexOffRing(polygons[p].outer, rings[q][0]);
      if (SideOfRing(rings[q][0], v) != CGAL::ON_BOUNDED_SIDE) continue;
      bool in_hole = false;
      for (std::size_t h = 1; h < rings[q].size() && !in_hole; ++h)
        in_hole = SideOfRing(rings[q][h], v) != CGAL::ON_UNBOUNDED_SIDE;
      if (!in_hole) Fail("polygon overlaps polygon " + std::to_string(q), p, -1, 0);
    }
  }
}

void AddRing(Shape::Impl* impl, const Ring& ring, int polygon, int ring_index, bool closed) {
  RingInfo info{polygon, ring_index, static_cast<int>(impl->vertices.size()), static_cast<int>(ring.size())};
  const int r = static_cast<int>(impl->rings.size());
  impl->rings.push_back(info);
  for (int i = 0; i < info.size; ++i) {
    impl->vertices.push_back(ring[i]);
    impl->vertex_ring.push_back(r);
    impl->next.push_back(info.first + (i + 1) % info.size);
    impl->prev.push_back(info.first + (i + info.size - 1) % info.size);
    if (closed || i + 1 < info.size) impl->edges.push_back(info.first + i);
  }
}

}  // namespace

std::shared_ptr<Shape::Impl> BuildShapeImpl(std::vector<Polygon> polygons, double radius) {
  auto impl = std::make_shared<Shape::Impl>();
  impl->radius = radius;
  impl->degenerate_core = polygons.size() == 1 && polygons[0].outer.size() <= 2;
  for (int p = 0; p < static_cast<int>(polygons.size()); ++p) {
    AddRing(impl.get(), polygons[p].outer, p, -1, !impl->degenerate_core);
    for (int h = 0; h < static_cast<int>(polygons[p].holes.size()); ++h) AddRing(impl.get(), polygons[p].holes[h], p, h, true);
    if (!impl->degenerate_core) {
      impl->core_area += SignedArea(polygons[p].outer);
      for (const Ring& hole : polygons[p].holes) impl->core_area += SignedArea(hole);
    }
  }
  impl->core_bounds = {impl->vertices[0], impl->vertices[0]};
  for (const Vec2& v : impl->vertices) {
    impl->core_bounds.min = impl->core_bounds.min.cwiseMin(v);
    impl->core_bounds.max = impl->core_bounds.max.cwiseMax(v);
  }
  impl->convex = impl->degenerate_core;
  if (!impl->degenerate_core && polygons.size() == 1 && polygons[0].holes.empty()) {
    const Ring& r = polygons[0].outer;
    const int n = static_cast<int>(r.size());
    impl->convex = true;
    for (int i = 0; i < n && impl->convex; ++i)
      impl->convex = exact::OrientationSign(r[(i + n - 1) % n], r[i], r[(i + 1) % n]) >= 0;
  }
  // Vertices at the same position: rings touching at a corner (or a pinched obstacle ring).
  const std::vector<Vec2>& v = impl->vertices;
  std::vector<int> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return v[a].x() < v[b].x() || (v[a].x() == v[b].x() && v[a].y() < v[b].y());
  });
  impl->shared_vertex.assign(v.size(), 0);
  for (std::size_t k = 1; k < order.size(); ++k)
    if (v[order[k]] == v[order[k - 1]]) impl->shared_vertex[order[k]] = impl->shared_vertex[order[k - 1]] = 1;
  impl->polygons = std::move(polygons);
  auto index = std::make_shared<EdgeIndex>();
  index->Build(impl->vertices, impl->edges, impl->next, impl->core_bounds);
  impl->index = std::move(index);
  return impl;
}

Shape ShapeAccess::MakeUnchecked(std::vector<Polygon> polygons, double radius) {
  for (Polygon& p : polygons) {
    if (p.outer.size() >= 3 && RingOrientation(p.outer) < 0) std::reverse(p.outer.begin(), p.outer.end());
    for (Ring& h : p.holes)
      if (RingOrientation(h) > 0) std::reverse(h.begin(), h.end());
  }
  return Shape(BuildShapeImpl(std::move(polygons), radius));
}

Shape::Shape() = default;
Shape::Shape(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

Shape Shape::FromPolygons(std::vector<Polygon> polygons, double radius) {
  if (!std::isfinite(radius) || radius < 0.0) {
    std::ostringstream text;
    text << radius;  // 6 significant digits: -1e-09, not -0.000000
    throw GeometryError("rounding radius must be finite and >= 0, got " + text.str());
  }
  if (radius > kMaxCoordinate) {
    std::ostringstream text;
    text << "rounding radius " << radius << " is above the supported " << kMaxCoordinate << " (docs/geometry.md, Limits)";
    throw GeometryError(text.str());
  }
  if (polygons.empty()) throw GeometryError("shape has no polygons");
  const int np = static_cast<int>(polygons.size());
  for (int p = 0; p < np; ++p) {
    Polygon& poly = polygons[p];
    CleanRing(&poly.outer, p, -1);
    const std::size_t n = poly.outer.size();
    if (n == 0) Fail("outer boundary has no vertices", p, -1);
    if (n <= 2) {
      const char* kind = n == 1 ? "a point" : "a segment";
      if (radius <= 0.0) Fail(std::string("outer boundary is ") + kind + ", which needs a rounding radius > 0", p, -1);
      if (np > 1) Fail(std::string("a point or segment core must be the shape's only polygon"), p, -1);
      if (!poly.holes.empty()) Fail(std::string(kind) + " cannot have holes", p, 0);
      if (n == 2 && poly.outer[0] == poly.outer[1]) Fail("segment has two equal vertices", p, -1, 1);
      continue;
    }
    if (AllCollinear(poly.outer)) Fail("outer boundary has zero area (all vertices collinear)", p, -1);
    if (RingOrientation(poly.outer) < 0) std::reverse(poly.outer.begin(), poly.outer.end());
    for (int h = 0; h < static_cast<int>(poly.holes.size()); ++h) {
      Ring& hole = poly.holes[h];
      CleanRing(&hole, p, h);
      if (hole.size() < 3) Fail("hole needs at least 3 vertices", p, h);
      if (AllCollinear(hole)) Fail("hole has zero area (all vertices collinear)", p, h);
      if (RingOrientation(hole) > 0) std::reverse(hole.begin(), hole.end());
    }
  }
  std::shared_ptr<Impl> impl = BuildShapeImpl(std::move(polygons), radius);
  const Vec2 size = impl->core_bounds.max - impl->core_bounds.min;
  if (std::max(size.x(), size.y()) + 2.0 * radius < kMinExtent) {
    std::ostringstream text;
    text << "the shape is " << std::max(size.x(), size.y()) + 2.0 * radius << " across, below the supported "
         << kMinExtent << " (scale the shape: docs/geometry.md, Limits)";
    throw GeometryError(text.str());
  }
  if (!impl->degenerate_core) {
    CheckEdgeIntersections(*impl);
    CheckNesting(impl->polygons);
  }
  return Shape(std::move(impl));
}

Shape Shape::Disk(double radius, const Vec2& centre) { return FromPolygons({Polygon{{centre}, {}}}, radius); }

Shape Shape::Capsule(const Vec2& a, const Vec2& b, double radius) { return FromPolygons({Polygon{{a, b}, {}}}, radius); }

Shape Shape::Box(double width, double height, double radius) {
  if (!(width > 0.0) || !(height > 0.0) || !std::isfinite(width) || !std::isfinite(height))
    throw GeometryError("box width and height must be finite and > 0");
  const double w = 0.5 * width, h = 0.5 * height;
  return FromPolygons({Polygon{{{-w, -h}, {w, -h}, {w, h}, {-w, h}}, {}}}, radius);
}

Shape Shape::RegularPolygon(int n, double circumradius, double radius) {
  if (n < 3) throw GeometryError("a regular polygon needs n >= 3, got " + std::to_string(n));
  // A bound before any allocation: n = 1e9 ran out of memory (killed, or std::bad_alloc).
  constexpr int kMaxCorners = 1000000;
  if (n > kMaxCorners)
    throw GeometryError("a regular polygon of " + std::to_string(n) + " corners is more than " + std::to_string(kMaxCorners) +
                        " (a circle is Shape::Disk)");
  if (!(circumradius > 0.0) || !std::isfinite(circumradius)) throw GeometryError("circumradius must be finite and > 0");
  Ring ring;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    ring.emplace_back(circumradius * std::cos(a), circumradius * std::sin(a));
  }
  return FromPolygons({Polygon{ring, {}}}, radius);
}

const Shape::Impl& Shape::impl() const {
  if (!impl_) throw GeometryError("operation on an empty shape");
  return *impl_;
}
bool Shape::empty() const { return !impl_; }
double Shape::radius() const { return impl().radius; }
const std::vector<Polygon>& Shape::polygons() const { return impl().polygons; }
bool Shape::is_degenerate_core() const { return impl().degenerate_core; }
bool Shape::is_convex() const { return impl().convex; }
int Shape::num_vertices() const { return static_cast<int>(impl().vertices.size()); }
double Shape::core_area() const { return impl().core_area; }
Box2 Shape::bounds() const {
  const Impl& m = impl();
  return {m.core_bounds.min - Vec2::Constant(m.radius), m.core_bounds.max + Vec2::Constant(m.radius)};
}
const Ring& Shape::ring(int polygon, int ring) const {
  const Impl& m = impl();
  if (polygon < 0 || polygon >= static_cast<int>(m.polygons.size()))
    throw GeometryError("no polygon " + std::to_string(polygon));
  const Polygon& p = m.polygons[polygon];
  if (ring < -1 || ring >= static_cast<int>(p.holes.size()))
    throw GeometryError("polygon " + std::to_string(polygon) + " has no hole " + std::to_string(ring));
  return ring < 0 ? p.outer : p.holes[ring];
}
Shape Shape::WithRadius(double radius) const {
  if (!std::isfinite(radius) || radius < 0.0) throw GeometryError("rounding radius must be finite and >= 0");
  if (radius > kMaxCoordinate) throw GeometryError("rounding radius is above the supported 1e6 (docs/geometry.md, Limits)");
  if (impl().degenerate_core && radius <= 0.0) throw GeometryError("a point or segment core needs a rounding radius > 0");
  // The same core (validated when this shape was made) and its index; only the radius differs.
  auto copy = std::make_shared<Impl>(impl());
  copy->radius = radius;
  return Shape(std::move(copy));
}

}  // namespace pushgraph::geometry
