// The boundary of K (+) D(R) from offset segments and arcs split at their crossings (header).
#include "rounded_boundary.h"

#include <pushgraph/geometry/errors.h>
#include <pushgraph/geometry/point_query.h>

#include "shape_impl.h"

#include <boost/geometry.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <boost/iterator/function_output_iterator.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace pushgraph::geometry {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BBox = bg::model::box<BPoint>;
using BoxEntry = std::pair<BBox, int>;
using BoxTree = bgi::rtree<BoxEntry, bgi::rstar<16>>;

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
Vec2 Rotate(const Vec2& u, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * u.x() - s * u.y(), s * u.x() + c * u.y()};
}

// A segment from p0 to p1, or an arc of radius R about `centre` from direction w0 counterclockwise
// to w1 (unit vectors; the sweep is below pi: arcs round convex vertices).
struct Curve {
  bool arc = false;
  Vec2 p0{0, 0}, p1{0, 0};
  Vec2 centre{0, 0}, w0{1, 0}, w1{1, 0};
  Vec2 normal{0, 0};  // segment: the outward unit normal of its edge
  double sweep = 0.0;
  CoreFeatureRef feature;
};

BBox BoxOf(const Curve& c, double radius) {
  Vec2 lo = c.p0.cwiseMin(c.p1), hi = c.p0.cwiseMax(c.p1);
  if (c.arc) {
    // An axis direction inside the sweep is an extreme point of the arc.
    const Vec2 axes[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    for (const Vec2& a : axes)
      if (Cross(c.w0, a) >= 0.0 && Cross(a, c.w1) >= 0.0) {
        const Vec2 p = c.centre + radius * a;
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
  }
  return BBox(BPoint(lo.x(), lo.y()), BPoint(hi.x(), hi.y()));
}

// Position of a point of the curve's circle or line along the curve: the segment parameter in
// [0, 1] or the angle from w0 in [0, sweep].
double ParameterOf(const Curve& c, const Vec2& x) {
  if (!c.arc) {
    const Vec2 d = c.p1 - c.p0;
    return (x - c.p0).dot(d) / d.squaredNorm();
  }
  const Vec2 w = x - c.centre;
  return std::atan2(Cross(c.w0, w), c.w0.dot(w));
}

double EndParameter(const Curve& c) { return c.arc ? c.sweep : 1.0; }

bool OnCurve(const Curve& c, double s) {
  const double slack = 1e-12 * EndParameter(c);
  return s >= -slack && s <= EndParameter(c) + slack;
}

// Points common to two curves (as lines and circles first, then kept where both curves are).
void Crossings(const Curve& a, const Curve& b, double R, std::vector<Vec2>* out) {
  out->clear();
  std::vector<Vec2> candidates;
  if (!a.arc && !b.arc) {
    const Vec2 r = a.p1 - a.p0, s = b.p1 - b.p0;
    const double den = Cross(r, s);
    if (std::abs(den) <= 1e-14 * r.norm() * s.norm()) return;  // parallel: no isolated crossing
    const double t = Cross(b.p0 - a.p0, s) / den;
    candidates.push_back(a.p0 + t * r);
  } else if (a.arc != b.arc) {
    const Curve& seg = a.arc ? b : a;
    const Curve& arc = a.arc ? a : b;
    // |p0 + t d - centre|^2 = R^2, solved without cancellation (Numerical Recipes 5.6).
    const Vec2 d = seg.p1 - seg.p0, f = seg.p0 - arc.centre;
    const double qa = d.squaredNorm(), qb = f.dot(d), qc = (f.squaredNorm() - R * R);
    const double disc = qb * qb - qa * qc;
    if (disc < 0.0) return;
    const double q = -(qb + std::copysign(std::sqrt(disc), qb));
    if (q != 0.0) {
      candidates.push_back(seg.p0 + (q / qa) * d);
      candidates.push_back(seg.p0 + (qc / q) * d);
    } else {
      candidates.push_back(seg.p0);
    }
  } else {
    const Vec2 between = b.centre - a.centre;
    const double D = between.norm();
    if (D == 0.0 || D > 2.0 * R) return;  // the same circle, or apart
    const double h = std::sqrt(std::max(0.0, R * R - 0.25 * D * D));
    const Vec2 mid = a.centre + 0.5 * between;
    const Vec2 across = Vec2(-between.y(), between.x()) / D;
    candidates.push_back(mid + h * across);
    candidates.push_back(mid - h * across);
  }
  for (const Vec2& x : candidates)
    if (OnCurve(a, ParameterOf(a, x)) && OnCurve(b, ParameterOf(b, x))) out->push_back(x);
}

struct Split {
  double s = 0.0;
  Vec2 point{0, 0};
  CoreFeatureRef other;
};

}  // namespace

struct RoundedBoundary::Impl {
  double R = 0.0;
  std::vector<Curve> pieces;
  // Per piece end (2k, 2k+1): the other feature when that end is a crossing.
  std::vector<char> end_is_corner;
  std::vector<CoreFeatureRef> end_other;
  BoxTree tree;
  double scale = 1.0;
  // Uniform grid over the pieces' extent: per cell, every piece that can be nearest to a point
  // of the cell (CSR lists), or -1 where that list would be long (deep inside: the R-tree).
  Vec2 grid_min{0, 0};
  double cell = 1.0;
  int nx = 0, ny = 0;
  std::vector<int> cell_begin, cell_end, cell_pieces;

  // Nearest point of piece k to c: distance, point, and the piece end it is (-1: interior).
  double PieceDistance(int k, const Vec2& c, Vec2* point, int* end) const;
  RoundedBoundaryPoint Search(const Vec2& c, double lower_bound) const;
  void BuildGrid();
};

RoundedBoundary::RoundedBoundary(const Shape& rounded) : impl_(std::make_unique<Impl>()) {
  const Shape::Impl& K = rounded.impl();
  const double R = K.radius;
  if (K.degenerate_core || !(R > 0.0)) throw GeometryError("internal: rounded boundary needs a polygonal core and a radius");
  Impl& m = *impl_;
  m.R = R;
  m.scale = std::max({K.core_bounds.max.cwiseAbs().maxCoeff(), K.core_bounds.min.cwiseAbs().maxCoeff(), R});

  // Raw curves: the offset segment of every edge, the arc of every convex vertex. Curves that
  // meet tangentially (an edge's segment and its end vertices' arcs, the segments of a straight
  // vertex) are linked so that their shared end is not taken for a crossing.
  std::vector<Curve> raw;
  std::vector<std::pair<int, int>> tangent_links;
  const int nv = static_cast<int>(K.vertices.size());
  std::vector<int> segment_of(nv, -1);
  auto outward = [&K](int g) {  // outward normal of the edge starting at global vertex g
    const Vec2 d = K.vertices[K.next[g]] - K.vertices[g];
    return Vec2(d.y(), -d.x()).normalized();
  };
  for (int g : K.edges) {
    if (K.vertices[K.next[g]] == K.vertices[g]) continue;
    Curve c;
    c.normal = outward(g);
    c.p0 = K.vertices[g] + R * c.normal;
    c.p1 = K.vertices[K.next[g]] + R * c.normal;
    c.feature = {false, g};
    segment_of[g] = static_cast<int>(raw.size());
    raw.push_back(c);
  }
  for (int g : K.edges) {
    const int in = K.prev[g];
    if (segment_of[in] < 0 || segment_of[g] < 0) continue;
    const Vec2 n_in = outward(in), n_out = outward(g);
    const double turn = Cross(n_in, n_out);
    if (turn > 0.0) {
      Curve c;
      c.arc = true;
      c.centre = K.vertices[g];
      c.w0 = n_in;
      c.w1 = n_out;
      c.sweep = std::atan2(turn, n_in.dot(n_out));
      c.p0 = c.centre + R * n_in;
      c.p1 = c.centre + R * n_out;
      c.feature = {true, g};
      const int a = static_cast<int>(raw.size());
      raw.push_back(c);
      tangent_links.push_back({a, segment_of[in]});
      tangent_links.push_back({a, segment_of[g]});
    } else if (turn == 0.0 && n_in.dot(n_out) > 0.0) {
      tangent_links.push_back({segment_of[in], segment_of[g]});
    }
  }
  std::sort(tangent_links.begin(), tangent_links.end());
  auto linked = [&tangent_links](int a, int b) {
    return std::binary_search(tangent_links.begin(), tangent_links.end(), std::make_pair(a, b)) ||
           std::binary_search(tangent_links.begin(), tangent_links.end(), std::make_pair(b, a));
  };

  // Crossings, found through an R-tree of the curves' boxes.
  std::vector<BoxEntry> entries;
  entries.reserve(raw.size());
  for (int i = 0; i < static_cast<int>(raw.size()); ++i) entries.push_back({BoxOf(raw[i], R), i});
  const BoxTree raw_tree(entries);
  std::vector<std::vector<Split>> splits(raw.size());
  std::vector<Vec2> points;
  for (int i = 0; i < static_cast<int>(raw.size()); ++i) {
    raw_tree.query(bgi::intersects(entries[i].first), boost::make_function_output_iterator([&](const BoxEntry& e) {
                     const int j = e.second;
                     if (j <= i || linked(i, j)) return;
                     Crossings(raw[i], raw[j], R, &points);
                     for (const Vec2& x : points) {
                       splits[i].push_back({std::clamp(ParameterOf(raw[i], x), 0.0, EndParameter(raw[i])), x, raw[j].feature});
                       splits[j].push_back({std::clamp(ParameterOf(raw[j], x), 0.0, EndParameter(raw[j])), x, raw[i].feature});
                     }
                   }));
  }

  // Pieces between consecutive crossings, kept when their midpoint is at distance R from K
  // (the exact point query's signed distance against the rounded shape is 0 there, up to the
  // rounding of the midpoint; pieces inside the obstacle are strictly negative).
  const double keep_tolerance = 1e-11 * m.scale;
  std::vector<BoxEntry> kept;
  for (int i = 0; i < static_cast<int>(raw.size()); ++i) {
    const Curve& c = raw[i];
    std::vector<Split>& s = splits[i];
    std::sort(s.begin(), s.end(), [](const Split& a, const Split& b) { return a.s < b.s; });
    std::vector<Split> ends;
    ends.push_back({0.0, c.p0, CoreFeatureRef{}});
    for (const Split& x : s) ends.push_back(x);
    ends.push_back({EndParameter(c), c.p1, CoreFeatureRef{}});
    const double min_length = 1e-12 * EndParameter(c);
    for (size_t k = 0; k + 1 < ends.size(); ++k) {
      const Split& a = ends[k];
      const Split& b = ends[k + 1];
      if (b.s - a.s <= min_length) continue;
      const double mid_s = 0.5 * (a.s + b.s);
      const Vec2 mid = c.arc ? Vec2(c.centre + R * Rotate(c.w0, mid_s)) : Vec2(c.p0 + mid_s * (c.p1 - c.p0));
      if (QueryPoint(rounded, mid).signed_distance < -keep_tolerance) continue;
      Curve piece = c;
      piece.p0 = a.point;
      piece.p1 = b.point;
      if (c.arc) {
        piece.w0 = (a.point - c.centre).normalized();
        piece.w1 = (b.point - c.centre).normalized();
        piece.sweep = b.s - a.s;
      }
      const int id = static_cast<int>(m.pieces.size());
      m.pieces.push_back(piece);
      m.end_is_corner.push_back(k > 0);
      m.end_other.push_back(a.other);
      m.end_is_corner.push_back(k + 2 < ends.size());
      m.end_other.push_back(b.other);
      kept.push_back({BoxOf(piece, R), id});
    }
  }
  if (m.pieces.empty()) throw GeometryError("internal: rounded obstacle without a boundary");
  m.tree = BoxTree(kept);
  m.BuildGrid();
}

RoundedBoundary::~RoundedBoundary() = default;

int RoundedBoundary::piece_count() const { return static_cast<int>(impl_->pieces.size()); }

double RoundedBoundary::Impl::PieceDistance(int k, const Vec2& c, Vec2* point, int* end) const {
  const Curve& p = pieces[k];
  *end = -1;
  if (!p.arc) {
    const Vec2 d = p.p1 - p.p0;
    const double t = (c - p.p0).dot(d) / d.squaredNorm();
    if (t > 0.0 && t < 1.0) {
      *point = p.p0 + t * d;
      return std::abs(p.normal.dot(c - p.p0));
    }
    *end = t <= 0.0 ? 0 : 1;
  } else {
    const Vec2 w = c - p.centre;
    const double L = w.norm();
    if (L > 0.0 && Cross(p.w0, w) >= 0.0 && Cross(w, p.w1) >= 0.0) {
      *point = p.centre + (R / L) * w;
      return std::abs(L - R);
    }
    *end = (c - p.p0).squaredNorm() <= (c - p.p1).squaredNorm() ? 0 : 1;
  }
  *point = *end == 0 ? p.p0 : p.p1;
  return (c - *point).norm();
}

RoundedBoundaryPoint RoundedBoundary::Impl::Search(const Vec2& c, double lower_bound) const {
  RoundedBoundaryPoint best;
  best.distance = std::numeric_limits<double>::infinity();
  int best_end = -1;  // -1 interior of the piece, else the piece end 2k or 2k+1
  auto visit = [&](int k) {
    Vec2 point;
    int end;
    const double distance = PieceDistance(k, c, &point, &end);
    // Ties (a corner reached through either of its pieces) keep the first: the answer is the same.
    if (distance < best.distance) {
      best.distance = distance;
      best.point = point;
      best.feature = pieces[k].feature;
      best_end = end < 0 ? -1 : 2 * k + end;
    }
  };
  const long ix = nx > 0 ? static_cast<long>(std::floor((c.x() - grid_min.x()) / cell)) : -1;
  const long iy = nx > 0 ? static_cast<long>(std::floor((c.y() - grid_min.y()) / cell)) : -1;
  const long id = ix >= 0 && iy >= 0 && ix < nx && iy < ny ? iy * nx + ix : -1;
  if (id >= 0 && cell_begin[id] >= 0) {
    for (int k = cell_begin[id]; k < cell_end[id]; ++k) visit(cell_pieces[k]);
  } else {
    // Boxes of half-width r around c, from the lower bound up, doubling while empty: every piece
    // within r of c meets the box, so the best so far is the nearest once it is <= r.
    double r = std::max(0.0, lower_bound) * (1.0 + 1e-9) + 1e-9 * scale;
    for (int round = 0; round < 200; ++round) {
      const BBox box(BPoint(c.x() - r, c.y() - r), BPoint(c.x() + r, c.y() + r));
      tree.query(bgi::intersects(box), boost::make_function_output_iterator([&](const BoxEntry& e) { visit(e.second); }));
      if (best.distance <= r) break;
      r = std::isfinite(best.distance) ? best.distance : 2.0 * r;
    }
  }
  if (best_end >= 0 && end_is_corner[best_end]) {
    best.corner = true;
    best.other = end_other[best_end];
  }
  return best;
}

// Cell lists (as EdgeIndex does for edges): a piece can be nearest to a point x of the cell only if
// its distance to x is at most dist(x, nearest piece of the centre q) <= d(q) + half diagonal, so
// the pieces whose boxes come that close to the cell are a complete candidate list.
void RoundedBoundary::Impl::BuildGrid() {
  const BBox bounds = tree.bounds();
  grid_min = Vec2(bg::get<bg::min_corner, 0>(bounds), bg::get<bg::min_corner, 1>(bounds));
  const Vec2 extent = Vec2(bg::get<bg::max_corner, 0>(bounds), bg::get<bg::max_corner, 1>(bounds)) - grid_min;
  const double target_cells = std::min(65536.0, 4.0 * static_cast<double>(pieces.size()) + 16.0);
  cell = std::sqrt(std::max(extent.x() * extent.y(), 1e-300) / target_cells);
  cell = std::max(cell, 1e-6 * std::max(extent.x(), extent.y()));
  nx = std::clamp(static_cast<int>(std::ceil(extent.x() / cell)), 1, 1024);
  ny = std::clamp(static_cast<int>(std::ceil(extent.y() / cell)), 1, 1024);
  cell = std::max(extent.x() / nx, extent.y() / ny) * (1.0 + 1e-12);
  constexpr int kLongList = 48;  // longer lists: the R-tree search instead
  const int saved_nx = nx;
  nx = 0;  // Search() below must not read the grid being built
  cell_begin.assign(static_cast<size_t>(saved_nx) * ny, -1);
  cell_end.assign(static_cast<size_t>(saved_nx) * ny, -1);
  cell_pieces.clear();
  std::vector<int> list;
  for (int iy = 0; iy < ny; ++iy)
    for (int ix = 0; ix < saved_nx; ++ix) {
      const Vec2 lo = grid_min + cell * Vec2(ix, iy);
      const Vec2 q = lo + 0.5 * cell * Vec2(1, 1);
      const double reach = Search(q, 0.0).distance + 0.7072 * cell;
      const BBox around(BPoint(lo.x() - reach, lo.y() - reach), BPoint(lo.x() + cell + reach, lo.y() + cell + reach));
      list.clear();
      tree.query(bgi::intersects(around), boost::make_function_output_iterator([&](const BoxEntry& e) {
                   if (static_cast<int>(list.size()) <= kLongList) list.push_back(e.second);
                 }));
      const size_t id = static_cast<size_t>(iy) * saved_nx + ix;
      if (static_cast<int>(list.size()) > kLongList) continue;
      cell_begin[id] = static_cast<int>(cell_pieces.size());
      cell_pieces.insert(cell_pieces.end(), list.begin(), list.end());
      cell_end[id] = static_cast<int>(cell_pieces.size());
    }
  nx = saved_nx;
}

RoundedBoundaryPoint RoundedBoundary::Nearest(const Vec2& c, double lower_bound) const {
  return impl_->Search(c, lower_bound);
}

}  // namespace pushgraph::geometry
