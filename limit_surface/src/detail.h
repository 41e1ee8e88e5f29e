#pragma once
// Internal building blocks of the limit-surface module (not installed).
#include <pushgraph/limit_surface/limit_surface.h>

#include <Eigen/Core>

#include <vector>

namespace pushgraph::limit_surface::detail {

/// Gauss-Legendre rule on [0, 1] with n points (1 <= n <= kMaxGaussPoints).
inline constexpr int kMaxGaussPoints = 64;
struct GaussRule {
  std::vector<double> nodes;
  std::vector<double> weights;
};
const GaussRule& GaussLegendre01(int n);

/// Closed-form edge sums of one directed ring about q (edge_sums.cpp):
/// G = integral of |r - q| dA, Phi = integral of (r - q)/|r - q| dA (signed by orientation).
struct EdgeSums {
  double G = 0.0;
  Vec2 Phi = Vec2::Zero();
};
EdgeSums RingEdgeSums(const std::vector<Vec2>& ring, const Vec2& q);

/// Signed area and first moment (integral of r dA) of a directed ring.
struct RingMoments {
  double area = 0.0;
  Vec2 first = Vec2::Zero();
};
RingMoments MomentsOf(const std::vector<Vec2>& ring);

/// Frame of a twist with v != 0: ex = v/|v|, ey = z x ex, s = omega/|v| (far_field.cpp).
struct FarFrame {
  Vec2 ex = Vec2::UnitX();
  Vec2 ey = Vec2::UnitY();
  double s = 0.0;
};
FarFrame MakeFarFrame(const Twist& twist);

/// Sustaining load per unit mu and unit pressure at a point r (relative to the centre of
/// pressure), in the frame's axes (force_ex, force_ey, torque), with the parts that integrate
/// to zero about the centre of pressure removed (so no cancellation for distant rotation
/// centres).
Eigen::Vector3d FarFieldDensity(const FarFrame& frame, const Vec2& r);

/// Sustaining load per unit mu in the frame's axes, for each support model (far_field.cpp).
Eigen::Vector3d FarFieldLoad(const Support& support, const FarFrame& frame, double rotation_centre_distance);

/// Uniform disk of radius R, unit mu and unit normal force, rotation centre at distance d from
/// its centre (disk.cpp): |force| and torque (sign of omega > 0).
struct DiskLoad {
  double force = 0.0;
  double torque = 0.0;
};
DiskLoad UniformDiskLoad(double radius, double d);

/// Smooth-density near field: the region cut into triangles that meet at the rotation centre q,
/// adaptive in the edge parameter (smooth_near_field.cpp). Per unit mu, omega > 0.
/// Adds the estimated relative error to *error.
Eigen::Vector3d SmoothNearFieldLoad(const Support& support, const Vec2& q, double* error);

/// Integral of g(r) over a directed ring's signed triangle fan with apex `apex`, collapsed
/// (Duffy) Gauss rule with n_rho points towards the apex and points_along(edge length) along
/// each edge: exact for polynomials of degree <= 2 min(n_rho - 1, n_t) - 1.
template <class PointsAlong, class Integrand>
Eigen::Vector3d FanIntegral(const std::vector<Vec2>& ring, const Vec2& apex, int n_rho, PointsAlong&& points_along,
                            Integrand&& g) {
  const GaussRule& radial = GaussLegendre01(n_rho);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const std::size_t size = ring.size();
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2 a = ring[i] - apex;
    const Vec2 b = ring[(i + 1) % size] - apex;
    const double jacobian = a.x() * b.y() - a.y() * b.x();  // twice the signed triangle area
    if (jacobian == 0.0) continue;
    const Vec2 ab = b - a;
    const GaussRule& along = GaussLegendre01(points_along(ab.norm()));
    Eigen::Vector3d edge = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < along.nodes.size(); ++j) {
      const Vec2 w = a + along.nodes[j] * ab;
      Eigen::Vector3d ray = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < radial.nodes.size(); ++k) {
        const double rho = radial.nodes[k];
        ray += (radial.weights[k] * rho) * g(Vec2(apex + rho * w));
      }
      edge += along.weights[j] * ray;
    }
    sum += jacobian * edge;
  }
  return sum;
}

/// Fixed order in both directions.
template <class Integrand>
Eigen::Vector3d FanIntegral(const std::vector<Vec2>& ring, const Vec2& apex, int n, Integrand&& g) {
  return FanIntegral(ring, apex, n, [n](double) { return n; }, g);
}

}  // namespace pushgraph::limit_surface::detail
