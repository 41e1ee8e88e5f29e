#pragma once
// Quasi-static pushing of a sliding object by a finger through one point contact with Coulomb
// friction mu_c: which way the object moves, whether the contact sticks or slides, and the load
// the finger applies (a load ON the object's limit surface).
//
//   using namespace pushgraph;
//   push::PushingSpec spec;
//   spec.object = {geometry::Shape::Box(0.09, 0.09), /*mass=*/0.8374, /*mu_surface=*/0.25};
//   spec.finger = {geometry::Shape::Disk(0.00235), /*mu_contact=*/0.3};
//   push::PushingModel model(spec);              // keep it: it caches the geometry
//   geometry::Pose2 object{0, 0, 0}, finger{-0.05, 0.01, 0};
//   push::PushStep step = model.Step(object, finger, {1e-4, 0.0});
//   // step.object_pose, step.finger_pose, step.response.mode / .force / .contact_point
//
// Model (docs/simulator.md). Quasi-static pushing (Mason 1986; Goyal, Ruina, Papadopoulos 1991):
// the applied load F lies on the object's limit surface and the object's body twist is normal
// to the surface at F. With a point contact at r (about the centre of pressure, body axes) the
// load is a force f at r: F = (f, r x f). Lynch, Maekawa, Tanie (1992) "motion cones": the twists
// produced by forces in the friction cone map the contact-point velocities v_p = v + omega z x r
// into a cone; a finger velocity inside it makes the contact stick (v_p = v_finger), outside it
// the contact slides and the force lies on the friction-cone edge on the side of the finger's
// relative slip. We solve the sticking case directly (a 1-D monotone root find on the twist
// family whose contact point moves with the finger, requiring the load's torque about the
// contact to vanish) and then test the force against the friction cone; this is equivalent to
// the motion-cone test and exact for the exact surface, not only for the ellipsoid.
#include <pushgraph/push/errors.h>
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/limit_surface/ellipsoid.h>
#include <pushgraph/limit_surface/limit_surface.h>
#include <pushgraph/limit_surface/support.h>
#include <pushgraph/push/trajectory.h>

#include <memory>

namespace pushgraph::push {

using geometry::Vec2;
using limit_surface::kStandardGravity;
using limit_surface::Load;
using limit_surface::Pressure;
using limit_surface::Twist;

/// Which limit surface the pushing model uses.
enum class SurfaceModel {
  kExact,      ///< the exact surface of the support (SustainingLoad / TwistForLoad)
  kEllipsoid,  ///< the paper's ellipsoid (Lambert et al. Eq. 3-4: semi-axes f_max, f_max, tau_max)
};

enum class ContactMode {
  kSeparated,  ///< apart, or touching while the finger does not push: the object stays put
  kSticking,   ///< the contact point moves with the finger
  kSliding,    ///< the finger slips along the object's boundary; force on a friction-cone edge
};

const char* ToString(ContactMode mode);
const char* ToString(SurfaceModel model);

struct PushingSpec {
  ObjectDescription object;     ///< shape = support region (no rounding), mass > 0, mu_surface > 0
  FingerDescription finger;     ///< any finger shape (disk, rounded square, polygon), mu_contact >= 0
  SurfaceModel surface = SurfaceModel::kExact;
  /// The shapes touch when their signed separation is at most this (m). Must be > 0.
  double contact_tolerance = 1e-6;
  /// After each step, penetration deeper than this (m) is pushed out quasi-statically.
  double penetration_tolerance = 1e-10;
};

/// The instantaneous quasi-static answer for a finger motion, poses held fixed.
struct PushResponse {
  ContactMode mode = ContactMode::kSeparated;
  bool touching = false;           ///< signed separation <= contact_tolerance
  double separation = 0.0;         ///< signed separation of the shapes (m), < 0 overlap
  /// Body twist of the object's centre of pressure (shape axes) per unit of finger motion:
  /// for a finger displacement d it is the displacement twist (m, m, rad). Zero when separated.
  Twist twist;
  Vec2 contact_point{0.0, 0.0};    ///< world frame, on the object's boundary
  Vec2 contact_normal{0.0, 1.0};   ///< world frame, unit, pointing INTO the object
  Vec2 force{0.0, 0.0};            ///< applied by the finger on the object, world frame (N)
  /// The applied load about the centre of pressure, shape axes: exactly the limit surface's load
  /// for `twist` (SustainingLoad or EllipsoidLoad); zero when separated.
  Load load;
  /// |load.torque - r x load.force| / tau_max: how far the load is from a pure force at the
  /// contact (root-finding / inverse-map residual, ~1e-12 or better).
  double torque_residual = 0.0;
  /// Sliding only: +1 when the finger slips along +t = z x n (n the inward normal) relative to
  /// the object, -1 along -t; 0 otherwise.
  int slip_direction = 0;
};

/// The result of advancing the finger by a displacement.
struct PushStep {
  geometry::Pose2 object_pose;
  geometry::Pose2 finger_pose;
  PushResponse response;           ///< the response of the (last) pushing sub-step; separated if none
  double separation_after = 0.0;   ///< signed separation at the end of the step (m)
  bool made_contact = false;       ///< the finger reached the object during this step
};

class PushingModel {
 public:
  /// Validates the spec (throws LimitSurfaceError / GeometryError naming the field).
  explicit PushingModel(PushingSpec spec);
  ~PushingModel();
  PushingModel(PushingModel&&) noexcept;
  PushingModel& operator=(PushingModel&&) noexcept;

  /// The quasi-static answer for an (infinitesimal) finger translation `finger_motion` (world),
  /// with both poses fixed: contact found with ShapePairQuerier; no motion when apart or when
  /// the finger does not move into the object. The twist is scaled to the finger motion.
  PushResponse Respond(const geometry::Pose2& object_pose, const geometry::Pose2& finger_pose,
                       const Vec2& finger_motion) const;

  /// Advances the finger by the translation `displacement` (world; keep it small compared with
  /// the shapes, e.g. <= 1 mm): free motion up to first contact (found by conservative
  /// advancement along the path), then quasi-static pushing, then any residual penetration
  /// deeper than penetration_tolerance is pushed out along the contact normal (quasi-statically).
  PushStep Step(const geometry::Pose2& object_pose, const geometry::Pose2& finger_pose,
                const Vec2& displacement) const;

  /// The object's pose after moving its centre of pressure by the body twist `twist` (SE(2) exp).
  geometry::Pose2 ApplyTwist(const geometry::Pose2& object_pose, const Twist& twist) const;

  /// The limit surface's load for a twist, with the selected surface model.
  Load SurfaceLoad(const Twist& twist) const;

  const PushingSpec& spec() const;
  const limit_surface::Support& support() const;
  const limit_surface::Summary& summary() const;
  const limit_surface::Ellipsoid& ellipsoid() const;  ///< the paper's ellipsoid of this support
  const geometry::ShapePairQuerier& querier() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::push
