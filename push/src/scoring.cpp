#include <pushgraph/push/scoring.h>

#include <algorithm>

#include <cmath>

namespace pushgraph::push {

bool TruthPoseAt(const std::vector<PoseSample>& truth, double t, Eigen::Vector3d* pose) {
  return StreamValueAt(truth, t, kTruthMaxGap, [](const PoseSample& s) { return Eigen::Vector3d(s.pose.vector()); },
                       pose);
}

bool TruthPointAt(const std::vector<PointSample>& truth, double t, Vec2* point) {
  return StreamValueAt(truth, t, kTruthMaxGap, [](const PointSample& s) { return Vec2(s.point); }, point);
}

bool TruthContactNear(const std::vector<PointSample>& truth, double t, const Vec2& point, Vec2* contact) {
  auto it = std::lower_bound(truth.begin(), truth.end(), t - 1e-9, [](const PointSample& a, double tt) { return a.t < tt; });
  int rows = 0;
  for (auto r = it; r != truth.end() && r->t <= t + 1e-9; ++r) {
    if (rows == 0 || (r->point - point).squaredNorm() < (*contact - point).squaredNorm()) *contact = r->point;
    ++rows;
  }
  return rows > 0 || TruthPointAt(truth, t, contact);
}

bool TruthForceAt(const std::vector<ForceSample>& truth, double t, Vec2* force) {
  return StreamValueAt(truth, t, kTruthMaxGap, [](const ForceSample& s) { return Vec2(s.force); }, force);
}

Eigen::Vector3d PoseError(const geometry::Pose2& estimate, const Eigen::Vector3d& truth) {
  return {estimate.x - truth.x(), estimate.y - truth.y(), geometry::WrapAngle(estimate.theta - truth.z())};
}

bool ObjectMovingAt(const std::vector<PoseSample>& truth, double t) {
  const double h = 0.01;  // s: central difference where the truth allows it, one-sided at its ends
  Eigen::Vector3d a, b;
  double ta = t - h, tb = t + h;
  if (!TruthPoseAt(truth, ta, &a)) {
    ta = t;
    if (!TruthPoseAt(truth, ta, &a)) return false;
  }
  if (!TruthPoseAt(truth, tb, &b)) {
    tb = t;
    if (!TruthPoseAt(truth, tb, &b)) return false;
  }
  if (tb - ta <= 0.0) return false;
  const Eigen::Vector3d v = (b - a) / (tb - ta);
  return v.head<2>().norm() > kMovingSpeed || std::abs(v.z()) > kMovingAngularSpeed;
}

}  // namespace pushgraph::push
