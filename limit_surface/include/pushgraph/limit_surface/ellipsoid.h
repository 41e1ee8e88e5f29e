#pragma once
// The ellipsoidal limit surface (Lambert et al. Eq. 3 and 4) and what it costs.
//
//   auto paper = limit_surface::PaperEllipsoid(limit_surface::Summarize(support));
//   limit_surface::Twist t = limit_surface::EllipsoidTwist(paper, load);   // Eq. 4
//   auto fitted = limit_surface::FitEllipsoid(support);                    // least squares
//   limit_surface::EllipsoidError e = limit_surface::CompareWithExact(support, paper);
//   // e.mean_direction_error_deg: ~5 degrees for a uniform disk or square
//
// An ellipsoid is {F : F^T A F = 1} with A symmetric positive definite; for a twist xi the load
// is the point whose normal A F is parallel to xi: F = A^-1 xi / sqrt(xi^T A^-1 xi).
#include <pushgraph/limit_surface/limit_surface.h>

#include <Eigen/Core>

#include <cstdint>

namespace pushgraph::limit_surface {

struct Ellipsoid {
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();  ///< acts on (fx, fy, tau)
};

/// Eq. 3: semi-axes f_max, f_max, tau_max (about the centre of pressure).
Ellipsoid PaperEllipsoid(const Summary& summary);
/// The load on the ellipsoid whose normal is the twist.
Load EllipsoidLoad(const Ellipsoid& ellipsoid, const Twist& twist);
/// Eq. 4 generalised: the twist direction (the normal A F) for a load, as a unit vector
/// (vx, vy, omega); only its direction is meaningful.
Twist EllipsoidTwist(const Ellipsoid& ellipsoid, const Load& load);

/// Least-squares fit of F^T A F = 1 to `samples` (>= 6) exact loads of random twists (seeded).
Ellipsoid FitEllipsoid(const Support& support, int samples = 2000, std::uint64_t seed = 1);

struct EllipsoidError {
  int samples = 0;
  double mean_direction_error_deg = 0.0;  ///< angle between exact and ellipsoid twists
  double max_direction_error_deg = 0.0;
  double min_radius_ratio = 0.0;          ///< |exact load| / ellipsoid radius, same direction
  double max_radius_ratio = 0.0;
};

/// For random twists xi (uniform on the sphere of (vx, vy, c omega)): the exact load F(xi), the
/// ellipsoid's twist for F, and the angle between that twist and xi in the scaled metric.
EllipsoidError CompareWithExact(const Support& support, const Ellipsoid& ellipsoid,
                                int samples = 4000, std::uint64_t seed = 1);

}  // namespace pushgraph::limit_surface
