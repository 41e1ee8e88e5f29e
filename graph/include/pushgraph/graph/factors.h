#pragma once
// The factors of the pushing factor graphs (Lambert et al., "Joint inference of kinematic and
// force trajectories with visuo-tactile sensing", ICRA 2019, Sec. III) as Ceres cost functions
// with analytic Jacobians (named J_out_in, chained from the geometry module's Jacobians).
//
// Parameter blocks (plain chart coordinates, no manifold):
//   object pose x_t = (x, y, theta)   finger pose e_t = (x, y, theta)
//   contact point p_t = (x, y)        contact force f_t = (f_x, f_y), applied by the finger
//                                      to the object, world frame.
// Every residual is whitened (divided by its sigma), so the cost is 1/2 sum |r|^2.
//
//   using namespace pushgraph;
//   ceres::Problem problem;
//   double x[3] = {0, 0, 0}, e[3] = {-0.05, 0, 0}, p[2] = {-0.045, 0};
//   problem.AddResidualBlock(new graph::PoseMeasurementFactor(measured, 0.005, 0.05), nullptr, x);
//   problem.AddResidualBlock(new graph::BoundaryPointFactor(object_shape, 1e-4), nullptr, x, p);
//   problem.AddResidualBlock(new graph::BoundaryPointFactor(finger_shape, 1e-4), nullptr, e, p);
//
// Angles are chart coordinates (never wrapped by the solver); pose differences always go
// through the SE(2) logarithm of Between(), whose angle is wrapped to (-pi, pi].
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/graph/errors.h>

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include <memory>
#include <stdexcept>
#include <string>

namespace pushgraph::graph {

using geometry::Pose2;
using geometry::Vec2;

/// M for an SE(2) pose: r = W Log(Between(measured, estimate)), W = diag(1/s_t, 1/s_t, 1/s_r).
class PoseMeasurementFactor : public ceres::SizedCostFunction<3, 3> {
 public:
  PoseMeasurementFactor(const Pose2& measured, double sigma_trans, double sigma_rot);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Pose2 measured_;
  Eigen::Vector3d w_;
};

/// M for a point or a force (or a weak prior): r = (v - measured) / sigma.
class VectorMeasurementFactor : public ceres::SizedCostFunction<2, 2> {
 public:
  VectorMeasurementFactor(const Vec2& measured, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Vec2 measured_;
  double w_;
};

/// M for the net force of a finger touching the object at two points (a force sensor in the
/// finger measures the sum of its contact forces): r = (a + b - measured) / sigma.
/// Parameters: a (2), b (2).
class VectorSumMeasurementFactor : public ceres::SizedCostFunction<2, 2, 2> {
 public:
  VectorSumMeasurementFactor(const Vec2& measured, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Vec2 measured_;
  double w_;
};

/// C (paper Eq. 6) for one body: the contact point lies on the boundary of `shape` placed at
/// the pose: r = (p - G(xi(pose), p)) / sigma, G the exact closest boundary point
/// (geometry::QueryPoint). Parameters: pose (3), point (2). Used for the object (pose x_t) and
/// for the finger (pose e_t).
class BoundaryPointFactor : public ceres::SizedCostFunction<2, 3, 2> {
 public:
  BoundaryPointFactor(geometry::Shape shape, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  geometry::Shape shape_;
  double w_;
};

/// C for one of several contacts (a finger wedged in a notch touches two walls), the local
/// witness: r = (p - G_o(x, G_f(e, p))) / sigma, with G_f the finger's closest boundary point to
/// p and G_o the object's closest boundary point to that. Its zero is the touching pair of the
/// features near p: unlike "p on both boundaries" (two boundary factors), which a finger
/// slightly into one wall satisfies at either of that wall's two crossings, and unlike the
/// shape-pair witness, which is the single nearest pair (one of the two walls), each contact
/// keeps to its own wall. Parameters: object pose (3), finger pose (3), contact point (2).
class LocalWitnessFactor : public ceres::SizedCostFunction<2, 3, 3, 2> {
 public:
  LocalWitnessFactor(geometry::Shape object, geometry::Shape finger, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  geometry::Shape object_, finger_;
  double w_;
};

/// LocalWitnessFactor on one given feature of the object: an edge (a wall of a notch) or a
/// vertex (an object corner on a flat pusher's face), the feature a contact was found on
/// (geometry::FindContacts at the current estimate). q is the closest point of that feature,
/// rounded by the object's radius, to G_f(e, p): r = (p - q) / sigma. Two contacts on two walls
/// then cannot both settle on one wall where noisy contact measurements pull them together.
/// Parameters: object pose (3), finger pose (3), contact point (2).
class FeatureWitnessFactor : public ceres::SizedCostFunction<2, 3, 3, 2> {
 public:
  /// `feature`: an edge of `object` (its start vertex when `vertex`). Throws GraphError for an
  /// edge the object does not have.
  /// `overlap_end` -1 or +1, for an edge along a flat finger face (a line contact, sensed as the
  /// overlap's two end points): q is the overlap's end toward the edge's start (-1) or its end
  /// (+1), wherever G_f(e, p) is on the facing finger edge; 0: the closest point as above.
  FeatureWitnessFactor(geometry::Shape object, geometry::EdgeId feature, bool vertex, geometry::Shape finger,
                       double sigma, int overlap_end = 0);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  geometry::Shape finger_;
  Vec2 a_, b_;          ///< the edge's end points (object frame); a_ alone for a vertex
  bool vertex_, two_sided_ = false;  ///< two-sided: a segment core, rounded on both sides
  int end_ = 0;
  double radius_, w_;
};

/// M for a line contact's inner end points. A flat face across an object face broken by a notch
/// touches it at four points: the face's two ends (a step's two contacts, held at the overlap's
/// outer ends by FeatureWitnessFactor) and the notch's corners between them, which are the only
/// ones that place the object along its face. Each such row measures the other end of one
/// contact's overlap (the object edge `object_edge` against the finger edge `finger_edge`):
/// r = (q_end(x, e) - measured) / sigma, q_end the overlap's end toward the edge's start (-1) or
/// its end (+1), as in FeatureWitnessFactor. Parameters: object pose (3), finger pose (3).
class OverlapEndMeasurementFactor : public ceres::SizedCostFunction<2, 3, 3> {
 public:
  /// Throws GraphError for an edge either shape does not have, or overlap_end not -1 or +1.
  OverlapEndMeasurementFactor(const geometry::Shape& object, geometry::EdgeId object_edge, geometry::Shape finger,
                              geometry::EdgeId finger_edge, int overlap_end, const Vec2& measured, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  geometry::Shape finger_;
  geometry::EdgeId finger_edge_;
  int end_;
  Vec2 a_, b_;
  bool two_sided_ = false;
  double radius_;
  Vec2 measured_;
  double w_;
};

/// Coulomb's friction cone of one contact, one-sided (zero inside the cone): with n the object's
/// inward normal at p (geometry::QueryPoint), f_n = f.n, f_t = f.(z x n),
///   r = (max(0, -f_n), max(0, |f_t| - mu f_n)) / sigma.
/// The finger pushes, it cannot pull, and friction is at most mu times the push. With two
/// contacts only their sum is measured; the cone is what keeps their split physical (forces near
/// the walls' normals, so the torque about the finger follows from the geometry).
/// Parameters: object pose (3), contact point (2), force (2).
class FrictionConeFactor : public ceres::SizedCostFunction<2, 3, 2, 2> {
 public:
  FrictionConeFactor(geometry::Shape object, double mu, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  geometry::Shape object_;
  double mu_, w_;
};

/// C(x_t, e_t): the finger touches the object, r = signed separation / sigma (exact, from
/// geometry::ShapePairQuerier, positive apart, minus the penetration depth when overlapping).
/// Parameters: object pose (3), finger pose (3).
class TouchingFactor : public ceres::SizedCostFunction<1, 3, 3> {
 public:
  TouchingFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<const geometry::ShapePairQuerier> querier_;
  double w_;
};

/// C(p_t, x_t, e_t), well-posed form: the contact point is where the shapes meet,
///   r = (p - (object_point + finger_point) / 2) / sigma,
/// the midpoint of the exact shape-pair witnesses (closest pair when apart, deepest finger point
/// delta and its projection G_delta when overlapping; they coincide when touching). "p on the
/// finger boundary" (BoundaryPointFactor on the finger) pins p to the intersection of two
/// boundaries, which near tangency (a rounded finger touching an edge) moves like
/// sqrt(overlap): 0.1 mm of overlap lets p slide 1 mm along the edge, and Levenberg-Marquardt
/// crawls. The witness is a smooth function of both poses. Parameters: object pose (3), finger
/// pose (3), contact point (2).
class ContactWitnessFactor : public ceres::SizedCostFunction<2, 3, 3, 2> {
 public:
  ContactWitnessFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<const geometry::ShapePairQuerier> querier_;
  double w_;
};

/// S: one-sided intersection penalty r = (G_delta - delta) / sigma when the finger and the
/// object overlap (delta the deepest finger point, G_delta its projection onto the object
/// boundary), r = 0 when apart. Parameters: object pose (3), finger pose (3).
class IntersectionFactor : public ceres::SizedCostFunction<2, 3, 3> {
 public:
  IntersectionFactor(std::shared_ptr<const geometry::ShapePairQuerier> querier, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<const geometry::ShapePairQuerier> querier_;
  double w_;
};

/// V (paper Eq. 7) on three consecutive poses with unequal steps dt1 = t - t_prev,
/// dt2 = t_next - t: r = W (Log(a^-1 b) / dt1 - Log(b^-1 c) / dt2), the change of the body twist
/// (zero for a constant body twist, i.e. motion along a circular arc or a line). W holds the
/// sigmas of a velocity difference (m/s, rad/s); see ConstantVelocitySigma for the
/// white-noise-acceleration scaling with the step sizes. Parameters: a, b, c poses (3 each).
class ConstantVelocityFactor : public ceres::SizedCostFunction<3, 3, 3, 3> {
 public:
  ConstantVelocityFactor(double dt1, double dt2, double sigma_trans, double sigma_rot);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double dt1_, dt2_;
  Eigen::Vector3d w_;
};

/// Velocity-difference sigma of a white-noise-acceleration model with spectral density q
/// (units/s^2/sqrt(Hz)): sigma = q sqrt((dt1 + dt2) / 2). Keeps V rate-independent.
double ConstantVelocitySigma(double q, double dt1, double dt2);

/// Random-walk prior on a vector variable between consecutive steps (the contact force: it
/// varies continuously while pushing): r = (b - a) / (q sqrt(dt)). Parameters: a (2), b (2).
class VectorRandomWalkFactor : public ceres::SizedCostFunction<2, 2, 2> {
 public:
  VectorRandomWalkFactor(double dt, double q);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double w_;
};

/// Zero-velocity (random-walk) prior of the Yu-Rodriguez baseline on two consecutive poses:
/// r = W Log(a^-1 b), W = diag(1/s_t, 1/s_t, 1/s_r) with s = q sqrt(dt).
class RandomWalkFactor : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  RandomWalkFactor(double dt, double q_trans, double q_rot);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d w_;
};

/// What the quasi-static factors share: the object's body twist from finite differences and
/// the applied load in the object frame, both scaled to length units with the limit surface's c
/// (docs/estimation.md):
///   xi = Log(x_prev^-1 x_t) / dt = (v_x, v_y, omega)       (body twist of the frame origin)
///   V' = (v_x - omega r_y, v_y + omega r_x, c omega)          (twist of the centre of pressure r)
///   f_b = R(theta_t)^T f,  q = x_t^-1 p - r,  tau = q x f_b
///   g' = (f_b,x, f_b,y, tau / c)
/// The ellipsoidal limit surface (paper Eq. 3-4) says V' is parallel to g' (and points the
/// same way). Jacobians with respect to x_prev, x_t, p, f.
struct QuasiStaticTerms {
  Eigen::Vector3d V;  ///< V'
  Eigen::Vector3d g;  ///< g'
  Eigen::Matrix3d J_V_xprev, J_V_x;
  Eigen::Matrix3d J_g_x;
  Eigen::Matrix<double, 3, 2> J_g_p, J_g_f;
};

struct QuasiStaticGeometry {
  double c = 0.03;                                  ///< limit-surface ratio tau_max / f_max (m)
  Vec2 centre_of_pressure = Vec2::Zero();           ///< in the object frame
  double dt = 0.01;                                 ///< t - t_prev (s)
};

QuasiStaticTerms ComputeQuasiStaticTerms(const QuasiStaticGeometry& geometry, const Pose2& x_prev,
                                         const Pose2& x, const Vec2& p, const Vec2& f);

/// D, non-singular (docs/estimation.md): the normalized cross product
///   r = (V' x g') / (sqrt(|V'|^2 + eps_v^2) sqrt(|g'|^2 + eps_f^2)) / sigma,
/// about sin(angle between twist and limit-surface normal) while the object slides and is
/// pushed; no division by omega or tau (paper Eq. 8 divides by both). For pure translation its
/// third component, v_x f_y - v_y f_x, says the velocity is parallel to the force.
/// Parameters: x_prev (3), x_t (3), p_t (2), f_t (2).
class QuasiStaticFactor : public ceres::SizedCostFunction<3, 3, 3, 2, 2> {
 public:
  QuasiStaticFactor(const QuasiStaticGeometry& geometry, double eps_velocity, double eps_force,
                    double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double eps_v_, eps_f_, w_;
};

/// D with two contacts (a finger wedged in a notch, touching both walls): the load is the sum
/// of both contacts' wrenches, g' = g'(p_1, f_1) + g'(p_2, f_2) (QuasiStaticTerms of each, about
/// the same centre of pressure), and the residual is QuasiStaticFactor's normalized cross
/// product of V' and that g'. Parameters: x_prev (3), x_t (3), p_1 (2), f_1 (2), p_2 (2), f_2 (2).
class QuasiStaticTwoContactFactor : public ceres::SizedCostFunction<3, 3, 3, 2, 2, 2, 2> {
 public:
  QuasiStaticTwoContactFactor(const QuasiStaticGeometry& geometry, double eps_velocity, double eps_force,
                              double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double eps_v_, eps_f_, w_;
};

/// D with the limit-surface ratio c as a fifth parameter block (1), shared by every step, to
/// estimate c jointly with the trajectory (EstimatorConfig::estimate_c). Same residual as
/// QuasiStaticFactor; Evaluate fails (Ceres shortens the step) for c <= 0.
class QuasiStaticFactorWithC : public ceres::SizedCostFunction<3, 3, 3, 2, 2, 1> {
 public:
  QuasiStaticFactorWithC(const QuasiStaticGeometry& geometry, double eps_velocity, double eps_force,
                         double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double eps_v_, eps_f_, w_;
};

/// The load lies on the limit surface while the object slides (paper Eq. 3: H(F) = 1 for the
/// ellipsoid, |g'| = f_max = mu m g): r = s_v (|g'|_eps - f_max) / (f_max sigma), gated by
/// s_v = |V'|^2 / (|V'|^2 + eps_v^2) (about 1 while sliding, 0 at rest, where the load may lie
/// anywhere inside the surface), |g'|_eps = sqrt(|g'|^2 + eps_f^2). It fixes the force
/// magnitude that D (direction only) leaves free. Parameters as QuasiStaticFactor.
class LimitSurfaceLoadFactor : public ceres::SizedCostFunction<1, 3, 3, 2, 2> {
 public:
  LimitSurfaceLoadFactor(const QuasiStaticGeometry& geometry, double f_max, double eps_velocity,
                         double eps_force, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double f_max_, eps_v_, eps_f_, w_;
};

/// LimitSurfaceLoadFactor with two contacts: |g'| of the summed load (QuasiStaticTwoContactFactor)
/// on the surface while sliding. Parameters as QuasiStaticTwoContactFactor.
class LimitSurfaceLoadTwoContactFactor : public ceres::SizedCostFunction<1, 3, 3, 2, 2, 2, 2> {
 public:
  LimitSurfaceLoadTwoContactFactor(const QuasiStaticGeometry& geometry, double f_max, double eps_velocity,
                                   double eps_force, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double f_max_, eps_v_, eps_f_, w_;
};

/// D with any number of contacts (three fingers, or more): QuasiStaticTwoContactFactor's
/// residual with g' the sum of every contact's g'(p_k, f_k). With two contacts it is that factor.
/// Parameters: x_prev (3), x_t (3), then p_k (2), f_k (2) of each contact.
class QuasiStaticMultiContactFactor : public ceres::CostFunction {
 public:
  QuasiStaticMultiContactFactor(const QuasiStaticGeometry& geometry, int contacts, double eps_velocity,
                                double eps_force, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  int contacts_;
  double eps_v_, eps_f_, w_;
};

/// LimitSurfaceLoadFactor of the summed load of any number of contacts. Parameters as
/// QuasiStaticMultiContactFactor.
class LimitSurfaceLoadMultiContactFactor : public ceres::CostFunction {
 public:
  LimitSurfaceLoadMultiContactFactor(const QuasiStaticGeometry& geometry, int contacts, double f_max,
                                     double eps_velocity, double eps_force, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  int contacts_;
  double f_max_, eps_v_, eps_f_, w_;
};

/// The limit-surface load with shared scalar parameters as variables, for their joint
/// estimation: c (EstimatorConfig::estimate_c, the same c as QuasiStaticFactorWithC's) and/or the
/// table friction mu (estimate_mu), with f_max = mu N, N = m g the normal load. The residual is
/// LimitSurfaceLoadFactor's, written r = s_v (|g'|_eps / f_max - 1) / sigma. Parameters:
/// x_prev (3), x_t (3), p_t (2), f_t (2), then c (1) if variable, then mu (1) if variable; a
/// fixed c is geometry.c, a fixed mu the constructor's. Jacobians:
///   d r / d mu = -s_v |g'|_eps / (f_max mu sigma),
///   d r / d c through V'_z = c omega and g'_z = tau / c (as in QuasiStaticFactorWithC).
/// Evaluate fails (Ceres shortens the step) for c <= 0 or mu <= 0.
///
///   auto* load = new LimitSurfaceLoadFactorWithParameters(geometry, mass * 9.81, /*mu=*/0.3,
///       {/*c=*/true, /*mu=*/true}, eps_v, eps_f, sigma);
///   problem.AddResidualBlock(load, nullptr, {x_prev, x, p, f, c_block, mu_block});  // Ceres owns it
class LimitSurfaceLoadFactorWithParameters : public ceres::CostFunction {
 public:
  struct Variables {
    bool c = false;
    bool mu = false;
  };
  LimitSurfaceLoadFactorWithParameters(const QuasiStaticGeometry& geometry, double normal_load, double mu,
                                       Variables variables, double eps_velocity, double eps_force, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double normal_load_, mu_, eps_v_, eps_f_, w_;
  Variables variables_;
};

/// The Yu-Rodriguez 2018 cross-multiplied quasi-static factor (the baseline):
///   r = (v_x tau - c^2 f_x omega, v_y tau - c^2 f_y omega) / sigma
/// in the object frame (centre-of-pressure twist). Vanishes for any pure translation: that is
/// the baseline's known weakness. Parameters as QuasiStaticFactor.
class CrossMultipliedQuasiStaticFactor : public ceres::SizedCostFunction<2, 3, 3, 2, 2> {
 public:
  CrossMultipliedQuasiStaticFactor(const QuasiStaticGeometry& geometry, double sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  QuasiStaticGeometry geometry_;
  double w_;
};

}  // namespace pushgraph::graph
