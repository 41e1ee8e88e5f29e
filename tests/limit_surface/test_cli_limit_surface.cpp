// `pushgraph limit-surface`: the JSON contract, loads against the library and closed forms,
// and one-line errors with a non-zero exit status on bad input.
#include <pushgraph/limit_surface/limit_surface.h>

#include "tool_runner.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;

using pushgraph::testing::ToolRun;

class LimitSurfaceCli : public pushgraph::testing::ToolTest {
 protected:
  void SetUp() override {
    ToolTest::SetUp();
    square_ = Write("square.json", R"({"polygons": [{"outer": [[0,0],[0.09,0],[0.09,0.09],[0,0.09]]}]})");
  }

  ToolRun Exec(const std::string& args) { return ToolTest::Exec("limit-surface " + args); }

  void ExpectOneLineError(const std::string& args, const std::string& fragment) {
    const ToolRun run = Exec(args);
    EXPECT_NE(run.status, 0) << args;
    EXPECT_TRUE(run.out.empty()) << args;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find(fragment), std::string::npos) << run.err;
  }

  std::string square_;
};

TEST_F(LimitSurfaceCli, PrintsTheContract) {
  const ToolRun run = Exec(square_ + " --mass 0.8374 --mu 0.35 --twist 0.05,0,0 --twist -0.01,0.02,0.5 --twist 0,0,-2");
  ASSERT_EQ(run.status, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  const double N = 0.8374 * 9.80665;
  EXPECT_NEAR(j.at("area").get<double>(), 0.0081, 1e-17);
  EXPECT_NEAR(j.at("centroid")[0].get<double>(), 0.045, 1e-17);
  EXPECT_NEAR(j.at("normal_force").get<double>(), N, 1e-14);
  EXPECT_NEAR(j.at("f_max").get<double>(), 0.35 * N, 1e-14);
  EXPECT_NEAR(j.at("c").get<double>(), 0.034433807240890, 1e-14);
  EXPECT_NEAR(j.at("tau_max").get<double>(), 0.35 * N * 0.034433807240890, 1e-14);
  const auto& twists = j.at("twists");
  ASSERT_EQ(twists.size(), 3u);
  // Pure translation along x: the force is f_max along x, no torque about the centroid.
  EXPECT_NEAR(twists[0].at("force")[0].get<double>(), 0.35 * N, 1e-14);
  EXPECT_EQ(twists[0].at("torque").get<double>(), 0.0);
  EXPECT_EQ(twists[1].at("twist")[2].get<double>(), 0.5);
  // Clockwise spin: the torque is -tau_max.
  EXPECT_NEAR(twists[2].at("torque").get<double>(), -j.at("tau_max").get<double>(), 1e-15);
  // The mixed twist against the library.
  pushgraph::limit_surface::SupportSpec spec;
  spec.region = pushgraph::geometry::Shape::Box(0.09, 0.09);
  spec.mass = 0.8374;
  spec.mu = 0.35;
  const auto load = pushgraph::limit_surface::SustainingLoad(pushgraph::limit_surface::MakeSupport(spec), {-0.01, 0.02, 0.5});
  EXPECT_NEAR(twists[1].at("force")[0].get<double>(), load.force.x(), 1e-14);
  EXPECT_NEAR(twists[1].at("force")[1].get<double>(), load.force.y(), 1e-14);
  EXPECT_NEAR(twists[1].at("torque").get<double>(), load.torque, 1e-15);
}

TEST_F(LimitSurfaceCli, DiskAndEllipsoidReport) {
  const std::string disk = Write("disk.json", R"({"polygons": [{"outer": [[0.1, 0.2]]}], "radius": 0.0525})");
  const ToolRun run = Exec(disk + " --mass 0.8937 --mu 0.35 --gravity 9.81 --ellipsoid --samples 500");
  ASSERT_EQ(run.status, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_NEAR(j.at("c").get<double>(), 0.035, 1e-16);
  EXPECT_NEAR(j.at("normal_force").get<double>(), 0.8937 * 9.81, 1e-14);
  EXPECT_TRUE(j.at("twists").empty());
  const double mean = j.at("ellipsoid").at("paper").at("mean_direction_error_deg").get<double>();
  EXPECT_GT(mean, 3.0);
  EXPECT_LT(mean, 7.0);
}

TEST_F(LimitSurfaceCli, BadInputIsAOneLineError) {
  ExpectOneLineError(square_ + " --mass -1 --mu 0.3", "mass");
  ExpectOneLineError(square_ + " --mass 1 --mu 0", "mu");
  ExpectOneLineError(square_ + " --mass 1 --mu 0.3 --gravity -9.8", "gravity");
  ExpectOneLineError(square_ + " --mass 1 --mu 0.3 --twist 0,0,0", "twist");
  ExpectOneLineError(square_ + " --mass 1 --mu 0.3 --twist 1,2", "twist");
  ExpectOneLineError(square_ + " --mass 1 --mu 0.3 --twist 1,nan,2", "twist");
  ExpectOneLineError((dir_ / "missing.json").string() + " --mass 1 --mu 0.3", "missing.json");
  const std::string rounded = Write("rounded.json", R"({"polygons": [{"outer": [[0,0],[1,0],[1,1]]}], "radius": 0.1})");
  ExpectOneLineError(rounded + " --mass 1 --mu 0.3", "rounded");
  EXPECT_NE(Exec(square_ + " --mu 0.3").status, 0);  // --mass is required
  // --samples is read by --ellipsoid alone (it was ignored without it).
  ExpectOneLineError(square_ + " --mass 1 --mu 0.3 --samples 10", "--ellipsoid");
  // A sliver has exact values but no ellipsoid: said so (it was "the load must be finite and
  // non-zero" alone); without --ellipsoid it is reported.
  const std::string sliver = Write("sliver.json", R"({"polygons": [{"outer": [[0,0],[1,0],[2,1e-17]]}]})");
  ExpectOneLineError(sliver + " --mass 0.5 --mu 0.3 --ellipsoid --samples 200", "a region this thin");
  EXPECT_EQ(Exec(sliver + " --mass 0.5 --mu 0.3").status, 0);
}

// An OBJ mesh is read as its footprint (it was a raw JSON parse error), and a shape in other
// units is warned of (a mesh in millimetres gave a 90 m block, c = 34 m, without a word).
TEST_F(LimitSurfaceCli, MeshesAreReadAndOtherUnitsWarned) {
  const std::string mesh = Write("box.obj", "v 0 0 0\nv 0.09 0 0\nv 0.09 0.09 0\nv 0 0.09 0\nf 1 2 3 4\n");
  const ToolRun from_mesh = Exec(mesh + " --mass 1 --mu 0.3");
  ASSERT_EQ(from_mesh.status, 0) << from_mesh.err;
  const ToolRun from_json = Exec(square_ + " --mass 1 --mu 0.3");
  EXPECT_EQ(nlohmann::json::parse(from_mesh.out)["c"], nlohmann::json::parse(from_json.out)["c"]);
  EXPECT_EQ(from_json.err.find("across"), std::string::npos) << from_json.err;
  const std::string mm = Write("square_mm.json", R"({"polygons": [{"outer": [[0,0],[90,0],[90,90],[0,90]]}]})");
  const ToolRun in_mm = Exec(mm + " --mass 1 --mu 0.3");
  ASSERT_EQ(in_mm.status, 0) << in_mm.err;
  EXPECT_NE(in_mm.err.find("the shape is 90 m across: shapes are in metres (is the file in millimetres (pushgraph footprint "), std::string::npos)
      << in_mm.err;
  // A prism seen from the side: the command that reads its cross-section (this one has no --up).
  const std::string tip = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/obj/tip.obj";
  if (!std::ifstream(tip)) GTEST_SKIP() << "no MIT data";
  const ToolRun side = Exec(tip + " --mass 0.1 --mu 0.3");
  ASSERT_EQ(side.status, 0) << side.err;
  EXPECT_NE(side.err.find("pushgraph footprint " + tip + " --up y -o SHAPE.json gives its cross-section"), std::string::npos)
      << side.err;
}

}  // namespace
