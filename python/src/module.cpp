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

namespace {

// A C++ error as the Python exception `name`, its message decoded from UTF-8 with U+FFFD for
// invalid bytes (a file's own bytes quoted in a message): pybind11's default translation
// fails to decode those and raised the exception with no message at all.
template <class Error>
void RegisterError(pybind11::module_& m, const char* name, PyObject* base) {
  static pybind11::exception<Error> type(m, name, base);
  pybind11::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const Error& e) {
      try {
        PyErr_SetObject(type.ptr(), pushgraph::python::Text(e.what()).ptr());
      } catch (pybind11::error_already_set& decoding) {
        decoding.restore();  // out of memory: that error is raised instead
      }
    }
  });
}

}  // namespace

PYBIND11_MODULE(_pushgraph, m) {
  namespace py = pybind11;
  m.doc() = "pushgraph: geometry-exact planar contact, limit surfaces and factor-graph estimation of pushing";
  RegisterError<pushgraph::geometry::GeometryError>(m, "GeometryError", PyExc_ValueError);
  RegisterError<pushgraph::limit_surface::LimitSurfaceError>(m, "LimitSurfaceError", PyExc_ValueError);
  RegisterError<pushgraph::push::PushError>(m, "PushError", PyExc_ValueError);
  RegisterError<pushgraph::graph::GraphError>(m, "GraphError", PyExc_ValueError);
  RegisterError<pushgraph::io::IoError>(m, "IoError", PyExc_OSError);
  RegisterError<pushgraph::evaluation::EvaluationError>(m, "EvaluationError", PyExc_OSError);
  pushgraph::python::RegisterGeometry(m);
  pushgraph::python::RegisterLimitSurface(m);
  pushgraph::python::RegisterTrajectory(m);
  pushgraph::python::RegisterEstimation(m);
  pushgraph::python::RegisterEvaluation(m);
}
