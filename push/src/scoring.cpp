#include <pushgraph/push/scoring.h>

#include <algorithm>

#include <cmath>

namespace pushgraph::push {

bool TruthPoseAt(const std::vector<PoseSample>& truth, double t, Eigen::Vector3d* pose) {
  // theta along the shorter arc: a truth wrapped into [-pi, pi] went linearly from -3.133 to
  // +3.138 between two samples, and the states between them were scored about 180 degrees off.
  const auto it = std::lower_bound(truth.begin(), truth.end(), t - 1e-9, [](const PoseSample& a, double tt) { return a.t < tt; });
  const geometry::Pose2* before = it != truth.begin() && it != truth.end() && std::abs(it->t - t) > 1e-9 ? &(it - 1)->pose : nullptr;
  auto get = [before](const PoseSample& s) {
    Eigen::Vector3d v = s.pose.vector();
    if (before) v.z() = before->theta + geometry::WrapAngle(v.z() - before->theta);
    return v;
  };
  return StreamValueAt(truth, t, kTruthMaxGap, get, pose);
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
  Eigen::Vector3d v = (b - a) / (tb - ta);
  v.z() = geometry::WrapAngle(b.z() - a.z()) / (tb - ta);
  return v.head<2>().norm() > kMovingSpeed || std::abs(v.z()) > kMovingAngularSpeed;
}

}  // namespace pushgraph::push
