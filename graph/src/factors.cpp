#include <pushgraph/graph/factors.h>

#include "solver_log.h"

#include <pushgraph/geometry/point_query.h>

#include <Eigen/Geometry>

#include <cmath>
#include <exception>
#include <cstring>
#include <iostream>
#include <utility>

namespace pushgraph::graph {
namespace {

using RowMat33 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
using RowMat32 = Eigen::Matrix<double, 3, 2, Eigen::RowMajor>;
using RowMat23 = Eigen::Matrix<double, 2, 3, Eigen::RowMajor>;
using RowMat22 = Eigen::Matrix<double, 2, 2, Eigen::RowMajor>;

double CheckedWeight(double sigma, const char* what) {
  if (!(sigma > 0.0) || !std::isfinite(sigma)) {
    throw GraphError(std::string("factor sigma '") + what + "' must be finite and > 0, got " +
                     std::to_string(sigma));
  }
  return 1.0 / sigma;
}

Pose2 PoseFrom(const double* v) { return {v[0], v[1], v[2]}; }

Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

}  // namespace

// ---------------------------------------------------------------------------------------- M
PoseMeasurementFactor::PoseMeasurementFactor(const Pose2& measured, double sigma_trans,
                                             double sigma_rot)
    : measured_(measured),
      w_(CheckedWeight(sigma_trans, "pose translation"), CheckedWeight(sigma_trans, "pose translation"),
         CheckedWeight(sigma_rot, "pose rotation")) {}

bool PoseMeasurementFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  Eigen::Matrix3d J_d_est, J_log_d;
  const Pose2 d = geometry::Between(measured_, PoseFrom(parameters[0]), nullptr, &J_d_est);
  const Eigen::Vector3d log = geometry::Log(d, &J_log_d);
  Eigen::Map<Eigen::Vector3d>{residuals} = w_.asDiagonal() * log;
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Map<RowMat33>{jacobians[0]} = w_.asDiagonal() * (J_log_d * J_d_est);
  }
  return true;
}

VectorMeasurementFactor::VectorMeasurementFactor(const Vec2& measured, double sigma)
    : measured_(measured), w_(CheckedWeight(sigma, "point/force measurement")) {}

bool VectorMeasurementFactor::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  Eigen::Map<Eigen::Vector2d>{residuals} =
      w_ * (Eigen::Map<const Eigen::Vector2d>(parameters[0]) - measured_);
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Eigen::Map<RowMat22>{jacobians[0]} = w_ * Eigen::Matrix2d::Identity();
  }
  return true;
}

VectorSumMeasurementFactor::VectorSumMeasurementFactor(const Vec2& measured, double sigma)
    : measured_(measured), w_(CheckedWeight(sigma, "force measurement")) {}

bool VectorSumMeasurementFactor::Evaluate(double const* const* parameters, double* residuals,
                                          double** jacobians) const {
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (Eigen::Map<const Eigen::Vector2d>(parameters[0]) +
                                                 Eigen::Map<const Eigen::Vector2d>(parameters[1]) - measured_);
  for (int k = 0; jacobians != nullptr && k < 2; ++k)
    if (jacobians[k] != nullptr) Eigen::Map<RowMat22>{jacobians[k]} = w_ * Eigen::Matrix2d::Identity();
  return true;
}

// ---------------------------------------------------------------------------------------- C
BoundaryPointFactor::BoundaryPointFactor(geometry::Shape shape, double sigma)
    : shape_(std::move(shape)), w_(CheckedWeight(sigma, "contact on boundary")) {
  if (shape_.empty()) throw GraphError("BoundaryPointFactor: empty shape");
}

// A posed point query; false for non-finite parameters (the solver then rejects the step).
static bool QueryPointOrReject(const geometry::Shape& shape, const double* pose, const Vec2& point,
                               geometry::PointQuery* q, geometry::PointQueryJacobians* J) {
  try {
    *q = geometry::QueryPoint(shape, PoseFrom(pose), point, J);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

bool BoundaryPointFactor::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const Vec2 p(parameters[1][0], parameters[1][1]);
  geometry::PointQueryJacobians J;
  geometry::PointQuery q;
  if (!QueryPointOrReject(shape_, parameters[0], p, &q, &J)) return false;
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (p - q.closest_point);
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = -w_ * J.J_closest_pose;
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMat22>{jacobians[1]} = w_ * (Eigen::Matrix2d::Identity() - J.J_closest_point);
    }
  }
  return true;
}

LocalWitnessFactor::LocalWitnessFactor(geometry::Shape object, geometry::Shape finger, double sigma)
    : object_(std::move(object)), finger_(std::move(finger)), w_(CheckedWeight(sigma, "local contact witness")) {}

bool LocalWitnessFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Vec2 p(parameters[2][0], parameters[2][1]);
  geometry::PointQueryJacobians Jf, Jo;
  geometry::PointQuery on_finger, on_object;
  if (!QueryPointOrReject(finger_, parameters[1], p, &on_finger, &Jf) ||
      !QueryPointOrReject(object_, parameters[0], on_finger.closest_point, &on_object, &Jo))
    return false;
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (p - on_object.closest_point);
  if (jacobians != nullptr) {
    // q = G_o(x, f), f = G_f(e, p): dq/dx = J_o,pose; dq/de = J_o,point J_f,pose; dq/dp = J_o,point J_f,point.
    if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = -w_ * Jo.J_closest_pose;
    if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]} = -w_ * Jo.J_closest_point * Jf.J_closest_pose;
    if (jacobians[2] != nullptr)
      Eigen::Map<RowMat22>{jacobians[2]} = w_ * (Eigen::Matrix2d::Identity() - Jo.J_closest_point * Jf.J_closest_point);
  }
  return true;
}

namespace {
// The ring holding `feature` of `shape` (its edge, or its start vertex when `vertex`), or a
// GraphError naming what is missing, prefixed by `factor` and `what` ("the object").
const geometry::Ring& FeatureRing(const geometry::Shape& shape, const geometry::EdgeId& feature, bool vertex,
                                  const std::string& factor, const std::string& what) {
  const auto& polygons = shape.polygons();
  if (feature.polygon < 0 || feature.polygon >= static_cast<int>(polygons.size()) || feature.ring < -1 ||
      feature.ring >= static_cast<int>(polygons[feature.polygon].holes.size()))
    throw GraphError(factor + ": " + what + " has no ring " + std::to_string(feature.ring) + " in polygon " +
                     std::to_string(feature.polygon));
  const geometry::Ring& ring = shape.ring(feature.polygon, feature.ring);
  const int n = static_cast<int>(ring.size());
  if (feature.index < 0 || feature.index >= n || (!vertex && n < 2))
    throw GraphError(factor + ": " + what + "'s ring has no edge " + std::to_string(feature.index));
  return ring;
}
}  // namespace

FeatureWitnessFactor::FeatureWitnessFactor(geometry::Shape object, geometry::EdgeId feature, bool vertex,
                                           geometry::Shape finger, double sigma, int overlap_end)
    : finger_(std::move(finger)), vertex_(vertex), end_(overlap_end), radius_(object.radius()),
      w_(CheckedWeight(sigma, "contact feature witness")) {
  if (overlap_end < -1 || overlap_end > 1) throw GraphError("contact feature witness: overlap_end must be -1, 0 or +1");
  const geometry::Ring& ring = FeatureRing(object, feature, vertex, "contact feature witness", "the object");
  const int n = static_cast<int>(ring.size());
  a_ = ring[feature.index];
  b_ = ring[(feature.index + 1) % n];
  two_sided_ = n < 3;
}

namespace {
// The closest point q of the segment [A, B] (or of the point A when `vertex`), pushed out by r,
// to f, with its Jacobians with respect to A, B and f (world frame).
struct SegmentClosest {
  Vec2 q;
  Eigen::Matrix2d J_q_A, J_q_B, J_q_f;
};
SegmentClosest ClosestOnFeature(const Vec2& A, const Vec2& B, bool vertex, bool two_sided, double r, const Vec2& f) {
  SegmentClosest out;
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  const Vec2 d = B - A, g = f - A;
  const double L = d.squaredNorm();
  const double s = vertex ? 0.0 : g.dot(d) / L;
  if (vertex || s <= 0.0 || s >= 1.0) {
    // A vertex: q = V + r w / |w|, w = f - V.
    const bool at_b = !vertex && s >= 1.0;
    const Vec2 V = at_b ? B : A, w = f - V;
    const double wn = w.norm();
    const Eigen::Matrix2d dq_dw = (r > 0.0 && wn > 0.0) ? Eigen::Matrix2d(r * (I - w * w.transpose() / (wn * wn)) / wn)
                                                        : Eigen::Matrix2d::Zero();
    out.q = V + (r > 0.0 && wn > 0.0 ? Vec2(r * w / wn) : Vec2::Zero());
    out.J_q_f = dq_dw;
    (at_b ? out.J_q_B : out.J_q_A) = I - dq_dw;
    (at_b ? out.J_q_A : out.J_q_B) = Eigen::Matrix2d::Zero();
    return out;
  }
  // Inside the edge: q = A + s d + r n, s = g.d / L, n = (d_y, -d_x) / |d| (interior on the left).
  const double gd = g.dot(d);
  const Eigen::RowVector2d ds_df = d.transpose() / L;
  const Eigen::RowVector2d ds_dA = ((-d - g).transpose() * L + 2.0 * gd * d.transpose()) / (L * L);
  const Eigen::RowVector2d ds_dB = (g.transpose() * L - 2.0 * gd * d.transpose()) / (L * L);
  const double dn_norm = std::sqrt(L);
  Eigen::Matrix2d M;
  M << 0.0, 1.0, -1.0, 0.0;
  // A segment core (no interior) is rounded on both sides: the side of f.
  const double side = two_sided && g.dot(M * d) < 0.0 ? -1.0 : 1.0;
  const Vec2 n = side * M * d / dn_norm;
  const Eigen::Matrix2d dn_dd = side * M * (I - d * d.transpose() / L) / dn_norm;
  out.q = A + s * d + r * n;
  out.J_q_f = d * ds_df;
  out.J_q_A = I + d * ds_dA - s * I - r * dn_dd;
  out.J_q_B = d * ds_dB + s * I + r * dn_dd;
  return out;
}

// A flat finger face along an object face touches it along their overlap (a line contact), and
// its contact measurements are the overlap's two end points. A contact point free to slide on
// the overlap let a noisy measurement beyond an end that is an object corner (the notched
// block's notch, 3.5 mm from the flat pusher's end) pull the object along its face, while those
// inside pulled back nothing: a one-sided, biased pull. Each of the two contacts is held at its
// own end instead: `side` -1 or +1, the end toward the object edge's start A or its end B, the
// projection of the finger edge's vertex there onto the object edge, clamped to it
// (ClosestOnFeature does both). False when the finger's closest feature is not an edge facing
// the object's (within 45 degrees of antiparallel).
struct OverlapEnd {
  SegmentClosest c;
  Eigen::Matrix<double, 2, 3> J_F_e;
};
bool SnapToOverlapEnd(const Vec2& A, const Vec2& B, bool two_sided, double radius, const geometry::Shape& finger,
                      const Pose2& e, const geometry::EdgeId& finger_edge, int side, OverlapEnd* out) {
  const geometry::Ring& ring = finger.ring(finger_edge.polygon, finger_edge.ring);
  const int n = static_cast<int>(ring.size());
  if (n < 2) return false;
  Eigen::Matrix<double, 2, 3> J_FA_e, J_FB_e;
  const Vec2 FA = geometry::Act(e, ring[finger_edge.index], &J_FA_e);
  const Vec2 FB = geometry::Act(e, ring[(finger_edge.index + 1) % n], &J_FB_e);
  const Vec2 d = B - A, fd = FB - FA;
  if (!(d.squaredNorm() > 0.0) || !(fd.squaredNorm() > 0.0)) return false;
  if (d.dot(fd) > -std::sqrt(0.5 * d.squaredNorm() * fd.squaredNorm())) return false;  // not facing
  // The finger vertex farther toward the chosen end of the object edge.
  const bool fa_is_end = side < 0 ? (FA - FB).dot(d) < 0.0 : (FA - FB).dot(d) > 0.0;
  out->c = ClosestOnFeature(A, B, false, two_sided, radius, fa_is_end ? FA : FB);
  out->J_F_e = fa_is_end ? J_FA_e : J_FB_e;
  return true;
}
}  // namespace

bool FeatureWitnessFactor::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const Pose2 x = PoseFrom(parameters[0]);
  const Vec2 p(parameters[2][0], parameters[2][1]);
  geometry::PointQueryJacobians Jf;
  geometry::PointQuery on_finger;
  if (!QueryPointOrReject(finger_, parameters[1], p, &on_finger, &Jf)) return false;
  Eigen::Matrix<double, 2, 3> J_A_x, J_B_x;
  const Vec2 A = geometry::Act(x, a_, &J_A_x), B = geometry::Act(x, b_, &J_B_x);
  OverlapEnd end;
  if (!vertex_ && end_ != 0 && on_finger.feature.kind == geometry::BoundaryFeature::Kind::kEdge &&
      SnapToOverlapEnd(A, B, two_sided_, radius_, finger_, PoseFrom(parameters[1]), on_finger.feature.edge, end_, &end)) {
    Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (p - end.c.q);
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = -w_ * (end.c.J_q_A * J_A_x + end.c.J_q_B * J_B_x);
      if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]} = -w_ * end.c.J_q_f * end.J_F_e;
      if (jacobians[2] != nullptr) Eigen::Map<RowMat22>{jacobians[2]} = w_ * Eigen::Matrix2d::Identity();
    }
    return true;
  }
  const SegmentClosest c = ClosestOnFeature(A, B, vertex_, two_sided_, radius_, on_finger.closest_point);
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (p - c.q);
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = -w_ * (c.J_q_A * J_A_x + c.J_q_B * J_B_x);
    if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]} = -w_ * c.J_q_f * Jf.J_closest_pose;
    if (jacobians[2] != nullptr)
      Eigen::Map<RowMat22>{jacobians[2]} = w_ * (Eigen::Matrix2d::Identity() - c.J_q_f * Jf.J_closest_point);
  }
  return true;
}

OverlapEndMeasurementFactor::OverlapEndMeasurementFactor(const geometry::Shape& object, geometry::EdgeId object_edge,
                                                         geometry::Shape finger, geometry::EdgeId finger_edge,
                                                         int overlap_end, const Vec2& measured, double sigma)
    : finger_(std::move(finger)), finger_edge_(finger_edge), end_(overlap_end), radius_(object.radius()), measured_(measured),
      w_(CheckedWeight(sigma, "overlap end measurement")) {
  if (overlap_end != -1 && overlap_end != 1) throw GraphError("overlap end measurement: overlap_end must be -1 or +1");
  const geometry::Ring& ring = FeatureRing(object, object_edge, false, "overlap end measurement", "the object");
  FeatureRing(finger_, finger_edge, false, "overlap end measurement", "the finger");
  a_ = ring[object_edge.index];
  b_ = ring[(object_edge.index + 1) % ring.size()];
  two_sided_ = ring.size() < 3;
}

bool OverlapEndMeasurementFactor::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  Eigen::Matrix<double, 2, 3> J_A_x, J_B_x;
  const Pose2 x = PoseFrom(parameters[0]);
  const Vec2 A = geometry::Act(x, a_, &J_A_x), B = geometry::Act(x, b_, &J_B_x);
  OverlapEnd end;
  if (!SnapToOverlapEnd(A, B, two_sided_, radius_, finger_, PoseFrom(parameters[1]), finger_edge_, end_, &end))
    return false;  // the faces do not face each other at this step: rejected, as a failed query
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (end.c.q - measured_);
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = w_ * (end.c.J_q_A * J_A_x + end.c.J_q_B * J_B_x);
    if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]} = w_ * end.c.J_q_f * end.J_F_e;
  }
  return true;
}

FrictionConeFactor::FrictionConeFactor(geometry::Shape object, double mu, double sigma)
    : object_(std::move(object)), mu_(mu), w_(CheckedWeight(sigma, "friction cone")) {
  if (!(mu >= 0.0) || !std::isfinite(mu)) throw GraphError("friction cone: mu_contact must be finite and >= 0");
}

bool FrictionConeFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  const Vec2 p(parameters[1][0], parameters[1][1]), f(parameters[2][0], parameters[2][1]);
  geometry::PointQueryJacobians J;
  geometry::PointQuery q;
  if (!QueryPointOrReject(object_, parameters[0], p, &q, &J)) return false;
  // Inward normal n = -outward, tangent t = z x n; dn/d(.) = -J_normal_(.).
  const Vec2 n = -q.normal, t(-n.y(), n.x());
  Eigen::Matrix2d perp;
  perp << 0.0, -1.0, 1.0, 0.0;
  const double fn = f.dot(n), ft = f.dot(t), sign = ft >= 0.0 ? 1.0 : -1.0;
  const bool pulls = fn < 0.0, slips = std::abs(ft) - mu_ * fn > 0.0;
  residuals[0] = pulls ? -w_ * fn : 0.0;
  residuals[1] = slips ? w_ * (std::abs(ft) - mu_ * fn) : 0.0;
  if (jacobians == nullptr) return true;
  // r0 = -w f.n; r1 = w (s f.t - mu f.n), t = perp n.
  const Eigen::RowVector2d dr0_dn = pulls ? Eigen::RowVector2d(-w_ * f.transpose()) : Eigen::RowVector2d::Zero();
  const Eigen::RowVector2d dr1_dn =
      slips ? Eigen::RowVector2d(w_ * (sign * f.transpose() * perp - mu_ * f.transpose())) : Eigen::RowVector2d::Zero();
  const Eigen::RowVector2d dr0_df = pulls ? Eigen::RowVector2d(-w_ * n.transpose()) : Eigen::RowVector2d::Zero();
  const Eigen::RowVector2d dr1_df =
      slips ? Eigen::RowVector2d(w_ * (sign * t.transpose() - mu_ * n.transpose())) : Eigen::RowVector2d::Zero();
  Eigen::Matrix2d dr_dn, dr_df;
  dr_dn << dr0_dn, dr1_dn;
  dr_df << dr0_df, dr1_df;
  if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = -dr_dn * J.J_normal_pose;
  if (jacobians[1] != nullptr) Eigen::Map<RowMat22>{jacobians[1]} = -dr_dn * J.J_normal_point;
  if (jacobians[2] != nullptr) Eigen::Map<RowMat22>{jacobians[2]} = dr_df;
  return true;
}

// Object pose in parameters[0], finger pose in parameters[1]. A geometry error (non-finite
// poses during a bad step) makes Ceres reject the step rather than abort the solve.
// The touching, witness and intersection factors of a step ask the same querier about the same
// two poses one after another (both solvers evaluate residual blocks in order): the last answer
// is kept per thread and reused when the querier (the same object, not just the same address:
// weak_ptr ownership) and the six pose values are bit-identical. The query is deterministic,
// so the reuse changes nothing but the time (one shape-pair query per step instead of three).
static bool QueryPair(const std::shared_ptr<const geometry::ShapePairQuerier>& querier,
                      double const* const* parameters, geometry::ShapePairResult* r, geometry::ShapePairJacobians* J) {
  struct LastQuery {
    std::weak_ptr<const geometry::ShapePairQuerier> querier;
    double poses[6] = {};
    bool has_jacobians = false;
    geometry::ShapePairResult result;
    geometry::ShapePairJacobians jacobians;
  };
  thread_local LastQuery last;
  double poses[6];
  std::copy(parameters[0], parameters[0] + 3, poses);
  std::copy(parameters[1], parameters[1] + 3, poses + 3);
  const bool same_querier = !last.querier.expired() && !last.querier.owner_before(querier) &&
                            !querier.owner_before(last.querier);
  if (same_querier && (J == nullptr || last.has_jacobians) && std::memcmp(poses, last.poses, sizeof poses) == 0) {
    *r = last.result;
    if (J != nullptr) *J = last.jacobians;
    return true;
  }
  try {
    *r = querier->Query(PoseFrom(parameters[0]), PoseFrom(parameters[1]), J);
  } catch (const std::exception& e) {
    // Ceres treats a failed evaluation as an infeasible step; say why when asked to.
    if (internal::SolverLogLevel() >= 1) {
      std::cerr << "pushgraph: shape-pair query failed: " << e.what() << "\n";
    }
    last.querier.reset();
    return false;
  }
  last.querier = querier;
  std::copy(poses, poses + 6, last.poses);
  last.has_jacobians = J != nullptr;
  last.result = *r;
  if (J != nullptr) last.jacobians = *J;
  return true;
}

TouchingFactor::TouchingFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier,
                               double sigma)
    : querier_(std::move(querier)), w_(CheckedWeight(sigma, "touching")) {
  if (!querier_) throw GraphError("TouchingFactor: null shape-pair querier");
}

bool TouchingFactor::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  geometry::ShapePairJacobians J;
  geometry::ShapePairResult r;
  if (!QueryPair(querier_, parameters, &r, &J)) return false;
  residuals[0] = w_ * r.signed_distance;
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<Eigen::RowVector3d>{jacobians[0]} = w_ * J.J_sd_object_pose;
    if (jacobians[1] != nullptr) Eigen::Map<Eigen::RowVector3d>{jacobians[1]} = w_ * J.J_sd_finger_pose;
  }
  return true;
}

// ------------------------------------------------------------------------- C, witness form
ContactWitnessFactor::ContactWitnessFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier,
                                           double sigma)
    : querier_(std::move(querier)), w_(CheckedWeight(sigma, "contact witness")) {
  if (!querier_) throw GraphError("ContactWitnessFactor: null shape-pair querier");
}

bool ContactWitnessFactor::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  geometry::ShapePairJacobians J;
  geometry::ShapePairResult r;
  if (!QueryPair(querier_, parameters, &r, &J)) return false;
  const Vec2 mid = 0.5 * (r.object_point + r.finger_point);
  Eigen::Map<Eigen::Vector2d>{residuals} = w_ * (Vec2(parameters[2][0], parameters[2][1]) - mid);
  if (jacobians != nullptr) {
    const double h = -0.5 * w_;
    if (jacobians[0] != nullptr) {
      Eigen::Map<RowMat23>{jacobians[0]} = h * (J.J_object_point_object_pose + J.J_finger_point_object_pose);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMat23>{jacobians[1]} = h * (J.J_object_point_finger_pose + J.J_finger_point_finger_pose);
    }
    if (jacobians[2] != nullptr) Eigen::Map<RowMat22>{jacobians[2]} = w_ * Eigen::Matrix2d::Identity();
  }
  return true;
}

// ---------------------------------------------------------------------------------------- S
IntersectionFactor::IntersectionFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier,
                                       double sigma)
    : querier_(std::move(querier)), w_(CheckedWeight(sigma, "intersection")) {
  if (!querier_) throw GraphError("IntersectionFactor: null shape-pair querier");
}

bool IntersectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  geometry::ShapePairJacobians J;
  geometry::ShapePairResult r;
  if (!QueryPair(querier_, parameters, &r, &J)) return false;
  Eigen::Map<Eigen::Vector2d> res(residuals);
  if (!r.intersecting) {
    res.setZero();
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]}.setZero();
      if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]}.setZero();
    }
    return true;
  }
  res = w_ * (r.object_point - r.finger_point);  // G_delta - delta
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) {
      Eigen::Map<RowMat23>{jacobians[0]} =
          w_ * (J.J_object_point_object_pose - J.J_finger_point_object_pose);
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMat23>{jacobians[1]} =
          w_ * (J.J_object_point_finger_pose - J.J_finger_point_finger_pose);
    }
  }
  return true;
}

// ---------------------------------------------------------------------------------------- V
double ConstantVelocitySigma(double q, double dt1, double dt2) {
  return q * std::sqrt(0.5 * (dt1 + dt2));
}

ConstantVelocityFactor::ConstantVelocityFactor(double dt1, double dt2, double sigma_trans,
                                               double sigma_rot)
    : dt1_(dt1),
      dt2_(dt2),
      w_(CheckedWeight(sigma_trans, "velocity translation"),
         CheckedWeight(sigma_trans, "velocity translation"), CheckedWeight(sigma_rot, "velocity rotation")) {
  if (!(dt1 > 0.0) || !(dt2 > 0.0) || !std::isfinite(dt1) || !std::isfinite(dt2)) {
    throw GraphError("ConstantVelocityFactor: time steps must be finite and > 0, got " +
                     std::to_string(dt1) + ", " + std::to_string(dt2));
  }
}

bool ConstantVelocityFactor::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const Pose2 a = PoseFrom(parameters[0]), b = PoseFrom(parameters[1]), c = PoseFrom(parameters[2]);
  Eigen::Matrix3d J_d1_a, J_d1_b, J_d2_b, J_d2_c, J_l1_d1, J_l2_d2;
  const Eigen::Vector3d l1 = geometry::Log(geometry::Between(a, b, &J_d1_a, &J_d1_b), &J_l1_d1);
  const Eigen::Vector3d l2 = geometry::Log(geometry::Between(b, c, &J_d2_b, &J_d2_c), &J_l2_d2);
  Eigen::Map<Eigen::Vector3d>{residuals} = w_.asDiagonal() * (l1 / dt1_ - l2 / dt2_);
  if (jacobians != nullptr) {
    const auto W = w_.asDiagonal();
    if (jacobians[0] != nullptr) Eigen::Map<RowMat33>{jacobians[0]} = W * (J_l1_d1 * J_d1_a / dt1_);
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMat33>{jacobians[1]} = W * (J_l1_d1 * J_d1_b / dt1_ - J_l2_d2 * J_d2_b / dt2_);
    }
    if (jacobians[2] != nullptr) Eigen::Map<RowMat33>{jacobians[2]} = W * (-J_l2_d2 * J_d2_c / dt2_);
  }
  return true;
}

RandomWalkFactor::RandomWalkFactor(double dt, double q_trans, double q_rot) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw GraphError("RandomWalkFactor: time step must be finite and > 0, got " + std::to_string(dt));
  }
  const double st = CheckedWeight(q_trans, "random walk translation");
  const double sr = CheckedWeight(q_rot, "random walk rotation");
  const double s = 1.0 / std::sqrt(dt);
  w_ = Eigen::Vector3d(st * s, st * s, sr * s);
}

bool RandomWalkFactor::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  Eigen::Matrix3d J_d_a, J_d_b, J_l_d;
  const Eigen::Vector3d l = geometry::Log(
      geometry::Between(PoseFrom(parameters[0]), PoseFrom(parameters[1]), &J_d_a, &J_d_b), &J_l_d);
  Eigen::Map<Eigen::Vector3d>{residuals} = w_.asDiagonal() * l;
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<RowMat33>{jacobians[0]} = w_.asDiagonal() * (J_l_d * J_d_a);
    if (jacobians[1] != nullptr) Eigen::Map<RowMat33>{jacobians[1]} = w_.asDiagonal() * (J_l_d * J_d_b);
  }
  return true;
}

VectorRandomWalkFactor::VectorRandomWalkFactor(double dt, double q) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw GraphError("VectorRandomWalkFactor: time step must be finite and > 0, got " + std::to_string(dt));
  }
  w_ = CheckedWeight(q, "vector random walk") / std::sqrt(dt);
}

bool VectorRandomWalkFactor::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  Eigen::Map<Eigen::Vector2d>{residuals} =
      w_ * (Eigen::Map<const Eigen::Vector2d>(parameters[1]) - Eigen::Map<const Eigen::Vector2d>(parameters[0]));
  if (jacobians != nullptr) {
    if (jacobians[0] != nullptr) Eigen::Map<RowMat22>{jacobians[0]} = -w_ * Eigen::Matrix2d::Identity();
    if (jacobians[1] != nullptr) Eigen::Map<RowMat22>{jacobians[1]} = w_ * Eigen::Matrix2d::Identity();
  }
  return true;
}

// ---------------------------------------------------------------------------------------- D
QuasiStaticTerms ComputeQuasiStaticTerms(const QuasiStaticGeometry& geo, const Pose2& x_prev,
                                         const Pose2& x, const Vec2& p, const Vec2& f) {
  QuasiStaticTerms t;
  // Body twist of the frame origin, then of the centre of pressure r: v + omega z x r.
  Eigen::Matrix3d J_d_xprev, J_d_x, J_l_d;
  const Eigen::Vector3d xi =
      geometry::Log(geometry::Between(x_prev, x, &J_d_xprev, &J_d_x), &J_l_d) / geo.dt;
  const Vec2& r = geo.centre_of_pressure;
  Eigen::Matrix3d A;
  A << 1.0, 0.0, -r.y(), 0.0, 1.0, r.x(), 0.0, 0.0, geo.c;
  t.V = A * xi;
  const Eigen::Matrix3d J_V_l = A / geo.dt;
  t.J_V_xprev = J_V_l * J_l_d * J_d_xprev;
  t.J_V_x = J_V_l * J_l_d * J_d_x;

  // Load in the object frame: f_b = R^T f, moment arm q = x^-1 p - r, tau = q x f_b.
  const Eigen::Matrix2d Rt = x.rotation().transpose();
  const Vec2 fb = Rt * f;
  Eigen::Matrix<double, 2, 3> J_fb_x = Eigen::Matrix<double, 2, 3>::Zero();
  J_fb_x(0, 2) = fb.y();
  J_fb_x(1, 2) = -fb.x();
  Eigen::Matrix<double, 2, 3> J_q_x;
  Eigen::Matrix2d J_q_p;
  const Vec2 q = geometry::InverseAct(x, p, &J_q_x, &J_q_p) - r;
  const double tau = q.x() * fb.y() - q.y() * fb.x();
  const Eigen::RowVector2d J_tau_q(fb.y(), -fb.x());
  const Eigen::RowVector2d J_tau_fb(-q.y(), q.x());
  t.g << fb.x(), fb.y(), tau / geo.c;
  t.J_g_x.topRows<2>() = J_fb_x;
  t.J_g_x.row(2) = (J_tau_q * J_q_x + J_tau_fb * J_fb_x) / geo.c;
  t.J_g_p.topRows<2>().setZero();
  t.J_g_p.row(2) = J_tau_q * J_q_p / geo.c;
  t.J_g_f.topRows<2>() = Rt;
  t.J_g_f.row(2) = J_tau_fb * Rt / geo.c;
  return t;
}

namespace {
void CheckGeometry(const QuasiStaticGeometry& g) {
  if (!(g.c > 0.0) || !std::isfinite(g.c)) throw GraphError("quasi-static factor: c must be finite and > 0");
  if (!(g.dt > 0.0) || !std::isfinite(g.dt)) {
    throw GraphError("quasi-static factor: dt must be finite and > 0, got " + std::to_string(g.dt));
  }
  if (!g.centre_of_pressure.allFinite()) throw GraphError("quasi-static factor: non-finite centre of pressure");
}

// The regularizers of |V'| and |g'| (D and the load factor).
void CheckEps(double eps_velocity, double eps_force, const char* factor) {
  if (!(eps_velocity > 0.0) || !(eps_force > 0.0) || !std::isfinite(eps_velocity) || !std::isfinite(eps_force)) {
    throw GraphError(std::string(factor) + " factor: eps_velocity and eps_force must be finite and > 0");
  }
}
}  // namespace

QuasiStaticFactor::QuasiStaticFactor(const QuasiStaticGeometry& geometry, double eps_velocity,
                                     double eps_force, double sigma)
    : geometry_(geometry),
      eps_v_(eps_velocity),
      eps_f_(eps_force),
      w_(CheckedWeight(sigma, "quasi-static")) {
  CheckGeometry(geometry_);
  CheckEps(eps_v_, eps_f_, "quasi-static");
}

// r = w u / (a b), u = V' x g', a = sqrt(|V'|^2 + eps_v^2), b = sqrt(|g'|^2 + eps_f^2):
//   dr/dV = w (-[g]x / (a b) - u V^T / (a^3 b)),  dr/dg = w ([V]x / (a b) - u g^T / (a b^3)).
static Eigen::Vector3d NormalizedCross(const QuasiStaticTerms& t, double eps_v, double eps_f, double w,
                                       Eigen::Matrix3d* J_r_V, Eigen::Matrix3d* J_r_g) {
  const Eigen::Vector3d u = t.V.cross(t.g);
  const double a = std::sqrt(t.V.squaredNorm() + eps_v * eps_v);
  const double b = std::sqrt(t.g.squaredNorm() + eps_f * eps_f);
  const double s = w / (a * b);
  if (J_r_V != nullptr) *J_r_V = s * (-Skew(t.g) - u * t.V.transpose() / (a * a));
  if (J_r_g != nullptr) *J_r_g = s * (Skew(t.V) - u * t.g.transpose() / (b * b));
  return s * u;
}

// D at c = geometry.c, or at c = parameters[4][0] when with_c (then also d r / d c).
static bool EvaluateQuasiStatic(QuasiStaticGeometry geometry, double eps_v, double eps_f, double w,
                                bool with_c, double const* const* parameters, double* residuals,
                                double** jacobians) {
  if (with_c) {
    geometry.c = parameters[4][0];
    if (!(geometry.c > 0.0) || !std::isfinite(geometry.c)) return false;  // Ceres shortens the step
  }
  const QuasiStaticTerms t = ComputeQuasiStaticTerms(
      geometry, PoseFrom(parameters[0]), PoseFrom(parameters[1]),
      Vec2(parameters[2][0], parameters[2][1]), Vec2(parameters[3][0], parameters[3][1]));
  Eigen::Matrix3d J_r_V, J_r_g;
  const bool jac = jacobians != nullptr;
  Eigen::Map<Eigen::Vector3d>{residuals} =
      NormalizedCross(t, eps_v, eps_f, w, jac ? &J_r_V : nullptr, jac ? &J_r_g : nullptr);
  if (!jac) return true;
  if (jacobians[0] != nullptr) Eigen::Map<RowMat33>{jacobians[0]} = J_r_V * t.J_V_xprev;
  if (jacobians[1] != nullptr) Eigen::Map<RowMat33>{jacobians[1]} = J_r_V * t.J_V_x + J_r_g * t.J_g_x;
  if (jacobians[2] != nullptr) Eigen::Map<RowMat32>{jacobians[2]} = J_r_g * t.J_g_p;
  if (jacobians[3] != nullptr) Eigen::Map<RowMat32>{jacobians[3]} = J_r_g * t.J_g_f;
  if (with_c && jacobians[4] != nullptr) {
    // V'_z = c omega and g'_z = tau / c: dV'/dc = (0, 0, V'_z / c), dg'/dc = (0, 0, -g'_z / c).
    const double c = geometry.c;
    Eigen::Map<Eigen::Vector3d>{jacobians[4]} = J_r_V.col(2) * (t.V.z() / c) - J_r_g.col(2) * (t.g.z() / c);
  }
  return true;
}

bool QuasiStaticFactor::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  return EvaluateQuasiStatic(geometry_, eps_v_, eps_f_, w_, false, parameters, residuals, jacobians);
}

QuasiStaticFactorWithC::QuasiStaticFactorWithC(const QuasiStaticGeometry& geometry, double eps_velocity,
                                               double eps_force, double sigma)
    : geometry_(geometry), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedWeight(sigma, "quasi-static")) {
  CheckGeometry(geometry_);
  CheckEps(eps_v_, eps_f_, "quasi-static");
}

bool QuasiStaticFactorWithC::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  return EvaluateQuasiStatic(geometry_, eps_v_, eps_f_, w_, true, parameters, residuals, jacobians);
}

namespace {
// The terms of two contacts: V' and its Jacobians from the first (the same poses), g' the sum.
struct TwoContactTerms {
  QuasiStaticTerms t;  // V', J_V_*; g' = g'_1 + g'_2, J_g_x summed; J_g_p, J_g_f of contact 1
  Eigen::Matrix<double, 3, 2> J_g_p2, J_g_f2;
};
TwoContactTerms ComputeTwoContactTerms(const QuasiStaticGeometry& geometry, double const* const* parameters) {
  const Pose2 x_prev = PoseFrom(parameters[0]), x = PoseFrom(parameters[1]);
  TwoContactTerms out;
  out.t = ComputeQuasiStaticTerms(geometry, x_prev, x, Vec2(parameters[2][0], parameters[2][1]),
                                  Vec2(parameters[3][0], parameters[3][1]));
  const QuasiStaticTerms second = ComputeQuasiStaticTerms(geometry, x_prev, x, Vec2(parameters[4][0], parameters[4][1]),
                                                          Vec2(parameters[5][0], parameters[5][1]));
  out.t.g += second.g;
  out.t.J_g_x += second.J_g_x;
  out.J_g_p2 = second.J_g_p;
  out.J_g_f2 = second.J_g_f;
  return out;
}
}  // namespace

QuasiStaticTwoContactFactor::QuasiStaticTwoContactFactor(const QuasiStaticGeometry& geometry, double eps_velocity,
                                                         double eps_force, double sigma)
    : geometry_(geometry), eps_v_(eps_velocity), eps_f_(eps_force), w_(CheckedWeight(sigma, "quasi-static")) {
  CheckGeometry(geometry_);
  CheckEps(eps_v_, eps_f_, "quasi-static");
}

bool QuasiStaticTwoContactFactor::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  const TwoContactTerms tc = ComputeTwoContactTerms(geometry_, parameters);
  Eigen::Matrix3d J_r_V, J_r_g;
  const bool jac = jacobians != nullptr;
  Eigen::Map<Eigen::Vector3d>{residuals} =
      NormalizedCross(tc.t, eps_v_, eps_f_, w_, jac ? &J_r_V : nullptr, jac ? &J_r_g : nullptr);
  if (!jac) return true;
  if (jacobians[0] != nullptr) Eigen::Map<RowMat33>{jacobians[0]} = J_r_V * tc.t.J_V_xprev;
  if (jacobians[1] != nullptr) Eigen::Map<RowMat33>{jacobians[1]} = J_r_V * tc.t.J_V_x + J_r_g * tc.t.J_g_x;
  if (jacobians[2] != nullptr) Eigen::Map<RowMat32>{jacobians[2]} = J_r_g * tc.t.J_g_p;
  if (jacobians[3] != nullptr) Eigen::Map<RowMat32>{jacobians[3]} = J_r_g * tc.t.J_g_f;
  if (jacobians[4] != nullptr) Eigen::Map<RowMat32>{jacobians[4]} = J_r_g * tc.J_g_p2;
  if (jacobians[5] != nullptr) Eigen::Map<RowMat32>{jacobians[5]} = J_r_g * tc.J_g_f2;
  return true;
}

// The load factors' arguments checked; their weight.
static double CheckedLoadWeight(const QuasiStaticGeometry& geometry, double f_max, double eps_v, double eps_f,
                                double sigma) {
  CheckGeometry(geometry);
  if (!(f_max > 0.0) || !std::isfinite(f_max)) throw GraphError("limit-surface load factor: f_max must be > 0");
  CheckEps(eps_v, eps_f, "limit-surface load");
  return CheckedWeight(sigma, "limit-surface load");
}

LimitSurfaceLoadFactor::LimitSurfaceLoadFactor(const QuasiStaticGeometry& geometry, double f_max,
                                               double eps_velocity, double eps_force, double sigma)
    : geometry_(geometry), f_max_(f_max), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedLoadWeight(geometry, f_max, eps_velocity, eps_force, sigma)) {}

namespace {

// r = w s_v (b / f_max - 1), b = |g'|_eps, from the terms t of the load's contact(s) (jacobians
// [2], [3] of the first contact; [4], [5] of a second one when `second` is given). With J_fmax:
// d r / d f_max; with J_c: d r / d c.
bool EvaluateLoad(const QuasiStaticGeometry& geometry, double f_max, double eps_v, double eps_f, double w,
                  const QuasiStaticTerms& t, double* residuals, double** jacobians, double* J_fmax, double* J_c,
                  const TwoContactTerms* second = nullptr, Eigen::RowVector3d* J_r_g_out = nullptr) {
  if (!(f_max > 0.0)) return false;
  const double v2 = t.V.squaredNorm(), e2 = eps_v * eps_v;
  const double sv = v2 / (v2 + e2);
  const double b = std::sqrt(t.g.squaredNorm() + eps_f * eps_f);
  residuals[0] = w * sv * (b / f_max - 1.0);
  if (jacobians == nullptr) return true;
  // ds_v/dV' = 2 eps^2 V'^T / (|V'|^2 + eps^2)^2;  d b / d g' = g'^T / b.
  const Eigen::RowVector3d J_r_V = w * (b / f_max - 1.0) * 2.0 * e2 * t.V.transpose() / ((v2 + e2) * (v2 + e2));
  const Eigen::RowVector3d J_r_g = w * sv * t.g.transpose() / (b * f_max);
  if (jacobians[0] != nullptr) Eigen::Map<Eigen::RowVector3d>{jacobians[0]} = J_r_V * t.J_V_xprev;
  if (jacobians[1] != nullptr) Eigen::Map<Eigen::RowVector3d>{jacobians[1]} = J_r_V * t.J_V_x + J_r_g * t.J_g_x;
  if (jacobians[2] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[2]} = J_r_g * t.J_g_p;
  if (jacobians[3] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[3]} = J_r_g * t.J_g_f;
  if (second != nullptr && jacobians[4] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[4]} = J_r_g * second->J_g_p2;
  if (second != nullptr && jacobians[5] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[5]} = J_r_g * second->J_g_f2;
  if (J_r_g_out != nullptr) *J_r_g_out = J_r_g;
  if (J_fmax != nullptr) *J_fmax = -w * sv * b / (f_max * f_max);
  // V'_z = c omega and g'_z = tau / c: dV'/dc = (0, 0, V'_z / c), dg'/dc = (0, 0, -g'_z / c).
  if (J_c != nullptr) *J_c = J_r_V(2) * (t.V.z() / geometry.c) - J_r_g(2) * (t.g.z() / geometry.c);
  return true;
}

QuasiStaticTerms OneContactTerms(const QuasiStaticGeometry& geometry, double const* const* parameters) {
  return ComputeQuasiStaticTerms(geometry, PoseFrom(parameters[0]), PoseFrom(parameters[1]),
                                 Vec2(parameters[2][0], parameters[2][1]), Vec2(parameters[3][0], parameters[3][1]));
}

}  // namespace

LimitSurfaceLoadTwoContactFactor::LimitSurfaceLoadTwoContactFactor(const QuasiStaticGeometry& geometry, double f_max,
                                                                   double eps_velocity, double eps_force, double sigma)
    : geometry_(geometry), f_max_(f_max), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedLoadWeight(geometry, f_max, eps_velocity, eps_force, sigma)) {}

bool LimitSurfaceLoadTwoContactFactor::Evaluate(double const* const* parameters, double* residuals,
                                                double** jacobians) const {
  const TwoContactTerms tc = ComputeTwoContactTerms(geometry_, parameters);
  return EvaluateLoad(geometry_, f_max_, eps_v_, eps_f_, w_, tc.t, residuals, jacobians, nullptr, nullptr, &tc);
}

namespace {
// The terms of any number of contacts: V' and its Jacobians from the first, g' the sum (in
// contact order, as ComputeTwoContactTerms adds its two), each contact's J_g_p and J_g_f.
struct MultiContactTerms {
  QuasiStaticTerms t;
  std::vector<Eigen::Matrix<double, 3, 2>> J_g_p, J_g_f;
};
MultiContactTerms ComputeMultiContactTerms(const QuasiStaticGeometry& geometry, int contacts,
                                           double const* const* parameters) {
  const Pose2 x_prev = PoseFrom(parameters[0]), x = PoseFrom(parameters[1]);
  MultiContactTerms out;
  for (int k = 0; k < contacts; ++k) {
    const double* p = parameters[2 + 2 * k];
    const double* f = parameters[3 + 2 * k];
    const QuasiStaticTerms c = ComputeQuasiStaticTerms(geometry, x_prev, x, Vec2(p[0], p[1]), Vec2(f[0], f[1]));
    if (k == 0) {
      out.t = c;
    } else {
      out.t.g += c.g;
      out.t.J_g_x += c.J_g_x;
    }
    out.J_g_p.push_back(c.J_g_p);
    out.J_g_f.push_back(c.J_g_f);
  }
  return out;
}

void SetMultiContactSizes(std::vector<int32_t>* sizes, int contacts, const char* what) {
  if (contacts < 1) throw GraphError(std::string(what) + ": needs at least one contact");
  sizes->assign({3, 3});
  for (int k = 0; k < contacts; ++k) sizes->insert(sizes->end(), {2, 2});
}
}  // namespace

QuasiStaticMultiContactFactor::QuasiStaticMultiContactFactor(const QuasiStaticGeometry& geometry, int contacts,
                                                             double eps_velocity, double eps_force, double sigma)
    : geometry_(geometry), contacts_(contacts), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedWeight(sigma, "quasi-static")) {
  CheckGeometry(geometry_);
  CheckEps(eps_v_, eps_f_, "quasi-static");
  set_num_residuals(3);
  SetMultiContactSizes(mutable_parameter_block_sizes(), contacts, "quasi-static factor");
}

bool QuasiStaticMultiContactFactor::Evaluate(double const* const* parameters, double* residuals,
                                             double** jacobians) const {
  const MultiContactTerms mc = ComputeMultiContactTerms(geometry_, contacts_, parameters);
  Eigen::Matrix3d J_r_V, J_r_g;
  const bool jac = jacobians != nullptr;
  Eigen::Map<Eigen::Vector3d>{residuals} =
      NormalizedCross(mc.t, eps_v_, eps_f_, w_, jac ? &J_r_V : nullptr, jac ? &J_r_g : nullptr);
  if (!jac) return true;
  if (jacobians[0] != nullptr) Eigen::Map<RowMat33>{jacobians[0]} = J_r_V * mc.t.J_V_xprev;
  if (jacobians[1] != nullptr) Eigen::Map<RowMat33>{jacobians[1]} = J_r_V * mc.t.J_V_x + J_r_g * mc.t.J_g_x;
  for (int k = 0; k < contacts_; ++k) {
    if (jacobians[2 + 2 * k] != nullptr) Eigen::Map<RowMat32>{jacobians[2 + 2 * k]} = J_r_g * mc.J_g_p[k];
    if (jacobians[3 + 2 * k] != nullptr) Eigen::Map<RowMat32>{jacobians[3 + 2 * k]} = J_r_g * mc.J_g_f[k];
  }
  return true;
}

LimitSurfaceLoadMultiContactFactor::LimitSurfaceLoadMultiContactFactor(const QuasiStaticGeometry& geometry,
                                                                       int contacts, double f_max,
                                                                       double eps_velocity, double eps_force,
                                                                       double sigma)
    : geometry_(geometry), contacts_(contacts), f_max_(f_max), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedLoadWeight(geometry, f_max, eps_velocity, eps_force, sigma)) {
  set_num_residuals(1);
  SetMultiContactSizes(mutable_parameter_block_sizes(), contacts, "limit-surface load factor");
}

bool LimitSurfaceLoadMultiContactFactor::Evaluate(double const* const* parameters, double* residuals,
                                                  double** jacobians) const {
  const MultiContactTerms mc = ComputeMultiContactTerms(geometry_, contacts_, parameters);
  Eigen::RowVector3d J_r_g;
  // The first contact's blocks through EvaluateLoad, every other's from d r / d g'.
  double* first[4] = {nullptr, nullptr, nullptr, nullptr};
  for (int k = 0; jacobians != nullptr && k < 4; ++k) first[k] = jacobians[k];
  if (!EvaluateLoad(geometry_, f_max_, eps_v_, eps_f_, w_, mc.t, residuals, jacobians != nullptr ? first : nullptr,
                    nullptr, nullptr, nullptr, &J_r_g))
    return false;
  for (int k = 1; jacobians != nullptr && k < contacts_; ++k) {
    if (jacobians[2 + 2 * k] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[2 + 2 * k]} = J_r_g * mc.J_g_p[k];
    if (jacobians[3 + 2 * k] != nullptr) Eigen::Map<Eigen::RowVector2d>{jacobians[3 + 2 * k]} = J_r_g * mc.J_g_f[k];
  }
  return true;
}

bool LimitSurfaceLoadFactor::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  return EvaluateLoad(geometry_, f_max_, eps_v_, eps_f_, w_, OneContactTerms(geometry_, parameters), residuals, jacobians,
                      nullptr, nullptr);
}

LimitSurfaceLoadFactorWithParameters::LimitSurfaceLoadFactorWithParameters(
    const QuasiStaticGeometry& geometry, double normal_load, double mu, Variables variables, double eps_velocity,
    double eps_force, double sigma)
    : geometry_(geometry), normal_load_(normal_load), mu_(mu), eps_v_(eps_velocity), eps_f_(eps_force),
      w_(CheckedWeight(sigma, "limit-surface load")), variables_(variables) {
  CheckGeometry(geometry_);
  if (!(normal_load > 0.0) || !std::isfinite(normal_load)) {
    throw GraphError("limit-surface load factor: the normal load m g must be > 0");
  }
  if (!variables.mu && (!(mu > 0.0) || !std::isfinite(mu))) throw GraphError("limit-surface load factor: mu must be > 0");
  CheckEps(eps_v_, eps_f_, "limit-surface load");
  set_num_residuals(1);
  for (int size : {3, 3, 2, 2}) mutable_parameter_block_sizes()->push_back(size);
  if (variables.c) mutable_parameter_block_sizes()->push_back(1);
  if (variables.mu) mutable_parameter_block_sizes()->push_back(1);
}

bool LimitSurfaceLoadFactorWithParameters::Evaluate(double const* const* parameters, double* residuals,
                                                    double** jacobians) const {
  const int c_index = variables_.c ? 4 : -1;
  const int mu_index = variables_.mu ? (variables_.c ? 5 : 4) : -1;
  QuasiStaticGeometry geometry = geometry_;
  if (c_index >= 0) geometry.c = parameters[c_index][0];
  const double mu = mu_index >= 0 ? parameters[mu_index][0] : mu_;
  if (!(geometry.c > 0.0) || !std::isfinite(geometry.c) || !(mu > 0.0) || !std::isfinite(mu)) return false;
  double J_fmax = 0.0, J_c = 0.0;
  const bool want_c = jacobians != nullptr && c_index >= 0 && jacobians[c_index] != nullptr;
  const bool want_mu = jacobians != nullptr && mu_index >= 0 && jacobians[mu_index] != nullptr;
  if (!EvaluateLoad(geometry, mu * normal_load_, eps_v_, eps_f_, w_, OneContactTerms(geometry, parameters), residuals, jacobians,
                    want_mu ? &J_fmax : nullptr, want_c ? &J_c : nullptr)) {
    return false;
  }
  if (want_c) jacobians[c_index][0] = J_c;
  if (want_mu) jacobians[mu_index][0] = J_fmax * normal_load_;  // f_max = mu N
  return true;
}

CrossMultipliedQuasiStaticFactor::CrossMultipliedQuasiStaticFactor(
    const QuasiStaticGeometry& geometry, double sigma)
    : geometry_(geometry), w_(CheckedWeight(sigma, "cross-multiplied quasi-static")) {
  CheckGeometry(geometry_);
}

bool CrossMultipliedQuasiStaticFactor::Evaluate(double const* const* parameters,
                                                double* residuals, double** jacobians) const {
  const QuasiStaticTerms t = ComputeQuasiStaticTerms(
      geometry_, PoseFrom(parameters[0]), PoseFrom(parameters[1]),
      Vec2(parameters[2][0], parameters[2][1]), Vec2(parameters[3][0], parameters[3][1]));
  // v_x tau - c^2 f_x omega = c (V_x g_z - V_z g_x);  v_y tau - c^2 f_y omega = c (V_y g_z - V_z g_y).
  const double k = w_ * geometry_.c;
  Eigen::Map<Eigen::Vector2d> res(residuals);
  res << k * (t.V.x() * t.g.z() - t.V.z() * t.g.x()), k * (t.V.y() * t.g.z() - t.V.z() * t.g.y());
  if (jacobians == nullptr) return true;
  Eigen::Matrix<double, 2, 3> J_r_V, J_r_g;
  J_r_V << t.g.z(), 0.0, -t.g.x(), 0.0, t.g.z(), -t.g.y();
  J_r_g << -t.V.z(), 0.0, t.V.x(), 0.0, -t.V.z(), t.V.y();
  J_r_V *= k;
  J_r_g *= k;
  if (jacobians[0] != nullptr) Eigen::Map<RowMat23>{jacobians[0]} = J_r_V * t.J_V_xprev;
  if (jacobians[1] != nullptr) Eigen::Map<RowMat23>{jacobians[1]} = J_r_V * t.J_V_x + J_r_g * t.J_g_x;
  if (jacobians[2] != nullptr) Eigen::Map<RowMat22>{jacobians[2]} = J_r_g * t.J_g_p;
  if (jacobians[3] != nullptr) Eigen::Map<RowMat22>{jacobians[3]} = J_r_g * t.J_g_f;
  return true;
}

}  // namespace pushgraph::graph
