#pragma once
// The multi-contact tests' push: the notched block (0.5 kg, mu 0.3) and noise of 2 mm, 0.02 rad
// and 0.2 N on every stream, light enough that the contact geometry, not the noise, decides.
#include <pushgraph/geometry/shape.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>

#include <string>
#include <vector>

#include "test_scale.h"

namespace pushgraph::graph::testing {

inline push::PushPlan NotchedBlockPlan(std::uint64_t seed) {
  push::PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  plan.noise.object_pose.position.sigma = 0.002;
  plan.noise.object_pose.angle.sigma = 0.02;
  plan.noise.finger_pose.position.sigma = 0.002;
  plan.noise.contact_point.position.sigma = 0.002;
  plan.noise.force.position.sigma = 0.2;
  plan.seed = seed;
  return plan;
}

/// The graphs a multi-contact test runs: CP, SDF and QS; scaled down (the sanitizer stage) QS
/// only, the model with every factor.
inline std::vector<Model> ModelsToRun() {
  if (pushgraph::testing::TestScale() < 1.0) return {Model::kQs};
  return {Model::kCp, Model::kSdf, Model::kQs};
}

}  // namespace pushgraph::graph::testing
