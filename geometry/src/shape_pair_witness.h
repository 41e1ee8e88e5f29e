#pragma once
// Witness points and separation derivatives of the shape-pair query (shape_pair.cpp): what a
// separation from the configuration-space obstacle C, the feature generating it and its material
// point give for the ShapePairResult and its Jacobians. Internal to pushgraph::geometry.
#include <pushgraph/geometry/pose.h>
#include <pushgraph/geometry/shape_pair.h>

#include <Eigen/Core>

namespace pushgraph::geometry::internal {

using Mat23 = Eigen::Matrix<double, 2, 3>;
using Row3 = Eigen::Matrix<double, 1, 3>;

/// d R(theta) / d theta.
Eigen::Matrix2d RotationDerivative(double theta);

// The same from the rotation's own entries (no second sincos).
Eigen::Matrix2d RotationDerivativeOf(const Eigen::Matrix2d& R);

inline Vec2 Perp(const Vec2& v) { return {-v.y(), v.x()}; }

// Witness points from a material point `m_w` (world) on the finger (finger_side) or on the
// object, the separating normal and the separation; with the Jacobians of each input.
struct WitnessInputs {
  bool on_finger = true;
  Vec2 m_w, n_w;
  double sd = 0.0;
  Mat23 J_m_obj = Mat23::Zero(), J_m_fin = Mat23::Zero();
  Mat23 J_n_obj = Mat23::Zero(), J_n_fin = Mat23::Zero();
  Row3 J_sd_obj = Row3::Zero(), J_sd_fin = Row3::Zero();
  // The contact normal k at the touching point after the separating move, where it differs from
  // the separating direction n (a concave corner of a rounded obstacle); otherwise k = n.
  bool separate_contact_normal = false;
  Vec2 k_w{0, 0};
  Mat23 J_k_obj = Mat23::Zero(), J_k_fin = Mat23::Zero();
};

// The ShapePairResult (separation, normal, depth, witness points) and its Jacobians from the inputs:
// witnesses offset along the separating normal n, or at a concave corner of a rounded obstacle
// along the contact normal k (separate_contact_normal).
void FillWitnesses(const WitnessInputs& in, double ro, double rf, ShapePairResult* r, ShapePairJacobians* J);

// How a feature of the obstacle's core moves with the relative angle phi, and which material
// point generates it (Lozano-Perez's contact types; see QueryExact).
struct FeatureMotion {
  Vec2 n{0, 0}, dn{0, 0};  // a line n . x = h of C: normal, d n / d phi, d h / d phi
  double dh = 0.0;
  Vec2 dv{0, 0};           // a vertex of C: d v / d phi
  bool finger_material = true;
  Vec2 f{0, 0}, o{0, 0};   // finger vertex (finger frame) / object vertex (object frame)
};

// The separation of the finger's origin c from C's boundary and its derivatives: d sd / d c = n^T,
// d sd / d phi, d n / d c (Nc) and d n / d phi (Nphi).
struct Separation {
  double sd = 0.0;
  Vec2 n{1, 0};
  double sd_phi = 0.0;
  Eigen::Matrix2d Nc = Eigen::Matrix2d::Zero();
  Vec2 Nphi = Vec2::Zero();
};

// Derivatives for one generating feature of C (sep->n set by the caller): a line n . x = h,
// sd = n . c - h (- R), or a vertex v, sd = s |c - v| (- R) with s the side of c.
void OneFeatureDerivatives(bool vertex, const Vec2& c, const Vec2& v, double s, const FeatureMotion& m, Separation* sep);

// The witness inputs of a separation in C (object frame, relative angle phi = finger theta -
// object theta) with c's Jacobians, and the generating feature's material point (`centre`: a
// point finger's centre with its Jacobian, when already at hand).
WitnessInputs ObstacleWitness(const Separation& sep, const Mat23& J_c_obj, const Mat23& J_c_fin, const Eigen::Matrix2d& Ro,
                              const Pose2& object_pose, const Pose2& finger_pose, const FeatureMotion& material,
                              const WitnessInputs* centre = nullptr);

}  // namespace pushgraph::geometry::internal
