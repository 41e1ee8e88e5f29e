// Ellipsoidal limit surface (Lambert et al. Eq. 3: (fx/f_max)^2 + (fy/f_max)^2 +
// (tau/tau_max)^2 = 1; Eq. 4: the twist is the surface normal, v/omega = c^2 f/tau), a
// least-squares ellipsoid fitted to the exact surface, and the direction error of either.
#include "detail.h"

#include <pushgraph/limit_surface/ellipsoid.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

namespace pushgraph::limit_surface {
namespace {

Eigen::Vector3d AsVector(const Load& load) { return {load.force.x(), load.force.y(), load.torque}; }

// Twists uniform on the unit sphere of (vx, vy, c omega).
std::vector<Twist> SampleTwists(double c, int samples, std::uint64_t seed) {
  if (samples < 1) throw LimitSurfaceError("ellipsoid: samples must be >= 1");
  std::mt19937_64 generator(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Twist> twists;
  while (static_cast<int>(twists.size()) < samples) {
    const Eigen::Vector3d xi(normal(generator), normal(generator), normal(generator));
    if (xi.norm() < 1e-12) continue;
    const Eigen::Vector3d unit = xi.normalized();
    twists.push_back({unit.x(), unit.y(), unit.z() / c});
  }
  return twists;
}

}  // namespace

Ellipsoid PaperEllipsoid(const Summary& summary) {
  if (!(summary.f_max > 0.0) || !(summary.tau_max > 0.0))
    throw LimitSurfaceError("ellipsoid: f_max and tau_max must be > 0");
  Ellipsoid e;
  e.A = Eigen::Vector3d(1.0 / (summary.f_max * summary.f_max), 1.0 / (summary.f_max * summary.f_max),
                        1.0 / (summary.tau_max * summary.tau_max))
            .asDiagonal();
  return e;
}

// Both maps depend on their argument's direction only; it is divided by its largest component
// first, so that no square overflows or underflows (a twist of 1e154 gave a zero load, one of
// 1e-160 lost five digits).
Load EllipsoidLoad(const Ellipsoid& ellipsoid, const Twist& twist) {
  const Eigen::Vector3d raw(twist.vx, twist.vy, twist.omega);
  const double largest = raw.cwiseAbs().maxCoeff();
  if (!raw.allFinite() || largest == 0.0) throw LimitSurfaceError("EllipsoidLoad: the twist must be finite and non-zero");
  const Eigen::Vector3d xi = raw / largest;
  const Eigen::Vector3d direction = ellipsoid.A.ldlt().solve(xi);
  const Eigen::Vector3d F = direction / std::sqrt(xi.dot(direction));
  return {F.head<2>(), F.z()};
}

Twist EllipsoidTwist(const Ellipsoid& ellipsoid, const Load& load) {
  const Eigen::Vector3d raw = AsVector(load);
  const double largest = raw.cwiseAbs().maxCoeff();
  if (!raw.allFinite() || largest == 0.0) throw LimitSurfaceError("EllipsoidTwist: the load must be finite and non-zero");
  const Eigen::Vector3d xi = (ellipsoid.A * (raw / largest)).stableNormalized();
  return {xi.x(), xi.y(), xi.z()};
}

Ellipsoid FitEllipsoid(const Support& support, int samples, std::uint64_t seed) {
  if (samples < 6) throw LimitSurfaceError("FitEllipsoid: needs at least 6 samples for 6 unknowns");
  const Summary summary = Summarize(support);
  // Fit in loads scaled to the unit sphere of the paper's ellipsoid, then scale back.
  const Eigen::Vector3d scale(1.0 / summary.f_max, 1.0 / summary.f_max, 1.0 / summary.tau_max);
  const std::vector<Twist> twists = SampleTwists(summary.c, samples, seed);
  Eigen::MatrixXd design(twists.size(), 6);
  for (std::size_t i = 0; i < twists.size(); ++i) {
    const Eigen::Vector3d F = AsVector(SustainingLoad(support, twists[i])).cwiseProduct(scale);
    design.row(i) << F.x() * F.x(), F.y() * F.y(), F.z() * F.z(), 2 * F.x() * F.y(), 2 * F.x() * F.z(), 2 * F.y() * F.z();
  }
  const Eigen::VectorXd a = design.colPivHouseholderQr().solve(Eigen::VectorXd::Ones(twists.size()));
  Eigen::Matrix3d scaled;
  scaled << a(0), a(3), a(4), a(3), a(1), a(5), a(4), a(5), a(2);
  if (scaled.selfadjointView<Eigen::Lower>().eigenvalues().minCoeff() <= 0.0)
    throw LimitSurfaceError("ellipsoid: the least-squares fit is not positive definite (too few samples?)");
  Ellipsoid e;
  e.A = scale.asDiagonal() * scaled * scale.asDiagonal();
  return e;
}

EllipsoidError CompareWithExact(const Support& support, const Ellipsoid& ellipsoid, int samples, std::uint64_t seed) {
  const double c = Summarize(support).c;
  const std::vector<Twist> twists = SampleTwists(c, samples, seed);
  EllipsoidError report;
  report.samples = samples;
  report.min_radius_ratio = HUGE_VAL;
  double total_angle = 0.0;
  for (const Twist& twist : twists) {
    const Eigen::Vector3d F = AsVector(SustainingLoad(support, twist));
    const Twist predicted = EllipsoidTwist(ellipsoid, {F.head<2>(), F.z()});
    const Eigen::Vector3d exact_scaled(twist.vx, twist.vy, c * twist.omega);
    const Eigen::Vector3d predicted_scaled(predicted.vx, predicted.vy, c * predicted.omega);
    const double angle = std::atan2(exact_scaled.cross(predicted_scaled).norm(), exact_scaled.dot(predicted_scaled));
    total_angle += angle;
    report.max_direction_error_deg = std::max(report.max_direction_error_deg, angle * 180.0 / M_PI);
    const double ratio = std::sqrt(F.dot(ellipsoid.A * F));  // |F| / ellipsoid radius along F
    report.min_radius_ratio = std::min(report.min_radius_ratio, ratio);
    report.max_radius_ratio = std::max(report.max_radius_ratio, ratio);
  }
  report.mean_direction_error_deg = total_angle / samples * 180.0 / M_PI;
  return report;
}

}  // namespace pushgraph::limit_surface
