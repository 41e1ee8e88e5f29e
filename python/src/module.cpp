// The compiled core of the `pushgraph` Python package (python/pushgraph/__init__.py wraps it).
// C++ errors become Python exceptions with the same messages: GeometryError, LimitSurfaceError
// and GraphError are ValueErrors (bad input), IoError an OSError (files).
#include "common.h"

#include <pushgraph/geometry/types.h>
#include <pushgraph/graph/factors.h>
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/limit_surface/support.h>

PYBIND11_MODULE(_pushgraph, m) {
  namespace py = pybind11;
  m.doc() = "pushgraph: geometry-exact planar contact, limit surfaces and factor-graph estimation of pushing";
  py::register_exception<pushgraph::geometry::GeometryError>(m, "GeometryError", PyExc_ValueError);
  py::register_exception<pushgraph::limit_surface::LimitSurfaceError>(m, "LimitSurfaceError", PyExc_ValueError);
  py::register_exception<pushgraph::graph::GraphError>(m, "GraphError", PyExc_ValueError);
  py::register_exception<pushgraph::io::IoError>(m, "IoError", PyExc_OSError);
  pushgraph::python::RegisterGeometry(m);
  pushgraph::python::RegisterLimitSurface(m);
  pushgraph::python::RegisterTrajectory(m);
  pushgraph::python::RegisterEstimation(m);
  pushgraph::python::RegisterEvaluation(m);
}
