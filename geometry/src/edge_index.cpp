#include "edge_index.h"

#include "exact.h"

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
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

// A chain of edges [first, first + count) in ring order inside the rectangle o + t u + s v,
// t in [t0, t1], s in [s0, s1], v = (-u.y, u.x). Kept small (80 bytes) and the two children side
// by side: deep in a detailed shape the search is bound by memory latency, not arithmetic.
struct StripNode {
  Vec2 o, u;
  double t0, t1, s0, s1;
  int first, count;
  int children = -1;  // the left child; the right one follows it. -1 for a leaf
  int sector = -1;    // its annular sector, if any
};

// Annular sector about c (radii [r0, r1], between the unit directions d0 and d1, less than a
// half turn apart) holding a chain that bends like an arc: tight where the rectangle is not,
// near the centre of a round shape (the rectangle's near side is the chord, a sagitta closer
// than the arc).
struct Sector {
  Vec2 c, d0, d1;
  double r0, r1;
};

// Can nothing in the node's rectangle be within `limit` of p? Squared distances (no square
// root on the search's critical path); the slack covers the rounding of the projections
// (relative eps of |p - o|; the ranges are padded at build time). `key`: the squared distance
// to the rectangle, to visit the nearer child first.
inline bool StripBeyond(const StripNode& n, const Vec2& p, double limit, double* key) {
  const double px = p.x() - n.o.x(), py = p.y() - n.o.y();
  const double t = px * n.u.x() + py * n.u.y();
  const double s = py * n.u.x() - px * n.u.y();
  const double dt = std::max({n.t0 - t, 0.0, t - n.t1});
  const double ds = std::max({n.s0 - s, 0.0, s - n.s1});
  const double reach = limit + 1e-14 * (std::abs(px) + std::abs(py));
  *key = dt * dt + ds * ds;
  return *key > reach * reach;
}

// The same for the node's annular sector.
inline bool SectorBeyond(const Sector& n, const Vec2& p, double limit) {
  const double wx = p.x() - n.c.x(), wy = p.y() - n.c.y();
  const double reach = limit + 1e-14 * (std::abs(wx) + std::abs(wy) + n.r1);
  const bool after0 = n.d0.x() * wy - n.d0.y() * wx >= 0.0;
  const bool before1 = wx * n.d1.y() - wy * n.d1.x() >= 0.0;
  const double r2 = wx * wx + wy * wy;
  if (after0 && before1) {  // within the sector's angles: the radial gap
    const double inner = n.r0 - reach, outer = n.r1 + reach;
    return (inner > 0.0 && r2 < inner * inner) || r2 > outer * outer;
  }
  // Outside its angles: the nearer of the two radial sides.
  for (const Vec2* d : {&n.d0, &n.d1}) {
    const double t = std::clamp(wx * d->x() + wy * d->y(), n.r0, n.r1);
    const double ex = wx - t * d->x(), ey = wy - t * d->y();
    if (ex * ex + ey * ey <= reach * reach) return false;
  }
  return true;
}

// Fits the annular sector of a chain (vertices and edges [first, first + count)); false when the
// chain is not arc-like (its circle through the first, middle and last vertices is degenerate or
// huge, or the chain turns by half a turn or more about the centre).
bool FitSector(const std::vector<Vec2>& a, const std::vector<Vec2>& b, int first, int count, Sector* node) {
  const Vec2 p = a[first], q = b[first + count / 2], r = b[first + count - 1];
  const Vec2 u = q - p, v = r - p;
  const double det = 2.0 * (u.x() * v.y() - u.y() * v.x());
  const double extent = std::max(u.norm(), v.norm());
  if (!(std::abs(det) > 1e-12 * extent * extent)) return false;
  const Vec2 offset(( v.y() * u.squaredNorm() - u.y() * v.squaredNorm()) / det,
                    (-v.x() * u.squaredNorm() + u.x() * v.squaredNorm()) / det);
  if (!(offset.norm() < 1e4 * extent)) return false;
  const Vec2 c = p + offset;
  const Vec2 mid = (q - c).normalized();
  double lo = 0.0, hi = 0.0, r0 = std::numeric_limits<double>::infinity(), r1 = 0.0;
  for (int k = first; k < first + count; ++k) {
    for (const Vec2* x : {&a[k], &b[k]}) {
      const Vec2 w = *x - c;
      const double angle = std::atan2(mid.x() * w.y() - mid.y() * w.x(), mid.dot(w));
      lo = std::min(lo, angle), hi = std::max(hi, angle);
      r1 = std::max(r1, w.norm());
    }
    r0 = std::min(r0, PointSegmentDistance(c, a[k], b[k]));  // an edge dips inside its ends
  }
  lo -= 1e-9, hi += 1e-9;  // padding for the rounding of the angles
  if (!(hi - lo < 3.0)) return false;  // below a half turn: the sector is convex
  node->c = c;
  const Eigen::Rotation2Dd r_lo(lo), r_hi(hi);
  node->d0 = r_lo * mid;
  node->d1 = r_hi * mid;
  node->r0 = std::max(0.0, r0 * (1.0 - 1e-13));
  node->r1 = r1 * (1.0 + 1e-13);
  return true;
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
  std::vector<char> fallback;  // cells answered by the strip tree (too many near-equidistant edges)
  std::vector<int> all_edges;

  // Strip tree (Ballard, "Strip trees: a hierarchical representation for curves", CACM 1981):
  // a balanced binary tree over the edges in ring order, each node bounding its chain by a
  // rectangle aligned with the chain's chord. A chord-aligned rectangle hugs a curved chain (its
  // width is the sagitta, quadratic in the chain's angle) where an axis-aligned box does not
  // (linear): deep inside a near-circular shape the best-first search reads only the chains that
  // face the point, about log n of them, instead of every edge.
  std::vector<StripNode> strips;
  std::vector<Sector> sectors;
  void BuildStrips(const std::vector<int>& ring_breaks);
  void NearestEdges(const Vec2& p, std::vector<int>* out) const;

  // The grid is built on the kQueriesBeforeGrid-th query: it costs about a thousand strip-tree
  // queries, and a shape made for a few queries (a Minkowski obstacle at one relative angle of a
  // polygonal finger) would pay it for nothing. Until then the strip tree answers (the same
  // candidates' superset; the choice among them is exact either way).
  static constexpr int kQueriesBeforeGrid = 256;
  Box2 bounds;
  bool grid_pending = false;
  mutable std::atomic<int> queries{0};
  mutable std::atomic<bool> grid_ready{false};
  mutable std::once_flag grid_once;
  void BuildGrid();
};

void EdgeIndex::Impl::BuildStrips(const std::vector<int>& ring_breaks) {
  strips.clear();
  sectors.clear();
  const int n = static_cast<int>(a.size());
  if (n == 0) return;
  strips.reserve(2 * n);
  // Leaves of up to 4 edges: below that a node costs as much as the edges it stands for.
  constexpr int kLeafEdges = 4;
  // Fills node `id` and allocates its children as a pair.
  std::function<void(int, int, int)> build = [&](int id, int first, int count) {
    StripNode node;
    node.first = first;
    node.count = count;
    // Axis: the chord from the chain's first to its last vertex; a closed or folded chain (chord
    // short against the chain) takes the direction to its farthest vertex instead.
    const Vec2 start = a[first], end = b[first + count - 1];
    Vec2 axis = end - start;
    double reach = 0.0;
    Vec2 farthest = start;
    for (int k = first; k < first + count; ++k) {
      for (const Vec2* q : {&a[k], &b[k]}) {
        const double r = (*q - start).squaredNorm();
        if (r > reach) reach = r, farthest = *q;
      }
    }
    if (axis.squaredNorm() < 0.25 * reach) axis = farthest - start;
    node.o = start;
    node.u = axis.squaredNorm() > 0.0 ? Vec2(axis.normalized()) : Vec2(1.0, 0.0);
    node.t0 = node.s0 = std::numeric_limits<double>::infinity();
    node.t1 = node.s1 = -std::numeric_limits<double>::infinity();
    double size = 0.0;
    for (int k = first; k < first + count; ++k) {
      for (const Vec2* q : {&a[k], &b[k]}) {
        const Vec2 w = *q - node.o;
        const double t = w.dot(node.u), s = w.y() * node.u.x() - w.x() * node.u.y();
        node.t0 = std::min(node.t0, t), node.t1 = std::max(node.t1, t);
        node.s0 = std::min(node.s0, s), node.s1 = std::max(node.s1, s);
        size = std::max(size, std::abs(w.x()) + std::abs(w.y()));
      }
    }
    // Padding for the rounding of these projections (a straight edge's rectangle is
    // otherwise thinner than its rounding).
    const double pad = 1e-14 * size + 1e-300;
    node.t0 -= pad, node.t1 += pad, node.s0 -= pad, node.s1 += pad;
    Sector sector;
    // Only where it is tighter than the rectangle (an arc, not a zigzag): otherwise it costs a
    // test and cuts nothing.
    if (count >= 3 && FitSector(a, b, first, count, &sector) && sector.r1 - sector.r0 < 0.5 * (node.s1 - node.s0)) {
      node.sector = static_cast<int>(sectors.size());
      sectors.push_back(sector);
    }
    if (count > kLeafEdges) {
      // Split in the middle, or at the ring break nearest to it, so that chains stay in one ring.
      int split = first + count / 2;
      const auto it = std::lower_bound(ring_breaks.begin(), ring_breaks.end(), first + 1);
      int best = -1;
      for (auto j = it; j != ring_breaks.end() && *j < first + count; ++j)
        if (best < 0 || std::abs(*j - split) < std::abs(best - split)) best = *j;
      if (best > 0) split = best;
      node.children = static_cast<int>(strips.size());
      strips.emplace_back();
      strips.emplace_back();
      build(node.children, first, split - first);
      build(node.children + 1, split, first + count - split);
    }
    strips[id] = node;
  };
  strips.emplace_back();
  build(0, 0, n);
}

// Branch and bound over the strip tree, depth first with the nearer child first: every edge
// whose distance can be within rounding of the nearest one. The first leaf reached sets a tight
// limit and everything farther is cut, so only near-ties are read.
void EdgeIndex::Impl::NearestEdges(const Vec2& p, std::vector<int>* out) const {
  thread_local std::vector<int> stack_storage;
  thread_local std::vector<std::pair<double, int>> found_storage;  // (edge lower bound, edge)
  std::vector<int>& stack = stack_storage;
  std::vector<std::pair<double, int>>& found = found_storage;
  stack.clear();
  found.clear();
  out->clear();
  double limit = std::numeric_limits<double>::infinity();
  stack.push_back(0);
  while (!stack.empty()) {
    const StripNode& node = strips[stack.back()];
    stack.pop_back();
    if (node.children < 0) {
      for (int k = node.first; k < node.first + node.count; ++k) {
        double lo, hi;
        exact::SegmentDistanceBounds(p, a[k], b[k], &lo, &hi);
        if (lo > limit) continue;
        limit = std::min(limit, hi);
        found.emplace_back(lo, k);
      }
      continue;
    }
    // Children that may hold something within the limit, the nearer pushed last (popped first).
    // A node pushed before the limit tightened is checked again when popped (through its children
    // or its edges' own bounds).
    double key[2];
    bool open[2];
    for (int i = 0; i < 2; ++i) {
      const StripNode& c = strips[node.children + i];
      open[i] = !StripBeyond(c, p, limit, &key[i]) && !(c.sector >= 0 && SectorBeyond(sectors[c.sector], p, limit));
    }
    const int near = key[1] < key[0] ? 1 : 0;
    if (open[1 - near]) stack.push_back(node.children + 1 - near);
    if (open[near]) stack.push_back(node.children + near);
  }
  for (const auto& [lo, k] : found)
    if (lo <= limit) out->push_back(k);
}

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
  std::vector<int> ring_breaks;  // positions where a new chain starts
  for (int k = 1; k < n; ++k)
    if (next[edges[k - 1]] != edges[k]) ring_breaks.push_back(k);
  m.BuildStrips(ring_breaks);
  m.bounds = bounds;
  m.grid_pending = true;
}

void EdgeIndex::Impl::BuildGrid() {
  Impl& m = *this;
  const Box2& bounds = m.bounds;
  const int n = static_cast<int>(m.a.size());
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
    thread_local std::vector<double> to_centre;
    to_centre.resize(parent.size());
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < parent.size(); ++i) {
      to_centre[i] = PointSegmentDistance(centre, m.a[parent[i]], m.b[parent[i]]);
      nearest = std::min(nearest, to_centre[i]);
    }
    // Every point of the box is within `upper` of the edge nearest to its centre, so only edges
    // within `upper` of the box can be closest to one of its points. The distance to the box is
    // within half a diagonal of the distance to its centre: most edges are decided by that alone
    // (with a relative margin for rounding), and only the rest by the exact box distance.
    const double upper = (nearest + half_diagonal) * (1.0 + 1e-9) + 1e-300;
    std::vector<int> mine;
    mine.reserve(parent.size());
    for (std::size_t i = 0; i < parent.size(); ++i) {
      const int k = parent[i];
      const double d = to_centre[i];
      if (d * (1.0 + 1e-9) <= upper - half_diagonal * 1e-9) {
        mine.push_back(k);  // the box's centre is within upper: so is the box
      } else if ((d - half_diagonal) * (1.0 - 1e-9) <= upper) {
        if (SegmentBoxDistance(m.a[k], m.b[k], box) <= upper) mine.push_back(k);
      }
    }
    // Inside finely tessellated round shapes many edges are almost equidistant from a whole cell
    // and lists stay long: such cells use the strip tree's search, which reads only the
    // near-ties, instead of a long list. A block whose list hardly shrinks from its parent's
    // will not shrink much further: it goes to the strip tree at once (filtering it down to
    // single cells would cost its cells times its list).
    // Near the boundary a block of span s holds about s edges per cell side, so 32 s is generous
    // there and cuts the filtering work (cells times list) where the lists stay long.
    const std::size_t cap = 32 * static_cast<std::size_t>(std::min(span, 16));
    const bool not_shrinking = mine.size() > 128 && 4 * mine.size() > 3 * parent.size();
    if (span <= m.nx / 8 && (mine.size() > cap || not_shrinking)) {
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
  if (!m.grid_pending) return {m.all_edges.data(), static_cast<int>(m.all_edges.size())};
  thread_local std::vector<int> scratch;
  if (!m.grid_ready.load(std::memory_order_acquire)) {
    if (m.queries.fetch_add(1, std::memory_order_relaxed) + 1 < Impl::kQueriesBeforeGrid) {
      m.NearestEdges(p, &scratch);
      return {scratch.data(), static_cast<int>(scratch.size())};
    }
    std::call_once(m.grid_once, [&m] {
      const_cast<Impl&>(m).BuildGrid();
      m.grid_ready.store(true, std::memory_order_release);
    });
  }
  const double fx = (p.x() - m.grid.min.x()) * m.inv_cell_x;
  const double fy = (p.y() - m.grid.min.y()) * m.inv_cell_y;
  if (fx >= 0.0 && fy >= 0.0 && fx < m.nx && fy < m.ny) {
    const std::size_t cell = static_cast<std::size_t>(fy) * m.nx + static_cast<std::size_t>(fx);
    if (!m.fallback[cell]) return {m.cell_edges.data() + m.cell_start[cell], m.cell_start[cell + 1] - m.cell_start[cell]};
  }
  // Outside the grid, or in a fallback cell.
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
