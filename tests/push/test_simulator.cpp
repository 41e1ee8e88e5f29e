// The push simulator (contact kept, no interpenetration, loads on the limit surface, contact
// broken on retreat, rates, determinism), the noise models (Gaussian, bimodal, occlusion,
// outliers, frozen sensor) and `pushgraph simulate`.
#include <pushgraph/io/trajectory_json.h>
#include <pushgraph/push/simulator.h>

#include "tool_runner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace pushgraph::push {
using namespace limit_surface;
namespace {


using geometry::Pose2;
using geometry::Shape;

PushPlan SquarePlan(double mu_contact, double offset, double push_distance = 0.04) {
  PushPlan plan;
  plan.object.shape = Shape::Box(0.09, 0.09);  // MIT rect1
  plan.finger.shape = Shape::Disk(0.00235);
  plan.object.mass = 0.8374;
  plan.object.mu_surface = 0.25;
  plan.finger.mu_contact = mu_contact;
  plan.object_pose = {0.0, 0.0, 0.0};
  plan.speed = 0.05;
  plan.waypoints = StraightPushPath(plan, 0.0, offset, 0.005, push_distance);
  return plan;
}

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

void ExpectPhysicalRun(const PushPlan& plan, const SimulationResult& r, double contact_start_time) {
  EXPECT_LE(r.stats.max_penetration, 1e-9);
  EXPECT_LE(r.stats.max_gap_in_contact, plan.contact_tolerance);
  EXPECT_LE(r.stats.max_torque_residual, 1e-9);
  PushingSpec spec;
  spec.object = plan.object;
  spec.finger = plan.finger;
  spec.object.mass = plan.object.mass;
  spec.object.mu_surface = plan.object.mu_surface;
  spec.finger.mu_contact = plan.finger.mu_contact;
  const PushingModel model(spec);
  const double path_time = PathLength(plan.waypoints) / plan.speed;
  int pushing_states = 0;
  for (const SimulationState& s : r.states) {
    const bool should_push = s.t > contact_start_time + 1e-3 && s.t < path_time - 1e-9;
    if (should_push) {
      // Contact is kept all along the push.
      EXPECT_NE(s.response.mode, ContactMode::kSeparated) << "t = " << s.t;
    }
    if (s.response.mode == ContactMode::kSeparated) continue;
    ++pushing_states;
    // The applied load lies on the limit surface at the resulting twist.
    const Load expected = SustainingLoad(model.support(), s.response.twist);
    EXPECT_LE((s.response.load.force - expected.force).norm(), 1e-9 * model.summary().f_max) << "t = " << s.t;
    EXPECT_LE(std::abs(s.response.load.torque - expected.torque), 1e-9 * model.summary().tau_max);
    const Vec2 rel = geometry::InverseAct(s.object_pose, s.response.contact_point) - model.support().centre_of_pressure;
    EXPECT_LE(std::abs(s.response.load.torque - Cross(rel, s.response.load.force)), 1e-9 * model.summary().tau_max);
    EXPECT_LE(std::abs(s.response.separation), plan.contact_tolerance);
  }
  EXPECT_GT(pushing_states, 10);
}

TEST(Simulator, CentralPushOnMitSquareTranslatesAndKeepsContact) {
  const PushPlan plan = SquarePlan(0.3, 0.0);
  const SimulationResult r = Simulate(plan);
  ExpectPhysicalRun(plan, r, 0.005 / plan.speed);
  const Pose2 end = r.states.back().object_pose;
  EXPECT_NEAR(r.states.back().t, 0.045 / plan.speed, 1e-12);
  EXPECT_NEAR(end.x, 0.04, 1e-6);  // pushed by the travel after contact
  EXPECT_NEAR(end.y, 0.0, 1e-9);
  EXPECT_NEAR(end.theta, 0.0, 1e-9);
  EXPECT_EQ(r.stats.sliding_steps, 0);
  // Every pushing force sample is mu m g along +x.
  const double f_max = 0.25 * 0.8374 * kStandardGravity;
  int pushing = 0;
  for (const ForceSample& f : r.trajectory.ground_truth->force) {
    if (f.force.norm() == 0.0) continue;
    ++pushing;
    EXPECT_NEAR(f.force.x(), f_max, 1e-9 * f_max);
    EXPECT_NEAR(f.force.y(), 0.0, 1e-9 * f_max);
  }
  EXPECT_GT(pushing, 150);
  // The reported twist is the object's velocity: the finger's speed along +x.
  for (const SimulationState& s : r.states) {
    if (s.response.mode == ContactMode::kSeparated) continue;
    EXPECT_NEAR(s.response.twist.vx, plan.speed, 1e-12);
    EXPECT_NEAR(s.response.twist.omega, 0.0, 1e-12);
  }
}

TEST(Simulator, OffsetPushRotatesClockwiseAndStaysInContact) {
  for (double mu_contact : {0.0, 0.2, 1.0}) {
    const PushPlan plan = SquarePlan(mu_contact, 0.02, 0.05);
    const SimulationResult r = Simulate(plan);
    ExpectPhysicalRun(plan, r, 0.005 / plan.speed);
    EXPECT_LT(r.trajectory.ground_truth->object_pose.back().pose.theta, -0.02) << mu_contact;
    if (mu_contact == 0.0) {
      EXPECT_EQ(r.stats.sticking_steps, 0);
      EXPECT_GT(r.stats.sliding_steps, 0);
    }
    if (mu_contact == 1.0) {
      EXPECT_GT(r.stats.sticking_steps, 0);
    }
    // The reported angular velocity matches the finite difference of the sampled poses.
    int checked = 0;
    for (std::size_t i = 1; i + 1 < r.states.size(); ++i) {
      const SimulationState &a = r.states[i], &b = r.states[i + 1];
      if (a.response.mode == ContactMode::kSeparated || b.response.mode == ContactMode::kSeparated) continue;
      const double fd = (b.object_pose.theta - a.object_pose.theta) / (b.t - a.t);
      EXPECT_NEAR(fd, 0.5 * (a.response.twist.omega + b.response.twist.omega), 1e-3 * std::abs(fd) + 1e-9)
          << "t = " << a.t;
      ++checked;
    }
    EXPECT_GT(checked, 100);
  }
}

TEST(Simulator, EllipsoidModelAndFrozenSensorRun) {
  PushPlan plan = SquarePlan(0.3, 0.02, 0.05);
  plan.surface = SurfaceModel::kEllipsoid;
  plan.speed = 0.075;  // the rect1 recordings' speed
  plan.noise = DefaultNoise(NoiseKind::kGaussian);
  plan.noise.frozen_force.push_back({0.3, 0.5, std::nullopt});
  const SimulationResult r = Simulate(plan);
  EXPECT_LE(r.stats.max_penetration, 1e-9);
  EXPECT_LE(r.stats.max_torque_residual, 1e-9);
  EXPECT_LT(r.states.back().object_pose.theta, -0.02);
  PushingSpec spec;
  spec.object = plan.object;
  spec.finger = plan.finger;
  spec.object.mass = plan.object.mass;
  spec.object.mu_surface = plan.object.mu_surface;
  spec.finger.mu_contact = plan.finger.mu_contact;
  spec.surface = SurfaceModel::kEllipsoid;
  const PushingModel model(spec);
  for (const SimulationState& s : r.states) {
    if (s.response.mode == ContactMode::kSeparated) continue;
    const Eigen::Vector3d F(s.response.load.force.x(), s.response.load.force.y(), s.response.load.torque);
    EXPECT_NEAR(F.dot(model.ellipsoid().A * F), 1.0, 1e-9);  // on the ellipsoid
  }
  int frozen = 0;
  const auto& measured = r.trajectory.measured.force;
  for (std::size_t i = 1; i < measured.size(); ++i) {
    if (measured[i].t > 0.3 && measured[i].t <= 0.5) {
      EXPECT_EQ(measured[i].force, measured[i - 1].force);
      ++frozen;
    }
  }
  EXPECT_EQ(frozen, 50);  // 250 Hz over (0.3, 0.5]
}

TEST(Simulator, ContactIsBrokenWhenTheFingerRetreats) {
  PushPlan plan = SquarePlan(0.3, 0.01, 0.02);
  const Vec2 in = plan.waypoints.back();
  plan.waypoints.push_back(in - Vec2(0.01, 0.0));  // back off 1 cm
  const SimulationResult r = Simulate(plan);
  const double retreat_start = PathLength({plan.waypoints[0], plan.waypoints[1]}) / plan.speed;
  Pose2 at_retreat;
  bool have = false;
  for (const SimulationState& s : r.states) {
    if (s.t < retreat_start - 1e-9) continue;
    if (!have) {
      at_retreat = s.object_pose;
      have = true;
    }
    EXPECT_EQ(s.response.mode, ContactMode::kSeparated) << s.t;
    EXPECT_EQ(s.response.force, Vec2(0.0, 0.0));
    EXPECT_EQ(s.object_pose.x, at_retreat.x);
    EXPECT_EQ(s.object_pose.theta, at_retreat.theta);
  }
  ASSERT_TRUE(have);
  // The contact stream stops once the finger has left (more than the tolerance away).
  const auto& contacts = r.trajectory.ground_truth->contact_point;
  ASSERT_FALSE(contacts.empty());
  EXPECT_LT(contacts.back().t, retreat_start + 0.01);
  EXPECT_GT(r.states.back().response.separation, 0.009);
}

TEST(Simulator, StreamsKeepTheirOwnRates) {
  PushPlan plan = SquarePlan(0.3, 0.0);
  plan.duration = 1.0;
  const SimulationResult r = Simulate(plan);
  const Streams& gt = *r.trajectory.ground_truth;
  EXPECT_EQ(gt.object_pose.size(), 26u);   // 25 Hz over [0, 1]
  EXPECT_EQ(gt.finger_pose.size(), 251u);  // 250 Hz
  EXPECT_EQ(gt.force.size(), 251u);
  EXPECT_NEAR(gt.object_pose[1].t - gt.object_pose[0].t, 0.04, 1e-15);
  EXPECT_NEAR(gt.finger_pose[1].t - gt.finger_pose[0].t, 0.004, 1e-15);
  // The finger follows its path at the commanded speed.
  const Vec2 start = plan.waypoints.front();
  for (const PoseSample& s : gt.finger_pose) {
    const double expected = std::min(plan.speed * s.t, PathLength(plan.waypoints));
    EXPECT_NEAR((s.pose.translation() - start).norm(), expected, 1e-12);
  }
}

TEST(Simulator, SameSeedSameOutputDifferentSeedDifferentNoise) {
  PushPlan plan = SquarePlan(0.3, 0.01);
  plan.noise = DefaultNoise(NoiseKind::kBimodal);
  plan.noise.force.outlier_probability = 0.05;
  plan.noise.force.outlier_magnitude = 1.0;
  plan.seed = 42;
  const std::string a = io::TrajectoryToJson(Simulate(plan).trajectory);
  const std::string b = io::TrajectoryToJson(Simulate(plan).trajectory);
  EXPECT_EQ(a, b);
  plan.seed = 43;
  const std::string c = io::TrajectoryToJson(Simulate(plan).trajectory);
  EXPECT_NE(a, c);
}

// ToolTest for its private temporary folder (ctest runs tests in parallel processes).
class SimulatorFiles : public pushgraph::testing::ToolTest {};

TEST_F(SimulatorFiles, WritesAndReadsBackTheTrajectoryFile) {
  PushPlan plan = SquarePlan(0.3, 0.01);
  plan.noise = DefaultNoise(NoiseKind::kGaussian);
  const SimulationResult r = Simulate(plan);
  const std::string path = (dir_ / "sim_roundtrip.json").string();
  io::SaveTrajectoryJson(r.trajectory, path);
  const Trajectory back = io::LoadTrajectoryJson(path);
  ASSERT_TRUE(back.ground_truth.has_value());
  EXPECT_EQ(back.measured.object_pose.size(), r.trajectory.measured.object_pose.size());
  EXPECT_EQ(back.ground_truth->force.size(), r.trajectory.ground_truth->force.size());
  EXPECT_DOUBLE_EQ(back.object.mass, 0.8374);
  EXPECT_DOUBLE_EQ(back.finger.mu_contact, 0.3);
  std::remove(path.c_str());
}

TEST(Simulator, NotchedBlockWithHoles) {
  PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  plan.finger.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/disk_finger_5mm.json");
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.finger.mu_contact = 0.4;
  plan.object_pose = {0.01, 0.02, 0.3};
  plan.waypoints = StraightPushPath(plan, M_PI / 2 + 0.3, -0.025, 0.005, 0.05);
  const SimulationResult r = Simulate(plan);
  ExpectPhysicalRun(plan, r, 0.005 / plan.speed);
  EXPECT_GT(std::abs(r.trajectory.ground_truth->object_pose.back().pose.theta - 0.3), 0.01);
}

TEST(Simulator, StraightPushPathTravelsToContactThenTheGivenDistance) {
  // Into the V-notch of the block from above: the line meets the notch walls obliquely, so the
  // travel to contact is longer than the initial separation.
  PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  plan.finger.shape = Shape::Disk(0.005);
  const std::vector<Vec2> path = StraightPushPath(plan, -M_PI / 2, 0.0, 0.005, 0.01);
  ASSERT_EQ(path.size(), 2u);
  const geometry::ShapePairQuerier q(plan.object.shape, plan.finger.shape);
  EXPECT_NEAR(q.Query(plan.object_pose, {path[0].x(), path[0].y(), 0.0}).signed_distance, 0.005, 1e-9);
  const Vec2 contact = path[1] + Vec2(0.0, 0.01);  // 1 cm before the end
  EXPECT_NEAR(q.Query(plan.object_pose, {contact.x(), contact.y(), 0.0}).signed_distance, 0.0, 1e-9);
  EXPECT_GT((path[1] - path[0]).norm() - 0.01, 0.0055);
}

TEST(Simulator, BadPlansNameTheField) {
  PushPlan plan = SquarePlan(0.3, 0.0);
  plan.speed = -1.0;
  try {
    Simulate(plan);
    FAIL() << "no exception";
  } catch (const PushError& e) {
    EXPECT_NE(std::string(e.what()).find("speed"), std::string::npos) << e.what();
  }
  plan = SquarePlan(0.3, 0.0);
  plan.waypoints.resize(1);
  EXPECT_THROW(Simulate(plan), PushError);
  plan = SquarePlan(0.3, 0.0);
  EXPECT_THROW(StraightPushPath(plan, 0.0, 0.2, 0.005, 0.01), PushError);  // line misses
  plan.waypoints = {Vec2(0.0, 0.0), Vec2(0.01, 0.0)};  // starts inside the object
  EXPECT_THROW(Simulate(plan), PushError);
  // Pushes too long to hold or to integrate are refused up front, not run out of memory or
  // forever (1e20 s once overflowed the sample count's cast and passed its check).
  auto expect_refused = [](const PushPlan& p, const std::string& text) {
    try {
      Simulate(p);
      ADD_FAILURE() << "no exception, expected " << text;
    } catch (const PushError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  for (double duration : {1e20, 1e9}) {
    plan = SquarePlan(0.3, 0.0);
    plan.duration = duration;
    expect_refused(plan, "more than 1e8 integration steps");
  }
  plan = SquarePlan(0.3, 0.0);
  plan.duration = 20000.0;  // 5e6 samples at 250 Hz
  plan.internal_step = 1.0;
  plan.max_step_length = 1e3;
  expect_refused(plan, "more than 1e6 samples in one stream");
  plan = SquarePlan(0.3, 0.0);
  plan.internal_step = 1e-12;
  expect_refused(plan, "more than 1e8 integration steps");
}

// ---- noise models ----------------------------------------------------------------------------

struct Moments {
  double mean = 0.0, sd = 0.0;
};
Moments MomentsOf(const std::vector<double>& v) {
  Moments m;
  m.mean = std::accumulate(v.begin(), v.end(), 0.0) / v.size();
  double ss = 0.0;
  for (double x : v) ss += (x - m.mean) * (x - m.mean);
  m.sd = std::sqrt(ss / (v.size() - 1));
  return m;
}

Streams LongTruth(int n, double dt) {
  Streams s;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    s.object_pose.push_back({t, Pose2{0.1 * t, 0.0, 0.01 * t}});
    s.finger_pose.push_back({t, Pose2{0.1 * t, -0.05, 0.0}});
    s.contact_point.push_back({t, Vec2(0.1 * t, -0.045)});
    s.force.push_back({t, Vec2(0.5, 0.1 * std::sin(t))});
  }
  return s;
}

TEST(Noise, GaussianSigmaMatches) {
  NoiseModel model = DefaultNoise(NoiseKind::kGaussian);
  const Streams truth = LongTruth(100000, 0.001);
  const Streams m = ApplyNoise(truth, model, 5);
  std::vector<double> ex, et, fy;
  for (std::size_t i = 0; i < truth.object_pose.size(); ++i) {
    ex.push_back(m.object_pose[i].pose.x - truth.object_pose[i].pose.x);
    et.push_back(m.object_pose[i].pose.theta - truth.object_pose[i].pose.theta);
    fy.push_back(m.force[i].force.y() - truth.force[i].force.y());
  }
  for (const auto& [v, sigma] : {std::pair{ex, 0.002}, std::pair{et, 0.02}, std::pair{fy, 0.05}}) {
    const Moments mo = MomentsOf(v);
    EXPECT_NEAR(mo.sd, sigma, 0.02 * sigma);
    EXPECT_NEAR(mo.mean, 0.0, 0.02 * sigma);
  }
}

TEST(Noise, BimodalMixtureOfTwoTriangles) {
  const ScalarNoise noise{NoiseKind::kBimodal, 2.0, 0.9};
  std::mt19937_64 rng(11);
  std::vector<double> v;
  const int n = 400000;
  for (int i = 0; i < n; ++i) v.push_back(noise.Sample(rng));
  const Moments mo = MomentsOf(v);
  EXPECT_NEAR(mo.sd, 2.0, 0.02 * 2.0);
  EXPECT_NEAR(mo.mean, 0.0, 0.02);
  // Bounded support: |x| <= a + w.
  const double a = 0.9 * 2.0, w = std::sqrt(6.0 * (1.0 - 0.81)) * 2.0;
  for (double x : v) ASSERT_LE(std::abs(x), a + w + 1e-12);
  // Histogram against the exact mixture density: peaks at +-a, dip at 0.
  auto density = [&](double x) {
    auto tri = [&](double c) { return std::max(0.0, 1.0 - std::abs(x - c) / w) / w; };
    return 0.5 * tri(-a) + 0.5 * tri(a);
  };
  const double h = 0.1;
  for (double centre : {-a, -1.0, 0.0, 1.0, a, a + 0.5 * w}) {
    int count = 0;
    for (double x : v) count += std::abs(x - centre) < 0.5 * h;
    const double empirical = count / (n * h);
    EXPECT_NEAR(empirical, density(centre), 0.05 * density(a)) << "at " << centre;
  }
  EXPECT_GT(density(a), 2.5 * density(0.0));
}

TEST(Noise, OcclusionStopsOrDegradesTheObjectStream) {
  const Streams truth = LongTruth(20000, 0.001);  // 20 s
  NoiseModel model = DefaultNoise(NoiseKind::kGaussian);
  model.occlusions.push_back({5.0, 10.0, OcclusionMode::kStop});
  Streams m = ApplyNoise(truth, model, 3);
  for (const PoseSample& s : m.object_pose) EXPECT_FALSE(s.t >= 5.0 && s.t <= 10.0) << s.t;
  EXPECT_NEAR(static_cast<double>(m.object_pose.size()), 20000.0 - 5001.0, 0.5);
  EXPECT_EQ(m.finger_pose.size(), truth.finger_pose.size());  // other streams untouched

  model.occlusions[0].mode = OcclusionMode::kDegrade;
  model.occlusions[0].sigma_scale = 8.0;
  m = ApplyNoise(truth, model, 3);
  ASSERT_EQ(m.object_pose.size(), truth.object_pose.size());
  std::vector<double> inside, outside;
  for (std::size_t i = 0; i < truth.object_pose.size(); ++i) {
    const double e = m.object_pose[i].pose.y - truth.object_pose[i].pose.y;
    (truth.object_pose[i].t >= 5.0 && truth.object_pose[i].t <= 10.0 ? inside : outside).push_back(e);
  }
  EXPECT_NEAR(MomentsOf(inside).sd, 8.0 * 0.002, 0.04 * 8.0 * 0.002);
  EXPECT_NEAR(MomentsOf(outside).sd, 0.002, 0.04 * 0.002);
}

TEST(Noise, OutliersHaveTheGivenRateAndMagnitude) {
  const Streams truth = LongTruth(50000, 0.001);
  NoiseModel model = DefaultNoise(NoiseKind::kNone);
  model.contact_point.outlier_probability = 0.1;
  model.contact_point.outlier_magnitude = 0.02;
  const Streams m = ApplyNoise(truth, model, 9);
  int outliers = 0;
  for (std::size_t i = 0; i < truth.contact_point.size(); ++i) {
    const double e = (m.contact_point[i].point - truth.contact_point[i].point).norm();
    if (e > 0.0) {
      ++outliers;
      EXPECT_NEAR(e, 0.02, 1e-12);
    }
  }
  EXPECT_NEAR(outliers / 50000.0, 0.1, 0.01);
  for (std::size_t i = 0; i < truth.force.size(); ++i) EXPECT_EQ(m.force[i].force, truth.force[i].force);
}

TEST(Noise, FrozenForceSensorIsConstant) {
  const Streams truth = LongTruth(3000, 0.001);
  NoiseModel model = DefaultNoise(NoiseKind::kGaussian);
  model.frozen_force.push_back({1.0, 2.0, std::nullopt});
  model.frozen_force.push_back({2.5, 2.7, Vec2(3.0, -1.0)});
  const Streams m = ApplyNoise(truth, model, 2);
  Vec2 before(0, 0);
  int frozen = 0;
  for (std::size_t i = 0; i < m.force.size(); ++i) {
    const double t = m.force[i].t;
    if (t < 1.0) before = m.force[i].force;
    if (t >= 1.0 && t <= 2.0) {
      EXPECT_EQ(m.force[i].force, before) << t;
      ++frozen;
    }
    if (t >= 2.5 && t <= 2.7) {
      EXPECT_EQ(m.force[i].force, Vec2(3.0, -1.0)) << t;
    }
    if (t > 2.0 && t < 2.5) {
      EXPECT_NE(m.force[i].force, m.force[i - 1].force) << t;  // live again
    }
  }
  EXPECT_EQ(frozen, 1001);
}

TEST(Noise, DeterministicAndStreamIndependent) {
  const Streams truth = LongTruth(1000, 0.01);
  const NoiseModel model = DefaultNoise(NoiseKind::kBimodal);
  const Streams a = ApplyNoise(truth, model, 77), b = ApplyNoise(truth, model, 77);
  for (std::size_t i = 0; i < a.force.size(); ++i) EXPECT_EQ(a.force[i].force, b.force[i].force);
  // Removing half of the force samples does not change the object stream's noise.
  Streams shorter = truth;
  shorter.force.resize(500);
  const Streams c = ApplyNoise(shorter, model, 77);
  for (std::size_t i = 0; i < a.object_pose.size(); ++i) EXPECT_EQ(a.object_pose[i].pose.x, c.object_pose[i].pose.x);
}

TEST(Noise, BadModelsNameTheField) {
  NoiseModel model;
  model.force.position.sigma = -1.0;
  try {
    ValidateNoise(model);
    FAIL();
  } catch (const PushError& e) {
    EXPECT_NE(std::string(e.what()).find("force.position.sigma"), std::string::npos) << e.what();
  }
  model = NoiseModel();
  model.occlusions.push_back({2.0, 1.0});
  EXPECT_THROW(ValidateNoise(model), PushError);
  model = NoiseModel();
  model.object_pose.outlier_probability = 1.5;
  EXPECT_THROW(ValidateNoise(model), PushError);
}

// ---- pushgraph simulate ------------------------------------------------------------------------

class SimulateCli : public pushgraph::testing::ToolTest {
 protected:
  pushgraph::testing::ToolRun RunTool(const std::string& args) { return Exec("simulate " + args); }
};

TEST_F(SimulateCli, DefaultsWriteAValidTrajectory) {
  const std::string out = (dir_ / "cli_sim.json").string();
  const pushgraph::testing::ToolRun r = RunTool("-o " + out + " --seed 3 --noise bimodal --occlusion 0.5,0.8 --outliers 0.02");
  ASSERT_EQ(r.status, 0) << r.err;
  const Trajectory t = io::LoadTrajectoryJson(out);
  ASSERT_TRUE(t.ground_truth.has_value());
  EXPECT_GT(t.ground_truth->object_pose.size(), 10u);
  EXPECT_LT(t.measured.object_pose.size(), t.ground_truth->object_pose.size());  // occluded
  EXPECT_GT(t.object.shape.core_area(), 0.0);
  // The object was pushed.
  const Pose2 a = t.ground_truth->object_pose.front().pose, b = t.ground_truth->object_pose.back().pose;
  EXPECT_GT(std::hypot(b.x - a.x, b.y - a.y), 0.01);
  // Same seed -> identical file.
  const std::string out2 = (dir_ / "cli_sim2.json").string();
  ASSERT_EQ(RunTool("-o " + out2 + " --seed 3 --noise bimodal --occlusion 0.5,0.8 --outliers 0.02").status, 0);
  std::ifstream f1(out), f2(out2);
  std::stringstream s1, s2;
  s1 << f1.rdbuf();
  s2 << f2.rdbuf();
  EXPECT_EQ(s1.str(), s2.str());
  std::remove(out.c_str());
  std::remove(out2.c_str());
}

TEST_F(SimulateCli, BadInputIsOneLineError) {
  const std::string out = (dir_ / "cli_bad.json").string();
  for (const std::string& args : {std::string("-o " + out + " --mass -1"), std::string("-o " + out + " --noise pink"),
                                  std::string("-o " + out + " --occlusion 2,1"),
                                  std::string("-o " + out + " --object /nonexistent/shape.json"),
                                  std::string("-o " + out + " --outliers 2"),
                                  // A file estimate could not read: noise beyond its range, or no object pose at all.
                                  std::string("-o " + out + " --sigma-object 1e300,1e300"),
                                  std::string("-o " + out + " --sigma-force 2e6"),
                                  std::string("-o " + out + " --occlusion -1,100"),
                                  // 50 m/s (mm/s meant): the push ends before a second sample.
                                  std::string("-o " + out + " --speed 50"),
                                  std::string("-o " + out + " --rate-object 0 --rate-finger 0 --rate-contact 0 --rate-force 0")}) {
    const pushgraph::testing::ToolRun r = RunTool(args);
    EXPECT_FALSE(std::ifstream(out).good()) << args << ": a file was written";
    EXPECT_NE(r.status, 0) << args;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

TEST_F(SimulateCli, SeveralFingersAndContactsAreWrittenAndDrawn) {
  // Two disk fingers of one pusher (placed by their own shape coordinates), and one finger
  // wedged in the notched block's V with --multi-contact.
  const std::string left = (dir_ / "left.json").string(), right = (dir_ / "right.json").string();
  std::ofstream(left) << R"({"polygons": [{"outer": [[0, 0.02]]}], "radius": 0.004})";
  std::ofstream(right) << R"({"polygons": [{"outer": [[0, -0.02]]}], "radius": 0.004})";
  const std::string two = (dir_ / "two.json").string(), two_svg = (dir_ / "two.svg").string();
  pushgraph::testing::ToolRun r =
      RunTool("-o " + two + " --fingers " + left + " " + right + " --push-angle 0 --offset 0 --distance 0.02 --svg " + two_svg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"fingers\": 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"max_simultaneous_contacts\": 2"), std::string::npos) << r.out;
  const Trajectory t = io::LoadTrajectoryJson(two);
  ASSERT_EQ(FingerCount(t), 2);
  EXPECT_FALSE(t.extra_fingers[0].measured.force.empty());
  // The summary counts the rows of every finger, as the file holds them.
  std::size_t contact_rows = t.measured.contact_point.size() + t.extra_fingers[0].measured.contact_point.size();
  EXPECT_NE(r.out.find("\"contact_point\": " + std::to_string(contact_rows)), std::string::npos) << r.out;
  std::ifstream svg_in(two_svg);
  std::stringstream svg;
  svg << svg_in.rdbuf();
  EXPECT_NE(svg.str().find("class='finger-1'"), std::string::npos);
  EXPECT_NE(svg.str().find("class='force-1'"), std::string::npos);
  const std::string wedge = (dir_ / "wedge.json").string();
  r = RunTool("-o " + wedge + " --multi-contact --push-angle -1.5707963267948966 --offset 0 --distance 0.02");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"max_simultaneous_contacts\": 2"), std::string::npos) << r.out;
  EXPECT_TRUE(HasRepeatedTimes(io::LoadTrajectoryJson(wedge).measured.contact_point));
  // One file after --fingers is a mistake, said in one line; so are overlapping fingers.
  r = RunTool("-o " + (dir_ / "bad.json").string() + " --fingers " + left);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--fingers needs two or more"), std::string::npos) << r.err;
  r = RunTool("-o " + (dir_ / "bad.json").string() + " --fingers " + left + " " + left);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("overlap each other"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // Fingers that touch each other (8 mm apart, radius 4 mm) are two fingers, not an overlap.
  const std::string touching = (dir_ / "touching.json").string();
  std::ofstream(touching) << R"({"polygons": [{"outer": [[0, -0.008]]}], "radius": 0.004})";
  const std::string middle = (dir_ / "middle.json").string();
  std::ofstream(middle) << R"({"polygons": [{"outer": [[0, 0]]}], "radius": 0.004})";
  r = RunTool("-o " + (dir_ / "touching_out.json").string() + " --fingers " + middle + " " + touching +
              " --push-angle 0 --offset 0 --distance 0.01");
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(SimulateCli, EveryFlagInHelpIsDocumented) {
  const pushgraph::testing::ToolRun run = RunTool("--help");
  ASSERT_EQ(run.status, 0) << run.err;
  std::ifstream doc_in(std::string(PUSHGRAPH_SOURCE_DIR) + "/docs/simulator.md");
  std::stringstream doc;
  doc << doc_in.rdbuf();
  const std::string h = run.out, d = doc.str();
  int flags = 0;
  for (std::size_t pos = h.find("--"); pos != std::string::npos; pos = h.find("--", pos + 2)) {
    std::size_t end = pos + 2;
    while (end < h.size() && (std::isalnum(static_cast<unsigned char>(h[end])) || h[end] == '-')) ++end;
    const std::string flag = h.substr(pos, end - pos);
    if (flag == "--" || flag == "--help") continue;
    ++flags;
    EXPECT_NE(d.find(flag), std::string::npos) << flag << " is not in docs/simulator.md";
  }
  EXPECT_GE(flags, 25);
}

}  // namespace
}  // namespace pushgraph::push
