// Stable far-field limit surface (../shared/notes/limit-surface.md, "Numerical trap").
// With v != 0, s = omega/|v|, ex = v/|v|, ey = z x ex and a point r = (x, y) in that frame,
// the sliding direction is u = (1 - s y, s x) / M, M = sqrt((1 - s y)^2 + (s x)^2). Writing
// 1/M - 1 = (2 s y - s^2 |r|^2) / (M (1 + M)) and dropping integral of x P and of y P (zero
// about the centre of pressure), the sustaining load per unit mu is
//   f_ex = integral (1 - s y)/M P,   f_ey = s integral x (2 s y - s^2 |r|^2)/(M (1 + M)) P,
//   tau  = s integral [ |r|^2/M - y (2 y - s |r|^2) / (M (1 + M)) ] P,
// free of the cancellation that ruins the closed forms when the rotation centre is far away.
// The integrand is analytic on the support when |q| = 1/|s| > size; we use it beyond
// kFarFieldRatio = 2 sizes (where the closed form has lost ~1e-14), so Gauss rules on a
// triangle fan from the centre of pressure (or polar rules on a disk) converge geometrically.
#include "detail.h"

#include <algorithm>
#include <cmath>

namespace pushgraph::limit_surface::detail {
namespace {

// Gauss-Legendre points for 1e-17 on an interval of length h whose integrand is analytic up to
// distance `distance` beyond its ends: Bernstein ellipse rho = x + sqrt(x^2 - 1), x = 1 + 2
// distance / h, error ~ rho^-2n for a bounded integrand. Ours grow like |r|^2 on the ellipse
// (the torque density starts at s x^2) and the torque is small against them: `margin` points
// more (found against the quad-precision oracle of the tests).
int GaussPointsForDistance(double distance_over_length, int margin, int minimum) {
  const double x = 1.0 + 2.0 * std::min(distance_over_length, 1e8);
  const double rho = x + std::sqrt(x * x - 1.0);
  const int n = static_cast<int>(std::ceil(17.0 / (2.0 * std::log10(rho)))) + margin;
  return std::clamp(n, minimum, 24);
}

// Rays from the centre of pressure have length <= size; the singularity is ratio sizes away
// (the Jacobian rho adds a degree: one more point of margin).
int GaussPointsFor(double ratio) { return GaussPointsForDistance(ratio - 1.0, 2, 4); }

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

// The fan rule of FanIntegral specialised to FarFieldDensity with a constant pressure: in the
// frame's axes a ray r = rho w has x = rho x_w, y = rho y_w, so the inner loop is plain scalar
// arithmetic (no singularity: the rotation centre is far) that the compiler vectorises.
template <class PointsAlong>
Eigen::Vector3d ConstantPressureFan(const std::vector<Vec2>& ring, const FarFrame& frame, const GaussRule& radial,
                                    PointsAlong&& points_along) {
  const double s = frame.s;
  const std::size_t size = ring.size(), n_rho = radial.nodes.size();
  double fx = 0.0, fy = 0.0, torque = 0.0;
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2& p = ring[i];
    const Vec2& q = ring[i + 1 == size ? 0 : i + 1];
    const double ax = p.dot(frame.ex), ay = p.dot(frame.ey), bx = q.dot(frame.ex), by = q.dot(frame.ey);
    const double jacobian = ax * by - ay * bx;
    if (jacobian == 0.0) continue;
    const GaussRule& along = GaussLegendre01(points_along(std::hypot(bx - ax, by - ay)));
    double edge_fx = 0.0, edge_fy = 0.0, edge_torque = 0.0;
    for (std::size_t j = 0; j < along.nodes.size(); ++j) {
      const double xw = ax + along.nodes[j] * (bx - ax), yw = ay + along.nodes[j] * (by - ay);
      const double r2w = xw * xw + yw * yw;
      double ray_fx = 0.0, ray_fy = 0.0, ray_torque = 0.0;
      for (std::size_t k = 0; k < n_rho; ++k) {
        const double rho = radial.nodes[k], weight = radial.weights[k] * rho;
        const double x = rho * xw, y = rho * yw, r2 = rho * rho * r2w;
        const double a = 1.0 - s * y, c = s * x;
        const double M = std::sqrt(a * a + c * c);
        const double inverse_m_one_plus_m = 1.0 / (M * (1.0 + M));  // one division for both
        const double inverse_m = (1.0 + M) * inverse_m_one_plus_m;
        ray_fx += weight * a * inverse_m;
        ray_fy += weight * c * (2.0 * s * y - s * s * r2) * inverse_m_one_plus_m;
        ray_torque += weight * s * (r2 * inverse_m - y * (2.0 * y - s * r2) * inverse_m_one_plus_m);
      }
      edge_fx += along.weights[j] * ray_fx;
      edge_fy += along.weights[j] * ray_fy;
      edge_torque += along.weights[j] * ray_torque;
    }
    fx += jacobian * edge_fx;
    fy += jacobian * edge_fy;
    torque += jacobian * edge_torque;
  }
  return {fx, fy, torque};
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
  const double along = 1.0 - s * y, across = s * x;
  const double M = std::sqrt(along * along + across * across);  // O(1) here: no overflow
  if (M == 0.0) return Eigen::Vector3d::Zero();  // a support point exactly at the rotation centre
  const double inverse_m = 1.0 / M;
  const double inverse_m_one_plus_m = inverse_m / (1.0 + M);
  return {along * inverse_m, across * (2.0 * s * y - s * s * r2) * inverse_m_one_plus_m,
          s * (r2 * inverse_m - y * (2.0 * y - s * r2) * inverse_m_one_plus_m)};
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
      // Along a short edge the integrand varies little: fewer points (thin fan triangles).
      const double gap = rotation_centre_distance - support.size;
      auto along = [gap](double length) { return GaussPointsForDistance(gap / length, 2, 2); };
      const GaussRule& radial = GaussLegendre01(GaussPointsFor(ratio));
      for (const WeightedRing& ring : support.rings)
        load += ring.pressure * ConstantPressureFan(ring.vertices, frame, radial, along);
      return load;
    }
    case SupportModel::kSmooth: {
      // The pressure adds its own variation: a polynomial needs its degree more points.
      const int n = GaussPointsFor(ratio) + (support.density_degree < 0 ? 8 : support.density_degree);
      auto weighted = [&](const Vec2& r) -> Eigen::Vector3d { return support.density(r) * density(r); };
      for (const WeightedRing& ring : support.rings) load += FanIntegral(ring.vertices, Vec2::Zero(), n, weighted);
      return load;
    }
  }
  return load;
}

}  // namespace pushgraph::limit_surface::detail
