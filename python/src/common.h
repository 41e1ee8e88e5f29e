#pragma once
// Internal to the Python module: NumPy array checks and conversions shared by the binding files.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>  // paths: str or os.PathLike (pathlib.Path)

#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

// Every float argument of the module (a radius, a mass, mu, a resolution) refuses booleans:
// pybind11's own caster takes True as 1.0 (`Shape.disk(True)` was a disk of radius 1 m, and
// `LimitSurface(box, 1.0, True)` used mu = 1, without a word). Otherwise as pybind11's: floats,
// ints and objects with __float__ or __index__. Declared before any binding file converts a
// double (every one includes this header first).
namespace pybind11::detail {
template <>
struct type_caster<double> {
  PYBIND11_TYPE_CASTER(double, const_name("float"));
  bool load(handle src, bool convert) {
    if (!src || PyBool_Check(src.ptr())) return false;
    if (PyFloat_Check(src.ptr())) {
      value = PyFloat_AsDouble(src.ptr());
      return true;
    }
    if (!convert) return false;
    if (!PyLong_Check(src.ptr()) && IsNumpyBool(src)) return false;
    const double d = PyFloat_AsDouble(src.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      return false;
    }
    value = d;
    return true;
  }
  static handle cast(double src, return_value_policy /*policy*/, handle /*parent*/) { return PyFloat_FromDouble(src); }

 private:
  // numpy.bool_ (named numpy.bool in NumPy 2: an isinstance test, not its name) and 0-d boolean
  // arrays.
  static bool IsNumpyBool(handle src) {
    static PyObject* const bool_type = [] {
      PyObject* numpy = PyImport_ImportModule("numpy");
      PyObject* type = numpy != nullptr ? PyObject_GetAttrString(numpy, "bool_") : nullptr;  // kept for the process
      Py_XDECREF(numpy);
      if (type == nullptr) PyErr_Clear();
      return type;
    }();
    if (bool_type != nullptr) {
      const int is_bool = PyObject_IsInstance(src.ptr(), bool_type);
      if (is_bool < 0) PyErr_Clear();
      if (is_bool == 1) return true;
    }
    if (isinstance<array>(src)) return reinterpret_borrow<array>(src).dtype().kind() == 'b';
    return false;
  }
};
}  // namespace pybind11::detail

namespace pushgraph::python {

namespace py = pybind11;

/// Any array-like of numbers, converted to C-contiguous float64 (a copy only when needed).
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// A list or tuple holding a bool (at any depth): NumPy reads (True, 0, 0) as the numbers
/// (1, 0, 0), where a bool array is refused (docs/python.md: booleans are no numbers).
/// NumPy's own bools (np.True_) too. At most 32 levels deep, NumPy's own limit on dimensions (a
/// list holding itself recursed until the stack overflowed); deeper is left to NumPy's error.
inline void RefuseBooleansInSequences(const py::handle& object, const char* what, int depth = 0) {
  if (depth > 32 || (!py::isinstance<py::list>(object) && !py::isinstance<py::tuple>(object))) return;
  // Held for the process's life (a static py::object would be released after the interpreter).
  static PyObject* const numpy_bool = py::object(py::module_::import("numpy").attr("bool_")).release().ptr();
  for (const py::handle item : object) {
    if (PyBool_Check(item.ptr()) || PyObject_IsInstance(item.ptr(), numpy_bool) == 1)
      throw py::type_error(std::string(what) + ": expected real numbers, got a bool");
    RefuseBooleansInSequences(item, what, depth + 1);
  }
}

/// `a` as an (N, columns) array; a single row (columns,) is taken as N = 1 when `allow_row`.
/// Throws ValueError naming `what` and the shape it got.
/// `expected` replaces "an array of shape (N, columns)" in that message (one pose, one point).
inline Array Rows(const py::handle& object, int columns, const char* what, bool allow_row = true,
                  const char* expected = nullptr) {
  // Real numbers only: NumPy would cast complex numbers (dropping the imaginary part, a warning
  // at most), booleans and None (to NaN) without complaint.
  RefuseBooleansInSequences(object, what);
  const py::array raw = py::array::ensure(object);
  if (!raw) throw py::type_error(std::string(what) + ": expected an array of numbers");
  const char kind = raw.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw py::type_error(std::string(what) + ": expected real numbers, got an array of dtype " +
                         std::string(py::str(raw.dtype())));
  }
  Array a = Array::ensure(raw);
  if (!a) throw py::type_error(std::string(what) + ": expected an array of numbers");
  if (allow_row && a.ndim() == 1 && a.shape(0) == columns) a = a.reshape({py::ssize_t(1), py::ssize_t(columns)});
  if (a.ndim() != 2 || a.shape(1) != columns) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
    shape += a.ndim() == 1 ? ",)" : ")";
    throw py::value_error(std::string(what) + ": expected " +
                          (expected ? std::string(expected) : "an array of shape (N, " + std::to_string(columns) + ")") +
                          ", got " + shape);
  }
  return a;
}

/// A 1-D array of real numbers (times); TypeError / ValueError naming `what` otherwise.
inline Array Vector(const py::handle& object, const char* what) {
  RefuseBooleansInSequences(object, what);
  const py::array raw = py::array::ensure(object);
  if (!raw || (raw.dtype().kind() != 'f' && raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u')) {
    throw py::type_error(std::string(what) + ": expected a 1-D array of real numbers");
  }
  Array a = Array::ensure(raw);
  if (a.ndim() != 1) throw py::value_error(std::string(what) + ": expected a 1-D array, got " + std::to_string(a.ndim()) + " dimensions");
  return a;
}

/// The first entry of `a` (N, k) that is not finite, as (row, column), or (-1, -1).
inline std::pair<py::ssize_t, py::ssize_t> FirstNonFinite(const Array& a) {
  const double* d = a.data();
  const py::ssize_t n = a.shape(0), k = a.shape(1);
  for (py::ssize_t i = 0; i < n; ++i) {
    for (py::ssize_t j = 0; j < k; ++j) {
      if (!std::isfinite(d[i * k + j])) return {i, j};
    }
  }
  return {-1, -1};
}

/// ValueError naming the entry: "pose[0, 2] is nan" (a NaN theta read "pose[0] is not finite").
inline void CheckFinite(const Array& a, const char* what) {
  const auto [row, column] = FirstNonFinite(a);
  if (row < 0) return;
  const double value = a.data()[row * a.shape(1) + column];
  throw py::value_error(std::string(what) + "[" + std::to_string(row) + ", " + std::to_string(column) + "] is " +
                        (std::isnan(value) ? "nan" : value > 0 ? "inf" : "-inf") + ": every entry must be finite");
}

/// A message from C++ as a Python str, invalid UTF-8 as U+FFFD: messages quote file names and
/// a file's own bytes, which need not be UTF-8 (pybind11's strict decoding raised instead).
inline py::str Text(const std::string& text) {
  PyObject* decoded = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
  if (decoded == nullptr) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(decoded);
}

inline py::list TextList(const std::vector<std::string>& texts) {
  py::list out;
  for (const std::string& t : texts) out.append(Text(t));
  return out;
}

/// A Python UserWarning at the caller's line.
inline void WarnUser(const std::string& message) {
  py::module_::import("warnings").attr("warn")(Text(message), py::handle(PyExc_UserWarning), 1);
}

/// A new float64 array of the given shape (uninitialized).
inline py::array_t<double> NewArray(std::vector<py::ssize_t> shape) { return py::array_t<double>(shape); }

/// (x, y, theta) from a row.
inline geometry::Pose2 PoseRow(const double* r) { return {r[0], r[1], r[2]}; }

/// One pose from a sequence of three numbers (ValueError otherwise; `finite`: non-finite values
/// too, where the callee names the stream and time of one, as OnlineEstimator does).
inline geometry::Pose2 ToPose(const py::handle& object, const char* what, bool finite = true) {
  const Array a = Rows(object, 3, what, true, "one pose (x, y, theta)");
  if (a.shape(0) != 1)
    throw py::value_error(std::string(what) + ": expected one pose (x, y, theta), got " + std::to_string(a.shape(0)) +
                          " poses");
  if (finite) CheckFinite(a, what);
  return PoseRow(a.data());
}

inline geometry::Vec2 ToVec2(const py::handle& object, const char* what, bool finite = true) {
  const Array a = Rows(object, 2, what, true, "one point (x, y)");
  if (a.shape(0) != 1)
    throw py::value_error(std::string(what) + ": expected one point (x, y), got " + std::to_string(a.shape(0)) +
                          " points");
  if (finite) CheckFinite(a, what);
  return {a.data()[0], a.data()[1]};
}

void RegisterGeometry(py::module_& m);
void RegisterLimitSurface(py::module_& m);
void RegisterTrajectory(py::module_& m);
void RegisterEstimation(py::module_& m);
void RegisterEvaluation(py::module_& m);

}  // namespace pushgraph::python
