#pragma once
// The limit surface of a sliding object: for every body twist, the load (force, torque) that
// must be applied to keep the object sliding with that twist quasi-statically (Lambert et al.,
// Eq. 2). The friction load on the object is its negative.
//
//   auto support = limit_surface::MakeSupport(spec);                 // see support.h
//   limit_surface::Summary s = limit_surface::Summarize(support);    // f_max, tau_max, c
//   limit_surface::Load load = limit_surface::SustainingLoad(support, {0.05, 0.0, 0.3});
//   // load.force (N), load.torque (N m about the centre of pressure), shape axes
//
// Twists are body twists of the centre of pressure: (vx, vy) the velocity of that point in the
// shape's axes, omega the angular velocity. Only the direction matters (loads are 0-homogeneous).
// Uniform pressure: exact closed forms (edge sums G, Phi of docs/limit_surface.md), a stable
// far-field integral once the rotation centre is beyond kFarFieldRatio times the support's size.
#include <pushgraph/limit_surface/support.h>

namespace pushgraph::limit_surface {

/// Rotation centres farther than this many support sizes use the far-field integral.
inline constexpr double kFarFieldRatio = 2.0;

struct Twist {
  double vx = 0.0;
  double vy = 0.0;
  double omega = 0.0;
};

struct Load {
  Vec2 force = Vec2::Zero();
  double torque = 0.0;
};

struct Summary {
  double area = 0.0;
  Vec2 centroid = Vec2::Zero();
  Vec2 centre_of_pressure = Vec2::Zero();
  double normal_force = 0.0;  ///< m g
  double f_max = 0.0;         ///< mu m g
  double tau_max = 0.0;       ///< mu * integral of |r| P dA about the centre of pressure
  double c = 0.0;             ///< tau_max / f_max (m)
};

Summary Summarize(const Support& support);

/// What the pushing models need from a region alone: its centre of pressure and
/// c = tau_max / f_max. Neither depends on mass or friction (mu m g scales f_max and tau_max
/// alike), so none is asked for. Throws LimitSurfaceError like MakeSupport for a bad region.
struct RegionGeometry {
  Vec2 centre_of_pressure = Vec2::Zero();
  double c = 0.0;  ///< m
};
RegionGeometry RegionGeometryOf(const geometry::Shape& region, const Pressure& pressure = {});

/// mu * integral of |r - centre of pressure| P dA: the torque sustaining pure rotation.
double MaxFrictionTorque(const Support& support);

/// The load that sustains `twist`, about the centre of pressure. Throws LimitSurfaceError for a
/// zero or non-finite twist. `error_estimate`, if given, receives an estimate of the relative
/// error (|force error| / (mu m g) + |torque error| / (mu m g size)); ~1e-15 for closed forms.
Load SustainingLoad(const Support& support, const Twist& twist, double* error_estimate = nullptr);

/// The friction load on the sliding object: -SustainingLoad.
Load FrictionLoad(const Support& support, const Twist& twist);

/// The same twist described at another reference point: v_to = v_from + omega z x (to - from).
Twist MoveTwist(const Twist& twist, const Vec2& from, const Vec2& to);
/// The same load with its torque taken about another point: tau_to = tau_from + (from - to) x f.
Load MoveLoad(const Load& load, const Vec2& from, const Vec2& to);

}  // namespace pushgraph::limit_surface
