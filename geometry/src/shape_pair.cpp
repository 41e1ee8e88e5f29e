// Object-versus-finger separation, penetration depth, witness points and their Jacobians.
//
// The finger's reference point c (its origin, in the object frame) is queried against the
// configuration-space obstacle C = object_core (+) (-R(phi) finger_core) inflated by both
// rounding radii: its signed distance is the signed separation of the two shapes, and its
// normal is the separating direction (the translational penetration depth is the distance from
// c to the boundary of C; Lozano-Perez 1983; Kim, Lin, Manocha 2002). For a point-core finger,
// C is the object itself. The witness pair is the pair of features of object and finger that
// form C's closest feature; their material points carry the Jacobians.
#include <pushgraph/geometry/shape_pair.h>

#include <pushgraph/geometry/point_query.h>

#include "minkowski_obstacle.h"
#include "rounded_boundary.h"
#include "shape_pair_witness.h"
#include "exact.h"
#include "shape_impl.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <mutex>

namespace pushgraph::geometry {
namespace {

using namespace internal;  // NOLINT: the query's own helpers (shape_pair_witness.h)

// Finger vertex f (finger frame) against the object: a posed point query on the object.
WitnessInputs FingerVertexAgainstObject(const Shape& object, const Pose2& object_pose, const Pose2& finger_pose,
                                        const Vec2& f, double rf, bool* inside) {
  WitnessInputs w;
  w.on_finger = true;
  w.m_w = Act(finger_pose, f, &w.J_m_fin);
  PointQueryJacobians pj;
  const PointQuery q = QueryPoint(object, object_pose, w.m_w, &pj);
  w.sd = q.signed_distance - rf;
  w.n_w = q.normal;
  w.J_sd_obj = pj.J_sd_pose;
  w.J_sd_fin = pj.J_sd_point * w.J_m_fin;
  w.J_n_obj = pj.J_normal_pose;
  w.J_n_fin = pj.J_normal_point * w.J_m_fin;
  if (inside) *inside = q.containment == Containment::kInside;
  return w;
}

// Object vertex o (object frame) against the finger: the finger separates along -n_finger.
WitnessInputs ObjectVertexAgainstFinger(const Shape& finger, const Pose2& object_pose, const Pose2& finger_pose,
                                        const Vec2& o, double ro, bool* inside) {
  WitnessInputs w;
  w.on_finger = false;
  w.m_w = Act(object_pose, o, &w.J_m_obj);
  PointQueryJacobians pj;
  const PointQuery q = QueryPoint(finger, finger_pose, w.m_w, &pj);
  w.sd = q.signed_distance - ro;
  w.n_w = -q.normal;
  w.J_sd_fin = pj.J_sd_pose;
  w.J_sd_obj = pj.J_sd_point * w.J_m_obj;
  w.J_n_fin = -pj.J_normal_pose;
  w.J_n_obj = -pj.J_normal_point * w.J_m_obj;
  if (inside) *inside = q.containment == Containment::kInside;
  return w;
}

void CheckPose(const Pose2& p, const char* which) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta))
    throw GeometryError(std::string(which) + " pose is not finite");
}

// Rounding of a distance computed at the scale of the obstacle and the query point.
double RoundingSlack(const Shape& C, const Vec2& c) {
  const Box2 b = C.bounds();
  const double scale = std::max({b.min.cwiseAbs().maxCoeff(), b.max.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff()});
  return 64.0 * std::numeric_limits<double>::epsilon() * scale;
}

// "Core depth + radius" is the depth of a rounded obstacle except where the obstacle fills a
// concave region: only rounded non-convex polygonal cores need the exact boundary.
bool NeedsRoundedBoundary(const Shape& C) {
  const Shape::Impl& k = C.impl();
  return k.radius > 0.0 && !k.degenerate_core && !k.convex;
}

}  // namespace

struct ShapePairQuerier::Impl {
  Shape object, finger;
  Options options;
  bool point_finger = false;
  Vec2 finger_centre{0, 0};
  // max |f| over the finger's core vertices: no point of its core boundary lies farther from its origin.
  double finger_reach = 0.0;
  Shape inflated_object;  // point fingers: the object with radius ro + rf

  struct CachedObstacle {
    Shape shape;
    std::shared_ptr<const RoundedBoundary> boundary;  // built by the first overlapping query
  };
  mutable std::mutex mutex;
  mutable std::map<double, CachedObstacle> obstacles;  // relative angle -> C (object frame)
  mutable std::deque<double> order;
  mutable int built = 0;
  mutable std::once_flag inflated_boundary_once;
  mutable std::unique_ptr<const RoundedBoundary> inflated_boundary;  // point fingers

  // The obstacle at relative angle phi, or at phi rounded to angle_cache_resolution: *used is
  // the angle it was built for (the touching pairs must be searched at that angle).
  Shape Obstacle(double phi, double* used) const {
    double key = WrapAngle(phi);
    if (options.angle_cache_resolution > 0.0)
      key = WrapAngle(std::round(key / options.angle_cache_resolution) * options.angle_cache_resolution);
    *used = key;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = obstacles.find(key);
    if (it != obstacles.end()) return it->second.shape;
    Shape c = MinkowskiSumOfCores(object, RotatedReflectedCore(finger, key), object.radius() + finger.radius());
    ++built;
    obstacles.emplace(key, CachedObstacle{c, nullptr});
    order.push_back(key);
    while (static_cast<int>(order.size()) > std::max(1, options.max_cached_angles)) {
      obstacles.erase(order.front());
      order.pop_front();
    }
    return c;
  }

  // The rounded boundary of the obstacle cached under `key` (built once per angle, like C).
  std::shared_ptr<const RoundedBoundary> BoundaryOf(double key, const Shape& C) const {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = obstacles.find(key);
    if (it == obstacles.end()) return std::make_shared<const RoundedBoundary>(C);  // evicted meanwhile
    if (!it->second.boundary) it->second.boundary = std::make_shared<const RoundedBoundary>(C);
    return it->second.boundary;
  }

  const RoundedBoundary& InflatedBoundary() const {
    std::call_once(inflated_boundary_once, [this] { inflated_boundary = std::make_unique<const RoundedBoundary>(inflated_object); });
    return *inflated_boundary;
  }

  ShapePairResult QueryPointFinger(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const {
    bool inside = false;
    const WitnessInputs w = FingerVertexAgainstObject(inflated_object, object_pose, finger_pose, finger_centre, 0.0, &inside);
    if (inside && options.exact_rounded_depth && NeedsRoundedBoundary(inflated_object)) {
      // The centre in the object frame, c = Ro^T (m - t), with d c / d theta = (c_y, -c_x).
      const Eigen::Matrix2d Ro = object_pose.rotation();
      const Vec2 c = Ro.transpose() * (w.m_w - object_pose.translation());
      const RoundedBoundaryPoint bp = InflatedBoundary().Nearest(c, -w.sd);
      if (bp.distance > -w.sd + RoundingSlack(inflated_object, c)) {
        Mat23 J_c_obj;
        J_c_obj << -Ro.transpose(), Vec2(c.y(), -c.x());
        const Mat23 J_c_fin = Ro.transpose() * w.J_m_fin;
        return QueryRounded(inflated_object, bp, c, J_c_obj, J_c_fin, 0.0, Ro, object_pose, finger_pose, &w, J);
      }
    }
    // The inflated object already carries rf: its signed distance is the separation, and the
    // finger point lies rf behind the centre.
    ShapePairResult r;
    FillWitnesses(w, object.radius(), finger.radius(), &r, J);
    r.intersecting = inside;
    return r;
  }

  FeatureMotion MotionAt(const Vec2& c_contact, double phi, bool vertex, const Vec2& n_hint) const;
  // `centre`: a point finger's centre (world) with its Jacobian, already at hand.
  ShapePairResult QueryRounded(const Shape& C, const RoundedBoundaryPoint& bp, const Vec2& c, const Mat23& J_c_obj,
                               const Mat23& J_c_fin, double phi, const Eigen::Matrix2d& Ro, const Pose2& object_pose,
                               const Pose2& finger_pose, const WitnessInputs* centre, ShapePairJacobians* J) const;
  ShapePairResult QueryExact(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const;
  ShapePairResult QuerySampled(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const;
};

// The touching pairs at the contact configuration c_contact (finger origin, object frame, at
// relative angle phi) generate a feature of C's core. Each is a line of C's boundary, n . x = h,
// moving with phi (Lozano-Perez's type A: finger vertex on object edge, n fixed; type B: object
// vertex on finger edge, n turns with phi), or a vertex-vertex pair, a C vertex o - R f.
FeatureMotion ShapePairQuerier::Impl::MotionAt(const Vec2& c_contact, double phi, bool vertex,
                                               const Vec2& n_hint) const {
  const double ro = object.radius(), rf = finger.radius();
  const Eigen::Matrix2d R = Pose2{0.0, 0.0, phi}.rotation();
  struct Pair {
    bool vertex_vertex = false, finger_material = true;
    // On a segment core (a capsule's), which has no inside: the point lies on the segment, and
    // the side of its normal is rounding's choice. Each side generates a line of C's boundary.
    bool two_sided = false;
    Vec2 f{0, 0}, o{0, 0};  // finger vertex (finger frame) / object vertex (object frame)
    Vec2 n{0, 0}, dn{0, 0};
    double dh = 0.0;
  };
  const Eigen::Matrix2d dR = RotationDerivative(phi);
  const Box2 ob = object.bounds(), fb = finger.bounds();
  const double tol = 1e-9 * ((ob.max - ob.min).norm() + (fb.max - fb.min).norm());
  std::vector<Pair> pairs;
  const Shape::Impl& oi = object.impl();
  const Shape::Impl& fi = finger.impl();
  // The object's vertex index of an edge's first vertex (its ring's first plus the edge's index).
  auto vertex_of = [&oi](const EdgeId& e) {
    for (const RingInfo& ring : oi.rings)
      if (ring.polygon == e.polygon && ring.ring == e.ring) return ring.first + e.index;
    return oi.rings[0].first;
  };
  for (const Vec2& f : fi.vertices) {
    const PointQuery q = QueryPoint(object, c_contact + R * f);
    if (std::abs(q.signed_distance + ro) > tol) continue;
    Pair p;
    p.f = f;
    p.two_sided = oi.degenerate_core;
    if (q.feature.kind == BoundaryFeature::Kind::kVertex) {
      p.vertex_vertex = true;
      p.o = oi.vertices[vertex_of(q.feature.edge)];
    } else {
      p.n = q.normal;
      p.dh = -p.n.dot(dR * f);
      // At a C vertex o - R f, c_contact + R f equals the object vertex o only to rounding, and
      // can land on one of o's edges just short of it: that pair is vertex-vertex too (else a C
      // vertex found no vertex pair, and d sd / d phi came out 0: a box finger's corner at a
      // square's, 9 of 3000 random poses).
      const int a = vertex_of(q.feature.edge);
      for (const int end : {a, oi.next[a]}) {
        if ((c_contact + R * f - oi.vertices[end]).norm() > tol) continue;
        Pair v;
        v.vertex_vertex = true;
        v.f = f;
        v.o = oi.vertices[end];
        pairs.push_back(v);
      }
    }
    pairs.push_back(p);
  }
  // An object vertex touches the finger only within its reach of the finger's origin (a bound
  // with a margin, so a cheap test that never drops a pair): without it every vertex of a
  // detailed object was queried against the finger, most of a polygonal finger's solve time.
  const double reach = (finger_reach + std::abs(rf) + tol) * (1.0 + 1e-9) + tol;
  for (const Vec2& o : oi.vertices) {
    if ((o - c_contact).squaredNorm() > reach * reach) continue;
    const Vec2 local = R.transpose() * (o - c_contact);
    const PointQuery q = QueryPoint(finger, local);
    if (std::abs(q.signed_distance + rf) > tol || q.feature.kind == BoundaryFeature::Kind::kVertex) continue;
    Pair p;
    p.finger_material = false;
    p.two_sided = fi.degenerate_core;
    p.o = o;
    p.n = -(R * q.normal);
    p.dn = Perp(p.n);
    p.dh = p.dn.dot(o);
    pairs.push_back(p);
  }
  if (pairs.empty()) throw GeometryError("internal: no touching pair found at the contact configuration");

  // A two-sided line faces the C edge it generates (found by n_hint, the edge's normal); for a
  // C vertex the sides do not matter (each line's equation only changes sign). A capsule finger
  // deep in a notch had d sd / d phi 0.0097 against 0.0625 (the other side's line).
  if (!vertex) {
    for (Pair& p : pairs) {
      if (p.two_sided && !p.vertex_vertex && p.n.dot(n_hint) < 0.0) {
        p.n = -p.n;
        p.dn = -p.dn;
        p.dh = -p.dh;
      }
    }
  }
  FeatureMotion m;
  const Pair* material = &pairs[0];
  if (!vertex) {
    const Pair* best = nullptr;
    for (const Pair& p : pairs)
      if (!p.vertex_vertex && (!best || p.n.dot(n_hint) > best->n.dot(n_hint))) best = &p;
    if (!best) best = &pairs[0];
    material = best;
    m.n = best->n;
    m.dn = best->dn;
    m.dh = best->dh;
  } else {
    // A C vertex: either o - R f, or the crossing of two contact lines (two simultaneous contacts).
    const Pair* vv = nullptr;
    for (const Pair& p : pairs)
      if (p.vertex_vertex) vv = &p;
    if (vv) {
      m.dv = -(dR * vv->f);
      material = vv;
    } else {
      const Pair* first = nullptr;
      const Pair* second = nullptr;
      for (const Pair& p : pairs) {
        if (!first) first = &p;
        else if (!second || std::abs(p.n.dot(first->n)) < std::abs(second->n.dot(first->n))) second = &p;
      }
      Eigen::Matrix2d Nm;
      Nm << first->n.transpose(), (second ? second->n : first->n).transpose();
      if (second && std::abs(Nm.determinant()) > 1e-12) {
        const Vec2 rhs(first->dh - first->dn.dot(c_contact), second->dh - second->dn.dot(c_contact));
        m.dv = Nm.inverse() * rhs;
      }
      material = first;
    }
  }
  m.finger_material = material->finger_material;
  m.f = material->f;
  m.o = material->o;
  return m;
}

ShapePairResult ShapePairQuerier::Impl::QueryExact(const Pose2& object_pose, const Pose2& finger_pose,
                                                   ShapePairJacobians* J) const {
  const double ro = object.radius(), rf = finger.radius();
  Mat23 J_c_obj;
  const Vec2 c = InverseAct(object_pose, finger_pose.translation(), &J_c_obj);
  double phi = 0.0;  // the relative angle the obstacle was built for (rounded when cached)
  const Shape C = Obstacle(finger_pose.theta - object_pose.theta, &phi);
  const PointQuery qc = QueryPoint(C, c);
  const Eigen::Matrix2d Ro = object_pose.rotation();
  if (qc.containment == Containment::kInside && options.exact_rounded_depth && NeedsRoundedBoundary(C)) {
    const RoundedBoundaryPoint bp = BoundaryOf(phi, C)->Nearest(c, -qc.signed_distance);
    if (bp.distance > -qc.signed_distance + RoundingSlack(C, c)) {
      Mat23 J_c_fin = Mat23::Zero();
      J_c_fin.block<2, 2>(0, 0) = Ro.transpose();
      return QueryRounded(C, bp, c, J_c_obj, J_c_fin, phi, Ro, object_pose, finger_pose, nullptr, J);
    }
  }
  const Vec2 c_contact = qc.closest_point - C.radius() * qc.normal;  // finger origin at first contact (cores)
  const bool vertex = qc.feature.kind != BoundaryFeature::Kind::kEdge;
  const FeatureMotion mo = MotionAt(c_contact, phi, vertex, qc.normal);
  Separation sep;
  sep.sd = qc.signed_distance;
  sep.n = qc.normal;
  OneFeatureDerivatives(vertex, c, c_contact, qc.signed_distance + C.radius() > 0.0 ? 1.0 : -1.0, mo, &sep);
  Mat23 J_c_fin = Mat23::Zero();
  J_c_fin.block<2, 2>(0, 0) = Ro.transpose();
  const WitnessInputs w = ObstacleWitness(sep, J_c_obj, J_c_fin, Ro, object_pose, finger_pose, mo);
  ShapePairResult r;
  FillWitnesses(w, ro, rf, &r, J);
  r.intersecting = qc.containment == Containment::kInside;
  return r;
}

// The exact depth of a rounded obstacle, from the nearest point p of its boundary (rounded_boundary.h):
// on the offset of one core feature (an edge's segment: sd = n . c - h - R; a vertex's arc:
// sd = |c - v| - R), or at a concave corner where the offsets of two features cross. There
// sd = -|p - c| and n = (p - c) / |p - c|, with p(phi) moving as both features do: differentiating
// their equations (line: n_i . p = h_i + R; arc: |p - v_j|^2 = R^2) gives a 2x2 system for
// d p / d phi. The contact normal k (the touching point's normal after the move) is the first
// feature's. For a point finger nothing moves with phi (C is the object).
ShapePairResult ShapePairQuerier::Impl::QueryRounded(const Shape& C, const RoundedBoundaryPoint& bp, const Vec2& c,
                                                     const Mat23& J_c_obj, const Mat23& J_c_fin, double phi,
                                                     const Eigen::Matrix2d& Ro, const Pose2& object_pose,
                                                     const Pose2& finger_pose, const WitnessInputs* centre,
                                                     ShapePairJacobians* J) const {
  const Shape::Impl& K = C.impl();
  const double R = K.radius;
  struct Feature {
    bool vertex = false;
    Vec2 v{0, 0}, n{0, 0};
    FeatureMotion motion;
  };
  auto feature_of = [&](const CoreFeatureRef& ref) {
    Feature f;
    f.vertex = ref.is_vertex;
    Vec2 contact, hint;
    if (ref.is_vertex) {
      f.v = K.vertices[ref.index];
      contact = f.v;
      hint = (bp.point - f.v) / R;
    } else {
      const Vec2 d = K.vertices[K.next[ref.index]] - K.vertices[ref.index];
      f.n = Vec2(d.y(), -d.x()).normalized();
      contact = bp.point - R * f.n;
      hint = f.n;
    }
    if (point_finger) {
      f.motion.f = finger_centre;  // the disk's centre touches; nothing turns with phi
    } else {
      f.motion = MotionAt(contact, phi, f.vertex, hint);
    }
    return f;
  };
  Feature a = feature_of(bp.feature);
  const double L = bp.distance;
  Separation sep;
  sep.sd = -L;
  Vec2 k = Vec2::Zero(), Kphi = Vec2::Zero();
  bool corner = false;
  if (bp.corner) {
    Feature b = feature_of(bp.other);
    const Vec2& p = bp.point;
    // The witnesses follow one of the corner's two contacts, chosen by the features' numbers so
    // that the choice depends neither on which piece the search met first nor on the side of the
    // bisector c is on (a finger wedged in a symmetric V sits on it: any rule by direction
    // would flip the witnesses from wall to wall with every tiny motion).
    if (std::make_pair(bp.other.index, bp.other.is_vertex) < std::make_pair(bp.feature.index, bp.feature.is_vertex))
      std::swap(a, b);
    Eigen::Matrix2d A;
    Vec2 rhs;
    auto equation = [&](const Feature& f, int row) {
      if (f.vertex) {
        A.row(row) = (p - f.v).transpose();
        rhs(row) = (p - f.v).dot(f.motion.dv);
      } else {
        A.row(row) = f.n.transpose();
        rhs(row) = f.motion.dh - f.motion.dn.dot(p);
      }
    };
    equation(a, 0);
    equation(b, 1);
    // A corner whose two curves are nearly tangent is smooth to first order: treat it as one piece.
    if (std::abs(A.determinant()) > 1e-6 * A.row(0).norm() * A.row(1).norm()) {
      corner = true;
      const Vec2 dp = A.partialPivLu().solve(rhs);
      sep.n = (p - c) / L;
      const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - sep.n * sep.n.transpose();
      sep.sd_phi = -sep.n.dot(dp);
      sep.Nc = -P / L;
      sep.Nphi = P * dp / L;
      if (a.vertex) {
        k = (p - a.v) / R;
        Kphi = (dp - a.motion.dv) / R;
      } else {
        k = a.n;
        Kphi = a.motion.dn;
      }
    }
  }
  if (!corner) {
    // On one feature's offset c lies on the feature's outer side (s = +1).
    const Vec2 from_v = c - a.v;
    const double d = from_v.norm();
    sep.n = !a.vertex ? a.n : d > 0.0 ? Vec2(from_v / d) : Vec2((bp.point - a.v) / R);
    OneFeatureDerivatives(a.vertex, c, a.v, 1.0, a.motion, &sep);
  }
  WitnessInputs w = ObstacleWitness(sep, J_c_obj, J_c_fin, Ro, object_pose, finger_pose, a.motion, centre);
  if (corner) {
    w.separate_contact_normal = true;
    w.k_w = Ro * k;
    w.J_k_obj.col(2) = -Ro * Kphi + RotationDerivativeOf(Ro) * k;
    w.J_k_fin.col(2) = Ro * Kphi;
  }
  ShapePairResult r;
  FillWitnesses(w, object.radius(), finger.radius(), &r, J);
  r.intersecting = true;
  return r;
}

ShapePairResult ShapePairQuerier::Impl::QuerySampled(const Pose2& object_pose, const Pose2& finger_pose,
                                                     ShapePairJacobians* J) const {
  // Deepest (or closest) vertex of either shape against the other. When apart, the closest pair
  // of two polygon sets always includes a vertex, so this is the exact distance.
  const double ro = object.radius(), rf = finger.radius();
  WitnessInputs best;
  best.sd = std::numeric_limits<double>::infinity();
  bool best_inside = false;
  for (const Vec2& f : finger.impl().vertices) {
    bool inside = false;
    WitnessInputs w = FingerVertexAgainstObject(object, object_pose, finger_pose, f, rf, &inside);
    if (w.sd < best.sd) best = w, best_inside = inside;
  }
  for (const Vec2& o : object.impl().vertices) {
    bool inside = false;
    WitnessInputs w = ObjectVertexAgainstFinger(finger, object_pose, finger_pose, o, ro, &inside);
    if (w.sd < best.sd) best = w, best_inside = inside;
  }
  ShapePairResult r;
  // A vertex on the other's boundary and none inside: edges that lie along each other (two
  // squares side by side, shifted along a common edge) overlap with no vertex inside, and
  // touching ones do not; only the exact path can tell (the sampled answer said "apart" for
  // squares overlapping by half their area).
  // Rounding puts such a vertex just inside or outside (1e-18 m deep under a turn, the overlap
  // 0.05 m): within 1e-12 of the shapes' size the sampled answer is a guess either way.
  double size = Between(object_pose, finger_pose).translation().norm();
  for (const Vec2& f : finger.impl().vertices) size = std::max(size, f.norm());
  for (const Vec2& o : object.impl().vertices) size = std::max(size, o.norm());
  if (std::abs(best.sd) <= 1e-12 * size) return QueryExact(object_pose, finger_pose, J);
  if (best.sd > 0.0) {
    // Cores may still cross with no vertex inside (two thin bars in a cross): the sampled
    // answer would be wrong, so such configurations take the exact path (exact orientations of
    // the transformed vertices).
    const Shape::Impl& fi = finger.impl();
    const Shape::Impl& oi = object.impl();
    const Pose2 rel = Between(object_pose, finger_pose);
    std::vector<int> nearby;
    for (int e : fi.edges) {
      const Vec2 a = Act(rel, fi.vertices[e]), b = Act(rel, fi.vertices[fi.next[e]]);
      oi.index->EdgesInBox({a.cwiseMin(b), a.cwiseMax(b)}, &nearby);
      for (int k : nearby) {
        const Vec2& u = oi.vertices[oi.edges[k]];
        const Vec2& v = oi.vertices[oi.next[oi.edges[k]]];
        if (exact::OrientationSign(a, b, u) * exact::OrientationSign(a, b, v) < 0 &&
            exact::OrientationSign(u, v, a) * exact::OrientationSign(u, v, b) < 0)
          return QueryExact(object_pose, finger_pose, J);
      }
    }
  }
  FillWitnesses(best, ro, rf, &r, J);
  r.intersecting = best_inside || best.sd < 0.0;
  return r;
}

ShapePairQuerier::ShapePairQuerier(Shape object, Shape finger) : ShapePairQuerier(std::move(object), std::move(finger), Options()) {}

ShapePairQuerier::ShapePairQuerier(Shape object, Shape finger, Options options) : impl_(std::make_unique<Impl>()) {
  if (object.empty() || finger.empty()) throw GeometryError("shape pair query needs a non-empty object and finger");
  impl_->object = std::move(object);
  impl_->finger = std::move(finger);
  impl_->options = options;
  const Shape::Impl& f = impl_->finger.impl();
  impl_->point_finger = f.edges.empty();
  for (const Vec2& v : f.vertices) impl_->finger_reach = std::max(impl_->finger_reach, v.norm());
  if (impl_->point_finger) {
    impl_->finger_centre = f.vertices[0];
    impl_->inflated_object = impl_->object.WithRadius(impl_->object.radius() + impl_->finger.radius());
  }
}

ShapePairQuerier::~ShapePairQuerier() = default;
ShapePairQuerier::ShapePairQuerier(ShapePairQuerier&&) noexcept = default;
ShapePairQuerier& ShapePairQuerier::operator=(ShapePairQuerier&&) noexcept = default;

// A moved-from querier holds nothing: an error, not a null dereference.
static void RequireHeld(const void* impl) {
  if (impl == nullptr) throw GeometryError("ShapePairQuerier: operation on a moved-from querier");
}

ShapePairResult ShapePairQuerier::Query(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const {
  RequireHeld(impl_.get());
  CheckPose(object_pose, "object");
  CheckPose(finger_pose, "finger");
  const Impl& m = *impl_;
  auto query = [&m](const Pose2& object, const Pose2& finger, ShapePairJacobians* jacobians) {
    if (m.point_finger) return m.QueryPointFinger(object, finger, jacobians);
    if (m.options.method == Method::kVertexSampling) return m.QuerySampled(object, finger, jacobians);
    return m.QueryExact(object, finger, jacobians);
  };
  ShapePairResult r = query(object_pose, finger_pose, J);
  if (!r.intersecting) return r;
  if (!m.point_finger && m.options.method == Method::kVertexSampling) {
    r.depth_exact = false;  // an estimate (header)
  } else if (m.options.check_rounded_depth && m.object.radius() + m.finger.radius() > 0.0) {
    // The rounded-shape depth (core depth + radii) is exact only if it separates: move the
    // finger by it and look (apart shapes' separations are exact, so this test is sound).
    Pose2 moved = finger_pose;
    moved.x += r.depth * r.normal.x();
    moved.y += r.depth * r.normal.y();
    const ShapePairResult after = query(object_pose, moved, nullptr);
    r.depth_exact = !(after.signed_distance < -(1e-12 + 1e-8 * r.depth));
  }
  return r;
}

const Shape& ShapePairQuerier::object() const { return (RequireHeld(impl_.get()), impl_->object); }
const Shape& ShapePairQuerier::finger() const { return (RequireHeld(impl_.get()), impl_->finger); }
int ShapePairQuerier::obstacles_built() const {
  RequireHeld(impl_.get());
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->built;
}

ShapePairResult QueryShapePair(const Shape& object, const Pose2& object_pose, const Shape& finger, const Pose2& finger_pose) {
  return ShapePairQuerier(object, finger).Query(object_pose, finger_pose);
}

}  // namespace pushgraph::geometry
