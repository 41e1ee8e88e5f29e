#pragma once
// The planar footprint of a mesh: its faces projected along an up axis and united exactly
// (CGAL Boolean set operations, Epeck), holes and several parts kept, duplicate and collinear
// vertices removed. Non-manifold meshes are fine (only the projected faces matter); an open one
// is read but warned of (FootprintReport::warnings: where faces are missing, the footprint lacks
// what they alone covered); faces with zero projected area (the sides of a prism) are skipped.
//
//   io::FootprintOptions options;
//   options.up = io::UpAxis::kY;                       // e.g. a cylinder lying along y
//   io::FootprintReport report;
//   geometry::Shape tip = io::MeshFootprint("tip.obj", options, &report);
#include <pushgraph/geometry/shape.h>

#include <optional>
#include <string>
#include <vector>

namespace pushgraph::io {

/// Projection: kZ -> (x, y), kY -> (x, -z), kX -> (y, z) (right-handed: u x v = up). kY is the
/// y-up convention of OBJ exports (Blender's, glTF's): a z-up model exported y-up, (x, z, -y),
/// comes back in the model's own (x, y). (Until 2026-11-27 kY gave (z, x): turned by 90 degrees.)
enum class UpAxis { kX, kY, kZ };

/// Parses "x", "y" or "z" (throws IoError otherwise).
UpAxis ParseUpAxis(const std::string& text);

struct FootprintOptions {
  UpAxis up = UpAxis::kZ;
  std::string object;  ///< only this object/group of the file; empty: all of them together
  double scale = 1.0;  ///< multiplies coordinates (e.g. 0.001 for a mesh in millimetres)
};

struct FootprintReport {
  std::vector<std::string> objects;  ///< object/group names in the file
  int faces = 0;                     ///< faces read (a polygon face counts once)
  int faces_used = 0;                ///< with non-zero projected area
  int vertices_removed = 0;          ///< collinear or duplicate vertices dropped from the outline
  /// Vertices within 1e-7 of the footprint's size of another vertex, moved onto it, or of a face's
  /// edge, inserted into it (seams with rounded coordinates, T-junctions): without it the exact
  /// union keeps such a seam as a slit of that width.
  int vertices_snapped = 0;
  /// What the footprint may not be what was meant: several objects united (tri3.obj holds two
  /// blocks), a prism along another axis than `up` (its side view, e.g. tip.obj without
  /// --up y: every vertex on the two end planes of another axis), or a mesh that is not closed
  /// (a point of the footprint covered by an odd number of faces; flat outlines are not asked).
  std::vector<std::string> warnings;
  /// The axes along which the mesh is a prism (every vertex on two end planes, at least three on
  /// each): an extruded outline, whose cross-section is its footprint along that axis.
  std::vector<UpAxis> prism_axes;
  /// Set when every used vertex lies in one plane (an outline drawn flat): the axis across it,
  /// the one reading of such a file (filled before MeshFootprint refuses another up axis).
  std::optional<UpAxis> flat_axis;
};

/// Throws IoError naming the file for unreadable, empty or broken meshes, an unknown object name,
/// or a footprint of zero area.
geometry::Shape MeshFootprint(const std::string& obj_path, const FootprintOptions& options = {},
                              FootprintReport* report = nullptr);

/// Shapes are in metres, and a pushed object or finger is 1 mm to 2 m across: outside that, a
/// warning naming the units that would bring it to 1 cm to 1 m ("the shape is 90 m across: ...
/// is the file in millimetres (--scale 0.001: 0.09 m across)?"), else nullopt. `scale_given`:
/// a scale already applied (the suggested --scale is relative to the file); `scale_is`: how the
/// caller's user gives a scale ("--scale " for footprint, "scale=" in Python). A shape of several
/// parts whose largest is 1 cm to 1 m across while they span over 2 m and 10 times it is asked
/// about a stray part far from the others instead.
std::optional<std::string> ShapeUnitsWarning(const geometry::Shape& shape, double scale_given = 1.0,
                                             const std::string& scale_is = "--scale ");

}  // namespace pushgraph::io
