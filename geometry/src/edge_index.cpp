#include "edge_index.h"

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <cmath>
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
  return std::hypot(dx, dy);
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
  std::vector<int> all_edges;

  void NearbyEdges(const Vec2& p, double radius, std::vector<int>* out) const {
    const BBox query(BPoint(p.x() - radius, p.y() - radius), BPoint(p.x() + radius, p.y() + radius));
    out->clear();
    for (auto it = rtree.qbegin(bgi::intersects(query)); it != rtree.qend(); ++it) out->push_back(it->second);
  }

  // An upper bound on the distance from p to the nearest edge.
  double NearestEdgeDistance(const Vec2& p) const {
    auto it = rtree.qbegin(bgi::nearest(BPoint(p.x(), p.y()), 1));
    return PointSegmentDistance(p, a[it->second], b[it->second]);
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

  // Grid over the bounds plus a margin of a quarter of the size; about 16 cells per edge, so
  // that a cell is small against the features and its candidate list short (1 to 3 edges).
  const Vec2 size = bounds.max - bounds.min;
  const double extent = std::max(size.x(), size.y());
  const Vec2 margin = Vec2::Constant(0.25 * extent);
  m.grid = {bounds.min - margin, bounds.max + margin};
  const Vec2 gsize = m.grid.max - m.grid.min;
  const int cells = std::clamp(16 * n, 1024, 1 << 18);
  const double aspect = gsize.x() / std::max(gsize.y(), 1e-300);
  m.nx = std::clamp(static_cast<int>(std::ceil(std::sqrt(cells * aspect))), 1, 1024);
  m.ny = std::clamp(static_cast<int>(std::ceil(cells / static_cast<double>(m.nx))), 1, 1024);
  const double cx = gsize.x() / m.nx, cy = gsize.y() / m.ny;
  m.inv_cell_x = 1.0 / cx;
  m.inv_cell_y = 1.0 / cy;
  m.cell_start.assign(static_cast<std::size_t>(m.nx) * m.ny + 1, 0);
  m.cell_edges.clear();
  std::vector<int> nearby;
  const double half_diagonal = 0.5 * std::hypot(cx, cy);
  for (int j = 0; j < m.ny; ++j) {
    for (int i = 0; i < m.nx; ++i) {
      // Cell boxes are padded by a relative 1e-9 so that rounding in the cell lookup can never
      // place a point outside the box its list was made for.
      const Vec2 lo = m.grid.min + Vec2(i * cx, j * cy);
      const Vec2 pad(cx * 1e-9 + 1e-300, cy * 1e-9 + 1e-300);
      const Box2 cell{lo - pad, lo + Vec2(cx, cy) + pad};
      const Vec2 centre = lo + 0.5 * Vec2(cx, cy);
      // Every point of the cell is within `upper` of the edge nearest to the centre, so only
      // edges within `upper` of the cell can be closest to a point of the cell.
      const double upper = (m.NearestEdgeDistance(centre) + half_diagonal) * (1.0 + 1e-9) + 1e-300;
      m.NearbyEdges(centre, upper + half_diagonal, &nearby);
      for (int k : nearby) {
        if (SegmentBoxDistance(m.a[k], m.b[k], cell) <= upper) m.cell_edges.push_back(k);
      }
      m.cell_start[static_cast<std::size_t>(j) * m.nx + i + 1] = static_cast<int>(m.cell_edges.size());
    }
  }
}

EdgeIndex::Span EdgeIndex::Candidates(const Vec2& p) const {
  const Impl& m = *impl_;
  if (m.nx == 0) return {m.all_edges.data(), static_cast<int>(m.all_edges.size())};
  const double fx = (p.x() - m.grid.min.x()) * m.inv_cell_x;
  const double fy = (p.y() - m.grid.min.y()) * m.inv_cell_y;
  if (fx >= 0.0 && fy >= 0.0 && fx < m.nx && fy < m.ny) {
    const std::size_t cell = static_cast<std::size_t>(fy) * m.nx + static_cast<std::size_t>(fx);
    return {m.cell_edges.data() + m.cell_start[cell], m.cell_start[cell + 1] - m.cell_start[cell]};
  }
  // Outside the grid: the nearest edge bounds the search radius.
  thread_local std::vector<int> scratch;
  const double upper = m.NearestEdgeDistance(p) * (1.0 + 1e-9) + 1e-300;
  m.NearbyEdges(p, upper, &scratch);
  return {scratch.data(), static_cast<int>(scratch.size())};
}

void EdgeIndex::EdgesInBox(const Box2& box, std::vector<int>* out) const {
  const BBox query(BPoint(box.min.x(), box.min.y()), BPoint(box.max.x(), box.max.y()));
  out->clear();
  for (auto it = impl_->rtree.qbegin(bgi::intersects(query)); it != impl_->rtree.qend(); ++it)
    out->push_back(it->second);
}

}  // namespace pushgraph::geometry
