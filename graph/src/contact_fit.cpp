// Contacts of recordings and the helpers of shape registration (contact_fit.h).
#include "contact_fit.h"

#include <pushgraph/graph/chain_solver.h>
#include <pushgraph/graph/factors.h>

#include "text.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace pushgraph::graph::internal::registration {

using internal::Median;

Vec2 Rotate(const Vec2& p, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

const char* UnitName(double scale) {
  if (scale == 0.001) return "millimetres";
  if (scale == 0.01) return "centimetres";
  if (scale == 0.0254) return "inches";
  return "metres";
}

std::string UnitPhrase(double scale) {
  if (scale == 100.0 || scale == 1000.0) {
    return "the file is " + std::to_string(static_cast<int>(scale)) + " times too small (converted from " +
           (scale == 100.0 ? "centimetres" : "millimetres") + " to metres twice?)";
  }
  if (scale == 0.001 || scale == 0.01 || scale == 0.0254) return std::string("the file is in ") + UnitName(scale);
  return "";
}

// The outer rings of the core polygons as one shape without holes: what a finger can touch
// from outside, and what symmetry is judged on.
Shape OutlineOf(const Shape& shape) {
  std::vector<geometry::Polygon> outers;
  for (const geometry::Polygon& p : shape.polygons()) outers.push_back({p.outer, {}});
  return Shape::FromPolygons(std::move(outers), shape.radius());
}

// Points on the outline: vertices and edge midpoints of the outer rings (at most 400).
std::vector<Vec2> OutlineSamples(const Shape& shape) {
  std::vector<Vec2> pts;
  for (const geometry::Polygon& p : shape.polygons()) {
    const int n = static_cast<int>(p.outer.size());
    for (int i = 0; i < n; ++i) {
      pts.push_back(p.outer[i]);
      if (n > 1) pts.push_back(0.5 * (p.outer[i] + p.outer[(i + 1) % n]));
    }
  }
  if (pts.size() > 400) {
    std::vector<Vec2> fewer;
    const double step = static_cast<double>(pts.size()) / 400.0;
    for (int i = 0; i < 400; ++i) fewer.push_back(pts[static_cast<std::size_t>(i * step)]);
    pts = std::move(fewer);
  }
  return pts;
}

double OutlineDisplacement(const Shape& file, const ShapeTransform& t) {
  double moved = 0.0;
  for (const Vec2& p : OutlineSamples(file)) {
    const Vec2 file_point(t.scale * p.x(), (t.mirrored ? -1.0 : 1.0) * t.scale * p.y());
    moved = std::max(moved, (geometry::Act(t.pose, file_point) - p).norm());
  }
  return moved;
}

// Whether placements a and b of a shape coincide on its outline within tolerance.
bool SamePlacement(const Shape& outline, const std::vector<Vec2>& samples, const Placement& a, const Placement& b,
                   double tolerance) {
  const Pose2 Ta{a.x.x(), a.x.y(), a.x.z()}, Tb{b.x.x(), b.x.y(), b.x.z()};
  const Pose2 rel = geometry::Between(Tb, Ta);  // Tb^-1 Ta
  const double sa = std::exp(a.log_scale), sb = std::exp(b.log_scale);
  for (const Vec2& p : samples) {
    const Vec2 w = geometry::Act(rel, Vec2(sa * p)) / sb;
    if (std::abs(sb * geometry::QueryPoint(outline, w).signed_distance) > tolerance) return false;
  }
  return true;
}

// A pose stream smoothed by the estimator's motion-only prior: pose measurements and the
// white-noise-acceleration constant-velocity factor (factors.h), solved with Ceres.
std::vector<push::PoseSample> Smoothed(const std::vector<push::PoseSample>& in, double sigma_t,
                                                double sigma_r, double accel_t, double accel_r) {
  const int n = static_cast<int>(in.size());
  if (n < 3) return in;
  std::vector<double> x(3 * n);
  for (int i = 0; i < n; ++i) {
    x[3 * i] = in[i].pose.x;
    x[3 * i + 1] = in[i].pose.y;
    // Continuous angles: the chart coordinate must not jump by 2 pi between samples.
    x[3 * i + 2] = i == 0 ? in[0].pose.theta : x[3 * i - 1] + geometry::WrapAngle(in[i].pose.theta - x[3 * i - 1]);
  }
  ceres::Problem problem;
  for (int i = 0; i < n; ++i) {
    problem.AddResidualBlock(new PoseMeasurementFactor(in[i].pose, sigma_t, sigma_r), nullptr, &x[3 * i]);
    if (i < 2) continue;
    const double dt1 = in[i - 1].t - in[i - 2].t, dt2 = in[i].t - in[i - 1].t;
    if (!(dt1 > 0.0 && dt2 > 0.0)) continue;
    problem.AddResidualBlock(new ConstantVelocityFactor(dt1, dt2, ConstantVelocitySigma(accel_t, dt1, dt2),
                                                        ConstantVelocitySigma(accel_r, dt1, dt2)),
                             nullptr, &x[3 * i - 6], &x[3 * i - 3], &x[3 * i]);
  }
  // The chain solver (chain_solver.h): the poses are added in time order, so J^T J is banded.
  ChainSolverOptions options;
  options.max_iterations = 10;
  options.function_tolerance = 1e-4;
  ChainSolver(problem).Solve(options);
  std::vector<push::PoseSample> out = in;
  for (int i = 0; i < n; ++i) out[i].pose = {x[3 * i], x[3 * i + 1], x[3 * i + 2]};
  return out;
}

// The white noise of a pose stream from its own samples: the second difference of three
// consecutive samples is sqrt(6) sigma for white noise on a smooth motion; robust through the
// median absolute value (x 1.4826). Triples with uneven steps (gaps) are skipped.
void StreamNoise(const std::vector<push::PoseSample>& s, double* trans, double* rot) {
  std::vector<double> dt, dx, da;
  for (std::size_t i = 1; i < s.size(); ++i) dt.push_back(s[i].t - s[i - 1].t);
  const double step = Median(dt);
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {
    const double a = s[i].t - s[i - 1].t, b = s[i + 1].t - s[i].t;
    if (!(a > 0.5 * step && a < 1.5 * step && b > 0.5 * step && b < 1.5 * step)) continue;
    const Vec2 d = s[i + 1].pose.translation() - 2.0 * s[i].pose.translation() + s[i - 1].pose.translation();
    dx.push_back(std::abs(d.x()));
    dx.push_back(std::abs(d.y()));
    da.push_back(std::abs(geometry::WrapAngle(s[i + 1].pose.theta - s[i].pose.theta) -
                          geometry::WrapAngle(s[i].pose.theta - s[i - 1].pose.theta)));
  }
  *trans = dx.empty() ? 0.0 : 1.4826 * Median(dx) / std::sqrt(6.0);
  *rot = da.empty() ? 0.0 : 1.4826 * Median(da) / std::sqrt(6.0);
}

// Every recording's contacts, pooled, with each recording's span (s).
Contacts PoolContacts(const std::vector<const push::Trajectory*>& recordings, const RegistrationOptions& o,
                      std::vector<double>* spans) {
  if (recordings.empty() || recordings.front() == nullptr) throw GraphError("registration: no recording");
  const push::Trajectory& first = *recordings.front();
  if (first.object.shape.empty()) throw GraphError("registration: the object shape is empty");
  Contacts pooled;
  pooled.recordings = static_cast<int>(recordings.size());
  spans->clear();
  for (std::size_t k = 0; k < recordings.size(); ++k) {
    const push::Trajectory& traj = *recordings[k];
    if (traj.measured.object_pose.empty() || traj.measured.finger_pose.empty()) {
      throw GraphError("registration: recording " + std::to_string(k) + " has no object or no finger pose measurements");
    }
    if (k > 0 && (traj.object.shape.num_vertices() != first.object.shape.num_vertices() ||
                  traj.finger.shape.num_vertices() != first.finger.shape.num_vertices())) {
      throw GraphError("registration: recording " + std::to_string(k) + " has another object or finger shape than the first");
    }
    const ContactPath path = MeasuredContactPath(traj, o);
    pooled.t.insert(pooled.t.end(), path.t.begin(), path.t.end());
    pooled.q.insert(pooled.q.end(), path.q.begin(), path.q.end());
    pooled.relative.insert(pooled.relative.end(), path.relative.begin(), path.relative.end());
    pooled.finger.insert(pooled.finger.end(), path.finger.begin(), path.finger.end());
    pooled.radius.insert(pooled.radius.end(), path.radius.begin(), path.radius.end());
    pooled.recording.insert(pooled.recording.end(), path.q.size(), static_cast<int>(k));
    spans->push_back(path.t.empty() ? 0.0 : path.t.back() - path.t.front());
    pooled.noise = std::max(pooled.noise, path.noise);
  }
  if (pooled.q.size() < 8) {
    throw GraphError("registration: only " + std::to_string(pooled.q.size()) +
                     " finger samples in contact with an object pose near them (at least 8 needed)");
  }
  pooled.weight.assign(pooled.q.size(), 1.0);
  pooled.members.assign(pooled.q.size(), 1);
  return pooled;
}

Contacts Contacts::StationaryMerged(double within, double min_span) const {
  Contacts out;
  out.recordings = recordings;
  out.noise = noise;
  for (std::size_t begin = 0; begin < q.size();) {
    std::size_t end = begin + 1;
    Vec2 mean = q[begin];
    while (end < q.size() && recording[end] == recording[begin] && finger[end] == finger[begin] &&
           (q[end] - mean).norm() <= within) {
      mean += (q[end] - mean) / static_cast<double>(end - begin + 1);
      ++end;
    }
    // Moving: too short a run, or one whose first and last thirds lie apart (a finger sliding
    // slowly along a side stays near its running mean, but its thirds drift).
    bool rests = t[end - 1] - t[begin] >= min_span;
    if (rests) {
      const std::size_t third = (end - begin) / 3;
      Vec2 first = Vec2::Zero(), last = Vec2::Zero();
      for (std::size_t i = 0; i < third; ++i) first += q[begin + i], last += q[end - 1 - i];
      rests = third > 0 && (last - first).norm() / static_cast<double>(third) <= 0.5 * within;
    }
    if (!rests) end = begin + 1;  // the sample alone
    Vec2 t_sum = Vec2::Zero();
    double turn_sum = 0.0, weight_sum = 0.0;
    int member_sum = 0;
    for (std::size_t i = begin; i < end; ++i) {
      t_sum += Vec2(relative[i].x, relative[i].y);
      turn_sum += geometry::WrapAngle(relative[i].theta - relative[begin].theta);
      weight_sum += weight[i];
      member_sum += members[i];
    }
    const double n = static_cast<double>(end - begin);
    out.t.push_back(0.5 * (t[begin] + t[end - 1]));
    out.q.push_back(end - begin == 1 ? q[begin] : mean);
    out.relative.push_back(Pose2{t_sum.x() / n, t_sum.y() / n, relative[begin].theta + turn_sum / n});
    out.finger.push_back(finger[begin]);
    out.radius.push_back(radius[begin]);
    out.recording.push_back(recording[begin]);
    out.weight.push_back(weight_sum);
    out.members.push_back(member_sum);
    begin = end;
  }
  return out;
}

// The shape as given against the contacts: median |gap| and the share penetrating beyond the
// tolerance max(fit_tolerance, 2.5 noise of the smoothed path).
ShapeFitCheck CheckContacts(const Shape& shape, const Shape& finger, const Contacts& c, const RegistrationOptions& o) {
  ShapeFitCheck check;
  check.tolerance = std::max(o.fit_tolerance, 2.5 * c.noise);
  ContactFit fit(shape, c, finger, FingerAsDisk(finger), 1e-3, 1.0, 0.0);
  fit.UseExactFinger();
  const Placement identity = fit.Start();
  // Weighted: a merged resting spot counts as the time it covers (Contacts::StationaryMerged).
  std::vector<double> gaps;
  double penetrating = 0.0, total = 0.0;
  for (std::size_t i = 0; i < fit.size(); ++i) {
    const double g = fit.Gap(i, identity);
    gaps.push_back(std::abs(g));
    penetrating += g < -check.tolerance ? c.weight[i] : 0.0;
    total += c.weight[i];
  }
  check.samples = c.SampleCount();
  check.gap_median = WeightedMedian(gaps, c.weight);
  check.penetration_share = total > 0.0 ? penetrating / total : 0.0;
  check.fits = check.gap_median <= check.tolerance && check.penetration_share <= 0.1;
  return check;
}

}  // namespace pushgraph::graph::internal::registration
