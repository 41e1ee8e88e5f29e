// The quasi-static pushing model: sticking and sliding contact, loads on the limit surface,
// contact made and broken, exact surface and ellipsoid, convex and non-convex objects.
#include <pushgraph/push/pushing.h>

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace pushgraph::push {
using namespace limit_surface;
namespace {

using geometry::Pose2;
using geometry::Shape;

constexpr double kSide = 0.09;       // MIT rect1
constexpr double kMass = 0.8374;
constexpr double kFingerRadius = 0.00235;
constexpr double kMuSurface = 0.25;

PushingSpec SquareSpec(double mu_contact, SurfaceModel surface = SurfaceModel::kExact) {
  PushingSpec spec;
  spec.object.shape = Shape::Box(kSide, kSide);
  spec.finger.shape = Shape::Disk(kFingerRadius);
  spec.object.mass = kMass;
  spec.object.mu_surface = kMuSurface;
  spec.finger.mu_contact = mu_contact;
  spec.surface = surface;
  return spec;
}

// Finger touching the left face (x = -kSide/2) of an object at `object` at height y (object frame).
Pose2 FingerOnLeftFace(const Pose2& object, double y) {
  const Vec2 p = geometry::Act(object, Vec2(-0.5 * kSide - kFingerRadius, y));
  return {p.x(), p.y(), 0.0};
}

Vec2 ContactVelocity(const Twist& twist, const Vec2& r) {
  return {twist.vx - twist.omega * r.y(), twist.vy + twist.omega * r.x()};
}

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The load must be the limit surface's load at the resulting twist, and a pure force at the
// contact point; the world force is the rotated body force.
void ExpectLoadOnSurface(const PushingModel& model, const Pose2& object, const PushResponse& r) {
  ASSERT_NE(r.mode, ContactMode::kSeparated);
  const Load expected = model.spec().surface == SurfaceModel::kExact
                            ? SustainingLoad(model.support(), r.twist)
                            : EllipsoidLoad(model.ellipsoid(), r.twist);
  const double f_scale = model.summary().f_max, t_scale = model.summary().tau_max;
  EXPECT_LE((r.load.force - expected.force).norm(), 1e-9 * f_scale);
  EXPECT_LE(std::abs(r.load.torque - expected.torque), 1e-9 * t_scale);
  const Vec2 rel = geometry::InverseAct(object, r.contact_point) - model.support().centre_of_pressure;
  EXPECT_LE(std::abs(r.load.torque - Cross(rel, r.load.force)), 1e-9 * t_scale);
  EXPECT_LE(r.torque_residual, 1e-9);
  EXPECT_LE((r.force - object.rotation() * r.load.force).norm(), 1e-12 * f_scale);
  EXPECT_GT(r.force.dot(r.contact_normal), 0.0);  // the finger pushes, never pulls
}

TEST(Pushing, PushThroughCentreTranslatesAlongThePush) {
  for (SurfaceModel surface : {SurfaceModel::kExact, SurfaceModel::kEllipsoid}) {
    const PushingModel model(SquareSpec(0.3, surface));
    const Pose2 object{0.1, -0.2, 0.7};
    const Pose2 finger = FingerOnLeftFace(object, 0.0);
    const Vec2 push = 1e-4 * (object.rotation() * Vec2(1.0, 0.0));
    const PushResponse r = model.Respond(object, finger, push);
    ASSERT_EQ(r.mode, ContactMode::kSticking) << ToString(surface);
    EXPECT_TRUE(r.touching);
    EXPECT_NEAR(r.twist.vx, 1e-4, 1e-15);
    EXPECT_NEAR(r.twist.vy, 0.0, 1e-15);
    EXPECT_NEAR(r.twist.omega, 0.0, 1e-13);
    // Pure translation: the applied force is mu m g along the push.
    const double f_max = kMuSurface * kMass * kStandardGravity;
    EXPECT_NEAR(r.force.norm(), f_max, 1e-9 * f_max);
    EXPECT_NEAR(r.force.normalized().dot(push.normalized()), 1.0, 1e-12);
    EXPECT_LE((r.contact_normal - push.normalized()).norm(), 1e-12);
    ExpectLoadOnSurface(model, object, r);
    // The object moves by the finger's displacement.
    const Pose2 moved = model.ApplyTwist(object, r.twist);
    EXPECT_NEAR(moved.x - object.x, push.x(), 1e-15);
    EXPECT_NEAR(moved.y - object.y, push.y(), 1e-15);
    EXPECT_NEAR(moved.theta, object.theta, 1e-12);
  }
}

TEST(Pushing, OffsetPushRotatesAwayFromTheContact) {
  const PushingModel model(SquareSpec(0.5));
  const Pose2 object{0.0, 0.0, 0.0};
  // Above the centre, pushing +x: clockwise (omega < 0); below: counter-clockwise.
  for (double y : {0.02, -0.02, 0.04, -0.035}) {
    const PushResponse r = model.Respond(object, FingerOnLeftFace(object, y), {1e-4, 0.0});
    ASSERT_NE(r.mode, ContactMode::kSeparated);
    EXPECT_LT(r.twist.omega * y, 0.0) << "y = " << y;
    EXPECT_GT(r.twist.vx, 0.0);
    if (std::abs(y) <= 0.02) {
      // Moderate offsets stick: the contact point moves with the finger.
      EXPECT_EQ(r.mode, ContactMode::kSticking) << "y = " << y;
      const Vec2 rel = geometry::InverseAct(object, r.contact_point) - model.support().centre_of_pressure;
      EXPECT_LE((ContactVelocity(r.twist, rel) - Vec2(1e-4, 0.0)).norm(), 1e-12);
    } else {
      // Near a corner the sticking force would leave the cone (|f_t| > 0.5 f_n): sliding.
      EXPECT_EQ(r.mode, ContactMode::kSliding) << "y = " << y;
      EXPECT_NE(r.slip_direction, 0) << "y = " << y;
    }
    ExpectLoadOnSurface(model, object, r);
  }
  // A larger offset turns the object faster.
  const double w1 = model.Respond(object, FingerOnLeftFace(object, 0.01), {1e-4, 0.0}).twist.omega;
  const double w2 = model.Respond(object, FingerOnLeftFace(object, 0.03), {1e-4, 0.0}).twist.omega;
  EXPECT_LT(w2, w1);
  EXPECT_LT(w1, 0.0);
}

TEST(Pushing, HighFrictionSticksZeroFrictionSlidesAlongTheNormal) {
  const Pose2 object{0.0, 0.0, 0.0};
  const Pose2 finger = FingerOnLeftFace(object, 0.01);
  const double angle = 50.0 * M_PI / 180.0;  // oblique push, 50 degrees from the normal
  const Vec2 push = 1e-4 * Vec2(std::cos(angle), std::sin(angle));
  for (SurfaceModel surface : {SurfaceModel::kExact, SurfaceModel::kEllipsoid}) {
    const PushingModel sticky(SquareSpec(3.0, surface));
    const PushResponse s = sticky.Respond(object, finger, push);
    ASSERT_EQ(s.mode, ContactMode::kSticking) << ToString(surface);
    const Vec2 rel = geometry::InverseAct(object, s.contact_point) - sticky.support().centre_of_pressure;
    EXPECT_LE((ContactVelocity(s.twist, rel) - push).norm(), 1e-12);
    ExpectLoadOnSurface(sticky, object, s);

    const PushingModel slippery(SquareSpec(0.0, surface));
    const PushResponse f = slippery.Respond(object, finger, push);
    ASSERT_EQ(f.mode, ContactMode::kSliding) << ToString(surface);
    EXPECT_LE(std::abs(Cross(f.force, f.contact_normal)), 1e-12 * f.force.norm());
    EXPECT_GT(f.force.dot(f.contact_normal), 0.0);
    // The contact point keeps up with the finger along the normal, the finger slips along +y.
    const Vec2 rel0 = geometry::InverseAct(object, f.contact_point) - slippery.support().centre_of_pressure;
    const Vec2 vp = ContactVelocity(f.twist, rel0);
    EXPECT_NEAR(vp.x(), push.x(), 1e-15);
    EXPECT_GT(push.y() - vp.y(), 0.0);
    EXPECT_EQ(f.slip_direction, 1);  // +t = z x n = +y for n = +x
    ExpectLoadOnSurface(slippery, object, f);
  }
}

TEST(Pushing, SlidingForceLiesOnTheFrictionConeEdgeOfTheSlip) {
  const Pose2 object{0.3, 0.1, -0.4};
  const double mu = 0.2;
  const PushingModel model(SquareSpec(mu));
  for (double angle_deg : {-70.0, -45.0, 45.0, 70.0}) {
    for (double y : {-0.03, 0.0, 0.025}) {
      const double a = angle_deg * M_PI / 180.0;
      const Vec2 push = object.rotation() * (1e-4 * Vec2(std::cos(a), std::sin(a)));
      const PushResponse r = model.Respond(object, FingerOnLeftFace(object, y), push);
      ASSERT_NE(r.mode, ContactMode::kSeparated);
      const Vec2 n = r.contact_normal, t(-n.y(), n.x());
      const double fn = r.force.dot(n), ft = r.force.dot(t);
      EXPECT_GT(fn, 0.0);
      if (r.mode == ContactMode::kSliding) {
        EXPECT_NEAR(std::abs(ft), mu * fn, 1e-9 * fn) << angle_deg << " " << y;
        // Friction on the object points along the finger's slip relative to the object.
        EXPECT_EQ(ft > 0.0 ? 1 : -1, r.slip_direction) << angle_deg << " " << y;
      } else {
        EXPECT_LE(std::abs(ft), mu * fn * (1 + 1e-9));
      }
      ExpectLoadOnSurface(model, object, r);
    }
  }
  // A 70 degree push with mu_c = 0.2 (cone half-angle 11 degrees) cannot stick.
  const PushResponse r = model.Respond(object, FingerOnLeftFace(object, 0.0),
                                       object.rotation() * Vec2(std::cos(1.2), std::sin(1.2)) * 1e-4);
  EXPECT_EQ(r.mode, ContactMode::kSliding);
}

TEST(Pushing, StickingAndSlidingMeetAtTheConeBoundary) {
  // Sweep the push direction: sticking for small angles, sliding beyond; the twist is
  // continuous across the switch (the motion-cone edge).
  const Pose2 object{0.0, 0.0, 0.0};
  const PushingModel model(SquareSpec(0.4));
  const Pose2 finger = FingerOnLeftFace(object, 0.015);
  ContactMode previous = ContactMode::kSticking;
  Twist previous_twist{};
  int switches = 0;
  for (int k = 0; k <= 400; ++k) {
    const double a = -1.2 + 2.4 * k / 400.0;
    const PushResponse r = model.Respond(object, finger, 1e-4 * Vec2(std::cos(a), std::sin(a)));
    ASSERT_NE(r.mode, ContactMode::kSeparated);
    if (k > 0) {
      const double jump = std::hypot(r.twist.vx - previous_twist.vx, r.twist.vy - previous_twist.vy) +
                          model.summary().c * std::abs(r.twist.omega - previous_twist.omega);
      EXPECT_LT(jump, 1e-4 * 0.05) << "a = " << a;  // continuous, no flip at the switch
      if (r.mode != previous) ++switches;
    }
    previous = r.mode;
    previous_twist = r.twist;
  }
  EXPECT_EQ(switches, 2);  // sliding -> sticking -> sliding
}

TEST(Pushing, NoMotionWhenApartOrRetreating) {
  const PushingModel model(SquareSpec(0.3));
  const Pose2 object{0.0, 0.0, 0.0};
  Pose2 apart = FingerOnLeftFace(object, 0.0);
  apart.x -= 1e-3;
  PushResponse r = model.Respond(object, apart, {1e-4, 0.0});
  EXPECT_EQ(r.mode, ContactMode::kSeparated);
  EXPECT_FALSE(r.touching);
  EXPECT_NEAR(r.separation, 1e-3, 1e-12);
  EXPECT_EQ(r.force, Vec2(0.0, 0.0));
  EXPECT_EQ(r.twist.omega, 0.0);
  // Touching, moving away or along the face: the object stays put.
  for (const Vec2& motion : {Vec2(-1e-4, 0.0), Vec2(0.0, 1e-4), Vec2(0.0, 0.0)}) {
    r = model.Respond(object, FingerOnLeftFace(object, 0.01), motion);
    EXPECT_TRUE(r.touching);
    EXPECT_EQ(r.mode, ContactMode::kSeparated);
    EXPECT_EQ(r.force, Vec2(0.0, 0.0));
  }
  // Step with a retreating finger: the object does not move and contact is broken.
  const PushStep step = model.Step(object, FingerOnLeftFace(object, 0.01), {-2e-4, 0.0});
  EXPECT_EQ(step.object_pose.x, object.x);
  EXPECT_EQ(step.object_pose.theta, object.theta);
  EXPECT_NEAR(step.separation_after, 2e-4, 1e-12);
}

TEST(Pushing, StepMakesContactMidStepAndDoesNotPenetrate) {
  const PushingModel model(SquareSpec(0.6));
  const Pose2 object{0.0, 0.0, 0.0};
  Pose2 finger = FingerOnLeftFace(object, 0.02);
  finger.x -= 1e-4;
  const PushStep step = model.Step(object, finger, {3e-4, 0.0});
  EXPECT_TRUE(step.made_contact);
  EXPECT_NE(step.response.mode, ContactMode::kSeparated);
  EXPECT_NEAR(step.finger_pose.x, finger.x + 3e-4, 1e-15);
  // Sticking: the touched material point moved with the finger by the 2e-4 m left after contact;
  // the object rotated clockwise.
  EXPECT_EQ(step.response.mode, ContactMode::kSticking);
  const Vec2 material = geometry::Act(step.object_pose, Vec2(-0.045, 0.02));
  // (up to the step's second-order arc-versus-tangent term, d^2 / (2 R) ~ 1e-7 m here)
  EXPECT_NEAR(material.x(), -0.045 + 2e-4, 1e-6);
  EXPECT_NEAR(material.y(), 0.02, 1e-6);
  EXPECT_LT(step.object_pose.theta, 0.0);
  EXPECT_GE(step.separation_after, -model.spec().penetration_tolerance);
  EXPECT_LE(step.separation_after, model.spec().contact_tolerance);
}

TEST(Pushing, LargeStepPenetrationIsPushedOut) {
  // A deliberately coarse 2 mm step on a corner-near contact: the first-order twist leaves the
  // finger inside the rotated object; the correction must remove it.
  const PushingModel model(SquareSpec(0.3));
  Pose2 object{0.0, 0.0, 0.0};
  Pose2 finger = FingerOnLeftFace(object, 0.042);
  for (int k = 0; k < 10; ++k) {
    const PushStep step = model.Step(object, finger, {2e-3, 0.0});
    object = step.object_pose;
    finger = step.finger_pose;
    EXPECT_GE(step.separation_after, -model.spec().penetration_tolerance) << "step " << k;
  }
  EXPECT_LT(object.theta, -0.05);
}

TEST(Pushing, NotchedBlockWithHolesAndAnyFinger) {
  PushingSpec spec;
  spec.object.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  spec.object.mass = 0.5;
  spec.object.mu_surface = 0.3;
  spec.finger.mu_contact = 0.4;
  for (const char* finger_file : {"disk_finger_5mm.json", "rounded_square_finger.json"}) {
    spec.finger.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/" + finger_file);
    const PushingModel model(spec);
    // Centre of pressure = centroid, off the origin because of the holes.
    EXPECT_GT(model.support().centre_of_pressure.norm(), 1e-4);
    Pose2 object{0.0, 0.0, 0.2};
    // Find a touching finger pose below the bottom face (y = -0.04), pushing +y in the object frame.
    const Vec2 up = object.rotation() * Vec2(0.0, 1.0);
    Vec2 p = geometry::Act(object, Vec2(0.03, -0.08));
    const Pose2 probe{p.x(), p.y(), 0.0};
    const double sd = model.querier().Query(object, probe).signed_distance;
    p += sd * up;
    Pose2 finger{p.x(), p.y(), 0.0};
    EXPECT_NEAR(model.querier().Query(object, finger).signed_distance, 0.0, 1e-12) << finger_file;
    const PushResponse r = model.Respond(object, finger, 1e-4 * up);
    ASSERT_NE(r.mode, ContactMode::kSeparated) << finger_file;
    ExpectLoadOnSurface(model, object, r);
    // Contact right of the centroid pushing up: counter-clockwise.
    EXPECT_GT(r.twist.omega, 0.0) << finger_file;
    for (int k = 0; k < 200; ++k) {
      const PushStep step = model.Step(object, finger, 1e-4 * up);
      object = step.object_pose;
      finger = step.finger_pose;
      ASSERT_NE(step.response.mode, ContactMode::kSeparated) << finger_file << " step " << k;
      EXPECT_GE(step.separation_after, -1e-9) << finger_file << " step " << k;
      EXPECT_LE(step.separation_after, spec.contact_tolerance) << finger_file << " step " << k;
    }
    EXPECT_GT(object.theta, 0.2);
  }
}

TEST(Pushing, EllipsoidLoadsLieOnTheEllipsoid) {
  const PushingModel model(SquareSpec(0.3, SurfaceModel::kEllipsoid));
  const Pose2 object{0.0, 0.0, 0.0};
  for (double y : {-0.04, -0.01, 0.02}) {
    for (double a : {-0.8, 0.0, 0.3}) {
      const PushResponse r = model.Respond(object, FingerOnLeftFace(object, y), 1e-4 * Vec2(std::cos(a), std::sin(a)));
      const Eigen::Vector3d F(r.load.force.x(), r.load.force.y(), r.load.torque);
      EXPECT_NEAR(F.dot(model.ellipsoid().A * F), 1.0, 1e-12);
      ExpectLoadOnSurface(model, object, r);
    }
  }
}

TEST(Pushing, EllipsoidStickingMatchesLynchClosedForm) {
  // Lynch, Maekawa, Tanie (1992): for the ellipsoidal limit surface (semi-axes f_max, f_max,
  // tau_max, c = tau_max / f_max) and a sticking contact at (x, y) about the centre of
  // pressure moving with velocity (a, b), the object's twist is
  //   v_x = ((c^2 + x^2) a + x y b) / (c^2 + x^2 + y^2),  v_y = (x y a + (c^2 + y^2) b) / (...),
  //   omega = (x v_y - y v_x) / c^2.
  const PushingModel model(SquareSpec(5.0, SurfaceModel::kEllipsoid));
  const double c = model.summary().c;
  const Pose2 object{0.0, 0.0, 0.0};
  for (double y : {-0.03, 0.0, 0.012, 0.04}) {
    for (double angle : {-0.6, 0.0, 0.4}) {
      const Vec2 push = 1e-4 * Vec2(std::cos(angle), std::sin(angle));
      const PushResponse r = model.Respond(object, FingerOnLeftFace(object, y), push);
      ASSERT_EQ(r.mode, ContactMode::kSticking) << y << " " << angle;
      const Vec2 p = geometry::InverseAct(object, r.contact_point);
      const double x0 = p.x(), y0 = p.y(), a = push.x(), b = push.y();
      const double den = c * c + x0 * x0 + y0 * y0;
      const double vx = ((c * c + x0 * x0) * a + x0 * y0 * b) / den;
      const double vy = (x0 * y0 * a + (c * c + y0 * y0) * b) / den;
      const double omega = (x0 * vy - y0 * vx) / (c * c);
      EXPECT_NEAR(r.twist.vx, vx, 1e-13) << y << " " << angle;
      EXPECT_NEAR(r.twist.vy, vy, 1e-13) << y << " " << angle;
      EXPECT_NEAR(r.twist.omega, omega, 1e-11) << y << " " << angle;
    }
  }
}

TEST(Pushing, BadInputNamesTheField) {
  auto message = [](PushingSpec spec) {
    try {
      PushingModel model(std::move(spec));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  PushingSpec s = SquareSpec(0.3);
  s.object.mass = -1.0;
  EXPECT_NE(message(s).find("mass"), std::string::npos) << message(s);
  s = SquareSpec(-0.1);
  EXPECT_NE(message(s).find("mu_contact"), std::string::npos) << message(s);
  s = SquareSpec(0.3);
  s.object.mu_surface = std::nan("");
  EXPECT_NE(message(s).find("mu_surface"), std::string::npos) << message(s);
  s = SquareSpec(0.3);
  s.object.shape = Shape();
  EXPECT_NE(message(s).find("object"), std::string::npos) << message(s);
  const PushingModel model(SquareSpec(0.3));
  EXPECT_THROW(model.Respond({0, 0, 0}, {-0.1, 0, 0}, {std::nan(""), 0.0}), PushError);
}

}  // namespace
}  // namespace pushgraph::push
