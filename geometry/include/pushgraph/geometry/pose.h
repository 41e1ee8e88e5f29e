#pragma once
// SE(2) poses as (x, y, theta) with analytic Jacobians.
//
// Every operation can return its Jacobians through optional output pointers, named J_out_in
// (manif / Sophus style). Jacobians are taken with respect to the plain coordinates
// (x, y, theta) of each pose, which is the parameterization the Ceres factors use, so they
// can be chained directly with the chain rule. Angles are not wrapped by Compose/Inverse
// (theta is a chart coordinate); use WrapAngle or Log where a wrapped angle is needed.
//
//   Pose2 T{0.1, 0.0, M_PI / 2};                       // shape frame -> world frame
//   Eigen::Matrix<double, 2, 3> J_p_T;
//   Vec2 p_world = Act(T, Vec2(0.01, 0.0), &J_p_T);    // also d p_world / d (x, y, theta)
#include <pushgraph/geometry/types.h>

#include <Eigen/Core>

namespace pushgraph::geometry {

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Vec2 translation() const { return {x, y}; }
  Eigen::Matrix2d rotation() const;
  Eigen::Vector3d vector() const { return {x, y, theta}; }
  static Pose2 FromVector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
};

/// Wraps an angle to (-pi, pi].
double WrapAngle(double angle);

/// a * b (apply b, then a): translation a.t + R(a) b.t, angle a.theta + b.theta.
Pose2 Compose(const Pose2& a, const Pose2& b, Eigen::Matrix3d* J_out_a = nullptr,
              Eigen::Matrix3d* J_out_b = nullptr);

/// a^-1.
Pose2 Inverse(const Pose2& a, Eigen::Matrix3d* J_out_a = nullptr);

/// a^-1 * b: the pose of b in a's frame.
Pose2 Between(const Pose2& a, const Pose2& b, Eigen::Matrix3d* J_out_a = nullptr,
              Eigen::Matrix3d* J_out_b = nullptr);

/// a * p: a point in a's frame mapped to the outer frame.
Vec2 Act(const Pose2& a, const Vec2& p, Eigen::Matrix<double, 2, 3>* J_out_a = nullptr,
         Eigen::Matrix2d* J_out_p = nullptr);

/// a^-1 * p: a point in the outer frame expressed in a's frame.
Vec2 InverseAct(const Pose2& a, const Vec2& p, Eigen::Matrix<double, 2, 3>* J_out_a = nullptr,
                Eigen::Matrix2d* J_out_p = nullptr);

/// SE(2) logarithm: tangent (rho_x, rho_y, phi) with phi = WrapAngle(theta) and
/// rho = V(phi)^-1 t (Sola, Deray, Atchuthan, "A micro Lie theory", 2018, Eq. 156-158).
Eigen::Vector3d Log(const Pose2& a, Eigen::Matrix3d* J_out_a = nullptr);

/// SE(2) exponential, the inverse of Log.
Pose2 Exp(const Eigen::Vector3d& tangent, Eigen::Matrix3d* J_out_tangent = nullptr);

}  // namespace pushgraph::geometry
