// Stable far-field limit surface (../shared/notes/limit-surface.md, "Numerical trap").
// With v != 0, s = omega/|v|, ex = v/|v|, ey = z x ex and a point r = (x, y) in that frame,
// the sliding direction is u = (1 - s y, s x) / M, M = sqrt((1 - s y)^2 + (s x)^2). Writing
// 1/M - 1 = (2 s y - s^2 |r|^2) / (M (1 + M)) and dropping integral of x P and of y P (zero
// about the centre of pressure), the sustaining load per unit mu is
//   f_ex = integral (1 - s y)/M P,   f_ey = s integral x (2 s y - s^2 |r|^2)/(M (1 + M)) P,
//   tau  = s integral [ |r|^2/M - y (2 y - s |r|^2) / (M (1 + M)) ] P,
// free of the cancellation that ruins the closed forms when the rotation centre is far away.
// The integrand is analytic on the support when |q| = 1/|s| > 3 size, so Gauss rules on a
// triangle fan from the centre of pressure (or polar rules on a disk) converge geometrically.
#include "detail.h"

#include <algorithm>
#include <cmath>

namespace pushgraph::limit_surface::detail {
namespace {

// Geometric convergence rate of Gauss rules for a singularity `ratio` support sizes away:
// a Bernstein ellipse of parameter rho = x + sqrt(x^2 - 1), x = 2 ratio - 1; error ~ rho^-2n.
int GaussPointsFor(double ratio) {
  const double x = 2.0 * std::min(ratio, 1e8) - 1.0;
  const double rho = x + std::sqrt(x * x - 1.0);
  const int n = static_cast<int>(std::ceil(17.0 / (2.0 * std::log10(rho)))) + 2;
  return std::clamp(n, 4, 24);
}

// Trapezoidal rule in the angle of a disk: error ~ ratio^-m.
int AnglePointsFor(double ratio) {
  const int m = static_cast<int>(std::ceil(17.0 / std::log10(std::min(ratio, 1e8)))) + 4;
  return std::clamp(m, 8, 64);
}

Eigen::Vector3d DiskFarField(const Support& support, const FarFrame& frame, double ratio) {
  const GaussRule& radial = GaussLegendre01(GaussPointsFor(ratio));
  const int m = AnglePointsFor(ratio);
  const double R = support.disk_radius;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int j = 0; j < m; ++j) {
    const double phi = 2.0 * M_PI * j / m;
    const Vec2 direction(std::cos(phi), std::sin(phi));
    for (std::size_t k = 0; k < radial.nodes.size(); ++k) {
      const double rho = radial.nodes[k];
      sum += (radial.weights[k] * rho) * FarFieldDensity(frame, R * rho * direction);
    }
  }
  return sum * (2.0 * M_PI / m) * R * R * support.disk_pressure;
}

}  // namespace

FarFrame MakeFarFrame(const Twist& twist) {
  const double speed = std::hypot(twist.vx, twist.vy);
  FarFrame frame;
  frame.ex = Vec2(twist.vx, twist.vy) / speed;
  frame.ey = Vec2(-frame.ex.y(), frame.ex.x());
  frame.s = twist.omega / speed;
  return frame;
}

Eigen::Vector3d FarFieldDensity(const FarFrame& frame, const Vec2& r) {
  const double s = frame.s;
  const double x = r.dot(frame.ex), y = r.dot(frame.ey);
  const double r2 = x * x + y * y;
  const double M = std::hypot(1.0 - s * y, s * x);
  if (M == 0.0) return Eigen::Vector3d::Zero();  // a support point exactly at the rotation centre
  const double inverse_m_one_plus_m = 1.0 / (M * (1.0 + M));
  return {(1.0 - s * y) / M, s * x * (2.0 * s * y - s * s * r2) * inverse_m_one_plus_m,
          s * (r2 / M - y * (2.0 * y - s * r2) * inverse_m_one_plus_m)};
}

Eigen::Vector3d FarFieldLoad(const Support& support, const FarFrame& frame, double rotation_centre_distance) {
  const double ratio = rotation_centre_distance / support.size;
  auto density = [&frame](const Vec2& r) { return FarFieldDensity(frame, r); };
  Eigen::Vector3d load = Eigen::Vector3d::Zero();
  switch (support.model) {
    case SupportModel::kDisk:
      return DiskFarField(support, frame, ratio);
    case SupportModel::kPoints:
      for (const SupportPoint& p : support.points) load += p.weight * FarFieldDensity(frame, p.position);
      return load;
    case SupportModel::kPiecewiseConstant: {
      const int n = GaussPointsFor(ratio);
      for (const WeightedRing& ring : support.rings)
        load += ring.pressure * FanIntegral(ring.vertices, Vec2::Zero(), n, density);
      return load;
    }
    case SupportModel::kSmooth: {
      const int n = GaussPointsFor(ratio) + (support.density_degree < 0 ? 8 : support.density_degree);
      auto weighted = [&](const Vec2& r) -> Eigen::Vector3d { return support.density(r) * density(r); };
      for (const WeightedRing& ring : support.rings) load += FanIntegral(ring.vertices, Vec2::Zero(), n, weighted);
      return load;
    }
  }
  return load;
}

}  // namespace pushgraph::limit_surface::detail
