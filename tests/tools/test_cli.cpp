// Runs the pushgraph tool as a user would and checks the contracts of its subcommands.
#include <pushgraph/geometry/point_query.h>

#include "tool_runner.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using pushgraph::geometry::Vec2;

using pushgraph::testing::ToolRun;
using CliTest = pushgraph::testing::ToolTest;

const char* kSquareWithHole =
    R"({"polygons": [{"outer": [[0,0],[1,0],[1,1],[0,1]], "holes": [[[0.4,0.4],[0.4,0.6],[0.6,0.6],[0.6,0.4]]]}]})";

TEST_F(CliTest, DistancePrintsOneRowPerPointInOrderWithFullPrecision) {
  const std::string shape = Write("s.json", kSquareWithHole);
  const std::string pts = Write("p.csv", "x,y\n0.5,0.5\n2,2\n1,0.5\n0.3,0.3\n0.5,1e-13\n");
  const ToolRun r = Exec("distance " + shape + " " + pts);
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "x,y,signed_distance,closest_x,closest_y,normal_x,normal_y");
  const pushgraph::geometry::Shape s = pushgraph::geometry::ParseShapeJson(kSquareWithHole);
  const Vec2 expected_points[] = {{0.5, 0.5}, {2, 2}, {1, 0.5}, {0.3, 0.3}, {0.5, 1e-13}};
  for (const Vec2& p : expected_points) {
    ASSERT_TRUE(std::getline(lines, line));
    std::vector<double> v;
    std::stringstream fields(line);
    std::string f;
    while (std::getline(fields, f, ',')) v.push_back(std::stod(f));
    ASSERT_EQ(v.size(), 7u) << line;
    const auto q = pushgraph::geometry::QueryPoint(s, p);
    EXPECT_EQ(v[0], p.x());
    EXPECT_EQ(v[1], p.y());
    EXPECT_EQ(v[2], q.signed_distance) << "17 significant digits must round-trip";
    EXPECT_EQ(v[3], q.closest_point.x());
    EXPECT_EQ(v[4], q.closest_point.y());
    EXPECT_EQ(v[5], q.normal.x());
    EXPECT_EQ(v[6], q.normal.y());
  }
  EXPECT_FALSE(std::getline(lines, line));
}

TEST_F(CliTest, DistanceValuesAreTheExactOnes) {
  const std::string shape = Write("s.json", kSquareWithHole);
  const ToolRun r = Exec("distance " + shape + " " + Write("p.csv", "x,y\n1,0.5\n0.5,0.5\n"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\n1,0.5,0,1,0.5,1,0\n"), std::string::npos) << r.out;  // on the boundary: exactly 0
  // In the hole, 0.1 from its edge y = 0.6: the exact difference of the doubles 0.6 and 0.5.
  EXPECT_NE(r.out.find("0.5,0.5,0.099999999999999978,"), std::string::npos) << r.out;
}

TEST_F(CliTest, DistanceBadInputNamesFileAndLine) {
  const std::string shape = Write("s.json", kSquareWithHole);
  ToolRun r = Exec("distance " + shape + " " + Write("bad.csv", "x,y\n1,2\n3,abc\n"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bad.csv:3"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line on stderr: " << r.err;

  r = Exec("distance " + shape + " " + Write("far.csv", "x,y\n1,2\n\n1e300,0\n"));  // beyond the queries' range
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("far.csv:4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("outside the supported range"), std::string::npos) << r.err;
  // The value as read, not rounded to 6 digits (1.0000001e12 was printed "1e+12", in range).
  r = Exec("distance " + shape + " " + Write("edge.csv", "x,y\n1.0000001e12,0\n"));
  EXPECT_NE(r.err.find("point (1000000100000, 0) is outside the supported range"), std::string::npos) << r.err;
  // Beyond a double's range is not "not a number".
  r = Exec("distance " + shape + " " + Write("huge.csv", "x,y\n1e400,0\n"));
  EXPECT_NE(r.err.find("huge.csv:2: point: '1e400' is outside the range of a double"), std::string::npos) << r.err;

  // Spaces around a number and a spreadsheet's UTF-8 byte order mark are layout: the same rows
  // as a plain file ("0.01 ,0.02" was refused while " 0.01,0.02" was read; a BOM failed the
  // header with an invisible difference).
  const ToolRun plain = Exec("distance " + shape + " " + Write("plain.csv", "x,y\n0.01,0.02\n0.3,-0.1\n"));
  ASSERT_EQ(plain.status, 0) << plain.err;
  const ToolRun spaced = Exec("distance " + shape + " " + Write("spaced.csv", "x, y\n0.01 ,0.02\n 0.3 , -0.1 \n"));
  EXPECT_EQ(spaced.status, 0) << spaced.err;
  EXPECT_EQ(spaced.out, plain.out);
  const ToolRun bom = Exec("distance " + shape + " " + Write("bom.csv", "\xEF\xBB\xBFx,y\n0.01,0.02\n0.3,-0.1\n"));
  EXPECT_EQ(bom.status, 0) << bom.err;
  EXPECT_EQ(bom.out, plain.out);
  r = Exec("distance " + shape + " " + Write("inner.csv", "x,y\n0.0 1,0.02\n"));  // a space inside a number
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("inner.csv:2"), std::string::npos) << r.err;

  r = Exec("distance " + shape + " " + Write("nohdr.csv", "1,2\n"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("nohdr.csv:1"), std::string::npos) << r.err;

  r = Exec("distance " + Write("bow.json", R"({"polygons":[{"outer":[[0,0],[1,1],[1,0],[0,1]]}]})") + " " +
           Write("p.csv", "x,y\n0,0\n"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bow.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("polygon 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not simple"), std::string::npos) << r.err;

  r = Exec("distance " + (dir_ / "missing.json").string() + " " + Write("p.csv", "x,y\n"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;

  r = Exec("distance " + Write("nan.json", R"({"polygons":[{"outer":[[0,0],[1,0],[1,1]]}], "radius": 0, "extra": 1})") +
           " " + Write("p.csv", "x,y\n"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("unknown field \"extra\""), std::string::npos) << r.err;
}

TEST_F(CliTest, PenetrationJsonContractAndNegativeNumberOptions) {
  const std::string object = Write("o.json", kSquareWithHole);
  const std::string finger = Write("f.json", R"({"polygons":[{"outer":[[0,0]]}],"radius":0.1})");
  for (const std::string pose : {"--finger-pose=-0.05,0.5,1", "--finger-pose -0.05,0.5,1"}) {
    const ToolRun r = Exec("penetration " + object + " " + finger + " " + pose);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["intersecting"].get<bool>());
    EXPECT_NEAR(j["signed_distance"].get<double>(), -0.05, 1e-15);
    EXPECT_NEAR(j["depth"].get<double>(), 0.05, 1e-15);
    EXPECT_EQ(j["direction"][0].get<double>(), -1.0);
    EXPECT_EQ(j["direction"][1].get<double>(), 0.0);
    EXPECT_NEAR(j["finger_point"][0].get<double>(), 0.05, 1e-15);   // deepest finger point
    EXPECT_NEAR(j["object_point"][0].get<double>(), 0.0, 1e-15);    // its projection
    EXPECT_TRUE(j["depth_exact"].get<bool>());                       // it leaves along -x
  }
  // Centred 0.05 below the 0.2-wide hole, the 0.2-radius disk cannot leave into it ("core depth +
  // radius" would say 0.25, towards the hole): it leaves through the bottom edge, 0.55 down.
  const std::string big = Write("big.json", R"({"polygons":[{"outer":[[0,0]]}],"radius":0.2})");
  const ToolRun hole = Exec("penetration " + object + " " + big + " --finger-pose 0.5,0.35,0");
  ASSERT_EQ(hole.status, 0) << hole.err;
  const auto h = nlohmann::json::parse(hole.out);
  EXPECT_NEAR(h["depth"].get<double>(), 0.55, 1e-15);
  EXPECT_EQ(h["direction"][1].get<double>(), -1.0);
  EXPECT_TRUE(h["depth_exact"].get<bool>());
  const ToolRun apart = Exec("penetration " + object + " " + finger + " --object-pose 0,0,0 --finger-pose -0.3,0.5,0");
  ASSERT_EQ(apart.status, 0) << apart.err;
  const auto j = nlohmann::json::parse(apart.out);
  EXPECT_FALSE(j["intersecting"].get<bool>());
  EXPECT_TRUE(j["direction"].is_null());
  EXPECT_EQ(j["depth"].get<double>(), 0.0);
  EXPECT_NEAR(j["signed_distance"].get<double>(), 0.2, 1e-15);
}

TEST_F(CliTest, DirectoriesAsInputFilesAreNamedAsSuch) {
  const std::string object = Write("o.json", kSquareWithHole);
  const std::string dir = fs::path(object).parent_path().string();
  for (const std::string& args : {"footprint " + dir, "distance " + object + " " + dir, "distance " + dir + " " + dir,
                                 "penetration " + dir + " " + object}) {
    const ToolRun r = Exec(args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_NE(r.err.find("is a directory"), std::string::npos) << args << ": " << r.err;
  }
}

// File names need not be UTF-8 (a Latin-1 "caf\xe9.json"): the tool's JSON summary quotes them
// with U+FFFD instead of failing ("invalid UTF-8 byte") after the work was done.
TEST_F(CliTest, FileNamesThatAreNotUtf8AreWrittenAndQuoted) {
  const std::string dir = fs::path(Write("o.json", kSquareWithHole)).parent_path().string();
  const std::string push = dir + "/caf\xe9.json", result = dir + "/r\xe9sultat.json";
  ToolRun r = Exec("simulate -o '" + push + "' --distance 0.01");
  ASSERT_EQ(r.status, 0) << r.err;
  r = Exec("estimate '" + push + "' -o '" + result + "' --model cp");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(result));
  EXPECT_NE(r.out.find("\xef\xbf\xbd"), std::string::npos) << r.out;  // U+FFFD in the summary's output path
}

// The default simulated push (the notched block, whose holes lie 2 cm inside the pushed face)
// under the paper's noise: C's "contact point on the object's boundary" measured p against the
// nearest ring, so noisy contact rows pulled p onto a hole's edge and the object after it:
// noise seed 6 gave 7.10 mm against 6.16 mm raw, object NEES 73. Now the outer boundary.
TEST_F(CliTest, TheDefaultPushUnderThePapersNoiseBeatsTheRawData) {
  const std::string dir = fs::path(Write("o.json", kSquareWithHole)).parent_path().string();
  const std::string clean = dir + "/clean.json", result = dir + "/result.json";
  ToolRun r = Exec("simulate -o " + clean + " --noise none");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* seed : {"2", "6"}) {
    r = Exec("estimate " + clean + " --add-noise gaussian --seed " + seed + " -o " + result);
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream in(result);
    const nlohmann::json metrics = nlohmann::json::parse(in).at("metrics");
    const double estimate = metrics.at("object_position_rms").get<double>();
    const double raw = metrics.at("measured_object_position_rms").get<double>();
    std::printf("[default push, paper noise, seed %s] object %.2f mm (raw %.2f mm), NEES %.1f\n", seed, 1e3 * estimate,
                1e3 * raw, metrics.at("object_pose_nees").get<double>());
    EXPECT_LT(estimate, 0.5 * raw) << seed;
    EXPECT_LT(metrics.at("object_pose_nees").get<double>(), 10.0) << seed;
  }
}

// --finger on a two-finger trajectory file replaces finger 0's shape only, and says so.
TEST_F(CliTest, FingerOptionOnATwoFingerFileSaysWhatItReplaces) {
  const std::string left = Write("left.json", R"({"polygons": [{"outer": [[0, 0.02]]}], "radius": 0.004})");
  const std::string right = Write("right.json", R"({"polygons": [{"outer": [[0, -0.02]]}], "radius": 0.004})");
  const std::string dir = fs::path(left).parent_path().string();
  ToolRun r = Exec("simulate -o " + dir + "/two.json --fingers " + left + " " + right +
                   " --offset 0 --push-angle 0 --distance 0.01");
  ASSERT_EQ(r.status, 0) << r.err;
  r = Exec("estimate " + dir + "/two.json --finger " + left + " --model cp -o " + dir + "/two_result.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("--finger replaces finger 0's shape only"), std::string::npos) << r.err;
}

TEST_F(CliTest, PenetrationBadPoseIsOneClearLine) {
  const std::string object = Write("o.json", kSquareWithHole);
  const std::string finger = Write("f.json", R"({"polygons":[{"outer":[[0,0]]}],"radius":0.1})");
  for (const std::string bad : {"--finger-pose 1,2", "--finger-pose=1,2,x", "--object-pose nan,0,0"}) {
    const ToolRun r = Exec("penetration " + object + " " + finger + " " + bad);
    EXPECT_NE(r.status, 0) << bad;
    EXPECT_NE(r.err.find("pose"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  const ToolRun r = Exec("penetration " + object + " " + Write("pt.json", R"({"polygons":[{"outer":[[0,0]]}]})"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("rounding radius > 0"), std::string::npos) << r.err;
}

TEST_F(CliTest, DemoRunsOnShippedShapesAndWritesSvg) {
  const std::string svg = (dir_ / "demo.svg").string();
  const ToolRun r = Exec("demo --geometry --data " PUSHGRAPH_SOURCE_DIR "/data --svg " + svg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 of 20000 random points differ from brute force"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(svg));
  EXPECT_GT(fs::file_size(svg), 500u);
}

// An output that is an input (the same path, another spelling, a link) or another output is
// refused before any work, and the input is left as it was; written files replace the old ones
// whole, with no temporary file left beside them.
// A run ended by a signal (Ctrl-C in a long estimate) removes the copy of its piped input
// (it stayed in /tmp).
TEST_F(CliTest, APipedInputsCopyGoesWhenTheRunIsInterrupted) {
  const std::string long_push = (dir_ / "long.json").string();
  ASSERT_EQ(Exec("simulate -o " + long_push + " --duration 6").status, 0);
  const fs::path tmp = dir_ / "tmp";
  fs::create_directories(tmp);
  const std::string script =
      "export TMPDIR=" + tmp.string() + "; cat " + long_push + " | " + std::string(PUSHGRAPH_TOOL) +
      " estimate /dev/stdin --mode incremental -o " + (dir_ / "long_result.json").string() +
      " 2>/dev/null & pid=$!; i=0; while [ $i -lt 600 ] && [ -z \"$(ls " + tmp.string() +
      ")\" ]; do sleep 0.05; i=$((i+1)); done; sleep 0.2; kill -TERM $pid; wait $pid; echo $? > " +
      (dir_ / "status").string();
  EXPECT_EQ(std::system(("sh -c '" + script + "'").c_str()), 0) << script;
  std::ifstream status_file(dir_ / "status");
  int status = -1;
  status_file >> status;
  if (status == 0) {
    GTEST_SKIP() << "the estimate ended before the signal: nothing to check";
  }
  EXPECT_EQ(status, 128 + 15) << "terminated by SIGTERM";
  EXPECT_TRUE(fs::is_empty(tmp)) << fs::directory_iterator(tmp)->path();
}

TEST_F(CliTest, OutputsThatAreInputsAreRefusedAndInputsKept) {
  const std::string shape = Write("s.json", kSquareWithHole);
  const std::string dir = fs::path(shape).parent_path().string();
  fs::create_symlink(shape, dir_ / "link.json");
  const std::string traj = (dir_ / "t.json").string();
  ASSERT_EQ(Exec("simulate -o " + traj + " --duration 0.2").status, 0);
  const std::string traj_text = [&] {
    std::ifstream in(traj);
    std::stringstream t;
    t << in.rdbuf();
    return t.str();
  }();
  struct Case {
    std::string args, output_flag, input;
  };
  const std::vector<Case> cases = {
      {"footprint " + shape + " -o " + shape, "-o", shape},
      {"footprint " + shape + " -o " + dir + "/./s.json", "-o", shape},
      {"footprint " + shape + " -o " + (dir_ / "link.json").string(), "-o", shape},
      {"simulate --object " + shape + " -o " + shape, "-o", shape},
      {"estimate " + traj + " -o " + traj, "-o", traj},
      {"estimate " + traj + " -o " + (dir_ / "r.json").string() + " --svg " + traj, "--svg", traj},
      {"estimate " + traj + " -o " + (dir_ / "r.json").string() + " --svg " + (dir_ / "r.json").string(), "--svg", "-o"},
      {"mit-import " + traj + " --object " + shape + " --finger " + shape + " --mass 1 --mu-surface 0.3 -o " + shape, "-o", shape},
  };
  for (const Case& c : cases) {
    const ToolRun r = Exec(c.args);
    EXPECT_EQ(r.status, 1) << c.args;
    EXPECT_NE(r.err.find(c.output_flag), std::string::npos) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.input), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "r.json")) << c.args;
  }
  std::ifstream in(shape);
  std::stringstream kept;
  kept << in.rdbuf();
  EXPECT_EQ(kept.str(), kSquareWithHole);
  std::ifstream tin(traj);
  std::stringstream tkept;
  tkept << tin.rdbuf();
  EXPECT_EQ(tkept.str(), traj_text);
  // An empty output (or any empty value) is refused before any work: `-o ""` ran the whole
  // estimate and then failed to write.
  for (const std::string& args : {"estimate " + traj + " -o ''", "estimate " + traj + " -o r.json --config ''"}) {
    const ToolRun r = Exec(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find("an empty value"), std::string::npos) << args << ": " << r.err;
  }
  // Inputs from a pipe are read once (the HDF5 sniff and then the JSON reader each read
  // /dev/stdin, the second finding it empty: "unexpected end of input"), and the same for a
  // mesh, whose OBJ coordinates are read twice.
  {
    const std::string piped = (dir_ / "piped.json").string();
    const std::string cmd = "cat " + traj + " | " + std::string(PUSHGRAPH_TOOL) + " estimate /dev/stdin --model cp -o " + piped +
                            " 2>/dev/null";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_TRUE(fs::exists(piped));
    const std::string mesh = Write("box.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    const std::string fp = (dir_ / "fp.json").string();
    const std::string cmd2 = "cat " + mesh + " | " + std::string(PUSHGRAPH_TOOL) + " footprint /dev/stdin -q -o " + fp + " 2>/dev/null";
    EXPECT_EQ(std::system(cmd2.c_str()), 0) << cmd2;
    EXPECT_TRUE(fs::exists(fp));
  }
  // A real write replaces the file whole and leaves nothing else in the folder.
  const std::string out = (dir_ / "out.json").string();
  ASSERT_EQ(Exec("footprint " + shape + " -o " + out + " -q").status, 0);
  ASSERT_EQ(Exec("footprint " + shape + " --scale 2 -o " + out + " -q").status, 0);
  for (const auto& entry : fs::directory_iterator(dir_))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  // A turn given in degrees is taken as radians, and said so (90 rad = 116.6 degrees modulo 360).
  const ToolRun degrees = Exec("footprint " + shape + " --transform 0,0,90 -o " + (dir_ / "turned.json").string() + " -q");
  EXPECT_EQ(degrees.status, 0) << degrees.err;
  EXPECT_NE(degrees.err.find("THETA 90 is taken as radians"), std::string::npos) << degrees.err;
  EXPECT_NE(degrees.err.find("for degrees give 1.5707963267948966"), std::string::npos) << degrees.err;
  EXPECT_EQ(Exec("footprint " + shape + " --transform 0,0,1.5 -o " + (dir_ / "t2.json").string() + " -q").err, "");
  // The mesh options on a shape JSON are said to be ignored (they were, without a word).
  const ToolRun up = Exec("footprint " + shape + " --up y -o " + (dir_ / "up.json").string() + " -q");
  EXPECT_EQ(up.status, 0) << up.err;
  EXPECT_NE(up.err.find("--up reads meshes; " + shape + " is a shape JSON (a footprint already): ignored"), std::string::npos)
      << up.err;
  EXPECT_EQ(Exec("footprint " + shape + " --transform 0,0,6.2832 -o " + (dir_ / "t3.json").string() + " -q").err, "");
  const ToolRun millimetres = Exec("footprint " + shape + " --transform 20,0,0 -o " + (dir_ / "t4.json").string() + " -q");
  EXPECT_NE(millimetres.err.find("taken as metres"), std::string::npos) << millimetres.err;
  // A shape scaled to millimetres takes its shift in millimetres (the docs' example was told to give 0.02).
  const ToolRun scaled = Exec("footprint " + shape + " --scale 1000 --transform 20,-15,0.5 -o " + (dir_ / "t6.json").string() + " -q");
  EXPECT_EQ(scaled.err.find("taken as metres"), std::string::npos) << scaled.err;
  const ToolRun huge = Exec("footprint " + shape + " --scale 1000 -o " + (dir_ / "t5.json").string() + " -q");
  // The suggestion is relative to the file: here the --scale given was the error.
  EXPECT_NE(huge.err.find("is the file in millimetres (--scale 1 in place of the scale given"), std::string::npos)
      << huge.err;
  // A shape 100 times too large: the units that make it 1 cm to 1 m across, centimetres among them.
  const ToolRun centimetres = Exec("footprint " + shape + " --scale 100 -o " + (dir_ / "t6.json").string() + " -q");
  EXPECT_NE(centimetres.err.find("centimetres (--scale 1 in place"), std::string::npos) << centimetres.err;
}

TEST_F(CliTest, UnknownSubcommandsSeedsAndIgnoredSigmasAreNamed) {
  ToolRun r = Exec("frobnicate x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown subcommand 'frobnicate'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("estimate"), std::string::npos) << r.err;  // the list of subcommands
  const std::string out = (dir_ / "t.json").string();
  for (const std::string seed : {"-1", "18446744073709551616", "1.5", "x"}) {
    r = Exec("simulate -o " + out + " --duration 0.1 --seed " + seed);
    EXPECT_EQ(r.status, 2) << seed;
    EXPECT_NE(r.err.find("--seed: '" + seed + "'"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(out));
  r = Exec("simulate -o " + out + " --duration 0.1 --seed 18446744073709551615");
  EXPECT_EQ(r.status, 0) << r.err;
  r = Exec("simulate -o " + out + " --duration 0.1 --noise none --sigma-force 5");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--sigma-force 5 is given with --noise none"), std::string::npos) << r.err;
  // Physical flags outside the supported ranges: the flag is named (it was "support: mu must be ...").
  const std::string shape = (fs::path(PUSHGRAPH_SOURCE_DIR) / "data/shapes/notched_block.json").string();
  r = Exec("limit-surface " + shape + " --mass 1e308 --mu 0.3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--mass: must be a finite number in (0, 1e6] (kg), got 1e308"), std::string::npos) << r.err;
  r = Exec("limit-surface " + shape + " --mass 1 --mu -1");
  EXPECT_NE(r.err.find("--mu: must be a finite number in (0, 10], got -1"), std::string::npos) << r.err;
  r = Exec("simulate -o " + out + " --mu-surface 20");
  EXPECT_NE(r.err.find("--mu-surface: must be a finite number in (0, 10], got 20"), std::string::npos) << r.err;
}

// An evaluation killed mid-run keeps every finished trajectory's row (rows.jsonl.partial, written
// after each); --resume runs only the rest and ends with the rows of an uninterrupted run.
TEST_F(CliTest, AKilledEvaluationResumesWithoutRedoingFinishedTrajectories) {
  const fs::path killed = dir_ / "killed", straight = dir_ / "straight";
  const std::string args = " evaluate --simulate 6 --protocol table1 -q -j 1 --out ";
  const std::string start = std::string(PUSHGRAPH_TOOL) + args + killed.string() + " 2>/dev/null & echo $! > " +
                            (dir_ / "pid").string();
  ASSERT_EQ(std::system(start.c_str()), 0);
  const fs::path partial = killed / "rows.jsonl.partial";
  auto lines = [](const fs::path& p) {
    std::ifstream in(p);
    return static_cast<int>(std::count(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>(), '\n'));
  };
  for (int wait = 0; wait < 600 && lines(partial) < 3; ++wait) std::system("sleep 0.1");  // header + 2 rows
  std::ifstream pid_file(dir_ / "pid");
  int pid = 0;
  pid_file >> pid;
  ASSERT_GT(pid, 0);
  std::system(("kill -9 " + std::to_string(pid) + " 2>/dev/null; sleep 0.2").c_str());
  ASSERT_GE(lines(partial), 3) << "no rows were written before the kill";
  EXPECT_FALSE(fs::exists(killed / "rows.jsonl"));
  ToolRun r = Exec(args + killed.string() + " --resume");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("trajectories already done"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(partial));
  r = Exec(args + straight.string());
  ASSERT_EQ(r.status, 0) << r.err;
  auto text = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(text(killed / "table1.csv"), text(straight / "table1.csv"));
  EXPECT_EQ(lines(killed / "rows.jsonl"), 7);
  // Another run's folder is not taken for this one's.
  r = Exec(" evaluate --simulate 5 --protocol table1 -q -j 1 --out " + killed.string() + " --resume");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("was written by a run with other settings"), std::string::npos) << r.err;
}

}  // namespace
