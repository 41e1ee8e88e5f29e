#pragma once
// Internal: steps, variables and factor assembly shared by the batch and incremental solvers.
#include <pushgraph/graph/chain_solver.h>
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/incremental.h>

#include "solver_log.h"

#include <ceres/ceres.h>

#include <cmath>
#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace pushgraph::graph::internal {

/// Per-step parameter blocks in chunks that never move (Ceres keeps pointers to them). One
/// chunk holds a batch's (or replay's) steps, so their addresses rise with the step index as in
/// a vector: Ceres orders parameter blocks by address in places (ParameterBlockOrdering's sets),
/// and heap-dependent orders would change last bits between runs. Online runs grow by chunks of
/// 4096 steps; addresses rise within a chunk only.
template <class T>
class StableArray {
 public:
  std::size_t size() const { return size_; }
  T& operator[](std::size_t i) { return chunks_[Chunk(i)][i - starts_[Chunk(i)]]; }
  const T& operator[](std::size_t i) const { return chunks_[Chunk(i)][i - starts_[Chunk(i)]]; }
  void resize(std::size_t n) {
    if (n <= capacity_) { size_ = std::max(size_, n); return; }
    const std::size_t count = std::max<std::size_t>(n - capacity_, 4096);
    chunks_.push_back(std::make_unique<T[]>(count));
    starts_.push_back(capacity_);
    capacity_ += count;
    size_ = n;
  }

 private:
  std::size_t Chunk(std::size_t i) const {
    return static_cast<std::size_t>(std::upper_bound(starts_.begin(), starts_.end(), i) - starts_.begin()) - 1;
  }
  std::vector<std::unique_ptr<T[]>> chunks_;
  std::vector<std::size_t> starts_;
  std::size_t size_ = 0, capacity_ = 0;
};

/// One estimation step: a time stamp and the index of the measurement of each stream taken at
/// that time (-1 when the step has none).
struct Step {
  double t = 0.0;
  int object = -1, finger = -1, contact = -1, force = -1;
  bool in_contact = false;
  /// A second contact (a finger wedged in a notch): the contact stream's nearest time has two
  /// rows. `contact2` is this step's second row (-1: none at this time); Initialize pairs the
  /// rows with the contact variables p and p2 by proximity to the previous step's.
  bool two_contacts = false;
  int contact2 = -1;
  /// Fingers 1, 2, ... of a push with several (Trajectory::extra_fingers): each one's rows at
  /// this time, whether it touches, and at two points (as finger 0's contact, contact2 and
  /// two_contacts above).
  struct OtherFinger {
    int finger = -1, contact = -1, force = -1;
    bool in_contact = false;
    bool two_contacts = false;
    int contact2 = -1;
  };
  std::vector<OtherFinger> others;
};

/// Parameter blocks of one step (addresses stay fixed: Ceres keeps pointers to them).
struct StepVars {
  double x[3] = {0, 0, 0};
  double e[3] = {0, 0, 0};
  double p[2] = {0, 0};
  double f[2] = {0, 0};
  double p2[2] = {0, 0};  ///< the second contact (Step::two_contacts, or finger 1's)
  double f2[2] = {0, 0};
  double e2[3] = {0, 0, 0};  ///< finger 1's pose (pushes with several fingers)
};

/// A contact's point and force blocks (GraphBuilder::SecondContactPoint).
struct ContactVars {
  double p[2] = {0, 0};
  double f[2] = {0, 0};
};

/// Parameter blocks of finger 2, 3, ... at one step (GraphBuilder::FingerPose and friends).
struct MoreFingerVars {
  double e[3] = {0, 0, 0};
  double p[2] = {0, 0};
  double f[2] = {0, 0};
};

/// What a residual block is, for the per-type diagnostics (diagnostics.h).
enum class FactorType {
  kObjectPose, kFingerPose, kContactPoint, kForce,                 // M
  kContactOnObject, kContactOnFinger, kTouching, kIntersection,    // C, S
  kConstantVelocity, kZeroVelocity, kForceContinuity, kForcePrior, // motion priors
  kQuasiStatic, kLimitSurfaceLoad,                                 // D
  kPrior,                                                          // c, mu, shape frame, marginal
};
struct TaggedBlock {
  FactorType type;
  ceres::ResidualBlockId id;
};

/// "quasi_static", "constant_velocity", ... (RESULT.json's diagnostics names).
const char* FactorTypeName(FactorType type);

/// What a solve did (either solver).
struct SolveOutcome {
  int iterations = 0;
  double final_cost = 0.0;
  bool converged = false;
  bool stalled = false;  ///< the chain solver's stall (ChainSolverSummary::stalled)
  std::string termination;
  double evaluation_s = 0.0, linear_solve_s = 0.0, factor_flops = 0.0;  ///< chain solver only
  /// The chain solver that ran (its factor serves the covariances); null for Ceres.
  std::unique_ptr<ChainSolver> chain;
};

class GraphBuilder {
 public:
  /// Solves `problem` (built by this builder) with config.solver; `what` names the stage in
  /// logs. Throws GraphError when the solve fails (naming the factor and step when known).
  /// soft_iteration_limit > 0: from that iteration on the solve ends once a step changes the cost
  /// by less than soft_tolerance of it (0: ChainSolverOptions::soft_function_tolerance),
  /// unconverged (ChainSolverOptions::soft_iteration_limit; Ceres: a second solve at that
  /// tolerance after the first soft_iteration_limit - 1 iterations).
  SolveOutcome Solve(ceres::Problem& problem, int max_iterations, double function_tolerance, const char* what,
                     int soft_iteration_limit = 0, double soft_tolerance = 0.0) const;
  /// The fixed-lag smoother's solves (its windows are refined by later updates and the final
  /// smoothing pass) stop on the function tolerance alone, as they did; batch solves also need
  /// the step's model to agree the change is small (ChainSolverOptions::model_confirms_convergence).
  void set_incremental(bool incremental) { incremental_ = incremental; }
  /// Names a residual block this builder added: "quasi_static factor at step 17 (t = 0.068 s)".
  std::string Describe(ceres::ResidualBlockId id) const;
  /// Drops a removed residual block's record (the fixed-lag smoother's marginalization): Ceres
  /// reuses the memory of removed blocks, so a stale record would misname a new block, and the
  /// records of a long online run would grow without bound.
  void ForgetResidualBlock(ceres::ResidualBlockId id) { origin_.erase(id); }
  /// Adds a residual block, records its type when RecordFactorTypes is on, and, for a factor
  /// that places the object's shape (`object_pose_blocks` non-empty) while the shape frame is a
  /// variable, wraps it in ShapeFrameFactor with those blocks composed with F.
  ceres::ResidualBlockId Add(ceres::Problem& problem, FactorType type, ceres::CostFunction* cost,
                             ceres::LossFunction* loss, std::vector<double*> blocks,
                             std::vector<int> object_pose_blocks = {});
  /// Every block Add()s from now on is appended to `tags` (nullptr: stop).
  void RecordFactorTypes(std::vector<TaggedBlock>* tags) { tags_ = tags; }
  /// `querier`: the object-finger querier to share (MakeQuerier of the same trajectory and
  /// config; the estimate and its diagnostics use one); null: a new one.
  GraphBuilder(const push::Trajectory& trajectory, Model model, const EstimatorConfig& config,
               std::shared_ptr<const geometry::ShapePairQuerier> querier = nullptr);
  /// The exact object-finger querier the factors use (its Minkowski obstacles cached per angle).
  static std::shared_ptr<const geometry::ShapePairQuerier> MakeQuerier(const push::Trajectory& trajectory,
                                                                      const EstimatorConfig& config);
  /// The same for `finger` (finger 1 of a two-finger push).
  static std::shared_ptr<const geometry::ShapePairQuerier> MakeQuerier(const push::Trajectory& trajectory,
                                                                      const geometry::Shape& finger,
                                                                      const EstimatorConfig& config);
  /// Online use (OnlineEstimator): `trajectory` starts with empty streams and grows as the
  /// caller appends measurements; steps come from AppendSteps. `streams` says which streams will
  /// arrive (contact gating, and the load factor runs when no force stream will).
  GraphBuilder(const push::Trajectory& trajectory, Model model, const EstimatorConfig& config,
               const OnlineStreams& streams);

  /// Appends a step for every time stamp in (last step, until] of the measurements not yet
  /// used, gating contact on the samples received so far. Returns the number of new steps.
  int AppendSteps(double until);

  const std::vector<Step>& steps() const { return steps_; }
  StableArray<StepVars>& vars() { return vars_; }
  const StableArray<StepVars>& vars() const { return vars_; }
  Model model() const { return model_; }
  bool HasContactVars(int i) const { return steps_[i].in_contact; }
  bool HasForceVars(int i) const { return steps_[i].in_contact && ModelHasForce(model_); }
  /// Whether step i has the blocks p2 (and, with forces, f2): finger 0's second contact when it
  /// is alone, finger 1's contact in a push with several fingers.
  bool HasSecondContact(int i) const {
    return other_fingers_ == 0 ? steps_[i].in_contact && steps_[i].two_contacts : steps_[i].others[0].in_contact;
  }
  bool HasSecondForceVars(int i) const { return HasSecondContact(i) && ModelHasForce(model_); }
  /// The fingers estimated: 1, or every finger of a push with several (the baseline keeps one).
  int num_fingers() const { return 1 + other_fingers_; }
  /// Several fingers: each one's pose is a variable of every step, its contact one point.
  bool several_fingers() const { return other_fingers_ > 0; }
  /// Finger k's pose, contact point and force variables at step i (finger 0: e, p, f; finger 1:
  /// e2, p2, f2; fingers 2, 3, ...: their own blocks), and whether it touches there.
  double* FingerPose(int i, int k) { return k == 0 ? vars_[i].e : k == 1 ? vars_[i].e2 : More(i, k).e; }
  double* FingerContact(int i, int k) { return k == 0 ? vars_[i].p : k == 1 ? vars_[i].p2 : More(i, k).p; }
  double* FingerForce(int i, int k) { return k == 0 ? vars_[i].f : k == 1 ? vars_[i].f2 : More(i, k).f; }
  const double* FingerPose(int i, int k) const { return const_cast<GraphBuilder*>(this)->FingerPose(i, k); }
  const double* FingerContact(int i, int k) const { return const_cast<GraphBuilder*>(this)->FingerContact(i, k); }
  const double* FingerForce(int i, int k) const { return const_cast<GraphBuilder*>(this)->FingerForce(i, k); }
  bool FingerTouches(int i, int k) const { return k == 0 ? steps_[i].in_contact : steps_[i].others[k - 1].in_contact; }
  /// Whether finger k touches at two points at step i, and the second contact's blocks: finger
  /// 0's alone are p2 and f2; with several fingers each finger's are its own.
  bool FingerTwoContacts(int i, int k) const {
    return FingerTouches(i, k) && (k == 0 ? steps_[i].two_contacts : steps_[i].others[k - 1].two_contacts);
  }
  double* SecondContactPoint(int i, int k) { return other_fingers_ == 0 ? vars_[i].p2 : SecondVars(i, k).p; }
  double* SecondContactForce(int i, int k) { return other_fingers_ == 0 ? vars_[i].f2 : SecondVars(i, k).f; }
  const double* SecondContactPoint(int i, int k) const { return const_cast<GraphBuilder*>(this)->SecondContactPoint(i, k); }
  const double* SecondContactForce(int i, int k) const { return const_cast<GraphBuilder*>(this)->SecondContactForce(i, k); }

  /// Initial values of step i from the measurements with time stamps <= limit (interpolated;
  /// the newest held). limit = INFINITY in batch; the update time in incremental mode.
  void Initialize(int i, double limit);
  /// Batch start beyond the object stream's ends (a camera lost before the push ends, or started
  /// late): after Initialize, the object's initial poses in an end gap longer than
  /// max(3 object periods, 0.1 s) follow the translation of a finger in contact (sticking)
  /// instead of holding the nearest measured pose. Returns the number of steps moved.
  int CarryObjectThroughGaps();
  /// Replaces the initial poses (all steps already Initialize()d) by a motion-only smoother's:
  /// pose measurements and the constant-velocity prior alone (nearly linear: 2 to 5 LM
  /// iterations; it is only a starting point, so the batch solver caps it at 10 iterations and a
  /// relative cost change of 1e-3), then re-derives geometric contact points. Interpolated raw poses at 250 Hz
  /// make V's initial cost huge (1e8 on a noisy MIT recording) and cost the full graph tens of
  /// iterations. Returns the iterations used.
  /// Only steps [first, last) are smoothed (last < 0: to the end); the two steps before `first`
  /// enter the V factors as constants (incremental mode: causal, the window's older estimates kept).
  int SmoothInitialMotion(int max_iterations, double function_tolerance, int first = 0, int last = -1);
  /// Parts of a step's factors: kinematic (M of poses and contact, C, S, V, random walk) and
  /// dynamic (force variable, its M and prior, D, the limit-surface load).
  static constexpr int kKinematic = 1, kDynamic = 2, kAll = 3;
  /// Adds the factors whose newest step is i (steps i-2, i-1 must already be in the problem).
  void AddFactors(ceres::Problem& problem, int i, int parts = kAll);
  /// The one staging path of the batch and incremental solvers: steps [first, last) start from
  /// SmoothInitialMotion; with forces (QS, Yu) their kinematic factors (the model's own M, C, S,
  /// V or random walk, touching) are then solved on their own, in a separate problem without the
  /// shape frame, the two steps before `first` held fixed (incremental: only the new steps need
  /// a start); then their full factors go into `problem`. Interpolated measurements are far from
  /// satisfying D's per-step velocity directions: starting D from them costs the full solve tens
  /// of iterations. `kinematic_iterations` caps the kinematic stage (0: max_iterations). Returns
  /// the iterations used.
  int StageSteps(ceres::Problem& problem, int first, int last, int max_iterations, double function_tolerance,
                 const std::string& what, int kinematic_iterations = 0);
  /// The object features the two-contact steps' contact factors were fixed to
  /// (FeatureWitnessFactor), re-derived at the current values: the number of steps whose choice
  /// changed. The batch solve rebuilds its problem and
  /// solves again while this is nonzero (at most 3 times): a feature chosen at the initial values
  /// can be the wrong one (a flat pusher's end near an object corner), and a fixed one, unlike the
  /// nearest pair, cannot move on.
  int FeatureChoicesChanged() const;
  /// Without a contact stream (the geometry, not the sensor, says how many contacts a step has):
  /// makes each in-contact step of [first, last) a two-contact step when, at the current values,
  /// finger 0 is within config.second_contact_tolerance of two object edges facing each other
  /// (a wedge), with p and p2 on those edges and the force split between them, and a one-contact
  /// step otherwise. Returns the number of steps whose count changed. Not for the baseline or
  /// two-finger pushes.
  int DetectSecondContacts(int first, int last);
  /// Forgets which shared priors (c, mu, shape frame) are in a problem: before building a new one.
  void StartNewProblem() { c_in_problem_ = mu_in_problem_ = frame_in_problem_ = false; }
  /// Parameter blocks of step i present in the problem.
  std::vector<double*> Blocks(int i);
  /// Whether step i has the limit-surface load factor: always when use_load_factor_, and under
  /// limit_surface_load "auto" at steps no force sample covers (beyond contact_max_gap and 1.5
  /// force periods).
  bool LoadFactorAt(int i) const;
  /// The finger (the object, without a finger stream) measured at rest around step i
  /// (PoseStreamAtRest): the object cannot slide there.
  bool MeasuredAtRest(int i) const;
  /// Makes c a shared variable of every D factor (QS only; the batch solver calls this when
  /// config.estimate_c). c_block() is then non-null once a D factor was added.
  void EnableCEstimation();
  double* c_block() { return c_in_problem_ ? c_var_ : nullptr; }
  double c() const { return estimate_c_ ? c_var_[0] : qs_.c; }
  /// Makes the table friction mu a variable of the limit-surface load factor (QS only,
  /// config.estimate_mu; turns that factor on). Throws GraphError without mass or mu_surface.
  void EnableMuEstimation();
  double* mu_block() { return mu_in_problem_ ? mu_var_ : nullptr; }
  /// mu of the load factor: the estimate, or the trajectory's mu_surface (0 when unknown).
  double mu() const { return estimate_mu_ ? mu_var_[0] : mu_surface_; }
  bool uses_load_factor() const { return use_load_factor_; }
  /// Whether anything fixes the forces' size: a force stream or the limit-surface load. Without
  /// either D fixes only their direction and the weak prior pulls them to zero.
  bool ForceScaleObservable() const {
    return !ModelHasForce(model_) || streams_.force || (model_ == Model::kQs && use_load_factor_);
  }
  /// Drops the forces of `result` (and says why in its warnings) when !ForceScaleObservable();
  /// warns when the baseline left second contacts out.
  void DropUnobservableForces(EstimationResult& result) const;
  /// Whether an estimated c / mu sits on a bound of AddSharedParameterPrior's [0.2, 5] x start.
  bool c_at_bound() const { return estimate_c_ && AtBound(c_var_[0], qs_.c); }
  bool mu_at_bound() const { return estimate_mu_ && AtBound(mu_var_[0], mu_surface_); }
  static bool AtBound(double value, double start) {
    return std::abs(value - 0.2 * start) <= 1e-6 * start || std::abs(value - 5.0 * start) <= 1e-6 * start;
  }
  double c_initial() const { return qs_.c; }
  /// Makes the shape frame F (shape_frame.h) a static variable of every factor that places the
  /// object's shape, with ShapeFramePrior(centroid, sigma_centroid, sigma_theta); `rotation`
  /// false keeps F's angle at 0 (a circular outline: unobservable). frame_block() is then
  /// non-null once such a factor was added.
  void EnableShapeFrame(const Vec2& centroid, double sigma_centroid, double sigma_theta, bool rotation);
  double* frame_block() { return frame_in_problem_ ? frame_ : nullptr; }
  Pose2 frame() const { return {frame_[0], frame_[1], frame_[2]}; }
  /// Sets variables to an estimate (diagnostics rebuild the graph there): step i's blocks from
  /// `state` (a missing contact point from the object's closest boundary point, a missing force
  /// 0), the shared c and mu (when estimated), the shape frame.
  void SetState(int i, const StateEstimate& state);
  void SetSharedParameters(std::optional<double> c, std::optional<double> mu);
  void SetFrame(const Pose2& frame) { frame_[0] = frame.x; frame_[1] = frame.y; frame_[2] = frame.theta; }
  const geometry::ShapePairQuerier& querier() const { return *querier_; }
  /// Object and finger k (k < num_fingers(); finger 0: querier()).
  const geometry::ShapePairQuerier& finger_querier(int k) const { return k == 0 ? *querier_ : *other_queriers_[k - 1]; }
  /// Finger k's shape and its streams (finger 0: the trajectory's own).
  const geometry::Shape& FingerShape(int k) const {
    return k == 0 ? traj_.finger.shape : traj_.extra_fingers[k - 1].finger.shape;
  }
  const std::vector<push::PoseSample>& FingerPoseRows(int k) const {
    return k == 0 ? traj_.measured.finger_pose : traj_.extra_fingers[k - 1].measured.finger_pose;
  }
  const std::vector<push::PointSample>& ContactRows(int k) const {
    return k == 0 ? traj_.measured.contact_point : traj_.extra_fingers[k - 1].measured.contact_point;
  }
  const std::vector<push::ForceSample>& ForceRows(int k) const {
    return k == 0 ? traj_.measured.force : traj_.extra_fingers[k - 1].measured.force;
  }
  double FingerMu(int k) const { return k == 0 ? traj_.finger.mu_contact : traj_.extra_fingers[k - 1].finger.mu_contact; }
  /// The estimate of step i (no covariances).
  StateEstimate State(int i) const;

 private:
  ceres::LossFunction* MakeLoss(const LossConfig& loss) const;

  void AddKinematicFactors(ceres::Problem& problem, int i);
  void AddPoseMeasurementFactors(ceres::Problem& problem, int i);   ///< M of both poses
  void AddConstantVelocityFactors(ceres::Problem& problem, int i);  ///< V on steps i-2, i-1, i
  void AddDynamicFactors(ceres::Problem& problem, int i);
  /// Finger k's second contact point at step i from its rows, paired with the previous step's.
  void InitializeSecondContact(int i, int k, bool causal);
  /// Finger k's contact rows of step i (the second: -1 when none) and its two-contact flag.
  int& ContactRow(int i, int k) { return k == 0 ? steps_[i].contact : steps_[i].others[k - 1].contact; }
  int& SecondContactRow(int i, int k) { return k == 0 ? steps_[i].contact2 : steps_[i].others[k - 1].contact2; }
  bool& TwoContactsFlag(int i, int k) { return k == 0 ? steps_[i].two_contacts : steps_[i].others[k - 1].two_contacts; }
  ContactVars& SecondVars(int i, int k) { return second_vars_[static_cast<std::size_t>(i) * num_fingers() + k]; }
  /// The object features (edge, or vertex) of finger k's two contacts at step i's current values:
  /// geometry::FindContacts within 3 contact-measurement sigmas, and of its distinct features
  /// the pair nearest the two contact variables' current values (one each). False when fewer
  /// than two.
  struct ContactFeature {
    geometry::EdgeId edge;
    bool vertex = false;
  };
  bool TwoContactFeatures(int i, int k, ContactFeature out[2]) const;
  /// The distinct object features (each with its contact point) within 3 contact sigmas of
  /// finger k at step i's current values.
  std::vector<std::pair<ContactFeature, Vec2>> NearbyContactFeatures(int i, int k) const;
  /// Finger k's two contacts at step i: M of both rows, C on the object's boundary and at each
  /// one's own feature (FeatureWitnessFactor) or local witness.
  void AddTwoContactFactors(ceres::Problem& problem, int i, int k);
  /// A faced finger's rows at step i beyond its two contacts' (three or four on a face broken by
  /// a notch): each measures the other end of one contact's overlap (OverlapEndMeasurementFactor).
  void AddInnerEndRows(ceres::Problem& problem, int i, int finger, const ContactFeature features[2],
                       double* const points[2], const int overlap_end[2]);
  /// Whether finger 0 at step i's current values is between two walls: two contacts within
  /// that tolerance whose normals differ by more than 60 degrees.
  bool BetweenWalls(int i) const;
  /// The two facing object edges finger 0 is within `tolerance` of at step i's current values
  /// (their contact points in a[0], a[1]); false when none.
  bool FacingWalls(int i, double tolerance, Vec2 points[2]) const;
  /// Finger k's fixed contact features at step i's current values, as keys (-1: none, the
  /// nearest pair or the local witness): what AddTwoContactFactors gives its witness factors.
  std::array<long long, 2> FeatureChoice(int i, int k) const;
  /// The keys of the features the contact factors hold fixed (edges; a vertex, or none: -1).
  static std::array<long long, 2> FixedFeatureKeys(bool on_features, const ContactFeature features[2]);
  /// A non-negative key of a feature (EdgeId's ring is -1 for the outer boundary).
  static long long FeatureKey(const ContactFeature& f) {
    return ((static_cast<long long>(f.edge.polygon) * 4096 + f.edge.ring + 1) * 1048576 + f.edge.index) * 2 + f.vertex;
  }
  std::vector<std::array<long long, 2>> feature_choices_;  ///< per step and finger, as last added
  /// Querier (the given one, else a new one), quasi-static geometry, friction (both constructors).
  void SetUpShapes(std::shared_ptr<const geometry::ShapePairQuerier> querier);
  /// The first and last of `rows` at row k's time.
  static std::pair<int, int> ContactRowsAt(const std::vector<push::PointSample>& rows, int k);
  /// Of `rows` at row k's time, the two farthest apart (k's own pair when two).
  static std::pair<int, int> FarthestContactRows(const std::vector<push::PointSample>& rows, int k);
  /// The object point nearest finger k's shape at step i's current values.
  Vec2 FingerNearestObjectPoint(int i, int k) const;
  /// Finger k's (k >= 1) initial pose, contact and force at step i.
  void InitializeOtherFinger(int i, int k, double limit);
  /// Finger k's (k >= 1) M, C, S and touching factors at step i.
  void AddOtherFingerKinematicFactors(ceres::Problem& problem, int i, int k);
  /// Finger 2, 3, ...'s blocks at step i.
  MoreFingerVars& More(int i, int k) { return more_vars_[static_cast<std::size_t>(i) * (other_fingers_ - 1) + (k - 2)]; }
  /// D and the limit-surface load of one contact (p, f) at step i.
  void AddOneContactQuasiStatic(ceres::Problem& problem, int i, double* p, double* f);

  const push::Trajectory& traj_;
  Model model_;
  EstimatorConfig cfg_;
  OnlineStreams streams_;  ///< which streams exist (batch: the non-empty ones)
  std::vector<Step> steps_;
  StableArray<StepVars> vars_;  ///< appending keeps the addresses Ceres holds
  /// Samples of each stream already in steps: finger 0's object, finger, contact and force
  /// streams, then finger k's finger, contact and force streams at 3 k + 1 .. 3 k + 3.
  std::vector<std::size_t> used_;
  std::shared_ptr<const geometry::ShapePairQuerier> querier_;
  int other_fingers_ = 0;  ///< fingers 1, 2, ... estimated (several fingers, not the baseline)
  StableArray<MoreFingerVars> more_vars_;  ///< fingers 2, 3, ...: other_fingers_ - 1 per step
  StableArray<ContactVars> second_vars_;   ///< several fingers: each finger's second contact
  std::vector<bool> finger_has_faces_;  ///< per finger: its core is more than a point (not a disk)
  std::vector<std::shared_ptr<const geometry::ShapePairQuerier>> other_queriers_;  ///< object and finger k >= 1
  /// The object without its holes: the boundary a finger outside the object touches. C's "p on
  /// the object's boundary" measures p against it (ContactBoundary), not against the nearest
  /// ring: a noisy contact row pulled p onto a hole's edge 2 cm inside the pushed face.
  geometry::Shape object_outer_;
  bool object_has_holes_ = false;
  /// The shape whose boundary a contact of finger `finger` at step i lies on: the outer
  /// boundary while the finger's reference point is outside the hole-free object (as it is when
  /// it pushes from outside), the whole shape when it is inside a hole.
  const geometry::Shape& ContactBoundary(int i, int finger) const;
  bool fingers_ignored_ = false;  ///< the baseline left fingers 1, 2, ... out
  int steps_with_more_contacts_ = 0;  ///< steps with 3+ contact rows, modelled by their farthest two
  QuasiStaticGeometry qs_;
  bool estimate_c_ = false;
  bool c_in_problem_ = false;
  double c_var_[1] = {0.0};
  double f_max_ = 0.0;  ///< mu m g; 0 when the trajectory lacks mass or friction
  double force_period_ = 0.0;  ///< the force stream's median sample period (s), 0 with under two samples
  double mu_surface_ = 0.0, normal_load_ = 0.0;  ///< the trajectory's mu and m g
  double eps_force_ = 0.0;  ///< cfg.eps_force, capped at f_max / 20 (a light object)
  bool estimate_mu_ = false;
  bool mu_in_problem_ = false;
  double mu_var_[1] = {0.0};
  bool use_load_factor_ = false;  ///< LimitSurfaceLoadFactor on (config + force stream)
  bool shape_frame_ = false, frame_in_problem_ = false, frame_rotation_ = true;
  double frame_[3] = {0.0, 0.0, 0.0};
  Vec2 frame_centroid_ = Vec2::Zero();
  std::vector<TaggedBlock>* tags_ = nullptr;
  /// While StageSteps solves the kinematics first: no shape frame, factors not recorded for
  /// Describe or the diagnostics (that problem is gone after it).
  bool warm_start_ = false;
  bool incremental_ = false;
  int adding_step_ = -1;  ///< the step whose factors are being added (-1: shared)
  int second_contacts_ignored_ = 0;  ///< Yu baseline: steps with two contacts it models as one
  /// Per finger, without a contact stream: whether its force samples so far have shown a contact
  /// above their noise (ForceSaysTouching) anywhere, and the first sample not yet looked at.
  std::vector<char> force_contact_seen_;
  std::vector<std::size_t> force_samples_seen_;
  /// Per finger: the first and last times its force stream showed a contact above its noise.
  std::vector<double> force_contact_first_, force_contact_last_;
  std::vector<char> force_contact_held_;  // per finger: ForceContactHeld somewhere
  bool object_moving_seen_ = false;
  std::size_t object_poses_seen_ = 0;
  std::unordered_map<ceres::ResidualBlockId, std::pair<FactorType, int>> origin_;  ///< for Describe
  /// The same for the staged start's temporary problem (StageSteps' kinematic stage), cleared
  /// after its solve: its stall named "a marginal prior or unnamed factor".
  std::unordered_map<ceres::ResidualBlockId, std::pair<FactorType, int>> warm_origin_;
  double frame_sigma_centroid_ = 0.01, frame_sigma_theta_ = 0.2;
};

/// Fills the covariances of `states` (indices `steps` into builder steps) by `method`
/// over `problem`, and, when `parameters` is given, the sigmas of the estimated c and mu
/// (builder.c_block(), mu_block()) in the same computation; returns a status string ("ok" or
/// the reason of failure).
std::string ComputeCovariances(ceres::Problem& problem, GraphBuilder& builder,
                               const std::vector<int>& steps, std::vector<StateEstimate>& states,
                               EstimatorConfig::CovarianceMethod method,
                               EstimationResult* parameters = nullptr, Eigen::Matrix3d* frame_cov = nullptr,
                               ChainSolver* chain = nullptr);

/// The shape frame of an estimate, for Diagnose.
struct FrameState {
  Vec2 centroid = Vec2::Zero();
  double sigma_centroid = 0.01, sigma_theta = 0.2;
  bool rotation = true;
  Pose2 frame;
};
/// The self-diagnosis of `result` (diagnostics.h), estimated on `trajectory` (the shape used)
/// with `model` and `config`; `frame` when the shape frame was a variable.
/// `querier`: the estimate's (GraphBuilder::MakeQuerier), shared; null: a new one.
Diagnostics Diagnose(const push::Trajectory& trajectory, Model model, const EstimatorConfig& config,
                     const EstimationResult& result, const FrameState* frame,
                     std::shared_ptr<const geometry::ShapePairQuerier> querier = nullptr);

/// Whether a finger pose sample lies within 0.05 s of `t` (the finger moves under 3 mm in it at
/// 5 cm/s): a contact point at `t` can then be judged against the finger
/// (DropContactStreamsOffTheFinger; OnlineEstimator counts such contacts before it judges).
bool FingerPoseNear(const std::vector<push::PoseSample>& finger_poses, double t);
/// How far `point` (world frame) lies from the finger's boundary at its pose at `t`, interpolated
/// between the poses around `t` (held at the newest beyond it). The one measure of the contact
/// checks: a stream off its finger, a corrupt row, online and in batch.
double DistanceFromFinger(const std::vector<push::PoseSample>& finger_poses, const geometry::Shape& finger, double t,
                          const geometry::Vec2& point);

/// Refuses a trajectory the estimator cannot use (trajectory_checks.cpp; GraphError naming the
/// stream, sample and value): missing shapes or streams, NaN, unsupported magnitudes, unsorted
/// samples, clock jumps within or between streams.
/// `finger_size` false leaves out CheckFingerSizes (Estimate reads a finger file in other units
/// first, FingerUnits, on an otherwise validated trajectory).
void ValidateTrajectory(const push::Trajectory& trajectory, bool finger_size = true);
/// A finger whose origin lies deeper inside it than the whole push reaches: refused, naming the
/// units that make it a probe. Part of ValidateTrajectory.
void CheckFingerSizes(const push::Trajectory& trajectory);
/// Refuses a push whose fingers never come near the object's tracked origin: every finger that
/// measures a contact point or a non-zero force (none: the nearest finger) must come within
/// max(0.5 m, twice the object's and its reach from their pose origins), and every contact stream
/// lie that near (its median). Part of ValidateTrajectory.
void CheckFingerReachesObject(const push::Trajectory& trajectory);
/// OnlineEstimator's form of that check at a finger's first touch (time t; `contact` its first
/// contact sample, or null when a force said so): why finger `finger` (0: the trajectory's
/// finger, k: extra_fingers[k - 1]) or that contact cannot touch the object there, or nullopt.
std::optional<std::string> FingerFarFromObject(const push::Trajectory& trajectory, int finger, double t,
                                               const push::PointSample* contact);
/// A warning when every stream is sampled at 0.2 s or slower (5 Hz) and the streams read in
/// milliseconds, microseconds or nanoseconds are a push (at most 20 kHz, a finger at most 2 m/s): a 250 Hz
/// sensor in milliseconds reads 4 s apart, and the noise model's per-second scales then no longer
/// fit the data. Empty otherwise.
/// `unit`, when given and a note is returned: the unit asked about ("milliseconds", ...).
std::optional<std::string> TimeUnitNote(const push::Trajectory& trajectory, const char** unit = nullptr);
/// Two of the trajectory's streams whose time spans do not overlap at all (a clock offset, a
/// stream from another recording), named with their spans.
std::optional<std::string> StreamOverlapNote(const push::Trajectory& trajectory);
/// Throws when a finger stream is 100 times as long as the object's and has most of its rows
/// outside the object's time (another time unit), naming it.
void CheckStreamTimeUnits(const push::Trajectory& trajectory);
/// A finger's pose or force stream that has no rows where the object moves more than 10 mm at
/// the start or end of the push (a sensor that stopped, or started late). Null when there is none.
std::optional<std::string> StreamCoverageNote(const push::Trajectory& trajectory);

/// Where the object's tracker is silent for over 0.5 s (and 10 of its periods), an estimated
/// object moving over 5 times as fast as the finger (plus 2 cm/s): a pushed object cannot outrun
/// its pusher. The warning, worded by model and mode; nullopt when there is none.
std::optional<std::string> UnobservedRunawayNote(const push::Trajectory& trajectory, const std::vector<StateEstimate>& states,
                                                 Model model, Mode mode);
/// A warning when the measured force does negative work on the object over the samples where it
/// is above a quarter of its 95th percentile (f . v summed, v the finger's velocity over +-0.1 s):
/// a quasi-static push takes positive work from the finger, so such a stream has its sign flipped
/// (the force on the sensor), its axes swapped, or another frame.
std::optional<std::string> ForceDirectionNote(const push::Trajectory& trajectory);
/// A warning when the force sensor reads a clear mean force where the finger does not touch: the
/// force samples more than 0.05 s before the first and after the last contact_point sample (at
/// least 10), whose mean is over 4 standard errors and over 0.05 N: a bias (an untared sensor).
/// Null without a contact stream to tell contact by. Where shifting the force stream's time
/// stamps by more than that margin (within +-1 s) makes its magnitude follow the contact rows
/// and leaves no clear force out of contact, the warning names the clock offset instead
/// (`clock_offset`).
struct ForceOutOfContactNote {
  std::string text;
  bool clock_offset = false;  // the force and contact streams' clocks disagree, rather than a bias
};
std::optional<ForceOutOfContactNote> ForceBiasNote(const push::Trajectory& trajectory);
/// A warning when the measured forces' 95th percentile is over 20 times the object's friction load
/// mu m g (and 5 force sigmas), or their fifth largest under 1/20 of it while the object moves over
/// 1 cm (a quasi-static push needs about that load): another force unit, or a wrong mass or mu.
/// Where the object moves: the forces' upper quartile under a quarter of the load (kgf), or their
/// lower quartile over twice it (a sensor's gain, or a mass or mu too small; not asked when
/// `mu_estimated`, the fit then sizing mu_surface to the forces).
std::optional<std::string> ForceScaleNote(const push::Trajectory& trajectory, double force_sigma, bool mu_estimated);
/// The object and finger pose streams without their tracker glitches (the finger's floor 2 cm): samples more than max(1 cm, 10 scatters)
/// or max(0.3 rad, 10 scatters) from the median of a window centred on them (+-max(0.1 s, 3
/// periods)), when they are at most a tenth of the stream (more is the stream itself, left to the
/// other checks); nullopt when there is none; `note` says how many, the first and the bounds.
std::optional<push::Trajectory> DropObjectPoseGlitches(const push::Trajectory& trajectory, std::string* note);
/// A warning when the object's yaw scatters by more than 0.2 rad about its centred running median
/// or turns at a median 8 rad/s or more: a yaw in degrees.
std::optional<std::string> YawUnitNote(const push::Trajectory& trajectory);
/// A step of the object pose stream that stays (samples on each side agree): said, not repaired.
std::optional<std::string> TrackerStepNote(const push::Trajectory& trajectory);
/// The farthest a tabletop object's shape reaches from its centroid (m): objects pushed by a
/// finger span centimetres to decimetres (MIT's 9 to 16 cm); beyond, a file in other units.
inline constexpr double kTabletopReach = 1.0;
/// A warning when the object's shape reaches more than 1 m from its centroid: a file in
/// centimetres or millimetres throughout (shapes and positions agree, so nothing else sees it).
std::optional<std::string> ShapeSizeNote(const push::Trajectory& trajectory);
/// The trajectory with its object's shape read as millimetres when it reaches over 1 m from its
/// centroid (a CAD export): what the finger's own checks (FingerUnits, the finger's origin) judge
/// the finger against, before the registration finds the object's units.
push::Trajectory WithObjectInMetres(const push::Trajectory& trajectory);
/// EstimatorConfig::object_delay: `delay` (s) subtracted from every measured object_pose stamp,
/// and from the ground truth's object poses too where they carry exactly the measured stream's
/// stamps (the tracker's own record, as mit-import and --add-noise keep: late like it); a
/// simulator's truth on its own clock stays.
push::Trajectory WithObjectDelay(const push::Trajectory& trajectory, double delay);
/// Finger shape files in other units (align_shape auto and on): a finger whose origin lies
/// deeper inside it than the whole push reaches (ValidateTrajectory refuses it), or whose file
/// reaches over 1 m from its origin, is read in the unit (millimetres, centimetres, inches) that
/// makes it a tabletop probe (0.5 to 100 mm from its origin) whose contacts fit the object
/// (CheckShapeFit, the smallest median gap); when none fits, millimetres if that is a probe.
/// Returns the trajectory with every such finger scaled, sets `note` and `finger_scale` (the
/// last scale applied); nullopt when none is.
std::optional<push::Trajectory> FingerUnits(const push::Trajectory& trajectory, const RegistrationOptions& options,
                                            std::string* note, double* finger_scale);
/// Contact streams that do not lie on their finger: the median distance of a finger's contact
/// points from its boundary (its pose interpolated at their times, where a finger sample lies
/// within 0.05 s) above
/// max(5 mm, 3 sqrt(sigma_contact^2 + sigma_finger^2)), over at least 5 such samples: a tactile
/// sensor in another frame or with an offset, which pulled every model's estimate beyond the raw
/// data's. Returns the trajectory with those streams left out and sets `note`; nullopt when none is.
std::optional<push::Trajectory> DropContactStreamsOffTheFinger(const push::Trajectory& trajectory,
                                                               const push::MeasurementSigmas& sigmas, std::string* note);
/// A contact row no sensor of this push could have measured (a corrupt row): farther from its
/// finger's boundary (the finger pose near its time, interpolated) than ContactFaultBound, max(2 cm,
/// 10 sqrt(sigma_contact^2 + sigma_finger^2)). One row moved by 5 m took a batch estimate to 160 mm
/// against 2.8 mm raw, with no word. Rows without a finger pose within 0.05 s are not judged; a
/// stream off its finger as a whole is DropContactStreamsOffTheFinger's case (run it first).
/// Returns the trajectory without them and sets `note`; nullopt when there is none.
std::optional<push::Trajectory> DropContactRowFaults(const push::Trajectory& trajectory, const push::MeasurementSigmas& sigmas,
                                                     std::string* note);
constexpr double kContactFaultFloor = 0.02;  // m
double ContactFaultBound(const push::MeasurementSigmas& sigmas);
/// Every finger whose outline is a tessellated cylinder (geometry::TessellatedDisk) as the disk
/// it approximates, when config.tessellated_finger_as_disk; sets `note` (which fingers, their
/// disks, how to keep the polygon). nullopt when no finger is one.
std::optional<push::Trajectory> TessellatedFingersAsDisks(const push::Trajectory& trajectory, const EstimatorConfig& config,
                                                          std::string* note);
/// A warning naming every measurement sigma above ten times the range of its stream's values
/// (and above 1 cm, 1 N; rotation above 10 rad): such a stream carries no weight.
std::optional<std::string> MeasurementSigmaNote(const push::Trajectory& trajectory, const push::MeasurementSigmas& sigmas);
/// A gap in the object pose stream that counts as the object unobserved (an occluded camera):
/// longer than max(3 median object periods, 0.1 s); INFINITY with fewer than two poses.
double LongObjectGap(const push::Trajectory& trajectory);
/// Contact above a force stream's noise (no contact stream): at t when a force sample lies within
/// max_gap of t and the component-wise median force of the samples within +-max(0.02 s, the
/// nearest sample's gap) of t is at least max(threshold, 5 sigma / sqrt(n)) (four of the median's
/// sigmas under Gaussian noise), n those samples. A finger whose force stream shows this nowhere
/// never touched: the graph and the registration then give it no contact (one sample against
/// the threshold let the noise through, 61 % of a free finger's samples with sigma at the 0.05 N
/// threshold: a finger passing 2 cm from the object had every step in contact, the object pulled
/// to it and the shape "aligned" by 56 mm). Elsewhere steps are still gated on one sample
/// against the threshold: gating the graph on this too cost the MIT ellip1 set 10 % in object
/// RMS (a light touch without a pushing model) and the QS force NEES 3.0 -> 7.7.
bool ForceSaysTouching(const std::vector<push::ForceSample>& force, double t, double max_gap, double threshold,
                       double sigma);
/// A contact the force stream holds: ForceSaysTouching at t and at the two times 0.05 and 0.1 s
/// after it, or before it (the end of a contact). One window's median crosses the noise bound now
/// and then: a force stream reading its declared 0.05 N noise alone, with the finger 0.2 m from a
/// resting box, had such crossings open a contact span and the box dragged 120 mm.
bool ForceContactHeld(const std::vector<push::ForceSample>& force, double t, double max_gap, double threshold,
                      double sigma);
/// Whether the object is seen to move: the median position of five consecutive poses more than
/// max(2 cm, 4 sigma) from that of the first five. Scans from *scanned (updated) so a growing
/// stream costs its new samples only. Something moved it, so a force stream under its noise
/// (a 50 g object pushed with 0.5 N noise) does not make the finger "never touching".
bool ObjectSeenMoving(const std::vector<push::PoseSample>& poses, double sigma, std::size_t* scanned);
/// The stream's positions within a window of t (+-200 sigma s/m, 0.1 to 1 s; medians of up to five
/// samples at both ends) move less than their noise allows (at least 1 mm); false where the window
/// holds too few samples to tell.
bool PoseStreamAtRest(const std::vector<push::PoseSample>& poses, double t, double sigma);
/// The same with "too few samples to tell" apart from "moving".
enum class Rest { kAtRest, kMoving, kUnknown };
Rest PoseStreamRest(const std::vector<push::PoseSample>& poses, double t, double sigma);
/// The finger count (at most two) and every finger's shape; ValidateTrajectory's first checks.
void ValidateFingers(const push::Trajectory& trajectory);
/// The 95th percentile of `values` (non-empty).
double Percentile95(std::vector<double> values);
/// A force sample above this is a sensor fault (docs/estimation.md, Input checks): 50 times the
/// larger of the forces' 95th percentile and the object's mu m g (when known), at least 1 N.
/// Used by the batch estimator (all forces) and OnlineEstimator (the newest 512).
double ForceFaultBound(double force_p95, const push::ObjectDescription& object);

}  // namespace pushgraph::graph::internal
