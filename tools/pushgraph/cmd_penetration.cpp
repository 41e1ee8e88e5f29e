// pushgraph penetration OBJECT.json FINGER.json --object-pose X,Y,THETA --finger-pose X,Y,THETA:
// signed separation, witness points, penetration depth and separating direction as JSON.
#include "cli_common.h"

#include <pushgraph/geometry/shape_pair.h>

#include <iostream>

namespace pushgraph::cli {

void RegisterPenetration(CLI::App& app) {
  auto* cmd = app.add_subcommand("penetration", "Signed separation and penetration depth between an object and a finger");
  struct Args {
    std::string object_path, finger_path, object_pose = "0,0,0", finger_pose = "0,0,0";
    bool fast = false;
  };
  auto args = std::make_shared<Args>();
  cmd->add_option("OBJECT", args->object_path, "Object shape JSON")->required();
  cmd->add_option("FINGER", args->finger_path, "Finger shape JSON")->required();
  cmd->add_option("--object-pose", args->object_pose, "Object pose X,Y,THETA (metres, radians)")->capture_default_str();
  cmd->add_option("--finger-pose", args->finger_pose, "Finger pose X,Y,THETA (metres, radians)")->capture_default_str();
  cmd->add_flag("--fast", args->fast, "Use the vertex-sampling fast path instead of the exact C-obstacle");
  cmd->footer(
      "Prints JSON: signed_distance (> 0 apart, -depth when overlapping), intersecting, object_point and\n"
      "finger_point (world frame; when overlapping, the projection G_delta and the deepest finger point delta),\n"
      "depth (>= 0; exact, rounded fingers in concave corners, notches and holes included), depth_exact\n"
      "when overlapping (false only with --fast, an estimate) and direction (unit vector the finger moves\n"
      "along to separate; null when apart).");
  cmd->callback([args] {
    const geometry::Shape object = geometry::LoadShapeJson(args->object_path);
    const geometry::Shape finger = geometry::LoadShapeJson(args->finger_path);
    const geometry::Pose2 object_pose = ParsePose(args->object_pose, "--object-pose");
    const geometry::Pose2 finger_pose = ParsePose(args->finger_pose, "--finger-pose");
    geometry::ShapePairQuerier::Options options;
    if (args->fast) options.method = geometry::ShapePairQuerier::Method::kVertexSampling;
    const geometry::ShapePairQuerier querier(object, finger, options);
    const geometry::ShapePairResult r = querier.Query(object_pose, finger_pose);
    nlohmann::json out;
    out["signed_distance"] = r.signed_distance;
    out["intersecting"] = r.intersecting;
    out["object_point"] = {r.object_point.x(), r.object_point.y()};
    out["finger_point"] = {r.finger_point.x(), r.finger_point.y()};
    out["depth"] = r.depth;
    // false only for --fast (an estimate); rounded fingers' depths are exact (docs/geometry.md).
    if (r.intersecting) out["depth_exact"] = r.depth_exact;
    // + 0.0: no "-0.0" in the output.
    out["direction"] = r.intersecting ? nlohmann::json{r.normal.x() + 0.0, r.normal.y() + 0.0} : nlohmann::json(nullptr);
    std::cout << DumpJson(out) << "\n";
  });
}

}  // namespace pushgraph::cli
