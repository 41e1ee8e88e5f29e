// Limit surface of a smooth (non-uniform) pressure with the rotation centre q near or inside
// the support. The sliding direction u = z x (r - q)/|r - q| (omega > 0) jumps at q, so plain
// triangle rules converge slowly; instead every directed boundary edge a -> b closes a
// triangle (q, a, b) and r = q + rho w(t), w(t) = a - q + t (b - a), rho, t in [0, 1]
// (a collapsed, or Duffy, map). Then u depends on t only and dA = rho cross(a - q, b - a):
//   force  = sum cross * integral dt (z x w/|w|) I1(t),              I1 = integral rho P drho
//   torque = sum cross * integral dt ((q . w/|w|) I1(t) + |w| I2(t)), I2 = integral rho^2 P drho
// (r x (z x u) = r . u). The signed triangles add up to the region for any q. The rho
// integrals use Gauss-Legendre (exact for polynomial pressure); the t integrals are adaptive
// (a Gauss rule against the sum over its two halves, bisecting until the difference is below
// the tolerance), which handles edges that pass close to q.
#include "detail.h"

#include <cmath>

namespace pushgraph::limit_surface::detail {
namespace {

struct EdgeIntegrand {
  const Support& support;
  const GaussRule& radial;
  Vec2 q, a_minus_q, edge;

  Eigen::Vector3d operator()(double t) const {
    const Vec2 w = a_minus_q + t * edge;
    const double length = w.norm();
    if (length == 0.0) return Eigen::Vector3d::Zero();
    const Vec2 direction = w / length;
    double i1 = 0.0, i2 = 0.0;
    for (std::size_t k = 0; k < radial.nodes.size(); ++k) {
      const double rho = radial.nodes[k];
      const double weighted = radial.weights[k] * rho * support.density(Vec2(q + rho * w));
      i1 += weighted;
      i2 += weighted * rho;
    }
    return {-direction.y() * i1, direction.x() * i1, q.dot(direction) * i1 + length * i2};
  }
};

class AdaptiveEdgeQuadrature {
 public:
  AdaptiveEdgeQuadrature(const EdgeIntegrand& f, double torque_scale, double tolerance)
      : f_(f), torque_scale_(torque_scale), tolerance_(tolerance) {}

  Eigen::Vector3d Integrate(double* error) {
    const Eigen::Vector3d whole = Rule(0.0, 1.0);
    return Refine(0.0, 1.0, whole, 0, error);
  }

 private:
  static constexpr int kPoints = 10;
  static constexpr int kMaxDepth = 40;

  Eigen::Vector3d Rule(double lo, double hi) const {
    const GaussRule& rule = GaussLegendre01(kPoints);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < kPoints; ++i) sum += rule.weights[i] * f_(lo + (hi - lo) * rule.nodes[i]);
    return (hi - lo) * sum;
  }

  double Norm(const Eigen::Vector3d& v) const { return v.head<2>().norm() + std::abs(v.z()) / torque_scale_; }

  Eigen::Vector3d Refine(double lo, double hi, const Eigen::Vector3d& whole, int depth, double* error) {
    const double mid = 0.5 * (lo + hi);
    const Eigen::Vector3d left = Rule(lo, mid), right = Rule(mid, hi);
    const Eigen::Vector3d halves = left + right;
    const double difference = Norm(halves - whole);
    if (difference <= tolerance_ * (hi - lo) || depth >= kMaxDepth) {
      *error += difference;
      return halves;
    }
    return Refine(lo, mid, left, depth + 1, error) + Refine(mid, hi, right, depth + 1, error);
  }

  const EdgeIntegrand& f_;
  double torque_scale_, tolerance_;
};

}  // namespace

Eigen::Vector3d SmoothNearFieldLoad(const Support& support, const Vec2& q, double* error) {
  // Exact in rho for a polynomial pressure of degree p: integrand degree p + 2.
  const int radial_points = support.density_degree >= 0 ? support.density_degree / 2 + 2 : 20;
  const GaussRule& radial = GaussLegendre01(radial_points);
  std::size_t edges = 0;
  for (const WeightedRing& ring : support.rings) edges += ring.vertices.size();
  // Per unit of t on one edge; differences are in units of N (force) and N m / size (torque).
  const double tolerance = support.relative_tolerance * support.normal_force / static_cast<double>(edges);
  Eigen::Vector3d load = Eigen::Vector3d::Zero();
  double absolute_error = 0.0;
  for (const WeightedRing& ring : support.rings) {
    const std::size_t size = ring.vertices.size();
    for (std::size_t i = 0; i < size; ++i) {
      const Vec2 a = ring.vertices[i] - q;
      const Vec2 edge = ring.vertices[(i + 1) % size] - ring.vertices[i];
      const double cross = a.x() * edge.y() - a.y() * edge.x();
      if (cross == 0.0) continue;
      const EdgeIntegrand integrand{support, radial, q, a, edge};
      const double edge_tolerance = tolerance / std::abs(cross);
      AdaptiveEdgeQuadrature quadrature(integrand, support.size, edge_tolerance);
      double edge_error = 0.0;
      load += cross * quadrature.Integrate(&edge_error);
      absolute_error += std::abs(cross) * edge_error;
    }
  }
  if (error != nullptr) *error += absolute_error / support.normal_force;
  return load;
}

}  // namespace pushgraph::limit_surface::detail
