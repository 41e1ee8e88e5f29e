// `pushgraph demo`, the README's first command: a simulated push with occlusion estimated by the
// CP, SDF and QS graphs; the table lists raw and all three, and QS beats the raw measurements.
#include "tool_runner.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using pushgraph::testing::ToolRun;
using DemoTest = pushgraph::testing::ToolTest;

// Rows of the error table: first word -> first number after it (object position RMS, mm).
std::map<std::string, double> ObjectErrors(const std::string& out) {
  std::map<std::string, double> rows;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string name, value;
    if (!(words >> name >> value)) continue;
    if (name != "raw" && name != "CP" && name != "SDF" && name != "QS") continue;
    rows[name] = std::stod(value);
  }
  return rows;
}

TEST_F(DemoTest, EstimationDemoPrintsAllModelsAndQsBeatsRawMeasurements) {
  const std::string svg = (dir_ / "pictures" / "demo.svg").string();  // the folder is created
  const ToolRun r = Exec("demo --data " PUSHGRAPH_SOURCE_DIR "/data --svg " + svg);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::map<std::string, double> errors = ObjectErrors(r.out);
  ASSERT_EQ(errors.size(), 4u) << r.out;
  for (const auto& [name, value] : errors) EXPECT_GT(value, 0.0) << name << "\n" << r.out;
  EXPECT_LT(errors.at("QS"), errors.at("raw")) << r.out;
  EXPECT_NE(r.out.find("occluded"), std::string::npos) << r.out;

  ASSERT_TRUE(fs::exists(svg));
  std::ifstream in(svg);
  std::stringstream text;
  text << in.rdbuf();
  const std::string picture = text.str();
  EXPECT_NE(picture.find("class='ellipse-object'"), std::string::npos);
  EXPECT_NE(picture.find("class='shaded'"), std::string::npos);  // the occlusion window
  for (const std::string label : {">CP<", ">SDF<", ">QS<", ">raw<"}) EXPECT_NE(picture.find(label), std::string::npos) << label;
}

TEST_F(DemoTest, GeometryDemoStaysReachable) {
  const std::string svg = (dir_ / "geometry.svg").string();
  const ToolRun r = Exec("demo --geometry --data " PUSHGRAPH_SOURCE_DIR "/data --svg " + svg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("0 of 20000 random points differ from brute force"), std::string::npos) << r.out;
  EXPECT_GT(fs::file_size(svg), 500u);
}

TEST_F(DemoTest, UnwritablePictureIsAnErrorNamingThePath) {
  const std::string file = Write("file", "x");
  const ToolRun r = Exec("demo --data " PUSHGRAPH_SOURCE_DIR "/data --svg " + file + "/demo.svg");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find(file + "/demo.svg"), std::string::npos) << r.err;
}

}  // namespace
