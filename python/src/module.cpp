// The compiled core of the `pushgraph` Python package (python/pushgraph/__init__.py wraps it).
// C++ errors become Python exceptions with the same messages: GeometryError, LimitSurfaceError,
// PushError and GraphError are ValueErrors (bad input), IoError and EvaluationError OSErrors
// (files, folders).
#include "common.h"

#include <pushgraph/evaluation/errors.h>
#include <pushgraph/geometry/errors.h>
#include <pushgraph/graph/errors.h>
#include <pushgraph/io/errors.h>
#include <pushgraph/limit_surface/errors.h>
#include <pushgraph/push/errors.h>

PYBIND11_MODULE(_pushgraph, m) {
  namespace py = pybind11;
  m.doc() = "pushgraph: geometry-exact planar contact, limit surfaces and factor-graph estimation of pushing";
  py::register_exception<pushgraph::geometry::GeometryError>(m, "GeometryError", PyExc_ValueError);
  py::register_exception<pushgraph::limit_surface::LimitSurfaceError>(m, "LimitSurfaceError", PyExc_ValueError);
  py::register_exception<pushgraph::push::PushError>(m, "PushError", PyExc_ValueError);
  py::register_exception<pushgraph::graph::GraphError>(m, "GraphError", PyExc_ValueError);
  py::register_exception<pushgraph::io::IoError>(m, "IoError", PyExc_OSError);
  py::register_exception<pushgraph::evaluation::EvaluationError>(m, "EvaluationError", PyExc_OSError);
  pushgraph::python::RegisterGeometry(m);
  pushgraph::python::RegisterLimitSurface(m);
  pushgraph::python::RegisterTrajectory(m);
  pushgraph::python::RegisterEstimation(m);
  pushgraph::python::RegisterEvaluation(m);
}
