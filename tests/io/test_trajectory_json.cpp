// The trajectory file format: round trip, sorting, and a clear error for every kind of bad input.
#include <pushgraph/io/trajectory_json.h>

#include <gtest/gtest.h>

#include <string>

namespace {

using pushgraph::io::IoError;
using pushgraph::io::ParseTrajectoryJson;
using pushgraph::io::TrajectoryToJson;

const std::string kShape = R"({"polygons": [{"outer": [[-0.045,-0.045],[0.045,-0.045],[0.045,0.045],[-0.045,0.045]]}]})";
const std::string kFinger = R"({"polygons": [{"outer": [[0,0]]}], "radius": 0.00235})";

std::string Doc(const std::string& streams, const std::string& extra = "") {
  return R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
         R"(, "mass": 0.8374, "mu_surface": 0.25, "pressure": "uniform"}, "finger": {"shape": )" + kFinger +
         R"(, "mu_contact": 0.3}, "streams": )" + streams + extra + "}";
}

TEST(TrajectoryJson, RoundTripIsExact) {
  const auto t = ParseTrajectoryJson(Doc(
      R"({"object_pose": [[0.0, 0.1, 0.2, 0.3], [0.04, 0.10000000000000001, 0.2, -3.1]],
          "finger_pose": [[0.0, -0.05, 0.0, 0.0]], "contact_point": [[0.004, -0.045, 0.001]],
          "force": [[0.004, 1.5, -0.25]]})",
      R"(, "ground_truth": {"object_pose": [[0.0, 0.1, 0.2, 0.3]]})"));
  ASSERT_EQ(t.measured.object_pose.size(), 2u);
  EXPECT_EQ(t.measured.object_pose[1].pose.x, 0.10000000000000001);
  EXPECT_EQ(t.measured.object_pose[1].pose.theta, -3.1);
  EXPECT_EQ(t.measured.force[0].force.y(), -0.25);
  ASSERT_TRUE(t.ground_truth.has_value());
  EXPECT_EQ(t.ground_truth->object_pose.size(), 1u);
  EXPECT_TRUE(t.ground_truth->force.empty());
  EXPECT_EQ(t.finger.shape.radius(), 0.00235);
  for (int indent : {-1, 1}) {
    const auto u = ParseTrajectoryJson(TrajectoryToJson(t, indent));
    EXPECT_EQ(TrajectoryToJson(u, indent), TrajectoryToJson(t, indent));
    EXPECT_EQ(u.measured.object_pose[1].pose.x, t.measured.object_pose[1].pose.x);
    EXPECT_EQ(u.object.mass, 0.8374);
  }
  // The writer refuses what the reader would (a mass of -1 was written, then refused on reading).
  for (const double mass : {-1.0, 0.0, double(NAN)}) {
    auto bad = t;
    bad.object.mass = mass;
    EXPECT_THROW(TrajectoryToJson(bad, -1), IoError) << mass;
  }
  auto bad_mu = t;
  bad_mu.object.mu_surface = 50.0;
  EXPECT_THROW(TrajectoryToJson(bad_mu, -1), IoError);
}

TEST(TrajectoryJson, MissingStreamsAreEmptyAndOutOfOrderSamplesAreSorted) {
  const auto t = ParseTrajectoryJson(Doc(R"({"force": [[0.3, 1, 0], [0.1, 2, 0], [0.2, 3, 0]]})"));
  EXPECT_TRUE(t.measured.object_pose.empty());
  EXPECT_FALSE(t.ground_truth.has_value());
  ASSERT_EQ(t.measured.force.size(), 3u);
  EXPECT_EQ(t.measured.force[0].t, 0.1);
  EXPECT_EQ(t.measured.force[0].force.x(), 2.0);
  EXPECT_EQ(t.measured.force[2].t, 0.3);
  // The reordering is reported when asked for.
  std::vector<std::string> notes;
  ParseTrajectoryJson(Doc(R"({"force": [[0.3, 1, 0], [0.1, 2, 0], [0.2, 3, 0]]})"), "push.json", &notes);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("streams.force: sorted 2 row(s)"), std::string::npos) << notes[0];  // both after 0.3
  EXPECT_NE(notes[0].find("row [1]"), std::string::npos) << notes[0];
  notes.clear();
  ParseTrajectoryJson(Doc(R"({"force": [[0.1, 1, 0], [0.2, 2, 0]]})"), "push.json", &notes);
  EXPECT_TRUE(notes.empty());
}

void ExpectError(const std::string& text, const std::string& needle) {
  try {
    ParseTrajectoryJson(text, "push.json");
    FAIL() << "no error for: " << needle;
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("push.json"), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

// A stream whose clock goes back by more than max(1 s, 100 median periods): two recordings
// joined (or a clock reset), refused naming the row; sorting interleaved such a file into one
// nonsense push. A few rows out of order are still sorted.
TEST(TrajectoryJson, AClockThatGoesBackIsRefused) {
  std::string rows;
  for (int i = 0; i <= 300; ++i) rows += (i ? "," : "") + std::string("[") + std::to_string(0.004 * i) + ", 1, 0]";
  for (int i = 0; i <= 10; ++i) rows += ",[" + std::to_string(0.002 + 0.004 * i) + ", 2, 0]";
  ExpectError(Doc(R"({"force": [)" + rows + "]}"), "streams.force: row [301] goes back in time by 1.198 s");
  ExpectError(Doc(R"({"force": [)" + rows + "]}"), "are two recordings joined");
  EXPECT_NO_THROW(ParseTrajectoryJson(Doc(R"({"force": [[0.0, 1, 0], [0.3, 1, 0], [0.1, 2, 0], [0.2, 3, 0]]})")));
  // A stream logged newest first is read in reverse, with a note (2 s at 25 Hz backwards was
  // refused as "two recordings joined ... the stream's median period is 0 s").
  std::string reversed;
  for (int i = 50; i >= 0; --i) reversed += (i < 50 ? "," : "") + std::string("[") + std::to_string(0.04 * i) + ", " + std::to_string(i) + ", 0]";
  std::vector<std::string> notes;
  const auto t = ParseTrajectoryJson(Doc(R"({"force": [)" + reversed + "]}"), "push.json", &notes);
  ASSERT_EQ(t.measured.force.size(), 51u);
  EXPECT_EQ(t.measured.force.front().t, 0.0);
  EXPECT_EQ(t.measured.force.back().force.x(), 50.0);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("streams.force: rows logged newest first, read in reverse"), std::string::npos) << notes[0];
  // With one pair of rows swapped too: reversed, then that pair sorted (helper-27 N5: it was
  // refused as "two recordings joined" again).
  std::string reversed_swapped;
  for (int i = 50; i >= 0; --i) {
    const int k = i == 30 ? 29 : i == 29 ? 30 : i;
    reversed_swapped += (i < 50 ? "," : "") + std::string("[") + std::to_string(0.04 * k) + ", " + std::to_string(k) + ", 0]";
  }
  notes.clear();
  const auto again = ParseTrajectoryJson(Doc(R"({"force": [)" + reversed_swapped + "]}"), "push.json", &notes);
  ASSERT_EQ(again.measured.force.size(), 51u);
  for (std::size_t i = 0; i < again.measured.force.size(); ++i) EXPECT_EQ(again.measured.force[i].force.x(), double(i));
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("rows logged newest first, read in reverse"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("sorted 1 row(s)"), std::string::npos) << notes[1];
  // The period in the message comes from the time stamps in order: rows swapped in pairs have
  // forward steps of 12 ms in file order but a period of 4 ms, so a clock that then goes back by
  // 1.1 s is refused (with 12 ms the limit was max(1 s, 1.2 s) and it passed).
  std::string swapped;
  for (int i = 0; i < 300; i += 2)
    for (const int k : {i + 1, i}) swapped += (swapped.empty() ? "" : ",") + std::string("[") + std::to_string(0.004 * k) + ", 1, 0]";
  swapped += ",[" + std::to_string(0.004 * 299 - 1.1) + ", 2, 0]";
  ExpectError(Doc(R"({"force": [)" + swapped + "]}"), "the stream's median period is 0.004 s");
  // Contacts of one time keep their file order when the stream is reversed.
  notes.clear();
  const auto two = ParseTrajectoryJson(
      Doc(R"({"contact_point": [[0.2, 5, 0], [0.1, 3, 0], [0.1, 4, 0], [0.0, 1, 0], [0.0, 2, 0]]})"), "push.json", &notes);
  ASSERT_EQ(two.measured.contact_point.size(), 5u);
  EXPECT_EQ(two.measured.contact_point[0].point.x(), 1.0);
  EXPECT_EQ(two.measured.contact_point[1].point.x(), 2.0);
  EXPECT_EQ(two.measured.contact_point[2].point.x(), 3.0);
  EXPECT_EQ(two.measured.contact_point[3].point.x(), 4.0);
  ASSERT_EQ(notes.size(), 1u);
}

TEST(TrajectoryJson, MeasurementSigmasRoundTripAndAreChecked) {
  const auto t = ParseTrajectoryJson(Doc(
      "{}", R"(, "measurement_sigmas": {"object_pose": [0.002, 0.02], "finger_pose": [0.0005, 0], "contact_point": 0.001, "force": 0.05})"));
  ASSERT_TRUE(t.measurement_sigmas.has_value());
  EXPECT_EQ(t.measurement_sigmas->object_rot, 0.02);
  EXPECT_EQ(t.measurement_sigmas->finger_trans, 0.0005);
  EXPECT_EQ(t.measurement_sigmas->force, 0.05);
  for (int indent : {-1, 1}) {
    const auto u = ParseTrajectoryJson(TrajectoryToJson(t, indent));
    ASSERT_TRUE(u.measurement_sigmas.has_value());
    EXPECT_EQ(u.measurement_sigmas->contact, 0.001);
    EXPECT_EQ(u.measurement_sigmas->object_trans, 0.002);
  }
  EXPECT_FALSE(ParseTrajectoryJson(Doc("{}")).measurement_sigmas.has_value());
  ExpectError(Doc("{}", R"(, "measurement_sigmas": {"force": -1})"), "measurement_sigmas.force");
  ExpectError(Doc("{}", R"(, "measurement_sigmas": {"object_pose": 0.1})"), "measurement_sigmas.object_pose");
  ExpectError(Doc("{}", R"(, "measurement_sigmas": {"gps": 1})"), "unknown field \"gps\"");
}

TEST(TrajectoryJson, BadInputNamesFileAndPath) {
  ExpectError("{", "malformed JSON");
  ExpectError(Doc("{}", R"(, "extra": 1)"), "unknown field \"extra\"");
  ExpectError(Doc(R"({"object_pose": [[0, 1, 2]]})"), "streams.object_pose[0]");
  ExpectError(Doc(R"({"object_pose": [[0, 1, 2, "x"]]})"), "streams.object_pose[0][3]");
  // A row with a finger index in a one-finger file: said why it is too long.
  ExpectError(Doc(R"({"force": [[0.0, 0, 1.0, 0.0]]})"), "with one finger the rows carry no finger index");
  ExpectError(Doc(R"({"force": [[0, 1e999, 2]]})"), "malformed JSON");
  // Where: the parser's "number overflow parsing '1e999'" had no place.
  ExpectError("{\"format\": \"pushgraph-trajectory-1\",\n \"streams\": {\"force\": [[0, 1e9999, 2]]}}",
              "number overflow parsing '1e9999' at line 2, column 28 (beyond a double's range");
  // Not the same text inside a string before it.
  ExpectError("{\"format\": \"1e9999\",\n \"streams\": {\"force\": [[0, 1e9999, 2]]}}",
              "number overflow parsing '1e9999' at line 2, column 28");
  ExpectError(Doc(R"({"force": [[0, 1, 2], [0, 1, 2]]})"), "same time stamp");
  // Less than a nanosecond apart: the same time stamp too (1e-12 s apart and 3 cm different was
  // read as a 30 km/s jump); a microsecond apart is two samples.
  ExpectError(Doc(R"({"object_pose": [[0.5, 0, 0, 0], [0.500000000001, 0.03, 0, 0]]})"),
              "streams.object_pose: rows [0] and [1] are 1e-12 s apart");
  ExpectError(Doc(R"({"object_pose": [[0.5, 0, 0, 0], [0.500000000001, 0.03, 0, 0]]})"), "less than 1 ns");
  EXPECT_EQ(ParseTrajectoryJson(Doc(R"({"object_pose": [[0.5, 0, 0, 0], [0.500001, 0, 0, 0]]})")).measured.object_pose.size(), 2u);
  ExpectError(Doc(R"({"velocity": []})"), "unknown field \"velocity\"");
  std::string bad_format = Doc("{}");
  bad_format.replace(bad_format.find("trajectory-1"), 12, "trajectory-9");
  ExpectError(bad_format, "format");
  std::string bad_mass = Doc("{}");
  bad_mass.replace(bad_mass.find("0.8374"), 6, "-1.000");
  ExpectError(bad_mass, "object.mass");
  std::string bad_shape = Doc("{}");
  bad_shape.replace(bad_shape.find("[0.045,0.045]"), 13, "[-0.045,-0.045]");
  ExpectError(bad_shape, "object.shape");
  std::string point_finger = Doc("{}");
  point_finger.replace(point_finger.find(", \"radius\": 0.00235"), 19, "");
  ExpectError(point_finger, "finger.shape");
  // A key given twice would silently keep the last value: refused, with where it is.
  std::string twice = Doc("{}");
  twice.replace(twice.find("\"mass\""), 6, "\"mass\": 5, \"mass\"");
  ExpectError(twice, "duplicate key \"mass\" in /object");
}

// Several fingers: "fingers" lists them; finger rows carry the finger's index after the time;
// contact_point may repeat a time (one row per contact); every row goes to its finger.
std::string MultiDoc(const std::string& streams, const std::string& extra = "") {
  return R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
         R"(, "mass": 0.8374, "mu_surface": 0.25}, "fingers": [{"shape": )" + kFinger +
         R"(, "mu_contact": 0.3}, {"shape": )" + kFinger + R"(, "mu_contact": 0.5}], "streams": )" + streams + extra + "}";
}

TEST(TrajectoryJson, SeveralFingersRoundTrip) {
  const auto t = ParseTrajectoryJson(MultiDoc(
      R"({"object_pose": [[0.0, 0.1, 0.2, 0.3]],
          "finger_pose": [[0.0, 1, -0.05, 0.02, 0.0], [0.0, 0, -0.05, -0.02, 0.0], [0.004, 0, -0.049, -0.02, 0.0]],
          "contact_point": [[0.004, 0, -0.045, 0.001], [0.004, 0, -0.045, 0.003], [0.004, 1, -0.045, 0.02]],
          "force": [[0.004, 1, 1.5, -0.25], [0.004, 0, 1.0, 0.0]]})",
      R"(, "ground_truth": {"force": [[0.004, 1, 1.4, -0.2]]})"));
  ASSERT_EQ(t.extra_fingers.size(), 1u);
  EXPECT_EQ(t.extra_fingers[0].finger.mu_contact, 0.5);
  ASSERT_EQ(t.measured.finger_pose.size(), 2u);
  EXPECT_EQ(t.measured.finger_pose[1].pose.x, -0.049);
  ASSERT_EQ(t.measured.contact_point.size(), 2u);  // two contacts of finger 0 at t = 0.004
  EXPECT_EQ(t.measured.contact_point[1].point.y(), 0.003);
  ASSERT_EQ(t.extra_fingers[0].measured.finger_pose.size(), 1u);
  EXPECT_EQ(t.extra_fingers[0].measured.finger_pose[0].pose.y, 0.02);
  ASSERT_EQ(t.extra_fingers[0].measured.contact_point.size(), 1u);
  EXPECT_EQ(t.extra_fingers[0].measured.force[0].force.x(), 1.5);
  EXPECT_EQ(t.measured.force[0].force.x(), 1.0);
  ASSERT_TRUE(t.extra_fingers[0].ground_truth.has_value());
  EXPECT_EQ(t.extra_fingers[0].ground_truth->force[0].force.x(), 1.4);
  EXPECT_TRUE(t.ground_truth->force.empty());
  // Written and read back: the same values, rows in time order with their finger's index.
  const std::string text = TrajectoryToJson(t);
  EXPECT_NE(text.find("\"fingers\""), std::string::npos);
  EXPECT_NE(text.find("[0.004,1,1.5,-0.25]"), std::string::npos) << text;
  const auto back = ParseTrajectoryJson(text);
  EXPECT_EQ(TrajectoryToJson(back), text);
  ASSERT_EQ(back.extra_fingers.size(), 1u);
  EXPECT_EQ(back.extra_fingers[0].measured.contact_point[0].point.y(), 0.02);
  // One finger: the single-finger form, unchanged.
  auto one = back;
  one.extra_fingers.clear();
  EXPECT_EQ(TrajectoryToJson(one).find("\"fingers\""), std::string::npos);
}

TEST(TrajectoryJson, SeveralFingersBadInputNamesRowAndFinger) {
  ExpectError(MultiDoc(R"({"force": [[0.0, 2, 1.0, 0.0]]})"), "streams.force[0][1]: finger index 2 is not one of the 2 fingers");
  ExpectError(MultiDoc(R"({"force": [[0.0, 0.5, 1.0, 0.0]]})"), "finger index 0.5");
  ExpectError(MultiDoc(R"({"force": [[0.0, -1, 1.0, 0.0]]})"), "finger index -1");
  ExpectError(MultiDoc(R"({"force": [[0.0, 1.0, 0.0]]})"), "must be a row of 4 numbers [t, finger, ...]");
  ExpectError(MultiDoc(R"({"force": [[0.1, 1, 1.0, 0.0], [0.1, 1, 2.0, 0.0]]})"),
              "rows [0] and [1] of finger 1 have the same time stamp");
  ExpectError(MultiDoc("{}", R"(, "finger": {"shape": )" + kFinger + R"(, "mu_contact": 0.3})"),
              "has both \"finger\" and \"fingers\"");
  ExpectError(R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
                  R"(, "mass": 1, "mu_surface": 0.25}, "fingers": []})",
              "fingers: must be a non-empty array");
  ExpectError(R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
                  R"(, "mass": 1, "mu_surface": 0.25}, "fingers": [{"shape": )" + kFinger + R"(, "mu_contact": -1}]})",
              "fingers[0].mu_contact");
  // Friction coefficients beyond the command line's [0, 10] (mu_surface 50 ran, forces of 157 N).
  ExpectError(R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
                  R"(, "mass": 1, "mu_surface": 50}, "fingers": [{"shape": )" + kFinger + R"(, "mu_contact": 0.3}]})",
              "object.mu_surface: must be at most 10");
  ExpectError(R"({"format": "pushgraph-trajectory-1", "object": {"shape": )" + kShape +
                  R"(, "mass": 1, "mu_surface": 0.3}, "fingers": [{"shape": )" + kFinger + R"(, "mu_contact": 11}]})",
              "fingers[0].mu_contact: must be at most 10");
  // A single finger's contact_point may repeat a time (a finger wedged in a notch); other
  // streams may not.
  EXPECT_EQ(ParseTrajectoryJson(Doc(R"({"contact_point": [[0.1, 0, 0], [0.1, 1, 0]]})")).measured.contact_point.size(), 2u);
  // The same contact twice is a row written twice, not two contacts (a file with every contact row
  // duplicated was estimated with two contacts at each point); among other contacts at that time too.
  ExpectError(Doc(R"({"contact_point": [[0.1, 0.02, 0.001], [0.1, 0.02, 0.001]]})"),
              "streams.contact_point: rows [0] and [1] are the same contact point (0.02, 0.001) at t = 0.1");
  ExpectError(Doc(R"({"contact_point": [[0.1, 0.02, 0.001], [0.1, 0.03, 0.0], [0.1, 0.02, 0.001]]})"),
              "rows [0] and [2] are the same contact point");
}

}  // namespace
