// `pushgraph estimate`: RESULT.json layout (the issue's format) for every model and both modes,
// MIT recordings as input with added noise, and one-line errors for bad input.
#include <pushgraph/evaluation/result_json.h>
#include <pushgraph/io/trajectory_json.h>

#include "graph/push_generator.h"

#include "tool_runner.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace pushgraph::graph {
namespace {

nlohmann::json Load(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The tool runs with ToolTest's private folder per test (ctest runs tests in parallel processes).
class EstimateCli : public pushgraph::testing::ToolTest {
 protected:
  std::string dir() const { return dir_.string(); }
  pushgraph::testing::ToolRun Tool(const std::string& args) { return Exec(args); }
  std::string WritePush() {
    testing::PushSpec s;
    s.contact_offset = 0.015;
    s.duration = 0.6;
    const std::string path = dir() + "/estimate_push.json";
    io::SaveTrajectoryJson(testing::GeneratePush(s), path);
    return path;
  }
  // The MIT sample (../shared), or "" when it is not there.
  static std::string Mit() {
    const std::string shared = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";
    return std::ifstream(shared + "obj/rect1.obj") ? shared : "";
  }
  // A dataset mesh through `pushgraph footprint MESH FOOTPRINT_ARGS` (the user's file), and a
  // probe of `radius` metres; returns the estimate's run on `h5` with the paper's noise (and
  // `extra_args`), RESULT.json at `out`.
  pushgraph::testing::ToolRun EstimateMit(const std::string& h5, const std::string& mesh, const std::string& footprint_args,
                                          double radius, double mass, const std::string& out,
                                          const std::string& extra_args = "") {
    const std::string shape = dir() + "/user_shape.json", tip = dir() + "/user_probe.json";
    const pushgraph::testing::ToolRun f = Tool("footprint " + Mit() + "obj/" + mesh + " " + footprint_args + " -o " + shape);
    if (f.status != 0) return f;
    std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": )" << radius << "}";
    char args[64];
    std::snprintf(args, sizeof args, " --mass %g --mu 0.35", mass);
    return Tool("estimate '" + h5 + "' --object " + shape + " --finger " + tip + args + " --add-noise gaussian -o " + out +
                " " + extra_args);
  }
  // The dataset's `mesh` as a user might have it: every vertex scaled by `scale`, then x moved by
  // `dx`, written to this test's folder as `name`.
  std::string EditedMesh(const std::string& mesh, double scale, double dx, const std::string& name) {
    std::ifstream in(Mit() + "obj/" + mesh);
    const std::string path = dir() + "/" + name;
    std::ofstream out(path);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("v ", 0) == 0) {
        double x, y, z;
        std::istringstream(line.substr(2)) >> x >> y >> z;
        out << "v " << x * scale + dx << " " << y * scale << " " << z * scale << "\n";
      } else {
        out << line << "\n";
      }
    }
    return path;
  }
  // The mesh turned about x by `degrees` (-90: a z-up model exported with y up, (x, z, -y)), as a
  // user's exporter writes it.
  // `exact_quarter` false keeps the quarter turn's rounding (cos 90 deg = 6e-17), as some
  // exporters write it: seams 1e-18 m apart.
  std::string TurnedMesh(const std::string& mesh, double degrees, const std::string& name, bool exact_quarter = true,
                         double scale = 1.0) {
    std::ifstream in(Mit() + "obj/" + mesh);
    const std::string path = dir() + "/" + name;
    std::ofstream out(path);
    out.precision(17);
    const double c = std::cos(degrees * M_PI / 180.0), s = std::sin(degrees * M_PI / 180.0);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("v ", 0) == 0) {
        double x, y, z;
        std::istringstream(line.substr(2)) >> x >> y >> z;
        // A quarter turn's cosine is 6e-17, not 0: such terms are dropped, as an exporter does.
        const bool quarter = exact_quarter && std::abs(c) < 1e-12;
        const double yy = quarter ? -s * z : c * y - s * z, zz = quarter ? s * y : s * y + c * z;
        out << "v " << scale * x << " " << scale * yy << " " << scale * zz << "\n";
      } else {
        out << line << "\n";
      }
    }
    return path;
  }
  // The dataset's mesh as a CAD tool exports it: a binary STL (float32), its coordinates times `scale`.
  std::string StlExport(const std::string& mesh, double scale, const std::string& name) {
    std::vector<std::array<float, 3>> vertices;
    std::vector<std::array<float, 12>> facets;
    std::ifstream in(Mit() + "obj/" + mesh);
    for (std::string line; std::getline(in, line);) {
      std::istringstream s(line);
      std::string kind;
      s >> kind;
      if (kind == "v") {
        double x, y, z;
        s >> x >> y >> z;
        vertices.push_back({static_cast<float>(x * scale), static_cast<float>(y * scale), static_cast<float>(z * scale)});
      } else if (kind == "f") {
        std::vector<int> face;
        for (std::string token; s >> token;) face.push_back(std::stoi(token.substr(0, token.find('/'))) - 1);
        for (std::size_t k = 1; k + 1 < face.size(); ++k) {
          std::array<float, 12> f{};
          for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) f[3 + 3 * c + a] = vertices[face[c == 0 ? 0 : k + c - 1]][a];
          facets.push_back(f);
        }
      }
    }
    const std::string path = dir() + "/" + name;
    std::ofstream out(path, std::ios::binary);
    const std::string header(80, ' ');
    out.write(header.data(), 80);
    const std::uint32_t count = static_cast<std::uint32_t>(facets.size());
    out.write(reinterpret_cast<const char*>(&count), 4);
    for (const auto& f : facets) {
      out.write(reinterpret_cast<const char*>(f.data()), 48);
      out.write("\0\0", 2);
    }
    return path;
  }
  // The largest difference of the object poses' first `components` (x, y, theta) of two results
  // with the same steps.
  static double LargestObjectPoseDifference(const nlohmann::json& a, const nlohmann::json& b, int components = 3) {
    EXPECT_EQ(a["states"].size(), b["states"].size());
    double largest = 0.0;
    for (std::size_t i = 0; i < a["states"].size() && i < b["states"].size(); ++i)
      for (int k = 0; k < components; ++k)
        largest = std::max(largest, std::abs(a["states"][i]["object_pose"][k].get<double>() -
                                             b["states"][i]["object_pose"][k].get<double>()));
    return largest;
  }
  static constexpr double kRect1Mass = 0.8374, kEllip1Mass = 0.8937, kProbe = 0.0047;
};

TEST_F(EstimateCli, WritesTheResultFormatForEveryModelAndMode) {
  const std::string in = WritePush();
  for (const std::string model : {"cp", "sdf", "qs", "yu"}) {
    for (const std::string mode : {"batch", "incremental"}) {
      const std::string out = dir() + "/result_" + model + "_" + mode + ".json";
      const pushgraph::testing::ToolRun r = Tool("estimate " + in + " --model " + model + " --mode " + mode + " -o " + out);
      ASSERT_EQ(r.status, 0) << r.err;
      const nlohmann::json j = Load(out);
      EXPECT_EQ(j["model"], model);
      EXPECT_EQ(j["mode"], mode);
      ASSERT_EQ(j["states"].size(), 151u);  // 0.6 s on the 250 Hz clock
      const auto& s = j["states"][75];
      EXPECT_DOUBLE_EQ(s["t"].get<double>(), 0.3);
      EXPECT_EQ(s["object_pose"].size(), 3u);
      EXPECT_EQ(s["finger_pose"].size(), 3u);
      EXPECT_EQ(s["contact"].size(), 2u);
      EXPECT_EQ(s["object_pose_cov"].size(), 3u);
      EXPECT_EQ(s["object_pose_cov"][0].size(), 3u);
      EXPECT_EQ(s["contact_cov"].size(), 2u);
      const bool forces = model == "qs" || model == "yu";
      EXPECT_EQ(s.contains("force"), forces);
      EXPECT_EQ(s.contains("force_cov"), forces);
      EXPECT_GT(j["solver"]["iterations"].get<int>(), 0);
      EXPECT_GE(j["solver"]["time_s"].get<double>(), 0.0);
      // The whole call (shape check, estimate, diagnostics) includes the estimate.
      EXPECT_GE(j["solver"]["total_time_s"].get<double>(), j["solver"]["time_s"].get<double>());
      EXPECT_GE(j["solver"]["final_cost"].get<double>(), 0.0);
      EXPECT_LT(j["metrics"]["object_position_rms"].get<double>(), j["metrics"]["measured_object_position_rms"].get<double>());
    }
  }
}

// The simulator's shortest push (0.02 s, one 25 Hz object sample): its streams are on one clock,
// and only the sample count is worth a word (it was told its clocks were probably offset).
TEST_F(EstimateCli, AShortPushOnOneClockIsNotCalledOffset) {
  const std::string in = dir() + "/tiny.json", out = dir() + "/tiny_result.json";
  ASSERT_EQ(Tool("simulate -o " + in + " --distance 0.0005 --standoff 0.0005 --seed 5").status, 0);
  const pushgraph::testing::ToolRun r = Tool("estimate " + in + " -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("share no time"), std::string::npos) << r.err;
}

// A 3 s gap in the object's tracker during a slow push (helper-38's file): the batch QS estimate
// either follows the push through it or says that its object outran the finger there (it slid
// 52 mm along its edge at 0.5 m/s, 20.6 mm RMS against the tracker's 2.6, with no word); the
// incremental mode and a push with the camera on say nothing.
TEST_F(EstimateCli, AnObjectThatOutrunsItsPusherWhereTheTrackerIsSilentIsSaid) {
  const std::string in = dir() + "/slow.json", gap = dir() + "/slow_gap.json";
  ASSERT_EQ(Tool("simulate -o " + in + " --distance 0.2 --speed 0.02 --seed 4").status, 0);
  push::Trajectory t = io::LoadTrajectoryJson(in);
  auto& object = t.measured.object_pose;
  object.erase(std::remove_if(object.begin(), object.end(), [](const push::PoseSample& p) { return p.t > 3.0 && p.t < 6.0; }),
               object.end());
  io::SaveTrajectoryJson(t, gap);
  for (const std::string mode : {"batch", "incremental"}) {
    const std::string out = dir() + "/slow_gap_" + mode + ".json";
    const pushgraph::testing::ToolRun r = Tool("estimate " + gap + " --mode " + mode + " -o " + out);
    ASSERT_EQ(r.status, 0) << r.err;
    const double rms = Load(out)["metrics"]["object_position_rms"].get<double>();
    const bool said = r.err.find("object unobserved: between t = 3") != std::string::npos;
    std::printf("[gap] %s: object %.2f mm, %s\n", mode.c_str(), 1e3 * rms, said ? "said" : "not said");
    EXPECT_TRUE(said || rms < 5e-3) << mode << ": " << 1e3 * rms << " mm with no word\n" << r.err;
    if (said) EXPECT_NE(r.err.find("a pushed object cannot outrun its pusher"), std::string::npos) << r.err;
    if (rms < 5e-3) EXPECT_FALSE(said) << r.err;
  }
  const pushgraph::testing::ToolRun whole = Tool("estimate " + in + " -o " + dir() + "/slow_result.json");
  ASSERT_EQ(whole.status, 0) << whole.err;
  EXPECT_EQ(whole.err.find("object unobserved"), std::string::npos) << whole.err;
}

// A degraded occlusion window is noisier than the one sigma per stream the file records: the
// simulator says so, and the robust object loss it points to bounds the estimate there.
TEST_F(EstimateCli, ADegradedOcclusionIsNotedAndARobustLossBoundsIt) {
  const std::string in = dir() + "/degrade.json", cfg = dir() + "/cauchy.json";
  const pushgraph::testing::ToolRun sim = Tool("simulate -o " + in + " --occlusion 0.3,0.8 --occlusion-mode degrade --seed 4");
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_NE(sim.err.find("note: --occlusion-mode degrade: inside the windows the object's noise is 10 times"), std::string::npos)
      << sim.err;
  std::ofstream(cfg) << R"({"losses": {"object_pose": {"type": "cauchy", "scale": 2}}})";
  ASSERT_EQ(Tool("estimate " + in + " -o " + dir() + "/as_given.json").status, 0);
  ASSERT_EQ(Tool("estimate " + in + " --config " + cfg + " -o " + dir() + "/robust.json").status, 0);
  const nlohmann::json a = Load(dir() + "/as_given.json")["metrics"], b = Load(dir() + "/robust.json")["metrics"];
  std::printf("[degrade] object %.2f mm, NEES %.1f as given; %.2f mm, NEES %.1f with the Cauchy loss\n",
              1e3 * a["object_position_rms"].get<double>(), a["object_pose_nees"].get<double>(),
              1e3 * b["object_position_rms"].get<double>(), b["object_pose_nees"].get<double>());
  EXPECT_LT(b["object_position_rms"].get<double>(), 0.5 * a["object_position_rms"].get<double>());
  EXPECT_LT(b["object_pose_nees"].get<double>(), 0.1 * a["object_pose_nees"].get<double>());
}

TEST_F(EstimateCli, ConfigFileIsApplied) {
  const std::string in = WritePush();
  const std::string cfg = dir() + "/estimate_cfg.json";
  std::ofstream(cfg) << R"({"covariance": false, "losses": {"force": {"type": "cauchy", "scale": 2}}})";
  const std::string out = dir() + "/result_cfg.json";
  ASSERT_EQ(Tool("estimate " + in + " --model qs -o " + out + " --config " + cfg).status, 0);
  EXPECT_FALSE(Load(out)["states"][10].contains("object_pose_cov"));
  // c and mu estimated: RESULT.json's "parameters" carries both with their sigmas.
  const std::string joint = dir() + "/estimate_joint.json";
  std::ofstream(joint) << R"({"estimate_c": true, "estimate_mu": true})";
  const pushgraph::testing::ToolRun joint_run = Tool("estimate " + in + " --model qs -o " + out + " --config " + joint);
  ASSERT_EQ(joint_run.status, 0) << joint_run.err;
  const nlohmann::json printed = nlohmann::json::parse(joint_run.out);  // the summary line echoes them
  EXPECT_TRUE(printed.contains("mu_sigma") && printed.contains("c_sigma")) << joint_run.out;
  const nlohmann::json p = Load(out)["parameters"];
  EXPECT_TRUE(p["c_estimated"].get<bool>());
  EXPECT_TRUE(p["mu_estimated"].get<bool>());
  EXPECT_GT(p["c_sigma"].get<double>(), 0.0);
  EXPECT_GT(p["mu_sigma"].get<double>(), 0.0);
  EXPECT_NEAR(p["mu"].get<double>(), 0.25, 0.05);  // the push generator's mu
  // Batch only: the incremental mode refuses with one line.
  const pushgraph::testing::ToolRun r = Tool("estimate " + in + " --model qs --mode incremental -o " + out + " --config " + joint);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("batch only"), std::string::npos) << r.err;
  // Default QS with a force stream: the load factor is off, so mu plays no part and is not reported.
  ASSERT_EQ(Tool("estimate " + in + " --model qs -o " + out).status, 0);
  EXPECT_FALSE(Load(out)["parameters"].contains("mu"));
  EXPECT_FALSE(Load(out)["parameters"]["c_estimated"].get<bool>());
  // The incremental mode reports the parameters its model used as batch does.
  const std::string load_on = dir() + "/load_on.json";
  std::ofstream(load_on) << R"({"limit_surface_load": "on", "covariance": false})";
  ASSERT_EQ(Tool("estimate " + in + " --model qs --mode incremental -o " + out + " --config " + load_on).status, 0);
  const nlohmann::json q = Load(out)["parameters"];
  EXPECT_GT(q["c"].get<double>(), 0.0);
  EXPECT_FALSE(q["c_estimated"].get<bool>());
  EXPECT_NEAR(q["mu"].get<double>(), 0.25, 1e-12);
  EXPECT_FALSE(q["mu_estimated"].get<bool>());
}

TEST_F(EstimateCli, BadInputGetsOneLineErrors) {
  const std::string in = WritePush();
  const std::string out = dir() + "/result_bad.json";
  pushgraph::testing::ToolRun r = Tool("estimate " + in + " --model qs3 -o " + out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("unknown model 'qs3'"), std::string::npos) << r.err;
  r = Tool("estimate " + in + " --mode online -o " + out);
  EXPECT_NE(r.err.find("unknown mode 'online'"), std::string::npos) << r.err;
  r = Tool("estimate /nonexistent/push.json -o " + out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("/nonexistent/push.json"), std::string::npos) << r.err;
  // No object measurements at all.
  push::Trajectory t = io::LoadTrajectoryJson(in);
  t.measured.object_pose.clear();
  const std::string empty = dir() + "/estimate_no_object.json";
  io::SaveTrajectoryJson(t, empty);
  r = Tool("estimate " + empty + " -o " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("no object pose measurements"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const std::string cfg = dir() + "/estimate_bad_cfg.json";
  std::ofstream(cfg) << R"({"window": 3})";
  r = Tool("estimate " + in + " -o " + out + " --config " + cfg);
  EXPECT_NE(r.err.find("'window'"), std::string::npos) << r.err;
  // A config value judged against the trajectory names the config file (it named the trajectory).
  const std::string long_c = dir() + "/estimate_long_c.json";
  std::ofstream(long_c) << R"({"c": 5})";
  r = Tool("estimate " + in + " -o " + out + " --config " + long_c);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find(long_c + ": c = 5 m is longer than the object reaches"), std::string::npos) << r.err;
  // An output that cannot be written is said before the work (it was said after the estimate).
  r = Tool("estimate " + in + " -o /nonexistent/dir/result.json");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("-o /nonexistent/dir/result.json: its folder /nonexistent/dir does not exist"), std::string::npos)
      << r.err;
  r = Tool("estimate " + in + " -o " + dir() + " --svg " + dir() + "/a.svg");
  EXPECT_NE(r.err.find("-o " + dir() + " is a folder"), std::string::npos) << r.err;
  r = Tool("estimate " + in + " -o " + out + " --svg /nonexistent/a.svg");
  EXPECT_NE(r.err.find("--svg /nonexistent/a.svg: its folder /nonexistent does not exist"), std::string::npos) << r.err;
}

// The data's measurement sigmas first, the configuration file's keys on top: a config that
// claims a 20x smaller object noise than the file's makes the covariances overconfident.
TEST_F(EstimateCli, ConfigOverridesTheDataMeasurementSigmas) {
  push::Trajectory t = io::LoadTrajectoryJson(WritePush());
  push::MeasurementSigmas sigmas;
  sigmas.object_trans = 0.005;
  sigmas.object_rot = 0.05;
  sigmas.finger_trans = 0.005;
  sigmas.finger_rot = 0.05;
  sigmas.contact = 0.005;
  sigmas.force = 0.5;
  t.measurement_sigmas = sigmas;
  const std::string in = dir() + "/estimate_sigmas.json";
  io::SaveTrajectoryJson(t, in);
  const std::string cfg = dir() + "/estimate_tight.json";
  std::ofstream(cfg) << R"({"object_pose_sigma_trans": 0.00025, "object_pose_sigma_rot": 0.0025})";
  const std::string plain = dir() + "/result_plain.json", tight = dir() + "/result_tight.json";
  ASSERT_EQ(Tool("estimate " + in + " --model cp -o " + plain).status, 0);
  ASSERT_EQ(Tool("estimate " + in + " --model cp -o " + tight + " --config " + cfg).status, 0);
  const double nees_plain = Load(plain)["metrics"]["object_pose_nees"].get<double>();
  const double nees_tight = Load(tight)["metrics"]["object_pose_nees"].get<double>();
  std::printf("[config over data sigmas] object NEES %.2f with the file's sigmas, %.2f with the config's\n",
              nees_plain, nees_tight);
  EXPECT_LT(nees_plain, 10.0);
  EXPECT_GT(nees_tight, 5.0 * nees_plain);
}

// Forces whose size nothing fixes (no force stream, no limit-surface load) are not reported:
// RESULT.json has no force and a warning says why, also on stderr.
TEST_F(EstimateCli, ForcesWithoutAScaleAreLeftOutWithAWarning) {
  push::Trajectory t = io::LoadTrajectoryJson(WritePush());
  t.measured.force.clear();
  const std::string in = dir() + "/estimate_no_force.json";
  io::SaveTrajectoryJson(t, in);
  const std::string off = dir() + "/estimate_load_off.json";
  std::ofstream(off) << R"({"limit_surface_load": "off"})";
  const std::string out = dir() + "/result_no_force.json";
  for (const std::string& args : {"--model qs --config " + off, std::string("--model yu")}) {
    const pushgraph::testing::ToolRun r = Tool("estimate " + in + " -o " + out + " " + args);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("warning: forces not reported"), std::string::npos) << args << ": " << r.err;
    const nlohmann::json j = Load(out);
    ASSERT_TRUE(j.contains("warnings")) << args;
    for (const auto& s : j["states"]) EXPECT_FALSE(s.contains("force") || s.contains("force_cov")) << args;
  }
  // QS with the load factor (auto: no force stream, mass and mu known): forces reported.
  const pushgraph::testing::ToolRun r = Tool("estimate " + in + " --model qs -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(Load(out).contains("warnings"));  // only what sizes the forces
  ASSERT_EQ(Load(out)["warnings"].size(), 1u) << r.err;
  EXPECT_NE(r.err.find("no force stream: the qs model infers the forces"), std::string::npos) << r.err;
  EXPECT_TRUE(Load(out)["states"][75].contains("force"));
}

TEST_F(EstimateCli, RefusesInputsItWouldMisread) {
  const std::string in = WritePush();
  const std::string out = dir() + "/result_misread.json";
  // A directory.
  pushgraph::testing::ToolRun r = Tool("estimate " + dir() + " -o " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
  // Noise on streams that already carry it, with no ground truth to score against.
  push::Trajectory t = io::LoadTrajectoryJson(in);
  t.ground_truth.reset();
  t.measurement_sigmas = push::MeasurementSigmas{0.005, 0.05, 0.005, 0.05, 0.005, 0.5};
  const std::string noisy = dir() + "/estimate_noisy_no_truth.json";
  io::SaveTrajectoryJson(t, noisy);
  r = Tool("estimate " + noisy + " --add-noise gaussian -o " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("already carry noise"), std::string::npos) << r.err;
  // A non-physical mass or friction.
  r = Tool("estimate " + in + " --mass -1 -o " + out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--mass"), std::string::npos) << r.err;
  r = Tool("estimate " + in + " --mu -0.1 -o " + out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--mu"), std::string::npos) << r.err;
  // --mu-contact was removed (no factor used it): giving it is an error, not silently ignored.
  r = Tool("estimate " + in + " --mu-contact 0.3 -o " + out);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--mu-contact"), std::string::npos) << r.err;
  for (const std::string flag : {"--mass", "--mu"}) {  // CLI11's range checks pass NaN
    r = Tool("estimate " + in + " " + flag + " nan -o " + out);
    EXPECT_NE(r.status, 0) << flag;
    EXPECT_NE(r.err.find("must be a finite number"), std::string::npos) << flag << ": " << r.err;
  }
  // Duplicate time stamps name both rows.
  nlohmann::json doc = Load(in);
  doc["streams"]["finger_pose"][3][0] = doc["streams"]["finger_pose"][2][0];
  const std::string dup = dir() + "/estimate_dup.json";
  std::ofstream(dup) << doc.dump();
  r = Tool("estimate " + dup + " -o " + out);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("rows [2] and [3]"), std::string::npos) << r.err;
}

// Without a force stream (rect1's is frozen) the limit-surface load alone sets the forces' size,
// and nothing in the data checks it: the warning gives the load the mass makes. The dataset's
// rect1 mesh with 10 kg instead of 0.84 kg once drove the forces to 0.14 N at a load ratio of
// 19.8, which the self-diagnosis named; that was a bad minimum (forces started towards the
// object's origin, some of them pulling: cost 2894 in 164 iterations), not evidence of the mass.
// Since 2026-11-28 they start along the inward normal (cost 349 in 72 iterations), the load fits
// any mass, and the warning is what is left to say.
TEST_F(EstimateCli, AWrongMassWithoutAForceStreamIsNamed) {
  const std::string shared = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";
  const std::string h5 = shared + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  if (!std::ifstream(h5)) GTEST_SKIP() << "no MIT data at " << shared;
  const std::string shape = dir() + "/rect1_mesh.json", tip = dir() + "/tip_mass.json";
  ASSERT_EQ(Tool("footprint " + shared + "obj/rect1.obj -o " + shape).status, 0);
  std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.0047})";
  for (const char* mass : {"0.8374", "10"}) {
    const std::string out = dir() + "/mass_" + mass + ".json";
    const pushgraph::testing::ToolRun r = Tool("estimate '" + h5 + "' --object " + shape + " --finger " + tip + " --mass " +
                                               mass + " --mu 0.35 --add-noise gaussian -o " + out);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(std::string("no force stream: the qs model infers the forces from the object's sliding friction "
                                     "alone, which sizes them by mu_surface x mass x g = ") +
                         (std::string(mass) == "10" ? "34.3 N" : "2.88 N")),
              std::string::npos)
        << mass << ": " << r.err;
    EXPECT_NE(r.err.find(std::string("mass ") + mass + " kg, as given: nothing in the data checks them"), std::string::npos)
        << r.err;
  }
}

// The chain solver stopped on a step accepted at rho 0.03 (a change below the function
// tolerance because the step's model failed, not because the cost was flat): 1125.44 on this
// recording where Ceres went on to 1121.56 (object 1.126 against 1.038 mm). It now needs the
// model to agree (1120.70 here).
TEST_F(EstimateCli, TheChainSolverDoesNotStopOnAMispredictedStep) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=50_i=0.000_s=0.175_t=-0.349.h5";
  double cost[2];
  for (int k = 0; k < 2; ++k) {
    const std::string out = dir() + (k == 0 ? "/chain.json" : "/ceres.json");
    const pushgraph::testing::ToolRun r = EstimateMit(h5, "ellip1.obj", "", kProbe, kEllip1Mass, out,
                                                      std::string("--seed 3 --solver ") + (k == 0 ? "chain" : "ceres"));
    ASSERT_EQ(r.status, 0) << r.err;
    cost[k] = Load(out)["solver"]["final_cost"].get<double>();
  }
  std::printf("[solver] ellip1 v=50 t=-0.349: chain %.3f, Ceres %.3f\n", cost[0], cost[1]);
  EXPECT_LE(cost[0], cost[1] * (1.0 + 1e-4));
}

// mit-import keeps the contact phase as `estimate RECORDING.h5` does, so the two estimate the
// same samples: untrimmed, rect1's import had 606 steps against 272, its batch solve hit the
// iteration limit and turned a shape that fits by 1.9 degrees. --no-trim keeps every sample.
TEST_F(EstimateCli, MitImportTrimsToTheContactPhaseAsEstimateDoes) {
  const std::string shared = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";
  const std::string h5 = shared + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  if (!std::ifstream(h5)) GTEST_SKIP() << "no MIT data at " << shared;
  const std::string tip = dir() + "/tip_trim.json", trimmed = dir() + "/trimmed.json", all = dir() + "/untrimmed.json";
  std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.0047})";
  const std::string common = " --object " + shared + "obj/rect1.obj --finger " + tip + " --mass 0.8374 --mu-surface 0.35";
  ASSERT_EQ(Tool("mit-import '" + h5 + "'" + common + " -o " + trimmed).status, 0);
  ASSERT_EQ(Tool("mit-import '" + h5 + "'" + common + " --no-trim -o " + all).status, 0);
  const nlohmann::json a = Load(trimmed)["streams"], b = Load(all)["streams"];
  EXPECT_LT(a["object_pose"].size(), b["object_pose"].size());
  EXPECT_GT(a["object_pose"][0][0].get<double>(), b["object_pose"][0][0].get<double>());
  const std::string cfg = dir() + "/trim_cfg.json", direct = dir() + "/direct.json", imported = dir() + "/imported.json";
  std::ofstream(cfg) << R"({"covariance": false, "diagnostics": false})";
  ASSERT_EQ(Tool("estimate '" + h5 + "' --object " + shared + "obj/rect1.obj --finger " + tip +
                 " --mass 0.8374 --mu 0.35 --config " + cfg + " -o " + direct).status, 0);
  ASSERT_EQ(Tool("estimate " + trimmed + " --config " + cfg + " -o " + imported).status, 0);
  const nlohmann::json d = Load(direct)["states"], i = Load(imported)["states"];
  ASSERT_EQ(d.size(), i.size());
  EXPECT_DOUBLE_EQ(d[0]["t"].get<double>(), i[0]["t"].get<double>());
  EXPECT_DOUBLE_EQ(d.back()["t"].get<double>(), i.back()["t"].get<double>());
  // estimate's --no-trim keeps every sample as mit-import's does; a trajectory file has nothing to trim.
  const std::string untrimmed = dir() + "/direct_untrimmed.json";
  ASSERT_EQ(Tool("estimate '" + h5 + "' --no-trim --object " + shared + "obj/rect1.obj --finger " + tip +
                 " --mass 0.8374 --mu 0.35 --config " + cfg + " -o " + untrimmed).status, 0);
  const nlohmann::json u = Load(untrimmed)["states"];
  EXPECT_GT(u.size(), d.size());
  EXPECT_LT(u[0]["t"].get<double>(), d[0]["t"].get<double>());
  const pushgraph::testing::ToolRun refused = Tool("estimate " + trimmed + " --no-trim -o " + dir() + "/never.json");
  EXPECT_NE(refused.status, 0);
  EXPECT_NE(refused.err.find("--no-trim applies to MIT recordings"), std::string::npos) << refused.err;
}

// A user's mesh turned by 37 degrees, on the three rect1 recordings where it went wrong: the
// placements were ranked by graph costs capped at 25 iterations (the right turn still moving lost
// to "the finger 9.3 / 4.3 mm larger", 5.54 and 2.43 mm), and a misfit hidden within the gap
// tolerance was only suspected (1.73 mm). The mesh as shipped gives 1.09 to 1.23 mm there.
TEST_F(EstimateCli, AMeshTurnedBy37DegreesIsAligned) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string prefix = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=";
  for (const char* t : {"-1.396", "0.000", "0.349"}) {
    const std::string out = dir() + "/turned_" + t + ".json";
    const pushgraph::testing::ToolRun r =
        EstimateMit(prefix + t + ".h5", "rect1.obj", "--transform 0,0,0.6458", kProbe, kRect1Mass, out);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("aligned it"), std::string::npos) << t << ": " << r.err;
    EXPECT_EQ(r.err.find("alone)"), std::string::npos) << t << ": a turn of 37 degrees is no units error: " << r.err;
    const nlohmann::json j = Load(out);
    EXPECT_TRUE(j["parameters"].contains("shape_transform")) << t;
    const double rms = j["metrics"]["object_position_rms"].get<double>();
    std::printf("[registration] rect1 turned by 37 deg, t=%s: object RMS %.2f mm\n", t, rms * 1e3);
    EXPECT_LT(rms, 1.6e-3) << t;
  }
}

// The dataset's meshes given directly (--object rect1.obj --finger tip.obj) are read as
// `pushgraph footprint` reads them, the probe's cylinder (a prism along y) by its cross-section
// and then as the 4.7 mm disk it tessellates, and say so; the estimate is the one from the
// converted object file and a 4.7 mm disk probe. A mesh in another format is
// told which files are read (it was "malformed JSON" alone).
TEST_F(EstimateCli, MeshFilesAreReadDirectly) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const std::string mass = " --mass 0.8374 --mu 0.35 ";
  const pushgraph::testing::ToolRun direct = Tool("estimate '" + h5 + "' --object " + Mit() + "obj/rect1.obj --finger " +
                                                  Mit() + "obj/tip.obj" + mass + "-o " + dir() + "/direct.json");
  ASSERT_EQ(direct.status, 0) << direct.err;
  EXPECT_NE(direct.err.find("tip.obj: the mesh's footprint along y (a prism along it: its cross-section)"), std::string::npos)
      << direct.err;
  EXPECT_NE(direct.err.find("rect1.obj: the mesh's footprint along z, in its own frame and units"), std::string::npos)
      << direct.err;
  EXPECT_EQ(direct.err.find("side view"), std::string::npos) << direct.err;
  // Its 32-gon is the 4.7 mm disk it tessellates (a polygonal finger solves 6 to 13x slower on the MIT recordings).
  EXPECT_NE(direct.err.find("regular 32-gon, a tessellated cylinder: used as the disk of radius 4.7 mm at (0.000, 0.000)"),
            std::string::npos)
      << direct.err;
  // The command that keeps the polygon reads it along the same axis (without --up y it gave the side view).
  EXPECT_NE(direct.err.find("to keep the polygon: pushgraph footprint " + Mit() + "obj/tip.obj --up y -o SHAPE.json, and "
                            "\"tessellated_finger_as_disk\": false in --config"),
            std::string::npos)
      << direct.err;
  ASSERT_EQ(Tool("footprint " + Mit() + "obj/rect1.obj -q -o " + dir() + "/rect1.json").status, 0);
  std::ofstream(dir() + "/tip.json") << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.0047})";
  const pushgraph::testing::ToolRun converted = Tool("estimate '" + h5 + "' --object " + dir() + "/rect1.json --finger " +
                                                     dir() + "/tip.json" + mass + "-o " + dir() + "/converted.json");
  ASSERT_EQ(converted.status, 0) << converted.err;
  const nlohmann::json a = Load(dir() + "/direct.json"), b = Load(dir() + "/converted.json");
  // The same estimate up to the disk's radius from the mesh's rounded vertices (4.7 mm +- 1 um).
  // (A recording has no ground truth: the states are compared, not metrics.)
  ASSERT_EQ(a["states"].size(), b["states"].size());
  double largest = 0.0;
  for (std::size_t i = 0; i < a["states"].size(); ++i) {
    for (int k = 0; k < 2; ++k) {
      largest = std::max(largest, std::abs(a["states"][i]["object_pose"][k].get<double>() -
                                           b["states"][i]["object_pose"][k].get<double>()));
      largest = std::max(largest, std::abs(a["states"][i]["finger_pose"][k].get<double>() -
                                           b["states"][i]["finger_pose"][k].get<double>()));
    }
  }
  EXPECT_LT(largest, 2e-5);
  // What reading a mesh warns of is in RESULT.json too (it was on stderr alone): rect1.obj with a
  // second object holding one of its own faces (the same footprint, two objects united).
  {
    std::ifstream in(Mit() + "obj/rect1.obj");
    std::ofstream out(dir() + "/two_objects.obj");
    out << in.rdbuf() << "o second\nf 1 2 3\n";
  }
  ASSERT_EQ(Tool("estimate '" + h5 + "' --object " + dir() + "/two_objects.obj --finger " + dir() + "/tip.json" + mass +
                 "-o " + dir() + "/two.json")
                .status,
            0);
  const nlohmann::json two = Load(dir() + "/two.json");
  bool said = false;
  for (const auto& w : two["warnings"])
    said = said || w.get<std::string>().find("two_objects.obj: the file holds 2 objects or groups") != std::string::npos;
  EXPECT_TRUE(said) << two["warnings"].dump();
  // STL, PLY and OFF meshes are read too (an empty one says so); other files are told which are.
  std::ofstream(dir() + "/probe.stl") << "solid probe\nendsolid probe\n";
  const pushgraph::testing::ToolRun stl =
      Tool("estimate '" + h5 + "' --object " + dir() + "/probe.stl --finger " + dir() + "/tip.json" + mass + "-o " + dir() + "/x.json");
  EXPECT_EQ(stl.status, 1);
  EXPECT_NE(stl.err.find("probe.stl: the mesh has no faces (an empty STL file, or not STL)"), std::string::npos) << stl.err;
  std::ofstream(dir() + "/probe.3mf") << "PK\x03\x04";
  const pushgraph::testing::ToolRun other =
      Tool("estimate '" + h5 + "' --object " + dir() + "/probe.3mf --finger " + dir() + "/tip.json" + mass + "-o " + dir() + "/x.json");
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.err.find("meshes named .obj, .stl, .ply or .off are read directly"), std::string::npos) << other.err;
}

// The mesh in millimetres and nothing else: the placement found with the units (turned by 12.1
// degrees, shifted by (-5.0, -5.6) mm, sigmas 8.1 degrees, 4.8 and 2.4 mm) is within three sigmas
// of none, and saving it would bake the turn into the file (later recordings then accepted it:
// 1.69 against 1.23 mm), so the units alone are offered too.
// A mesh exported with y up (Blender's and glTF's convention) is a prism along y: read along z it
// is its 90 x 12.7 mm side view, and the estimate was 1.35 mm against 0.95 with the true mesh,
// with a warning only. The recording's contacts fit its cross-section along y, which is used,
// and said. Upside down (a turn of +90 degrees: its cross-section mirrored, the same square) and
// with align_shape off (the side view kept, and the warning) as well. A flat outline drawn in
// the x-z plane has one reading (it was refused with "--up y reads it", a flag estimate lacks).
TEST_F(EstimateCli, AMeshExportedWithYUpIsReadByItsCrossSection) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string rest = " --finger " + Mit() + "obj/tip.obj --model cp --mass 0.8374 --mu 0.35 -o ";
  ASSERT_EQ(Tool("estimate '" + h5 + "' --object " + Mit() + "obj/rect1.obj" + rest + dir() + "/z_up.json").status, 0);
  const nlohmann::json truth = Load(dir() + "/z_up.json");
  auto largest_difference = [&](const nlohmann::json& j) { return LargestObjectPoseDifference(j, truth); };
  for (const double degrees : {-90.0, 90.0}) {
    const std::string mesh = TurnedMesh("rect1.obj", degrees, "rect1_turned.obj");
    const std::string out = dir() + "/turned.json";
    const pushgraph::testing::ToolRun r = Tool("estimate '" + h5 + "' --object " + mesh + rest + out);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("contacts fit its cross-section along y, not its footprint along z (its side view): estimated "
                         "with the cross-section"),
              std::string::npos)
        << degrees << ": " << r.err;
    EXPECT_NE(r.err.find(mesh + " --up y -o SHAPE.json saves it"), std::string::npos) << r.err;
    const nlohmann::json j = Load(out);
    EXPECT_LT(largest_difference(j), 1e-6) << degrees;
    bool said = false;
    for (const auto& w : j["warnings"]) said = said || w.get<std::string>().find("cross-section along y") != std::string::npos;
    EXPECT_TRUE(said) << degrees << ": RESULT.json's warnings say it too";
  }
  const std::string y_up = TurnedMesh("rect1.obj", -90.0, "rect1_y_up.obj");
  // The probe exported with y up as well, its quarter turn rounded: a cylinder along z, whose
  // footprint's 32-gon has two seam vertices 1e-18 m apart (it was kept as a 34-gon polygon
  // finger, 6 to 13 times slower and not the disk).
  {
    const std::string tip = TurnedMesh("tip.obj", -90.0, "tip_y_up.obj", /*exact_quarter=*/false);
    const std::string both = "estimate '" + h5 + "' --object " + y_up + " --finger " + tip +
                             " --model cp --mass 0.8374 --mu 0.35 -o " + dir() + "/both.json";
    const pushgraph::testing::ToolRun r = Tool(both);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("regular 32-gon, a tessellated cylinder: used as the disk of radius 4.7 mm"), std::string::npos)
        << r.err;
    EXPECT_LT(largest_difference(Load(dir() + "/both.json")), 1e-6);
  }
  // In millimetres too (a CAD export): the command that saves the shape reads it along y and in
  // metres (it said "--scale 0.001" alone, which saves the side view).
  {
    const std::string y_up_mm = TurnedMesh("rect1.obj", -90.0, "rect1_y_up_mm.obj", true, 1000.0);
    const pushgraph::testing::ToolRun r = Tool("estimate '" + h5 + "' --object " + y_up_mm + rest + dir() + "/y_up_mm.json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("pushgraph footprint " + y_up_mm + " --up y --scale 0.001"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("pushgraph footprint " + y_up_mm + " --scale"), std::string::npos) << r.err;
  }
  const pushgraph::testing::ToolRun off = Tool("estimate '" + h5 + "' --object " + y_up + rest + dir() + "/off.json --align-shape off");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_NE(off.err.find("seen along z its footprint is its side view"), std::string::npos) << off.err;
  EXPECT_EQ(off.err.find("estimated with the cross-section"), std::string::npos) << off.err;
  // mit-import writes the reading its recording fits into the trajectory file.
  const pushgraph::testing::ToolRun imported = Tool("mit-import '" + h5 + "' --object " + y_up + " --finger " + Mit() +
                                                    "obj/tip.obj --mass 0.8374 --mu-surface 0.35 -o " + dir() + "/imported.json");
  ASSERT_EQ(imported.status, 0) << imported.err;
  const geometry::Box2 top = pushgraph::io::LoadTrajectoryJson(dir() + "/imported.json").object.shape.bounds();
  EXPECT_NEAR(top.max.y() - top.min.y(), 0.09, 1e-6) << "its cross-section, not the 12.7 mm side view";
  // The outline of rect1 drawn flat in the x-z plane (y = 0; (x, -z) is the footprint's (x, y)).
  const std::string flat = dir() + "/flat.obj";
  std::ofstream(flat) << "v -0.045 0 0.045\nv 0.045 0 0.045\nv 0.045 0 -0.045\nv -0.045 0 -0.045\nf 1 2 3\nf 1 3 4\n";
  const pushgraph::testing::ToolRun drawn = Tool("estimate '" + h5 + "' --object " + flat + rest + dir() + "/flat.json");
  ASSERT_EQ(drawn.status, 0) << drawn.err;
  EXPECT_NE(drawn.err.find("the mesh's footprint along y (an outline drawn flat across it)"), std::string::npos) << drawn.err;
  EXPECT_LT(largest_difference(Load(dir() + "/flat.json")), 2e-3) << "a sharp-cornered square for rect1";
}

// A CAD export as binary STL in millimetres, object and probe, was refused ("STL meshes are not
// read, only Wavefront OBJ"): now read directly, in the units its contacts fit, and estimated as
// the dataset's OBJ files in metres are (float32 coordinates: 2e-9 m).
TEST_F(EstimateCli, AnStlExportInMillimetresIsReadDirectly) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string rest = " --model cp --mass 0.8374 --mu 0.35 -o ";
  const pushgraph::testing::ToolRun stl = Tool("estimate '" + h5 + "' --object " + StlExport("rect1.obj", 1000.0, "rect1.stl") +
                                               " --finger " + StlExport("tip.obj", 1000.0, "tip.stl") + rest + dir() + "/stl.json");
  ASSERT_EQ(stl.status, 0) << stl.err;
  EXPECT_NE(stl.err.find("tip.stl: its footprint is a regular 32-gon, a tessellated cylinder"), std::string::npos) << stl.err;
  const pushgraph::testing::ToolRun obj = Tool("estimate '" + h5 + "' --object " + Mit() + "obj/rect1.obj --finger " + Mit() +
                                               "obj/tip.obj" + rest + dir() + "/obj.json");
  ASSERT_EQ(obj.status, 0) << obj.err;
  const nlohmann::json a = Load(dir() + "/stl.json"), b = Load(dir() + "/obj.json");
  EXPECT_EQ(a["parameters"]["shape_scale"].get<double>(), 1e-3);
  EXPECT_EQ(a["parameters"]["finger_scale"].get<double>(), 1e-3);
  EXPECT_LT(LargestObjectPoseDifference(a, b), 1e-6);
}

TEST_F(EstimateCli, AMeshInMillimetresIsOfferedItsUnitsAlone) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "--scale 1000", kProbe, kRect1Mass, dir() + "/mm.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the file is in millimetres"), std::string::npos) << r.err;
  // The file the user gave, not a placeholder.
  EXPECT_NE(r.err.find("pushgraph footprint " + dir() + "/user_shape.json --scale 0.001 alone"), std::string::npos) << r.err;
  // Estimated as given (alignment off), the self-diagnosis' gap of 5748.5 mm was put on the probe
  // alone ("a finger radius 5748.5 mm smaller would touch"); it now points at the shape check's finding.
  const pushgraph::testing::ToolRun off =
      EstimateMit(h5, "rect1.obj", "--scale 1000", kProbe, kRect1Mass, dir() + "/mm_off.json", "--align-shape off");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_NE(off.err.find("the file is in millimetres"), std::string::npos) << off.err;
  EXPECT_NE(off.err.find("the shape check above found the shape as given off"), std::string::npos) << off.err;
}

// A mesh shifted 40 mm along the pushed side fits the contacts as given (they do not fix the
// position along that side) and raised at most a suggestion: 2.47 mm against 0.95 mm with the
// mesh as shipped, raw 7.3 mm. The push's mechanics place it: the shape as given with the frame
// free in the graph costs 429.3 against 505.7 as given, and is used.
TEST_F(EstimateCli, AMeshShiftedAlongThePushedSideIsPlacedByTheMechanics) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const std::string out = dir() + "/along.json";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "--transform 0.04,0,0", kProbe, kRect1Mass, out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the whole graph (the push's mechanics) places it elsewhere"), std::string::npos) << r.err;
  const nlohmann::json j = Load(out);
  EXPECT_TRUE(j["shape"]["aligned"].get<bool>());
  const double rms = j["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] rect1 shifted 40 mm along the pushed side: object RMS %.2f mm\n", rms * 1e3);
  EXPECT_LT(rms, 1.3e-3);
}

// The notched block turned by 30 degrees, one simulated push along a straight stretch of it: the
// contacts fit several placements, and the solves of some (the one near the truth among them)
// stalled where a contact feature switches, so the whole graph's costs do not rank them. It was
// "aligned" by -125 degrees "(sigma 1.5 deg, 0.8 and 0.4 mm)"; now the placement is said to be
// unsettled, RESULT.json's shape_transform_sigma is null and the curvature's sigmas are kept
// apart as shape.local_transform_sigma.
TEST_F(EstimateCli, AnUnsettledPlacementGetsNoSigma) {
  const std::string push = dir() + "/notched.json", given = dir() + "/notched_shape.json",
                    turned = dir() + "/notched_r30.json", out = dir() + "/unsettled.json";
  ASSERT_EQ(Tool("simulate -o " + push + " --seed 1").status, 0);
  std::ofstream(given) << Load(push)["object"]["shape"].dump();
  ASSERT_EQ(Tool("footprint " + given + " --transform 0,0,0.5235987756 -o " + turned + " -q").status, 0);
  const pushgraph::testing::ToolRun r = Tool("estimate " + push + " --object " + turned + " -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(out);
  ASSERT_TRUE(j["shape"]["aligned"].get<bool>()) << r.err;
  EXPECT_FALSE(j["shape"]["placement_settled"].get<bool>()) << r.err;
  EXPECT_FALSE(j["shape"]["placement_unsettled_by"].get<std::string>().empty());
  EXPECT_TRUE(j["parameters"]["shape_transform_sigma"].is_null());
  EXPECT_EQ(j["shape"]["local_transform_sigma"].size(), 3u);
  EXPECT_NE(r.err.find("(not settled: "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("(sigma "), std::string::npos) << r.err;
  // A rect1 recording with its mesh turned by 37 degrees: one placement, settled, with sigmas.
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const std::string settled_out = dir() + "/settled.json", shape = dir() + "/rect1_r37.json", tip = dir() + "/probe.json";
  ASSERT_EQ(Tool("footprint " + Mit() + "obj/rect1.obj --transform 0,0,0.6458 -o " + shape + " -q").status, 0);
  std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.00475})";
  const pushgraph::testing::ToolRun s = Tool("estimate '" + h5 + "' --object " + shape + " --finger " + tip +
                                             " --mass 0.8374 --mu 0.35 -o " + settled_out);
  ASSERT_EQ(s.status, 0) << s.err;
  const nlohmann::json k = Load(settled_out);
  ASSERT_TRUE(k["shape"]["aligned"].get<bool>()) << s.err;
  EXPECT_TRUE(k["shape"]["placement_settled"].get<bool>()) << k["shape"].dump();
  EXPECT_EQ(k["parameters"]["shape_transform_sigma"].size(), 3u);
  EXPECT_NE(s.err.find("(sigma "), std::string::npos) << s.err;
}

// The true ellip1 mesh on its longest recording (2061 steps at 20 mm/s, as recorded): with the
// frame free the graph gained 28.4 (the model's own error on real data grows with the length)
// and the mesh was "aligned" by a 12 mm shift, where the two pushes at the same spot put it
// within 1.5 mm. The frame check's margin grows with the steps (0.02 a step, at least 20).
TEST_F(EstimateCli, ATrueMeshOnALongRecordingIsNotMovedByTheFrameCheck) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=20_i=0.000_s=0.675_t=0.349.h5";
  const std::string shape = dir() + "/ellip1_true.json", tip = dir() + "/probe_true.json", out = dir() + "/long.json";
  ASSERT_EQ(Tool("footprint " + Mit() + "obj/ellip1.obj -o " + shape).status, 0);
  std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.0047})";
  const pushgraph::testing::ToolRun r =
      Tool("estimate '" + h5 + "' --object " + shape + " --finger " + tip + " --mass 0.8937 --mu 0.35 -o " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(out);
  EXPECT_FALSE(j["shape"]["aligned"].get<bool>()) << r.err;
  EXPECT_FALSE(j["parameters"].contains("shape_transform")) << r.err;
  bool noted = false;
  for (const auto& n : j["shape"]["notes"]) noted = noted || n.get<std::string>().find("on 2061 steps") != std::string::npos;
  EXPECT_TRUE(noted) << j["shape"]["notes"].dump();
}

// The shape frame as a variable of the graph starts from a converged estimate. ellip1 is a
// circle, so the contacts fix its frame only across the short stretch the probe touches, and CP
// has no mechanics to place it by. Freed together with everything else, the frame drifted while
// the contacts were still far from their solution: the true mesh under align_shape "on" was
// moved by 53 mm "(sigma 2.4 and 1.2 mm)", 300 iterations to a cost of 879.6 against 794.2 with
// the frame held, object RMS 1.55 mm against 1.35 as given; the mesh shifted by 36 mm, aligned
// under auto, gave 2.8 mm against 1.1 mm with the true mesh on another recording.
TEST_F(EstimateCli, TheGraphsShapeFrameIsFreedOnlyFromAConvergedEstimate) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=50_i=0.000_s=0.175_t=-0.349.h5";
  const std::string on = dir() + "/on.json", shifted = dir() + "/shifted.json", given = dir() + "/given.json";
  const pushgraph::testing::ToolRun g = EstimateMit(h5, "ellip1.obj", "", kProbe, kEllip1Mass, given, "--model cp --align-shape off");
  ASSERT_EQ(g.status, 0) << g.err;
  const double given_rms = Load(given)["metrics"]["object_position_rms"].get<double>();
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "ellip1.obj", "", kProbe, kEllip1Mass, on, "--model cp --align-shape on");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(on);
  ASSERT_TRUE(j["shape"]["aligned"].get<bool>()) << r.err;
  const auto& t = j["parameters"]["shape_transform"];
  const double moved = std::hypot(t[0].get<double>(), t[1].get<double>());
  const double rms = j["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] true ellip1 mesh, CP, frame refined: moved %.1f mm, object RMS %.2f mm (as given %.2f)\n",
              moved * 1e3, rms * 1e3, given_rms * 1e3);
  EXPECT_LT(moved, 5e-3) << r.err;
  EXPECT_LT(rms, given_rms + 1e-4) << r.err;
  EXPECT_EQ(r.err.find("iteration limit"), std::string::npos) << r.err;
  // A solve stopped at its iteration limit is short of a minimum: its curvature is no sigma.
  const std::string capped = dir() + "/capped.json", config = dir() + "/capped_config.json";
  std::ofstream(config) << R"({"max_iterations": 3})";
  const pushgraph::testing::ToolRun c =
      EstimateMit(h5, "ellip1.obj", "", kProbe, kEllip1Mass, capped, "--model cp --align-shape on --config " + config);
  ASSERT_EQ(c.status, 0) << c.err;
  const nlohmann::json cj = Load(capped);
  ASSERT_TRUE(cj["shape"]["aligned"].get<bool>()) << c.err;
  EXPECT_FALSE(cj["shape"]["placement_settled"].get<bool>()) << c.err;
  EXPECT_TRUE(cj["parameters"]["shape_transform_sigma"].is_null()) << c.err;
  EXPECT_NE(c.err.find("the solve with the frame free stopped at its iteration limit"), std::string::npos) << c.err;
  // A recording whose contacts leave the shift across them open: the mesh shifted by 36 mm is
  // aligned back, and estimated as with the true mesh.
  const std::string h5b = Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=100_i=0.000_s=0.075_t=0.698.h5";
  const pushgraph::testing::ToolRun gb = EstimateMit(h5b, "ellip1.obj", "", kProbe, kEllip1Mass, given, "--model cp");
  ASSERT_EQ(gb.status, 0) << gb.err;
  const double true_rms = Load(given)["metrics"]["object_position_rms"].get<double>();
  const pushgraph::testing::ToolRun s =
      EstimateMit(h5b, "ellip1.obj", "--transform 0.036,0,0", kProbe, kEllip1Mass, shifted, "--model cp");
  ASSERT_EQ(s.status, 0) << s.err;
  const nlohmann::json k = Load(shifted);
  ASSERT_TRUE(k["shape"]["aligned"].get<bool>()) << s.err;
  const double shifted_rms = k["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] ellip1 mesh shifted 36 mm, CP: object RMS %.2f mm (true mesh %.2f)\n", shifted_rms * 1e3,
              true_rms * 1e3);
  EXPECT_LT(shifted_rms, true_rms + 2e-4) << s.err;
  // The transform it offers to save puts the circle back on its centre (the ranking's own frame
  // put it 47 mm off, "sigma 5.2 and 1.4 mm").
  const auto& fix = k["parameters"]["shape_transform"];
  char transform[160];
  std::snprintf(transform, sizeof transform, " --transform %.9g,%.9g,%.9g", fix[0].get<double>(), fix[1].get<double>(),
                fix[2].get<double>());
  const std::string fixed = dir() + "/fixed.json";
  ASSERT_EQ(Tool("footprint " + dir() + "/user_shape.json" + transform + " -o " + fixed + " -q").status, 0);
  double cx = 0.0, cy = 0.0;
  const nlohmann::json fixed_shape = Load(fixed);
  const auto& outer = fixed_shape["polygons"][0]["outer"];
  for (const auto& v : outer) cx += v[0].get<double>() / outer.size(), cy += v[1].get<double>() / outer.size();
  std::printf("[registration] the saved transform puts the circle's centre at (%.1f, %.1f) mm\n", cx * 1e3, cy * 1e3);
  EXPECT_LT(std::hypot(cx, cy), 3e-3) << s.err;
}

// A mesh in millimetres and otherwise right: the units alone compete in the whole graph with the
// placements found with them, and win ties as the shape as given does. On this recording the
// placement had a turn of 3.9 degrees and a 1.7 mm shift (0.942 mm, saved with the file); now the estimate is the one
// with the mesh as shipped, and the command to save it is the units alone.
TEST_F(EstimateCli, AMeshInMillimetresAloneIsEstimatedAsTheRightOne) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "--scale 1000", kProbe, kRect1Mass, dir() + "/mm.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("(to save it: pushgraph footprint " + dir() + "/user_shape.json --scale 0.001)"), std::string::npos)
      << r.err;
  const nlohmann::json j = Load(dir() + "/mm.json");
  ASSERT_TRUE(j["parameters"].contains("shape_transform"));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(j["parameters"]["shape_transform"][k].get<double>(), 0.0);
  // No placement was fitted: no sigma (it read exactly [0, 0, 0]), and the ties the warning names
  // leave it unsettled (it read settled).
  EXPECT_TRUE(j["shape"]["units_only"].get<bool>());
  EXPECT_TRUE(j["parameters"]["shape_transform_sigma"].is_null());
  ASSERT_TRUE(j["shape"].contains("tied_transforms")) << j["shape"].dump();  // a turn of 4 degrees ties here
  EXPECT_FALSE(j["shape"]["placement_settled"].get<bool>()) << j["shape"].dump();
  std::printf("[registration] rect1 in millimetres: settled %d, ties %s\n", j["shape"]["placement_settled"].get<bool>(),
              j["shape"].value("tied_transforms", nlohmann::json::array()).dump().c_str());
  const pushgraph::testing::ToolRun shipped = EstimateMit(h5, "rect1.obj", "", kProbe, kRect1Mass, dir() + "/m.json");
  ASSERT_EQ(shipped.status, 0) << shipped.err;
  const double rms = j["metrics"]["object_position_rms"].get<double>();
  const double rms_shipped = Load(dir() + "/m.json")["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] rect1 in millimetres: object RMS %.3f mm (as shipped %.3f mm)\n", rms * 1e3, rms_shipped * 1e3);
  EXPECT_NEAR(rms, rms_shipped, 1e-5);
}

// A CAD export in millimetres, object and finger alike (the dataset's meshes with every vertex
// times 1000): the object's units were found by the shape check, while the finger, read as a
// 4.7 m disk, was refused ("Is the finger's shape file in millimetres?"). Now the finger is read
// as millimetres too, said so, and the estimate is the one with the probe in metres.
TEST_F(EstimateCli, ACadExportInMillimetresIsReadAsSuchFingerIncluded) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string object = EditedMesh("rect1.obj", 1000.0, 0.0, "mm_rect1.obj");
  const std::string finger = EditedMesh("tip.obj", 1000.0, 0.0, "mm_tip.obj");
  const std::string rest = " --model cp --mass 0.8374 --mu 0.35 -o ";
  const pushgraph::testing::ToolRun mm = Tool("estimate '" + h5 + "' --object " + object + " --finger " + finger + rest + dir() + "/mm.json");
  ASSERT_EQ(mm.status, 0) << mm.err;
  EXPECT_NE(mm.err.find("so it is read as millimetres: it reaches 4.7 mm"), std::string::npos) << mm.err;
  const pushgraph::testing::ToolRun metres =
      Tool("estimate '" + h5 + "' --object " + object + " --finger " + Mit() + "obj/tip.obj" + rest + dir() + "/m.json");
  ASSERT_EQ(metres.status, 0) << metres.err;
  const nlohmann::json a = Load(dir() + "/mm.json"), b = Load(dir() + "/m.json");
  EXPECT_EQ(a["parameters"]["finger_scale"].get<double>(), 1e-3);
  EXPECT_FALSE(b["parameters"].contains("finger_scale"));
  EXPECT_EQ(a["parameters"]["shape_scale"].get<double>(), 1e-3);
  EXPECT_LT(LargestObjectPoseDifference(a, b, 2), 1e-6);
  // Drawn 10 mm off its axis as well: it holds nothing (its origin outside it) but reaches 14.7 "m"
  // from it; read as millimetres, then centred (the shape check had called the object's file "6.36
  // times the size of the finger's path").
  const std::string off_axis = EditedMesh("tip.obj", 1000.0, 10.0, "mm_tip_off.obj");
  const pushgraph::testing::ToolRun both =
      Tool("estimate '" + h5 + "' --object " + object + " --finger " + off_axis + rest + dir() + "/off_axis.json");
  ASSERT_EQ(both.status, 0) << both.err;
  const nlohmann::json c = Load(dir() + "/off_axis.json");
  EXPECT_EQ(c["parameters"]["finger_scale"].get<double>(), 1e-3);
  ASSERT_TRUE(c["parameters"].contains("finger_transform")) << c["parameters"].dump();
  EXPECT_NEAR(c["parameters"]["finger_transform"][0].get<double>(), -0.01, 1e-9);
  EXPECT_LT(LargestObjectPoseDifference(c, b, 2), 1e-6);
  // --align-shape off keeps the refusal, naming the units.
  const pushgraph::testing::ToolRun off =
      Tool("estimate '" + h5 + "' --object " + object + " --finger " + finger + " --align-shape off" + rest + dir() + "/off.json");
  EXPECT_EQ(off.status, 1);
  EXPECT_NE(off.err.find("Is the finger's shape file in millimetres"), std::string::npos) << off.err;
}

// The dataset's probe mesh drawn 10 mm off its axis (every vertex moved), with the tracker on the
// probe's centre: the misfit was blamed on the object's frame (rect1: 2.11 mm against 1.23 mm on
// one recording, nothing said of the finger). The contacts fit the probe centred on its tracked
// point, so it is estimated so and said; moved along the pushed side (a 2.9 mm median gap as
// given, within the tolerance; 1.1 mm centred) as well.
TEST_F(EstimateCli, AProbeMeshOffItsAxisIsCentredOnTheTrackedPoint) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string rest = " --model cp --mass 0.8374 --mu 0.35 --add-noise gaussian -o ";
  ASSERT_EQ(Tool("estimate '" + h5 + "' --object " + Mit() + "obj/rect1.obj --finger " + Mit() + "obj/tip.obj" + rest +
                 dir() + "/true.json").status,
            0);
  const nlohmann::json truth = Load(dir() + "/true.json");
  EXPECT_FALSE(truth["parameters"].contains("finger_transform"));
  for (const double dx : {0.01, -0.01}) {
    const std::string finger = EditedMesh("tip.obj", 1.0, dx, dx > 0 ? "tip_plus.obj" : "tip_minus.obj");
    const pushgraph::testing::ToolRun r =
        Tool("estimate '" + h5 + "' --object " + Mit() + "obj/rect1.obj --finger " + finger + rest + dir() + "/off.json");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("its shape lies 5.3 mm outside its pose origin"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("estimated with it centred"), std::string::npos) << r.err;
    const nlohmann::json j = Load(dir() + "/off.json");
    ASSERT_TRUE(j["parameters"].contains("finger_transform")) << j["parameters"].dump();
    EXPECT_NEAR(j["parameters"]["finger_transform"][0].get<double>(), -dx, 1e-9);
    EXPECT_NEAR(j["parameters"]["finger_transform"][1].get<double>(), 0.0, 1e-9);
    // The object's shape is not moved to explain the probe's offset, and the estimate is the true probe's.
    EXPECT_FALSE(j["shape"].value("aligned", false)) << j["shape"].dump();
    const double rms = j["metrics"]["object_position_rms"].get<double>();
    const double rms_true = truth["metrics"]["object_position_rms"].get<double>();
    std::printf("[registration] probe mesh %+.0f mm off its axis: object RMS %.3f mm (true probe %.3f mm)\n", dx * 1e3,
                rms * 1e3, rms_true * 1e3);
    EXPECT_NEAR(rms, rms_true, 1e-6);
  }
}

// A rect1 mesh in millimetres on a simulated push that ends with the finger resting for 4.5 s
// (10 Hz tracker): the best placement found at those units only nudged the shape (a 5.2 mm
// shift; before the resting samples were merged, a turn of 31.8 degrees), and it beat the units
// alone by 7.5 in graph cost, what the graph's frame alone buys. It must now beat them by as much
// as the frame check asks (20): the units alone win, estimated as the true shape is.
TEST_F(EstimateCli, AMeshInMillimetresOnARestingPushIsOnlyItsUnits) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string rect1 = dir() + "/rect1.json", mm = dir() + "/rect1_mm.json", sim = dir() + "/rest.json";
  ASSERT_EQ(Tool("footprint " + Mit() + "obj/rect1.obj -q -o " + rect1).status, 0);
  ASSERT_EQ(Tool("footprint " + Mit() + "obj/rect1.obj --scale 1000 -q -o " + mm).status, 0);
  ASSERT_EQ(Tool("simulate -o " + sim + " --object " + rect1 + " --mass 0.8374 --seed 3 --duration 6 --rate-object 10").status, 0);
  const pushgraph::testing::ToolRun truth = Tool("estimate " + sim + " -o " + dir() + "/truth.json");
  ASSERT_EQ(truth.status, 0) << truth.err;
  const pushgraph::testing::ToolRun r = Tool("estimate " + sim + " --object " + mm + " -o " + dir() + "/mm.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(dir() + "/mm.json");
  ASSERT_TRUE(j["parameters"].contains("shape_transform")) << r.err;
  for (int k = 0; k < 3; ++k) EXPECT_EQ(j["parameters"]["shape_transform"][k].get<double>(), 0.0) << r.err;
  const double rms = j["metrics"]["object_position_rms"].get<double>();
  const double rms_true = Load(dir() + "/truth.json")["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] rect1 in millimetres, push and rest: object RMS %.3f mm (true shape %.3f mm)\n", rms * 1e3,
              rms_true * 1e3);
  EXPECT_NEAR(rms, rms_true, 1e-5);
}

// A mesh converted from millimetres to metres twice (footprint --scale 0.001 on a file already in
// metres): 1000 times too small, it "fit as given" (every placement of a shape that small moves
// it by less than the fit tolerance), and the estimate was 25.2 mm off against 1.21 mm (raw 7.27).
// Units of 100 and 1000 are tried now. 100000 times too small no unit explains: it is named.
TEST_F(EstimateCli, AMeshConvertedToMetresTwiceIsFoundSo) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const std::string out = dir() + "/tiny.json";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "--scale 0.001", kProbe, kRect1Mass, out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the file is 1000 times too small"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pushgraph footprint " + dir() + "/user_shape.json --scale 1000 alone"), std::string::npos) << r.err;
  const double rms = Load(out)["metrics"]["object_position_rms"].get<double>();
  std::printf("[registration] rect1 1000 times too small: object RMS %.2f mm\n", rms * 1e3);
  EXPECT_LT(rms, 1.6e-3);
  // A shape no unit explains is refused (a placement of it would be a guess): --align-shape off
  // estimates it as given.
  const pushgraph::testing::ToolRun far = EstimateMit(h5, "rect1.obj", "--scale 0.00001", kProbe, kRect1Mass, dir() + "/far.json");
  EXPECT_NE(far.status, 0) << far.err;
  EXPECT_NE(far.err.find("no unit tried"), std::string::npos) << far.err;
  EXPECT_NE(far.err.find("check the shape file's size and units"), std::string::npos) << far.err;
  EXPECT_NE(far.err.find("so nothing is estimated (--align-shape off"), std::string::npos) << far.err;
  EXPECT_FALSE(std::ifstream(dir() + "/far.json").good());
}

// A 1 mm probe given for the 4.7 mm one, on a rect1 recording: one side's contacts cannot tell a
// shift of the block along its normal from a larger finger, and the graph takes the placement
// (by 2.8 in cost). The warning said "aligned it" and nothing of the radius; now it names both.
TEST_F(EstimateCli, AProbeTooSmallIsNamedBesideThePlacement) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.000.h5";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "", 0.001, kRect1Mass, dir() + "/small.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("explains the contacts about as well"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("check the probe radius"), std::string::npos) << r.err;
}

// rect1's mesh 10 % too large: the contacts and the whole graph fit a placement (turned by 4.7 deg)
// and the finger 4.5 mm smaller about as well. The placement was reported settled, with sigmas,
// and the size as a probe of radius 0.2 mm; now it is unsettled and the size is named as the
// outline's (a hostile user's probe, 2026-11-30).
TEST_F(EstimateCli, AMeshOfTheWrongSizeIsNoSettledPlacement) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string out = dir() + "/large.json";
  const pushgraph::testing::ToolRun r = EstimateMit(h5, "rect1.obj", "--scale 1.1", kProbe, kRect1Mass, out);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(out);
  EXPECT_FALSE(j["shape"]["placement_settled"].get<bool>()) << r.err;
  EXPECT_NE(j["shape"]["placement_unsettled_by"].get<std::string>().find("(another probe radius or object size) fits about as well"),
            std::string::npos)
      << j["shape"].dump();
  // 4.5 mm on every side of a 45 mm half width (10 % on this recording).
  const std::size_t size_at = r.err.find("(as an object size: its outline about ");
  ASSERT_NE(size_at, std::string::npos) << r.err;
  const double percent = std::stod(r.err.substr(size_at + 38));
  EXPECT_NEAR(percent, 10.0, 2.0) << r.err.substr(size_at, 80);
  EXPECT_EQ(r.err.compare(size_at + 38 + std::to_string(static_cast<int>(percent)).size(), 12, " % too large"), 0)
      << r.err.substr(size_at, 80);
  EXPECT_EQ(r.err.find("do not fix its position along"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the contacts fix its position in no direction"), std::string::npos) << r.err;
}

// A 9 mm probe given for the 4.7 mm one: on two ellip1 recordings the whole graph prefers the
// finger 3.5 and 4.5 mm smaller to any placement by 8 and 43 in cost. Estimated with the probe as
// given, against a shape it does not touch, they were 1.49 and 2.43 mm off; with the preferred
// radius 0.88 and 0.80 mm (with the right probe 1.13 and 0.82 mm). On other recordings a
// placement wins (the contacts of one push cannot tell a shift from a size), also near 1 mm; a
// third recording where the size won by 5 (t=0.349 at 100 mm/s) is such a tie: the placement's
// solve reaches 928.0 with the banded factorization and 935.7 without, against 930.6 for the size.
// The second recording here is one too (the size 2136.3, a placement 2132.9 to 2133.2 as the
// registration's details change): either is used, and the warning names both when the placement is.
TEST_F(EstimateCli, AFingerSizeTheGraphPrefersIsUsedAndNamed) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  for (const char* rec : {"100_i=0.000_s=0.075_t=0.000.h5", "20_i=0.000_s=0.675_t=0.698.h5"}) {
    const bool tie = std::string(rec).rfind("20_", 0) == 0;
    const std::string out = dir() + "/sized.json";
    const pushgraph::testing::ToolRun r = EstimateMit(Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=" + rec,
                                                      "ellip1.obj", "", 0.009, kEllip1Mass, out);
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = Load(out);
    const double rms = j["metrics"]["object_position_rms"].get<double>();
    EXPECT_LT(rms, 1.3e-3) << rec;
    if (tie && !j["parameters"].contains("finger_radius")) {
      EXPECT_NE(r.err.find("explains the contacts about as well"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("check the probe radius"), std::string::npos) << r.err;
      std::printf("[registration] ellip1 with a 9 mm probe: a placement used (a tie), object RMS %.2f mm\n", rms * 1e3);
      continue;
    }
    EXPECT_NE(r.err.find("a wrong probe radius or object size? Estimated with that radius"), std::string::npos) << r.err;
    ASSERT_TRUE(j["parameters"].contains("finger_radius")) << rec;
    const double radius = j["parameters"]["finger_radius"].get<double>();
    std::printf("[registration] ellip1 with a 9 mm probe: radius used %.2f mm, object RMS %.2f mm\n", radius * 1e3, rms * 1e3);
    EXPECT_NEAR(radius, kProbe, 1.2e-3) << rec;  // 5.49 and 4.53 mm
  }
  // The converse on the 20 mm/s recording: the right probe and the mesh shifted by 1 cm. The
  // graph prefers a finger 5.4 mm larger there too (by 11 in cost), and the contacts fit the
  // placement as well: the warning names the placement beside the size (the frame error went
  // unnamed, blamed on the probe).
  const std::string out = dir() + "/shifted.json";
  const pushgraph::testing::ToolRun r = EstimateMit(Mit() + "abs/ellip1/motion_surface=abs_shape=ellip1_a=0_v=20_i=0.000_s=0.675_t=0.698.h5",
                                                    "ellip1.obj", "--transform 0.01,0,0", kProbe, kEllip1Mass, out);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = Load(out);
  EXPECT_LT(j["metrics"]["object_position_rms"].get<double>(), 1.3e-3);
  ASSERT_TRUE(j["parameters"].contains("finger_radius")) << r.err;  // the size wins (the noise is seeded)
  EXPECT_NE(r.err.find("if the probe's radius is right, the shape file's frame may be off by that much"), std::string::npos)
      << r.err;
}


// A real recording (rect1, mocap) with its object stamps made 0.15 s late: the true mesh is
// "aligned" by a few millimetres and the estimate is worse than the late tracker itself; the
// warning names the latency as another cause, and --object-delay 0.15 gives the estimate of the
// recording in step. The recording's own record as ground truth (late like the tracker, as
// --add-noise keeps it) is moved back with it.
TEST_F(EstimateCli, ALateObjectTrackerOnARealRecordingIsNamedAndObjectDelayUndoesIt) {
  if (Mit().empty()) GTEST_SKIP() << "no MIT data";
  const std::string h5 = Mit() + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.700_t=-1.047.h5";
  const std::string in_step = dir() + "/in_step.json";
  ASSERT_EQ(Tool("mit-import '" + h5 + "' --object " + Mit() + "obj/rect1.obj --finger " + Mit() +
                 "obj/tip.obj --mass 0.8374 --mu-surface 0.35 -o " + in_step).status,
            0);
  nlohmann::json late = Load(in_step);
  for (auto& row : late["streams"]["object_pose"]) row[0] = row[0].get<double>() + 0.15;  // the truth in step
  std::ofstream(dir() + "/late.json") << late.dump();
  for (auto& row : late["ground_truth"]["object_pose"]) row[0] = row[0].get<double>() + 0.15;  // late like it
  std::ofstream(dir() + "/late_record.json") << late.dump();
  auto estimate = [&](const std::string& input, const std::string& options, const std::string& out) {
    const pushgraph::testing::ToolRun run = Tool("estimate " + input + options + " -o " + dir() + "/" + out);
    EXPECT_EQ(run.status, 0) << run.err;
    return std::make_pair(run.err, Load(dir() + "/" + out));
  };
  const auto [said, as_recorded] = estimate(dir() + "/late.json", "", "as_recorded.json");
  EXPECT_NE(said.find("an object tracker running late against the finger"), std::string::npos) << said;
  EXPECT_FALSE(as_recorded["parameters"].contains("object_delay"));
  const double late_rms = as_recorded["metrics"]["object_position_rms"].get<double>();
  const double raw_rms = as_recorded["metrics"]["measured_object_position_rms"].get<double>();
  EXPECT_GT(late_rms, raw_rms);  // what the option is for: worse than the late tracker itself
  // With the delay: the estimate of the recording in step (whose measurements are then its truth).
  const auto [undone_said, undone] = estimate(dir() + "/late.json", " --object-delay 0.15", "undone.json");
  EXPECT_EQ(undone_said.find("running late"), std::string::npos) << undone_said;
  EXPECT_EQ(undone["parameters"]["object_delay"].get<double>(), 0.15);
  const nlohmann::json reference = estimate(in_step, "", "in_step_result.json").second;
  const double undone_gap = LargestObjectPoseDifference(undone, reference, 2);
  EXPECT_LT(undone_gap, 1e-6);
  // The paper's noise on the late recording, its record late too: the delay moves both back, and
  // the estimate and its metrics are those of the recording in step with the same noise.
  const nlohmann::json noisy_in_step = estimate(in_step, " --add-noise gaussian", "noisy_in_step.json").second;
  const nlohmann::json noisy = estimate(dir() + "/late_record.json", " --add-noise gaussian --object-delay 0.15", "noisy.json").second;
  EXPECT_LT(LargestObjectPoseDifference(noisy, noisy_in_step, 2), 1e-6);
  EXPECT_NEAR(noisy["metrics"]["object_position_rms"].get<double>(),
              noisy_in_step["metrics"]["object_position_rms"].get<double>(), 1e-6);
  std::printf("[estimate] rect1 with its tracker 0.15 s late: object %.2f mm, raw %.2f mm; --object-delay 0.15: the "
              "in-step estimate to %.2g m (with the paper's noise: %.2f mm, in step %.2f mm)\n",
              late_rms * 1e3, raw_rms * 1e3, undone_gap, noisy["metrics"]["object_position_rms"].get<double>() * 1e3,
              noisy_in_step["metrics"]["object_position_rms"].get<double>() * 1e3);
  EXPECT_NE(Tool("estimate " + dir() + "/late.json --object-delay 1e400 -o " + dir() + "/x.json").err.find("--object-delay"),
            std::string::npos);
}

// An MIT recording (HDF5) read directly: trimmed to contact, time stamps kept (unix seconds),
// the paper's noise added with the clean recording as ground truth, and a picture.
TEST_F(EstimateCli, MitRecordingWithAddedNoise) {
  const std::string shared = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";
  const std::string h5 = shared + "abs/rect1/motion_surface=abs_shape=rect1_a=0_v=75_i=2.000_s=0.800_t=0.349.h5";
  if (!std::ifstream(h5)) GTEST_SKIP() << "no MIT data at " << shared;
  const std::string square = dir() + "/square.json", tip = dir() + "/tip.json";
  std::ofstream(square) << R"({"polygons": [{"outer": [[-0.045, -0.045], [0.045, -0.045], [0.045, 0.045], [-0.045, 0.045]]}]})";
  std::ofstream(tip) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.0047})";
  const std::string cfg = dir() + "/mit_cfg.json";
  std::ofstream(cfg) << R"({"covariance": false})";
  const std::string out = dir() + "/mit_result.json", svg = dir() + "/mit.svg";
  const std::string common = "estimate '" + h5 + "' --object " + square + " --finger " + tip + " --mass 0.8374 --mu 0.35 --model cp --config " + cfg;
  const pushgraph::testing::ToolRun r = Tool(common + " --add-noise gaussian --seed 4 -o " + out + " --svg " + svg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("force sensor frozen"), std::string::npos) << r.err;  // the reader's repair notes
  const nlohmann::json j = Load(out);
  ASSERT_GT(j["states"].size(), 100u);
  const double t0 = j["states"][0]["t"].get<double>();
  EXPECT_GT(t0, 1.4e9);  // the recording's own unix time stamps
  EXPECT_LT(t0, 1.6e9);
  const nlohmann::json& m = j["metrics"];
  EXPECT_NEAR(m["measured_object_position_rms"].get<double>(), 0.005 * std::sqrt(2.0), 0.0015);
  EXPECT_NEAR(m["measured_object_rotation_rms"].get<double>(), 0.05, 0.015);
  EXPECT_LT(m["object_position_rms"].get<double>(), m["measured_object_position_rms"].get<double>());
  EXPECT_TRUE(std::ifstream(svg).good());
  // Another seed, other noise; without --add-noise a recording has nothing to be scored against
  // (its "ground truth" would be the measurements themselves: measured_*_rms 0, the estimate
  // "0.7 mm off"): no metrics, and said why.
  ASSERT_EQ(Tool(common + " --add-noise bimodal --seed 5 -o " + out).status, 0);
  EXPECT_NE(Load(out)["metrics"]["measured_object_position_rms"].get<double>(), m["measured_object_position_rms"].get<double>());
  const pushgraph::testing::ToolRun plain = Tool(common + " -o " + out);
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_FALSE(Load(out).contains("metrics")) << Load(out)["metrics"].dump();
  EXPECT_NE(plain.err.find("no metrics: the input's ground_truth is its own measurements"), std::string::npos) << plain.err;
  // MIT input needs the object's description; unknown content is named.
  pushgraph::testing::ToolRun bad = Tool("estimate '" + h5 + "' -o " + out);
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("is an MIT recording"), std::string::npos) << bad.err;
  const std::string junk = dir() + "/junk.json";
  std::ofstream(junk) << R"({"hello": 1})";
  bad = Tool("estimate " + junk + " -o " + out);
  EXPECT_NE(bad.err.find("neither a pushgraph trajectory"), std::string::npos) << bad.err;
  bad = Tool("estimate '" + h5 + "' --add-noise uniform -o " + out);
  EXPECT_EQ(bad.status, 2);
}

}  // namespace
}  // namespace pushgraph::graph
