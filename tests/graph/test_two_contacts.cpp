// Estimation of a push whose finger wedges in the notched block's V and touches both walls
// (simulated with every contact, push::PushPlan::multi_contact): two contact rows at one time
// give a step two contact points and two forces, each on both boundaries, the force sensor
// measuring their sum and D taking their summed wrench. Batch (both solvers) and incremental.
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>

#include <Eigen/Cholesky>

#include "graph/notched_push.h"
#include "graph/online_feed.h"

#include <gtest/gtest.h>

#include <optional>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pushgraph::graph {
namespace {

// A finger pushed into the V from above, slightly off its axis: it meets one wall, slides to the
// apex and wedges; the block then translates with it. Noise: 2 mm, 0.02 rad, 0.2 N.
push::Trajectory WedgedPush(std::uint64_t seed) {
  push::PushPlan plan = testing::NotchedBlockPlan(seed);
  plan.finger = {geometry::Shape::Disk(0.004), 0.4};
  plan.object_pose = {0.0, 0.0, 0.1};
  plan.multi_contact = true;
  plan.waypoints = push::StraightPushPath(plan, -M_PI / 2 + 0.25, 0.0, 0.005, 0.05);
  return push::Simulate(plan).trajectory;
}

int TwoContactStates(const EstimationResult& r) {
  int n = 0;
  for (const StateEstimate& s : r.states) n += s.contacts.size() == 2;
  return n;
}

// The same push with only the first contact row of each time: what a one-contact model sees.
push::Trajectory FirstContactOnly(push::Trajectory t) {
  std::vector<push::PointSample> first;
  for (const push::PointSample& p : t.measured.contact_point)
    if (first.empty() || first.back().t != p.t) first.push_back(p);
  t.measured.contact_point = first;
  return t;
}

// Object position RMS error and mean object-pose NEES over the true two-contact times (where the
// truth has two contact rows and an object pose), and the raw measurements' RMS there.
struct PhaseError {
  double rms = 0.0, nees = 0.0, raw_rms = 0.0;
  int n = 0;
};
PhaseError TwoContactPhase(const push::Trajectory& t, const EstimationResult& r) {
  const push::Streams& gt = *t.ground_truth;
  PhaseError out;
  double sq = 0.0, raw_sq = 0.0;
  int raw_n = 0;
  for (const StateEstimate& s : r.states) {
    int rows = 0;
    for (const push::PointSample& c : gt.contact_point) rows += c.t == s.t;
    if (rows < 2) continue;
    const auto truth = std::find_if(gt.object_pose.begin(), gt.object_pose.end(),
                                    [&](const push::PoseSample& p) { return p.t == s.t; });
    if (truth == gt.object_pose.end() || !s.object_pose_cov) continue;
    Eigen::Vector3d e = s.object_pose.vector() - truth->pose.vector();
    e.z() = geometry::WrapAngle(e.z());
    sq += e.head<2>().squaredNorm();
    out.nees += e.dot(s.object_pose_cov->ldlt().solve(e));
    ++out.n;
    for (const push::PoseSample& m : t.measured.object_pose)
      if (m.t == s.t) raw_sq += (m.pose.translation() - truth->pose.translation()).squaredNorm(), ++raw_n;
  }
  if (out.n > 0) out.rms = std::sqrt(sq / out.n), out.nees /= out.n;
  if (raw_n > 0) out.raw_rms = std::sqrt(raw_sq / raw_n);
  return out;
}

// While the finger is wedged, modelling both contacts beats modelling one (the first row of
// each time) on the object pose, and its covariances are consistent where the one-contact
// model's are less so (measured: QS 0.47 mm, NEES 1.9 against 0.58 mm, NEES 2.8).
TEST(TwoContacts, AWedgedFingerIsEstimatedWithBothContacts) {
  const push::Trajectory t = WedgedPush(5);
  ASSERT_TRUE(push::HasRepeatedTimes(t.measured.contact_point));
  const push::Trajectory one = FirstContactOnly(t);
  EstimatorConfig config = ApplyMeasurementSigmas(EstimatorConfig{}, *t.measurement_sigmas);
  for (const Model model : testing::ModelsToRun()) {
    for (const auto solver : {EstimatorConfig::Solver::kCeres, EstimatorConfig::Solver::kChain}) {
      config.solver = solver;
      const EstimationResult r = Estimate(t, model, Mode::kBatch, config);
      const EstimationResult r1 = Estimate(one, model, Mode::kBatch, config);
      const PhaseError two_model = TwoContactPhase(t, r), one_model = TwoContactPhase(t, r1);
      std::printf("[two contacts] %-3s %-6s wedged (%d poses): object %.2f mm, NEES %.2f; one-contact model %.2f mm, "
                  "NEES %.2f; raw %.2f mm; %d two-contact states, %d iterations\n",
                  ModelName(model).c_str(), solver == EstimatorConfig::Solver::kChain ? "chain" : "ceres", two_model.n,
                  1e3 * two_model.rms, two_model.nees, 1e3 * one_model.rms, one_model.nees, 1e3 * two_model.raw_rms,
                  TwoContactStates(r), r.solver.iterations);
      EXPECT_EQ(r.solver.covariance_status, "ok");
      EXPECT_GT(TwoContactStates(r), 100);
      EXPECT_EQ(TwoContactStates(r1), 0);
      ASSERT_GE(two_model.n, 8);
      EXPECT_LT(two_model.rms, 0.5 * two_model.raw_rms) << ModelName(model);
      EXPECT_LT(two_model.rms, one_model.rms) << ModelName(model);
      EXPECT_LT(two_model.nees, one_model.nees) << ModelName(model);
      EXPECT_LT(two_model.nees, 3.0 * 1.5) << ModelName(model);
      int apart = 0, states = 0;
      for (const StateEstimate& s : r.states) {
        if (s.contacts.empty()) continue;
        ASSERT_EQ(s.contacts.size(), 2u);
        ++states;
        EXPECT_TRUE(s.contacts[0].point_cov && s.contacts[1].point_cov);
        // The two contacts are on the two walls, not both on one.
        apart += (s.contacts[0].point - s.contacts[1].point).norm() > 0.002;
        if (ModelHasForce(model)) {
          ASSERT_TRUE(s.force && s.contacts[0].force && s.contacts[1].force);
          EXPECT_LE((*s.force - *s.contacts[0].force - *s.contacts[1].force).norm(), 1e-12);
          EXPECT_FALSE(s.force_cov.has_value());  // the sum's needs the cross-covariance
          EXPECT_TRUE(s.contacts[1].force_cov.has_value());
        }
      }
      EXPECT_GE(apart, states * 95 / 100) << ModelName(model);
    }
  }
}

// Without a tactile sensor (force and poses only) the geometry of the estimate says where the
// finger touches both walls (config.second_contact_tolerance), and modelling both there beats one.
TEST(TwoContacts, WithoutAContactStreamTheGeometryFindsTheWedge) {
  push::Trajectory t = WedgedPush(5);
  t.measured.contact_point.clear();
  EstimatorConfig config = ApplyMeasurementSigmas(EstimatorConfig{}, *t.measurement_sigmas);
  const EstimationResult two = Estimate(t, Model::kQs, Mode::kBatch, config);
  config.second_contact_tolerance = 0.0;
  const EstimationResult one = Estimate(t, Model::kQs, Mode::kBatch, config);
  const PhaseError a = TwoContactPhase(t, two), b = TwoContactPhase(t, one);
  std::printf("[two contacts] qs without contact rows, wedged (%d poses): object %.2f mm, NEES %.2f (%d two-contact "
              "states); one contact: %.2f mm, NEES %.2f; raw %.2f mm\n",
              a.n, 1e3 * a.rms, a.nees, TwoContactStates(two), 1e3 * b.rms, b.nees, 1e3 * a.raw_rms);
  EXPECT_EQ(TwoContactStates(one), 0);
  EXPECT_GT(TwoContactStates(two), 100);
  int apart = 0, states = 0;
  for (const StateEstimate& s : two.states) {
    if (s.contacts.size() != 2) continue;
    ++states;
    apart += (s.contacts[0].point - s.contacts[1].point).norm() > 0.002;  // one on each wall
  }
  EXPECT_GE(apart, states * 95 / 100);
  // Measured: 0.61 mm, NEES 1.46 against 0.62 mm, NEES 1.56: without contact rows the local
  // witness between the walls already serves one contact well; two are no worse.
  ASSERT_GE(a.n, 8);
  EXPECT_LT(a.rms, 1.05 * b.rms);
  EXPECT_LT(a.nees, 1.1 * b.nees);
  EXPECT_EQ(two.solver.covariance_status, "ok");
}

TEST(TwoContacts, IncrementalAndTheBaseline) {
  const push::Trajectory t = WedgedPush(6);
  const EstimatorConfig config = ApplyMeasurementSigmas(EstimatorConfig{}, *t.measurement_sigmas);
  const EstimationResult inc = Estimate(t, Model::kQs, Mode::kIncremental, config);
  EXPECT_GT(TwoContactStates(inc), 100);
  const PhaseError wedged = TwoContactPhase(t, inc);
  std::printf("[two contacts] qs incremental wedged (%d poses): object %.2f mm, NEES %.2f; raw %.2f mm\n", wedged.n,
              1e3 * wedged.rms, wedged.nees, 1e3 * wedged.raw_rms);
  EXPECT_LT(wedged.rms, 0.5 * wedged.raw_rms);
  // The Yu-Rodriguez baseline models one contact, as published: it keeps the first, and says so.
  const EstimationResult yu = Estimate(t, Model::kYu, Mode::kBatch, config);
  EXPECT_EQ(TwoContactStates(yu), 0);
  bool said = false;
  for (const std::string& w : yu.warnings) said = said || w.find("models one contact") != std::string::npos;
  EXPECT_TRUE(said);
}

// Fed sample by sample (two contact rows at one time arrive one after the other), the online
// estimator keeps both contacts; a third at that time is refused by name.
TEST(TwoContacts, OnlineTakesTwoContactsAtOneTime) {
  const push::Trajectory t = WedgedPush(7);
  const EstimatorConfig config = ApplyMeasurementSigmas(EstimatorConfig{}, *t.measurement_sigmas);
  OnlineEstimator online(testing::SetupOf(t), Model::kQs, config, testing::StreamsOf(t));
  for (const testing::Arrival& a : testing::ArrivalOrder(t)) {
    testing::Deliver(a, t, online);
    if (online.UpdateDue()) online.Update();
  }
  const EstimationResult r = online.Finish();
  EXPECT_GT(TwoContactStates(r), 100);
  const PhaseError wedged = TwoContactPhase(t, r);
  std::printf("[two contacts] qs online wedged (%d poses): object %.2f mm, NEES %.2f; raw %.2f mm\n", wedged.n,
              1e3 * wedged.rms, wedged.nees, 1e3 * wedged.raw_rms);
  EXPECT_LT(wedged.rms, 0.5 * wedged.raw_rms);

  OnlineEstimator third(testing::SetupOf(t), Model::kQs, config, testing::StreamsOf(t));
  ASSERT_TRUE(third.AddContactPoint(0.5, Vec2(0.0, 0.01)));
  ASSERT_TRUE(third.AddContactPoint(0.5, Vec2(0.005, 0.01)));
  try {
    third.AddContactPoint(0.5, Vec2(0.001, 0.01));
    FAIL() << "a third contact at one time was accepted";
  } catch (const GraphError& e) {
    EXPECT_NE(std::string(e.what()).find("at most two contacts at one time"), std::string::npos) << e.what();
  }
}

// The self-diagnosis on a wedged push: a disk in the V is near two walls, where the signed
// distance of a noisy finger sample (the nearer wall's) is biased inward; the measured gap along
// the estimate's contact normal is not, so no "wrong probe radius" is reported for the right
// radius (before: -1.1 mm at 2 mm noise, -3.0 mm at 5 mm, both named), and a wrong one still is.
TEST(TwoContacts, AWedgedFingerIsNotTakenForAWrongProbeRadius) {
  // Scaled down (the sanitizer stage): the 2 mm noise only.
  const std::vector<double> noise_scales = pushgraph::testing::TestScale() < 1.0 ? std::vector<double>{1.0}
                                                                                 : std::vector<double>{1.0, 2.5};
  for (const double noise_scale : noise_scales) {
    push::PushPlan plan = testing::NotchedBlockPlan(15);
    plan.noise.object_pose.position.sigma *= noise_scale;
    plan.noise.finger_pose.position.sigma *= noise_scale;
    plan.noise.contact_point.position.sigma *= noise_scale;
    plan.finger = {geometry::Shape::Disk(0.004), 0.4};
    plan.object_pose = {0.0, 0.0, 0.1};
    plan.multi_contact = true;
    plan.waypoints = push::StraightPushPath(plan, -M_PI / 2 + 0.25, 0.0, 0.005, 0.05);
    const push::Trajectory truth = push::Simulate(plan).trajectory;
    for (const double radius : {0.004, 0.0015, 0.0075}) {
      push::Trajectory t = truth;
      t.finger.shape = geometry::Shape::Disk(radius);
      const EstimationResult r = Estimate(t, Model::kQs, Mode::kBatch, ApplyMeasurementSigmas({}, *t.measurement_sigmas));
      ASSERT_TRUE(r.diagnostics.has_value());
      // Named by the self-diagnosis, or by the shape check when the whole graph preferred
      // another finger size, which the estimate then used (ShapeAlignment::finger_radius).
      bool named = false;
      for (const std::string& w : r.warnings) named = named || w.find("probe radius") != std::string::npos;
      const std::optional<double> resized = r.shape_alignment ? r.shape_alignment->finger_radius : std::nullopt;
      std::printf("[wedged diagnostics] noise x%.1f, radius %.1f mm (true 4.0): measured gap median %+.2f mm over %d "
                  "samples%s", noise_scale, 1e3 * radius, 1e3 * r.diagnostics->measured_gap_median,
                  r.diagnostics->measured_samples, named ? ", wrong probe radius named" : "");
      if (resized) std::printf(", estimated with a radius of %.2f mm", *resized * 1e3);
      std::printf("\n");
      // The gap of the finger as given (when the estimate used another size, its gap plus the difference).
      const double gap = r.diagnostics->measured_gap_median + (resized ? *resized - radius : 0.0);
      if (radius == 0.004) {
        // At 5 mm noise the estimated finger's own error (0.4 to 0.7 mm along the normal, smooth
        // in time) is in the median too: one seed of five gave -1.15 mm there.
        if (noise_scale == 1.0) {
          EXPECT_FALSE(named) << "the right radius named wrong";
        }
        EXPECT_LT(std::abs(gap), noise_scale == 1.0 ? 0.8e-3 : 1.5e-3);
      } else if (radius > 0.004) {
        if (noise_scale == 1.0) {
          EXPECT_TRUE(named) << "a probe 3.5 mm too large not named";
        }
        EXPECT_LT(gap, -1.0e-3);
      } else if (noise_scale == 1.0) {
        // Too small: wedged deeper in the V, the finger takes the object with it (the object's
        // pose absorbs much of the error), so the gap shows less of it; its sign is still right.
        EXPECT_GT(gap, 0.3e-3);
      }
    }
  }
}

}  // namespace
}  // namespace pushgraph::graph
