#pragma once
// Internal to the Python module: trajectories and estimation results as dicts of NumPy arrays.
#include "common.h"

#include <pushgraph/graph/estimator.h>
#include <pushgraph/limit_surface/trajectory.h>

namespace pushgraph::python {

py::dict TrajectoryToDict(const limit_surface::Trajectory& trajectory);
/// Throws ValueError / TypeError naming the key for a malformed dict.
limit_surface::Trajectory TrajectoryFromDict(const py::handle& object);
py::dict ResultToDict(const graph::EstimationResult& result);

}  // namespace pushgraph::python
