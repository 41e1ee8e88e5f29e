#pragma once
// Internal to shape registration (registration.cpp): the contacts of recordings in the object
// frame and the robust fit of a shape's placement to them (ContactFit), with the helpers the
// search shares. Not installed.
#include <pushgraph/geometry/point_query.h>
#include <pushgraph/geometry/shape_pair.h>
#include <pushgraph/graph/registration.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace pushgraph::graph::internal::registration {

using geometry::Pose2;
using geometry::Shape;
using geometry::Vec2;

inline constexpr double kPi = 3.14159265358979323846;
// The least noise the smoothed contact path is given (m): a fit of a few parameters absorbs part
// of it, so residuals alone underestimate it.
inline constexpr double kMinPathNoise = 3e-4;
// A finger whose path stays within RestRadius for this long (s) rests on one boundary point
// (Contacts::StationaryMerged): ten correlation times of the smoothed path.
inline constexpr double kMinRestSpan = 0.5;
// 2.5 noises of the smoothed path, at most the fit tolerance: with the paper's 5 mm tracker
// noise 2.5 noises are 7.6 mm, and a finger sliding 7 mm along a side in half a second was taken
// for one point (a quarter turn of the notched block then went unnoticed).
inline double RestRadius(double path_noise, const RegistrationOptions& o) {
  return std::min(2.5 * std::max(kMinPathNoise, path_noise), o.fit_tolerance);
}

/// p turned by `angle` about the origin.
Vec2 Rotate(const Vec2& p, double angle);
/// The scales a shape file is tried at: metres, centimetres, millimetres, inches, and 100 and 1000
/// (a file converted to metres twice).
inline constexpr double kUnitScales[] = {1.0, 0.01, 0.001, 0.0254, 100.0, 1000.0};
/// "millimetres", "centimetres", "inches" or "metres" for a unit scale.
const char* UnitName(double scale);
// "the file is in millimetres", or for scales 100 and 1000 "the file is 1000 times too small
// (converted from millimetres to metres twice?)"; empty for a scale that is no unit.
std::string UnitPhrase(double scale);
/// The outer rings of the core polygons as one shape without holes: what a finger can touch
/// from outside, and what symmetry is judged on.
Shape OutlineOf(const Shape& shape);
/// Points on the outline: vertices and edge midpoints of the outer rings (at most 400).
std::vector<Vec2> OutlineSamples(const Shape& shape);
// How far transform t moves the outline of the shape `file` (the largest move of its outline
// samples, each scaled and mirrored by t, then placed by t.pose).
double OutlineDisplacement(const Shape& file, const ShapeTransform& t);

// Contact samples of one or more recordings: the finger's reference point and pose in the
// object frame, the recording each comes from, and its weight (1 / samples per correlation time).
struct Contacts {
  std::vector<double> t;        // time stamp (s)
  std::vector<Vec2> q;
  std::vector<Pose2> relative;
  std::vector<int> finger;      // which finger (ContactPath::finger)
  std::vector<double> radius;   // its disk's radius
  std::vector<int> recording;
  std::vector<double> weight;
  std::vector<int> members;     // samples this one stands for (StationaryMerged)
  int recordings = 0;
  double noise = 0.0;  // of the smoothed q (ContactPath::noise), the largest of the recordings

  std::size_t size() const { return q.size(); }
  // At most `count` samples, evenly spaced, with the weights of their recordings rescaled so
  // that each recording still counts as (its span / correlation time) independent samples.
  Contacts Subsampled(int count, const std::vector<double>& spans, double correlation_time) const {
    Contacts out;
    out.recordings = recordings;
    out.noise = noise;
    const double step = std::max(1.0, static_cast<double>(q.size()) / count);
    for (double k = 0.0; static_cast<std::size_t>(k) < q.size(); k += step) {
      const std::size_t i = static_cast<std::size_t>(k);
      out.t.push_back(t[i]);
      out.q.push_back(q[i]);
      out.relative.push_back(relative[i]);
      out.finger.push_back(finger[i]);
      out.radius.push_back(radius[i]);
      out.recording.push_back(recording[i]);
      out.members.push_back(members[i]);
    }
    std::vector<int> per(recordings, 0);
    for (int r : out.recording) ++per[r];
    for (int r : out.recording) {
      const double independent = std::max(1.0, spans[r] / correlation_time);
      out.weight.push_back(std::min(1.0, independent / per[r]));
    }
    return out;
  }
  // Runs of consecutive samples of one recording and finger that stay within `within` of their
  // running mean for `min_span` seconds or longer become one sample at their mean, with their
  // summed weight. A finger resting on the object gives a cloud of samples of one boundary point;
  // fitted one by one, an outline with a corner or a hole there fits the cloud's spread better
  // than the true side does, by an amount growing with the rest's length (simulated pushes of
  // the notched block followed by a 3.5 s rest: a turn of 84 to 111 degrees "fit better" by 13
  // to 20 in log-likelihood on every seed tried, and the graph then aligned it, the finger in a
  // hole). Shorter runs are a moving finger and stay as they are.
  Contacts StationaryMerged(double within, double min_span) const;
  // What a fit reads: at most `count` samples (Subsampled), resting runs merged (StationaryMerged).
  Contacts ForFit(int count, const std::vector<double>& spans, const RegistrationOptions& o) const {
    return Subsampled(count, spans, o.correlation_time).StationaryMerged(RestRadius(noise, o), kMinRestSpan);
  }
  int SampleCount() const {
    int n = 0;
    for (int m : members) n += m;
    return n;
  }
};

// One placement of the candidate shape in the object frame, and each recording's gap.
struct Placement {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  // tx, ty, theta
  double log_scale = 0.0;                       // relative to the candidate's units
  Eigen::VectorXd gap;                          // per recording (m)
  double cost = INFINITY;
  bool sector = false;  // kept as the best of its sector of the turn, not as a local minimum
};

// Which parameters a minimization moves.
struct Active {
  bool translation = true, rotation = true, scale = false, gaps = true;
};

// Robust negative log-likelihood of a placement:
//   sum_i w_i a log(1 + (d_i / c)^2) + |centroid prior|^2 / 2 + sum_k (gap_k / gap_sigma)^2 / 2,
// d_i = sd(placed shape, q_i) - r - gap_{rec(i)}, Cauchy scale c = max(1 mm, 2 noise) and
// a = c^2 / (2 noise^2) (d^2 / (2 noise^2) for small d). Its Gauss-Newton information is the
// inverse covariance of the parameters.
class ContactFit {
 public:
  ContactFit(const Shape& shape, const Contacts& contacts, const Shape& finger, const FingerDisk& disk, double noise,
             double prior_sigma, double gap_sigma)
      : shape_(shape), c_(contacts), finger_(finger), disk_(disk), centroid_(geometry::CoreCentroid(shape)),
        prior_sigma_(prior_sigma), gap_sigma_(gap_sigma) {
    set_noise(noise);
  }

  /// The exact finger (polygonal fingers) through `shared` when it queries this fit's shape and
  /// finger (the same shape impl): its Minkowski obstacles, one per relative angle, are then built
  /// once for every fit of one candidate file instead of once per fit. Returns the querier used.
  std::shared_ptr<const geometry::ShapePairQuerier> UseExactFinger(std::shared_ptr<const geometry::ShapePairQuerier> shared = {}) {
    if (disk_.exact) return nullptr;
    if (querier_) return querier_;
    if (shared && &shared->object().impl() == &shape_.impl() && &shared->finger().impl() == &finger_.impl()) {
      querier_ = std::move(shared);
      return querier_;
    }
    geometry::ShapePairQuerier::Options o;
    o.angle_cache_resolution = 5e-3;
    o.max_cached_angles = 2048;
    o.check_rounded_depth = false;
    querier_ = std::make_shared<const geometry::ShapePairQuerier>(shape_, finger_, o);
    return querier_;
  }
  void set_noise(double noise) {
    noise_ = noise;
    cauchy_ = std::max(1e-3, 2.0 * noise);
    a_ = cauchy_ * cauchy_ / (2.0 * noise * noise);
  }
  std::size_t size() const { return c_.size(); }
  Placement Start() const {
    Placement p;
    p.gap = Eigen::VectorXd::Zero(c_.recordings);
    return p;
  }

  // The gap of sample i without the recording's calibration gap (sd - r, or the exact
  // separation), and its gradient with respect to (tx, ty, theta, log s).
  double RawGap(std::size_t i, const Placement& p, Eigen::Vector4d* J) const {
    const Pose2 T{p.x.x(), p.x.y(), p.x.z()};
    if (querier_ && c_.finger[i] == 0) {  // finger 0's exact shape; other fingers as disks
      geometry::ShapePairJacobians Js;
      const auto r = querier_->Query(T, c_.relative[i], &Js);
      if (J) *J << Js.J_sd_object_pose.transpose(), 0.0;
      return r.signed_distance;
    }
    const double s = std::exp(p.log_scale);
    Eigen::Matrix<double, 2, 3> J_local_T;
    const Vec2 local = geometry::InverseAct(T, c_.q[i], J ? &J_local_T : nullptr);
    // The shape scaled by s: s * sd(S, local / s).
    const geometry::PointQuery pq = geometry::QueryPoint(shape_, Vec2(local / s));
    const double sd = s * pq.signed_distance;
    if (J) {
      J->head<3>() = (pq.normal.transpose() * J_local_T).transpose();
      (*J)(3) = sd - pq.normal.dot(local);
    }
    return sd - c_.radius[i];
  }
  double Gap(std::size_t i, const Placement& p) const { return RawGap(i, p, nullptr) - p.gap(c_.recording[i]); }

  // The scaled centroid placed by T, over the prior sigma, with its Jacobian (tx, ty, theta, log s).
  Vec2 Prior(const Placement& p, Eigen::Matrix<double, 2, 4>* J) const {
    const Vec2 sc = std::exp(p.log_scale) * centroid_;
    if (J) {
      J->setZero();
      J->block<2, 2>(0, 0) = Eigen::Matrix2d::Identity();
      J->col(2) = Rotate(sc, p.x.z() + 0.5 * kPi);
      J->col(3) = Rotate(sc, p.x.z());
      *J /= prior_sigma_;
    }
    return (Rotate(sc, p.x.z()) + p.x.head<2>()) / prior_sigma_;
  }

  double Cost(const Placement& p, bool gap_prior = true) const {
    double f = 0.0;
    for (std::size_t i = 0; i < size(); ++i) {
      const double z = Gap(i, p) / cauchy_;
      f += c_.weight[i] * a_ * std::log1p(z * z);
    }
    f += 0.5 * Prior(p, nullptr).squaredNorm();
    if (gap_prior && gap_sigma_ > 0.0) f += 0.5 * (p.gap / gap_sigma_).squaredNorm();
    return f;
  }

  // Levenberg-Marquardt over the active parameters; returns the final cost. `info`: the
  // Gauss-Newton information in the order (active of tx, ty, theta, log s), then the gaps.
  double Minimize(Placement* p, const Active& act, int max_iterations, Eigen::MatrixXd* info = nullptr) const {
    std::vector<int> idx;  // indices into (tx, ty, theta, log s)
    if (act.translation) { idx.push_back(0); idx.push_back(1); }
    if (act.rotation) idx.push_back(2);
    if (act.scale) idx.push_back(3);
    const int np = static_cast<int>(idx.size());
    const int ng = act.gaps && gap_sigma_ > 0.0 ? c_.recordings : 0;
    const int n = np + ng;
    auto normal_equations = [&](const Placement& pl, Eigen::MatrixXd* H, Eigen::VectorXd* g) {
      H->setZero(n, n);
      g->setZero(n);
      double f = 0.0;
      Eigen::Vector4d J4;
      // A sample's Jacobian row: the active placement parameters, and -1 at its recording's gap;
      // w J J^T accumulated on those entries only (the gaps' rows are otherwise zero).
      double J[4];
      for (std::size_t i = 0; i < size(); ++i) {
        const double d = RawGap(i, pl, &J4) - pl.gap(c_.recording[i]);
        const double z2 = (d / cauchy_) * (d / cauchy_);
        f += c_.weight[i] * a_ * std::log1p(z2);
        const double w = c_.weight[i] / (noise_ * noise_ * (1.0 + z2));  // IRLS weight of the Cauchy loss
        for (int k = 0; k < np; ++k) J[k] = J4(idx[k]);
        for (int a = 0; a < np; ++a) {
          const double wa = w * J[a];
          for (int b = 0; b < np; ++b) (*H)(a, b) += wa * J[b];
          (*g)(a) += w * d * J[a];
        }
        if (ng > 0) {
          const int r = np + c_.recording[i];
          for (int a = 0; a < np; ++a) {
            (*H)(a, r) -= w * J[a];
            (*H)(r, a) -= w * J[a];
          }
          (*H)(r, r) += w;
          (*g)(r) -= w * d;
        }
      }
      Eigen::Matrix<double, 2, 4> Jp;
      const Vec2 rp = Prior(pl, &Jp);
      f += 0.5 * rp.squaredNorm();
      for (int a = 0; a < np; ++a) {
        (*g)(a) += Jp.col(idx[a]).dot(rp);
        for (int b = 0; b < np; ++b) (*H)(a, b) += Jp.col(idx[a]).dot(Jp.col(idx[b]));
      }
      if (gap_sigma_ > 0.0) f += 0.5 * (pl.gap / gap_sigma_).squaredNorm();
      for (int k = 0; k < ng; ++k) {
        (*H)(np + k, np + k) += 1.0 / (gap_sigma_ * gap_sigma_);
        (*g)(np + k) += pl.gap(k) / (gap_sigma_ * gap_sigma_);
      }
      return f;
    };
    auto apply = [&](const Placement& pl, const Eigen::VectorXd& step) {
      Placement out = pl;
      Eigen::Vector4d v;
      v << pl.x, pl.log_scale;
      for (int k = 0; k < np; ++k) v(idx[k]) += step(k);
      out.x = v.head<3>();
      out.log_scale = v(3);
      for (int k = 0; k < ng; ++k) out.gap(k) += step(np + k);
      return out;
    };
    Eigen::MatrixXd H;
    Eigen::VectorXd g;
    double f = normal_equations(*p, &H, &g);
    double lambda = 1e-4;
    for (int it = 0; it < max_iterations && n > 0; ++it) {
      Eigen::MatrixXd A = H;
      A.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
      const Eigen::VectorXd step = -A.ldlt().solve(g);
      if (!step.allFinite()) break;
      const Placement trial = apply(*p, step);
      Eigen::MatrixXd Ht;
      Eigen::VectorXd gt;
      const double ft = normal_equations(trial, &Ht, &gt);
      if (ft < f) {
        const bool converged = f - ft < 1e-10 * (1.0 + f);
        *p = trial;
        f = ft;
        H = Ht;
        g = gt;
        lambda = std::max(lambda * 0.3, 1e-9);
        if (converged) break;
      } else {
        lambda *= 10.0;
        if (lambda > 1e8) break;
      }
    }
    p->cost = f;
    if (info) *info = H;
    return f;
  }

 private:
  const Shape& shape_;
  const Contacts& c_;
  const Shape& finger_;
  FingerDisk disk_;
  Vec2 centroid_;
  double prior_sigma_, gap_sigma_;
  double noise_ = 1e-3, cauchy_ = 2e-3, a_ = 2.0;
  std::shared_ptr<const geometry::ShapePairQuerier> querier_;
};

/// Whether placements a and b of a shape coincide on its outline within tolerance.
bool SamePlacement(const Shape& outline, const std::vector<Vec2>& samples, const Placement& a, const Placement& b,
                   double tolerance);
/// A pose stream smoothed by the estimator's motion-only prior: pose measurements and the
/// white-noise-acceleration constant-velocity factor (factors.h), solved by the chain solver.
std::vector<push::PoseSample> Smoothed(const std::vector<push::PoseSample>& in, double sigma_t, double sigma_r,
                                       double accel_t, double accel_r);
/// The white noise of a pose stream from its own samples (robust second differences).
void StreamNoise(const std::vector<push::PoseSample>& s, double* trans, double* rot);
/// Every recording's contacts, pooled, with each recording's span (s).
Contacts PoolContacts(const std::vector<const push::Trajectory*>& recordings, const RegistrationOptions& o,
                      std::vector<double>* spans);
/// The shape as given against the contacts: median |gap| and the share penetrating beyond the
/// tolerance max(fit_tolerance, 2.5 noise of the smoothed path).
ShapeFitCheck CheckContacts(const Shape& shape, const Shape& finger, const Contacts& c, const RegistrationOptions& o);

}  // namespace pushgraph::graph::internal::registration
