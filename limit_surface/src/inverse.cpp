// Inverse limit surface map. The support function of the (convex) limit surface is the
// dissipated power h(xi) = xi . L(xi), L = SustainingLoad, whose gradient is L(xi) itself
// (maximum dissipation). The twist for a load F is therefore the minimizer of h on the plane
// xi . F = 1: there the gradient of h restricted to the plane, B^T L (B spans F's orthogonal
// complement), vanishes, i.e. L is parallel to F. We run damped Newton with a
// finite-difference Hessian in the metric (vx, vy, c omega) / (fx, fy, tau / c).
#include "detail.h"

#include <pushgraph/limit_surface/inverse.h>

#include <Eigen/Dense>

#include <cmath>

namespace pushgraph::limit_surface {
namespace {

class ScaledProblem {
 public:
  ScaledProblem(const Support& support, double c) : support_(support), c_(c) {}

  Twist ToTwist(const Eigen::Vector3d& xi) const { return {xi.x(), xi.y(), xi.z() / c_}; }
  Eigen::Vector3d ToScaled(const Load& load) const { return {load.force.x(), load.force.y(), load.torque / c_}; }
  Eigen::Vector3d LoadAt(const Eigen::Vector3d& xi) const { return ToScaled(SustainingLoad(support_, ToTwist(xi))); }

 private:
  const Support& support_;
  double c_;
};

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

}  // namespace

InverseResult TwistForLoad(const Support& support, const Load& load) {
  if (!load.force.allFinite() || !std::isfinite(load.torque))
    throw LimitSurfaceError("TwistForLoad: the load must be finite");
  const double c = Summarize(support).c;
  const ScaledProblem problem(support, c);
  const Eigen::Vector3d raw_target = problem.ToScaled(load);
  // Only the load's direction matters: one whose squares would leave the double range is divided
  // by its largest component first (a load of 1e155 overflowed its norm and came back "twist is
  // zero"; one of 1e-300 underflowed to "zero"). Others are used as given, bit for bit.
  const double largest = raw_target.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) throw LimitSurfaceError("TwistForLoad: the load is zero");
  if (!std::isfinite(largest)) throw LimitSurfaceError("TwistForLoad: the load is too large (its torque / c overflows)");
  const double scale = largest > 1e100 || largest < 1e-100 ? largest : 1.0;
  const Eigen::Vector3d target = raw_target / scale;
  const Eigen::Vector3d f = target.normalized();
  // Orthonormal basis B of the plane orthogonal to f.
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = f.unitOrthogonal();
  B.col(1) = f.cross(B.col(0));

  InverseResult result;
  Eigen::Vector3d xi = f;  // the ellipsoid's answer in this metric (a sphere when tau_max = c f_max)
  Eigen::Vector3d L = problem.LoadAt(xi);
  double h = xi.dot(L);
  constexpr int kMaxIterations = 60;
  constexpr double kStep = 1e-6;
  for (result.iterations = 0; result.iterations < kMaxIterations; ++result.iterations) {
    const Eigen::Vector2d gradient = B.transpose() * L;
    if (Angle(L, f) < 1e-14) break;
    Eigen::Matrix2d hessian;
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3d step = kStep * xi.norm() * B.col(i);
      hessian.col(i) = B.transpose() * (problem.LoadAt(xi + step) - problem.LoadAt(xi - step)) / (2.0 * kStep * xi.norm());
    }
    hessian = 0.5 * (hessian + hessian.transpose()).eval();
    // Levenberg-style damping keeps the step a descent direction where h is barely curved.
    const double damping = std::max(0.0, -hessian.eigenvalues().real().minCoeff()) + 1e-12 * hessian.norm();
    Eigen::Vector2d delta = -(hessian + damping * Eigen::Matrix2d::Identity()).ldlt().solve(gradient);
    bool improved = false;
    for (int halving = 0; halving < 40 && !improved; ++halving, delta *= 0.5) {
      const Eigen::Vector3d candidate = xi + B * delta;
      const Eigen::Vector3d candidate_load = problem.LoadAt(candidate);
      const double candidate_h = candidate.dot(candidate_load);
      if (candidate_h <= h || Angle(candidate_load, f) < Angle(L, f)) {
        xi = candidate;
        L = candidate_load;
        h = candidate_h;
        improved = true;
      }
    }
    if (!improved) break;
  }
  result.angle_residual = Angle(L, f);
  result.converged = result.angle_residual < 1e-9;
  const Eigen::Vector3d unit = xi.normalized();
  result.twist = problem.ToTwist(unit);
  result.surface_load = SustainingLoad(support, result.twist);
  result.load_ratio = scale * (target.norm() / problem.ToScaled(result.surface_load).norm());
  return result;
}

}  // namespace pushgraph::limit_surface
