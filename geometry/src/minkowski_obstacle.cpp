// Exact Minkowski sums of polygonal cores (CGAL 5.5, Epeck, reduced convolution).
#include "minkowski_obstacle.h"

#include "shape_impl.h"

#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_set_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/minkowski_sum_2.h>

#include <cmath>

namespace pushgraph::geometry {
namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = K::Point_2;
using Polygon2 = CGAL::Polygon_2<K>;
using PolygonWithHoles = CGAL::Polygon_with_holes_2<K>;
using PolygonSet = CGAL::Polygon_set_2<K>;

Polygon2 ToCgal(const Ring& ring) {
  Polygon2 out;
  for (const Vec2& v : ring) out.push_back(Point(v.x(), v.y()));
  return out;
}

PolygonWithHoles ToCgal(const Polygon& p) {
  PolygonWithHoles out(ToCgal(p.outer));
  for (const Ring& h : p.holes) out.add_hole(ToCgal(h));
  return out;
}

Ring FromCgal(const Polygon2& p) {
  Ring out;
  for (auto it = p.vertices_begin(); it != p.vertices_end(); ++it)
    out.emplace_back(CGAL::to_double(it->x()), CGAL::to_double(it->y()));
  return out;
}

Polygon2 Translated(const Polygon2& p, const Point& t) {
  Polygon2 out;
  for (auto it = p.vertices_begin(); it != p.vertices_end(); ++it) out.push_back(Point(it->x() + t.x(), it->y() + t.y()));
  return out;
}

// A segment s0-s1 swept over a polygon with holes: P(+)s = (P + s0) u (P + s1) u U (e (+) s)
// over the boundary edges e, each parallelogram non-degenerate unless e is parallel to s.
void AddSegmentSum(const PolygonWithHoles& p, const Point& s0, const Point& s1, PolygonSet* set) {
  auto translated = [&](const Point& t) {
    PolygonWithHoles out(Translated(p.outer_boundary(), t));
    for (auto h = p.holes_begin(); h != p.holes_end(); ++h) out.add_hole(Translated(*h, t));
    return out;
  };
  set->join(translated(s0));
  set->join(translated(s1));
  const K::Vector_2 d = s1 - s0;
  auto add_edges = [&](const Polygon2& ring) {
    for (auto e = ring.edges_begin(); e != ring.edges_end(); ++e) {
      const Point a = e->source() + (s0 - CGAL::ORIGIN), b = e->target() + (s0 - CGAL::ORIGIN);
      if (CGAL::orientation(a, b, b + d) == CGAL::COLLINEAR) continue;
      Polygon2 quad;
      quad.push_back(a);
      quad.push_back(b);
      quad.push_back(b + d);
      quad.push_back(a + d);
      if (quad.orientation() == CGAL::CLOCKWISE) quad.reverse_orientation();
      set->join(quad);
    }
  };
  add_edges(p.outer_boundary());
  for (auto h = p.holes_begin(); h != p.holes_end(); ++h) add_edges(*h);
}

std::vector<Polygon> FromPolygonSet(const PolygonSet& set) {
  std::vector<PolygonWithHoles> parts;
  set.polygons_with_holes(std::back_inserter(parts));
  std::vector<Polygon> out;
  for (const PolygonWithHoles& pwh : parts) {
    Polygon p;
    p.outer = FromCgal(pwh.outer_boundary());
    for (auto h = pwh.holes_begin(); h != pwh.holes_end(); ++h) p.holes.push_back(FromCgal(*h));
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace

Shape RotatedReflectedCore(const Shape& shape, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  auto map_ring = [&](const Ring& ring) {
    Ring out;
    for (const Vec2& v : ring) out.emplace_back(-(c * v.x() - s * v.y()), -(s * v.x() + c * v.y()));
    return out;
  };
  std::vector<Polygon> polygons;
  for (const Polygon& p : shape.polygons()) {
    Polygon q{map_ring(p.outer), {}};
    for (const Ring& h : p.holes) q.holes.push_back(map_ring(h));
    polygons.push_back(std::move(q));
  }
  // A point reflection keeps orientation; rotation too: rings stay normalized.
  return ShapeAccess::MakeUnchecked(std::move(polygons), shape.radius());
}

Shape MinkowskiSumOfCores(const Shape& a, const Shape& b, double radius) {
  const bool a_small = a.is_degenerate_core(), b_small = b.is_degenerate_core();
  const Shape& big = a_small ? b : a;
  const Shape& small = a_small ? a : b;
  if (a_small && b_small) {
    // Point/segment (+) point/segment: a point, a segment or a parallelogram.
    const Ring& p = a.polygons()[0].outer;
    const Ring& q = b.polygons()[0].outer;
    if (p.size() == 1 || q.size() == 1) {
      const Ring& other = p.size() == 1 ? q : p;
      const Vec2 t = p.size() == 1 ? p[0] : q[0];
      Ring sum;
      for (const Vec2& v : other) sum.push_back(v + t);
      return ShapeAccess::MakeUnchecked({Polygon{sum, {}}}, radius);
    }
    const Vec2 u = p[1] - p[0], v = q[1] - q[0];
    if (u.x() * v.y() - u.y() * v.x() == 0.0) {  // parallel: a segment (extreme sums)
      Ring candidates = {p[0] + q[0], p[0] + q[1], p[1] + q[0], p[1] + q[1]};
      std::sort(candidates.begin(), candidates.end(), [](const Vec2& x, const Vec2& y) {
        return x.x() < y.x() || (x.x() == y.x() && x.y() < y.y());
      });
      return ShapeAccess::MakeUnchecked({Polygon{{candidates.front(), candidates.back()}, {}}}, radius);
    }
    return ShapeAccess::MakeUnchecked({Polygon{{p[0] + q[0], p[1] + q[0], p[1] + q[1], p[0] + q[1]}, {}}}, radius);
  }
  PolygonSet set;
  if (small.is_degenerate_core()) {
    const Ring& s = small.polygons()[0].outer;
    const Point s0(s[0].x(), s[0].y());
    for (const Polygon& p : big.polygons()) {
      if (s.size() == 1) {
        PolygonWithHoles pwh = ToCgal(p);
        PolygonWithHoles moved(Translated(pwh.outer_boundary(), s0));
        for (auto h = pwh.holes_begin(); h != pwh.holes_end(); ++h) moved.add_hole(Translated(*h, s0));
        set.join(moved);
      } else {
        AddSegmentSum(ToCgal(p), s0, Point(s[1].x(), s[1].y()), &set);
      }
    }
  } else {
    for (const Polygon& p : a.polygons()) {
      const PolygonWithHoles pa = ToCgal(p);
      for (const Polygon& q : b.polygons()) {
        // Reduced convolution (Behar and Lien 2011), CGAL's default and fastest method.
        set.join(CGAL::minkowski_sum_2(pa, ToCgal(q)));
      }
    }
  }
  return ShapeAccess::MakeUnchecked(FromPolygonSet(set), radius);
}

}  // namespace pushgraph::geometry
