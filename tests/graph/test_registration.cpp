// Shape registration (registration.h) on real MIT recordings whose meshes are turned, shifted
// and rescaled by known transforms, as a user's CAD file would be: the transform must come back.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/graph/errors.h>
#include <pushgraph/graph/registration.h>
#include <pushgraph/io/footprint.h>
#include <pushgraph/io/mit_push.h>
#include <pushgraph/push/simulator.h>

#include "test_scale.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <vector>

namespace pushgraph::graph {
namespace {

using geometry::Pose2;
using geometry::Shape;
using geometry::Vec2;

const std::string kMit = std::string(PUSHGRAPH_SHARED_DIR) + "/data/mit-push/";

std::vector<std::string> Recordings(const std::string& object) {
  std::vector<std::string> files;
  const std::string dir = kMit + "abs/" + object;
  if (!std::filesystem::exists(dir)) return files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

push::Trajectory Recording(const std::string& file, const Shape& shape, double noise, unsigned seed) {
  io::MitReadOptions options;
  options.trim_to_contact = true;
  const io::MitRecording rec = io::ReadMitPush(file, options);
  push::ObjectDescription object;
  object.shape = shape;
  object.mass = 1.0;
  object.mu_surface = 0.35;
  push::FingerDescription finger;
  finger.shape = Shape::Disk(0.0047);  // tip.obj: a 4.7 mm radius cylinder
  push::Trajectory t = io::MitToTrajectory(rec, object, finger);
  if (noise > 0.0) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    for (auto& s : t.measured.object_pose) s.pose = {s.pose.x + noise * n(rng), s.pose.y + noise * n(rng), s.pose.theta + 10 * noise * n(rng)};
    for (auto& s : t.measured.finger_pose) s.pose = {s.pose.x + noise * n(rng), s.pose.y + noise * n(rng), s.pose.theta};
    push::MeasurementSigmas sigmas;
    sigmas.object_trans = sigmas.finger_trans = noise;
    sigmas.object_rot = 10 * noise;
    t.measurement_sigmas = sigmas;
  }
  return t;
}

// Largest distance between the outlines of two shapes (vertices of each against the other).
double OutlineDistance(const Shape& a, const Shape& b) {
  double worst = 0.0;
  for (const auto* pair : {&a, &b}) {
    const Shape& from = *pair;
    const Shape& to = pair == &a ? b : a;
    for (const auto& p : from.polygons()) {
      for (const Vec2& v : p.outer) worst = std::max(worst, std::abs(geometry::QueryPoint(to, v).signed_distance));
    }
  }
  return worst;
}

struct Misframe {
  const char* name;
  Pose2 pose;  // the file's frame is the true frame moved by this (and scaled by 1/scale)
  double scale;
};

const Misframe kMisframes[] = {
    {"as shipped", {0, 0, 0}, 1.0},
    {"quarter turn", {0, 0, M_PI / 2}, 1.0},
    {"30 deg", {0, 0, M_PI / 6}, 1.0},
    {"-2 cm, +1.5 cm", {-0.02, 0.015, 0}, 1.0},
    {"quarter turn and 3 cm", {0.03, 0.0, -M_PI / 2}, 1.0},  // rect1: along the pushed side
    {"quarter turn, 3 cm, 1 cm", {0.03, 0.01, -M_PI / 2}, 1.0},
    {"millimetres", {0, 0, 0}, 0.001},
    {"mm, 30 deg, 2 cm", {0.02, -0.01, M_PI / 6}, 0.001},
};

// The file's shape: the true shape moved by the misframe, in the misframe's units.
Shape FileShape(const Shape& truth, const Misframe& m) {
  return geometry::TransformShape(geometry::TransformShape(truth, m.pose, 1.0), Pose2{}, 1.0 / m.scale);
}


// Calls fn(object, truth, files, misframe, file shape, noise) for every shared object with
// recordings, every misframe and both noise levels.
template <class Fn>
void ForEachCase(Fn fn) {
  for (const std::string object : {"rect1", "ellip1"}) {
    const auto files = Recordings(object);
    if (files.empty()) GTEST_SKIP() << "no MIT data at " << kMit;
    const Shape truth = io::MeshFootprint(kMit + "obj/" + object + ".obj");
    // Scaled down (the sanitizer stage): every other misframe (the shipped frame always), with noise only.
    const bool reduced = pushgraph::testing::TestScale() < 1.0;
    int index = 0;
    for (const Misframe& m : kMisframes) {
      if (reduced && index++ % 2 == 1) continue;
      const Shape file = FileShape(truth, m);
      for (double noise : {0.0, 0.005}) {
        if (!reduced || noise > 0.0) fn(object, truth, files, m, file, noise);
      }
    }
  }
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

bool Undetectable(const std::string& object, const Misframe& m) {
  // A turned disk is the same disk; a square turned by a quarter is the same square; a shift
  // along the one side of rect1 the sample's pushes touch changes no contact.
  const bool pure_turn = m.pose.x == 0 && m.pose.y == 0 && m.scale == 1.0;
  if (object == "ellip1" && pure_turn) return true;
  if (object == "rect1" && pure_turn && std::abs(std::remainder(m.pose.theta, M_PI / 2)) < 1e-9) return true;
  return false;
}

// Every recording on its own: the verdict (fits as given or not) and how close the transform
// comes. One push touches one side over a few centimetres, so a turn or a shift along it is
// left to the centroid prior; the estimator's graph refines it further (test_alignment).
TEST(Registration, JudgesTheSharedMeshesOnEveryRealRecording) {
  ForEachCase([](const std::string& object, const Shape& truth, const std::vector<std::string>& files, const Misframe& m,
                 const Shape& file, double noise) {
        std::vector<double> errors;
        int fitting = 0;
        for (std::size_t k = 0; k < files.size(); ++k) {
          const push::Trajectory t = Recording(files[k], file, noise, 7 + k);
          const RegistrationResult r = RegisterShape(t);
          errors.push_back(OutlineDistance(r.Apply(file), truth));
          // Fits: the gaps are in tolerance and no other placement is clearly better (a
          // suspicion the estimator warns about).
          fitting += r.fits_as_given && !r.better_elsewhere ? 1 : 0;
        }
        const bool as_shipped = m.pose.x == 0 && m.pose.y == 0 && m.pose.theta == 0 && m.scale == 1.0;
        std::printf("[registration] %-6s %-22s noise %.3f: %2d of %zu recordings fit as given; outline error median %.2f mm, "
                    "worst %.2f mm\n",
                    object.c_str(), m.name, noise, fitting, files.size(), Median(errors) * 1e3,
                    *std::max_element(errors.begin(), errors.end()) * 1e3);
        if (as_shipped || Undetectable(object, m)) {
          // Noise-free motion capture makes every gap count: one ellip1 recording whose probe
          // sits 2 mm off the block is judged on the likelihood ratio alone, which the estimator
          // then settles with its graph (the shape as given competes: Estimate()).
          EXPECT_GE(fitting, static_cast<int>(files.size()) - (noise == 0.0 ? 1 : 0)) << object << " " << m.name << " noise " << noise;
        } else if (!(object == "rect1" && std::string(m.name) == "quarter turn and 3 cm")) {
          EXPECT_EQ(fitting, 0) << object << " " << m.name << " noise " << noise;
        }
  });
}

}  // namespace
}  // namespace pushgraph::graph

namespace pushgraph::graph {
namespace {

TEST(Registration, PooledOverAnObjectsRecordings) {
  ForEachCase([](const std::string& object, const Shape& truth, const std::vector<std::string>& files, const Misframe& m,
                 const Shape& file, double noise) {
        std::vector<push::Trajectory> trajs;
        for (std::size_t k = 0; k < files.size(); ++k) trajs.push_back(Recording(files[k], file, noise, 7 + k));
        std::vector<const push::Trajectory*> ptrs;
        for (const auto& t : trajs) ptrs.push_back(&t);
        const RegistrationResult r = RegisterShape(ptrs);
        const double d = OutlineDistance(r.Apply(file), truth);
        std::printf("[pooled] %-6s %-22s noise %.3f: %s; sigma (%.2f mm, %.2f mm, %.2f deg); outline error %.2f mm%s\n",
                    object.c_str(), m.name, noise, r.Describe().c_str(), r.sigma.x() * 1e3, r.sigma.y() * 1e3,
                    r.sigma.z() * 180 / M_PI, d * 1e3, r.fits_as_given ? " (fits as given)" : "");
        for (const auto& n : r.notes) std::printf("    %s\n", n.c_str());
        EXPECT_LT(d, 2.5e-3) << object << " " << m.name;
  });
}

}  // namespace
}  // namespace pushgraph::graph

namespace pushgraph::graph {
namespace {

// The dataset's meshes as shipped against pushes of the objects as the tracker saw them (the
// dataset's shape table): rect3's mesh has its long side along y; a hexagon file turned by 30
// degrees; a mirrored file (an L pushed from eight directions: four straight pushes leave a
// shifted unmirrored L fitting as well). (tri2's mesh is the mirror image of the shape table's triangle, but
// the two share the right-angle corner and their hypotenuses cross: pushes near the corner or
// the hypotenuse's middle cannot tell them apart, and four straight pushes could not.) Four simulated pushes
// from different sides with motion-capture noise, registered together as `pushgraph evaluate`
// does with a group's clean recordings.
TEST(Registration, DatasetMeshesAsShippedAreRegisteredOnSimulatedPushes) {
  struct Case {
    std::string name;
    Shape truth;  // in the tracker's frame
    Shape file;   // as shipped
  };
  std::vector<Case> cases;
  if (std::filesystem::exists(kMit + "obj/rect3.obj")) {
    cases.push_back({"rect3", Shape::Box(0.13501, 0.08994), io::MeshFootprint(kMit + "obj/rect3.obj")});
  }
  // A mirrored file (a footprint seen from below): the project's L-shaped bracket, centred.
  {
    const Shape l = io::MeshFootprint(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/meshes/l_bracket.obj");
    const Vec2 c = geometry::CoreCentroid(l);
    const Shape truth = geometry::TransformShape(l, Pose2{-c.x(), -c.y(), 0.0});
    cases.push_back({"l_bracket mirrored", truth, geometry::TransformShape(truth, Pose2{}, 1.0, /*mirror=*/true)});
  }
  cases.push_back({"hex (synthetic file)", Shape::RegularPolygon(6, 0.0605),
                   geometry::TransformShape(Shape::RegularPolygon(6, 0.0605), Pose2{0, 0, M_PI / 6})});
  for (const Case& c : cases) {
    std::vector<push::Trajectory> pushes;
    const int count = c.name == "l_bracket mirrored" ? 8 : 4;
    for (int k = 0; k < count; ++k) {
      push::PushPlan plan;
      plan.object.shape = c.truth;
      plan.finger.shape = Shape::Disk(0.0047);
      plan.object.mass = 1.0;
      plan.object.mu_surface = 0.35;
      plan.finger.mu_contact = 0.25;
      plan.waypoints = push::StraightPushPath(plan, 0.3 + k * 2 * M_PI / count, 0.01 * ((k % 4) - 1.5), 0.005, 0.05);
      plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
      // Motion-capture noise: `pushgraph evaluate` registers each object on its clean recordings.
      for (push::StreamNoise* s : {&plan.noise.object_pose, &plan.noise.finger_pose, &plan.noise.contact_point}) {
        s->position.sigma = 0.0005;
      }
      plan.noise.object_pose.angle.sigma = 0.005;
      plan.seed = 11 + k;
      push::Trajectory t = push::Simulate(plan).trajectory;
      t.object.shape = c.file;
      pushes.push_back(std::move(t));
    }
    std::vector<const push::Trajectory*> ptrs;
    for (const auto& t : pushes) ptrs.push_back(&t);
    const RegistrationResult r = RegisterShape(ptrs);
    const double error = OutlineDistance(r.Apply(c.file), c.truth);
    std::printf("[dataset] %-20s %s; outline error %.2f mm%s\n", c.name.c_str(), r.Describe().c_str(), error * 1e3,
                r.fits_as_given ? " (fits as given)" : "");
    for (const auto& n : r.notes) std::printf("    %s\n", n.c_str());
    EXPECT_FALSE(r.fits_as_given) << c.name;
    EXPECT_LT(error, 3e-3) << c.name;
    EXPECT_EQ(r.transform.mirrored, c.name == "l_bracket mirrored") << c.name;
  }
}

// The units are judged by the shape's size against the finger's path about the tracked origin.
// An origin on the outline (a U-shaped block whose origin is the middle of its outer edge, pushed
// 10 mm beside it) put the contacts 10 mm from it against the shape's 60 mm radius: no unit was
// within 4 times, and the true shape, in metres or in millimetres, was refused as "no unit makes
// it fit" (2 of 5 simulated pushes in metres by `pushgraph simulate`, the millimetre file every time). Now a
// unit 4 to 30 times the path is plausible too where the shape in it, as given, lies on the contacts.
// A 5 cm straight push of `shape` by a 5 mm disk, with the paper's Gaussian noise.
push::Trajectory SimulatedPush(const Shape& shape, double mass, double push_angle, double offset, unsigned seed) {
  push::PushPlan plan;
  plan.object.shape = shape;
  plan.object.mass = mass;
  plan.object.mu_surface = 0.3;
  plan.finger.shape = Shape::Disk(0.005);
  plan.finger.mu_contact = 0.4;
  plan.waypoints = push::StraightPushPath(plan, push_angle, offset, 0.005, 0.05);
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  plan.seed = seed;
  return push::Simulate(plan).trajectory;
}

// A mesh exported with y up is a prism along y, and read along z it is its side view: rect1's
// 90 x 12.7 mm, ellip1's 105 x 12.7 mm (io::MeshFootprint along y of the shipped mesh is exactly
// what a y-up export gives along z). The contacts choose the cross-section on every recording,
// keep a reading 0 that fits, and, with the file turned as well, choose by the registered costs.
TEST(Registration, TheContactsChooseWhichReadingOfAMeshWasMeant) {
  int recordings = 0, turned_chosen = 0, turned_side = 0;
  for (const std::string object : {"rect1", "ellip1"}) {
    const auto files = Recordings(object);
    if (files.empty()) GTEST_SKIP() << "no MIT data at " << kMit;
    const Shape top = io::MeshFootprint(kMit + "obj/" + object + ".obj");
    io::FootprintOptions along_y;
    along_y.up = io::UpAxis::kY;
    const Shape side = io::MeshFootprint(kMit + "obj/" + object + ".obj", along_y);
    const Shape turned = geometry::TransformShape(top, Pose2{0.0, 0.0, M_PI / 6}, 1.0);
    for (std::size_t i = 0; i < files.size(); i += pushgraph::testing::TestScale() < 1.0 ? 3 : 1) {
      const push::Trajectory t = Recording(files[i], top, 0.005, 7u + static_cast<unsigned>(i));
      ++recordings;
      const ShapeReadingChoice y_up = ChooseShapeReading(t, {side, top});
      EXPECT_EQ(y_up.index, 1) << files[i] << ": " << y_up.reason;
      EXPECT_FALSE(y_up.by_registration) << files[i];
      ASSERT_EQ(y_up.checks.size(), 2u);
      EXPECT_TRUE(y_up.checked[0] && !y_up.checks[0].fits) << files[i];
      EXPECT_NE(y_up.reason.find("reading 1 fits"), std::string::npos) << y_up.reason;
      const ShapeReadingChoice z_up = ChooseShapeReading(t, {top, side});
      EXPECT_EQ(z_up.index, 0) << files[i] << ": " << z_up.reason;
      EXPECT_TRUE(z_up.reason.empty()) << z_up.reason;
      // Turned by 30 degrees too: neither fits as given (ellip1's outline is nearly a circle, so
      // its turn fits); the registered costs decide or keep reading 0 with the reason.
      const ShapeReadingChoice both = ChooseShapeReading(t, {side, turned});
      std::printf("[readings] %s: y-up %d, turned y-up %d (%s)\n", files[i].substr(files[i].rfind('/') + 1).c_str(),
                  y_up.index, both.index, both.reason.c_str());
      EXPECT_FALSE(both.reason.empty());
      if (both.index == 1) ++turned_chosen;
      else if (both.by_registration || both.index != 0) ++turned_side;
      EXPECT_TRUE(both.index == 1 || !both.by_registration) << "a side view is never chosen over reading 0: " << both.reason;
    }
  }
  std::printf("[readings] %d recordings; the turned cross-section chosen on %d\n", recordings, turned_chosen);
  EXPECT_EQ(turned_side, 0);
  EXPECT_GE(turned_chosen, recordings / 2);
}

// A can lying on its side, a prism along y in a z-up file: pushed on its end, the contacts fit its
// footprint along z (a 100 x 60 mm rectangle), not its round cross-section, which is kept.
TEST(Registration, ACanLyingOnItsSideKeepsItsFootprintAlongZ) {
  const Shape lying = Shape::Box(0.1, 0.06);
  const Shape round = Shape::Disk(0.03);
  for (unsigned seed : {1u, 2u}) {
    const push::Trajectory t = SimulatedPush(lying, 0.4, 0.0, 0.005, seed);
    const ShapeReadingChoice kept = ChooseShapeReading(t, {lying, round});
    EXPECT_EQ(kept.index, 0) << kept.reason;
    EXPECT_TRUE(kept.reason.empty()) << kept.reason;
    const ShapeReadingChoice chosen = ChooseShapeReading(t, {round, lying});
    EXPECT_EQ(chosen.index, 1) << chosen.reason;
  }
  EXPECT_THROW(ChooseShapeReading(push::Trajectory{}, {}), GraphError);
}

TEST(Registration, AnOriginOnTheOutlineIsNoSizeMismatch) {
  const Shape u = Shape::FromPolygons({{{{0.003, 0.0}, {0.05, 0.0}, {0.05, 0.06}, {0.03, 0.06}, {0.03, 0.02},
                                         {-0.03, 0.02}, {-0.03, 0.06}, {-0.05, 0.06}, {-0.05, 0.0}, {-0.003, 0.0},
                                         {-0.003, 0.006}, {0.003, 0.006}},
                                        {}}});
  for (unsigned seed : {1u, 2u, 3u}) {
    push::Trajectory t = SimulatedPush(u, 0.5, M_PI / 2, 0.01, seed);
    const RegistrationResult as_given = RegisterShape(t);
    std::printf("[origin on the outline] seed %u, metres: %s%s; ratio %.3g\n", seed, as_given.Describe().c_str(),
                as_given.fits_as_given ? " (fits as given)" : "", as_given.size_ratio);
    EXPECT_FALSE(as_given.size_mismatch) << seed;
    EXPECT_TRUE(as_given.fits_as_given) << seed;
    EXPECT_EQ(as_given.transform.scale, 1.0) << seed;
    t.object.shape = geometry::TransformShape(u, Pose2{}, 1000.0);
    const RegistrationResult mm = RegisterShape(t);
    std::printf("[origin on the outline] seed %u, millimetres: %s\n", seed, mm.Describe().c_str());
    EXPECT_FALSE(mm.size_mismatch) << seed;
    EXPECT_FALSE(mm.fits_as_given) << seed;
    // Where it goes the contacts of this push do not settle (the U's bottom edge fits turned and
    // shifted ones as well): the estimator's graph ranks them (Alignment.AUShapeWhoseOrigin...).
    EXPECT_EQ(mm.transform.scale, 0.001) << seed;
  }
}

}  // namespace
}  // namespace pushgraph::graph
