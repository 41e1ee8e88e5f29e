// Gauss-Legendre rules on [0, 1]: nodes are roots of the Legendre polynomial P_n found by
// Newton's method from Tricomi's initial guesses (Golub & Welsch give the same rules).
#include "detail.h"

#include <array>
#include <cmath>
#include <stdexcept>

namespace pushgraph::limit_surface::detail {
namespace {

GaussRule ComputeRule(int n) {
  GaussRule rule;
  rule.nodes.resize(n);
  rule.weights.resize(n);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(M_PI * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;  // recurrence for P_n(x) and P_n'(x)
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-17) break;
    }
    const double weight = 2.0 / ((1.0 - x * x) * derivative * derivative);
    // Map [-1, 1] -> [0, 1]; store in ascending order.
    rule.nodes[i] = 0.5 * (1.0 - x);
    rule.nodes[n - 1 - i] = 0.5 * (1.0 + x);
    rule.weights[i] = rule.weights[n - 1 - i] = 0.5 * weight;
  }
  return rule;
}

}  // namespace

const GaussRule& GaussLegendre01(int n) {
  static const std::array<GaussRule, kMaxGaussPoints + 1> rules = [] {
    std::array<GaussRule, kMaxGaussPoints + 1> all;
    for (int k = 1; k <= kMaxGaussPoints; ++k) all[k] = ComputeRule(k);
    return all;
  }();
  if (n < 1 || n > kMaxGaussPoints) throw std::out_of_range("GaussLegendre01: bad number of points");
  return rules[n];
}

}  // namespace pushgraph::limit_surface::detail
