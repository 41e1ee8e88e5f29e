#pragma once
// Mean object position error inside a time window (an occlusion, say), by push/scoring.h's rule:
// what the demo and the pictures report for "while the tracker was blind".
//
//   double est = evaluation::MeanObjectPositionError(traj, result, 0.55, 0.95);   // m
//   double raw = evaluation::MeanHeldRawObjectPositionError(traj, 0.55, 0.95);    // last sample held
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/trajectory.h>

namespace pushgraph::evaluation {

/// Of the estimate's states with t in [t0, t1] against the ground truth; NaN when there is none
/// (no ground truth, no state in the window).
double MeanObjectPositionError(const push::Trajectory& trajectory, const graph::EstimationResult& result, double t0,
                               double t1);

/// Of the raw object stream as a user without an estimator sees it: at every ground-truth sample
/// in [t0, t1] the last measurement at or before it (held through an occlusion); NaN when none.
double MeanHeldRawObjectPositionError(const push::Trajectory& trajectory, double t0, double t1);

}  // namespace pushgraph::evaluation
