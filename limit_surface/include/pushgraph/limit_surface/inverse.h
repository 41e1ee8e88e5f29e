#pragma once
// Inverse of the limit surface map: the twist direction an applied load produces.
//
//   limit_surface::InverseResult r = limit_surface::TwistForLoad(support, {{0.3, 0.1}, 0.002});
//   // r.twist: unit twist (in the scaled metric below), r.surface_load: the load on the exact
//   // surface parallel to the query, r.load_ratio > 1: the object slides, < 1: it sticks.
//
// The exact surface is convex and its support function is the dissipated power
// h(xi) = xi . SustainingLoad(xi). The twist for a load F minimizes h on the plane xi . F = 1
// (its gradient there is parallel to F); we run damped Newton on that plane.
// Twists and loads are compared in the metric scaled by c = tau_max / f_max:
// (vx, vy, c omega) and (fx, fy, tau / c).
#include <pushgraph/limit_surface/limit_surface.h>

namespace pushgraph::limit_surface {

struct InverseResult {
  Twist twist;                 ///< (vx, vy, omega) with |(vx, vy, c omega)| = 1
  Load surface_load;           ///< SustainingLoad(twist): on the surface, parallel to the query
  double load_ratio = 0.0;     ///< |query| / |surface_load| (scaled metric)
  double angle_residual = 0.0; ///< radians between surface_load and the query (scaled metric)
  int iterations = 0;
  bool converged = false;      ///< false e.g. on a facet of a point-support surface
};

/// Throws LimitSurfaceError for a zero or non-finite load.
InverseResult TwistForLoad(const Support& support, const Load& load);

}  // namespace pushgraph::limit_surface
