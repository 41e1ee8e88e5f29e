// Shape JSON: round trips (bit-exact coordinates) and every malformed-input case, with errors
// that name the file (or source name) and what is wrong.
#include <pushgraph/geometry/json_check.h>
#include <pushgraph/geometry/shape.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

namespace fs = std::filesystem;

fs::path TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("pushgraph_test_shape_json_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

void ExpectSameShape(const Shape& a, const Shape& b) {
  EXPECT_EQ(a.radius(), b.radius());
  ASSERT_EQ(a.polygons().size(), b.polygons().size());
  for (size_t i = 0; i < a.polygons().size(); ++i) {
    EXPECT_EQ(a.polygons()[i].outer, b.polygons()[i].outer) << "polygon " << i;
    ASSERT_EQ(a.polygons()[i].holes.size(), b.polygons()[i].holes.size());
    for (size_t h = 0; h < a.polygons()[i].holes.size(); ++h)
      EXPECT_EQ(a.polygons()[i].holes[h], b.polygons()[i].holes[h]) << "polygon " << i << " hole " << h;
  }
}

TEST(ShapeJson, ParsesTheDocumentedFormat) {
  const Shape s = ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [0.09, 0], [0.09, 0.09], [0, 0.09]],
                                                    "holes": [[[0.01, 0.01], [0.02, 0.01], [0.02, 0.02]]]}],
                                     "radius": 0.001})");
  EXPECT_EQ(s.radius(), 0.001);
  ASSERT_EQ(s.polygons().size(), 1u);
  EXPECT_EQ(s.polygons()[0].outer.size(), 4u);
  EXPECT_EQ(s.polygons()[0].holes.size(), 1u);
  // holes and radius are optional
  const Shape t = ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [1, 0], [0, 1]]}]})");
  EXPECT_EQ(t.radius(), 0.0);
  EXPECT_TRUE(t.polygons()[0].holes.empty());
  // a point and a segment, with a radius
  const Shape disk = ParseShapeJson(R"({"polygons": [{"outer": [[0.5, -0.5]]}], "radius": 0.25})");
  EXPECT_TRUE(disk.is_degenerate_core());
  EXPECT_EQ(disk.polygons()[0].outer[0], Vec2(0.5, -0.5));
  const Shape cap = ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [1, 0]]}], "radius": 0.25})");
  EXPECT_EQ(cap.num_vertices(), 2);
  // integers and exponents are numbers
  const Shape e = ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [1e-3, 0], [0, 2E-3]]}], "radius": 0})");
  EXPECT_EQ(e.polygons()[0].outer.size(), 3u);
}

TEST(ShapeJson, RoundTripIsBitExact) {
  std::mt19937_64 rng(501);
  for (int i = 0; i < 10; ++i) {
    const Shape s = Shape::FromPolygons(testing::RandomPolygons(rng, 1 + i % 3), i % 2 ? 0.0 : 0.0123456789012345678);
    ExpectSameShape(s, ParseShapeJson(ShapeToJson(s)));
    ExpectSameShape(s, ParseShapeJson(ShapeToJson(s, -1)));  // compact
    const fs::path path = TempPath("round_trip_" + std::to_string(i) + ".json");
    SaveShapeJson(s, path.string());
    ExpectSameShape(s, LoadShapeJson(path.string()));
  }
  for (const Shape& s : {Shape::Disk(0.1, Vec2(1.0 / 3, -2.0 / 7)), Shape::Capsule(Vec2(0.1, 0.2), Vec2(0.3, 0.7), 0.05),
                         Shape::RegularPolygon(7, 1.0 / 3, 1e-7)})
    ExpectSameShape(s, ParseShapeJson(ShapeToJson(s)));
}

/// Parsing fails with GeometryError and the message contains every fragment.
::testing::AssertionResult FailsWith(const std::string& text, std::initializer_list<std::string> fragments,
                                     const std::string& source = "my_shape.json") {
  try {
    ParseShapeJson(text, source);
  } catch (const GeometryError& e) {
    const std::string msg = e.what();
    if (msg.find(source) == std::string::npos)
      return ::testing::AssertionFailure() << "error does not name the source \"" << source << "\": " << msg;
    for (const auto& f : fragments)
      if (msg.find(f) == std::string::npos)
        return ::testing::AssertionFailure() << "error does not mention \"" << f << "\": " << msg;
    if (msg.find('\n') != std::string::npos)
      return ::testing::AssertionFailure() << "error is not one line: " << msg;
    return ::testing::AssertionSuccess();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << "threw a non-GeometryError: " << e.what();
  }
  return ::testing::AssertionFailure() << "accepted: " << text;
}

TEST(ShapeJson, UnknownFields) {
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}], "colour": "red"})", {"colour"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]], "hole": []}]})", {"hole"}));
  EXPECT_TRUE(FailsWith(R"({"polygon": [{"outer": [[0,0],[1,0],[0,1]]}]})", {"polygon"}));
}

TEST(ShapeJson, MissingFields) {
  EXPECT_TRUE(FailsWith(R"({"radius": 0.1})", {"polygons"}));
  EXPECT_TRUE(FailsWith(R"({})", {"polygons"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"holes": []}]})", {"outer"}));
}

TEST(ShapeJson, WrongTypes) {
  EXPECT_TRUE(FailsWith(R"({"polygons": {"outer": [[0,0],[1,0],[0,1]]}})", {"polygons"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}], "radius": "0.1"})", {"radius"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,"a"],[0,1]]}]})", {"outer"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0,2],[0,1]]}]})", {"outer"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1],[0,1]]}]})", {"outer"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": "square"}]})", {"outer"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]], "holes": [[0.1, 0.1]]}]})", {"holes"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]], "holes": 3}]})", {"holes"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [[[0,0],[1,0],[0,1]]]})", {"polygons[0]"}));
  EXPECT_TRUE(FailsWith(R"([1, 2, 3])", {}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,null]]}]})", {"outer"}));
  // The second polygon is named.
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}, {"outer": [[5,5],[6,true],[5,6]]}]})",
                        {"polygons[1]"}));
}

TEST(ShapeJson, MalformedJson) {
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}])", {}));  // missing brace
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1],]}]})", {}));  // trailing comma
  EXPECT_TRUE(FailsWith("", {}));
  EXPECT_TRUE(FailsWith("not json", {}));
  // A mesh where a shape file is asked for says what it is and how to make a shape of it.
  EXPECT_TRUE(FailsWith("o L\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", {"looks like an OBJ mesh", "pushgraph footprint"}));
  EXPECT_TRUE(FailsWith("solid L\nfacet normal 0 0 1\n", {"this is an STL mesh", "pushgraph footprint"}));
  EXPECT_FALSE(FailsWith("not json", {"mesh"}));
}

TEST(ShapeJson, InvalidGeometryNamesFileAndLocation) {
  // Bow-tie in polygon 1: the message names the source, the polygon and the vertex.
  const std::string bowtie = R"({"polygons": [{"outer": [[-5,-5],[-4,-5],[-4,-4]]},
                                               {"outer": [[0,0],[1,1],[1,0],[0,1]]}]})";
  try {
    ParseShapeJson(bowtie, "bowtie.json");
    ADD_FAILURE() << "bow-tie accepted";
  } catch (const GeometryError& e) {
    EXPECT_EQ(e.polygon(), 1) << e.what();
    EXPECT_EQ(e.ring(), -1) << e.what();
    EXPECT_NE(std::string(e.what()).find("bowtie.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("polygon 1"), std::string::npos) << e.what();
  }
  // Overflowing number (1e999 is infinite): not finite, vertex named.
  try {
    ParseShapeJson(R"({"polygons": [{"outer": [[0,0],[1e999,0],[0,1]]}]})", "inf.json");
    ADD_FAILURE() << "infinite coordinate accepted";
  } catch (const GeometryError& e) {
    EXPECT_NE(std::string(e.what()).find("inf.json"), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "non-GeometryError: " << e.what();
  }
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0]]}]})", {"radius"}));  // point needs r > 0
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}], "radius": -1})", {"radius"}));
  EXPECT_TRUE(FailsWith(R"({"polygons": []})", {}));
  EXPECT_TRUE(FailsWith(R"({"polygons": [{"outer": [[0,0],[4,0],[4,4],[0,4]], "holes": [[[5,5],[6,5],[6,6]]]}]})",
                        {"hole 0"}));
}

TEST(ShapeJson, FileErrorsNameTheFile) {
  const std::string missing = TempPath("does_not_exist.json").string();
  try {
    LoadShapeJson(missing);
    ADD_FAILURE() << "missing file accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    EXPECT_NE(dynamic_cast<const GeometryError*>(&e), nullptr) << e.what();
  }
  const fs::path bad = TempPath("bad.json");
  {
    std::ofstream out(bad);
    out << R"({"polygons": [{"outer": [[0,0],[1,0],[0,1]]}], "extra": 1})";
  }
  try {
    LoadShapeJson(bad.string());
    ADD_FAILURE() << "unknown field accepted";
  } catch (const GeometryError& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("extra"), std::string::npos) << e.what();
  }
  // Saving into a directory that does not exist names the path.
  const std::string unwritable = (TempPath("no_such_dir") / "x" / "shape.json").string();
  try {
    SaveShapeJson(Shape::Box(1, 1), unwritable);
    ADD_FAILURE() << "save into a missing directory succeeded";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(unwritable), std::string::npos) << e.what();
  }
}

TEST(ShapeJson, DuplicateKeysAreRefusedWithTheirPlace) {
  EXPECT_EQ(FindDuplicateJsonKey(R"({"a": 1, "b": {"c": [1, {"d": 2, "d": 3}]}})"), "duplicate key \"d\" in /b/c/1");
  EXPECT_EQ(FindDuplicateJsonKey(R"({"radius": 1, "radius": 2})"), "duplicate key \"radius\" in the top-level object");
  EXPECT_EQ(FindDuplicateJsonKey(R"({"a": {"x": 1}, "b": {"x": 1}, "c": [{"x": 1}, {"x": 2}]})"), "");
  EXPECT_EQ(FindDuplicateJsonKey("{not json"), "");
  try {
    ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [1, 0], [0, 1]]}], "radius": 0, "radius": 0.5})", "s.json");
    ADD_FAILURE() << "accepted";
  } catch (const GeometryError& e) {
    EXPECT_NE(std::string(e.what()).find("s.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("duplicate key \"radius\""), std::string::npos) << e.what();
  }
}

// NaN and Infinity written as numbers (Python's json.dump does) are named: the parser's own
// message, "invalid literal; last read: '0.4, N'", does not say what is wrong.
TEST(ShapeJson, NaNAndInfinityAreNamedInSyntaxErrors) {
  for (const char* text : {R"({"polygons": [{"outer": [[0, 0], [1, NaN], [0, 1]]}]})",
                           R"({"polygons": [{"outer": [[0, 0], [1, Infinity], [0, 1]]}]})",
                           R"({"polygons": [{"outer": [[0, 0], [1, -Infinity], [0, 1]]}]})"}) {
    try {
      ParseShapeJson(text, "s.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const GeometryError& e) {
      EXPECT_NE(std::string(e.what()).find("NaN or Infinity written as a number?"), std::string::npos) << e.what();
    }
  }
  try {
    ParseShapeJson(R"({"polygons": [{"outer": [[0, 0], [1, 0], [0, 1]]}], "radius": tru})", "s.json");
    ADD_FAILURE() << "accepted";
  } catch (const GeometryError& e) {
    EXPECT_EQ(std::string(e.what()).find("NaN"), std::string::npos) << e.what();  // another mistake, not named so
  }
}

}  // namespace
}  // namespace pushgraph::geometry
