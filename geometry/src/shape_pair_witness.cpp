// Witness points and separation derivatives of the shape-pair query (header).
#include "shape_pair_witness.h"

#include <algorithm>
#include <cmath>

namespace pushgraph::geometry::internal {

Eigen::Matrix2d RotationDerivative(double theta) { return RotationDerivativeOf(Pose2{0.0, 0.0, theta}.rotation()); }

Eigen::Matrix2d RotationDerivativeOf(const Eigen::Matrix2d& R) {
  Eigen::Matrix2d dR;
  dR << -R(1, 0), -R(0, 0), R(0, 0), -R(1, 0);
  return dR;
}

namespace {

// Finger material point f: finger_point = f - rf n, object_point = f - (sd + rf) n.
// Object material point o: object_point = o + ro n, finger_point = o + (sd + ro) n.
void FillWitnessesAlongNormal(const WitnessInputs& in, double ro, double rf, ShapePairResult* r, ShapePairJacobians* J) {
  if (in.on_finger) {
    r->finger_point = in.m_w - rf * in.n_w;
    r->object_point = in.m_w - (in.sd + rf) * in.n_w;
  } else {
    r->object_point = in.m_w + ro * in.n_w;
    r->finger_point = in.m_w + (in.sd + ro) * in.n_w;
  }
  if (!J) return;
  if (in.on_finger) {
    J->J_finger_point_object_pose = in.J_m_obj - rf * in.J_n_obj;
    J->J_finger_point_finger_pose = in.J_m_fin - rf * in.J_n_fin;
    J->J_object_point_object_pose = in.J_m_obj - in.n_w * in.J_sd_obj - (in.sd + rf) * in.J_n_obj;
    J->J_object_point_finger_pose = in.J_m_fin - in.n_w * in.J_sd_fin - (in.sd + rf) * in.J_n_fin;
  } else {
    J->J_object_point_object_pose = in.J_m_obj + ro * in.J_n_obj;
    J->J_object_point_finger_pose = in.J_m_fin + ro * in.J_n_fin;
    J->J_finger_point_object_pose = in.J_m_obj + in.n_w * in.J_sd_obj + (in.sd + ro) * in.J_n_obj;
    J->J_finger_point_finger_pose = in.J_m_fin + in.n_w * in.J_sd_fin + (in.sd + ro) * in.J_n_fin;
  }
}

// At a concave corner of a rounded obstacle the touching point's normal k is not n:
// finger material: finger_point = f - rf k, object_point = finger_point - sd n;
// object material: object_point = o + ro k, finger_point = object_point + sd n.
void FillWitnessesAtCorner(const WitnessInputs& in, double ro, double rf, ShapePairResult* r, ShapePairJacobians* J) {
  if (in.on_finger) {
    r->finger_point = in.m_w - rf * in.k_w;
    r->object_point = r->finger_point - in.sd * in.n_w;
  } else {
    r->object_point = in.m_w + ro * in.k_w;
    r->finger_point = r->object_point + in.sd * in.n_w;
  }
  if (!J) return;
  if (in.on_finger) {
    J->J_finger_point_object_pose = in.J_m_obj - rf * in.J_k_obj;
    J->J_finger_point_finger_pose = in.J_m_fin - rf * in.J_k_fin;
    J->J_object_point_object_pose = J->J_finger_point_object_pose - in.n_w * in.J_sd_obj - in.sd * in.J_n_obj;
    J->J_object_point_finger_pose = J->J_finger_point_finger_pose - in.n_w * in.J_sd_fin - in.sd * in.J_n_fin;
  } else {
    J->J_object_point_object_pose = in.J_m_obj + ro * in.J_k_obj;
    J->J_object_point_finger_pose = in.J_m_fin + ro * in.J_k_fin;
    J->J_finger_point_object_pose = J->J_object_point_object_pose + in.n_w * in.J_sd_obj + in.sd * in.J_n_obj;
    J->J_finger_point_finger_pose = J->J_object_point_finger_pose + in.n_w * in.J_sd_fin + in.sd * in.J_n_fin;
  }
}

}  // namespace

void FillWitnesses(const WitnessInputs& in, double ro, double rf, ShapePairResult* r, ShapePairJacobians* J) {
  r->signed_distance = in.sd;
  r->normal = in.n_w;
  r->depth = std::max(0.0, -in.sd);
  if (J) {
    J->J_sd_object_pose = in.J_sd_obj;
    J->J_sd_finger_pose = in.J_sd_fin;
  }
  if (in.separate_contact_normal) FillWitnessesAtCorner(in, ro, rf, r, J);
  else FillWitnessesAlongNormal(in, ro, rf, r, J);
}

void OneFeatureDerivatives(bool vertex, const Vec2& c, const Vec2& v, double s, const FeatureMotion& m, Separation* sep) {
  if (!vertex) {
    sep->sd_phi = m.dn.dot(c) - m.dh;
    sep->Nphi = m.dn;
    return;
  }
  const double d = (c - v).norm();
  sep->sd_phi = -sep->n.dot(m.dv);
  if (d > 0.0) {
    const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - sep->n * sep->n.transpose();
    sep->Nc = s * P / d;
    sep->Nphi = -s * P * m.dv / d;
  }
}

WitnessInputs ObstacleWitness(const Separation& sep, const Mat23& J_c_obj, const Mat23& J_c_fin, const Eigen::Matrix2d& Ro,
                              const Pose2& object_pose, const Pose2& finger_pose, const FeatureMotion& material,
                              const WitnessInputs* centre) {
  const Eigen::Matrix2d dRo = RotationDerivativeOf(Ro);
  WitnessInputs w;
  w.sd = sep.sd;
  w.n_w = Ro * sep.n;
  w.J_sd_obj = sep.n.transpose() * J_c_obj;
  w.J_sd_obj(2) -= sep.sd_phi;
  w.J_sd_fin = sep.n.transpose() * J_c_fin;
  w.J_sd_fin(2) += sep.sd_phi;
  w.J_n_obj = Ro * sep.Nc * J_c_obj;
  w.J_n_obj.col(2) += -Ro * sep.Nphi + dRo * sep.n;
  w.J_n_fin = Ro * sep.Nc * J_c_fin;
  w.J_n_fin.col(2) += Ro * sep.Nphi;
  w.on_finger = material.finger_material;
  if (centre) {
    w.m_w = centre->m_w;
    w.J_m_fin = centre->J_m_fin;
  } else if (material.finger_material) {
    w.m_w = Act(finger_pose, material.f, &w.J_m_fin);
  } else {
    w.m_w = Act(object_pose, material.o, &w.J_m_obj);
  }
  return w;
}

}  // namespace pushgraph::geometry::internal
