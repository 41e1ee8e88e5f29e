// Validation and preparation of a support: region rings, pressure normalised to m g, centre
// of pressure, and the integration model (see SupportModel in support.h).
#include "detail.h"

#include <pushgraph/geometry/point_query.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace pushgraph::limit_surface {
namespace {

using detail::MomentsOf;

[[noreturn]] void Fail(const std::string& message) { throw LimitSurfaceError("support: " + message); }

std::string Number(double value) {
  std::ostringstream out;
  out.precision(17);
  out << value;
  return out.str();
}

std::string Describe(const Vec2& p) { return "(" + Number(p.x()) + ", " + Number(p.y()) + ")"; }

void CheckScalars(const SupportSpec& spec) {
  if (!std::isfinite(spec.mass) || spec.mass <= 0.0) Fail("mass must be finite and > 0, got " + Number(spec.mass));
  if (!std::isfinite(spec.mu) || spec.mu <= 0.0) Fail("mu must be finite and > 0, got " + Number(spec.mu));
  if (!std::isfinite(spec.gravity) || spec.gravity <= 0.0)
    Fail("gravity must be finite and > 0, got " + Number(spec.gravity));
  if (spec.mass > kMaxMass) Fail("mass " + Number(spec.mass) + " kg is above the supported " + Number(kMaxMass) + " kg");
  if (spec.mu > kMaxFriction) Fail("mu " + Number(spec.mu) + " is above the supported " + Number(kMaxFriction));
  if (spec.gravity > kMaxGravity) Fail("gravity " + Number(spec.gravity) + " is above the supported " + Number(kMaxGravity));
  if (!(spec.mu * spec.mass * spec.gravity >= kMinFrictionLoad))
    Fail("the friction load mu m g = " + Number(spec.mu * spec.mass * spec.gravity) + " N (mu " + Number(spec.mu) + ", mass " +
         Number(spec.mass) + " kg) is below the supported " + Number(kMinFrictionLoad) + " N");
  if (!(spec.relative_tolerance >= 1e-15 && spec.relative_tolerance <= 1e-2))
    Fail("relative_tolerance must lie in [1e-15, 1e-2]");
  if (spec.region.empty()) Fail("the region is an empty shape");
}

// Outer rings (CCW) and holes (CW) of a polygonal region, as given by the normalized Shape.
std::vector<std::vector<Vec2>> RegionRings(const geometry::Shape& region) {
  std::vector<std::vector<Vec2>> rings;
  for (const geometry::Polygon& polygon : region.polygons()) {
    rings.push_back(polygon.outer);
    for (const geometry::Ring& hole : polygon.holes) rings.push_back(hole);
  }
  return rings;
}

// Sutherland-Hodgman clip of a directed ring to the half-plane n . p <= c. Clipping a ring of
// any shape to a convex window keeps every edge-sum integral exact: the extra edges along the
// window boundary come in opposite pairs.
std::vector<Vec2> ClipHalfPlane(const std::vector<Vec2>& ring, const Vec2& n, double c) {
  std::vector<Vec2> out;
  const std::size_t size = ring.size();
  for (std::size_t i = 0; i < size; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % size];
    const double da = n.dot(a) - c, db = n.dot(b) - c;
    if (da <= 0.0) out.push_back(a);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) out.push_back(a + (da / (da - db)) * (b - a));
  }
  return out;
}

std::vector<Vec2> ClipBox(std::vector<Vec2> ring, const Vec2& lo, const Vec2& hi) {
  ring = ClipHalfPlane(ring, Vec2(1, 0), hi.x());
  ring = ClipHalfPlane(ring, Vec2(-1, 0), -lo.x());
  ring = ClipHalfPlane(ring, Vec2(0, 1), hi.y());
  return ClipHalfPlane(ring, Vec2(0, -1), -lo.y());
}

void CheckGrid(const GridPressure& grid) {
  if (grid.columns <= 0 || grid.rows <= 0) Fail("grid pressure needs columns > 0 and rows > 0");
  // The product in 64 bits: in int, 65536 x 65537 read as "expected columns * rows = 65536".
  const std::size_t expected = static_cast<std::size_t>(grid.columns) * static_cast<std::size_t>(grid.rows);
  if (grid.values.size() != expected)
    Fail("grid pressure has " + std::to_string(grid.values.size()) + " values, expected columns * rows = " +
         std::to_string(grid.columns) + " * " + std::to_string(grid.rows) + " = " + std::to_string(expected));
  if (!grid.origin.allFinite() || !grid.cell_size.allFinite() || grid.cell_size.minCoeff() <= 0.0)
    Fail("grid pressure needs a finite origin and finite cell sizes > 0");
  for (std::size_t i = 0; i < grid.values.size(); ++i)
    if (!std::isfinite(grid.values[i]) || grid.values[i] < 0.0)
      Fail("grid pressure value " + std::to_string(i) + " (column " + std::to_string(i % grid.columns) + ", row " +
           std::to_string(i / grid.columns) + ") must be finite and >= 0");
}

// Region cut into grid cells, each piece carrying its cell's relative pressure.
std::vector<WeightedRing> GridPieces(const std::vector<std::vector<Vec2>>& rings, const GridPressure& grid) {
  CheckGrid(grid);
  std::vector<WeightedRing> pieces;
  for (const std::vector<Vec2>& ring : rings) {
    Vec2 lo = ring[0], hi = ring[0];
    for (const Vec2& p : ring) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Vec2 first = ((lo - grid.origin).cwiseQuotient(grid.cell_size)).array().floor();
    const Vec2 last = ((hi - grid.origin).cwiseQuotient(grid.cell_size)).array().floor();
    for (int j = std::max(0, static_cast<int>(first.y())); j <= std::min(grid.rows - 1, static_cast<int>(last.y())); ++j) {
      for (int i = std::max(0, static_cast<int>(first.x())); i <= std::min(grid.columns - 1, static_cast<int>(last.x())); ++i) {
        const double value = grid.values[static_cast<std::size_t>(j) * grid.columns + i];
        if (value == 0.0) continue;
        const Vec2 cell_lo = grid.origin + Vec2(i, j).cwiseProduct(grid.cell_size);
        std::vector<Vec2> piece = ClipBox(ring, cell_lo, cell_lo + grid.cell_size);
        if (piece.size() >= 3 && MomentsOf(piece).area != 0.0) pieces.push_back({std::move(piece), value});
      }
    }
  }
  return pieces;
}

// Relative pressure scaled so that it integrates to m g, centre of pressure, shift to it.
void FinishPiecewiseConstant(Support& support, std::vector<WeightedRing> pieces) {
  double load = 0.0;
  Vec2 moment = Vec2::Zero();
  for (const WeightedRing& piece : pieces) {
    const detail::RingMoments m = MomentsOf(piece.vertices);
    load += piece.pressure * m.area;
    moment += piece.pressure * m.first;
  }
  if (!(load > 0.0)) Fail("the pressure is zero on the whole region");
  support.centre_of_pressure = moment / load;
  const double scale = support.normal_force / load;
  for (WeightedRing& piece : pieces) {
    piece.pressure *= scale;
    for (Vec2& p : piece.vertices) p -= support.centre_of_pressure;
  }
  support.rings = std::move(pieces);
}

std::function<double(const Vec2&)> UserDensity(const Pressure& pressure, int* degree) {
  if (pressure.kind == PressureKind::kLinear) {
    const LinearPressure linear = pressure.linear;
    if (!std::isfinite(linear.offset) || !linear.slope.allFinite()) Fail("linear pressure must be finite");
    *degree = 1;
    return [linear](const Vec2& r) { return linear.offset + linear.slope.dot(r); };
  }
  if (!pressure.function) Fail("function pressure without a function");
  *degree = -1;
  return [f = pressure.function](const Vec2& r) {
    const double value = f(r);
    if (!std::isfinite(value)) Fail("the pressure function returned " + Number(value) + " at " + Describe(r));
    return value;
  };
}

void PrepareSmooth(Support& support, const geometry::Shape& region, const std::vector<std::vector<Vec2>>& rings,
                   const Pressure& pressure) {
  int degree = -1;
  std::function<double(const Vec2&)> user = UserDensity(pressure, &degree);
  for (const std::vector<Vec2>& ring : rings)
    for (const Vec2& p : ring)
      if (user(p) < 0.0) Fail("the pressure is negative at the region vertex " + Describe(p));
  // Total and first moment with a fan rule from the centroid (exact for polynomials). Its nodes
  // inside the region also check the sign: |r|^2 - 0.001 on a 0.1 m box, >= 0 at every vertex and
  // negative at the centre, was taken (c 0.0602, where c can be at most about 0.04 on that box).
  // Nodes in holes and notches (the fan covers the convex hull; their parts cancel) are not the
  // region's: a pressure negative only there is valid.
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();
  for (const std::vector<Vec2>& ring : rings)
    moments += detail::FanIntegral(ring, support.centroid, 20, [&](const Vec2& r) -> Eigen::Vector3d {
      const double p = user(r);
      if (p < 0.0 && geometry::QueryPoint(region, r).signed_distance < 0.0)
        Fail("the pressure is negative inside the region, at " + Describe(r) + " (" + Number(p) + ")");
      return {p, p * r.x(), p * r.y()};
    });
  if (!(moments.x() > 0.0)) Fail("the pressure integrates to " + Number(moments.x()) + " (must be > 0)");
  support.centre_of_pressure = moments.tail<2>() / moments.x();
  const double scale = support.normal_force / moments.x();
  const Vec2 cop = support.centre_of_pressure;
  support.density = [user, scale, cop](const Vec2& r) { return scale * user(r + cop); };
  support.density_degree = degree;
  for (const std::vector<Vec2>& ring : rings) {
    WeightedRing shifted{ring, 0.0};
    for (Vec2& p : shifted.vertices) p -= cop;
    support.rings.push_back(std::move(shifted));
  }
}

void PreparePoints(Support& support, const std::vector<SupportPoint>& points) {
  if (points.empty()) Fail("point pressure without points");
  double total = 0.0;
  Vec2 moment = Vec2::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const SupportPoint& p = points[i];
    if (!p.position.allFinite() || !std::isfinite(p.weight) || p.weight < 0.0)
      Fail("support point " + std::to_string(i) + " needs a finite position and a finite weight >= 0");
    total += p.weight;
    moment += p.weight * p.position;
  }
  if (!(total > 0.0)) Fail("support point weights sum to zero");
  support.centre_of_pressure = moment / total;
  for (const SupportPoint& p : points)
    support.points.push_back({p.position - support.centre_of_pressure, p.weight * support.normal_force / total});
}

void PrepareDisk(Support& support, const geometry::Shape& region, const Pressure& pressure) {
  const std::vector<geometry::Polygon>& polygons = region.polygons();
  if (polygons.size() != 1 || polygons[0].outer.size() != 1)
    Fail("rounded regions are supported only as a single disk (one point with a radius); this one has radius " +
         Number(region.radius()) + " around a segment, polygon or several points: approximate it by polygons");
  support.disk_radius = region.radius();
  support.area = M_PI * support.disk_radius * support.disk_radius;
  support.centroid = polygons[0].outer[0];
  if (pressure.kind == PressureKind::kPoints) {
    support.model = SupportModel::kPoints;
    PreparePoints(support, pressure.points);
    return;
  }
  if (pressure.kind != PressureKind::kUniform)
    Fail("a disk region supports uniform or point pressure only; approximate it by a polygon for others");
  support.model = SupportModel::kDisk;
  support.centre_of_pressure = support.centroid;
  support.disk_pressure = support.normal_force / support.area;
}

void PreparePolygons(Support& support, const geometry::Shape& region, const Pressure& pressure) {
  const std::vector<std::vector<Vec2>> rings = RegionRings(region);
  Vec2 first = Vec2::Zero();
  for (const std::vector<Vec2>& ring : rings) {
    const detail::RingMoments m = MomentsOf(ring);
    support.area += m.area;
    first += m.first;
  }
  if (!(support.area > 0.0)) Fail("the region has no area");
  support.centroid = first / support.area;
  switch (pressure.kind) {
    case PressureKind::kUniform: {
      std::vector<WeightedRing> pieces;
      for (const std::vector<Vec2>& ring : rings) pieces.push_back({ring, 1.0});
      support.model = SupportModel::kPiecewiseConstant;
      FinishPiecewiseConstant(support, std::move(pieces));  // centre of pressure = centroid
      return;
    }
    case PressureKind::kGrid:
      support.model = SupportModel::kPiecewiseConstant;
      FinishPiecewiseConstant(support, GridPieces(rings, pressure.grid));
      return;
    case PressureKind::kLinear:
    case PressureKind::kFunction:
      support.model = SupportModel::kSmooth;
      PrepareSmooth(support, region, rings, pressure);
      return;
    case PressureKind::kPoints:
      support.model = SupportModel::kPoints;
      PreparePoints(support, pressure.points);
      return;
  }
}

double SupportSize(const Support& support) {
  double size = 0.0;
  for (const WeightedRing& ring : support.rings)
    for (const Vec2& p : ring.vertices) size = std::max(size, p.norm());
  for (const SupportPoint& p : support.points) size = std::max(size, p.position.norm());
  if (support.model == SupportModel::kDisk) size = support.disk_radius;
  return size;
}

}  // namespace

Pressure Pressure::Linear(double offset, const Vec2& slope) {
  Pressure p;
  p.kind = PressureKind::kLinear;
  p.linear = {offset, slope};
  return p;
}

Pressure Pressure::Function(std::function<double(const Vec2&)> density) {
  Pressure p;
  p.kind = PressureKind::kFunction;
  p.function = std::move(density);
  return p;
}

Pressure Pressure::Grid(GridPressure grid) {
  Pressure p;
  p.kind = PressureKind::kGrid;
  p.grid = std::move(grid);
  return p;
}

Pressure Pressure::Points(std::vector<SupportPoint> points) {
  Pressure p;
  p.kind = PressureKind::kPoints;
  p.points = std::move(points);
  return p;
}

Support MakeSupport(const SupportSpec& spec) {
  CheckScalars(spec);
  Support support;
  support.normal_force = spec.mass * spec.gravity;
  support.mu = spec.mu;
  support.relative_tolerance = spec.relative_tolerance;
  if (spec.region.radius() > 0.0) {
    PrepareDisk(support, spec.region, spec.pressure);
  } else {
    PreparePolygons(support, spec.region, spec.pressure);
  }
  support.size = SupportSize(support);
  if (!(support.size > 0.0)) Fail("all the support is at one point; a limit surface needs extent");
  return support;
}

}  // namespace pushgraph::limit_surface
