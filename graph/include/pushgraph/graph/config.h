#pragma once
// Configuration of the pushing estimator: factor sigmas, robust losses, solver and
// incremental settings. Every field has a documented default (docs/estimation.md); a JSON file
// overrides any subset of them by name:
//
//   {"object_pose_sigma_trans": 0.005, "quasi_static_sigma": 0.1,
//    "losses": {"contact": {"type": "huber", "scale": 1.345}, "force": {"type": "cauchy", "scale": 1}},
//    "incremental_window": 10}
//
//   graph::EstimatorConfig cfg = graph::LoadEstimatorConfig("config.json");
//
// Unknown keys, wrong types, non-positive sigmas and NaN are errors (GraphError naming the key).
#include <pushgraph/push/trajectory.h>

#include <algorithm>
#include <optional>
#include <string>

namespace pushgraph::graph {

/// Robust loss on a whitened residual (Ceres HuberLoss / CauchyLoss with parameter `scale`).
struct LossConfig {
  enum class Type { kNone, kHuber, kCauchy };
  Type type = Type::kNone;
  double scale = 1.0;
};

struct EstimatorConfig {
  /// M: measurement sigmas, the push module's MeasurementSigmas (JSON keys
  /// object_pose_sigma_trans, object_pose_sigma_rot, finger_pose_sigma_trans,
  /// finger_pose_sigma_rot, contact_sigma, force_sigma). Defaults: the paper's Sec. IV noise,
  /// 0.5 cm and 0.5 N, with 0.05 rad for orientations.
  push::MeasurementSigmas measurement{0.005, 0.05, 0.005, 0.05, 0.005, 0.5};
  // C and S: geometric consistency (stiff).
  double contact_object_sigma = 5e-4;  ///< m, contact point on the object boundary
  double contact_finger_sigma = 5e-4;  ///< m, contact point on the finger (witness or boundary)
  /// How C ties p to the finger: kWitness, p = the midpoint of the exact shape-pair witnesses
  /// (well-posed, the default); kBoundary, p on the finger's boundary (the paper's literal
  /// C(p, e); ill-conditioned near tangency, see ContactWitnessFactor). JSON "contact_finger":
  /// "witness" | "boundary".
  enum class ContactFinger { kWitness, kBoundary };
  ContactFinger contact_finger = ContactFinger::kWitness;
  double touching_sigma = 5e-4;        ///< m, signed separation of finger and object
  double intersection_sigma = 5e-4;    ///< m, S
  /// Polygonal (non-disk) fingers: the exact C-obstacle (a CGAL Minkowski sum, 0.5 to 18 ms) is
  /// cached per relative angle rounded to this resolution (rad; 0: exact angles, one obstacle per
  /// distinct angle, which LM produces at every evaluation: minutes per push). The rounding moves
  /// a finger point by at most resolution x finger size (2e-3 x 5 mm = 10 um).
  double finger_angle_resolution = 2e-3;
  // V: white-noise-acceleration spectral densities; sigma = q sqrt((dt1 + dt2) / 2).
  double accel_trans = 0.5;  ///< m/s^2/sqrt(Hz)
  double accel_rot = 5.0;    ///< rad/s^2/sqrt(Hz)
  // D: the normalized cross-product quasi-static factor (dimensionless, about sin(angle)).
  // Sigmas of D and of the limit-surface load are for a 10 ms step; a step of dt gets
  // sigma sqrt(0.01 / dt), so the information per second does not depend on the input rate.
  // 0.3 (about 17 degrees) covers the ellipsoid's error against the exact limit surface (mean 5,
  // max 10-20 degrees, docs/limit_surface.md) and per-step velocity noise; 0.1 made the
  // covariances overconfident (object-pose NEES 9-27 for dimension 3 on simulated pushes).
  double quasi_static_sigma = 0.3;
  double eps_velocity = 1e-3;  ///< m/s, regularizes |V'| in D
  double eps_force = 0.05;     ///< N, regularizes |g'| in D; at most f_max / 20 when m and mu are known
  double c = 0.0;              ///< m; 0: from the object's limit surface (uniform pressure)
  double c_scale = 1.0;        ///< multiplies c (published fits are about 1.11 on real data)
  /// Estimate c jointly with the trajectory (QS, batch): one shared variable, started at the
  /// c above, with a Gaussian prior of relative sigma c_prior_sigma around it and bounded to
  /// [0.2, 5] times it. The estimate and its sigma are in EstimationResult::c.
  bool estimate_c = false;
  double c_prior_sigma = 0.3;  ///< relative
  /// Estimate the table friction mu jointly (QS, batch): one shared variable in the
  /// limit-surface load factor (|g'| = mu m g while sliding; the factor is then on whatever
  /// limit_surface_load says), started at the trajectory's mu_surface, with a Gaussian prior of
  /// relative sigma mu_prior_sigma and bounds [0.2, 5] times it. Needs the object's mass and
  /// mu_surface, and a force stream: mu is observed through |f| while the object slides, and
  /// without force measurements scaling all forces with mu changes nothing, so it is refused.
  /// estimate_c and estimate_mu: the other models have no such variable (ignored, reported as
  /// not estimated); the incremental mode refuses them (it keeps c and mu fixed).
  bool estimate_mu = false;
  double mu_prior_sigma = 0.3;  ///< relative
  /// When the limit-surface load factor is used: kAuto (the default) only at steps no force
  /// sample covers (no force stream, or one that stops or pauses), where it is the sole
  /// information on the force magnitude; with force measurements
  /// it adds little and its rest/sliding gate (|V'| against eps_velocity) slows convergence
  /// 2-4x. JSON "limit_surface_load": "auto" | "on" | "off".
  enum class LimitSurfaceLoad { kAuto, kOn, kOff };
  LimitSurfaceLoad limit_surface_load = LimitSurfaceLoad::kAuto;
  double limit_surface_sigma = 0.1;  ///< relative, |load| = f_max while sliding (0.875-1.03 exact/ellipsoid)
  double force_prior_sigma = 100.0;  ///< N, weak prior f ~ N(0, s^2) keeping |f| observable
  /// N/sqrt(s): force continuity between consecutive steps (a random walk). Under the paper's
  /// 0.5 N noise, force RMS / NEES: simulated pushes 0.24 / 1.2 (3), 0.28 / 1.1 (5), 0.37 / 1.1
  /// (10); an MIT ellip1 recording, whose real forces vary faster, 0.56 / 10.9 (3), 0.40 / 2.8
  /// (5), 0.38 / 1.1 (10). 5 is the compromise.
  double force_random_walk = 5.0;
  // The Yu-Rodriguez 2018 baseline.
  double yu_quasi_static_sigma = 2e-4;  ///< m^2 N / s, cross-multiplied residual
  double random_walk_trans = 0.05;      ///< m/sqrt(s), zero-velocity prior
  double random_walk_rot = 0.5;         ///< rad/sqrt(s)
  // Contact gating: a step is in contact when a contact measurement (or, without a contact
  // stream, a force of at least contact_force_threshold) lies within contact_max_gap of it; a
  // finger whose force stream never shows a contact above its noise (the median of +-20 ms of
  // samples at least max(contact_force_threshold, 5 force sigmas / sqrt(their count))) never
  // touches (in the graph and the registration), unless the object is seen to move, and steps
  // before its first or after its last such contact (0.1 s to spare) are out of contact;
  // without either stream every step is in contact (the paper's constant-contact assumption).
  double contact_max_gap = 0.05;          ///< s
  double contact_force_threshold = 0.05;  ///< N
  // Without a contact stream, a step in contact has two contacts (a finger wedged between two
  // walls) when, at the current estimate, the finger is within this distance of two object
  // edges that face each other (GraphBuilder::DetectSecondContacts). 0 turns it off.
  double second_contact_tolerance = 0.001;  ///< m
  // Robust losses on measurement factors.
  LossConfig object_pose_loss, finger_pose_loss, contact_loss, force_loss;
  // Solver.
  /// kChain (the default): ChainSolver (chain_solver.h), Levenberg-Marquardt on the
  /// block-banded normal equations with its symbolic factorization reused by every iteration and
  /// by the covariances; kCeres: Ceres' LM with SPARSE_NORMAL_CHOLESKY, the reference and the
  /// benchmarks' peer. Both reach the same minimum from the same start (tested); the chain solver
  /// takes less time per iteration, and on docs/results.md's set its rows are within 2 % (object
  /// RMS) and 10 % (QS NEES) of Ceres' (docs/estimation.md, Solvers). JSON "solver": "chain" | "ceres".
  enum class Solver { kChain, kCeres };
  Solver solver = Solver::kChain;
  /// Iteration limit of the batch's final LM stage (the staged start has its own). QS on real
  /// recordings can need more than 100: 4 of docs/results.md's 40 trajectories stopped at 100
  /// (rect1 QS batch object RMS 1.54 mm there, 1.42 mm converged); at 300 none does.
  int max_iterations = 300;
  double function_tolerance = 1e-6;
  bool covariance = true;  ///< marginal covariances of every state
  /// Self-diagnosis of the estimate (diagnostics.h): rebuilds the graph at the estimate and
  /// factorizes it once more for the expected chi-squares (about 10% of a QS batch solve).
  bool diagnostics = true;
  /// How they are computed: kSelectedInversion (SparseMarginals: sparse Cholesky of J^T J and
  /// Takahashi's recursion, linear in the trajectory length; the default, falling back to
  /// ceres::Covariance when J^T J is too ill-conditioned) or kCeres (ceres::Covariance with
  /// SPARSE_QR, quadratic in the length: 4 to 5 s for 1000 QS steps; the reference).
  /// JSON "covariance_method": "selected_inversion" | "ceres".
  enum class CovarianceMethod { kSelectedInversion, kCeres };
  CovarianceMethod covariance_method = CovarianceMethod::kSelectedInversion;
  // Shape registration (registration.h): the object's shape file against the recording's frame.
  /// kAuto (the default): check the shape as given against the contacts (graph::CheckShapeFit);
  /// when it does not fit, align it (graph::RegisterShape, then the shape frame refined as a
  /// static variable of the batch graph) and say so in the warnings. kOn: always align. kOff:
  /// never (the check still warns). JSON "align_shape": "auto" | "on" | "off".
  enum class AlignShape { kAuto, kOn, kOff };
  AlignShape align_shape = AlignShape::kAuto;
  /// The object tracker's latency (s): its time stamps minus the clock of the finger, contact
  /// and force streams, subtracted from every object_pose stamp before anything else (Estimate,
  /// IncrementalEstimator, OnlineEstimator::AddObjectPose), and from the ground truth's object
  /// poses where they carry the measured stream's own stamps (a recording's, late like it). A
  /// camera's 0.1 to 0.3 s is typical; it is not estimated: on a straight push a late tracker and
  /// a shape file shifted along the push fit the contacts alike (docs/estimation.md, Shape
  /// registration). Within +-10 s; JSON "object_delay" (s); --object-delay.
  double object_delay = 0.0;
  /// Also estimate a continuous scale factor (disk fingers) when aligning; the units (m, cm, mm,
  /// inch) and a mirrored file are always detected.
  bool align_scale = false;
  /// A finger whose outline is a regular polygon of 20 or more corners (a tessellated cylinder,
  /// geometry::TessellatedDisk: the MIT tip.obj's footprint is a 32-gon) is estimated as the disk
  /// it approximates, and a warning says so. As a 32-gon the probe solved 6 to 13 times slower,
  /// and the fixed-lag smoother drifted from the tracker on a slow real push (an object 11.5 mm
  /// RMS and 54 mm at worst from a 0.1 mm tracker online, 0.44 mm as a disk). false keeps the polygon.
  bool tessellated_finger_as_disk = true;
  // Incremental (fixed-lag smoothing).
  /// Object measurement periods kept in the window after an update (>= incremental_update_every
  /// when set). 0: unset, which means the larger of 5 and incremental_update_every: the window
  /// then holds the last update's samples, and an update solves them with the new ones. 7 until
  /// 2026-11-28 (20 until 2026-11-26): the final smoothing pass (incremental_smoothing) brings the
  /// older states to the batch estimate, so the shorter window costs little accuracy on
  /// docs/results.md's set (object RMS within -3.9 %..+2.1 % of the 7-period window's; most NEES
  /// nearer their dimension, sim-multi's object-pose NEES up to 10 % higher) and an update every
  /// 5 samples takes 10 % fewer instructions. Updates further apart than the window (a late
  /// sample, an occlusion) marginalize their oldest new steps after one window solve. With
  /// incremental_smoothing off, states keep the estimate of the window they left: a longer
  /// window is then better.
  int incremental_window = 0;
  /// The window in object periods that incremental_window means.
  int IncrementalWindowPeriods() const {
    return incremental_window > 0 ? incremental_window : std::max(5, incremental_update_every);
  }
  int incremental_update_every = 5;   ///< object measurements between updates (k)
  /// Estimator steps between updates (1: an update at every step, the sensor rate); when set
  /// (>= 1) it takes precedence over incremental_update_every. 0: unset.
  int incremental_update_every_steps = 0;
  /// Estimator steps kept in the window (>= 3); when set it takes precedence over
  /// incremental_window. 0: unset, which means incremental_window object periods, or 15 steps
  /// (60 ms at 250 Hz; 10 k steps when k = incremental_update_every_steps is 2 or more) when
  /// incremental_update_every_steps is set: an update at the sensor rate
  /// re-solves a short window, and the final smoothing pass (incremental_smoothing) brings the
  /// older states to the batch estimate's accuracy.
  int incremental_window_steps = 0;
  /// Iteration limit of the new steps' staging (but the new QS steps' kinematic stage after the
  /// first update: 2) and of every window solve (the first update's,
  /// Finish's re-solve of a last window that stopped at a limit, and every update's unless
  /// incremental_window_iterations applies).
  int incremental_max_iterations = 50;
  /// A hard cap on the Levenberg-Marquardt iterations of each update's window solve after the
  /// first (>= 1, in every mode when set); Finish re-solves the last window when its solve stopped
  /// at the cap. 0: unset, which means a soft limit of 3 where a step spends ten or more updates
  /// in the window (incremental_update_every_steps set with the default window): from the third
  /// iteration on, the solve ends at a step that changes the cost by less than 3e-4 of it
  /// (ChainSolverOptions::soft_iteration_limit), a bounded relinearization per update as
  /// iSAM2's, which goes on where a window is still far from its minimum; every k object samples
  /// (incremental_update_every_steps unset) the same limit at 3e-5, since a step spends only one
  /// or two updates in the window and leaves with the linearization point it had (3e-4 there
  /// cost accuracy, docs/estimation.md); and incremental_max_iterations otherwise. A hard cap of
  /// 3 at the sensor rate, the default until 2026-11-28, made slow real pushes diverge.
  int incremental_window_iterations = 0;
  /// The final result of the incremental mode (Finish()): true (the default) smooths the whole
  /// trajectory backwards through the Gaussian conditionals its steps left when they were
  /// marginalized (a Rauch-Tung-Striebel pass on the chain, as iSAM2's back-substitution without
  /// relinearizing the old part): every state then uses all the measurements, before and after it,
  /// with its smoothed marginal covariance. false: every state as it was when it left the window
  /// (what a robot knew a window after the fact). The updates' own estimates (LatestState) are
  /// the same either way.
  bool incremental_smoothing = true;
};

/// Parses a JSON object overriding fields of `base` (the defaults unless given); `source` names
/// the input in errors.
EstimatorConfig ParseEstimatorConfig(const std::string& json_text,
                                     const std::string& source = "<config>",
                                     const EstimatorConfig& base = {});
EstimatorConfig LoadEstimatorConfig(const std::string& path, const EstimatorConfig& base = {});

/// `config` with its measurement sigmas (M factors) set to the known noise of the data
/// (push::Trajectory::measurement_sigmas), so covariances are consistent. Zero
/// (noise-free) sigmas are floored at 1e-4 m, 1e-3 rad and 1e-3 N: an exact measurement would
/// make the problem infinitely stiff.
///
///   cfg = graph::ApplyMeasurementSigmas(cfg, *traj.measurement_sigmas);
EstimatorConfig ApplyMeasurementSigmas(EstimatorConfig config,
                                       const push::MeasurementSigmas& sigmas);
/// Checks every field (positive sigmas, finite values, window >= update_every >= 1).
void ValidateConfig(const EstimatorConfig& config);

}  // namespace pushgraph::graph
