#pragma once
// RESULT.json, the output of `pushgraph estimate` (docs/estimation.md):
//
//   {"model": "qs", "mode": "batch",
//    "states": [{"t": t, "object_pose": [x, y, theta], "finger_pose": [x, y, theta],
//                "contact": [x, y], "force": [fx, fy],
//                "object_pose_cov": [[..3..], [..], [..]], "finger_pose_cov": 3x3,
//                "contact_cov": 2x2, "force_cov": 2x2}, ...],
//    "solver": {"iterations": n, "time_s": s, "final_cost": c},
//    "metrics": {"object_position_rms": ..., ...}}
//
// `contact` only while in contact, `force` only for models with forces (qs, yu) while in
// contact, each *_cov only where the covariance was computed, `metrics` only with ground truth.
//
//   graph::EstimationResult r = graph::Estimate(traj, graph::Model::kQs, graph::Mode::kBatch);
//   evaluation::SaveResultJson(r, "RESULT.json");
#include <pushgraph/evaluation/errors.h>
#include <pushgraph/graph/estimator.h>

#include <string>

namespace pushgraph::evaluation {

std::string ResultToJson(const graph::EstimationResult& result, int indent = 1);
/// RESULT.json without its states: the solver, parameters, shape check, diagnostics, warnings
/// and metrics (what the Python result dict takes its "parameters", "shape" and "diagnostics" from).
std::string ResultSummaryJson(const graph::EstimationResult& result, int indent = -1);
/// Throws EvaluationError (trajectory_json.h) when the file cannot be written.
void SaveResultJson(const graph::EstimationResult& result, const std::string& path);

}  // namespace pushgraph::evaluation
