#pragma once
// A small deterministic quasi-static push generator for the estimation tests and benchmarks
// (independent of the project's simulator): a disk finger sticks to a point of a square's edge
// and pushes with a constant world velocity; the object's twist follows the ellipsoidal limit
// surface (Lynch's sticking-contact solution, paper Eq. 3-4), integrated exactly with Exp.
// Streams at their own rates with seeded Gaussian or bimodal noise; ground truth at every
// stream sample.
//
//   PushSpec spec;  spec.contact_offset = 0.02;   // off-centre: the object rotates
//   push::Trajectory t = GeneratePush(spec);
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>
#include <pushgraph/push/noise.h>
#include <pushgraph/push/simulator.h>
#include <pushgraph/push/trajectory.h>

#include <cmath>
#include <random>
#include <string>

namespace pushgraph::graph::testing {

struct PushSpec {
  double side = 0.09;              ///< square object
  double finger_radius = 0.005;    ///< disk finger
  double mass = 0.8, mu = 0.25;
  double contact_offset = 0.0;     ///< along the pushed edge (0: through the centre)
  Eigen::Vector2d push_velocity{0.05, 0.0};  ///< world frame, m/s
  double duration = 2.0;
  double object_rate = 25.0, finger_rate = 250.0, contact_rate = 250.0, force_rate = 250.0;
  double sigma_object_trans = 0.005, sigma_object_rot = 0.05;
  double sigma_finger_trans = 0.005, sigma_finger_rot = 0.05;
  double sigma_contact = 0.005, sigma_force = 0.5;
  bool bimodal_contact_force = false;  ///< the paper's Sec. V non-Gaussian noise
  double occlusion_begin = -1.0, occlusion_end = -1.0;  ///< object stream missing in between
  unsigned seed = 1;
};

struct PushTruth {
  geometry::Pose2 object, finger;
  geometry::Vec2 contact, force;
};

inline double LimitSurfaceC(const PushSpec& s) {
  limit_surface::SupportSpec spec;
  spec.region = geometry::Shape::Box(s.side, s.side);
  spec.mass = s.mass;
  spec.mu = s.mu;
  return limit_surface::Summarize(limit_surface::MakeSupport(spec)).c;
}

/// The true state at time t (closed form: integrated at 10 kHz from t = 0).
class PushModel {
 public:
  explicit PushModel(const PushSpec& s) : s_(s), c_(LimitSurfaceC(s)) {
    f_max_ = s.mu * s.mass * limit_surface::kStandardGravity;
  }
  std::vector<PushTruth> Sample(const std::vector<double>& times) const {
    std::vector<PushTruth> out;
    geometry::Pose2 x{0.0, 0.0, 0.0};
    double t = 0.0;
    const double h = 1e-4;
    const geometry::Vec2 q(-s_.side / 2, s_.contact_offset);  // contact, object frame
    for (double target : times) {
      while (t + h <= target + 1e-12) {
        x = geometry::Compose(x, geometry::Exp(Twist(x, q) * h));
        t += h;
      }
      const geometry::Pose2 xt = geometry::Compose(x, geometry::Exp(Twist(x, q) * (target - t)));
      PushTruth tr;
      tr.object = xt;
      tr.contact = geometry::Act(xt, q);
      const geometry::Vec2 centre = geometry::Act(xt, q + geometry::Vec2(-s_.finger_radius, 0.0));
      tr.finger = {centre.x(), centre.y(), 0.0};
      const Eigen::Vector3d V = Twist(xt, q);
      const double lambda = f_max_ / std::sqrt(V.x() * V.x() + V.y() * V.y() + c_ * c_ * V.z() * V.z());
      tr.force = xt.rotation() * geometry::Vec2(lambda * V.x(), lambda * V.y());
      out.push_back(tr);
    }
    return out;
  }
  double c() const { return c_; }

 private:
  // Sticking contact q, pusher velocity u (object frame): the ellipsoid's twist (Lynch 1992).
  Eigen::Vector3d Twist(const geometry::Pose2& x, const geometry::Vec2& q) const {
    const geometry::Vec2 u = x.rotation().transpose() * s_.push_velocity;
    const double c2 = c_ * c_, d = c2 + q.squaredNorm();
    const double vx = ((c2 + q.x() * q.x()) * u.x() + q.x() * q.y() * u.y()) / d;
    const double vy = (q.x() * q.y() * u.x() + (c2 + q.y() * q.y()) * u.y()) / d;
    return {vx, vy, (q.x() * vy - q.y() * vx) / c2};
  }
  PushSpec s_;
  double c_, f_max_;
};

inline push::Trajectory GeneratePush(const PushSpec& s) {
  push::Trajectory traj;
  traj.object.shape = geometry::Shape::Box(s.side, s.side);
  traj.object.mass = s.mass;
  traj.object.mu_surface = s.mu;
  traj.finger.shape = geometry::Shape::Disk(s.finger_radius);
  traj.finger.mu_contact = 0.3;
  PushModel model(s);
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  // Bimodal: an equal mixture of two triangular distributions centred at +-1.5 sigma.
  auto bimodal = [&](double sigma) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double tri = (u(rng) + u(rng) - 1.0) * sigma;  // triangular on [-sigma, sigma]
    return (u(rng) < 0.5 ? -1.5 : 1.5) * sigma + tri;
  };
  auto clock = [&](double rate) {
    std::vector<double> t;
    for (int i = 0; i <= static_cast<int>(std::floor(s.duration * rate + 1e-9)); ++i) t.push_back(i / rate);
    return t;
  };
  push::Streams gt;
  const auto to = clock(s.object_rate), tf = clock(s.finger_rate), tc = clock(s.contact_rate), tfo = clock(s.force_rate);
  const auto xo = model.Sample(to), xf = model.Sample(tf), xc = model.Sample(tc), xfo = model.Sample(tfo);
  for (std::size_t i = 0; i < to.size(); ++i) {
    gt.object_pose.push_back({to[i], xo[i].object});
    if (to[i] > s.occlusion_begin && to[i] < s.occlusion_end) continue;
    const geometry::Pose2& p = xo[i].object;
    traj.measured.object_pose.push_back(
        {to[i], {p.x + s.sigma_object_trans * n01(rng), p.y + s.sigma_object_trans * n01(rng),
                 p.theta + s.sigma_object_rot * n01(rng)}});
  }
  for (std::size_t i = 0; i < tf.size(); ++i) {
    gt.finger_pose.push_back({tf[i], xf[i].finger});
    const geometry::Pose2& p = xf[i].finger;
    traj.measured.finger_pose.push_back(
        {tf[i], {p.x + s.sigma_finger_trans * n01(rng), p.y + s.sigma_finger_trans * n01(rng),
                 p.theta + s.sigma_finger_rot * n01(rng)}});
  }
  for (std::size_t i = 0; i < tc.size(); ++i) {
    gt.contact_point.push_back({tc[i], xc[i].contact});
    geometry::Vec2 noise = s.bimodal_contact_force ? geometry::Vec2(bimodal(s.sigma_contact), bimodal(s.sigma_contact))
                                                   : geometry::Vec2(s.sigma_contact * n01(rng), s.sigma_contact * n01(rng));
    traj.measured.contact_point.push_back({tc[i], xc[i].contact + noise});
  }
  for (std::size_t i = 0; i < tfo.size(); ++i) {
    gt.force.push_back({tfo[i], xfo[i].force});
    geometry::Vec2 noise = s.bimodal_contact_force ? geometry::Vec2(bimodal(s.sigma_force), bimodal(s.sigma_force))
                                                   : geometry::Vec2(s.sigma_force * n01(rng), s.sigma_force * n01(rng));
    traj.measured.force.push_back({tfo[i], xfo[i].force + noise});
  }
  traj.ground_truth = gt;
  return traj;
}

/// The simulator's straight push of the project's notched block (0.5 kg, mu 0.3) by a 5 mm disk
/// (mu 0.4), 5 cm at 5 cm/s from 5 mm away along `angle`, 1 cm off the centroid, with the
/// simulator's Gaussian noise; `duration` 0 ends it with the path (longer: the finger rests).
inline push::PushPlan NotchedBlockPushPlan(double angle, unsigned seed, double duration = 0.0) {
  push::PushPlan plan;
  plan.object.shape = geometry::LoadShapeJson(std::string(PUSHGRAPH_SOURCE_DIR) + "/data/shapes/notched_block.json");
  plan.finger.shape = geometry::Shape::Disk(0.005);
  plan.object.mass = 0.5;
  plan.object.mu_surface = 0.3;
  plan.finger.mu_contact = 0.4;
  plan.waypoints = push::StraightPushPath(plan, angle, 0.01, 0.005, 0.05);
  plan.duration = duration;
  plan.noise = push::DefaultNoise(push::NoiseKind::kGaussian);
  plan.seed = seed;
  return plan;
}

}  // namespace pushgraph::graph::testing
