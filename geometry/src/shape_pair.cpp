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
#include "shape_impl.h"

#include <Eigen/LU>

#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <mutex>

namespace pushgraph::geometry {
namespace {

using Mat23 = Eigen::Matrix<double, 2, 3>;
using Row3 = Eigen::Matrix<double, 1, 3>;

Eigen::Matrix2d RotationDerivative(double theta) {
  Eigen::Matrix2d dR;
  dR << -std::sin(theta), -std::cos(theta), std::cos(theta), -std::sin(theta);
  return dR;
}

Vec2 Perp(const Vec2& v) { return {-v.y(), v.x()}; }

// Witness points from a material point `m_w` (world) on the finger (finger_side) or on the
// object, the separating normal and the separation; with the Jacobians of each input.
struct WitnessInputs {
  bool on_finger = true;
  Vec2 m_w, n_w;
  double sd = 0.0;
  Mat23 J_m_obj = Mat23::Zero(), J_m_fin = Mat23::Zero();
  Mat23 J_n_obj = Mat23::Zero(), J_n_fin = Mat23::Zero();
  Row3 J_sd_obj = Row3::Zero(), J_sd_fin = Row3::Zero();
};

// Finger material point f: finger_point = f - rf n, object_point = f - (sd + rf) n.
// Object material point o: object_point = o + ro n, finger_point = o + (sd + ro) n.
void FillWitnesses(const WitnessInputs& in, double ro, double rf, ShapePairResult* r, ShapePairJacobians* J) {
  r->signed_distance = in.sd;
  r->normal = in.n_w;
  r->depth = std::max(0.0, -in.sd);
  if (in.on_finger) {
    r->finger_point = in.m_w - rf * in.n_w;
    r->object_point = in.m_w - (in.sd + rf) * in.n_w;
  } else {
    r->object_point = in.m_w + ro * in.n_w;
    r->finger_point = in.m_w + (in.sd + ro) * in.n_w;
  }
  if (!J) return;
  J->J_sd_object_pose = in.J_sd_obj;
  J->J_sd_finger_pose = in.J_sd_fin;
  if (in.on_finger) {
    J->J_finger_point_object_pose = in.J_m_obj - rf * in.J_n_obj;
    J->J_finger_point_finger_pose = in.J_m_fin - rf * in.J_n_fin;
    J->J_object_point_object_pose = in.J_m_obj - in.n_w * in.J_sd_obj - (in.sd + rf) * in.J_n_obj;
    J->J_object_point_finger_pose = in.J_m_fin - in.n_w * in.J_sd_fin - (in.sd + rf) * in.J_n_fin;
  } else {
    J->J_object_point_object_pose = in.J_m_obj + ro * in.J_n_obj;
    J->J_object_point_finger_pose = in.J_m_fin + ro * in.J_n_fin;
    J->J_finger_point_object_pose = in.J_m_obj + in.n_w * in.J_sd_obj + (in.sd + ro) * in.J_n_obj;
    J->J_finger_point_finger_pose = in.J_m_fin + in.n_w * in.J_sd_fin + (in.sd + ro) * in.J_n_fin;
  }
}

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

}  // namespace

struct ShapePairQuerier::Impl {
  Shape object, finger;
  Options options;
  bool point_finger = false;
  Vec2 finger_centre{0, 0};
  Shape inflated_object;  // point fingers: the object with radius ro + rf

  mutable std::mutex mutex;
  mutable std::map<double, Shape> obstacles;  // relative angle -> C (object frame)
  mutable std::deque<double> order;
  mutable int built = 0;

  // The obstacle at relative angle phi, or at phi rounded to angle_cache_resolution: *used is
  // the angle it was built for (the touching pairs must be searched at that angle).
  Shape Obstacle(double phi, double* used) const {
    double key = WrapAngle(phi);
    if (options.angle_cache_resolution > 0.0)
      key = WrapAngle(std::round(key / options.angle_cache_resolution) * options.angle_cache_resolution);
    *used = key;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = obstacles.find(key);
    if (it != obstacles.end()) return it->second;
    Shape c = MinkowskiSumOfCores(object, RotatedReflectedCore(finger, key), object.radius() + finger.radius());
    ++built;
    obstacles.emplace(key, c);
    order.push_back(key);
    while (static_cast<int>(order.size()) > std::max(1, options.max_cached_angles)) {
      obstacles.erase(order.front());
      order.pop_front();
    }
    return c;
  }

  ShapePairResult QueryPointFinger(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const {
    bool inside = false;
    const WitnessInputs w = FingerVertexAgainstObject(inflated_object, object_pose, finger_pose, finger_centre, 0.0, &inside);
    // The inflated object already carries rf: its signed distance is the separation, and the
    // finger point lies rf behind the centre.
    ShapePairResult r;
    FillWitnesses(w, object.radius(), finger.radius(), &r, J);
    r.intersecting = inside;
    return r;
  }

  ShapePairResult QueryExact(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const;
  ShapePairResult QuerySampled(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const;
};

ShapePairResult ShapePairQuerier::Impl::QueryExact(const Pose2& object_pose, const Pose2& finger_pose,
                                                   ShapePairJacobians* J) const {
  const double ro = object.radius(), rf = finger.radius();
  Mat23 J_c_obj;
  const Vec2 c = InverseAct(object_pose, finger_pose.translation(), &J_c_obj);
  double phi = 0.0;  // the relative angle the obstacle was built for (rounded when cached)
  const Shape C = Obstacle(finger_pose.theta - object_pose.theta, &phi);
  const PointQuery qc = QueryPoint(C, c);
  const Vec2 n_o = qc.normal;
  const double sd = qc.signed_distance;
  const Vec2 c_contact = qc.closest_point - C.radius() * n_o;  // finger origin at first contact (cores)
  const Eigen::Matrix2d R = Pose2{0.0, 0.0, phi}.rotation();

  // The touching pairs at the contact configuration c_contact generate C's closest feature.
  // Each is a line of C's boundary, n . x = h, moving with phi (Lozano-Perez's type A: finger
  // vertex on object edge, n fixed; type B: object vertex on finger edge, n turns with phi),
  // or a vertex-vertex pair, a C vertex o - R f.
  struct Pair {
    bool vertex_vertex = false, finger_material = true;
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
  for (const Vec2& f : fi.vertices) {
    const PointQuery q = QueryPoint(object, c_contact + R * f);
    if (std::abs(q.signed_distance + ro) > tol) continue;
    Pair p;
    p.f = f;
    if (q.feature.kind == BoundaryFeature::Kind::kVertex) {
      p.vertex_vertex = true;
      p.o = oi.vertices[oi.rings[0].first];  // replaced below by the exact vertex
      for (const RingInfo& ring : oi.rings)
        if (ring.polygon == q.feature.edge.polygon && ring.ring == q.feature.edge.ring) p.o = oi.vertices[ring.first + q.feature.edge.index];
    } else {
      p.n = q.normal;
      p.dh = -p.n.dot(dR * f);
    }
    pairs.push_back(p);
  }
  for (const Vec2& o : oi.vertices) {
    const Vec2 local = R.transpose() * (o - c_contact);
    const PointQuery q = QueryPoint(finger, local);
    if (std::abs(q.signed_distance + rf) > tol || q.feature.kind == BoundaryFeature::Kind::kVertex) continue;
    Pair p;
    p.finger_material = false;
    p.o = o;
    p.n = -(R * q.normal);
    p.dn = Perp(p.n);
    p.dh = p.dn.dot(o);
    pairs.push_back(p);
  }
  if (pairs.empty()) throw GeometryError("internal: no touching pair found at the contact configuration");

  // d sd / d c = n; d sd / d phi and the normal's derivatives from the generating pair(s).
  double sd_phi = 0.0;
  Eigen::Matrix2d Nc = Eigen::Matrix2d::Zero();
  Vec2 Nphi = Vec2::Zero();
  const Pair* material = &pairs[0];
  if (qc.feature.kind == BoundaryFeature::Kind::kEdge) {
    const Pair* best = nullptr;
    for (const Pair& p : pairs)
      if (!p.vertex_vertex && (!best || p.n.dot(n_o) > best->n.dot(n_o))) best = &p;
    if (!best) best = &pairs[0];
    material = best;
    sd_phi = best->dn.dot(c) - best->dh;
    Nphi = best->dn;
  } else {
    // A C vertex: either o - R f, or the crossing of two contact lines (two simultaneous contacts).
    Vec2 dv = Vec2::Zero();
    const Pair* vv = nullptr;
    for (const Pair& p : pairs)
      if (p.vertex_vertex) vv = &p;
    if (vv) {
      dv = -(dR * vv->f);
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
        dv = Nm.inverse() * rhs;
      }
      material = first;
    }
    const double d = (c - c_contact).norm();
    sd_phi = -n_o.dot(dv);
    if (d > 0.0) {
      const double s = qc.signed_distance + C.radius() > 0.0 ? 1.0 : -1.0;
      const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - n_o * n_o.transpose();
      Nc = s * P / d;
      Nphi = -s * P * dv / d;
    }
  }
  const bool finger_material = material->finger_material;
  const Vec2 f_l = material->f, o_l = material->o;
  const Eigen::Matrix2d Ro = object_pose.rotation();
  WitnessInputs w;
  w.sd = sd;
  w.n_w = Ro * n_o;
  w.J_sd_obj = n_o.transpose() * J_c_obj;
  w.J_sd_obj(2) -= sd_phi;
  w.J_sd_fin << (n_o.transpose() * Ro.transpose()), sd_phi;
  w.J_n_obj = Ro * Nc * J_c_obj;
  w.J_n_obj.col(2) += -Ro * Nphi + RotationDerivative(object_pose.theta) * n_o;
  w.J_n_fin.block<2, 2>(0, 0) = Ro * Nc * Ro.transpose();
  w.J_n_fin.col(2) = Ro * Nphi;
  w.on_finger = finger_material;
  if (finger_material) {
    w.m_w = Act(finger_pose, f_l, &w.J_m_fin);
  } else {
    w.m_w = Act(object_pose, o_l, &w.J_m_obj);
  }
  ShapePairResult r;
  FillWitnesses(w, ro, rf, &r, J);
  r.intersecting = qc.containment == Containment::kInside;
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
  if (best.sd > 0.0) {
    // Cores may still cross with no vertex inside (two thin bars in a cross): the sampled
    // answer would be wrong, so such configurations take the exact path.
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
        const auto side = [](const Vec2& p, const Vec2& q, const Vec2& x) {
          return (q - p).x() * (x - p).y() - (q - p).y() * (x - p).x();
        };
        if (side(a, b, u) * side(a, b, v) < 0 && side(u, v, a) * side(u, v, b) < 0) return QueryExact(object_pose, finger_pose, J);
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
  if (impl_->point_finger) {
    impl_->finger_centre = f.vertices[0];
    impl_->inflated_object = impl_->object.WithRadius(impl_->object.radius() + impl_->finger.radius());
  }
}

ShapePairQuerier::~ShapePairQuerier() = default;
ShapePairQuerier::ShapePairQuerier(ShapePairQuerier&&) noexcept = default;
ShapePairQuerier& ShapePairQuerier::operator=(ShapePairQuerier&&) noexcept = default;

ShapePairResult ShapePairQuerier::Query(const Pose2& object_pose, const Pose2& finger_pose, ShapePairJacobians* J) const {
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

const Shape& ShapePairQuerier::object() const { return impl_->object; }
const Shape& ShapePairQuerier::finger() const { return impl_->finger; }
int ShapePairQuerier::obstacles_built() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->built;
}

ShapePairResult QueryShapePair(const Shape& object, const Pose2& object_pose, const Shape& finger, const Pose2& finger_pose) {
  return ShapePairQuerier(object, finger).Query(object_pose, finger_pose);
}

}  // namespace pushgraph::geometry
