#pragma once
// The evaluation config file (`pushgraph evaluate --config`, docs/evaluation.md):
//
//   {"mesh_dir": DIR,
//    "estimator": {...graph::EstimatorConfig keys...},
//    "objects": {"ellip1": {"shape": SHAPE, "finger": SHAPE, "mass": kg, "mu_surface": mu,
//                           "mu_contact": mu}}}
//
// SHAPE is a shape file name ("ellip1.json") or a mesh {"mesh": "x.obj", "up": "z", "scale": 1};
// relative paths are relative to the config file. Unknown keys, duplicate keys, bad values:
// EvaluationError naming the file and key.
//
//   evaluation::EvaluationOptions options;
//   evaluation::LoadEvaluationConfig("eval.json", &options);
#include <pushgraph/evaluation/evaluation.h>

#include <string>

namespace pushgraph::evaluation {

/// Sets options->mesh_dir, options->estimator and options->objects from the file's keys.
void LoadEvaluationConfig(const std::string& path, EvaluationOptions* options);

}  // namespace pushgraph::evaluation
