// Estimating a push online, as a robot would (Lambert et al. 2019, incremental inference): the
// sensors' samples reach graph::OnlineEstimator one at a time, and every 5 object measurements
// (UpdateDue) the fixed-lag smoother solves its window and reports the newest state, with the
// paper's occlusion of the object tracker in the middle of the push.
#include <pushgraph/geometry/shape.h>
#include <pushgraph/graph/incremental.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

using namespace pushgraph;
namespace ls = pushgraph::limit_surface;

const push::SimulationState& TruthAt(const push::SimulationResult& sim, double t) {
  return *std::min_element(sim.states.begin(), sim.states.end(), [t](const auto& a, const auto& b) {
    return std::abs(a.t - t) < std::abs(b.t - t);
  });
}

// One sensor sample, as a robot's callbacks would deliver it.
struct Sample {
  double t;
  int stream;  // 0 object pose, 1 finger pose, 2 contact point, 3 force
  std::size_t index;
};

}  // namespace

int main() {
  try {
    // 1. A recorded push stands in for the robot's sensors: the square and probe of
    //    estimate_push.cpp, with the camera occluded from 0.4 s to 0.8 s.
    push::PushPlan plan;
    plan.object.shape = geometry::Shape::Box(0.09, 0.09);
    plan.finger.shape = geometry::Shape::Disk(0.00235);
    plan.object.mass = 0.8374;
    plan.object.mu_surface = 0.25;
    plan.finger.mu_contact = 0.3;
    plan.waypoints = push::StraightPushPath(plan, 0.0, 0.015, 0.003, 0.05);
    plan.speed = 0.05;
    plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
    plan.seed = 7;
    const push::SimulationResult sim = push::Simulate(plan);
    const push::Streams& streams = sim.trajectory.measured;
    const double occlusion_begin = 0.4, occlusion_end = 0.8;

    // 2. The estimator knows the shapes, mass and frictions (no samples yet), the noise, and
    //    which sensors will report.
    push::Trajectory setup;
    setup.object = sim.trajectory.object;
    setup.finger = sim.trajectory.finger;
    setup.ground_truth = sim.trajectory.ground_truth;  // only for the final metrics
    graph::EstimatorConfig config;
    config.measurement.object_trans = plan.noise.object_pose.position.sigma;
    config.measurement.object_rot = plan.noise.object_pose.angle.sigma;
    config.measurement.finger_trans = plan.noise.finger_pose.position.sigma;
    config.measurement.contact = plan.noise.contact_point.position.sigma;
    config.measurement.force = plan.noise.force.position.sigma;
    graph::OnlineStreams sensors;
    sensors.contact_point = true;  // a tactile sensor
    sensors.force = true;          // a force/torque sensor
    graph::OnlineEstimator online(setup, graph::Model::kQs, config, sensors);

    // 3. The robot's loop: deliver the samples of each time stamp, update when due.
    std::vector<Sample> samples;
    for (std::size_t i = 0; i < streams.object_pose.size(); ++i) {
      const double t = streams.object_pose[i].t;
      if (t < occlusion_begin || t > occlusion_end) samples.push_back({t, 0, i});
    }
    for (std::size_t i = 0; i < streams.finger_pose.size(); ++i) samples.push_back({streams.finger_pose[i].t, 1, i});
    for (std::size_t i = 0; i < streams.contact_point.size(); ++i) samples.push_back({streams.contact_point[i].t, 2, i});
    for (std::size_t i = 0; i < streams.force.size(); ++i) samples.push_back({streams.force[i].t, 3, i});
    std::stable_sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; });

    std::printf("%6s %9s %7s  %-24s %-24s\n", "t (s)", "update", "window", "object x, y (mm) now", "truth");
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const Sample& s = samples[k];
      if (s.stream == 0) online.AddObjectPose(s.t, streams.object_pose[s.index].pose);
      if (s.stream == 1) online.AddFingerPose(s.t, streams.finger_pose[s.index].pose);
      if (s.stream == 2) online.AddContactPoint(s.t, streams.contact_point[s.index].point);
      if (s.stream == 3) online.AddForce(s.t, streams.force[s.index].force);
      const bool stamp_complete = k + 1 == samples.size() || samples[k + 1].t > s.t;
      if (!stamp_complete || !online.UpdateDue()) continue;
      const double seconds = online.Update();
      const graph::StateEstimate now = online.LatestState();  // the filtered (causal) estimate
      const push::SimulationState& truth = TruthAt(sim, now.t);
      const bool occluded = now.t > occlusion_begin && now.t < occlusion_end;
      std::printf("%6.3f %6.1f ms %7d  %7.2f %7.2f %-8s %7.2f %7.2f\n", now.t, 1e3 * seconds, online.WindowSteps(),
                  1e3 * now.object_pose.x, 1e3 * now.object_pose.y, occluded ? "occluded" : "",
                  1e3 * truth.object_pose.x, 1e3 * truth.object_pose.y);
    }

    // 4. The smoothed trajectory (every step, with the covariances of its last window).
    const graph::EstimationResult result = online.Finish();
    const auto& m = result.metrics;
    auto get = [&m](const char* key) { return m.count(key) ? m.at(key) : NAN; };
    std::printf("\n%d updates (the last in Finish), worst %.1f ms; %zu steps\n", result.solver.updates,
                1e3 * result.solver.max_update_time_s, result.states.size());
    std::printf("object position RMS %.3f mm (measured %.3f mm), force RMS %.3f N (measured %.3f N), object NEES %.2f\n",
                1e3 * get("object_position_rms"), 1e3 * get("measured_object_position_rms"), get("force_rms"),
                get("measured_force_rms"), get("object_pose_nees"));
    // What the estimator found wrong with its setup or its solves (online.Warnings() has the
    // setup's findings as soon as an update makes them: a shape in other units or frame).
    for (const std::string& warning : result.warnings) std::printf("warning: %s\n", warning.c_str());
    if (!(get("object_position_rms") < get("measured_object_position_rms"))) {
      std::fprintf(stderr, "online_push: the estimate is not better than the measurements\n");
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "online_push: %s\n", e.what());
    return 1;
  }
  return 0;
}
