// The contact manifold (FindContacts): a disk wedged in the notched block's V touches both walls;
// a flat pusher face on a block face touches it at the two ends of the overlap; a disk on a
// convex corner is one vertex contact, and near it on a face one edge contact (not two); on
// random non-convex shapes with holes, touching fingers' manifolds contain the exact nearest pair
// (ShapePairQuerier) and no contact is nearer than it; bad input is refused.
#include <pushgraph/geometry/contacts.h>
#include <pushgraph/geometry/shape_pair.h>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/random_shapes.h"

namespace pushgraph::geometry {
namespace {

using testing::kPi;
using testing::Scaled;

Shape NotchedBlock() { return LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json"); }

TEST(Contacts, ADiskWedgedInTheNotchTouchesBothWalls) {
  // The V: walls from (+-0.015, 0.04) down to (0, 0.012); a disk of radius R on its axis
  // touches both walls where its centre is R / sin(half angle) above the apex.
  const Shape block = NotchedBlock();
  const double R = 0.005;
  const Shape disk = Shape::Disk(R);
  const Vec2 wall = Vec2(0.015, 0.028).normalized();
  const double half_angle = std::atan2(wall.x(), wall.y());
  const Vec2 centre(0.0, 0.012 + R / std::sin(half_angle));
  for (const double theta : {0.0, 0.7, -2.1}) {
    // The same configuration turned and shifted as a whole.
    const Pose2 object{0.3, -0.2, theta};
    const Vec2 c = Act(object, centre);
    const std::vector<ContactPoint> contacts = FindContacts(block, object, disk, {c.x(), c.y(), 0.4});
    ASSERT_EQ(contacts.size(), 2u) << "theta " << theta;
    for (const ContactPoint& k : contacts) {
      EXPECT_EQ(k.kind, ContactPoint::Kind::kFingerVertexObjectEdge);
      EXPECT_NEAR(k.separation, 0.0, 1e-15);
      EXPECT_NEAR((k.object_point - c).norm(), R, 1e-15);
      EXPECT_NEAR((k.finger_point - k.object_point).norm(), 0.0, 1e-15);
      EXPECT_NEAR(k.normal.norm(), 1.0, 1e-15);
      // The normal points from the wall to the disk's centre.
      EXPECT_NEAR((c - k.object_point).normalized().dot(k.normal), 1.0, 1e-14);
    }
    // Mirror images across the V's axis.
    const Vec2 a = InverseAct(object, contacts[0].object_point), b = InverseAct(object, contacts[1].object_point);
    EXPECT_NEAR(a.x(), -b.x(), 1e-15);
    EXPECT_NEAR(a.y(), b.y(), 1e-15);
    // Lifted off by more than the tolerance, no contact remains.
    const Vec2 lifted = Act(object, centre + Vec2(0.0, 1e-6));
    EXPECT_TRUE(FindContacts(block, object, disk, {lifted.x(), lifted.y(), 0.0}).empty());
  }
}

TEST(Contacts, AFlatPusherFaceOnABlockFaceTouchesAtTheEndsOfTheOverlap) {
  const Shape block = Shape::Box(0.09, 0.09);          // [-0.045, 0.045]^2
  const Shape pusher = Shape::Box(0.06, 0.01, 0.001);  // rounded: core [-0.03, 0.03] x [-0.005, 0.005]
  // The pusher's lower face rests on the block's top face, shifted right so that it overhangs
  // the block's corner: the overlap runs from the pusher's left core corner to the block's corner.
  const Pose2 object{0.0, 0.0, 0.0};
  const Pose2 finger{0.04, 0.045 + 0.005 + 0.001, 0.0};
  const std::vector<ContactPoint> contacts = FindContacts(block, object, pusher, finger);
  ASSERT_EQ(contacts.size(), 2u);
  int finger_vertex = 0, object_vertex = 0;
  for (const ContactPoint& k : contacts) {
    EXPECT_NEAR(k.separation, 0.0, 1e-15);
    EXPECT_NEAR(k.normal.y(), 1.0, 1e-15);
    EXPECT_NEAR(k.object_point.y(), 0.045, 1e-15);
    if (k.kind == ContactPoint::Kind::kFingerVertexObjectEdge) {
      ++finger_vertex;
      EXPECT_NEAR(k.object_point.x(), 0.04 - 0.03, 1e-15);
    } else {
      ASSERT_EQ(k.kind, ContactPoint::Kind::kObjectVertexFingerEdge);
      ++object_vertex;
      EXPECT_NEAR(k.object_point.x(), 0.045, 1e-15);
    }
  }
  EXPECT_EQ(finger_vertex, 1);
  EXPECT_EQ(object_vertex, 1);
  // Tilted by 1e-4 rad about its left end the face opens at the block's corner by ~3.5e-6 m: one contact.
  const Vec2 left_end(0.01, 0.045);
  Pose2 tilted = finger;
  tilted.theta = 1e-4;
  const Vec2 shift = left_end - Act(tilted, Vec2(-0.03, -0.006));
  tilted.x += shift.x();
  tilted.y += shift.y();
  const std::vector<ContactPoint> tilt = FindContacts(block, object, pusher, tilted);
  ASSERT_EQ(tilt.size(), 1u);
  EXPECT_NEAR(tilt[0].object_point.x(), 0.01, 2e-7);  // the core corner turned about the pivot below it
  // A larger tolerance sees the opening end again.
  EXPECT_EQ(FindContacts(block, object, pusher, tilted, {1e-5, 1e-4}).size(), 2u);
}

TEST(Contacts, ACornerIsOneContactAndAFaceNearItIsOne) {
  const Shape block = Shape::Box(0.09, 0.09);
  const Shape disk = Shape::Disk(0.005);
  const Pose2 object{0.0, 0.0, 0.0};
  const Vec2 corner(0.045, 0.045);
  const Vec2 diagonal = Vec2(1.0, 1.0).normalized();
  const Vec2 on_corner = corner + 0.005 * diagonal;
  std::vector<ContactPoint> c = FindContacts(block, object, disk, {on_corner.x(), on_corner.y(), 0.0});
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].kind, ContactPoint::Kind::kVertexVertex);
  EXPECT_NEAR((c[0].object_point - corner).norm(), 0.0, 1e-16);
  EXPECT_NEAR(c[0].normal.dot(diagonal), 1.0, 1e-15);
  // On the top face 1e-6 m from the corner: the corner's own gap is ~1e-10, inside the tolerance,
  // yet it is the same touch: one edge contact.
  c = FindContacts(block, object, disk, {0.045 - 1e-6, 0.045 + 0.005, 0.0});
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].kind, ContactPoint::Kind::kFingerVertexObjectEdge);
}

TEST(Contacts, TouchingFingersOnRandomShapesContainTheExactNearestPair) {
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < Scaled(300); ++trial) {
    testing::RandomPolygonOptions o;
    o.size = 0.05;
    o.max_holes = 2;
    const Shape object = Shape::FromPolygons({testing::RandomPolygonWithHoles(rng, Vec2::Zero(), o)});
    const int kind = trial % 3;
    const Shape finger = kind == 0   ? Shape::Disk(0.002 + 0.006 * unit(rng))
                         : kind == 1 ? Shape::RegularPolygon(3 + trial % 4, 0.004 + 0.01 * unit(rng))
                                     : Shape::Box(0.01, 0.004, 0.001);
    ShapePairQuerier::Options options;
    options.method = ShapePairQuerier::Method::kExact;
    const ShapePairQuerier querier(object, finger, options);
    const Pose2 object_pose{unit(rng) - 0.5, unit(rng) - 0.5, 2.0 * kPi * unit(rng)};
    const double angle = 2.0 * kPi * unit(rng);
    Pose2 finger_pose{object_pose.x + 0.1 * std::cos(angle), object_pose.y + 0.1 * std::sin(angle),
                      2.0 * kPi * unit(rng)};
    // Move the finger along the nearest pair's normal until it touches (exactly up to rounding).
    ShapePairResult q = querier.Query(object_pose, finger_pose);
    for (int k = 0; k < 3 && std::abs(q.signed_distance) > 1e-13; ++k) {
      finger_pose.x -= q.signed_distance * q.normal.x();
      finger_pose.y -= q.signed_distance * q.normal.y();
      q = querier.Query(object_pose, finger_pose);
    }
    if (std::abs(q.signed_distance) > 1e-12) continue;  // a wedge of features moved the nearest pair
    const std::vector<ContactPoint> contacts = FindContacts(object, object_pose, finger, finger_pose, {1e-9, 1e-9});
    ASSERT_FALSE(contacts.empty()) << "trial " << trial;
    double nearest = 1.0;
    bool has_pair = false;
    for (const ContactPoint& c : contacts) {
      nearest = std::min(nearest, c.separation);
      EXPECT_GE(c.separation, q.signed_distance - 1e-13) << "trial " << trial;
      EXPECT_LE(c.separation, 1e-9);
      EXPECT_NEAR(c.normal.norm(), 1.0, 1e-14);
      // The reported points are apart by the gap along the normal.
      EXPECT_NEAR((c.finger_point - c.object_point).dot(c.normal), c.separation, 1e-13) << "trial " << trial;
      if ((c.object_point - q.object_point).norm() < 1e-9) has_pair = true;
    }
    EXPECT_NEAR(nearest, q.signed_distance, 1e-13) << "trial " << trial;
    EXPECT_TRUE(has_pair) << "trial " << trial;
    ++checked;
  }
  EXPECT_GE(checked, Scaled(300) * 9 / 10);
}

TEST(Contacts, BadInputIsAClearError) {
  const Shape block = Shape::Box(0.09, 0.09), disk = Shape::Disk(0.005);
  EXPECT_THROW(FindContacts(Shape(), {}, disk, {}), GeometryError);
  EXPECT_THROW(FindContacts(block, {}, Shape(), {}), GeometryError);
  EXPECT_THROW(FindContacts(block, {NAN, 0.0, 0.0}, disk, {}), GeometryError);
  EXPECT_THROW(FindContacts(block, {}, disk, {0.0, INFINITY, 0.0}), GeometryError);
  EXPECT_THROW(FindContacts(block, {}, disk, {}, {-1.0, 0.0}), GeometryError);
  EXPECT_THROW(FindContacts(block, {}, disk, {}, {1e-7, NAN}), GeometryError);
}

}  // namespace
}  // namespace pushgraph::geometry
