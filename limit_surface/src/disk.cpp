// Exact limit surface of a uniform disk (radius R, mu = N = 1), rotation centre at distance d
// from the centre, with K, E the complete elliptic integrals of modulus k
// (../shared/notes/limit-surface.md, "Exact limit surface of a uniform disk"):
//   d <= R, k = d/R: f = 4((1 + k^2) E - (1 - k^2) K) / (3 pi k),
//                    tau = (4R / (9 pi)) ((4 - 2k^2) E - (1 - k^2) K)
//   d >= R, k = R/d: f = 4((1 + k^2) E - (1 - k^2) K) / (3 pi k^2),
//                    tau = (4R / (9 pi k^3)) ((4k^2 - 2) E - (1 - k^2)(3k^2 - 2) K)
// (1 + k^2) E - (1 - k^2) K = 3k^2/2 + O(k^4) cancels for small k; there we sum its power
// series instead (from K = pi/2 sum a_n k^2n, E = pi/2 sum a_n k^2n / (1 - 2n),
// a_n = ((2n-1)!! / (2n)!!)^2).
#include "detail.h"

#include <cmath>

namespace pushgraph::limit_surface::detail {
namespace {

// (1 + k^2) E(k) - (1 - k^2) K(k).
double ForceCombination(double k) {
  const double k2 = k * k;
  if (k >= 1.0) return 2.0;  // E(1) = 1, (1 - k^2) K -> 0
  if (k < 0.5) {
    double sum = 0.0, power = k2, a_previous = 1.0, a = 0.25;  // a_0, a_1
    for (int m = 1; m < 60; ++m) {
      const double coefficient =
          a * (2.0 * m) / (1.0 - 2.0 * m) + a_previous * (4.0 - 2.0 * m) / (3.0 - 2.0 * m);
      sum += coefficient * power;
      if (std::abs(coefficient * power) < 1e-18 * std::abs(sum)) break;
      power *= k2;
      a_previous = a;
      const double ratio = (2.0 * m + 1.0) / (2.0 * m + 2.0);
      a *= ratio * ratio;
    }
    return 0.5 * M_PI * sum;
  }
  return (1.0 + k2) * std::comp_ellint_2(k) - (1.0 - k2) * std::comp_ellint_1(k);
}

}  // namespace

DiskLoad UniformDiskLoad(double radius, double d) {
  DiskLoad load;
  if (d <= radius) {
    const double k = d / radius;
    const double k2 = k * k;
    load.force = k == 0.0 ? 0.0 : 4.0 * ForceCombination(k) / (3.0 * M_PI * k);
    const double K = k < 1.0 ? std::comp_ellint_1(k) : 0.0;  // (1 - k^2) K -> 0 on the rim
    load.torque = (4.0 * radius / (9.0 * M_PI)) * ((4.0 - 2.0 * k2) * std::comp_ellint_2(k) - (1.0 - k2) * K);
  } else {
    const double k = radius / d;
    const double k2 = k * k;
    const double E = std::comp_ellint_2(k), K = std::comp_ellint_1(k);
    load.force = 4.0 * ForceCombination(k) / (3.0 * M_PI * k2);
    load.torque = (4.0 * radius / (9.0 * M_PI * k2 * k)) *
                  ((4.0 * k2 - 2.0) * E - (1.0 - k2) * (3.0 * k2 - 2.0) * K);
  }
  return load;
}

}  // namespace pushgraph::limit_surface::detail
