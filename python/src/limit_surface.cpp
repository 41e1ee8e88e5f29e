// pushgraph.LimitSurface: Coulomb friction of an object sliding on its support region (uniform
// pressure, or the support points given), loads for twists and twists for loads over arrays.
#include "common.h"

#include <pushgraph/limit_surface/ellipsoid.h>
#include <pushgraph/limit_surface/inverse.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>

namespace pushgraph::python {
namespace {

using namespace limit_surface;

struct PyLimitSurface {
  Support support;
  Summary summary;
  Ellipsoid ellipsoid;
};

// Applies `f` to every row of an (N, 3) array into a new (N, 3) array, the GIL released.
template <class F>
py::array_t<double> MapRows(const py::handle& in, const char* what, F f) {
  const Array a = Rows(in, 3, what);
  CheckFinite(a, what);
  const py::ssize_t n = a.shape(0);
  py::array_t<double> out = NewArray({n, 3});
  const double* src = a.data();
  double* dst = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      try {
        f(src + 3 * i, dst + 3 * i);
      } catch (const LimitSurfaceError& e) {
        py::gil_scoped_acquire acquire;
        throw LimitSurfaceError(std::string(what) + "[" + std::to_string(i) + "]: " + e.what());
      }
    }
  }
  return out;
}

}  // namespace

void RegisterLimitSurface(py::module_& m) {
  using namespace pybind11::literals;
  py::class_<PyLimitSurface>(m, "LimitSurface", R"doc(
The limit surface of an object of `mass` kg sliding with table friction `mu` on the support
region `shape` (uniform pressure), or on weighted support points (an (N, 3) array of x, y,
relative weight: the weights are scaled to carry the normal force mass * gravity, so only their
ratios matter). Loads are (fx, fy, tau) about the centre of pressure, twists (vx, vy, omega)
of the centre of pressure.

    ls = pushgraph.LimitSurface(pushgraph.Shape.box(0.09, 0.09), mass=0.8, mu=0.3)
    ls.summary["c"]                        # tau_max / f_max (m)
    loads = ls.sustaining_load(twists)     # (N, 3) -> (N, 3), exact
    twists = ls.twist_for_load(loads)      # (N, 3) twists (vx, vy, omega), |(vx, vy, c omega)| = 1
)doc")
      .def(py::init([](const geometry::Shape& shape, double mass, double mu, double gravity, const py::object& points) {
             SupportSpec spec;
             spec.region = shape;
             spec.mass = mass;
             spec.mu = mu;
             spec.gravity = gravity;
             if (!points.is_none()) {
               const Array p = Rows(points, 3, "points");
               CheckFinite(p, "points");
               std::vector<SupportPoint> sp(p.shape(0));
               for (py::ssize_t i = 0; i < p.shape(0); ++i) {
                 sp[i].position = Vec2(p.data()[3 * i], p.data()[3 * i + 1]);
                 sp[i].weight = p.data()[3 * i + 2];
               }
               spec.pressure = Pressure::Points(std::move(sp));
             }
             auto ls = std::make_unique<PyLimitSurface>();
             ls->support = MakeSupport(spec);
             ls->summary = Summarize(ls->support);
             ls->ellipsoid = PaperEllipsoid(ls->summary);
             return ls;
           }),
           "shape"_a, "mass"_a, "mu"_a, "gravity"_a = kStandardGravity, "points"_a = py::none())
      .def_property_readonly("summary",
                             [](const PyLimitSurface& ls) {
                               const Summary& s = ls.summary;
                               py::dict d;
                               d["area"] = s.area;
                               d["centroid"] = py::make_tuple(s.centroid.x(), s.centroid.y());
                               d["centre_of_pressure"] = py::make_tuple(s.centre_of_pressure.x(), s.centre_of_pressure.y());
                               d["normal_force"] = s.normal_force;
                               d["f_max"] = s.f_max;
                               d["tau_max"] = s.tau_max;
                               d["c"] = s.c;
                               return d;
                             })
      .def(
          "sustaining_load",
          [](const PyLimitSurface& ls, const py::handle& twists) {
            return MapRows(twists, "twists", [&](const double* t, double* out) {
              const Load l = SustainingLoad(ls.support, Twist{t[0], t[1], t[2]});
              out[0] = l.force.x();
              out[1] = l.force.y();
              out[2] = l.torque;
            });
          },
          "twists"_a, "The load sustaining each twist (N, 3) -> (N, 3), exact (closed forms or adaptive quadrature).")
      .def(
          "twist_for_load",
          [](const PyLimitSurface& ls, const py::handle& loads) {
            // Rows whose Newton solve did not converge (a facet of a point support's surface,
            // where the twist is not unique): said, as C++'s InverseResult::converged says it
            // (185 of 2000 random loads on three legs came back silently, 1.9x off in dissipation).
            std::size_t unconverged = 0, first = 0, row = 0;
            double first_residual = 0.0;
            py::array_t<double> twists = MapRows(loads, "loads", [&](const double* l, double* out) {
              const InverseResult r = TwistForLoad(ls.support, Load{Vec2(l[0], l[1]), l[2]});
              out[0] = r.twist.vx;
              out[1] = r.twist.vy;
              out[2] = r.twist.omega;
              if (!r.converged && unconverged++ == 0) first = row, first_residual = r.angle_residual;
              ++row;
            });
            if (unconverged > 0) {
              char text[400];
              std::snprintf(text, sizeof text,
                            "twist_for_load: %zu of %zu loads did not converge (the first: loads[%zu], its load %.3g rad "
                            "from the surface's): where the limit surface is not smooth (a support of points or straight "
                            "edges has flat faces and creases) the solve can stop short, and the returned twist need not "
                            "be the load's (the one of maximum dissipation)",
                            unconverged, row, first, first_residual);
              WarnUser(text);
            }
            return twists;
          },
          "loads"_a,
          "The exact surface's twist direction for each load (N, 3) -> (N, 3): (vx, vy, omega), scaled so\n"
          "that (vx, vy, c * omega) has unit length (c = summary['c']). Only the load's direction matters.")
      .def_property_readonly("ellipsoid",
                             [](const PyLimitSurface& ls) {
                               py::array_t<double> a = NewArray({3, 3});
                               for (int r = 0; r < 3; ++r)
                                 for (int c = 0; c < 3; ++c) a.mutable_data()[3 * r + c] = ls.ellipsoid.A(r, c);
                               return a;
                             },
                             "The paper's ellipsoid (Eq. 3): A acting on (fx, fy, tau).")
      .def(
          "ellipsoid_load",
          [](const PyLimitSurface& ls, const py::handle& twists) {
            return MapRows(twists, "twists", [&](const double* t, double* out) {
              const Load l = EllipsoidLoad(ls.ellipsoid, Twist{t[0], t[1], t[2]});
              out[0] = l.force.x();
              out[1] = l.force.y();
              out[2] = l.torque;
            });
          },
          "twists"_a, "The paper's ellipsoidal surface (Eq. 3) at each twist's normal: (N, 3) -> (N, 3) loads.")
      .def(
          "ellipsoid_twist",
          [](const PyLimitSurface& ls, const py::handle& loads) {
            return MapRows(loads, "loads", [&](const double* l, double* out) {
              const Twist t = EllipsoidTwist(ls.ellipsoid, Load{Vec2(l[0], l[1]), l[2]});
              out[0] = t.vx;
              out[1] = t.vy;
              out[2] = t.omega;
            });
          },
          "loads"_a,
          "The ellipsoid's twist direction for each load (Eq. 4, the surface normal): (N, 3) -> (N, 3)\n"
          "twists (vx, vy, omega) of unit length. Only the load's direction matters.")
      .def(
          "ellipsoid_error",
          [](const PyLimitSurface& ls, int samples, std::uint64_t seed) {
            EllipsoidError e;
            {
              py::gil_scoped_release release;
              e = CompareWithExact(ls.support, ls.ellipsoid, samples, seed);
            }
            py::dict d;
            d["samples"] = e.samples;
            d["mean_direction_error_deg"] = e.mean_direction_error_deg;
            d["max_direction_error_deg"] = e.max_direction_error_deg;
            d["min_radius_ratio"] = e.min_radius_ratio;
            d["max_radius_ratio"] = e.max_radius_ratio;
            return d;
          },
          "samples"_a = 4000, "seed"_a = 1, "The ellipsoid against the exact surface over random twists.");
}

}  // namespace pushgraph::python
