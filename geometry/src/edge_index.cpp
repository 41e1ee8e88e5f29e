#include "edge_index.h"

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

namespace pushgraph::geometry {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BSegment = bg::model::segment<BPoint>;
using BBox = bg::model::box<BPoint>;
using RValue = std::pair<BSegment, int>;
using RTree = bgi::rtree<RValue, bgi::rstar<16>>;

// Below this many edges a linear scan is as fast as any index.
constexpr int kLinearScanEdges = 8;

double PointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 e = b - a;
  const double len2 = e.squaredNorm();
  double t = len2 > 0 ? (p - a).dot(e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (p - (a + t * e)).norm();
}

double PointBoxDistance(const Vec2& p, const Box2& box) {
  const double dx = std::max({box.min.x() - p.x(), 0.0, p.x() - box.max.x()});
  const double dy = std::max({box.min.y() - p.y(), 0.0, p.y() - box.max.y()});
  return std::sqrt(dx * dx + dy * dy);  // std::hypot is several times slower here
}

// Liang-Barsky clip: does segment a-b meet the closed box?
bool SegmentMeetsBox(const Vec2& a, const Vec2& b, const Box2& box) {
  double t0 = 0.0, t1 = 1.0;
  const Vec2 d = b - a;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a.x() - box.min.x(), box.max.x() - a.x(), a.y() - box.min.y(), box.max.y() - a.y()};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0.0) {
      if (q[i] < 0.0) return false;
    } else {
      const double r = q[i] / p[i];
      if (p[i] < 0.0) t0 = std::max(t0, r);
      else t1 = std::min(t1, r);
      if (t0 > t1) return false;
    }
  }
  return true;
}

double SegmentBoxDistance(const Vec2& a, const Vec2& b, const Box2& box) {
  if (SegmentMeetsBox(a, b, box)) return 0.0;
  double d = std::min(PointBoxDistance(a, box), PointBoxDistance(b, box));
  const Vec2 corners[4] = {box.min, {box.max.x(), box.min.y()}, box.max, {box.min.x(), box.max.y()}};
  for (const Vec2& c : corners) d = std::min(d, PointSegmentDistance(c, a, b));
  return d;
}

}  // namespace

struct EdgeIndex::Impl {
  std::vector<Vec2> a, b;  // edge endpoints by edge number
  RTree rtree;
  // Grid: cells x cells over `grid`, candidate lists in CSR form.
  Box2 grid;
  int nx = 0, ny = 0;
  double inv_cell_x = 0, inv_cell_y = 0;
  std::vector<int> cell_start;
  std::vector<int> cell_edges;
  std::vector<char> fallback;  // cells answered by the R-tree (too many near-equidistant edges)
  std::vector<int> all_edges;

  // Every edge whose distance to p is within rounding of the nearest one, visiting the R-tree
  // in increasing distance order (incremental nearest-neighbour query): only near-ties are read.
  void NearestEdges(const Vec2& p, std::vector<int>* out) const {
    out->clear();
    double limit = std::numeric_limits<double>::infinity();
    for (auto it = rtree.qbegin(bgi::nearest(BPoint(p.x(), p.y()), static_cast<unsigned>(a.size()))); it != rtree.qend(); ++it) {
      const double d = PointSegmentDistance(p, a[it->second], b[it->second]);
      if (d > limit) break;
      if (out->empty()) limit = d * (1.0 + 1e-9) + 1e-300;
      out->push_back(it->second);
    }
  }

};

EdgeIndex::EdgeIndex() : impl_(std::make_unique<Impl>()) {}
EdgeIndex::~EdgeIndex() = default;
EdgeIndex::EdgeIndex(EdgeIndex&&) noexcept = default;
EdgeIndex& EdgeIndex::operator=(EdgeIndex&&) noexcept = default;

void EdgeIndex::Build(const std::vector<Vec2>& vertices, const std::vector<int>& edges, const std::vector<int>& next,
                      const Box2& bounds) {
  Impl& m = *impl_;
  const int n = static_cast<int>(edges.size());
  m.a.resize(n);
  m.b.resize(n);
  std::vector<RValue> values;
  values.reserve(n);
  for (int k = 0; k < n; ++k) {
    m.a[k] = vertices[edges[k]];
    m.b[k] = vertices[next[edges[k]]];
    values.emplace_back(BSegment(BPoint(m.a[k].x(), m.a[k].y()), BPoint(m.b[k].x(), m.b[k].y())), k);
  }
  m.rtree = RTree(values.begin(), values.end());  // bulk loading (packing)
  m.all_edges.resize(n);
  std::iota(m.all_edges.begin(), m.all_edges.end(), 0);
  m.nx = m.ny = 0;
  if (n <= kLinearScanEdges) return;

  // Grid over the bounds plus a margin of a quarter of the size, 2^k x 2^k cells with about 16
  // cells per edge, so that a cell is small against the features and its candidate list short.
  const Vec2 size = bounds.max - bounds.min;
  const double extent = std::max(size.x(), size.y());
  const Vec2 margin = Vec2::Constant(0.25 * extent);
  m.grid = {bounds.min - margin, bounds.max + margin};
  int levels = 5;
  while (levels < 9 && (1 << (2 * levels)) < 16 * n) ++levels;
  m.nx = m.ny = 1 << levels;
  const Vec2 gsize = m.grid.max - m.grid.min;
  const double cx = gsize.x() / m.nx, cy = gsize.y() / m.ny;
  m.inv_cell_x = 1.0 / cx;
  m.inv_cell_y = 1.0 / cy;

  // Quadtree refinement: a child cell's candidates are a subset of its parent's (its bound on
  // the nearest-edge distance is no larger, its distance to every edge no smaller), so each
  // node filters its parent's list instead of searching all edges.
  std::vector<int> items;
  std::vector<std::pair<int, int>> leaves;  // (cell, first item); lists are contiguous
  std::function<void(int, int, int, const std::vector<int>&)> refine = [&](int ix, int iy, int span,
                                                                          const std::vector<int>& parent) {
    const Vec2 lo = m.grid.min + Vec2(ix * cx, iy * cy);
    const Vec2 extent_cells(span * cx, span * cy);
    // Padded by a relative 1e-9 so that rounding in the cell lookup never places a point outside
    // the box its list was made for.
    const Vec2 pad(cx * 1e-9 + 1e-300, cy * 1e-9 + 1e-300);
    const Box2 box{lo - pad, lo + extent_cells + pad};
    const Vec2 centre = lo + 0.5 * extent_cells;
    const double half_diagonal = 0.5 * extent_cells.norm();
    double nearest = std::numeric_limits<double>::infinity();
    for (int k : parent) nearest = std::min(nearest, PointSegmentDistance(centre, m.a[k], m.b[k]));
    // Every point of the box is within `upper` of the edge nearest to its centre, so only edges
    // within `upper` of the box can be closest to one of its points.
    const double upper = (nearest + half_diagonal) * (1.0 + 1e-9) + 1e-300;
    std::vector<int> mine;
    mine.reserve(parent.size());
    for (int k : parent)
      if (SegmentBoxDistance(m.a[k], m.b[k], box) <= upper) mine.push_back(k);
    // Inside finely tessellated round shapes many edges are almost equidistant from a whole cell
    // and lists stay long: such cells use the R-tree's incremental nearest query, which reads only
    // the near-ties, instead of a long list.
    const std::size_t cap = span == 1 ? 64 : 512;
    if (span <= m.nx / 8 && mine.size() > cap) {
      for (int y = iy; y < iy + span; ++y)
        for (int x = ix; x < ix + span; ++x) leaves.emplace_back(y * m.nx + x, -1);
      return;
    }
    if (span == 1) {
      leaves.emplace_back(iy * m.nx + ix, static_cast<int>(items.size()));
      items.insert(items.end(), mine.begin(), mine.end());
      return;
    }
    const int half = span / 2;
    for (int q = 0; q < 4; ++q) refine(ix + (q & 1) * half, iy + (q >> 1) * half, half, mine);
  };
  refine(0, 0, m.nx, m.all_edges);
  // Leaves come in quadtree order; lay the lists out by cell number.
  std::vector<int> count(static_cast<std::size_t>(m.nx) * m.ny, 0), first(count.size(), 0);
  m.fallback.assign(count.size(), 0);
  int next_first = static_cast<int>(items.size());
  for (std::size_t l = leaves.size(); l-- > 0;) {  // backwards: each list ends where the next begins
    if (leaves[l].second < 0) {
      m.fallback[leaves[l].first] = 1;
      continue;
    }
    count[leaves[l].first] = next_first - leaves[l].second;
    first[leaves[l].first] = leaves[l].second;
    next_first = leaves[l].second;
  }
  m.cell_start.assign(count.size() + 1, 0);
  for (std::size_t c = 0; c < count.size(); ++c) m.cell_start[c + 1] = m.cell_start[c] + count[c];
  m.cell_edges.resize(items.size());
  for (std::size_t c = 0; c < count.size(); ++c)
    std::copy(items.begin() + first[c], items.begin() + first[c] + count[c], m.cell_edges.begin() + m.cell_start[c]);
}

EdgeIndex::Span EdgeIndex::Candidates(const Vec2& p) const {
  const Impl& m = *impl_;
  if (m.nx == 0) return {m.all_edges.data(), static_cast<int>(m.all_edges.size())};
  const double fx = (p.x() - m.grid.min.x()) * m.inv_cell_x;
  const double fy = (p.y() - m.grid.min.y()) * m.inv_cell_y;
  if (fx >= 0.0 && fy >= 0.0 && fx < m.nx && fy < m.ny) {
    const std::size_t cell = static_cast<std::size_t>(fy) * m.nx + static_cast<std::size_t>(fx);
    if (!m.fallback[cell]) return {m.cell_edges.data() + m.cell_start[cell], m.cell_start[cell + 1] - m.cell_start[cell]};
  }
  // Outside the grid, or in a fallback cell.
  thread_local std::vector<int> scratch;
  m.NearestEdges(p, &scratch);
  return {scratch.data(), static_cast<int>(scratch.size())};
}

void EdgeIndex::EdgesInBox(const Box2& box, std::vector<int>* out) const {
  const BBox query(BPoint(box.min.x(), box.min.y()), BPoint(box.max.x(), box.max.y()));
  out->clear();
  for (auto it = impl_->rtree.qbegin(bgi::intersects(query)); it != impl_->rtree.qend(); ++it)
    out->push_back(it->second);
}

}  // namespace pushgraph::geometry
