#pragma once
// Estimation of a whole pushing trajectory: object pose, finger pose, contact point and (QS,
// baseline) contact force per step, with marginal covariances, from noisy, multi-rate and
// partly missing measurements (Lambert et al. 2019, Sec. III, Fig. 2).
//
//   push::Trajectory traj = io::LoadTrajectoryJson("push.json");
//   graph::EstimatorConfig cfg;                        // or graph::LoadEstimatorConfig(path)
//   if (traj.measurement_sigmas)                       // the data's known noise (simulator, --add-noise)
//     cfg = graph::ApplyMeasurementSigmas(cfg, *traj.measurement_sigmas);
//   graph::EstimationResult r = graph::Estimate(traj, graph::Model::kQs, graph::Mode::kBatch, cfg);
//   for (const graph::StateEstimate& s : r.states) { s.t, s.object_pose, *s.object_pose_cov ... }
//   r.metrics["object_position_rms"]                   // when traj.ground_truth is present
//   r.warnings                                         // e.g. forces left out: nothing fixes their size
//
// Models (Fig. 2): kCp = M + C + V; kSdf = CP + S; kQs = SDF + force variables, force M and the
// non-singular quasi-static factor D; kYu = the Yu-Rodriguez 2018 baseline: M + C +
// cross-multiplied quasi-static factor + zero-velocity (random-walk) priors, no S.
// Steps: the sorted union of all measurement time stamps; a step has a factor for each
// measurement it has, contact variables only while in contact (EstimatorConfig's gating).
// Modes: kBatch solves everything at once (config.solver: Ceres' LM with SPARSE_NORMAL_CHOLESKY
// by default, or ChainSolver, chain_solver.h; covariances by SparseMarginals, marginals.h);
// kIncremental is a fixed-lag smoother (incremental.h).
#include <pushgraph/graph/config.h>
#include <pushgraph/graph/diagnostics.h>
#include <pushgraph/graph/factors.h>
#include <pushgraph/graph/registration.h>
#include <pushgraph/push/trajectory.h>

#include <Eigen/Core>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pushgraph::graph {

enum class Model { kCp, kSdf, kQs, kYu };
enum class Mode { kBatch, kIncremental };

/// "cp", "sdf", "qs", "yu"; throws GraphError naming the bad value.
Model ParseModel(const std::string& name);
std::string ModelName(Model model);
/// "batch", "incremental".
Mode ParseMode(const std::string& name);
std::string ModeName(Mode mode);
bool ModelHasForce(Model model);

/// One contact of a step that has two (a finger wedged in a notch touches both walls), or of a
/// two-finger push (every contact of either finger).
struct ContactEstimate {
  int finger = 0;  ///< whose contact: 0 is Trajectory::finger, 1 the first extra finger
  Vec2 point{0.0, 0.0};
  std::optional<Vec2> force;  ///< this contact's force (QS), world frame
  std::optional<Eigen::Matrix2d> point_cov, force_cov;
};

/// A finger other than finger 0 (two-finger pushes): its pose.
struct FingerPoseEstimate {
  int finger = 1;
  Pose2 pose;
  std::optional<Eigen::Matrix3d> pose_cov;  ///< (x, y, theta)
};

struct StateEstimate {
  double t = 0.0;
  Pose2 object_pose;
  Pose2 finger_pose;
  std::optional<Vec2> contact;  ///< while in contact (the first contact when there are two)
  /// QS and baseline, while in contact: the finger's net force on the object (the sum over its
  /// contacts: what its force sensor measures).
  std::optional<Vec2> force;
  /// Steps with two contacts of finger 0: both, each with its own force and covariances
  /// (`contact` is the first; `force_cov` is then not reported: the sum's covariance needs their
  /// cross-covariance). Two-finger pushes: every contact of either finger at this step (`contact`
  /// and `force` are finger 0's own, absent while it does not touch).
  std::vector<ContactEstimate> contacts;
  /// Two-finger pushes: finger 1's pose (finger_pose is finger 0's).
  std::vector<FingerPoseEstimate> other_fingers;
  std::optional<Eigen::Matrix3d> object_pose_cov, finger_pose_cov;  ///< (x, y, theta)
  std::optional<Eigen::Matrix2d> contact_cov, force_cov;
};

struct SolverStats {
  int iterations = 0;      ///< LM iterations (summed over updates when incremental)
  double time_s = 0.0;     ///< wall time of solving and covariance estimation
  /// Wall time of the whole Estimate call: the input checks, the shape check and registration
  /// (and the placements it compares), the estimate and its self-diagnosis. Under align_shape
  /// "auto" the shape check can take longer than the estimate itself (time_s leaves it out).
  /// 0 in IncrementalEstimator's and OnlineEstimator's results, which are no Estimate call (their
  /// time_s and update_times_s say how long they took).
  double total_time_s = 0.0;
  double final_cost = 0.0; ///< batch: final cost; incremental: cost of the last window
  int updates = 0;         ///< incremental updates (1 for batch)
  double max_update_time_s = 0.0;
  double mean_update_time_s = 0.0;
  std::string covariance_status = "not computed";
  std::string name = "chain";           ///< which solver ran: "ceres" or "chain" (ChainSolver)
  /// Batch: the last stage stopped on a stall (a residual that jumps next to the current point;
  /// the warnings say which), so final_cost is no minimum.
  bool stalled = false;
  /// Batch: the last stage stopped at its iteration limit (max_iterations) before converging.
  bool at_iteration_limit = false;
  std::vector<double> update_times_s;   ///< incremental: each update's wall time, in order
  /// The chain solver's profile of the batch's final stage: wall time (s) in residual and
  /// Jacobian evaluation with the J^T J accumulation and in factorizations and solves, and the
  /// floating-point operations of one factorization and solve (0 with Ceres).
  double evaluation_time_s = 0.0, linear_solve_time_s = 0.0, factor_flops = 0.0;
};

/// What the estimator did about the object's shape frame (EstimatorConfig::align_shape).
struct ShapeAlignment {
  bool checked = false;  ///< the check ran (it needs 8 contact samples with object poses)
  ShapeFitCheck check;   ///< the shape as given against the recording
  bool aligned = false;  ///< the estimate used the transformed shape
  /// Shape file to object frame (geometry::TransformShape); with `aligned`, the one used (batch:
  /// refined in the graph), else what the contacts suggest (when the shape did not fit).
  ShapeTransform transform;
  bool suggested = false;  ///< `transform` was computed (aligned, or suggested for a misfit)
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  ///< of (x, y, theta); theta 0 when unobservable
  bool rotation_observable = true;
  bool refined = false;  ///< refined as a static variable of the factor graph (batch)
  /// The units alone were applied (scale, mirror; the file's own frame): no placement was fitted,
  /// so the transform has no sigma (RESULT.json: null), not a zero one.
  bool units_only = false;
  /// The finger radius (m) the estimate used when it is not the given one: the shape did not
  /// fit, and the shape as given with this finger fitted the whole graph clearly better than any
  /// placement (a wrong probe radius or object size; align_shape "auto" only).
  std::optional<double> finger_radius;
  /// Other placements the whole graph fits within 2 in cost of `transform` (graph-refined,
  /// turned or shifted by more than 3 degrees or 3 mm): one push often cannot tell them apart,
  /// and `sigma` (the curvature at the chosen one) does not say so.
  std::vector<ShapeTransform> ties;
  /// False when the recording leaves the placement open (aligned or suggested): the contacts fit
  /// several placements about as well (a straight stretch of the outline touched), the whole
  /// graph ties (`ties`), or a competing placement's solve stalled, so its cost is no comparison.
  /// `sigma` is then the curvature at the chosen placement only, and `unsettled_by` says why.
  bool settled = true;
  std::string unsettled_by;
  std::vector<std::string> notes;  ///< registration's notes: symmetry, weak directions, ambiguity
};

struct EstimationResult {
  Model model = Model::kQs;
  Mode mode = Mode::kBatch;
  std::vector<StateEstimate> states;
  SolverStats solver;
  /// The limit-surface ratio c used by D (m); estimated when config.estimate_c (QS batch),
  /// with its marginal sigma (c_sigma, when covariances were computed).
  std::optional<double> c, c_sigma;
  bool c_estimated = false;
  /// The table friction mu of the limit-surface load; estimated when config.estimate_mu (QS
  /// batch), with its marginal sigma. Set only when the load factor is used (QS with mass and
  /// mu_surface, and no force stream or limit_surface_load "on" or estimate_mu).
  std::optional<double> mu, mu_sigma;
  bool mu_estimated = false;
  /// An estimated c or mu that ended on its bound ([0.2, 5] times its start): the Gaussian
  /// sigma would be meaningless there, so c_sigma / mu_sigma are left empty.
  bool c_at_bound = false, mu_at_bound = false;
  /// RMS errors against the trajectory's ground truth (empty without it): object_position_rms
  /// (m), object_rotation_rms (rad), finger_position_rms, finger_rotation_rms, contact_rms (m),
  /// force_rms (N); the same of the raw measurements as measured_*; and the mean normalized
  /// estimation error squared object_pose_nees (dimension 3) etc. where covariances exist.
  std::map<std::string, double> metrics;
  /// The scale applied to the finger shape files: 1; 0.001, 0.01 or 0.0254 (millimetres,
  /// centimetres, inches) when a finger's file read as metres would hold the whole push inside it
  /// or reaches over 1 m from its origin, and so read is a tabletop probe the contacts fit
  /// (align_shape auto and on, said in the warnings; "off" refuses such a finger).
  /// RESULT.json parameters.finger_scale, written when not 1.
  double finger_scale = 1.0;
  /// The shift (m, in the finger's frame) applied to finger 0's shape (after finger_scale): zero;
  /// with align_shape auto, when its pose origin lies over 1 mm outside the shape (or a disk's
  /// centre over 1 mm off it) and the contacts (graph::CheckShapeFit) fit the finger centred on
  /// it and not as given, or clearly closer, minus the shape's centroid (said in the warnings).
  /// RESULT.json parameters.finger_transform [x, y, 0], written when not zero.
  geometry::Vec2 finger_shift = geometry::Vec2::Zero();
  /// The delay (s) subtracted from the object_pose stream's time stamps (config.object_delay);
  /// 0: as recorded. RESULT.json parameters.object_delay, written when not 0.
  double object_delay = 0.0;
  /// The shape check and alignment (RESULT.json parameters.shape_transform and "shape").
  std::optional<ShapeAlignment> shape_alignment;
  /// Self-diagnosis (config.diagnostics; RESULT.json "diagnostics"); its causes are also in
  /// the warnings.
  std::optional<Diagnostics> diagnostics;
  /// What the caller should know about the result, one sentence each (RESULT.json "warnings",
  /// printed by the tool): e.g. forces left out because nothing in the graph fixes their size.
  std::vector<std::string> warnings;
};

/// Runs the estimator. Throws GraphError for unusable input (no object or finger
/// measurements, non-finite samples, missing shapes, estimate_mu without mass, mu_surface or a
/// force stream). QS and the baseline report forces only when something fixes their size: a
/// force stream, or (QS) the limit-surface load from the object's mass and mu_surface; otherwise
/// D fixes only their direction, the states carry no force and `warnings` says why.
EstimationResult Estimate(const push::Trajectory& trajectory, Model model, Mode mode,
                          const EstimatorConfig& config = {});

/// The metrics of EstimationResult for given states.
std::map<std::string, double> ComputeMetrics(const push::Trajectory& trajectory,
                                             const std::vector<StateEstimate>& states);

/// The limit-surface ratio c used by D for this trajectory and config (config.c if set, else
/// the uniform-pressure limit surface of the object's shape; times config.c_scale), and the
/// centre of pressure in the object frame.
QuasiStaticGeometry QuasiStaticGeometryFor(const push::Trajectory& trajectory,
                                           const EstimatorConfig& config);

}  // namespace pushgraph::graph
