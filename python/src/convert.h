#pragma once
// Internal to the Python module: trajectories and estimation results as dicts of NumPy arrays.
#include "common.h"

#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/trajectory.h>

namespace pushgraph::python {

py::dict TrajectoryToDict(const push::Trajectory& trajectory);
/// Throws ValueError / TypeError naming the key for a malformed dict.
push::Trajectory TrajectoryFromDict(const py::handle& object);
py::dict ResultToDict(const graph::EstimationResult& result);

}  // namespace pushgraph::python
