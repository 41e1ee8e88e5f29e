// pushgraph limit-surface SHAPE.json --mass KG --mu MU [--twist VX,VY,W]... [--gravity G]
// [--ellipsoid]: f_max, tau_max, c and the applied loads that sustain the given twists
// (uniform pressure, about the centroid, in the shape's axes); docs/limit_surface.md.
#include "cli_common.h"

#include <pushgraph/limit_surface/ellipsoid.h>
#include <pushgraph/limit_surface/limit_surface.h>

#include <iostream>
#include <memory>

namespace pushgraph::cli {
namespace {

namespace ls = limit_surface;

struct LimitSurfaceOptions {
  std::string shape_path;
  double mass = 0.0;
  double mu = 0.0;
  double gravity = ls::kStandardGravity;
  std::vector<std::string> twists;
  bool ellipsoid = false;
  int samples = 4000;
};

nlohmann::json ToJson(const ls::EllipsoidError& e) {
  return {{"samples", e.samples},
          {"mean_direction_error_deg", e.mean_direction_error_deg},
          {"max_direction_error_deg", e.max_direction_error_deg},
          {"min_radius_ratio", e.min_radius_ratio},
          {"max_radius_ratio", e.max_radius_ratio}};
}

void Run(const LimitSurfaceOptions& options) {
  ls::SupportSpec spec;
  spec.region = LoadShapeArgument(options.shape_path, "SHAPE");
  WarnShapeUnits(spec.region, "SHAPE", options.shape_path);
  spec.mass = options.mass;
  spec.mu = options.mu;
  spec.gravity = options.gravity;
  const ls::Support support = ls::MakeSupport(spec);
  const ls::Summary summary = ls::Summarize(support);

  nlohmann::json out;
  out["area"] = summary.area;
  out["centroid"] = {summary.centroid.x(), summary.centroid.y()};
  out["normal_force"] = summary.normal_force;
  out["f_max"] = summary.f_max;
  out["tau_max"] = summary.tau_max;
  out["c"] = summary.c;
  out["twists"] = nlohmann::json::array();
  for (const std::string& text : options.twists) {
    const std::vector<double> v = ParseNumbers(text, 3, "--twist (VX,VY,W)");
    ls::Load load;
    try {
      load = ls::SustainingLoad(support, {v[0], v[1], v[2]});  // centroid = centre of pressure
    } catch (const ls::LimitSurfaceError& e) {
      throw CliError("--twist " + text + ": " + e.what());
    }
    out["twists"].push_back(
        {{"twist", v}, {"force", {load.force.x(), load.force.y()}}, {"torque", load.torque}});
  }
  if (options.ellipsoid) {
    if (options.samples < 6) throw CliError("--samples must be >= 6 (the fitted ellipsoid has 6 unknowns)");
    try {
      out["ellipsoid"] = {
          {"paper", ToJson(ls::CompareWithExact(support, ls::PaperEllipsoid(summary), options.samples))},
          {"fitted", ToJson(ls::CompareWithExact(support, ls::FitEllipsoid(support, options.samples, 2),
                                                 options.samples))}};
    } catch (const ls::LimitSurfaceError& e) {
      // A sliver (a triangle 1e-17 m high) has exact loads, but some twist's load is zero or its
      // ellipsoid singular: "EllipsoidTwist: the load must be finite and non-zero" said neither.
      const geometry::Box2 box = spec.region.bounds();
      const double span = std::max(box.max.x() - box.min.x(), box.max.y() - box.min.y());
      char text[320];
      std::snprintf(text, sizeof text,
                    " (the support region's area is %.3g m^2 over a span of %.3g m, %.3g of a square's: a region this "
                    "thin has a near-degenerate limit surface, which no ellipsoid fits; without --ellipsoid its exact f_max, tau_max and c are reported)",
                    summary.area, span, span > 0.0 ? summary.area / (span * span) : 0.0);
      throw CliError("--ellipsoid: " + std::string(e.what()) + text);
    }
  }
  std::cout << DumpJson(out) << "\n";
}

}  // namespace

void RegisterLimitSurface(CLI::App& app) {
  auto options = std::make_shared<LimitSurfaceOptions>();
  auto* cmd = app.add_subcommand("limit-surface", "Limit surface of a sliding shape under uniform pressure");
  cmd->add_option("SHAPE", options->shape_path, "Support region: shape JSON file (polygons with holes, or a disk) or OBJ mesh (its footprint along z)")
      ->required()
      ->transform(ReadOnceInput());
  cmd->add_option("--mass", options->mass, "Object mass in kg (> 0)")->required()->check(MassValue());
  cmd->add_option("--mu", options->mu, "Object-surface friction coefficient (> 0)")->required()->check(FrictionValue(false));
  cmd->add_option("--gravity", options->gravity, "Gravity in m/s^2 (default 9.80665)");
  cmd->add_option("--twist", options->twists,
                  "Body twist VX,VY,W of the centroid (m/s, m/s, rad/s), shape axes; repeatable")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  CLI::Option* ellipsoid = cmd->add_flag("--ellipsoid", options->ellipsoid,
                                         "Also report the direction error of the paper's ellipsoid and of a fitted one");
  // Refused without --ellipsoid, which alone reads it (it was ignored without a word).
  cmd->add_option("--samples", options->samples, "Random twists for --ellipsoid (default 4000)")->needs(ellipsoid);
  cmd->footer(
      "Prints one JSON object: area, centroid, normal_force (m g), f_max (mu m g), tau_max, c = tau_max/f_max,\n"
      "twists: [{twist: [vx, vy, w], force: [fx, fy], torque}], the load that must be applied to keep the\n"
      "object sliding with each twist (about the centroid, shape axes; friction is its negative).\n"
      "Rounded polygons and capsules are rejected; a disk (one point with a radius) is exact.");
  cmd->callback([options] { Run(*options); });
}

}  // namespace pushgraph::cli
