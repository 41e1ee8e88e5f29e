#pragma once
// The solver's logging and options, shared by the graph module's sources (not installed).
#include <ceres/solver.h>

namespace pushgraph::graph::internal {

/// Diagnostics level from the environment, read once: PUSHGRAPH_SOLVER_LOG=1 prints every solve's
/// Ceres report and why a factor evaluation failed, =2 also the per-iteration trace; unset: 0.
int SolverLogLevel();
/// Prints the solver's full report to stderr when SolverLogLevel() >= 1.
void LogSummary(const char* what, const ceres::Solver::Summary& summary);
/// Ceres' options for the graph's solves (sparse normal Cholesky, LM).
ceres::Solver::Options SolverOptions(int max_iterations, double function_tolerance);

}  // namespace pushgraph::graph::internal
