// SVG plots (plot_svg.h): well-formed output, the right number of ellipses and arrows for a known
// result, results without covariances or forces, trajectories without ground truth, shapes with
// holes and rounding, errors naming the path.
#include <pushgraph/evaluation/plots.h>
#include <pushgraph/io/trajectory_json.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace pushgraph;
using geometry::Pose2;
using geometry::Vec2;

// A minimal XML well-formedness check: every tag closes in order, attributes are quoted, no
// stray '<' or '&' in text, exactly one root element. Returns "" or what is wrong.
std::string XmlProblem(const std::string& xml) {
  std::vector<std::string> stack;
  std::size_t i = 0;
  int roots = 0;
  if (xml.rfind("<?xml", 0) == 0) i = xml.find("?>") + 2;
  while (i < xml.size()) {
    if (xml[i] != '<') {
      if (xml[i] == '&') {
        const std::size_t semi = xml.find(';', i);
        const std::string entity = xml.substr(i, semi - i + 1);
        if (entity != "&amp;" && entity != "&lt;" && entity != "&gt;" && entity != "&apos;" && entity != "&quot;")
          return "bad entity at " + std::to_string(i);
      }
      if (stack.empty() && !std::isspace(static_cast<unsigned char>(xml[i]))) return "text outside the root at " + std::to_string(i);
      ++i;
      continue;
    }
    // Find the end of the tag, skipping quoted attribute values.
    std::size_t j = i + 1;
    char quote = 0;
    for (; j < xml.size(); ++j) {
      if (quote) {
        if (xml[j] == quote) quote = 0;
        else if (xml[j] == '<') return "'<' inside an attribute at " + std::to_string(j);
      } else if (xml[j] == '\'' || xml[j] == '"') {
        quote = xml[j];
      } else if (xml[j] == '>') {
        break;
      }
    }
    if (j >= xml.size()) return "unterminated tag at " + std::to_string(i);
    const std::string tag = xml.substr(i + 1, j - i - 1);
    if (tag.empty()) return "empty tag at " + std::to_string(i);
    if (tag[0] == '/') {
      const std::string name = tag.substr(1);
      if (stack.empty() || stack.back() != name) return "closing </" + name + "> does not match at " + std::to_string(i);
      stack.pop_back();
    } else {
      const std::size_t name_end = tag.find_first_of(" \t\n/");
      const std::string name = tag.substr(0, name_end);
      // Attributes: name='value' pairs only.
      static const std::regex attributes(R"(^[A-Za-z][\w:-]*(\s+[A-Za-z][\w:-]*\s*=\s*('[^']*'|"[^"]*"))*\s*/?$)");
      if (!std::regex_match(tag, attributes)) return "malformed tag <" + tag.substr(0, 60) + ">";
      if (stack.empty()) ++roots;
      if (tag.back() != '/') stack.push_back(name);
    }
    i = j + 1;
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  if (roots != 1) return std::to_string(roots) + " root elements";
  return "";
}

// With PUSHGRAPH_PLOT_DUMP=folder set, the tests' pictures are written there to be looked at.
void Dump(const std::string& name, const std::string& svg) {
  if (const char* folder = std::getenv("PUSHGRAPH_PLOT_DUMP")) evaluation::WriteSvgFile(std::string(folder) + "/" + name, svg);
}

int Count(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// The `d` attribute of the first element with class `cls`.
std::string FirstPath(const std::string& svg, const std::string& cls) {
  const std::size_t at = svg.find("class='" + cls + "'");
  if (at == std::string::npos) return "";
  const std::size_t d = svg.find(" d='", at);
  return svg.substr(d + 4, svg.find('\'', d + 4) - d - 4);
}

std::vector<Vec2> PathPoints(const std::string& d) {
  std::vector<Vec2> points;
  static const std::regex pair(R"((-?[\d.]+),(-?[\d.]+))");
  for (auto it = std::sregex_iterator(d.begin(), d.end(), pair); it != std::sregex_iterator(); ++it)
    points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  return points;
}

// A push of the notched block (holes) up by 3 cm in 1 s: 21 states, a 2 cm offset finger below.
constexpr int kStates = 21;

evaluation::TrajectoryPlotOptions Every(int every) {
  evaluation::TrajectoryPlotOptions options;
  options.every = every;
  return options;
}

push::Trajectory Push(bool with_truth) {
  push::Trajectory traj;
  traj.object.shape = geometry::LoadShapeJson(PUSHGRAPH_SOURCE_DIR "/data/shapes/notched_block.json");
  traj.finger.shape = geometry::Shape::Disk(0.005);
  push::Streams truth;
  for (int k = 0; k < kStates; ++k) {
    const double t = 0.05 * k, y = 0.0015 * k;
    truth.object_pose.push_back({t, Pose2{0.0, y, 0.01 * k}});
    truth.finger_pose.push_back({t, Pose2{-0.02, y - 0.045, 0.0}});
    truth.contact_point.push_back({t, Vec2(-0.02, y - 0.04)});
    truth.force.push_back({t, Vec2(0.0, 1.0)});
  }
  traj.measured = truth;
  for (auto& s : traj.measured.object_pose) s.pose.x += 0.002;
  if (with_truth) traj.ground_truth = truth;
  return traj;
}

graph::EstimationResult Result(const push::Trajectory& traj, bool covariances, bool forces) {
  graph::EstimationResult r;
  for (int k = 0; k < kStates; ++k) {
    graph::StateEstimate s;
    s.t = 0.05 * k;
    s.object_pose = traj.measured.object_pose[k].pose;
    s.object_pose.x = 0.0005;
    s.finger_pose = traj.measured.finger_pose[k].pose;
    if (k >= 5) s.contact = traj.measured.contact_point[k].point;  // contact from step 5 on
    if (forces && s.contact) s.force = Vec2(0.1, 0.9);
    if (covariances) {
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      cov << 4e-6, 1e-6, 0, 1e-6, 1e-6, 0, 0, 0, 1e-4;
      s.object_pose_cov = cov;
      s.finger_pose_cov = 0.25 * cov;
      if (s.contact) s.contact_cov = Eigen::Matrix2d::Identity() * 1e-6;
    }
    r.states.push_back(s);
  }
  return r;
}

TEST(PlotSvg, KnownResultHasOneEllipsePerCovarianceAndOneArrowPerForceAtMarkedSteps) {
  const push::Trajectory traj = Push(true);
  const graph::EstimationResult result = Result(traj, true, true);
  evaluation::TrajectoryPlotOptions options;
  options.every = 5;  // marked steps 0, 5, 10, 15, 20; in contact at 4 of them
  options.title = "push <&> test";
  const std::string svg = evaluation::TrajectorySvg(traj, result, options);
  Dump("known.svg", svg);
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_EQ(Count(svg, "class='ellipse-object'"), 5);
  EXPECT_EQ(Count(svg, "class='ellipse-finger'"), 5);
  EXPECT_EQ(Count(svg, "class='ellipse-contact'"), 4);
  EXPECT_EQ(Count(svg, "class='force-estimated'"), 4);
  EXPECT_EQ(Count(svg, "class='force-measured'"), 5);  // measured force at every marked step
  EXPECT_EQ(Count(svg, "class='force-truth'"), 5);
  EXPECT_EQ(Count(svg, "class='footprint-estimated'"), 5);
  EXPECT_EQ(Count(svg, "class='footprint-truth'"), 5);
  EXPECT_EQ(Count(svg, "class='finger'"), 5);
  EXPECT_EQ(Count(svg, "class='object-measured'"), kStates);
  EXPECT_EQ(Count(svg, "class='contact-estimated'"), 4);
  EXPECT_EQ(Count(svg, "class='path-truth'"), 1);
  EXPECT_EQ(Count(svg, "class='scale-bar'"), 1);
  EXPECT_NE(svg.find("push &lt;&amp;&gt; test"), std::string::npos);
  EXPECT_NE(svg.find("2-sigma"), std::string::npos);
  EXPECT_NE(svg.find("1 N = "), std::string::npos);
  EXPECT_NE(svg.find(" mm</text>"), std::string::npos);
  EXPECT_NE(svg.find("object position error"), std::string::npos);  // error panel with ground truth
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);

  // The object ellipse is 2 sigma along the principal axes of the 2x2 position block:
  // eigenvalues of [[4, 1], [1, 1]] mm^2 are (5 +- sqrt 13) / 2, so rx / ry = sqrt(4.303 / 0.697).
  const std::smatch m = [&] {
    std::smatch match;
    static const std::regex e(R"(class='ellipse-object' cx='[-\d.]+' cy='[-\d.]+' rx='([\d.]+)' ry='([\d.]+)')");
    std::regex_search(svg, match, e);
    return match;
  }();
  ASSERT_EQ(m.size(), 3u);
  EXPECT_NEAR(std::stod(m[1]) / std::stod(m[2]), std::sqrt((5 + std::sqrt(13.0)) / (5 - std::sqrt(13.0))), 0.02);

  options.ellipses = false;
  options.forces = false;
  const std::string plain = evaluation::TrajectorySvg(traj, result, options);
  EXPECT_EQ(XmlProblem(plain), "");
  EXPECT_EQ(Count(plain, "<ellipse class='ellipse-"), 0);
  EXPECT_EQ(Count(plain, "class='force-"), 0);
}

TEST(PlotSvg, AutomaticSpacingMarksAboutTwelveSteps) {
  const push::Trajectory traj = Push(true);
  const std::string svg = evaluation::TrajectorySvg(traj, Result(traj, true, true));
  const int marks = Count(svg, "class='ellipse-object'");
  EXPECT_GE(marks, 10);
  EXPECT_LE(marks, 15);
}

TEST(PlotSvg, ResultWithoutCovariancesOrForcesDrawsNoEllipsesOrEstimatedArrows) {
  push::Trajectory traj = Push(true);
  traj.measured.force.clear();
  traj.ground_truth->force.clear();
  const std::string svg = evaluation::TrajectorySvg(traj, Result(traj, false, false), Every(5));
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_EQ(Count(svg, "<ellipse class='ellipse-"), 0);
  EXPECT_EQ(Count(svg, "class='force-"), 0);
  EXPECT_EQ(svg.find("2-sigma"), std::string::npos);
  EXPECT_EQ(svg.find("1 N = "), std::string::npos);
  EXPECT_EQ(Count(svg, "class='footprint-estimated'"), 5);
}

TEST(PlotSvg, TrajectoryWithoutGroundTruthHasNoTruthLayersOrErrorPanel) {
  const push::Trajectory traj = Push(false);
  const std::string svg = evaluation::TrajectorySvg(traj, Result(traj, true, true), Every(5));
  Dump("no_truth.svg", svg);
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_EQ(Count(svg, "class='footprint-truth'"), 0);
  EXPECT_EQ(Count(svg, "class='path-truth'"), 0);
  EXPECT_EQ(Count(svg, "class='force-truth'"), 0);
  EXPECT_EQ(svg.find("object position error"), std::string::npos);
  EXPECT_EQ(Count(svg, "class='ellipse-object'"), 5);
  EXPECT_TRUE(evaluation::ObjectPositionErrorSeries(traj, {}).empty());
}

TEST(PlotSvg, FootprintsDrawHolesAndRoundedBoundaries) {
  // The notched block: one outer boundary and two holes, evenodd-filled.
  const push::Trajectory traj = Push(true);
  const std::string svg = evaluation::TrajectorySvg(traj, Result(traj, true, true), Every(5));
  const std::string footprint = FirstPath(svg, "footprint-estimated");
  EXPECT_EQ(Count(footprint, "Z"), 3);
  EXPECT_EQ(Count(footprint, "M"), 3);
  EXPECT_NE(svg.find("fill-rule='evenodd'"), std::string::npos);

  // A rounded 40 x 20 mm box with r = 5 mm at rest: its drawn outline spans 50 x 30 mm (the
  // rounding sampled, not dropped), whatever the picture's scale; two parts give two outlines.
  push::Trajectory box;
  box.object.shape = geometry::Shape::FromPolygons(
      {{{{-0.02, -0.01}, {0.02, -0.01}, {0.02, 0.01}, {-0.02, 0.01}}, {}},
       {{{0.03, -0.01}, {0.05, -0.01}, {0.04, 0.01}}, {}}},
      0.005);
  box.finger.shape = geometry::Shape::Capsule(Vec2(-0.002, 0), Vec2(0.002, 0), 0.002);
  box.measured.object_pose.push_back({0.0, Pose2{}});
  box.measured.finger_pose.push_back({0.0, Pose2{0.0, -0.03, 0.0}});
  graph::EstimationResult rest;
  rest.states.resize(1);
  rest.states[0].finger_pose = Pose2{0.0, -0.03, 0.0};
  const std::string rounded = evaluation::TrajectorySvg(box, rest);
  Dump("rounded.svg", rounded);
  EXPECT_EQ(XmlProblem(rounded), "");
  const std::string d = FirstPath(rounded, "footprint-estimated");
  EXPECT_EQ(Count(d, "M"), 2);
  std::vector<Vec2> points = PathPoints(d.substr(0, d.find('M', 1)));
  ASSERT_GT(points.size(), 20u);  // 4 corners x 90 degrees in arcs of at most 10 degrees
  Eigen::Array2d lo = points[0].array(), hi = lo;
  for (const Vec2& p : points) lo = lo.min(p.array()), hi = hi.max(p.array());
  EXPECT_NEAR((hi.x() - lo.x()) / (hi.y() - lo.y()), 50.0 / 30.0, 0.01);
  EXPECT_GT(PathPoints(FirstPath(rounded, "finger")).size(), 20u);  // the capsule finger, sampled
}

// A push with two fingers, finger 0 touching at two points at once at t = 0.04.
TEST(PushSvg, DrawsEveryFingerContactAndForceAtTheMarkedTimes) {
  push::Trajectory t;
  t.object.shape = geometry::Shape::Box(0.09, 0.09);
  t.finger.shape = geometry::Shape::Disk(0.004, {0.0, 0.02});
  push::ExtraFinger second;
  second.finger.shape = geometry::Shape::Disk(0.004, {0.0, -0.02});
  push::Streams truth;
  push::FingerStreams truth_second;
  for (int k = 0; k < 3; ++k) {
    const double time = 0.04 * k;
    truth.object_pose.push_back({time, {0.001 * k, 0.0, 0.0}});
    truth.finger_pose.push_back({time, {-0.05 + 0.001 * k, 0.0, 0.0}});
    truth_second.finger_pose.push_back({time, {-0.05 + 0.001 * k, 0.0, 0.0}});
    truth.force.push_back({time, {1.0, 0.0}});
    truth_second.force.push_back({time, {0.5, 0.1}});
    truth_second.contact_point.push_back({time, {-0.045, -0.02}});
  }
  truth.contact_point = {{0.0, {-0.045, 0.02}}, {0.04, {-0.045, 0.019}}, {0.04, {-0.045, 0.021}}, {0.08, {-0.045, 0.02}}};
  t.ground_truth = truth;
  second.ground_truth = truth_second;
  t.extra_fingers.push_back(second);
  evaluation::PushPlotOptions options;
  options.marks = 3;
  const std::string svg = evaluation::PushSvg(t, options);
  EXPECT_EQ(Count(svg, "class='footprint'"), 3);
  EXPECT_EQ(Count(svg, "class='finger-0'"), 3);
  EXPECT_EQ(Count(svg, "class='finger-1'"), 3);
  EXPECT_EQ(Count(svg, "class='finger-1-path'"), 1);
  EXPECT_EQ(Count(svg, "class='contact'"), 4 + 3);  // both of finger 0's contacts at t = 0.04
  EXPECT_EQ(Count(svg, "class='force-0'"), 3);
  EXPECT_EQ(Count(svg, "class='force-1'"), 3);
  EXPECT_NE(svg.find("up to 2 contacts of one finger at once"), std::string::npos);
  // Without ground truth (or asked for the measurements): the measured streams, here empty.
  options.ground_truth = false;
  EXPECT_THROW(evaluation::PushSvg(t, options), evaluation::EvaluationError);
}

// An estimate of a two-finger push: finger 1's shape at every marked step and its path, every
// contact of either finger and each contact's own force arrow.
TEST(PlotSvg, EstimatesOfTwoFingersDrawBothFingersAndEveryContact) {
  push::Trajectory traj = Push(true);
  push::ExtraFinger second;
  second.finger.shape = geometry::Shape::Disk(0.004, {0.0, -0.02});
  traj.extra_fingers.push_back(second);
  graph::EstimationResult result = Result(traj, true, true);
  for (graph::StateEstimate& s : result.states) {
    s.other_fingers.push_back({1, s.finger_pose, std::nullopt});
    if (!s.contact) continue;
    graph::ContactEstimate own, other;
    own.point = *s.contact;
    own.force = s.force;
    other.finger = 1;
    other.point = *s.contact + Vec2(0.0, -0.02);
    other.force = Vec2(0.2, 0.5);
    s.contacts = {own, other};
  }
  evaluation::TrajectoryPlotOptions options;
  options.every = 5;  // marked steps 0, 5, 10, 15, 20; in contact at 4 of them
  const std::string svg = evaluation::TrajectorySvg(traj, result, options);
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_EQ(Count(svg, "class='finger'"), 2 * 5);
  EXPECT_EQ(Count(svg, "class='finger-path-estimated'"), 2);
  EXPECT_EQ(Count(svg, "class='contact-estimated'"), 2 * 4);
  EXPECT_EQ(Count(svg, "class='force-estimated'"), 2 * 4);
}

TEST(PlotSvg, ErrorsNameThePathOrTheProblem) {
  const push::Trajectory traj = Push(true);
  const graph::EstimationResult result = Result(traj, true, true);
  const std::string bad = "/nonexistent-folder-pushgraph/plot.svg";
  try {
    evaluation::WriteTrajectorySvg(bad, traj, result);
    FAIL() << "no error for " << bad;
  } catch (const evaluation::EvaluationError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  try {
    evaluation::WriteTrajectorySvg("empty.svg", traj, graph::EstimationResult{});
    FAIL() << "no error for an empty result";
  } catch (const evaluation::EvaluationError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.svg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("without states"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists("empty.svg"));
  EXPECT_THROW(evaluation::TrajectorySvg(traj, graph::EstimationResult{}), evaluation::EvaluationError);
  EXPECT_THROW(evaluation::WriteSvgFile(bad, "<svg/>"), evaluation::EvaluationError);

  const std::string good = (std::filesystem::temp_directory_path() / "pushgraph_plot_test.svg").string();
  evaluation::WriteTrajectorySvg(good, traj, result);
  std::ifstream in(good);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), evaluation::TrajectorySvg(traj, result));
  std::filesystem::remove(good);
}

TEST(PlotSvg, ErrorSeriesMeasureDistanceToInterpolatedGroundTruth) {
  const push::Trajectory traj = Push(true);
  graph::EstimationResult offset = Result(traj, false, false);
  for (auto& s : offset.states) {
    s.t += 0.025;  // half-way between ground-truth samples: interpolated truth y = 0.0015 (k + 0.5)
    const double k = (s.t - 0.025) / 0.05;
    s.object_pose = Pose2{0.003, 0.0015 * (k + 0.5) + 0.004, 0.0};
  }
  offset.states.pop_back();  // stay inside the ground truth's time span
  const std::vector<evaluation::TimeSeries> series = evaluation::ObjectPositionErrorSeries(traj, {{"offset", &offset}});
  ASSERT_EQ(series.size(), 2u);
  EXPECT_EQ(series[0].label, "raw");
  ASSERT_EQ(series[0].value.size(), static_cast<std::size_t>(kStates));
  for (double v : series[0].value) EXPECT_NEAR(v, 2.0, 1e-9);  // measured 2 mm off in x
  EXPECT_EQ(series[1].label, "offset");
  ASSERT_EQ(series[1].value.size(), static_cast<std::size_t>(kStates - 1));
  for (double v : series[1].value) EXPECT_NEAR(v, 5.0, 1e-9);  // (3, 4) mm off
  EXPECT_THROW(evaluation::ObjectPositionErrorSeries(traj, {{"null", nullptr}}), evaluation::EvaluationError);
}

TEST(PlotSvg, TimeSeriesBreaksLinesAtGapsAndShadesWindows) {
  evaluation::TimeSeries a{"raw", {}, {}}, b{"QS", {}, {}};
  for (int k = 0; k < 50; ++k) {
    const double t = 0.04 * k;
    if (t < 0.6 || t > 1.0) a.t.push_back(t), a.value.push_back(2.0 + std::sin(t));  // occluded 0.6-1.0 s
    b.t.push_back(t), b.value.push_back(0.5);
  }
  const std::string svg = evaluation::TimeSeriesSvg({a, b}, "error <1>", "mm", {{0.6, 1.0}});
  Dump("series.svg", svg);
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_EQ(Count(svg, "class='series'"), 2);
  EXPECT_EQ(Count(svg, "class='shaded'"), 1);
  EXPECT_EQ(Count(FirstPath(svg, "series"), "M"), 2);  // raw: two pieces around the gap
  EXPECT_NE(svg.find("error &lt;1&gt;"), std::string::npos);
  EXPECT_NE(svg.find(">occlusion<"), std::string::npos);
  EXPECT_EQ(XmlProblem(evaluation::TimeSeriesSvg({}, "nothing", "mm")), "");

  const std::string stacked = evaluation::StackSvgVertically({svg, svg});
  EXPECT_EQ(XmlProblem(stacked), "");
  EXPECT_NE(stacked.find("height='600.00'"), std::string::npos);
  EXPECT_EQ(Count(stacked, "class='series'"), 4);
  EXPECT_THROW(evaluation::StackSvgVertically({"not svg"}), evaluation::EvaluationError);
}

// Unix time stamps (MIT recordings) are plotted from the first sample, so the ticks differ.
TEST(PlotSvg, UnixTimeStampsArePlottedFromTheFirstSample) {
  evaluation::TimeSeries a{"raw", {}, {}};
  for (int k = 0; k < 50; ++k) a.t.push_back(1461860553.5 + 0.02 * k), a.value.push_back(1.0 + 0.1 * k);
  const std::string svg = evaluation::TimeSeriesSvg({a}, "error", "mm", {{1461860553.9, 1461860554.1}});
  EXPECT_EQ(XmlProblem(svg), "");
  EXPECT_NE(svg.find("time from t0 = 1461860553.500 s"), std::string::npos);
  EXPECT_EQ(svg.find("1.46186e+09"), std::string::npos);
  EXPECT_NE(svg.find(">0.4<"), std::string::npos);  // a tick in seconds from t0
  EXPECT_EQ(Count(svg, "class='shaded'"), 1);
}

}  // namespace
