// Quasi-static pushing with several contacts (MultiPushingModel). Every answer is checked for the
// model's conditions independently of how it was found: the contacts' wrenches sum to the load
// (conservation), the load is the limit surface's load for the twist (recomputed here), every
// force lies in its friction cone, sticking contacts move with their finger, sliding ones match
// its normal velocity with the force on the cone edge opposing the slip, open ones separate with
// no force. With one contact the answer is PushingModel's.
#include <pushgraph/limit_surface/ellipsoid.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/push/multi_contact.h>
#include <pushgraph/push/pushing.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "test_scale.h"

namespace pushgraph::push {
namespace {

using geometry::Pose2;
using geometry::Shape;
using pushgraph::testing::Scaled;

constexpr double kTol = 1e-9;

Shape NotchedBlock() { return geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json"); }

ObjectDescription Object(const Shape& shape, double mass, double mu_surface) {
  ObjectDescription o;
  o.shape = shape;
  o.mass = mass;
  o.mu_surface = mu_surface;
  return o;
}

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The model's conditions, checked from the response alone.
void ExpectPhysical(const MultiPushingModel& model, const MultiPushResponse& r, const Pose2& object,
                    const std::vector<Vec2>& motions, const std::string& where) {
  SCOPED_TRACE(where);
  if (!r.moving) {
    for (const ContactState& c : r.contacts) EXPECT_EQ(c.force.norm(), 0.0);
    return;
  }
  const auto& summary = model.summary();
  const Vec2 cop = model.support().centre_of_pressure;
  const Eigen::Matrix2d R = object.rotation();
  // Limit surface: the load is the surface's load for the twist.
  const Load expected = model.SurfaceLoad(r.twist);
  EXPECT_LE((expected.force - r.load.force).norm(), kTol * summary.f_max);
  EXPECT_LE(std::abs(expected.torque - r.load.torque), kTol * summary.tau_max);
  // Conservation: the contact wrenches (body axes, about the centre of pressure) sum to the load.
  Vec2 force = Vec2::Zero();
  double torque = 0.0;
  std::vector<Vec2> per_finger(motions.size(), Vec2::Zero());
  double speed = 0.0;
  for (const Vec2& u : motions) speed = std::max(speed, u.norm());
  for (const ContactState& c : r.contacts) {
    const Vec2 f = R.transpose() * c.force;
    const Vec2 arm = geometry::InverseAct(object, c.point) - cop;
    force += f;
    torque += Cross(arm, f);
    per_finger[c.finger] += c.force;
    const Vec2 n = R.transpose() * c.normal, t(-n.y(), n.x());
    const Vec2 u = R.transpose() * motions[c.finger];
    const Vec2 v(r.twist.vx - r.twist.omega * arm.y(), r.twist.vy + r.twist.omega * arm.x());
    const double mu = model.spec().fingers[c.finger].mu_contact;
    switch (c.mode) {
      case ContactMode::kSticking:
        EXPECT_LE((v - u).norm(), kTol * speed);
        EXPECT_GE(f.dot(n), -kTol * summary.f_max);
        EXPECT_LE(std::abs(f.dot(t)), mu * f.dot(n) + kTol * summary.f_max);
        break;
      case ContactMode::kSliding: {
        EXPECT_LE(std::abs((v - u).dot(n)), kTol * speed);
        EXPECT_GE(f.dot(n), -kTol * summary.f_max);
        // On the cone edge, on the side of the finger's slip.
        EXPECT_NEAR(f.dot(t), c.slip_direction * mu * f.dot(n), kTol * summary.f_max);
        if (mu > 0.0) {
          EXPECT_GE(c.slip_direction * (u - v).dot(t), -kTol * speed);
        }
        break;
      }
      case ContactMode::kSeparated:
        EXPECT_EQ(c.force.norm(), 0.0);
        EXPECT_GE((v - u).dot(n), -kTol * speed);  // the contact opens
        break;
    }
  }
  EXPECT_LE((force - r.load.force).norm(), kTol * summary.f_max);
  EXPECT_LE(std::abs(torque - r.load.torque), kTol * summary.tau_max);
  for (std::size_t i = 0; i < motions.size(); ++i) EXPECT_LE((per_finger[i] - r.finger_force[i]).norm(), 1e-15);
}

// The notched block's V: walls from (+-0.015, 0.04) to the apex (0, 0.012).
Vec2 WedgedCentre(double radius) {
  const Vec2 wall = Vec2(0.015, 0.028).normalized();
  return {0.0, 0.012 + radius / std::sin(std::atan2(wall.x(), wall.y()))};
}

TEST(MultiContact, OneContactIsThePushingModelsAnswer) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const SurfaceModel surface : {SurfaceModel::kExact, SurfaceModel::kEllipsoid}) {
    for (const double mu : {0.0, 0.2, 0.8}) {
      PushingSpec single;
      single.object = Object(NotchedBlock(), 0.5, 0.3);
      single.finger = {Shape::Disk(0.004), mu};
      single.surface = surface;
      const PushingModel reference(single);
      MultiPushingSpec spec;
      spec.object = single.object;
      spec.fingers = {single.finger};
      spec.surface = surface;
      const MultiPushingModel model(spec);
      int compared = 0;
      for (int trial = 0; trial < Scaled(60); ++trial) {
        // A finger touching the block's bottom or side faces at a random point, pushing inwards.
        const Pose2 object{unit(rng) - 0.5, unit(rng) - 0.5, 6.0 * unit(rng)};
        const bool bottom = trial % 2 == 0;
        const Vec2 local = bottom ? Vec2(-0.05 + 0.1 * unit(rng), -0.04 - 0.004) : Vec2(0.06 + 0.004, -0.03 + 0.06 * unit(rng));
        const Vec2 inward = bottom ? Vec2(0.0, 1.0) : Vec2(-1.0, 0.0);
        const double a = (unit(rng) - 0.5) * 2.4;  // up to ~69 degrees off the normal
        const Vec2 d = 1e-4 * Vec2(std::cos(a) * inward.x() - std::sin(a) * inward.y(), std::sin(a) * inward.x() + std::cos(a) * inward.y());
        const Vec2 c = geometry::Act(object, local);
        const Pose2 finger{c.x(), c.y(), 0.0};
        const std::vector<Vec2> motion{object.rotation() * d};
        const PushResponse expected = reference.Respond(object, finger, motion[0]);
        const MultiPushResponse got = model.Respond(object, {finger}, motion);
        ASSERT_EQ(got.contacts.size(), 1u);
        ExpectPhysical(model, got, object, motion, "trial " + std::to_string(trial));
        ASSERT_EQ(got.contacts[0].mode, expected.mode) << "trial " << trial << " mu " << mu;
        const double scale = 1e-4;
        EXPECT_NEAR(got.twist.vx, expected.twist.vx, 1e-9 * scale);
        EXPECT_NEAR(got.twist.vy, expected.twist.vy, 1e-9 * scale);
        EXPECT_NEAR(got.twist.omega, expected.twist.omega, 1e-9 * scale / 0.05);
        EXPECT_LE((got.contacts[0].force - expected.force).norm(), 1e-9 * model.summary().f_max);
        EXPECT_EQ(got.contacts[0].slip_direction, expected.slip_direction);
        ++compared;
      }
      EXPECT_EQ(compared, Scaled(60));
    }
  }
}

TEST(MultiContact, AFingerPushedIntoTheVSticksOnBothWalls) {
  // The notched block's outline without its holes: symmetric about the V's axis.
  MultiPushingSpec spec;
  spec.object = Object(Shape::FromPolygons({{NotchedBlock().polygons()[0].outer, {}}}), 0.5, 0.3);
  const double radius = 0.005;
  spec.fingers = {{Shape::Disk(radius), 0.5}};
  const MultiPushingModel model(spec);
  for (const double theta : {0.0, 1.1}) {
    const Pose2 object{0.2, 0.1, theta};
    const Vec2 c = geometry::Act(object, WedgedCentre(radius));
    const std::vector<Vec2> motion{object.rotation() * Vec2(0.0, -1e-4)};  // straight into the V
    const MultiPushResponse r = model.Respond(object, {{c.x(), c.y(), 0.0}}, motion);
    ASSERT_EQ(r.contacts.size(), 2u);
    ExpectPhysical(model, r, object, motion, "straight");
    EXPECT_EQ(r.contacts[0].mode, ContactMode::kSticking);
    EXPECT_EQ(r.contacts[1].mode, ContactMode::kSticking);
    // The block is symmetric: it translates with the finger, the walls share the load evenly,
    // with normal forces only (the least-friction split of the indeterminate pair).
    EXPECT_NEAR(r.twist.omega, 0.0, 1e-12);
    const Vec2 f0 = object.rotation().transpose() * r.contacts[0].force;
    const Vec2 f1 = object.rotation().transpose() * r.contacts[1].force;
    EXPECT_NEAR(f0.x(), -f1.x(), 1e-9 * model.summary().f_max);
    EXPECT_NEAR(f0.y(), f1.y(), 1e-9 * model.summary().f_max);
    EXPECT_NEAR(Cross(r.contacts[0].normal, r.contacts[0].force), 0.0, 1e-9 * model.summary().f_max);
    // The net force is the sliding friction of the whole block (mu m g), along the push.
    EXPECT_NEAR(r.finger_force[0].norm(), model.summary().f_max, 1e-9 * model.summary().f_max);
  }
}

TEST(MultiContact, EveryPushOfAWedgedFingerSatisfiesTheModel) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const double mu : {0.0, 0.15, 0.6}) {
    MultiPushingSpec spec;
    spec.object = Object(NotchedBlock(), 0.5, 0.3);
    const double radius = 0.005;
    spec.fingers = {{Shape::Disk(radius), mu}};
    for (const SurfaceModel surface : {SurfaceModel::kExact, SurfaceModel::kEllipsoid}) {
      spec.surface = surface;
      const MultiPushingModel model(spec);
      int modes[3] = {0, 0, 0};
      // At least 80 trials even scaled down (the sanitizer stage): fewer need not reach every mode.
      for (int trial = 0; trial < Scaled(80, 80); ++trial) {
        const Pose2 object{unit(rng), unit(rng), 6.0 * unit(rng)};
        const Vec2 c = geometry::Act(object, WedgedCentre(radius));
        const double a = -M_PI / 2 + (unit(rng) - 0.5) * 2.8;  // around straight in
        const std::vector<Vec2> motion{object.rotation() * (1e-4 * Vec2(std::cos(a), std::sin(a)))};
        MultiPushResponse r;
        try {
          r = model.Respond(object, {{c.x(), c.y(), 0.0}}, motion);
        } catch (const PushError& e) {
          ADD_FAILURE() << "trial " << trial << ": " << e.what();
          continue;
        }
        ASSERT_EQ(r.contacts.size(), 2u);
        ExpectPhysical(model, r, object, motion, "mu " + std::to_string(mu) + " trial " + std::to_string(trial));
        for (const ContactState& s : r.contacts) ++modes[static_cast<int>(s.mode)];
      }
      // The sample covers sliding, opening (with little friction: with much the finger sticks
      // on one wall and the block translates with it) and sticking (when friction allows).
      EXPECT_GT(modes[static_cast<int>(ContactMode::kSliding)], 0);
      if (mu < 0.3) {
        EXPECT_GT(modes[static_cast<int>(ContactMode::kSeparated)], 0);
      }
      if (mu > 0.3) {
        EXPECT_GT(modes[static_cast<int>(ContactMode::kSticking)], 0);
      }
    }
  }
}

TEST(MultiContact, TwoFingersAndAFlatPusherSatisfyTheModel) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Shape block = Shape::Box(0.09, 0.06);
  // Two disks 3 cm apart on the block's left face, moving together.
  MultiPushingSpec two;
  two.object = Object(block, 0.8, 0.25);
  two.fingers = {{Shape::Disk(0.004), 0.4}, {Shape::Disk(0.004), 0.2}};
  const MultiPushingModel two_model(two);
  // A flat pusher (a rounded bar) whose face lies on the block's left face, off centre: from
  // below or near the centre of pressure up past the block's corner.
  MultiPushingSpec flat;
  flat.object = two.object;
  flat.fingers = {{Shape::Box(0.004, 0.05, 0.001), 0.3}};
  const MultiPushingModel flat_model(flat);
  int rotating = 0;
  for (int trial = 0; trial < Scaled(60); ++trial) {
    const Pose2 object{unit(rng), unit(rng), 6.0 * unit(rng)};
    const double shift = (unit(rng) - 0.5) * 0.02;
    const double a = (unit(rng) - 0.5) * 2.0;
    const Vec2 d = object.rotation() * (1e-4 * Vec2(std::cos(a), std::sin(a)));
    const Vec2 c0 = geometry::Act(object, Vec2(-0.045 - 0.004, shift + 0.015));
    const Vec2 c1 = geometry::Act(object, Vec2(-0.045 - 0.004, shift - 0.015));
    const MultiPushResponse r2 =
        two_model.Respond(object, {{c0.x(), c0.y(), 0.0}, {c1.x(), c1.y(), 0.0}}, {d, d});
    ASSERT_EQ(r2.contacts.size(), 2u);
    ExpectPhysical(two_model, r2, object, {d, d}, "two fingers, trial " + std::to_string(trial));
    const Vec2 bar = geometry::Act(object, Vec2(-0.045 - 0.003, 0.02 + shift));
    const MultiPushResponse rf = flat_model.Respond(object, {{bar.x(), bar.y(), object.theta}}, {d});
    ASSERT_EQ(rf.contacts.size(), 2u) << "trial " << trial;
    ExpectPhysical(flat_model, rf, object, {d}, "flat pusher, trial " + std::to_string(trial));
    if (std::abs(rf.twist.omega) > 1e-6) ++rotating;
  }
  EXPECT_GT(rotating, 0);  // an off-centre line contact can turn the block (one end opens)
}

TEST(MultiContact, FingersSqueezingTheObjectJamIt) {
  MultiPushingSpec spec;
  spec.object = Object(Shape::Box(0.09, 0.06), 0.8, 0.25);
  spec.fingers = {{Shape::Disk(0.004), 0.4}, {Shape::Disk(0.004), 0.4}};
  const MultiPushingModel model(spec);
  const Pose2 object{0.0, 0.0, 0.0};
  try {
    model.Respond(object, {{-0.049, 0.0, 0.0}, {0.049, 0.0, 0.0}}, {Vec2(1e-4, 0.0), Vec2(-1e-4, 0.0)});
    FAIL() << "no error";
  } catch (const PushError& e) {
    EXPECT_NE(std::string(e.what()).find("jam"), std::string::npos) << e.what();
  }
}

TEST(MultiContact, AWedgedPushStaysOutOfTheObjectStepByStep) {
  MultiPushingSpec spec;
  spec.object = Object(NotchedBlock(), 0.5, 0.3);
  const double radius = 0.005;
  spec.fingers = {{Shape::Disk(radius), 0.5}};
  const MultiPushingModel model(spec);
  Pose2 object{0.0, 0.0, 0.3};
  const Vec2 start = geometry::Act(object, WedgedCentre(radius) + Vec2(0.0, 0.003));
  std::vector<Pose2> finger{{start.x(), start.y(), 0.0}};
  // Straight into the V, then slanted: 40 mm in 0.2 mm steps.
  const Vec2 in = object.rotation() * Vec2(0.0, -2e-4);
  const Vec2 slanted = object.rotation() * Vec2(0.8e-4, -1.8e-4);
  int two_contacts = 0;
  for (int k = 0; k < 200; ++k) {
    const std::vector<Vec2> d{k < 100 ? in : slanted};
    const MultiPushStep step = model.Step(object, finger, d);
    ExpectPhysical(model, step.response, object, step.pushing_motions, "step " + std::to_string(k));
    object = step.object_pose;
    finger = step.finger_poses;
    EXPECT_GE(step.separation_after, -1e-10) << "step " << k;
    if (step.response.contacts.size() == 2) ++two_contacts;
  }
  EXPECT_GT(two_contacts, 150);
  // The finger went 15 + 20 mm after touching; the block moved with it.
  EXPECT_GT(object.translation().norm(), 0.025);
}

TEST(MultiContact, BadInputIsAClearError) {
  MultiPushingSpec spec;
  spec.object = Object(Shape::Box(0.09, 0.06), 0.8, 0.25);
  EXPECT_THROW(MultiPushingModel{spec}, PushError);  // no finger
  spec.fingers = {{Shape::Disk(0.004), 0.4}, {Shape::Disk(0.004), -0.1}};
  try {
    MultiPushingModel bad(spec);
    FAIL() << "no error";
  } catch (const PushError& e) {
    EXPECT_NE(std::string(e.what()).find("fingers[1]"), std::string::npos) << e.what();
  }
  spec.fingers[1].mu_contact = 0.3;
  const MultiPushingModel model(spec);
  EXPECT_THROW(model.Respond({}, {{-0.05, 0.0, 0.0}}, {Vec2(1, 0)}), PushError);  // one pose for two fingers
  EXPECT_THROW(model.Respond({}, {{-0.05, 0.0, 0.0}, {0.05, 0.0, 0.0}}, {Vec2(1, 0), Vec2(NAN, 0)}), PushError);
  EXPECT_THROW(model.Step({}, {{-0.05, 0.0, 0.0}, {NAN, 0.0, 0.0}}, {Vec2(1, 0), Vec2(0, 0)}), PushError);
}

}  // namespace
}  // namespace pushgraph::push
