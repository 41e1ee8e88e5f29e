// Simulated pushes with several contacts: a finger wedged in the notched block's V, two fingers
// moving together, a flat pusher on a block face. At every sample the contacts' forces are in
// balance with the limit surface's load (conservation, 1e-9), nothing penetrates, the streams
// carry one contact row per contact and one force row per finger, and the files round-trip.
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/push/simulator.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

namespace pushgraph::push {
namespace {

using geometry::Shape;

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

Shape NotchedBlock() { return geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json"); }

// Conservation and the limit-surface condition at every moving sample, and no penetration.
void ExpectBalancedRun(const PushPlan& plan, const SimulationResult& r) {
  EXPECT_LE(r.stats.max_penetration, 1e-9);
  EXPECT_LE(r.stats.max_torque_residual, 1e-9);
  PushingSpec spec;
  spec.object = plan.object;
  spec.finger = plan.finger;
  const PushingModel model(spec);
  const double f_max = model.summary().f_max, tau_max = model.summary().tau_max;
  for (const SimulationState& s : r.states) {
    ASSERT_TRUE(s.contacts.has_value());
    const MultiPushResponse& m = *s.contacts;
    if (!m.moving) continue;
    const limit_surface::Load expected = limit_surface::SustainingLoad(model.support(), m.twist);
    EXPECT_LE((m.load.force - expected.force).norm(), 1e-9 * f_max) << "t = " << s.t;
    EXPECT_LE(std::abs(m.load.torque - expected.torque), 1e-9 * tau_max) << "t = " << s.t;
    Vec2 force = Vec2::Zero();
    double torque = 0.0;
    for (const ContactState& c : m.contacts) {
      const Vec2 f = s.object_pose.rotation().transpose() * c.force;
      force += f;
      torque += Cross(geometry::InverseAct(s.object_pose, c.point) - model.support().centre_of_pressure, f);
    }
    EXPECT_LE((force - m.load.force).norm(), 1e-9 * f_max) << "t = " << s.t;
    EXPECT_LE(std::abs(torque - m.load.torque), 1e-9 * tau_max) << "t = " << s.t;
  }
}

TEST(MultiContactSimulation, AFingerPushedIntoTheNotchWedgesAndTouchesBothWalls) {
  PushPlan plan;
  plan.object = {NotchedBlock(), 0.5, 0.3, {}, limit_surface::kStandardGravity};
  plan.finger = {Shape::Disk(0.005), 0.4};
  plan.object_pose = {0.01, -0.02, 0.2};
  plan.multi_contact = true;
  // From above into the V, slightly off its axis: the finger meets one wall, slides into the
  // apex region and wedges.
  plan.waypoints = StraightPushPath(plan, -M_PI / 2 + 0.2, 0.001, 0.005, 0.03);
  plan.noise = DefaultNoise(NoiseKind::kGaussian);
  const SimulationResult r = Simulate(plan);
  ExpectBalancedRun(plan, r);
  int wedged = 0;
  for (const SimulationState& s : r.states) wedged += s.contacts->contacts.size() == 2;
  EXPECT_GT(wedged, 50);
  // Two contact rows at each wedged contact sample, in the truth and the measurements alike.
  std::map<double, int> rows;
  for (const PointSample& p : r.trajectory.ground_truth->contact_point) ++rows[p.t];
  int doubled = 0;
  for (const auto& [t, n] : rows) doubled += n == 2;
  EXPECT_GT(doubled, 50);
  EXPECT_EQ(r.trajectory.measured.contact_point.size(), r.trajectory.ground_truth->contact_point.size());
  EXPECT_TRUE(HasRepeatedTimes(r.trajectory.measured.contact_point));
  // The block went down with the finger.
  EXPECT_LT(r.trajectory.ground_truth->object_pose.back().pose.y, plan.object_pose.y - 0.02);
  // The file keeps the repeated contact times.
  const push::Trajectory back = io::ParseTrajectoryJson(io::TrajectoryToJson(r.trajectory));
  EXPECT_EQ(back.measured.contact_point.size(), r.trajectory.measured.contact_point.size());
  EXPECT_EQ(io::TrajectoryToJson(back), io::TrajectoryToJson(r.trajectory));
}

TEST(MultiContactSimulation, TwoFingersPushTogetherAndEachHasItsStreams) {
  PushPlan plan;
  plan.object = {Shape::Box(0.09, 0.06), 0.8, 0.25, {}, limit_surface::kStandardGravity};
  plan.finger = {Shape::Disk(0.004, {0.0, 0.02}), 0.4};
  plan.extra_fingers = {{Shape::Disk(0.004, {0.0, -0.015}), 0.2}};
  plan.object_pose = {0.0, 0.0, 0.1};
  plan.waypoints = StraightPushPath(plan, 0.0, 0.0, 0.005, 0.03);
  plan.noise = DefaultNoise(NoiseKind::kGaussian);
  const SimulationResult r = Simulate(plan);
  ExpectBalancedRun(plan, r);
  const Trajectory& t = r.trajectory;
  ASSERT_EQ(FingerCount(t), 2);
  const FingerStreams& second = *t.extra_fingers[0].ground_truth;
  EXPECT_EQ(second.finger_pose.size(), t.ground_truth->finger_pose.size());
  EXPECT_EQ(second.force.size(), t.ground_truth->force.size());
  EXPECT_FALSE(second.contact_point.empty());
  // Each finger's force stream is its share; together they carry the load.
  int both = 0;
  for (const SimulationState& s : r.states) {
    if (!s.contacts->moving) continue;
    std::map<int, int> per_finger;
    for (const ContactState& c : s.contacts->contacts) ++per_finger[c.finger];
    both += per_finger.size() == 2;
    const Vec2 total = s.contacts->finger_force[0] + s.contacts->finger_force[1];
    EXPECT_LE((s.object_pose.rotation().transpose() * total - s.contacts->load.force).norm(), 1e-9);
  }
  EXPECT_GT(both, 50);  // the first finger touches first; the block turns until the second does
  // The second finger's sensors have their own noise.
  EXPECT_NE(t.extra_fingers[0].measured.force[10].force, second.force[10].force);
  EXPECT_NE(t.extra_fingers[0].measured.force[10].force - second.force[10].force,
            t.measured.force[10].force - t.ground_truth->force[10].force);
  const push::Trajectory back = io::ParseTrajectoryJson(io::TrajectoryToJson(t));
  EXPECT_EQ(io::TrajectoryToJson(back), io::TrajectoryToJson(t));
}

TEST(MultiContactSimulation, AFlatPusherKeepsItsLineContactCentredAndTurnsTheBlockOffCentre) {
  PushPlan plan;
  plan.object = {Shape::Box(0.09, 0.06), 0.8, 0.25, {}, limit_surface::kStandardGravity};
  plan.finger = {Shape::Box(0.004, 0.04, 0.001), 0.3};  // a bar, its face along y
  plan.multi_contact = true;
  for (const double offset : {0.0, 0.025}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    plan.waypoints = StraightPushPath(plan, 0.0, offset, 0.005, 0.03);
    const SimulationResult r = Simulate(plan);
    ExpectBalancedRun(plan, r);
    int line = 0, pushing = 0;
    for (const SimulationState& s : r.states) {
      line += s.contacts->contacts.size() == 2;
      pushing += s.contacts->moving;
    }
    const double turn = r.trajectory.ground_truth->object_pose.back().pose.theta;
    if (offset == 0.0) {
      // Face on face, centred: a line contact (its two ends) all along, the block translates.
      EXPECT_GE(line, pushing - 1);
      EXPECT_GT(pushing, 100);
      EXPECT_LT(std::abs(turn), 1e-9);
    } else {
      // Pushed along +x above its centre the block turns clockwise (one end of the line contact
      // opens).
      EXPECT_GE(line, 1);
      EXPECT_LT(turn, -0.01);
    }
  }
}

TEST(MultiContactSimulation, BadPlansNameTheFinger) {
  PushPlan plan;
  plan.object = {Shape::Box(0.09, 0.06), 0.8, 0.25, {}, limit_surface::kStandardGravity};
  plan.finger = {Shape::Disk(0.004, {0.0, 0.02}), 0.4};
  plan.extra_fingers = {{Shape::Disk(0.004, {0.0, 0.025}), 0.2}};
  plan.waypoints = {Vec2(-0.1, 0.0), Vec2(0.0, 0.0)};
  auto message = [&](const PushPlan& p) {
    try {
      Simulate(p);
    } catch (const PushError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(plan).find("fingers 0 and 1 overlap"), std::string::npos) << message(plan);
  plan.extra_fingers[0].shape = Shape::Disk(0.004, {0.09, 0.0});  // 9 cm ahead: inside the block
  EXPECT_NE(message(plan).find("finger 1 starts inside the object"), std::string::npos) << message(plan);
  plan.extra_fingers[0].shape = Shape();
  EXPECT_NE(message(plan).find("extra_fingers[0].shape is empty"), std::string::npos) << message(plan);
}

}  // namespace
}  // namespace pushgraph::push
