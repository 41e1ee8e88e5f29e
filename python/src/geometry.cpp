// pushgraph.Shape, ShapePair, DistanceField: the geometry module over NumPy arrays. Every query
// takes an (N, 2) array of points (or (N, 3) poses) and loops in C++ with the GIL released.
#include "common.h"

#include <pushgraph/geometry/distance_field.h>
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/io/footprint.h>

#include <cstdint>
#include <cstring>
#include <memory>

namespace pushgraph::python {
namespace {

using geometry::Shape;
using geometry::Vec2;

geometry::Ring ToRing(const py::handle& object, const char* what) {
  const Array a = Rows(object, 2, what, false);
  CheckFinite(a, what);
  geometry::Ring ring(a.shape(0));
  for (py::ssize_t i = 0; i < a.shape(0); ++i) ring[i] = Vec2(a.data()[2 * i], a.data()[2 * i + 1]);
  return ring;
}

py::array_t<double> FromRing(const geometry::Ring& ring) {
  py::array_t<double> out = NewArray({static_cast<py::ssize_t>(ring.size()), 2});
  double* d = out.mutable_data();
  for (std::size_t i = 0; i < ring.size(); ++i) {
    d[2 * i] = ring[i].x();
    d[2 * i + 1] = ring[i].y();
  }
  return out;
}

// A polygon from a dict {"outer": (N, 2), "holes": [(M, 2), ...]} or a bare (N, 2) outline.
geometry::Polygon ToPolygon(const py::handle& object, std::size_t index) {
  const std::string where = "polygons[" + std::to_string(index) + "]";
  geometry::Polygon p;
  if (py::isinstance<py::dict>(object)) {
    const py::dict d = py::reinterpret_borrow<py::dict>(object);
    for (const auto& item : d) {
      const std::string key = py::str(item.first);
      if (key != "outer" && key != "holes") throw py::value_error(where + ": unknown key '" + key + "' (outer, holes)");
    }
    if (!d.contains("outer")) throw py::value_error(where + ": missing 'outer'");
    p.outer = ToRing(d["outer"], (where + "['outer']").c_str());
    if (d.contains("holes")) {
      std::size_t k = 0;
      for (const py::handle h : d["holes"]) {
        p.holes.push_back(ToRing(h, (where + "['holes'][" + std::to_string(k++) + "]").c_str()));
      }
    }
  } else {
    p.outer = ToRing(object, where.c_str());
  }
  return p;
}

// [[min_x, min_y], [max_x, max_y]]
py::array_t<double> BoxArray(const geometry::Box2& b) {
  py::array_t<double> out = NewArray({2, 2});
  double* d = out.mutable_data();
  d[0] = b.min.x();
  d[1] = b.min.y();
  d[2] = b.max.x();
  d[3] = b.max.y();
  return out;
}

py::dict PolygonsOf(const Shape& shape) {
  py::list polygons;
  for (const geometry::Polygon& p : shape.polygons()) {
    py::list holes;
    for (const geometry::Ring& h : p.holes) holes.append(FromRing(h));
    py::dict d;
    d["outer"] = FromRing(p.outer);
    d["holes"] = holes;
    polygons.append(d);
  }
  py::dict out;
  out["polygons"] = polygons;
  out["radius"] = shape.radius();
  return out;
}

// Per-point results of Shape.query.
struct PointArrays {
  py::array_t<double> signed_distance, closest_point, normal, feature_t;
  py::array_t<std::int8_t> containment, feature_kind;
  py::array_t<std::int32_t> feature_polygon, feature_ring, feature_index;
  py::array_t<double> J_sd_point, J_sd_pose, J_closest_point, J_closest_pose, J_normal_point, J_normal_pose;
};

template <int R, int C>
void Put(double* out, const Eigen::Matrix<double, R, C>& m) {
  for (int r = 0; r < R; ++r) {
    for (int c = 0; c < C; ++c) out[r * C + c] = m(r, c);
  }
}

py::dict Query(const Shape& shape, const py::handle& points_in, const py::object& pose_in, bool jacobians) {
  const Array points = Rows(points_in, 2, "points");
  CheckFinite(points, "points");
  const bool posed = !pose_in.is_none();
  const geometry::Pose2 pose = posed ? ToPose(pose_in, "pose") : geometry::Pose2{};
  if (jacobians && !posed) throw py::value_error("jacobians need a pose (the derivatives are with respect to it)");
  const py::ssize_t n = points.shape(0);
  PointArrays a;
  a.signed_distance = NewArray({n});
  a.closest_point = NewArray({n, 2});
  a.normal = NewArray({n, 2});
  a.feature_t = NewArray({n});
  a.containment = py::array_t<std::int8_t>(n);
  a.feature_kind = py::array_t<std::int8_t>(n);
  a.feature_polygon = py::array_t<std::int32_t>(n);
  a.feature_ring = py::array_t<std::int32_t>(n);
  a.feature_index = py::array_t<std::int32_t>(n);
  if (jacobians) {
    a.J_sd_point = NewArray({n, 1, 2});
    a.J_sd_pose = NewArray({n, 1, 3});
    a.J_closest_point = NewArray({n, 2, 2});
    a.J_closest_pose = NewArray({n, 2, 3});
    a.J_normal_point = NewArray({n, 2, 2});
    a.J_normal_pose = NewArray({n, 2, 3});
  }
  const double* p = points.data();
  double* sd = a.signed_distance.mutable_data();
  double* cp = a.closest_point.mutable_data();
  double* nm = a.normal.mutable_data();
  double* ft = a.feature_t.mutable_data();
  std::int8_t* ct = a.containment.mutable_data();
  std::int8_t* fk = a.feature_kind.mutable_data();
  std::int32_t* fp = a.feature_polygon.mutable_data();
  std::int32_t* fr = a.feature_ring.mutable_data();
  std::int32_t* fi = a.feature_index.mutable_data();
  double* J[6] = {nullptr, nullptr, nullptr, nullptr, nullptr, nullptr};
  if (jacobians) {
    J[0] = a.J_sd_point.mutable_data();
    J[1] = a.J_sd_pose.mutable_data();
    J[2] = a.J_closest_point.mutable_data();
    J[3] = a.J_closest_pose.mutable_data();
    J[4] = a.J_normal_point.mutable_data();
    J[5] = a.J_normal_pose.mutable_data();
  }
  {
    py::gil_scoped_release release;
    geometry::PointQueryJacobians jac;
    for (py::ssize_t i = 0; i < n; ++i) {
      const Vec2 q(p[2 * i], p[2 * i + 1]);
      const geometry::PointQuery r = posed ? geometry::QueryPoint(shape, pose, q, jacobians ? &jac : nullptr)
                                           : geometry::QueryPoint(shape, q);
      sd[i] = r.signed_distance;
      cp[2 * i] = r.closest_point.x();
      cp[2 * i + 1] = r.closest_point.y();
      nm[2 * i] = r.normal.x();
      nm[2 * i + 1] = r.normal.y();
      ct[i] = static_cast<std::int8_t>(r.containment);
      fk[i] = static_cast<std::int8_t>(r.feature.kind);
      fp[i] = r.feature.edge.polygon;
      fr[i] = r.feature.edge.ring;
      fi[i] = r.feature.edge.index;
      ft[i] = r.feature.t;
      if (jacobians) {
        Put(J[0] + 2 * i, jac.J_sd_point);
        Put(J[1] + 3 * i, jac.J_sd_pose);
        Put(J[2] + 4 * i, jac.J_closest_point);
        Put(J[3] + 6 * i, jac.J_closest_pose);
        Put(J[4] + 4 * i, jac.J_normal_point);
        Put(J[5] + 6 * i, jac.J_normal_pose);
      }
    }
  }
  py::dict out;
  out["signed_distance"] = a.signed_distance;
  out["closest_point"] = a.closest_point;
  out["normal"] = a.normal;
  out["containment"] = a.containment;
  out["feature_kind"] = a.feature_kind;
  out["feature_polygon"] = a.feature_polygon;
  out["feature_ring"] = a.feature_ring;
  out["feature_index"] = a.feature_index;
  out["feature_t"] = a.feature_t;
  if (jacobians) {
    out["J_sd_point"] = a.J_sd_point;
    out["J_sd_pose"] = a.J_sd_pose;
    out["J_closest_point"] = a.J_closest_point;
    out["J_closest_pose"] = a.J_closest_pose;
    out["J_normal_point"] = a.J_normal_point;
    out["J_normal_pose"] = a.J_normal_pose;
  }
  return out;
}

py::array_t<double> SignedDistances(const Shape& shape, const py::handle& points_in) {
  const Array points = Rows(points_in, 2, "points");
  CheckFinite(points, "points");
  const py::ssize_t n = points.shape(0);
  py::array_t<double> out = NewArray({n});
  const double* p = points.data();
  double* d = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) d[i] = geometry::QueryPoint(shape, Vec2(p[2 * i], p[2 * i + 1])).signed_distance;
  }
  return out;
}

// Rows of one of two pose arrays, broadcasting a single pose over the other's rows.
struct PosePairs {
  Array a, b;
  py::ssize_t n = 0;
  geometry::Pose2 A(py::ssize_t i) const { return PoseRow(a.data() + 3 * (a.shape(0) == 1 ? 0 : i)); }
  geometry::Pose2 B(py::ssize_t i) const { return PoseRow(b.data() + 3 * (b.shape(0) == 1 ? 0 : i)); }
};

PosePairs Broadcast(const py::handle& a_in, const py::handle& b_in, const char* a_name, const char* b_name) {
  PosePairs p{Rows(a_in, 3, a_name), Rows(b_in, 3, b_name)};
  CheckFinite(p.a, a_name);
  CheckFinite(p.b, b_name);
  const py::ssize_t na = p.a.shape(0), nb = p.b.shape(0);
  if (na != nb && na != 1 && nb != 1) {
    throw py::value_error(std::string(a_name) + " and " + b_name + ": " + std::to_string(na) + " and " +
                          std::to_string(nb) + " rows (equal, or one of them 1)");
  }
  // NumPy's rule: one row beside none is none (it was one row, read from the empty array's
  // missing memory).
  p.n = na == 0 || nb == 0 ? 0 : std::max(na, nb);
  return p;
}

py::dict PairQuery(const geometry::ShapePairQuerier& querier, const py::handle& object_poses, const py::handle& finger_poses,
                   bool jacobians) {
  const PosePairs poses = Broadcast(object_poses, finger_poses, "object_poses", "finger_poses");
  const py::ssize_t n = poses.n;
  py::array_t<double> sd = NewArray({n}), depth = NewArray({n}), op = NewArray({n, 2}), fp = NewArray({n, 2}),
                      normal = NewArray({n, 2});
  py::array_t<bool> intersecting(n), exact(n);
  py::array_t<double> J[6];
  const std::vector<py::ssize_t> shapes[6] = {{n, 1, 3}, {n, 1, 3}, {n, 2, 3}, {n, 2, 3}, {n, 2, 3}, {n, 2, 3}};
  if (jacobians) {
    for (int k = 0; k < 6; ++k) J[k] = NewArray(shapes[k]);
  }
  double* out_sd = sd.mutable_data();
  double* out_depth = depth.mutable_data();
  double* out_op = op.mutable_data();
  double* out_fp = fp.mutable_data();
  double* out_n = normal.mutable_data();
  bool* out_i = intersecting.mutable_data();
  bool* out_e = exact.mutable_data();
  double* out_J[6] = {};
  if (jacobians) {
    for (int k = 0; k < 6; ++k) out_J[k] = J[k].mutable_data();
  }
  {
    py::gil_scoped_release release;
    geometry::ShapePairJacobians jac;
    for (py::ssize_t i = 0; i < n; ++i) {
      const geometry::ShapePairResult r = querier.Query(poses.A(i), poses.B(i), jacobians ? &jac : nullptr);
      out_sd[i] = r.signed_distance;
      out_depth[i] = r.depth;
      out_op[2 * i] = r.object_point.x();
      out_op[2 * i + 1] = r.object_point.y();
      out_fp[2 * i] = r.finger_point.x();
      out_fp[2 * i + 1] = r.finger_point.y();
      out_n[2 * i] = r.normal.x();
      out_n[2 * i + 1] = r.normal.y();
      out_i[i] = r.intersecting;
      out_e[i] = r.depth_exact;
      if (jacobians) {
        Put(out_J[0] + 3 * i, jac.J_sd_object_pose);
        Put(out_J[1] + 3 * i, jac.J_sd_finger_pose);
        Put(out_J[2] + 6 * i, jac.J_object_point_object_pose);
        Put(out_J[3] + 6 * i, jac.J_object_point_finger_pose);
        Put(out_J[4] + 6 * i, jac.J_finger_point_object_pose);
        Put(out_J[5] + 6 * i, jac.J_finger_point_finger_pose);
      }
    }
  }
  py::dict out;
  out["signed_distance"] = sd;
  out["intersecting"] = intersecting;
  out["object_point"] = op;
  out["finger_point"] = fp;
  out["depth"] = depth;
  out["depth_exact"] = exact;
  out["normal"] = normal;
  if (jacobians) {
    const char* names[6] = {"J_sd_object_pose", "J_sd_finger_pose", "J_object_point_object_pose",
                            "J_object_point_finger_pose", "J_finger_point_object_pose", "J_finger_point_finger_pose"};
    for (int k = 0; k < 6; ++k) out[names[k]] = J[k];
  }
  return out;
}

}  // namespace

void RegisterGeometry(py::module_& m) {
  using namespace pybind11::literals;
  m.attr("OUTSIDE") = static_cast<int>(geometry::Containment::kOutside);
  m.attr("ON_BOUNDARY") = static_cast<int>(geometry::Containment::kOnBoundary);
  m.attr("INSIDE") = static_cast<int>(geometry::Containment::kInside);
  m.attr("VERTEX") = static_cast<int>(geometry::BoundaryFeature::Kind::kVertex);
  m.attr("EDGE") = static_cast<int>(geometry::BoundaryFeature::Kind::kEdge);

  py::class_<Shape>(m, "Shape", R"doc(
A planar shape: polygons with holes (non-convex allowed), optionally rounded by a radius, in its
own frame (metres). Immutable; copies share their acceleration structures.

    square = pushgraph.Shape.box(0.09, 0.09)
    ring = pushgraph.Shape.from_polygons([{"outer": outer_xy, "holes": [hole_xy]}])
    d = square.signed_distance(points)            # (N,) for points (N, 2)
    q = square.query(points, pose=(0, 0, 0.3), jacobians=True)   # dict of arrays
)doc")
      .def_static(
          "from_polygons",
          [](const py::list& polygons, double radius) {
            std::vector<geometry::Polygon> ps;
            for (std::size_t i = 0; i < polygons.size(); ++i) ps.push_back(ToPolygon(polygons[i], i));
            return Shape::FromPolygons(std::move(ps), radius);
          },
          "polygons"_a, "radius"_a = 0.0,
          "Polygons as dicts {'outer': (N, 2), 'holes': [(M, 2), ...]} or bare (N, 2) outlines (any orientation); "
          "several parts allowed. Raises GeometryError for self-intersecting, degenerate or non-finite input, naming "
          "the polygon, ring and vertex.")
      .def_static(
          "from_arrays",
          [](const py::handle& outer, const py::list& holes, double radius) {
            geometry::Polygon p;
            p.outer = ToRing(outer, "outer");
            for (std::size_t k = 0; k < holes.size(); ++k) {
              p.holes.push_back(ToRing(holes[k], ("holes[" + std::to_string(k) + "]").c_str()));
            }
            return Shape::FromPolygons({p}, radius);
          },
          "outer"_a, "holes"_a = py::list(), "radius"_a = 0.0, "One polygon: an (N, 2) outline and (M, 2) holes.")
      .def_static(
          "disk", [](double r, const py::handle& c) { return Shape::Disk(r, ToVec2(c, "centre")); }, "radius"_a,
          "centre"_a = py::make_tuple(0.0, 0.0))
      .def_static("box", &Shape::Box, "width"_a, "height"_a, "radius"_a = 0.0, "Axis-aligned rectangle centred at 0.")
      .def_static(
          "capsule",
          [](const py::handle& a, const py::handle& b, double r) { return Shape::Capsule(ToVec2(a, "a"), ToVec2(b, "b"), r); },
          "a"_a, "b"_a, "radius"_a)
      .def_static("regular_polygon", &Shape::RegularPolygon, "n"_a, "circumradius"_a, "radius"_a = 0.0)
      .def_static(
          "load_json", [](const std::filesystem::path& path) { return geometry::LoadShapeJson(path.string()); }, "path"_a,
          "A shape JSON file (docs/formats.md).")
      .def_static("from_json", &geometry::ParseShapeJson, "text"_a, "source_name"_a = "<string>")
      // Pickling (copy.deepcopy of a trajectory dict, multiprocessing): its JSON, whose numbers
      // round-trip exactly.
      .def(py::pickle([](const Shape& shape) { return geometry::ShapeToJson(shape, -1); },
                      [](const std::string& json) { return geometry::ParseShapeJson(json, "<pickled Shape>"); }))
      .def_static(
          "from_mesh",
          [](const std::filesystem::path& file, const std::string& up, const std::string& object, double scale) {
            const std::string path = file.string();
            io::FootprintOptions o;
            o.up = io::ParseUpAxis(up);
            o.object = object;
            o.scale = scale;
            io::FootprintReport report;
            Shape shape = io::MeshFootprint(path, o, &report);
            // What `pushgraph footprint` warns of (a side view, several objects united, other
            // units), as Python warnings: it came back silently.
            std::vector<std::string> warnings = report.warnings;
            if (const auto units = io::ShapeUnitsWarning(shape, scale, "scale=")) warnings.push_back(*units);
            for (std::string w : warnings) {
              // The command line's flags, as this function's arguments.
              for (const auto& [flag, argument] : {std::pair<std::string, std::string>{"--object NAME", "object='NAME'"},
                                                   {"--up x", "up='x'"}, {"--up y", "up='y'"}, {"--up z", "up='z'"}}) {
                for (std::size_t at = w.find(flag); at != std::string::npos; at = w.find(flag, at + argument.size()))
                  w.replace(at, flag.size(), argument);
              }
              WarnUser(path + ": " + w);
            }
            return shape;
          },
          "path"_a, "up"_a = "z", "object"_a = "", "scale"_a = 1.0,
          "The footprint of a mesh (OBJ, STL, PLY or OFF): the exact union of its triangles projected along `up` ('x', 'y' or 'z'; "
          "'y' gives (x, -z), the top view of a y-up export), holes kept; `object` picks one object/group of the "
          "file; `scale` 0.001 for a mesh in millimetres. A UserWarning says when the footprint is probably not "
          "what was meant: a prism seen from the side, several objects united, a shape outside 1 mm to 2 m across.")
      .def("to_json", &geometry::ShapeToJson, "indent"_a = 2)
      .def("save_json", [](const Shape& s, const std::filesystem::path& path) { geometry::SaveShapeJson(s, path.string()); }, "path"_a)
      .def_property_readonly("radius", &Shape::radius)
      .def_property_readonly("area", &Shape::core_area, "Area of the core polygons (rounding not included).")
      .def_property_readonly("num_vertices", &Shape::num_vertices)
      .def_property_readonly("is_convex", &Shape::is_convex)
      .def_property_readonly("empty", &Shape::empty)
      .def_property_readonly(
          "bounds",
          [](const Shape& s) { return BoxArray(s.bounds()); },
          "[[min_x, min_y], [max_x, max_y]] (rounding included).")
      .def_property_readonly(
          "centroid",
          [](const Shape& s) {
            const Vec2 c = geometry::CoreCentroid(s);
            return py::make_tuple(c.x(), c.y());
          })
      .def("polygons", &PolygonsOf, "{'polygons': [{'outer': (N, 2), 'holes': [...]}], 'radius': r}: the normalized "
                                    "polygons (outer CCW, holes CW), ready for from_polygons.")
      .def("with_radius", &Shape::WithRadius, "radius"_a)
      .def(
          "transformed",
          [](const Shape& s, const py::handle& pose, double scale, bool mirror) {
            return geometry::TransformShape(s, ToPose(pose, "pose"), scale, mirror);
          },
          "pose"_a = py::make_tuple(0.0, 0.0, 0.0), "scale"_a = 1.0, "mirror"_a = false,
          "Every point p becomes pose * (scale * M p), M = diag(1, -1) when mirror.")
      .def("query", &Query, "points"_a, "pose"_a = py::none(), "jacobians"_a = false, R"doc(
Exact point queries on an (N, 2) array (the shape's frame, or the world with the shape at `pose`
(x, y, theta)). Returns a dict of arrays: signed_distance (N,), closest_point (N, 2), normal (N, 2),
containment (N,) int8 (OUTSIDE, ON_BOUNDARY, INSIDE), feature_kind (VERTEX, EDGE), feature_polygon,
feature_ring (-1 outer, k hole k), feature_index, feature_t; with jacobians=True (needs a pose)
J_sd_point (N, 1, 2), J_sd_pose (N, 1, 3), J_closest_point (N, 2, 2), J_closest_pose (N, 2, 3),
J_normal_point (N, 2, 2), J_normal_pose (N, 2, 3).)doc")
      .def("signed_distance", &SignedDistances, "points"_a, "Signed distances (N,) of (N, 2) points, shape frame.")
      .def("__repr__", [](const Shape& s) {
        return "<pushgraph.Shape: " + std::to_string(s.polygons().size()) + " polygon(s), " +
               std::to_string(s.num_vertices()) + " vertices, radius " + std::to_string(s.radius()) + ">";
      });

  py::class_<geometry::ShapePairQuerier, std::shared_ptr<geometry::ShapePairQuerier>>(m, "ShapePair", R"doc(
Exact separation and penetration of an object and a finger shape, each at a pose.

    pair = pushgraph.ShapePair(object, finger)
    r = pair.query(object_poses, finger_poses, jacobians=True)   # (N, 3) each, or one of them (3,)
)doc")
      .def(py::init([](const Shape& object, const Shape& finger, bool exact, double angle_cache_resolution) {
             geometry::ShapePairQuerier::Options o;
             o.method = exact ? geometry::ShapePairQuerier::Method::kExact : geometry::ShapePairQuerier::Method::kVertexSampling;
             o.angle_cache_resolution = angle_cache_resolution;
             return std::make_shared<geometry::ShapePairQuerier>(object, finger, o);
           }),
           "object"_a, "finger"_a, "exact"_a = true, "angle_cache_resolution"_a = 0.0)
      .def("query", &PairQuery, "object_poses"_a, "finger_poses"_a, "jacobians"_a = false, R"doc(
Returns a dict: signed_distance (N,) (> 0 apart, -depth overlapping), intersecting (N,) bool,
object_point, finger_point (N, 2) (witnesses, world), depth (N,), depth_exact (N,) bool,
normal (N, 2); with jacobians J_sd_object_pose, J_sd_finger_pose (N, 1, 3) and the witnesses'
J_object_point_object_pose ... J_finger_point_finger_pose (N, 2, 3).)doc");

  py::class_<geometry::DistanceField>(m, "DistanceField", R"doc(
A sampled signed distance field of a shape (bicubic), checked against the exact queries at
build time (max_error: the largest error seen at the check's points, an estimate, not a bound;
NaN with error_samples_per_cell=0).

    field = pushgraph.DistanceField(shape, resolution=1e-3)
    d, grad = field.evaluate(points, gradient=True)
)doc")
      .def(py::init([](const Shape& shape, double resolution, double margin, int error_samples_per_cell) {
             geometry::DistanceField::Options o;
             o.resolution = resolution;
             o.margin = margin;
             o.error_samples_per_cell = error_samples_per_cell;
             py::gil_scoped_release release;
             return std::make_unique<geometry::DistanceField>(shape, o);
           }),
           "shape"_a, "resolution"_a = 1e-3, "margin"_a = 1e-2, "error_samples_per_cell"_a = 2)
      .def(
          "evaluate",
          [](const geometry::DistanceField& f, const py::handle& points_in, bool gradient) -> py::object {
            const Array points = Rows(points_in, 2, "points");
            CheckFinite(points, "points");
            const py::ssize_t n = points.shape(0);
            py::array_t<double> d = NewArray({n});
            py::array_t<double> g = NewArray({gradient ? n : 0, 2});
            const double* p = points.data();
            double* out = d.mutable_data();
            double* out_g = g.mutable_data();
            {
              py::gil_scoped_release release;
              Vec2 grad;
              for (py::ssize_t i = 0; i < n; ++i) {
                out[i] = f.Evaluate(Vec2(p[2 * i], p[2 * i + 1]), gradient ? &grad : nullptr);
                if (gradient) {
                  out_g[2 * i] = grad.x();
                  out_g[2 * i + 1] = grad.y();
                }
              }
            }
            if (gradient) return py::make_tuple(d, g);
            return std::move(d);
          },
          "points"_a, "gradient"_a = false)
      .def_property_readonly("max_error", &geometry::DistanceField::max_error,
                             "Largest |interpolated - exact| seen at the build-time check's points (inside the grid): an "
                             "estimate, not a bound (between those points up to 1.35 times it was measured); NaN when "
                             "the check is off.")
      .def_property_readonly(
          "bounds",
          [](const geometry::DistanceField& f) { return BoxArray(f.grid_bounds()); },
          "The grid's [[min_x, min_y], [max_x, max_y]]; outside it the value is a conservative continuation.")
      .def_property_readonly("shape", [](const geometry::DistanceField& f) { return py::make_tuple(f.rows(), f.cols()); });
}

}  // namespace pushgraph::python
