// Mesh footprints: the real MIT meshes (from ../shared) and small meshes made here.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/trajectory_json.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using namespace pushgraph;

const std::string kObj = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/obj/";

int Holes(const geometry::Shape& s) {
  int h = 0;
  for (const auto& p : s.polygons()) h += static_cast<int>(p.holes.size());
  return h;
}

class Footprint : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pushgraph_footprint_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  static bool SharedAvailable() { return fs::exists(kObj + "rect1.obj"); }
  fs::path dir_;
};

TEST_F(Footprint, Rect1IsASquareWithFourThroughHoles) {
  if (!SharedAvailable()) GTEST_SKIP() << "shared MIT meshes not found at " << kObj;
  io::FootprintReport report;
  const geometry::Shape s = io::MeshFootprint(kObj + "rect1.obj", {}, &report);
  ASSERT_EQ(s.polygons().size(), 1u);
  EXPECT_EQ(Holes(s), 4);
  EXPECT_GT(s.core_area(), 8.0e-3);
  EXPECT_LT(s.core_area(), 0.09 * 0.09);
  const geometry::Box2 b = s.bounds();
  EXPECT_DOUBLE_EQ(b.min.x(), -0.045);
  EXPECT_DOUBLE_EQ(b.max.y(), 0.045);
  // The outline is the bare square: collinear vertices of the triangulation are removed.
  EXPECT_EQ(s.polygons()[0].outer.size(), 4u);
  EXPECT_LT(report.faces_used, report.faces);  // the side faces project to nothing
  // Coordinates are the file's decimal values correctly rounded.
  EXPECT_EQ(geometry::QueryPoint(s, geometry::Vec2(0.045, 0.0)).signed_distance, 0.0);
}

TEST_F(Footprint, Ellip1IsADiskWithHolesAndTheTipIsADiskAlongY) {
  if (!SharedAvailable()) GTEST_SKIP() << "shared MIT meshes not found at " << kObj;
  const geometry::Shape e = io::MeshFootprint(kObj + "ellip1.obj");
  EXPECT_EQ(e.polygons().size(), 1u);
  EXPECT_GE(Holes(e), 1);
  EXPECT_NEAR(e.bounds().max.x(), 0.0525, 1e-4);
  io::FootprintOptions up_y;
  up_y.up = io::UpAxis::kY;
  const geometry::Shape tip = io::MeshFootprint(kObj + "tip.obj", up_y);
  EXPECT_EQ(tip.polygons().size(), 1u);
  EXPECT_EQ(Holes(tip), 0);
  const double radius = std::sqrt(tip.core_area() / M_PI);
  EXPECT_NEAR(radius, 0.0047, 2e-4);
  EXPECT_TRUE(tip.is_convex());
}

TEST_F(Footprint, SeveralObjectsInOneFile) {
  if (!SharedAvailable()) GTEST_SKIP() << "shared MIT meshes not found at " << kObj;
  io::FootprintReport report;
  const geometry::Shape all = io::MeshFootprint(kObj + "tri3.obj", {}, &report);
  ASSERT_EQ(report.objects.size(), 2u);
  io::FootprintOptions one;
  one.object = report.objects[1];
  const geometry::Shape part = io::MeshFootprint(kObj + "tri3.obj", one);
  EXPECT_LE(part.core_area(), all.core_area() * (1 + 1e-12));
  one.object = "no_such_object";
  try {
    io::MeshFootprint(kObj + "tri3.obj", one);
    FAIL() << "unknown object accepted";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find(report.objects[0]), std::string::npos) << e.what();
  }
}

// Footprints that are probably not what was meant are named (a hostile-user session: tip.obj
// along z gave a 9.4 x 20 mm rectangle silently, and estimates then blamed the object's frame and
// the sensors; tri3.obj's two blocks were united into a 5-vertex outline of neither).
TEST_F(Footprint, SideViewsAndSeveralObjectsAreWarned) {
  if (!SharedAvailable()) GTEST_SKIP() << "shared MIT meshes not found at " << kObj;
  auto warnings = [](const std::string& mesh, io::UpAxis up) {
    io::FootprintOptions options;
    options.up = up;
    io::FootprintReport report;
    io::MeshFootprint(kObj + mesh, options, &report);
    std::string all;
    for (const std::string& w : report.warnings) all += w + "\n";
    return all;
  };
  EXPECT_EQ(warnings("rect1.obj", io::UpAxis::kZ), "");
  EXPECT_EQ(warnings("ellip2.obj", io::UpAxis::kZ), "");
  EXPECT_EQ(warnings("tip.obj", io::UpAxis::kY), "");
  EXPECT_NE(warnings("tip.obj", io::UpAxis::kZ).find("a prism along y"), std::string::npos);
  EXPECT_NE(warnings("rect2.obj", io::UpAxis::kY).find("--up z gives its cross-section"), std::string::npos);
  const std::string tri3 = warnings("tri3.obj", io::UpAxis::kZ);
  EXPECT_NE(tri3.find("holds 2 objects"), std::string::npos) << tri3;
  EXPECT_NE(tri3.find("--object NAME"), std::string::npos) << tri3;
  // A 3-D body that is no prism along any axis: nothing to say.
  const std::string tetra = Write("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  io::FootprintReport report;
  io::MeshFootprint(tetra, {}, &report);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_TRUE(report.prism_axes.empty());
  // A lone flat triangle: its three vertices lie on two planes across x, but no end face has
  // three of them, so it is no prism (it was told "a prism along x").
  const std::string flat = Write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  io::FootprintReport flat_report;
  io::MeshFootprint(flat, {}, &flat_report);
  EXPECT_TRUE(flat_report.warnings.empty()) << flat_report.warnings[0];
  EXPECT_TRUE(flat_report.prism_axes.empty());
  // A flat outline of two squares in z = 0: its vertices lie on two planes across y (three on
  // each), yet it is no prism: it was told "a prism along y ... --up y", which then failed.
  const std::string outline =
      Write("outline.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 5 6 3\n");
  io::FootprintReport outline_report;
  const geometry::Shape two_squares = io::MeshFootprint(outline, {}, &outline_report);
  EXPECT_TRUE(outline_report.warnings.empty()) << outline_report.warnings[0];
  EXPECT_TRUE(outline_report.prism_axes.empty());
  EXPECT_DOUBLE_EQ(two_squares.core_area(), 2.0);
  // Drawn in a plane across y and read along z: the error names the plane and the --up to use.
  const std::string side = Write("side.obj", "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n");
  try {
    io::MeshFootprint(side, {});
    ADD_FAILURE() << "a mesh seen edge-on was read";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("flat, drawn in a plane across y"), std::string::npos) << e.what();
  }
  io::FootprintOptions along_y;
  along_y.up = io::UpAxis::kY;
  EXPECT_DOUBLE_EQ(io::MeshFootprint(side, along_y).core_area(), 1.0);
  // A z-up model exported y-up, (x, y, z) -> (x, z, -y), read with --up y: the model's own (x, y)
  // (it came back as (z, x), turned by 90 degrees).
  const std::string z_up = Write("z_up.obj", "v 0 0 0\nv 0.3 0 0\nv 0.05 0.1 0\nf 1 2 3\n");
  const std::string y_up = Write("y_up.obj", "v 0 0 -0\nv 0.3 0 -0\nv 0.05 0 -0.1\nf 1 2 3\n");
  const geometry::Shape model = io::MeshFootprint(z_up, {}), exported = io::MeshFootprint(y_up, along_y);
  ASSERT_EQ(exported.polygons().size(), 1u);
  EXPECT_EQ(exported.polygons()[0].outer, model.polygons()[0].outer);
  // --object on a file without named objects says so instead of listing nothing.
  io::FootprintOptions named;
  named.object = "nope";
  try {
    io::MeshFootprint(outline, named);
    ADD_FAILURE() << "an unknown object was read";
  } catch (const io::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("no named objects"), std::string::npos) << e.what();
  }
  // OBJ statements the footprint does not use pass; a line of no OBJ kind is counted and named.
  const std::string decorated = Write("d.obj",
                                      "# c\nmtllib a.mtl\no t\ng t\nusemtl m\ns off\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                      "vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nl 1 2\n");
  io::FootprintReport decorated_report;
  io::MeshFootprint(decorated, {}, &decorated_report);
  EXPECT_TRUE(decorated_report.warnings.empty()) << decorated_report.warnings[0];
  const std::string garbled = Write("g.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nhello world\n<html>\n");
  io::FootprintReport garbled_report;
  io::MeshFootprint(garbled, {}, &garbled_report);
  ASSERT_EQ(garbled_report.warnings.size(), 1u);
  EXPECT_NE(garbled_report.warnings[0].find("2 line(s) that are no OBJ statement were skipped (the first at line 5: 'hello world')"),
            std::string::npos)
      << garbled_report.warnings[0];
  // A bow-tie quad is named (its fan triangulation is neither the bow-tie nor the square); a
  // convex and a non-convex (L-shaped) simple face pass.
  const std::string bowtie = Write("b.obj", "v 0 0 0\nv 0.05 0.05 0\nv 0.05 0 0\nv 0 0.05 0\nf 1 2 3 4\n");
  io::FootprintReport bowtie_report;
  io::MeshFootprint(bowtie, {}, &bowtie_report);
  ASSERT_EQ(bowtie_report.warnings.size(), 1u);
  EXPECT_NE(bowtie_report.warnings[0].find("1 face(s) cross themselves (the first at line 5)"), std::string::npos)
      << bowtie_report.warnings[0];
  // A closed box whose top is a bow-tie: the crossing is named, and so is the check for missing
  // faces it keeps from running (the fan's triangles overlap, so coverage parity says nothing).
  const std::string bowtie_box = Write("bb.obj",
                                       "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                       "f 1 4 3 2\nf 5 7 6 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  io::FootprintReport bowtie_box_report;
  io::MeshFootprint(bowtie_box, {}, &bowtie_box_report);
  ASSERT_EQ(bowtie_box_report.warnings.size(), 2u);
  EXPECT_NE(bowtie_box_report.warnings[0].find("1 face(s) cross themselves (the first at line 10)"), std::string::npos)
      << bowtie_box_report.warnings[0];
  EXPECT_NE(bowtie_box_report.warnings[1].find("whether the mesh is closed was not checked"), std::string::npos)
      << bowtie_box_report.warnings[1];
  const std::string ell = Write("l.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 1 2 3 4 5 6\n"
                                         "v 0 0 1\nv 0 1 1\nv 1 1 1\nv 1 0 1\nf 7 8 9 10\n");
  io::FootprintReport ell_report;
  io::MeshFootprint(ell, {}, &ell_report);
  EXPECT_TRUE(ell_report.warnings.empty()) << ell_report.warnings[0];
  // The axes a prism is extruded along, which LoadShapeArgument uses to read a probe's mesh.
  io::FootprintReport tip;
  io::MeshFootprint(kObj + "tip.obj", {}, &tip);
  ASSERT_EQ(tip.prism_axes.size(), 1u);
  EXPECT_EQ(tip.prism_axes[0], io::UpAxis::kY);
  io::FootprintReport rect;
  io::MeshFootprint(kObj + "rect1.obj", {}, &rect);
  EXPECT_EQ(rect.prism_axes, std::vector<io::UpAxis>{io::UpAxis::kZ});
}

TEST_F(Footprint, UnionOfOverlappingAndOpenNonManifoldMeshes) {
  // Two overlapping squares (each two triangles, no shared vertices) and a detached triangle
  // sharing one corner with them: an exact union with two parts touching at a vertex.
  const std::string mesh = Write("m.obj",
                                 "o a\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3\nf 1 3 4\n"
                                 "o b\nv 1 1 1\nv 3 1 1\nv 3 3 1\nv 1 3 1\nf 5 6 7\nf 5 7 8\n"
                                 "o c\nv 3 3 0\nv 4 3 0\nv 4 4 0\nf 9 10 11\n"
                                 "o degenerate\nv 0 0 0\nv 0 0 1\nv 1 0 1\nf 12 13 14\n");
  io::FootprintReport report;
  const geometry::Shape s = io::MeshFootprint(mesh, {}, &report);
  EXPECT_EQ(report.faces, 6);
  EXPECT_EQ(report.faces_used, 5);
  EXPECT_EQ(s.polygons().size(), 2u);
  EXPECT_DOUBLE_EQ(s.core_area(), 4 + 4 - 1 + 0.5);
  EXPECT_EQ(geometry::QueryPoint(s, geometry::Vec2(1.5, 1.5)).containment, geometry::Containment::kInside);
  EXPECT_EQ(geometry::QueryPoint(s, geometry::Vec2(3, 3)).containment, geometry::Containment::kOnBoundary);
  // A ring of quads around a hole: the hole is kept.
  const std::string frame = Write("frame.obj",
                                  "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 0 3 0\nv 1 1 0\nv 2 1 0\nv 2 2 0\nv 1 2 0\n"
                                  "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n");
  const geometry::Shape f = io::MeshFootprint(frame, {});
  EXPECT_EQ(Holes(f), 1);
  EXPECT_DOUBLE_EQ(f.core_area(), 8.0);
  io::FootprintOptions mm;
  mm.scale = 0.001;
  EXPECT_DOUBLE_EQ(io::MeshFootprint(frame, mm).core_area(), 8.0e-6);
}

// A closed surface covers each point of its footprint an even number of times; a mesh with faces
// lost (a block's bottom, some of its top) is said to be open, whatever its vertex order or
// T-junctions. The shipped MIT meshes are closed, and a flat outline (one sheet) is meant so.
TEST_F(Footprint, AMeshWithFacesMissingIsSaidToBeOpen) {
  auto open_warning = [](const io::FootprintReport& r) {
    for (const std::string& w : r.warnings)
      if (w.find("the mesh is not closed") != std::string::npos) return w;
    return std::string();
  };
  const std::string vertices = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 0 0 1\nv 2 0 1\nv 2 1 1\nv 0 1 1\n";
  const std::string sides = "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  // The top split in two at x = 1 (a T-junction on the bottom's long edges seen from above).
  const std::string top = "v 1 0 1\nv 1 1 1\nf 5 9 10 8\nf 9 6 7 10\n";
  io::FootprintReport closed, open, no_bottom;
  io::MeshFootprint(Write("closed.obj", vertices + top + sides + "f 1 4 3 2\n"), {}, &closed);
  EXPECT_EQ(open_warning(closed), "");
  const geometry::Shape half = io::MeshFootprint(Write("open.obj", vertices + "v 1 0 1\nv 1 1 1\nf 5 9 10 8\n" + sides), {}, &open);
  const std::string said = open_warning(open);
  EXPECT_NE(said.find("covered by 1 face"), std::string::npos) << said;
  EXPECT_DOUBLE_EQ(half.core_area(), 1.0);  // what the lost face alone covered is lacking
  io::MeshFootprint(Write("no_bottom.obj", vertices + top + sides), {}, &no_bottom);
  EXPECT_NE(open_warning(no_bottom).find("2 of 2 sample points"), std::string::npos) << open_warning(no_bottom);
  io::FootprintReport flat, tilted;
  io::MeshFootprint(Write("flat.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\n"), {}, &flat);
  EXPECT_EQ(open_warning(flat), "");
  // A sheet tilted by a rounding (2e-7 across 2): a sheet still, not asked.
  io::MeshFootprint(Write("tilted.obj", "v 0 0 0\nv 2 0 2e-7\nv 2 1 2e-7\nv 0 1 0\nf 1 2 3 4\n"), {}, &tilted);
  EXPECT_EQ(open_warning(tilted), "");
  if (!SharedAvailable()) GTEST_SKIP() << "no MIT meshes";
  for (const char* name : {"rect1", "rect2", "rect3", "ellip1", "ellip2", "tri1", "tri2", "tri3"}) {
    io::FootprintReport r;
    io::MeshFootprint(kObj + name + ".obj", {}, &r);
    EXPECT_EQ(open_warning(r), "") << name;
  }
  io::FootprintOptions along_y;
  along_y.up = io::UpAxis::kY;
  io::FootprintReport tip;
  io::MeshFootprint(kObj + "tip.obj", along_y, &tip);
  EXPECT_EQ(open_warning(tip), "");
}

// Seams a rounding error wide. A ring of quads, each with its own vertices, closed at angle 2 pi
// (sin 2 pi = -1.2e-17 where the first quad has 0), and a U of five boxes with T-junctions turned
// by 37 degrees and written to 9 digits: the exact union kept each seam as a slit, the ring's hole
// open to the outside through it (one polygon, no hole: a point deep in the material was on the
// boundary) and the U in 4 parts. Vertices within 1e-7 of the size of another or of an edge are
// snapped now, and the report says how many.
TEST_F(Footprint, SeamsWrittenWithRoundedCoordinatesLeaveNoSlit) {
  std::ostringstream ring;
  ring.precision(9);
  const int n = 48;
  for (int i = 0; i < n; ++i) {
    for (double r : {0.05, 0.02}) {
      for (int j : {i, i + 1}) {
        const double a = 2.0 * M_PI * j / n;
        ring << "v " << r * std::cos(a) << " " << r * std::sin(a) << " 0\n";
      }
    }
    ring << "f " << 4 * i + 1 << " " << 4 * i + 2 << " " << 4 * i + 4 << " " << 4 * i + 3 << "\n";
  }
  io::FootprintReport report;
  const geometry::Shape r = io::MeshFootprint(Write("ring.obj", ring.str()), {}, &report);
  EXPECT_EQ(r.polygons().size(), 1u);
  EXPECT_EQ(Holes(r), 1);
  EXPECT_GT(report.vertices_snapped, 0);
  EXPECT_NE(report.warnings.size(), 0u);
  // Deep in the material on the seam, 15 mm from the outer vertex and the inner one (a little
  // less from the inner 48-gon's sides): inside, not on a slit.
  const geometry::PointQuery q = geometry::QueryPoint(r, geometry::Vec2(0.035, 0.0));
  EXPECT_EQ(q.containment, geometry::Containment::kInside);
  EXPECT_LT(q.signed_distance, -0.0149);
  EXPECT_EQ(geometry::QueryPoint(r, geometry::Vec2(0.0, 0.0)).containment, geometry::Containment::kOutside);

  const double boxes[5][4] = {{-0.05, 0.0, -0.003, 0.02}, {0.003, 0.0, 0.05, 0.02}, {-0.003, 0.006, 0.003, 0.02},
                              {-0.05, 0.02, -0.03, 0.06}, {0.03, 0.02, 0.05, 0.06}};
  for (double degrees : {0.0, 37.0}) {
    const double c = std::cos(degrees * M_PI / 180.0), s = std::sin(degrees * M_PI / 180.0);
    std::ostringstream u;
    u.precision(9);
    int v = 0;
    for (const auto& b : boxes) {
      const double corners[4][2] = {{b[0], b[1]}, {b[2], b[1]}, {b[2], b[3]}, {b[0], b[3]}};
      for (const auto& p : corners) u << "v " << c * p[0] - s * p[1] << " " << s * p[0] + c * p[1] << " 0\n";
      u << "f " << v + 1 << " " << v + 2 << " " << v + 3 << " " << v + 4 << "\n";
      v += 4;
    }
    io::FootprintReport u_report;
    const geometry::Shape shape = io::MeshFootprint(Write("u.obj", u.str()), {}, &u_report);
    EXPECT_EQ(shape.polygons().size(), 1u) << degrees << " degrees";
    EXPECT_EQ(Holes(shape), 0) << degrees << " degrees";
    EXPECT_NEAR(shape.core_area(), 0.003564, 1e-11) << degrees << " degrees";
    // Axis-aligned, every T-junction lies exactly on its edge: nothing to snap or say.
    if (degrees == 0.0) {
      EXPECT_EQ(u_report.vertices_snapped, 0);
    }
  }
}

// A shape of several parts, one far from the others (a sliver 5 m off a 9 cm block): named as a
// stray part; it was asked "is the file in centimetres or inches?". One part 5 m across is still
// a units question.
TEST_F(Footprint, AStrayPartFarAwayIsNamedAsSuch) {
  const geometry::Shape block = geometry::Shape::Box(0.09, 0.09);
  const geometry::Shape stray = geometry::Shape::FromPolygons(
      {{{{-0.045, -0.045}, {0.045, -0.045}, {0.045, 0.045}, {-0.045, 0.045}}, {}},
       {{{5.0, 0.0}, {5.001, 0.0}, {5.001, 0.001}, {5.0, 0.001}}, {}}});
  EXPECT_FALSE(io::ShapeUnitsWarning(block).has_value());
  const std::optional<std::string> w = io::ShapeUnitsWarning(stray);
  ASSERT_TRUE(w.has_value());
  EXPECT_NE(w->find("the shape's 2 parts span 5.046 m, but the largest is 0.09 m across: a stray part"), std::string::npos) << *w;
  const std::optional<std::string> big = io::ShapeUnitsWarning(geometry::Shape::Box(5.0, 5.0));
  ASSERT_TRUE(big.has_value());
  EXPECT_NE(big->find("is the file in"), std::string::npos) << *big;
}

// A non-convex polygon face (a U, 8 vertices) gives its own area from whichever vertex it is
// listed from, in either orientation: the OBJ reader's triangulation filled the notch when the
// face started at the notch's corner (area 0.01 instead of 0.0072, no warning).
TEST_F(Footprint, ANonConvexPolygonFaceIsUnitedAsItIs) {
  const double u[8][2] = {{0, 0}, {0.1, 0}, {0.1, 0.1}, {0.07, 0.1}, {0.07, 0.03}, {0.03, 0.03}, {0.03, 0.1}, {0, 0.1}};
  for (int start = 0; start < 8; ++start) {
    for (int direction : {1, -1}) {
      std::ostringstream obj;
      for (const auto& v : u) obj << "v " << v[0] << " " << v[1] << " 0.5\n";
      obj << "f";
      for (int k = 0; k < 8; ++k) obj << " " << ((start + direction * k + 8) % 8) + 1;
      obj << "\n";
      io::FootprintReport report;
      const geometry::Shape s = io::MeshFootprint(Write("u.obj", obj.str()), {}, &report);
      EXPECT_NEAR(s.core_area(), 0.0072, 1e-15) << "from vertex " << start + 1 << ", direction " << direction;
      EXPECT_EQ(report.faces, 1);
      EXPECT_EQ(geometry::QueryPoint(s, geometry::Vec2(0.05, 0.08)).containment, geometry::Containment::kOutside);
    }
  }
}

// A CAD export: the dataset's rect1.obj (its 636 triangles, 4 through holes) as a binary STL in
// millimetres (float32 coordinates), an ASCII STL, a PLY and an OFF file: the footprint of each
// is the OBJ's, to float32's rounding for the binary STL and exactly for the text formats.
TEST_F(Footprint, StlPlyAndOffMeshesAreReadAsTheObjIs) {
  if (!SharedAvailable()) GTEST_SKIP() << "no shared MIT meshes";
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;
  {
    std::ifstream in(kObj + "rect1.obj");
    for (std::string line; std::getline(in, line);) {
      std::istringstream s(line);
      std::string kind;
      s >> kind;
      if (kind == "v") {
        std::array<double, 3> v{};
        s >> v[0] >> v[1] >> v[2];
        vertices.push_back(v);
      } else if (kind == "f") {
        std::vector<int> face;
        for (std::string token; s >> token;) face.push_back(std::stoi(token.substr(0, token.find('/'))) - 1);
        for (std::size_t k = 1; k + 1 < face.size(); ++k) triangles.push_back({face[0], face[k], face[k + 1]});
      }
    }
  }
  ASSERT_EQ(triangles.size(), 636u);
  const geometry::Shape obj = io::MeshFootprint(kObj + "rect1.obj");
  {
    std::ofstream out(dir_ / "rect1_mm.stl", std::ios::binary);
    char header[80] = "binary STL, millimetres";
    out.write(header, 80);
    const std::uint32_t count = static_cast<std::uint32_t>(triangles.size());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (const auto& t : triangles) {
      float values[12] = {0, 0, 0};
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) values[3 + 3 * k + a] = static_cast<float>(1000.0 * vertices[t[k]][a]);
      out.write(reinterpret_cast<const char*>(values), sizeof values);
      const std::uint16_t attributes = 0;
      out.write(reinterpret_cast<const char*>(&attributes), 2);
    }
  }
  std::ostringstream ascii, off, ply;
  ascii.precision(17), off.precision(17), ply.precision(17);
  ascii << "solid rect1\n";
  for (const auto& t : triangles) {
    ascii << "facet normal 0 0 0\nouter loop\n";
    for (int k = 0; k < 3; ++k) ascii << "vertex " << vertices[t[k]][0] << " " << vertices[t[k]][1] << " " << vertices[t[k]][2] << "\n";
    ascii << "endloop\nendfacet\n";
  }
  ascii << "endsolid rect1\n";
  off << "OFF\n" << vertices.size() << " " << triangles.size() << " 0\n";
  ply << "ply\nformat ascii 1.0\nelement vertex " << vertices.size() << "\nproperty double x\nproperty double y\n"
      << "property double z\nelement face " << triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& v : vertices) off << v[0] << " " << v[1] << " " << v[2] << "\n", ply << v[0] << " " << v[1] << " " << v[2] << "\n";
  for (const auto& t : triangles) off << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n", ply << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  io::FootprintOptions millimetres;
  millimetres.scale = 1e-3;
  struct Case {
    std::string path;
    io::FootprintOptions options;
    double tolerance;
  };
  const Case cases[] = {{(dir_ / "rect1_mm.stl").string(), millimetres, 1e-8},  // float32 of 45 mm: 2e-9 m
                        {Write("rect1.stl", ascii.str()), {}, 0.0},
                        {Write("rect1.off", off.str()), {}, 0.0},
                        {Write("rect1.ply", ply.str()), {}, 0.0}};
  for (const Case& c : cases) {
    io::FootprintReport report;
    const geometry::Shape s = io::MeshFootprint(c.path, c.options, &report);
    EXPECT_EQ(report.faces, 636) << c.path;
    EXPECT_EQ(Holes(s), 4) << c.path;
    ASSERT_EQ(report.prism_axes.size(), 1u) << c.path;
    EXPECT_EQ(report.prism_axes[0], io::UpAxis::kZ) << c.path;
    EXPECT_NEAR(s.core_area(), obj.core_area(), 1e-6 * obj.core_area() + c.tolerance * 0.4) << c.path;
    double worst = 0.0;
    for (const auto& p : s.polygons())
      for (const geometry::Vec2& v : p.outer) worst = std::max(worst, std::abs(geometry::QueryPoint(obj, v).signed_distance));
    EXPECT_LE(worst, c.tolerance) << c.path;
  }
}

TEST_F(Footprint, ClearErrors) {
  auto expect_error = [](const std::string& path, const io::FootprintOptions& o, const std::string& needle) {
    try {
      io::MeshFootprint(path, o);
      ADD_FAILURE() << "no error, expected: " << needle;
    } catch (const io::IoError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expect_error((dir_ / "missing.obj").string(), {}, "cannot read mesh");
  expect_error(Write("empty.obj", "# nothing here\n"), {}, "no faces");
  // Other mesh formats are named (a glTF read as "the mesh has no faces"); broken STL, PLY and
  // OFF files say which format they failed as.
  expect_error(Write("part.gltf", "{\"asset\": {}}\n"), {}, "glTF meshes are not read, only Wavefront OBJ, STL, PLY and OFF");
  expect_error(Write("part.stl", "solid part\nendsolid part\n"), {}, "the mesh has no faces (an empty STL file, or not STL)");
  expect_error(Write("part_stl.obj", "solid part\nfacet normal 0 0 1\n"), {}, "(an empty STL file, or not STL)");
  expect_error(Write("part.PLY", "ply\nformat ascii 1.0\n"), {}, "cannot read PLY mesh");
  expect_error(Write("text.stl", "hello world\n"), {}, "not STL");
  expect_error(Write("badidx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"), {}, "cannot read OFF mesh");
  expect_error(Write("nan.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n"), {}, "");
  expect_error((dir_ / "missing.stl").string(), {}, "no such file");
  // Counts a file cannot hold are refused before the reader sizes anything by them (a 90-byte OFF
  // whose face claimed 2e9 vertices took 15.6 GB); an index past the vertices is named.
  expect_error(Write("huge.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n"), {},
               "face 1's vertex count at line 6 claims 2000000000, more than the file's");
  expect_error(Write("long.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n5 0 1 2\n"), {},
               "face 1 at line 6 lists 5 vertices but its line holds 3 numbers after the count");
  expect_error(Write("many.off", "OFF\n2000000000 1 0\n0 0 0\n"), {}, "the vertex count at line 2 claims 2000000000");
  expect_error(Write("index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), {},
               "face 1 at line 6 refers to vertex '3', but the file has 3 vertices, indexed from 0 to 2");
  const std::string ply_head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  expect_error(Write("huge.ply", ply_head + "2000000000 0 1 2\n"), {}, "claims 2000000000, more than the file's");
  expect_error(Write("index.ply", ply_head + "3 0 1 9\n"), {}, "refers to vertex '9', but the file has 3 vertices");
  io::FootprintOptions named;
  named.object = "part";
  expect_error(Write("square.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"), named,
               "OFF files hold one unnamed mesh");
  io::FootprintOptions up_y;
  up_y.up = io::UpAxis::kY;
  expect_error(Write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), up_y, "zero area");
  // Collinear faces have no footprint along any axis: said so, not "--up y reads it" (which
  // then failed too).
  for (const io::UpAxis up : {io::UpAxis::kX, io::UpAxis::kY, io::UpAxis::kZ}) {
    io::FootprintOptions o;
    o.up = up;
    expect_error(Write("line.obj", "v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nf 1 2 3\n"), o,
                 "every face is degenerate (its vertices collinear or repeated: zero area in 3-D)");
  }
  expect_error(Write("badidx.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"), {}, "");
  io::FootprintOptions bad_scale;
  bad_scale.scale = -1;
  expect_error(Write("ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), bad_scale, "scale");
  EXPECT_THROW(io::ParseUpAxis("w"), io::IoError);
  // Bad vertex coordinates name the line (tinyobjloader alone reads "abc" as 0 and keeps NaN).
  expect_error(Write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), {}, "nan.obj:2: vertex coordinate 1 is not finite");
  expect_error(Write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n"), {}, "inf.obj:3: vertex coordinate 2 is not finite");
  expect_error(Write("abc.obj", "v 0 0 0\nv 1 0 abc\nv 0 1 0\nf 1 2 3\n"), {}, "abc.obj:2: vertex coordinate 3 is missing or not a number");
  expect_error(Write("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"), {}, "short.obj:2: vertex coordinate 3");
  expect_error(Write("tail.obj", "v 0 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), {}, "tail.obj:1: unexpected text");
  // A NUL byte, a face cut short, a face before its vertices: named with the line, not read as
  // another shape.
  static const char kWithNul[] = "v 0 0 0\nv 1 0 0\nv 0 1\0 0\nf 1 2 3\n";
  const std::string with_nul(kWithNul, sizeof kWithNul - 1);
  expect_error(Write("nul.obj", with_nul), {}, "nul.obj:3: a NUL byte at column 6");
  expect_error(Write("cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4"), {},
               "cut.obj:6: a face needs at least 3 vertices, this one has 2");
  expect_error(Write("early.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"), {}, "early.obj:3: face vertex '3'");
  // Comments, a weight and vertex colours after the coordinates are fine.
  EXPECT_NO_THROW(io::MeshFootprint(Write("colours.obj", "v 0 0 0 1 0 0 # red\nv 1 0 0 1.0\nv 0 1 0\nf 1 2 3\n"), {}));
}

}  // namespace
