// The limit surface of a non-convex object with a hole under a non-uniform pressure: the
// summary numbers (f_max, tau_max, c), the load that keeps the object sliding with a given twist,
// the inverse (the twist a load produces), and how far the paper's ellipsoid is from it.
//
// The object is a 100 x 60 mm plate with a 30 x 20 mm notch cut into its top edge and a hexagonal
// hole; its weight rests more on the right than on the left (a tilted-plane pressure).
#include <pushgraph/geometry/shape.h>
#include <pushgraph/limit_surface/ellipsoid.h>
#include <pushgraph/limit_surface/inverse.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

namespace {

using namespace pushgraph;
using geometry::Vec2;
namespace ls = pushgraph::limit_surface;

geometry::Shape NotchedPlateWithHole() {
  geometry::Polygon plate;
  // Outline in metres, shape frame at the plate's centre; either orientation is accepted.
  plate.outer = {{-0.05, -0.03}, {0.05, -0.03}, {0.05, 0.03}, {0.01, 0.03},
                 {0.01, 0.01},   {-0.02, 0.01}, {-0.02, 0.03}, {-0.05, 0.03}};
  geometry::Ring hexagon;
  for (int k = 0; k < 6; ++k) {
    const double angle = k * M_PI / 3;
    hexagon.push_back(Vec2(0.03, -0.005) + 0.012 * Vec2(std::cos(angle), std::sin(angle)));
  }
  plate.holes.push_back(hexagon);
  return geometry::Shape::FromPolygons({plate});  // validates: throws GeometryError if invalid
}

void PrintSummary(const char* label, const ls::Summary& s) {
  std::printf("%-8s area %.4e m^2  centroid (%+.5f, %+.5f)  centre of pressure (%+.5f, %+.5f)\n", label, s.area,
              s.centroid.x(), s.centroid.y(), s.centre_of_pressure.x(), s.centre_of_pressure.y());
  std::printf("%-8s f_max = mu m g = %.6f N   tau_max = %.6e N m   c = tau_max / f_max = %.6f m\n", "", s.f_max,
              s.tau_max, s.c);
}

// A twist as a unit vector in the metric where translation and rotation compare: (vx, vy, c omega).
Eigen::Vector3d Scaled(const ls::Twist& t, double c) {
  return Eigen::Vector3d(t.vx, t.vy, c * t.omega).normalized();
}

}  // namespace

int main() {
  try {
    ls::SupportSpec spec;
    spec.region = NotchedPlateWithHole();
    spec.mass = 1.0;  // kg
    spec.mu = 0.3;
    // P(r) = 1 + 15 x (relative; MakeSupport scales it to integrate to m g): 0.25 at the left
    // edge, 1.75 at the right edge. It must be >= 0 on the region (MakeSupport checks).
    spec.pressure = ls::Pressure::Linear(1.0, {15.0, 0.0});
    const ls::Support support = ls::MakeSupport(spec);
    const ls::Summary summary = ls::Summarize(support);

    ls::SupportSpec uniform_spec = spec;
    uniform_spec.pressure = ls::Pressure::Uniform();
    std::printf("Notched 100 x 60 mm plate with a hexagonal hole, m = 1 kg, mu = 0.3\n\n");
    PrintSummary("uniform", ls::Summarize(ls::MakeSupport(uniform_spec)));
    PrintSummary("linear", summary);

    // Forward map: twists are body twists of the centre of pressure; only their direction
    // matters. The load is the force and torque (about the centre of pressure) that keeps the
    // object sliding that way; it lies on the limit surface.
    struct Case {
      const char* label;
      ls::Twist twist;
    };
    const std::vector<Case> cases = {
        {"slide +x", {1.0, 0.0, 0.0}},
        {"slide +y", {0.0, 1.0, 0.0}},
        {"spin about CoP", {0.0, 0.0, 1.0}},
        {"slide +x, turn left", {0.02, 0.0, 1.0}},  // rotation centre 2 cm to the left of the CoP
        {"diagonal, turn right", {0.03, 0.03, -0.5}},
    };
    std::printf("\n%-22s %30s  %34s  %s\n", "twist (vx, vy, omega)", "", "load (fx N, fy N, tau N m)",
                "inverse: angle to twist");
    double worst_round_trip = 0.0;
    for (const Case& c : cases) {
      double error_estimate = 0.0;
      const ls::Load load = ls::SustainingLoad(support, c.twist, &error_estimate);
      // Inverse map: which twist does this load produce? It must give back the same direction.
      const ls::InverseResult back = ls::TwistForLoad(support, load);
      const double angle = std::acos(std::min(1.0, Scaled(back.twist, summary.c).dot(Scaled(c.twist, summary.c))));
      worst_round_trip = std::max(worst_round_trip, angle);
      std::printf("%-22s (%+.3f, %+.3f, %+.3f)   (%+9.5f, %+9.5f, %+.6f)   %.1e rad (%d Newton it.)\n", c.label,
                  c.twist.vx, c.twist.vy, c.twist.omega, load.force.x(), load.force.y(), load.torque, angle,
                  back.iterations);
    }

    // A load inside the surface does not move the object: the inverse reports its ratio to the
    // surface load in the same direction (< 1: sticks, > 1: slides).
    const ls::Load gentle{{0.3, 0.2}, 0.001};
    const ls::InverseResult r = ls::TwistForLoad(support, gentle);
    std::printf("\nload (0.3 N, 0.2 N, 0.001 N m): %.3f of the surface load in its direction -> %s; "
                "scaled up to the surface it slides with twist direction (vx, vy, c omega) = (%+.3f, %+.3f, %+.3f)\n",
                r.load_ratio, r.load_ratio < 1 ? "the object stays put" : "the object slides", r.twist.vx,
                r.twist.vy, summary.c * r.twist.omega);

    // The paper's ellipsoid (semi-axes f_max, f_max, tau_max) against the exact surface.
    const ls::EllipsoidError e = ls::CompareWithExact(support, ls::PaperEllipsoid(summary));
    std::printf("paper's ellipsoid vs exact surface over %d random twists: twist direction error mean %.2f deg, "
                "max %.2f deg; |exact load| / ellipsoid radius in [%.3f, %.3f]\n",
                e.samples, e.mean_direction_error_deg, e.max_direction_error_deg, e.min_radius_ratio,
                e.max_radius_ratio);
    // This program is also a test: twist -> load -> twist must come back (to 1e-9 rad).
    if (!(worst_round_trip < 1e-9)) {
      std::fprintf(stderr, "limit_surface_nonuniform: inverse round trip off by %.3e rad\n", worst_round_trip);
      return 1;
    }
  } catch (const std::exception& e) {  // GeometryError or LimitSurfaceError, naming the bad input
    std::fprintf(stderr, "limit_surface_nonuniform: %s\n", e.what());
    return 1;
  }
  return 0;
}
