#pragma once
// Shape registration: the transform between a shape file's frame and the frame in which a
// tracker reports the object's pose, estimated from a recorded push.
//
// A mesh or CAD file rarely shares the tracker's frame: its origin differs, its axes may be a
// quarter turn off, its units may be millimetres. Estimating with such a shape runs to the end
// and gives errors larger than the raw measurements. RegisterShape finds T and a scale s with
//
//     p_object_frame = T * (s * p_shape_file)       (geometry::TransformShape(shape, T, s))
//
// from the measured finger path during contact, expressed in the object frame,
// q_i = x(t_i)^-1 * e_i: a touching finger lies on the object's boundary, so a disk finger's
// centre is at its radius r outside it, sd(T s S, q_i) = r (other fingers: approximated by a
// disk in the global search, exact shape-pair separations in the refinement).
//
// 1. Units: s is tried among 1 (metres), 0.01, 0.001 and 0.0254 (cm, mm, inch files), 100 and
//    1000 (a file converted to metres twice) where the scaled shape is of the size of the
//    finger path (options.detect_units).
// 2. Global search, so that no quarter turn or symmetry traps it: for every rotation on a grid
//    (options.rotation_step; only one turn of the outline's symmetry), robust Gauss-Newton
//    over the translation from two starts, scored by the Cauchy cost sum log(1 + (d_i/c)^2).
//    A weak prior puts the shape's area centroid at the object frame's origin (trackers of
//    rigid blocks report the centroid; the MIT dataset does): it decides only what the
//    contacts leave free, e.g. the position along the one side of a block that was pushed.
// 3. Refinement of the best candidates in (x, y, theta) (and log s with estimate_scale), exact
//    queries, covariance from the Gauss-Newton information. The estimator refines T further as
//    a static variable of the factor graph (EstimatorConfig::align_shape).
//
// Rotationally symmetric outlines (a disk) leave the rotation unobservable: it is kept at 0
// and reported (rotation_observable false), not invented. An outline with k-fold symmetry is
// searched over one k-th of a turn; the reported rotation is the equivalent one closest to 0.
//
//   graph::RegistrationResult reg = graph::RegisterShape(trajectory);
//   if (!reg.fits_as_given) {
//     std::cerr << reg.Describe() << "\n";
//     trajectory.object.shape = reg.Apply(trajectory.object.shape);
//   }
#include <pushgraph/graph/config.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/push/trajectory.h>

#include <Eigen/Core>

#include <string>
#include <vector>

namespace pushgraph::graph {

/// Shape-file frame to object frame: p_object = pose * (scale * M p_file), M = diag(1, -1)
/// when mirrored (a footprint seen from below), else the identity.
struct ShapeTransform {
  geometry::Pose2 pose;
  double scale = 1.0;
  bool mirrored = false;
  bool IsIdentity() const {
    return pose.x == 0.0 && pose.y == 0.0 && pose.theta == 0.0 && scale == 1.0 && !mirrored;
  }
};

struct RegistrationOptions {
  /// Also try the shape file in centimetres, millimetres and inches, and 100 and 1000 times larger.
  bool detect_units = true;
  /// Also try the shape file mirrored (seen from below); chosen only when it fits clearly better.
  bool detect_mirror = true;
  /// Smooth the object and finger streams (pose measurements and the constant-velocity prior
  /// of the estimator) before fitting: the paper's 5 mm noise becomes about 1.5 mm.
  bool smooth = true;
  /// Refine a continuous scale factor (disk fingers; 1-parameter change of size).
  bool estimate_scale = false;
  double rotation_step = 2.0 * 3.14159265358979323846 / 180.0;  ///< rad, global grid
  int max_search_samples = 160;   ///< contact samples in the global search
  int max_refine_samples = 1200;  ///< and in the refinement
  /// Standard deviation of the finger's measured position relative to the object (m); 0: from
  /// the trajectory's measurement_sigmas, else from the residuals (median absolute deviation).
  double noise = 0.0;
  /// Sigma of the centroid-at-origin prior, as a fraction of the outline's radius (0.15: 7 mm
  /// for a 9 cm square). Observable directions are fixed by hundreds of contacts to a fraction
  /// of a millimetre whatever it is; it decides what they leave free (one pushed side of a
  /// block), where the fit would otherwise drift to whatever corner fits the noise best.
  double centroid_prior = 0.15;
  /// The shape as given fits (RegistrationResult::fits_as_given) when the median |contact gap|
  /// is at most max(fit_tolerance, 2.5 noise of the smoothed path) and at most 10% of the
  /// samples penetrate it by more than that. 3 mm: the MIT recordings' probe stays 0.2 to 2.5 mm off the blocks.
  double fit_tolerance = 3e-3;
  /// Alternatives (RegistrationResult::alternatives): the local minima over the rotation within
  /// this of the best cost (log-likelihood), and the best placement of each of `sectors` equal
  /// sectors of the full turn (fewer for a symmetric outline).
  double alternative_margin = 10.0;
  int sectors = 8;
  /// RegistrationResult::better_elsewhere: the best placement's log-likelihood is higher by this
  /// much and it moves the outline by more than fit_tolerance.
  double misfit_evidence = 6.0;
  /// A best fit that moves no outline point further than this (m) is the shape as given.
  double min_displacement = 1e-3;
  /// Contact gating as the estimator's (EstimatorConfig: contact_max_gap, contact_force_threshold;
  /// the force sigma decides whether a force stream shows any contact above its noise at all).
  double contact_max_gap = 0.05;
  double contact_force_threshold = 0.05;
  double contact_force_sigma = 0.5;
  /// Smoothing: measurement sigmas when the trajectory has none, and the white-noise
  /// acceleration densities (EstimatorConfig's object_pose_sigma_*, accel_*).
  double pose_sigma_trans = 0.005, pose_sigma_rot = 0.05;
  double accel_trans = 0.5, accel_rot = 5.0;
  /// The object pose is interpolated to finger samples only across gaps up to this (s).
  double max_object_gap = 0.1;
  /// Smoothed samples are correlated: a recording's contacts count as one independent sample
  /// per this time (s), however many there are (honest sigmas; a weak prior still matters).
  double correlation_time = 0.05;
  /// Each recording's probe may sit off the surface by a calibration gap (MIT: 0.2 to 2.5 mm);
  /// it is fitted per recording with this prior sigma (m), so that no shift or turn along a
  /// direction the contacts leave free is abused to close it. 0: no gap is fitted.
  double gap_sigma = 1e-3;
};

/// The options implied by an estimator configuration (contact gating, smoothing priors).
RegistrationOptions RegistrationOptionsFor(const EstimatorConfig& config);

/// The shape as given against a recording's contacts, without searching: the median |gap|
/// (finger at its radius from the boundary) and the share of samples inside the shape beyond
/// the tolerance max(options.fit_tolerance, half the raw measurement noise).
struct ShapeFitCheck {
  bool fits = true;
  double gap_median = 0.0;         ///< m
  double penetration_share = 0.0;  ///< in [0, 1]
  double tolerance = 0.0;          ///< m
  int samples = 0;
  /// "median contact gap 12.3 mm, 40% of the contact samples inside the shape by more than 3.0 mm (420 samples)"
  std::string Describe() const;
};

/// The cheap check alone (smoothing and one exact query per contact sample): what
/// EstimatorConfig::align_shape "auto" runs on every estimate before deciding to search.
ShapeFitCheck CheckShapeFit(const push::Trajectory& trajectory, const RegistrationOptions& options = {});
/// The same over several recordings of one object (pooled contacts; the first one's shapes).
ShapeFitCheck CheckShapeFit(const std::vector<const push::Trajectory*>& recordings,
                            const RegistrationOptions& options = {});

struct RegistrationResult {
  ShapeTransform transform;  ///< the best transform (the identity when nothing was found)
  /// Standard deviations of (x, y, theta) from the Gauss-Newton information (correlated
  /// measurement noise makes them optimistic); theta's is 0 when the rotation is unobservable.
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  double scale_sigma = 0.0;         ///< with estimate_scale
  bool rotation_observable = true;  ///< false for rotationally symmetric outlines
  /// The outline is unchanged by turns of 360 / symmetry_order degrees about its centroid;
  /// 0: by any turn (a disk), 1: no symmetry.
  int symmetry_order = 1;
  bool fits_as_given = true;   ///< the gaps of the shape as given are within tolerance (see options)
  /// The gaps fit, but a placement moving the outline by more than fit_tolerance fits the
  /// contacts better by misfit_evidence or more (a suspicion: estimators warn, "auto" does not
  /// align on it).
  bool better_elsewhere = false;
  /// Unit directions (object frame) of translations the contacts do not fix (the prior does).
  std::vector<geometry::Vec2> weak_directions;
  bool ambiguous = false;      ///< another, non-equivalent placement fits about as well
  /// Other placements, not equivalent to the best or each other (RegistrationOptions::
  /// alternative_margin and sectors), and their cost differences to the best:
  /// the contacts of one push often leave a few; the estimator judges them with its whole graph.
  std::vector<ShapeTransform> alternatives;
  std::vector<double> alternative_costs;
  /// When the shape does not fit as given: the contacts fit the shape as given about as well
  /// with the finger size_offset (m) larger (negative: smaller) as with the best placement
  /// (data and centroid prior): a wrong probe radius or object size, not a wrong frame.
  bool size_explains = false;
  double size_offset = 0.0;
  std::string ambiguity;       ///< what it is, when ambiguous
  /// No unit tried (metres, centimetres, millimetres, inches; 100 and 1000 times too small)
  /// makes the shape the size of the finger's path (its median distance from the object's
  /// origin in the contacts): the shape file's size or the pose stream's frame is wrong.
  bool size_mismatch = false;
  double size_ratio = 0.0;     ///< with size_mismatch: the shape's radius over the path's, as given
  ShapeFitCheck check;  ///< the shape as given (fits_as_given also accepts equivalent placements)
  double identity_gap_rms = 0.0;  ///< robust RMS (m) of sd - r over the contact samples, as given
  double aligned_gap_rms = 0.0;   ///< the same with the transform
  double identity_cost = 0.0, aligned_cost = 0.0;  ///< Cauchy costs (including the prior)
  /// The log-likelihood gain better_elsewhere weighs: identity_cost - aligned_cost, without the
  /// centroid prior's parts where the file's origin lies on or outside its outline (a CAD corner).
  double evidence = 0.0;
  double noise = 0.0;             ///< noise scale used (m)
  /// Independent contact samples the fit rests on (one per correlation_time of contact).
  double independent_samples = 0.0;
  /// The fitted calibration gap of each recording (m, positive: the finger stays off the surface).
  std::vector<double> gaps;
  double displacement = 0.0;      ///< largest move of an outline point by the transform (m)
  int samples = 0;                ///< contact samples used in the refinement
  std::vector<std::string> notes; ///< what was decided and why, one line each

  /// The shape in the object frame: geometry::TransformShape(shape, pose, scale, mirrored).
  geometry::Shape Apply(const geometry::Shape& shape) const;
  /// One line: "turned by 90.0 deg, shifted by (12.0, -3.1) mm, scale 0.001 (the file is in
  /// millimetres)", with "mirrored" when it is.
  std::string Describe() const;
};

/// Registers `trajectory.object.shape` to the trajectory's object frame from its measured
/// streams (object and finger poses; contact from the contact or force stream, else every
/// finger sample). Throws GraphError when there are fewer than 8 usable contact samples or no
/// object or finger stream.
RegistrationResult RegisterShape(const push::Trajectory& trajectory, const RegistrationOptions& options = {});

/// The same from several recordings of one object with one tracker (pooled contacts: pushes on
/// different sides fix what one push leaves free). Every trajectory must carry the same object
/// and finger shapes; throws GraphError otherwise.
RegistrationResult RegisterShape(const std::vector<const push::Trajectory*>& recordings,
                                 const RegistrationOptions& options = {});

/// Which of several readings of one object file a recording's contacts fit. A mesh exported with
/// y up (Blender's, glTF's convention) is a prism along y: seen along z its footprint is its side
/// view (rect1: 90 x 12.7 mm for its 90 x 90 mm top), and estimating with it gave 1.35 mm against
/// 0.95. Its cross-section along y is the footprint meant. A can lying along y is a prism along y
/// too, but pushed on its side, whose footprint along z is right: only the contacts can tell.
///
/// Reading 0 (the default, e.g. along z) is kept when its contacts fit it (CheckShapeFit).
/// Otherwise the reading whose contacts fit as given with the smallest median gap is chosen; when
/// none fits as given, each is registered (RegisterShape, one noise scale for all) and another
/// reading is chosen only when its registered cost is lower than reading 0's by 2 (a
/// log-likelihood), or reading 0 is no size of the push at all (size_mismatch).
///
///   std::vector<geometry::Shape> readings{along_z, along_y};
///   const graph::ShapeReadingChoice c = graph::ChooseShapeReading(trajectory, readings);
///   trajectory.object.shape = readings[c.index];
struct ShapeReadingChoice {
  int index = 0;                      ///< the reading chosen
  std::vector<ShapeFitCheck> checks;  ///< each reading as given (empty when it could not be checked)
  std::vector<bool> checked;          ///< whether checks[k] holds a check (too few contacts: no)
  /// Registered Cauchy costs (RegistrationResult::aligned_cost) when no reading fit as given; NaN
  /// for a reading not registered or refused for its size.
  std::vector<double> registered_costs;
  bool by_registration = false;       ///< the choice rests on the registered costs
  /// Why: "as given, reading 0 does not fit (median contact gap 38.8 mm, ...); reading 1 fits
  /// (...)", then the registered costs when they decided; empty when reading 0 fits as given.
  std::string reason;
};
/// `names` name the readings in `reason` ("along z", "along y"); empty: "reading 0", "reading 1".
ShapeReadingChoice ChooseShapeReading(const push::Trajectory& trajectory, const std::vector<geometry::Shape>& readings,
                                      const RegistrationOptions& options = {},
                                      const std::vector<std::string>& names = {});
/// The same from several recordings of one object (pooled contacts, as RegisterShape's).
ShapeReadingChoice ChooseShapeReading(const std::vector<const push::Trajectory*>& recordings,
                                      const std::vector<geometry::Shape>& readings,
                                      const RegistrationOptions& options = {},
                                      const std::vector<std::string>& names = {});

/// The finger's reference point in the object frame at every finger sample in contact (object
/// pose interpolated; both streams smoothed first when options.smooth), with the time stamps
/// and the finger's pose relative to the object: the data registration fits.
struct ContactPath {
  std::vector<double> t;
  std::vector<geometry::Vec2> q;          ///< finger reference point, object frame
  std::vector<geometry::Pose2> relative;  ///< finger pose in the object frame
  /// Which finger touched (0 is Trajectory::finger; a push with several fingers has the samples
  /// of each, finger by finger, each gated on its own contact or force stream) and the radius of
  /// its disk (FingerAsDisk).
  std::vector<int> finger;
  std::vector<double> radius;
  /// Standard deviation (m, per axis) of q's error: a parametric bootstrap of the smoothing with
  /// the raw noise (the measurement sigmas, else the streams' own second differences).
  double noise = 0.0;
};
ContactPath MeasuredContactPath(const push::Trajectory& trajectory, const RegistrationOptions& options);

/// Of the transforms that place a shape with k-fold symmetric outline identically (turns by
/// multiples of 360/k degrees about its centroid), the one whose angle is closest to 0.
/// `file_shape` is the shape in its file's frame and units; symmetry_order as in
/// RegistrationResult (0 and 1: returned unchanged).
ShapeTransform CanonicalTransform(const ShapeTransform& transform, const geometry::Shape& file_shape, int symmetry_order);

/// The finger's reference point (its core's centroid) and the radius of the disk that stands
/// for it in the global search (exact for disk fingers).
struct FingerDisk {
  geometry::Vec2 centre;
  double radius = 0.0;
  bool exact = false;  ///< the finger is a disk
};
FingerDisk FingerAsDisk(const geometry::Shape& finger);

/// The order of rotational symmetry of the outline (outer boundaries) about `centre`: k when
/// turning by 360/k degrees maps it onto itself within `tolerance`, 0 for a circle, 1 for none.
int OutlineSymmetryOrder(const geometry::Shape& shape, const geometry::Vec2& centre, double tolerance);

}  // namespace pushgraph::graph
