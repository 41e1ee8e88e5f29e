// Sustaining load for a body twist: dispatch between the exact near field (closed forms for
// constant pressure, elliptic integrals for a disk, fan quadrature for smooth pressure, sums for
// points) and the stable far-field integral (far_field.cpp) once the rotation centre
// q = (-vy, vx)/omega lies beyond kFarFieldRatio support sizes.
// Near field, omega != 0, per unit mu: with G, Phi the edge sums about q,
//   force = sgn(omega) sum_rings p z x Phi(q),   torque = sgn(omega) sum_rings p (G(q) + q . Phi(q)).
#include "detail.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pushgraph::limit_surface {
namespace {

Vec2 CrossZ(const Vec2& v) { return {-v.y(), v.x()}; }  // z x v

// Sustaining load per unit mu for omega > 0 and rotation centre q (relative to the centre of
// pressure), for q within kFarFieldRatio sizes.
Eigen::Vector3d NearFieldLoadPositiveOmega(const Support& support, const Vec2& q, double* error) {
  Eigen::Vector3d load = Eigen::Vector3d::Zero();
  switch (support.model) {
    case SupportModel::kPiecewiseConstant:
      for (const WeightedRing& ring : support.rings) {
        const detail::EdgeSums sums = detail::RingEdgeSums(ring.vertices, q);
        load.head<2>() += ring.pressure * CrossZ(sums.Phi);
        load.z() += ring.pressure * (sums.G + q.dot(sums.Phi));
      }
      return load;
    case SupportModel::kDisk: {
      const double d = q.norm();
      const detail::DiskLoad unit = detail::UniformDiskLoad(support.disk_radius, d);
      // Phi points from q towards the centre: force = |f| z x (-q/|q|).
      if (d > 0.0) load.head<2>() = -unit.force * support.normal_force * CrossZ(q / d);
      load.z() = unit.torque * support.normal_force;
      return load;
    }
    case SupportModel::kSmooth:
      return detail::SmoothNearFieldLoad(support, q, error);
    case SupportModel::kPoints:
      for (const SupportPoint& p : support.points) {
        const Vec2 r = p.position - q;  // velocity direction z x (r - q)
        const double distance = r.norm();
        if (distance == 0.0) continue;  // a point at the rotation centre carries no friction
        const Vec2 u = CrossZ(r) / distance;
        load.head<2>() += p.weight * u;
        load.z() += p.weight * (p.position.x() * u.y() - p.position.y() * u.x());
      }
      return load;
  }
  return load;
}

void CheckTwist(const Twist& twist) {
  if (!std::isfinite(twist.vx) || !std::isfinite(twist.vy) || !std::isfinite(twist.omega)) {
    std::ostringstream out;
    out << "twist must be finite, got (" << twist.vx << ", " << twist.vy << ", " << twist.omega << ")";
    throw LimitSurfaceError(out.str());
  }
  if (twist.vx == 0.0 && twist.vy == 0.0 && twist.omega == 0.0)
    throw LimitSurfaceError("twist is zero: a sliding load needs a non-zero twist");
}

// A Support is made by MakeSupport; a default-constructed one (no region, no load) gave c = NaN
// and loads of zero without a word.
void CheckSupport(const Support& support) {
  bool prepared = std::isfinite(support.normal_force) && support.normal_force > 0.0 && std::isfinite(support.mu) &&
                  support.mu > 0.0;
  switch (support.model) {
    case SupportModel::kPiecewiseConstant: prepared = prepared && !support.rings.empty(); break;
    case SupportModel::kSmooth: prepared = prepared && !support.rings.empty() && static_cast<bool>(support.density); break;
    case SupportModel::kDisk: prepared = prepared && support.disk_radius > 0.0; break;
    case SupportModel::kPoints: prepared = prepared && !support.points.empty(); break;
  }
  if (!prepared) {
    throw LimitSurfaceError("support: not prepared (no region, normal force or friction: a default-constructed Support?); "
                            "make it with MakeSupport");
  }
}

}  // namespace

Load SustainingLoad(const Support& support, const Twist& raw_twist, double* error_estimate) {
  CheckSupport(support);
  CheckTwist(raw_twist);
  // Loads depend on the twist's direction only: scaling it to O(1) rules out overflow.
  const double scale = std::max({std::abs(raw_twist.vx), std::abs(raw_twist.vy), std::abs(raw_twist.omega)});
  const Twist twist{raw_twist.vx / scale, raw_twist.vy / scale, raw_twist.omega / scale};
  double error = 0.0;
  const double speed = std::hypot(twist.vx, twist.vy);
  Load load;
  if (twist.omega == 0.0) {  // translation: every point slides along v, no torque about the centre of pressure
    load.force = support.mu * support.normal_force * Vec2(twist.vx, twist.vy) / speed;
  } else if (speed > kFarFieldRatio * support.size * std::abs(twist.omega)) {
    const detail::FarFrame frame = detail::MakeFarFrame(twist);
    const double distance = speed / std::abs(twist.omega);
    const Eigen::Vector3d local = detail::FarFieldLoad(support, frame, distance);
    load.force = support.mu * (local.x() * frame.ex + local.y() * frame.ey);
    load.torque = support.mu * local.z();
  } else {
    const Vec2 q(-twist.vy / twist.omega, twist.vx / twist.omega);
    const double sign = twist.omega > 0.0 ? 1.0 : -1.0;  // reversing the twist reverses the load
    const Eigen::Vector3d local = NearFieldLoadPositiveOmega(support, q, &error);
    load.force = sign * support.mu * local.head<2>();
    load.torque = sign * support.mu * local.z();
  }
  if (error_estimate != nullptr) *error_estimate = error;
  return load;
}

Load FrictionLoad(const Support& support, const Twist& twist) {
  const Load load = SustainingLoad(support, twist);
  return {-load.force, -load.torque};
}

double MaxFrictionTorque(const Support& support) { return SustainingLoad(support, {0.0, 0.0, 1.0}).torque; }

Summary Summarize(const Support& support) {
  Summary s;
  s.area = support.area;
  s.centroid = support.centroid;
  s.centre_of_pressure = support.centre_of_pressure;
  s.normal_force = support.normal_force;
  s.f_max = support.mu * support.normal_force;
  s.tau_max = MaxFrictionTorque(support);
  s.c = s.tau_max / s.f_max;
  return s;
}

RegionGeometry RegionGeometryOf(const geometry::Shape& region, const Pressure& pressure) {
  SupportSpec spec;  // unit mass and friction: c and the centre of pressure do not depend on them
  spec.region = region;
  spec.pressure = pressure;
  spec.mass = 1.0;
  spec.mu = 1.0;
  const Summary s = Summarize(MakeSupport(spec));
  return {s.centre_of_pressure, s.c};
}

Twist MoveTwist(const Twist& twist, const Vec2& from, const Vec2& to) {
  const Vec2 v = Vec2(twist.vx, twist.vy) + twist.omega * CrossZ(to - from);
  return {v.x(), v.y(), twist.omega};
}

Load MoveLoad(const Load& load, const Vec2& from, const Vec2& to) {
  const Vec2 arm = from - to;
  return {load.force, load.torque + arm.x() * load.force.y() - arm.y() * load.force.x()};
}

}  // namespace pushgraph::limit_surface
