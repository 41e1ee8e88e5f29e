// Exact point-versus-shape queries.
//
// The closest feature (a vertex, or the interior of an edge) is found among the edge index's
// candidates. Which part of an edge is closest is decided by exact dot-product signs; features
// whose approximate squared distances tie to within rounding are compared in double-double
// arithmetic with an error bound, and in exact rationals where even that cannot decide; exact
// ties go to the lowest vertex number, so the answer never depends on the
// candidates' order. The side (inside/outside) follows from the closest feature with exact
// orientation tests: interior is on the left of every ring (outer CCW, holes CW).
#include <pushgraph/geometry/point_query.h>

#include "exact.h"
#include "shape_impl.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace pushgraph::geometry {
namespace {

using exact::FeatureDistance;

struct Feature {
  bool is_edge;
  int vertex;    // the vertex, or the edge's start vertex (global numbering); -1: none yet
  double d2;
  double cross;  // edge: accurate cross(b - a, p - a)
  double len2;   // edge: |b - a|^2
  int key() const { return 2 * vertex + (is_edge ? 1 : 0); }
};
constexpr Feature kNoFeature{false, -1, std::numeric_limits<double>::infinity(), 0.0, 0.0};

struct CoreResult {
  double distance = 0.0;  // unsigned distance to the core boundary
  int side = 1;           // +1 outside the core, -1 inside, 0 on its boundary
  Vec2 closest{0, 0};
  Vec2 normal{1, 0};
  BoundaryFeature feature;
  FeatureDistance exact_feature;
};

FeatureDistance ToExact(const Shape::Impl& m, const Feature& f) {
  FeatureDistance fd;
  fd.is_edge = f.is_edge;
  fd.a = m.vertices[f.vertex];
  if (f.is_edge) fd.b = m.vertices[m.next[f.vertex]];
  return fd;
}

// First pass, plain double arithmetic: bounds on the squared distance from p to an edge
// (exact::SegmentDistanceBounds).
struct Bounded {  // plain data: a buffer of these is not initialized per query
  int start;
  double lo, hi;
};

inline Bounded BoundEdge(const Shape::Impl& m, int start, const Vec2& p) {
  double lo, hi;
  exact::SegmentDistanceBounds(p, m.vertices[start], m.vertices[m.next[start]], &lo, &hi);
  return {start, lo * lo, hi * hi};
}

// Second pass, for the edges that can still win: which part of the edge is closest (exact
// dot-product signs) and the accurate squared distance.
Feature ClassifyEdge(const Shape::Impl& m, int start, const Vec2& p) {
  const Vec2& a = m.vertices[start];
  const Vec2& b = m.vertices[m.next[start]];
  Feature f = kNoFeature;
  if (exact::DotSign(p, a, b) <= 0) {
    f.vertex = start;
  } else if (exact::DotSign(p, b, a) <= 0) {
    f.vertex = m.next[start];
  } else {
    f.is_edge = true;
    f.vertex = start;
    f.cross = exact::AccurateCross(a, b, p);
    f.len2 = exact::AccurateSquaredLength(a, b);
    f.d2 = f.cross * f.cross / f.len2;
    return f;
  }
  f.d2 = (p - m.vertices[f.vertex]).squaredNorm();
  return f;
}

// Is `candidate` strictly closer than `best`, exact ties broken by the lower key?
bool Closer(const Shape::Impl& m, const Vec2& p, const Feature& candidate, const Feature& best) {
  if (best.vertex < 0) return true;
  if (candidate.key() == best.key()) return false;
  // Relative error of either d2 is below ~8 eps; outside that window the doubles decide.
  const double window = 32.0 * exact::kEps * std::max(candidate.d2, best.d2);
  if (candidate.d2 < best.d2 - window) return true;
  if (candidate.d2 > best.d2 + window) return false;
  const int c = exact::CompareSquaredDistance(p, ToExact(m, candidate), ToExact(m, best));
  return c < 0 || (c == 0 && candidate.key() < best.key());
}

Vec2 RightNormal(const Vec2& a, const Vec2& b) {
  const Vec2 e = b - a;
  return Vec2(e.y(), -e.x()).normalized();
}

// Parity of the rings strictly containing p (used only where rings share a vertex).
int SideByParity(const Shape::Impl& m, const Vec2& p) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  int count = 0;
  for (const RingInfo& r : m.rings) {
    std::vector<K::Point_2> pts;
    for (int i = 0; i < r.size; ++i) pts.emplace_back(m.vertices[r.first + i].x(), m.vertices[r.first + i].y());
    if (CGAL::bounded_side_2(pts.begin(), pts.end(), K::Point_2(p.x(), p.y()), K()) == CGAL::ON_BOUNDED_SIDE) ++count;
  }
  return count % 2 == 1 ? -1 : 1;
}

int VertexSide(const Shape::Impl& m, int v, const Vec2& p) {
  if (m.shared_vertex[v]) return SideByParity(m, p);
  const Vec2& u = m.vertices[m.prev[v]];
  const Vec2& q = m.vertices[v];
  const Vec2& w = m.vertices[m.next[v]];
  const bool right1 = exact::OrientationSign(u, q, p) < 0;
  const bool right2 = exact::OrientationSign(q, w, p) < 0;
  const int turn = exact::OrientationSign(u, q, w);
  // Outside a convex corner: right of either edge; outside a reflex corner: right of both.
  const bool outside = turn > 0 ? (right1 || right2) : turn < 0 ? (right1 && right2) : right1;
  return outside ? 1 : -1;
}

CoreResult QueryCore(const Shape::Impl& m, const Vec2& p, EdgeIndex::Span span) {
  CoreResult out;
  Feature best = kNoFeature;
  if (m.edges.empty()) {  // point core
    best.vertex = 0;
    best.d2 = (p - m.vertices[0]).squaredNorm();
  }
  // Bounds for every candidate; the accurate value only for those whose lower bound does not
  // exceed the smallest upper bound.
  constexpr int kInline = 32;
  Bounded inline_buffer[kInline];
  thread_local std::vector<Bounded> heap_buffer;
  Bounded* bounded = inline_buffer;
  if (span.size > kInline) {
    heap_buffer.resize(span.size);
    bounded = heap_buffer.data();
  }
  double min_hi = std::numeric_limits<double>::infinity();
  for (int k = 0; k < span.size; ++k) {
    bounded[k] = BoundEdge(m, m.edges[span.data[k]], p);
    min_hi = std::min(min_hi, bounded[k].hi);
  }
  for (int k = 0; k < span.size; ++k) {
    if (bounded[k].lo > min_hi) continue;
    const Feature f = ClassifyEdge(m, bounded[k].start, p);
    if (Closer(m, p, f, best)) best = f;
  }
  out.exact_feature = ToExact(m, best);
  out.feature.edge = m.edge_id(best.vertex);
  out.feature.kind = best.is_edge ? BoundaryFeature::Kind::kEdge : BoundaryFeature::Kind::kVertex;
  const Vec2& a = m.vertices[best.vertex];
  if (best.is_edge) {
    const Vec2& b = m.vertices[m.next[best.vertex]];
    const double len = std::sqrt(best.len2);
    const double h = best.cross / len;  // signed distance along the left normal
    const Vec2 left_unit = Vec2(a.y() - b.y(), b.x() - a.x()) / len;
    out.distance = std::abs(h);
    out.closest = best.cross == 0.0 ? p : Vec2(p - h * left_unit);
    // A segment core has no inside: its normal points to the side the point is on.
    out.normal = m.degenerate_core && best.cross > 0.0 ? left_unit : Vec2(-left_unit);
    out.side = best.cross == 0.0 ? 0 : (m.degenerate_core ? 1 : (best.cross > 0 ? -1 : 1));
    out.feature.t = std::clamp(exact::AccurateDot(a, b, p) / best.len2, 0.0, 1.0);
    return out;
  }
  out.closest = a;
  const Vec2 diff = p - a;
  out.distance = diff.norm();
  if (out.distance == 0.0) {
    out.side = 0;
    if (m.edges.empty()) {
      out.normal = Vec2(1.0, 0.0);
    } else if (m.degenerate_core) {
      out.normal = (a - m.vertices[m.next[best.vertex]]).normalized();
    } else {
      const Vec2 n = RightNormal(m.vertices[m.prev[best.vertex]], a) + RightNormal(a, m.vertices[m.next[best.vertex]]);
      out.normal = n.squaredNorm() > 0 ? Vec2(n.normalized()) : RightNormal(a, m.vertices[m.next[best.vertex]]);
    }
    return out;
  }
  out.side = m.degenerate_core ? 1 : VertexSide(m, best.vertex, p);
  out.normal = out.side > 0 ? Vec2(diff / out.distance) : Vec2(-diff / out.distance);
  return out;
}

void CheckPoint(const Vec2& p) {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
    throw GeometryError("query point is not finite: (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ")");
  if (std::abs(p.x()) > kMaxQueryCoordinate || std::abs(p.y()) > kMaxQueryCoordinate) {
    char text[200];
    std::snprintf(text, sizeof text, "query point (%.17g, %.17g) is outside the supported range +-%g (docs/geometry.md, Limits)",
                  p.x(), p.y(), kMaxQueryCoordinate);
    throw GeometryError(text);
  }
}

PointQuery Finish(const Shape::Impl& m, const Vec2& p, const CoreResult& core) {
  PointQuery q;
  q.feature = core.feature;
  q.normal = core.normal;
  const double r = m.radius;
  q.closest_point = r > 0.0 ? Vec2(core.closest + r * core.normal) : core.closest;
  if (r == 0.0) {
    q.signed_distance = core.side * core.distance;
    q.containment = core.side > 0 ? Containment::kOutside : core.side < 0 ? Containment::kInside : Containment::kOnBoundary;
    return q;
  }
  if (core.side <= 0) {
    q.signed_distance = -core.distance - r;
    q.containment = Containment::kInside;
    return q;
  }
  q.signed_distance = core.distance - r;
  // Decide |p - core| against r exactly unless the doubles already do.
  int cmp = 0;
  if (q.signed_distance > 8.0 * exact::kEps * r) cmp = 1;
  else if (q.signed_distance < -8.0 * exact::kEps * r) cmp = -1;
  else cmp = exact::CompareSquaredDistanceToRadiusExact(p, core.exact_feature, r);
  q.containment = cmp > 0 ? Containment::kOutside : cmp < 0 ? Containment::kInside : Containment::kOnBoundary;
  if (cmp == 0) q.signed_distance = 0.0;
  return q;
}

}  // namespace

PointQuery QueryPoint(const Shape& shape, const Vec2& point) {
  CheckPoint(point);
  const Shape::Impl& m = shape.impl();
  return Finish(m, point, QueryCore(m, point, m.index->Candidates(point)));
}

PointQuery QueryPointBruteForce(const Shape& shape, const Vec2& point) {
  CheckPoint(point);
  const Shape::Impl& m = shape.impl();
  std::vector<int> all(m.edges.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  return Finish(m, point, QueryCore(m, point, {all.data(), static_cast<int>(all.size())}));
}

Containment Contains(const Shape& shape, const Vec2& point) { return QueryPoint(shape, point).containment; }

double SignedDistance(const Shape& shape, const Vec2& point, Vec2* gradient) {
  const PointQuery q = QueryPoint(shape, point);
  if (gradient) *gradient = q.normal;
  return q.signed_distance;
}

PointQuery QueryPoint(const Shape& shape, const Pose2& pose, const Vec2& point, PointQueryJacobians* J) {
  CheckPoint(point);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
    throw GeometryError("shape pose is not finite");
  Eigen::Matrix<double, 2, 3> J_local_pose;
  const Vec2 local = InverseAct(pose, point, J ? &J_local_pose : nullptr);
  const PointQuery q = QueryPoint(shape, local);
  PointQuery w = q;
  const Eigen::Matrix2d R = pose.rotation();
  w.closest_point = Act(pose, q.closest_point);
  w.normal = R * q.normal;
  if (!J) return w;

  // Local derivatives of the closest point (M) and the normal (N) with respect to the local
  // point: an edge's closest point slides along the edge (M = e e^T, N = 0); at a vertex the
  // normal turns with the point, (I - n n^T) / d, which moves a rounded closest point by r N.
  const Shape::Impl& m = shape.impl();
  Eigen::Matrix2d M = Eigen::Matrix2d::Zero(), N = Eigen::Matrix2d::Zero();
  const Vec2 core_closest = q.closest_point - m.radius * q.normal;
  const double core_distance = (local - core_closest).norm();
  if (q.feature.kind == BoundaryFeature::Kind::kEdge) {
    const Vec2 e(-q.normal.y(), q.normal.x());
    M = e * e.transpose();
  } else if (core_distance > 0.0) {
    const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - q.normal * q.normal.transpose();
    const bool outside_core = q.signed_distance + m.radius > 0.0;
    N = (outside_core ? 1.0 : -1.0) * P / core_distance;
    M = m.radius * N;
  }
  Eigen::Matrix2d dR;  // d R / d theta from R's own cos and sin
  dR << -R(1, 0), -R(0, 0), R(0, 0), -R(1, 0);
  J->J_sd_point = w.normal.transpose();
  J->J_sd_pose = q.normal.transpose() * J_local_pose;
  J->J_closest_point = R * M * R.transpose();
  J->J_closest_pose = R * M * J_local_pose;
  J->J_closest_pose.block<2, 2>(0, 0) += Eigen::Matrix2d::Identity();
  J->J_closest_pose.col(2) += dR * q.closest_point;
  J->J_normal_point = R * N * R.transpose();
  J->J_normal_pose = R * N * J_local_pose;
  J->J_normal_pose.col(2) += dR * q.normal;
  return w;
}

}  // namespace pushgraph::geometry
