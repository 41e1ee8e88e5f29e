// Estimating a push with the library (no tool, no files): simulate a noisy push of a 9 cm square
// by a 4.7 mm probe (the MIT dataset's rect1 and probe), estimate object pose, finger pose,
// contact point and contact force with the quasi-static factor graph (Lambert et al. 2019, QS
// graph), and compare with the simulator's ground truth.
#include <pushgraph/geometry/shape.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

namespace {

using namespace pushgraph;
namespace ls = pushgraph::limit_surface;

// The ground-truth state at time t (the simulator records every sample time of every stream).
const push::SimulationState& TruthAt(const push::SimulationResult& sim, double t) {
  return *std::min_element(sim.states.begin(), sim.states.end(), [t](const auto& a, const auto& b) {
    return std::abs(a.t - t) < std::abs(b.t - t);
  });
}

double TwoSigma(const Eigen::MatrixXd& covariance, int i) { return 2.0 * std::sqrt(covariance(i, i)); }

}  // namespace

int main() {
  try {
    // 1. A push: the finger starts 3 mm from the square's left side, 1.5 cm above its centre
    //    line (so the object turns while it slides), and pushes 5 cm to the right at 5 cm/s.
    push::PushPlan plan;
    plan.object.shape = geometry::Shape::Box(0.09, 0.09);
    plan.finger.shape = geometry::Shape::Disk(0.00235);
    plan.object.mass = 0.8374;      // kg
    plan.object.mu_surface = 0.25;  // object-table
    plan.finger.mu_contact = 0.3;   // finger-object
    plan.waypoints = push::StraightPushPath(plan, /*push_angle=*/0.0, /*offset=*/0.015, /*standoff=*/0.003,
                                          /*push_distance=*/0.05);
    plan.speed = 0.05;
    // Streams at the paper's rates (object 25 Hz, finger/contact/force 250 Hz) with Gaussian noise:
    // object 2 mm / 0.02 rad, finger 0.5 mm, contact 1 mm, force 0.05 N (DefaultNoise).
    plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
    plan.seed = 7;
    const push::SimulationResult sim = push::Simulate(plan);
    std::printf("simulated %.2f s: %d steps (%d sticking, %d sliding); %zu object and %zu force samples\n",
                sim.states.back().t, sim.stats.steps, sim.stats.sticking_steps, sim.stats.sliding_steps,
                sim.trajectory.measured.object_pose.size(), sim.trajectory.measured.force.size());

    // 2. The estimator, told the measurement noise it will see (the defaults are the paper's
    //    5 mm / 0.5 N). The trajectory carries the shapes, mass and friction the factors need.
    graph::EstimatorConfig config;
    config.measurement.object_trans = plan.noise.object_pose.position.sigma;
    config.measurement.object_rot = plan.noise.object_pose.angle.sigma;
    config.measurement.finger_trans = plan.noise.finger_pose.position.sigma;
    config.measurement.contact = plan.noise.contact_point.position.sigma;
    config.measurement.force = plan.noise.force.position.sigma;
    const graph::EstimationResult result =
        graph::Estimate(sim.trajectory, graph::Model::kQs, graph::Mode::kBatch, config);
    std::printf("QS batch: %zu steps, %d LM iterations, %.3f s, final cost %.2f, covariance: %s\n\n",
                result.states.size(), result.solver.iterations, result.solver.time_s, result.solver.final_cost,
                result.solver.covariance_status.c_str());

    // 3. A few steps: estimate +- 2 sigma (from the marginal covariances) next to the truth.
    std::printf("%6s  %-44s %-26s %-34s %s\n", "t (s)", "object x, y (mm), theta (deg) +- 2 sigma",
                "truth", "force (N) +- 2 sigma", "truth");
    const int stride = std::max<int>(1, static_cast<int>(result.states.size()) / 8);
    for (size_t i = 0; i < result.states.size(); i += stride) {
      const graph::StateEstimate& s = result.states[i];
      const push::SimulationState& truth = TruthAt(sim, s.t);
      std::printf("%6.3f  %6.2f %6.2f %6.2f  +- (%4.2f %4.2f %4.2f)     %6.2f %6.2f %6.2f  ", s.t,
                  1e3 * s.object_pose.x, 1e3 * s.object_pose.y, s.object_pose.theta * 180 / M_PI,
                  s.object_pose_cov ? 1e3 * TwoSigma(*s.object_pose_cov, 0) : NAN,
                  s.object_pose_cov ? 1e3 * TwoSigma(*s.object_pose_cov, 1) : NAN,
                  s.object_pose_cov ? TwoSigma(*s.object_pose_cov, 2) * 180 / M_PI : NAN,
                  1e3 * truth.object_pose.x, 1e3 * truth.object_pose.y, truth.object_pose.theta * 180 / M_PI);
      if (s.force) {  // force variables exist only while finger and object are in contact
        std::printf("(%5.2f %5.2f) +- (%4.2f %4.2f)   (%5.2f %5.2f)\n", s.force->x(), s.force->y(),
                    s.force_cov ? TwoSigma(*s.force_cov, 0) : NAN, s.force_cov ? TwoSigma(*s.force_cov, 1) : NAN,
                    truth.response.force.x(), truth.response.force.y());
      } else {
        std::printf("not in contact\n");
      }
    }

    // 4. Metrics against ground truth: the estimate's RMS error next to the raw measurements'.
    //    NEES (normalized estimation error squared) near its dimension means honest covariances.
    const auto& m = result.metrics;
    auto get = [&m](const char* key) { return m.count(key) ? m.at(key) : NAN; };
    std::printf("\n%-24s %12s %12s\n", "RMS error", "estimate", "measured");
    std::printf("%-24s %12.3f %12.3f\n", "object position (mm)", 1e3 * get("object_position_rms"),
                1e3 * get("measured_object_position_rms"));
    std::printf("%-24s %12.3f %12.3f\n", "object rotation (deg)", get("object_rotation_rms") * 180 / M_PI,
                get("measured_object_rotation_rms") * 180 / M_PI);
    std::printf("%-24s %12.3f %12.3f\n", "finger position (mm)", 1e3 * get("finger_position_rms"),
                1e3 * get("measured_finger_position_rms"));
    std::printf("%-24s %12.3f %12.3f\n", "contact point (mm)", 1e3 * get("contact_rms"),
                1e3 * get("measured_contact_rms"));
    std::printf("%-24s %12.3f %12.3f\n", "force (N)", get("force_rms"), get("measured_force_rms"));
    std::printf("NEES: object pose %.2f (dim 3), force %.2f (dim 2)\n", get("object_pose_nees"), get("force_nees"));

    // This program is also a test: fusing the streams must beat the raw object measurements.
    if (!(get("object_position_rms") < get("measured_object_position_rms"))) {
      std::fprintf(stderr, "estimate_push: the estimate is not better than the measurements\n");
      return 1;
    }
  } catch (const std::exception& e) {  // LimitSurfaceError (plan), GraphError (trajectory/config)
    std::fprintf(stderr, "estimate_push: %s\n", e.what());
    return 1;
  }
  return 0;
}
