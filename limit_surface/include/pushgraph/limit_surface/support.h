#pragma once
// The support of a sliding object: the region it rests on, how its weight m g is spread over
// that region (the pressure), and the Coulomb coefficient mu between object and surface.
//
//   using namespace pushgraph;
//   limit_surface::SupportSpec spec;
//   spec.region = geometry::Shape::Box(0.09, 0.09);   // any Shape: holes, several parts
//   spec.mass = 0.8374;                               // kg
//   spec.mu = 0.25;
//   spec.pressure = limit_surface::Pressure::Linear(1.0, {20.0, 0.0});   // default: uniform
//   limit_surface::Support support = limit_surface::MakeSupport(spec);
//   // support.centre_of_pressure, support.normal_force, ... then see limit_surface.h
//
// Pressures are relative: MakeSupport scales them so that they integrate to m g.
// Rounded shapes: a point core (a disk) is handled exactly with uniform or point pressure;
// rounded segments and rounded polygons are rejected (LimitSurfaceError says so).
#include <pushgraph/geometry/shape.h>
#include <pushgraph/geometry/types.h>
#include <pushgraph/limit_surface/errors.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pushgraph::limit_surface {

using geometry::Vec2;

/// Standard gravity, m/s^2.
inline constexpr double kStandardGravity = 9.80665;
/// The supported ranges (docs/limit_surface.md): mass in (0, kMaxMass] kg, the surface's friction
/// coefficient mu in (0, kMaxFriction] (without friction there is no limit surface), gravity in (0, kMaxGravity] m/s^2. Beyond them no pushing experiment
/// exists and products like mu m g |r| overflow or lose their meaning: refused.
inline constexpr double kMaxMass = 1e6;
inline constexpr double kMaxFriction = 10.0;
inline constexpr double kMaxGravity = 1e3;
/// The least friction load mu m g (N): smaller ones underflow in the surface's squared loads
/// (mass and mu 1e-300 each gave f_max 0 and c null without a word). Refused.
inline constexpr double kMinFrictionLoad = 1e-100;

/// P(r) = offset + slope . r, r in the shape frame (a tilted plane). Must be >= 0 on the region.
struct LinearPressure {
  double offset = 1.0;
  Vec2 slope = Vec2::Zero();
};

/// Piecewise-constant pressure on an axis-aligned grid of cells (e.g. a tactile pressure mat).
/// Cell (column i, row j) covers origin + [i, i+1) x [j, j+1) times cell_size; zero outside.
struct GridPressure {
  Vec2 origin = Vec2::Zero();
  Vec2 cell_size = Vec2::Ones();
  int columns = 0;
  int rows = 0;
  std::vector<double> values;  ///< row-major: values[j * columns + i], all >= 0
};

/// A finite support point (a leg, a felt pad) carrying a relative share `weight` of m g.
struct SupportPoint {
  Vec2 position = Vec2::Zero();
  double weight = 1.0;
};

enum class PressureKind { kUniform, kLinear, kFunction, kGrid, kPoints };

struct Pressure {
  PressureKind kind = PressureKind::kUniform;
  LinearPressure linear;
  /// Must be smooth and finite on the region's convex hull (quadrature nodes of triangles that
  /// join the rotation centre to the boundary may lie outside a non-convex region).
  std::function<double(const Vec2&)> function;
  GridPressure grid;
  std::vector<SupportPoint> points;  ///< the region is then used only for area and centroid

  static Pressure Uniform() { return {}; }
  static Pressure Linear(double offset, const Vec2& slope);
  static Pressure Function(std::function<double(const Vec2&)> density);
  static Pressure Grid(GridPressure grid);
  static Pressure Points(std::vector<SupportPoint> points);
};

struct SupportSpec {
  geometry::Shape region;
  Pressure pressure;
  double mass = 0.0;                    ///< kg, > 0
  double mu = 0.0;                      ///< object-surface Coulomb coefficient, in (0, kMaxFriction]
  double gravity = kStandardGravity;    ///< m/s^2, > 0
  double relative_tolerance = 1e-12;    ///< quadrature target (non-uniform pressures only)
};

/// How the prepared support integrates (chosen by MakeSupport from the pressure and shape).
enum class SupportModel {
  kPiecewiseConstant,  ///< rings with constant pressure each (uniform, grid): closed forms
  kSmooth,             ///< rings with a smooth density (linear, function): quadrature
  kDisk,               ///< a uniform disk: elliptic-integral closed forms
  kPoints,             ///< finite support points: sums
};

/// A directed boundary ring (outer CCW, hole CW) carrying a constant pressure.
struct WeightedRing {
  std::vector<Vec2> vertices;  ///< relative to the centre of pressure
  double pressure = 0.0;       ///< N/m^2 (kPiecewiseConstant); unused for kSmooth
};

/// A validated support, all positions in the shape frame unless stated otherwise.
struct Support {
  double area = 0.0;              ///< of the region (m^2)
  Vec2 centroid = Vec2::Zero();   ///< of the region
  Vec2 centre_of_pressure = Vec2::Zero();
  double normal_force = 0.0;      ///< m g (N)
  double mu = 0.0;
  double size = 0.0;              ///< largest distance from the centre of pressure to the support
  double relative_tolerance = 1e-12;

  SupportModel model = SupportModel::kPiecewiseConstant;
  std::vector<WeightedRing> rings;                 ///< kPiecewiseConstant, kSmooth
  std::function<double(const Vec2&)> density;      ///< kSmooth: N/m^2 at a centre-of-pressure-relative point
  int density_degree = -1;                         ///< polynomial degree of density, -1: not a polynomial
  double disk_radius = 0.0;                        ///< kDisk (centred at the centre of pressure)
  double disk_pressure = 0.0;                      ///< kDisk, N/m^2
  std::vector<SupportPoint> points;                ///< kPoints: relative positions, weights in N
};

/// Validates the spec and prepares the support; throws LimitSurfaceError on bad input.
Support MakeSupport(const SupportSpec& spec);

}  // namespace pushgraph::limit_surface
