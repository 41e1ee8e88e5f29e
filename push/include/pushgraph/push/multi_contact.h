#pragma once
// Quasi-static pushing with several contacts: one finger wedged in a notch or a corner (two
// walls touched), several fingers moving together, a flat pusher face on an object face (a line
// contact, as its two end points). Each contact has its own point and force; every force lies in
// its friction cone (finger-object friction mu_contact of its finger); the net wrench about the
// centre of pressure is the limit surface's load for the object's twist (the twist is normal to
// the surface there); each contact sticks, slides or opens.
//
//   using namespace pushgraph;
//   push::MultiPushingSpec spec;
//   spec.object = {geometry::LoadShapeJson("data/shapes/notched_block.json"), 0.5, 0.3};
//   spec.fingers = {{geometry::Shape::Disk(0.005), /*mu_contact=*/0.3}};
//   push::MultiPushingModel model(spec);
//   push::MultiPushResponse r = model.Respond(object_pose, {finger_pose}, {Vec2(0, -1e-4)});
//   for (const push::ContactState& c : r.contacts) { ... c.finger, c.mode, c.point, c.force ... }
//
// Model (docs/simulator.md, "Several contacts"). With contact i at r_i (about the centre of
// pressure, body axes), inward normal n_i, tangent t_i = z x n_i, finger velocity u_i, and the
// object's twist xi = (v, omega), the contact point moves with v_i = v + omega z x r_i. A mode
// assigns each contact one of
//   sticking   v_i = u_i,                 force f_i free (2 unknowns), |f_i.t_i| <= mu f_i.n_i
//   sliding    n_i.v_i = n_i.u_i,         f_i = lambda_i (n_i + s mu t_i), lambda_i >= 0,
//              s = the sign of the finger's slip (u_i - v_i).t_i
//   open       f_i = 0,                   n_i.v_i >= n_i.u_i (the contact separates)
// and the load condition L(xi) = sum_i (f_i, r_i x f_i) closes the system (L the exact surface's
// SustainingLoad, or the paper's ellipsoid). This is the mode enumeration of the quasi-static
// complementarity problem (Lynch and Mason 1996; Trinkle et al. 1997 for the LCP form): each
// mode is solved by Newton's method from the ellipsoid's closed-form (linear) solution, and the
// first mode whose solution satisfies every inequality is the answer, modes ordered by the
// number of open contacts, then of sliding ones (so a contact opens or slides only when it must).
// Statics cannot split a force among sticking contacts beyond three equations (a finger
// squeezed into a V): of those splits the one using the least friction (least-squares tangential
// forces) is taken, then checked against the cones. With one contact this is PushingModel's
// answer (tests compare them).
#include <pushgraph/geometry/contacts.h>
#include <pushgraph/push/errors.h>
#include <pushgraph/push/pushing.h>
#include <pushgraph/push/trajectory.h>

#include <memory>
#include <vector>

namespace pushgraph::push {

struct MultiPushingSpec {
  ObjectDescription object;                ///< shape = support region (no rounding)
  std::vector<FingerDescription> fingers;  ///< at least one; each with its own mu_contact
  SurfaceModel surface = SurfaceModel::kExact;
  /// m: contacts with a gap up to this are active. 1 um, not less: a face settling onto a face
  /// (a flat pusher, a disk between two walls) rotates a little past flat within a step, so at
  /// 0.1 um the contact flipped from one end of the face to the other at every step instead of
  /// becoming a line contact (docs/simulator.md).
  double contact_tolerance = 1e-6;
  double penetration_tolerance = 1e-10;    ///< m: deeper overlap after a step is pushed out
  /// m: overlap deeper than this is not a contact of a feature pair (geometry::ContactOptions).
  double max_contact_depth = 1e-4;
  /// At most this many contacts at once (the mode enumeration is 4^N); more is a PushError.
  int max_contacts = 6;
};

/// One contact's answer.
struct ContactState {
  int finger = 0;                    ///< index into MultiPushingSpec::fingers
  ContactMode mode = ContactMode::kSeparated;  ///< kSeparated: the contact opens (no force)
  Vec2 point{0.0, 0.0};              ///< world, on the object's boundary
  Vec2 normal{0.0, 1.0};             ///< world, unit, pointing INTO the object
  double separation = 0.0;           ///< signed gap of the feature pair (m)
  Vec2 force{0.0, 0.0};              ///< applied by the finger on the object, world (N)
  int slip_direction = 0;            ///< sliding: +1 along +t = z x normal, -1 along -t
};

struct MultiPushResponse {
  bool touching = false;             ///< some finger is within contact_tolerance
  bool moving = false;               ///< the object moves (some contact pushes)
  /// Body twist of the centre of pressure (shape axes) per unit of finger motion, as in
  /// PushResponse::twist; zero when not moving.
  Twist twist;
  /// SurfaceLoad(twist) about the centre of pressure, shape axes; zero when not moving.
  Load load;
  std::vector<ContactState> contacts;   ///< every contact found, ordered by finger, then feature
  std::vector<Vec2> finger_force;       ///< per finger: the sum of its contacts' forces, world
  /// |sum of the contacts' wrenches - load| in (N, N, N m / c), relative to f_max: ~1e-13.
  double wrench_residual = 0.0;
  /// Largest |kinematic condition| (sticking velocity match, sliding normal match) relative to
  /// the fastest finger motion: ~1e-13.
  double kinematic_residual = 0.0;
  int modes_tried = 0;                  ///< how many modes were solved before this one held
};

/// The result of advancing every finger by its displacement.
struct MultiPushStep {
  geometry::Pose2 object_pose;
  std::vector<geometry::Pose2> finger_poses;
  MultiPushResponse response;        ///< of the pushing sub-step (not moving if none)
  std::vector<Vec2> pushing_motions; ///< the fingers' motions in that sub-step (the response's scale)
  double separation_after = 0.0;     ///< the smallest finger-object separation at the end (m)
  bool made_contact = false;
};

class MultiPushingModel {
 public:
  /// Validates the spec like PushingModel (errors name the field and the finger).
  explicit MultiPushingModel(MultiPushingSpec spec);
  ~MultiPushingModel();
  MultiPushingModel(MultiPushingModel&&) noexcept;
  MultiPushingModel& operator=(MultiPushingModel&&) noexcept;

  /// The quasi-static answer for (infinitesimal) finger translations `finger_motions` (world, one
  /// per finger), poses held fixed. Throws PushError when no mode is consistent (the fingers jam
  /// the object: e.g. two fingers squeezing it from opposite sides) or when more than
  /// max_contacts contacts are active.
  MultiPushResponse Respond(const geometry::Pose2& object_pose, const std::vector<geometry::Pose2>& finger_poses,
                            const std::vector<Vec2>& finger_motions) const;

  /// Advances every finger by its displacement (world; small, e.g. <= 1 mm): free motion to the
  /// first contact (conservative advancement), quasi-static pushing, then penetration deeper
  /// than penetration_tolerance pushed out along the contacts' normals (quasi-statically).
  MultiPushStep Step(const geometry::Pose2& object_pose, const std::vector<geometry::Pose2>& finger_poses,
                     const std::vector<Vec2>& displacements) const;

  /// The smallest signed separation of any finger from the object, and which finger (exact,
  /// ShapePairQuerier).
  double Separation(const geometry::Pose2& object_pose, const std::vector<geometry::Pose2>& finger_poses,
                    int* finger = nullptr) const;

  geometry::Pose2 ApplyTwist(const geometry::Pose2& object_pose, const Twist& twist) const;
  Load SurfaceLoad(const Twist& twist) const;
  const MultiPushingSpec& spec() const;
  const limit_surface::Summary& summary() const;
  const limit_surface::Support& support() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::push
