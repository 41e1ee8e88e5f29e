#pragma once
// Configuration of the pushing estimator: factor sigmas, robust losses, solver and
// incremental settings. Every field has a documented default (docs/estimation.md); a JSON file
// overrides any subset of them by name:
//
//   {"object_pose_sigma_trans": 0.005, "quasi_static_sigma": 0.1,
//    "losses": {"contact": {"type": "huber", "scale": 1.345}, "force": {"type": "cauchy", "scale": 1}},
//    "incremental_window": 20}
//
//   graph::EstimatorConfig cfg = graph::LoadEstimatorConfig("config.json");
//
// Unknown keys, wrong types, non-positive sigmas and NaN are errors (GraphError naming the key).
#include <string>

namespace pushgraph::graph {

/// Robust loss on a whitened residual (Ceres HuberLoss / CauchyLoss with parameter `scale`).
struct LossConfig {
  enum class Type { kNone, kHuber, kCauchy };
  Type type = Type::kNone;
  double scale = 1.0;
};

struct EstimatorConfig {
  // M: measurement sigmas (the paper's Sec. IV noise is 0.5 cm and 0.5 N).
  double object_pose_sigma_trans = 0.005;  ///< m
  double object_pose_sigma_rot = 0.05;     ///< rad
  double finger_pose_sigma_trans = 0.005;  ///< m
  double finger_pose_sigma_rot = 0.05;     ///< rad
  double contact_sigma = 0.005;            ///< m
  double force_sigma = 0.5;                ///< N
  // C and S: geometric consistency (stiff).
  double contact_object_sigma = 5e-4;  ///< m, contact point on the object boundary
  double contact_finger_sigma = 5e-4;  ///< m, contact point on the finger boundary
  double touching_sigma = 5e-4;        ///< m, signed separation of finger and object
  double intersection_sigma = 5e-4;    ///< m, S
  // V: white-noise-acceleration spectral densities; sigma = q sqrt((dt1 + dt2) / 2).
  double accel_trans = 0.5;  ///< m/s^2/sqrt(Hz)
  double accel_rot = 5.0;    ///< rad/s^2/sqrt(Hz)
  // D: the normalized cross-product quasi-static factor (dimensionless, about sin(angle)).
  // Sigmas of D and of the limit-surface load are for a 10 ms step; a step of dt gets
  // sigma sqrt(0.01 / dt), so the information per second does not depend on the input rate.
  double quasi_static_sigma = 0.1;
  double eps_velocity = 1e-3;  ///< m/s, regularizes |V'| in D
  double eps_force = 0.05;     ///< N, regularizes |g'| in D
  double c = 0.0;              ///< m; 0: from the object's limit surface (uniform pressure)
  double c_scale = 1.0;        ///< multiplies c (published fits are about 1.11 on real data)
  double limit_surface_sigma = 0.1;  ///< relative, |load| = f_max while sliding (0.875-1.03 exact/ellipsoid)
  double force_prior_sigma = 100.0;
  double force_random_walk = 10.0;  ///< N/sqrt(s), force continuity between consecutive steps  ///< N, weak prior f ~ N(0, s^2) keeping |f| observable
  // The Yu-Rodriguez 2018 baseline.
  double yu_quasi_static_sigma = 2e-4;  ///< m^2 N / s, cross-multiplied residual
  double random_walk_trans = 0.05;      ///< m/sqrt(s), zero-velocity prior
  double random_walk_rot = 0.5;         ///< rad/sqrt(s)
  // Contact gating: a step is in contact when a contact measurement (or, without a contact
  // stream, a force of at least contact_force_threshold) lies within contact_max_gap of it;
  // without either stream every step is in contact (the paper's constant-contact assumption).
  double contact_max_gap = 0.05;          ///< s
  double contact_force_threshold = 0.05;  ///< N
  // Robust losses on measurement factors.
  LossConfig object_pose_loss, finger_pose_loss, contact_loss, force_loss;
  // Solver.
  int max_iterations = 100;
  double function_tolerance = 1e-6;
  bool covariance = true;  ///< marginal covariances of every state
  // Incremental (fixed-lag smoothing).
  int incremental_window = 20;        ///< object measurement periods kept in the window
  int incremental_update_every = 5;   ///< object measurements between updates (k)
  int incremental_max_iterations = 50;
};

/// Parses a JSON object overriding fields of the defaults; `source` names the input in errors.
EstimatorConfig ParseEstimatorConfig(const std::string& json_text,
                                     const std::string& source = "<config>");
EstimatorConfig LoadEstimatorConfig(const std::string& path);
/// Checks every field (positive sigmas, finite values, window >= update_every >= 1).
void ValidateConfig(const EstimatorConfig& config);

}  // namespace pushgraph::graph
