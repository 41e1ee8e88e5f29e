// Quasi-static pushing with several contacts (see multi_contact.h and docs/simulator.md).
//
// Per mode the unknowns are the twist xi (3) and the contact force coordinates lambda (K: two
// per sticking contact, in the (n, t) basis; one per sliding contact, along its cone edge). The
// K kinematic rows G xi = b and the three load rows L(xi) = B lambda make a square system.
// Start: for the ellipsoid surface F^T A F = 1 the twist is xi = k A F, so with F = B lambda the
// kinematic rows are linear in mu = k lambda: G A B mu = b (Lynch and Mason 1996's motion-cone
// computation, here for several contacts); this start is exact for the ellipsoid model. Newton's
// method (numeric dL/dxi by central differences, minimum-norm steps by a complete orthogonal
// decomposition, backtracking) then solves the exact surface's system.
#include <pushgraph/push/multi_contact.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <utility>

namespace pushgraph::push {
namespace {

using geometry::Pose2;
using limit_surface::Summary;
using limit_surface::Support;

double Cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
Vec2 Perp(const Vec2& v) { return {-v.y(), v.x()}; }  // z x v

enum class Mode { kStick, kSlidePlus, kSlideMinus, kSlideFrictionless, kOpen };

// One contact in body axes (about the centre of pressure).
struct BodyContact {
  Vec2 r, n, t, u;  // lever arm, inward normal, tangent z x n, finger velocity
  double mu = 0.0;
};

struct ModeSolution {
  Eigen::Vector3d xi;          // (vx, vy, omega)
  Eigen::VectorXd lambda;      // force coordinates
  Load load;
  double wrench_residual = 0.0;
  double kinematic_residual = 0.0;
};

int SlideSign(Mode m) { return m == Mode::kSlidePlus ? 1 : (m == Mode::kSlideMinus ? -1 : 0); }
bool IsSlide(Mode m) { return m == Mode::kSlidePlus || m == Mode::kSlideMinus || m == Mode::kSlideFrictionless; }

// d v_i / d xi = [I, z x r]: the contact point's velocity row(s).
Eigen::Matrix<double, 2, 3> PointVelocityMap(const Vec2& r) {
  Eigen::Matrix<double, 2, 3> m;
  m << 1.0, 0.0, -r.y(), 0.0, 1.0, r.x();
  return m;
}

Eigen::Vector3d Wrench(const Vec2& r, const Vec2& f) { return {f.x(), f.y(), Cross(r, f)}; }

}  // namespace

struct MultiPushingModel::Impl {
  MultiPushingSpec spec;
  std::vector<PushingModel> models;  // one per finger: its querier; models[0] also the object's surface

  const PushingModel& object_model() const { return models.front(); }
  Load SurfaceLoad(const Twist& t) const { return object_model().SurfaceLoad(t); }

  // Solves one mode for finger velocities of unit scale; false when Newton's method does not
  // reach a solution.
  bool Solve(const std::vector<BodyContact>& contacts, const std::vector<Mode>& modes, ModeSolution* out) const {
    const Summary& s = object_model().summary();
    const int count = static_cast<int>(contacts.size());
    int K = 0;
    for (Mode m : modes) K += m == Mode::kStick ? 2 : (IsSlide(m) ? 1 : 0);
    if (K == 0) return false;
    Eigen::MatrixXd G(K, 3), B(3, K);
    Eigen::VectorXd b(K), tangential = Eigen::VectorXd::Zero(K);  // 1: a friction coordinate
    int row = 0;
    for (int i = 0; i < count; ++i) {
      const BodyContact& c = contacts[i];
      const Eigen::Matrix<double, 2, 3> P = PointVelocityMap(c.r);
      if (modes[i] == Mode::kStick) {
        G.middleRows(row, 2) = P;
        b.segment(row, 2) = c.u;
        B.col(row) = Wrench(c.r, c.n);
        B.col(row + 1) = Wrench(c.r, c.t);
        tangential(row + 1) = 1.0;
        row += 2;
      } else if (IsSlide(modes[i])) {
        G.row(row) = c.n.transpose() * P;
        b(row) = c.n.dot(c.u);
        B.col(row) = Wrench(c.r, c.n + SlideSign(modes[i]) * c.mu * c.t);
        row += 1;
      }
    }
    const Eigen::Vector3d load_scale(1.0 / s.f_max, 1.0 / s.f_max, 1.0 / s.tau_max);
    auto load_of = [&](const Eigen::Vector3d& xi) {
      const Load L = SurfaceLoad({xi(0), xi(1), xi(2)});
      return Eigen::Vector3d(L.force.x(), L.force.y(), L.torque);
    };
    // The least-friction force coordinates for a load: lambda = lambda_p + N z over the solutions
    // of B lambda = load (lambda_p the minimum-norm one, N a basis of B's kernel), z minimizing
    // the tangential coordinates (then the norm): exact when the split is unique.
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> b_cod(load_scale.asDiagonal() * B);
    const Eigen::MatrixXd kernel = Eigen::FullPivLU<Eigen::MatrixXd>(B).kernel();
    const bool indeterminate = b_cod.rank() < K && kernel.cols() > 0 && kernel.norm() > 0.0;
    const Eigen::MatrixXd TN = tangential.asDiagonal() * kernel;
    auto forces_for = [&](const Eigen::Vector3d& load) -> Eigen::VectorXd {
      Eigen::VectorXd lambda = b_cod.solve(load_scale.cwiseProduct(load));
      if (indeterminate) lambda -= kernel * TN.completeOrthogonalDecomposition().solve(tangential.cwiseProduct(lambda));
      return lambda;
    };

    // Start: the ellipsoid's linear solution.
    const Eigen::Matrix3d& A = object_model().ellipsoid().A;
    const Eigen::MatrixXd GAB = G * A * B;
    const Eigen::VectorXd mu0 = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(GAB).solve(b);
    Eigen::Vector3d xi = A * B * mu0;
    if (!xi.allFinite() || xi.norm() == 0.0) return false;
    Eigen::VectorXd lambda;
    try {
      lambda = forces_for(load_of(xi));
    } catch (const std::exception&) {
      return false;
    }

    auto residual = [&](const Eigen::Vector3d& x, const Eigen::VectorXd& l, Eigen::VectorXd* r) {
      r->resize(K + 3);
      r->head(K) = G * x - b;
      r->tail(3) = load_scale.cwiseProduct(load_of(x) - B * l);
    };
    Eigen::VectorXd r;
    try {
      residual(xi, lambda, &r);
      const double c = s.c;
      for (int iteration = 0; iteration < 40; ++iteration) {
        const double norm = r.lpNorm<Eigen::Infinity>();
        if (norm <= 1e-14) break;
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(K + 3, 3 + K);
        J.topLeftCorner(K, 3) = G;
        const double size = std::hypot(std::hypot(xi(0), xi(1)), c * xi(2));
        for (int j = 0; j < 3; ++j) {
          const double h = 1e-6 * size / (j == 2 ? c : 1.0);
          Eigen::Vector3d plus = xi, minus = xi;
          plus(j) += h;
          minus(j) -= h;
          J.block(K, j, 3, 1) = load_scale.cwiseProduct(load_of(plus) - load_of(minus)) / (2.0 * h);
        }
        J.bottomRightCorner(3, K) = -(load_scale.asDiagonal() * B);
        const Eigen::VectorXd step = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(J).solve(-r);
        double t = 1.0;
        bool improved = false;
        for (int k = 0; k < 30; ++k, t *= 0.5) {
          const Eigen::Vector3d x_try = xi + t * step.head(3);
          if (x_try.norm() == 0.0) continue;
          const Eigen::VectorXd l_try = lambda + t * step.tail(K);
          Eigen::VectorXd r_try;
          residual(x_try, l_try, &r_try);
          if (r_try.lpNorm<Eigen::Infinity>() < norm) {
            xi = x_try;
            lambda = l_try;
            r = r_try;
            improved = true;
            break;
          }
        }
        if (!improved) break;
      }
      // Among the force splits that carry this load, the least-friction one.
      const Eigen::Vector3d load = load_of(xi);
      lambda = forces_for(load);
      residual(xi, lambda, &r);
      out->xi = xi;
      out->lambda = lambda;
      out->load = {Vec2(load(0), load(1)), load(2)};
      out->kinematic_residual = r.head(K).lpNorm<Eigen::Infinity>();
      out->wrench_residual = r.tail(3).lpNorm<Eigen::Infinity>();
    } catch (const std::exception&) {
      return false;  // a zero or non-finite twist on the way
    }
    return out->kinematic_residual <= 1e-10 && out->wrench_residual <= 1e-10;
  }
};

MultiPushingModel::MultiPushingModel(MultiPushingSpec spec) : impl_(std::make_unique<Impl>()) {
  if (spec.fingers.empty()) throw PushError("MultiPushingSpec.fingers is empty (at least one finger)");
  if (!(spec.max_contacts >= 1 && spec.max_contacts <= 8))
    throw PushError("MultiPushingSpec.max_contacts must be in [1, 8] (got " + std::to_string(spec.max_contacts) + ")");
  if (!(std::isfinite(spec.max_contact_depth) && spec.max_contact_depth >= 0.0))
    throw PushError("MultiPushingSpec.max_contact_depth must be finite and >= 0");
  for (std::size_t i = 0; i < spec.fingers.size(); ++i) {
    PushingSpec single;
    single.object = spec.object;
    single.finger = spec.fingers[i];
    single.surface = spec.surface;
    single.contact_tolerance = spec.contact_tolerance;
    single.penetration_tolerance = spec.penetration_tolerance;
    try {
      impl_->models.emplace_back(std::move(single));
    } catch (const PushError& e) {
      std::string what = e.what();
      if (what.find("finger") != std::string::npos)
        throw PushError("MultiPushingSpec.fingers[" + std::to_string(i) + "]: " + what);
      throw;
    } catch (const geometry::GeometryError& e) {
      throw PushError("MultiPushingSpec.fingers[" + std::to_string(i) + "]: " + e.what());
    }
  }
  impl_->spec = std::move(spec);
}
MultiPushingModel::~MultiPushingModel() = default;
MultiPushingModel::MultiPushingModel(MultiPushingModel&&) noexcept = default;
MultiPushingModel& MultiPushingModel::operator=(MultiPushingModel&&) noexcept = default;

const MultiPushingSpec& MultiPushingModel::spec() const { return impl_->spec; }
const Summary& MultiPushingModel::summary() const { return impl_->object_model().summary(); }
const Support& MultiPushingModel::support() const { return impl_->object_model().support(); }
Load MultiPushingModel::SurfaceLoad(const Twist& twist) const { return impl_->SurfaceLoad(twist); }
Pose2 MultiPushingModel::ApplyTwist(const Pose2& object_pose, const Twist& twist) const {
  return impl_->object_model().ApplyTwist(object_pose, twist);
}

namespace {
void CheckFingers(const char* where, std::size_t expected, const std::vector<Pose2>& poses,
                  const std::vector<Vec2>* motions) {
  if (poses.size() != expected)
    throw PushError(std::string(where) + ": " + std::to_string(poses.size()) + " finger poses for " +
                    std::to_string(expected) + " fingers");
  if (motions && motions->size() != expected)
    throw PushError(std::string(where) + ": " + std::to_string(motions->size()) + " finger motions for " +
                    std::to_string(expected) + " fingers");
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!poses[i].vector().allFinite())
      throw PushError(std::string(where) + ": finger " + std::to_string(i) + "'s pose is not finite");
    if (motions && !(*motions)[i].allFinite())
      throw PushError(std::string(where) + ": finger " + std::to_string(i) + "'s motion is not finite");
  }
}
}  // namespace

double MultiPushingModel::Separation(const Pose2& object_pose, const std::vector<Pose2>& finger_poses, int* finger) const {
  CheckFingers("MultiPushingModel::Separation", impl_->models.size(), finger_poses, nullptr);
  double best = 0.0;
  for (std::size_t i = 0; i < finger_poses.size(); ++i) {
    const double sd = impl_->models[i].querier().Query(object_pose, finger_poses[i]).signed_distance;
    if (i == 0 || sd < best) {
      best = sd;
      if (finger) *finger = static_cast<int>(i);
    }
  }
  return best;
}

MultiPushResponse MultiPushingModel::Respond(const Pose2& object_pose, const std::vector<Pose2>& finger_poses,
                                             const std::vector<Vec2>& finger_motions) const {
  const Impl& m = *impl_;
  const MultiPushingSpec& spec = m.spec;
  CheckFingers("MultiPushingModel::Respond", m.models.size(), finger_poses, &finger_motions);
  if (!object_pose.vector().allFinite()) throw PushError("MultiPushingModel::Respond: the object pose is not finite");
  MultiPushResponse out;
  out.finger_force.assign(finger_poses.size(), Vec2::Zero());
  const Eigen::Matrix2d R = object_pose.rotation();
  const Vec2 cop = m.object_model().support().centre_of_pressure;
  std::vector<BodyContact> body;
  double speed = 0.0;
  for (const Vec2& u : finger_motions) speed = std::max(speed, u.norm());
  for (std::size_t f = 0; f < finger_poses.size(); ++f) {
    const std::vector<geometry::ContactPoint> found =
        geometry::FindContacts(spec.object.shape, object_pose, spec.fingers[f].shape, finger_poses[f],
                               {spec.contact_tolerance, spec.max_contact_depth});
    for (const geometry::ContactPoint& c : found) {
      ContactState state;
      state.finger = static_cast<int>(f);
      state.point = c.object_point;
      state.normal = -c.normal;
      state.separation = c.separation;
      out.contacts.push_back(state);
      BodyContact bc;
      bc.r = geometry::InverseAct(object_pose, c.object_point) - cop;
      bc.n = (R.transpose() * state.normal).normalized();
      bc.t = Perp(bc.n);
      bc.u = R.transpose() * finger_motions[f];  // divided by `speed` below
      bc.mu = spec.fingers[f].mu_contact;
      body.push_back(bc);
    }
  }
  out.touching = !out.contacts.empty();
  const bool pushes = std::any_of(body.begin(), body.end(), [](const BodyContact& c) { return c.u.dot(c.n) > 0.0; });
  if (!out.touching || speed == 0.0 || !pushes) return out;
  // Solved for unit speed (the twist scales with the motion; the load does not), so that tiny
  // motions (a path's last 1e-17 m) are as well conditioned as any.
  for (BodyContact& c : body) c.u /= speed;
  const int count = static_cast<int>(body.size());
  if (count > spec.max_contacts)
    throw PushError("MultiPushingModel::Respond: " + std::to_string(count) + " contacts at once, more than max_contacts " +
                    std::to_string(spec.max_contacts));

  // Every mode, ordered by the number of open, then of sliding contacts.
  std::vector<std::vector<Mode>> modes(1);
  for (int i = 0; i < count; ++i) {
    const std::vector<Mode> choices = body[i].mu > 0.0
                                          ? std::vector<Mode>{Mode::kStick, Mode::kSlidePlus, Mode::kSlideMinus, Mode::kOpen}
                                          : std::vector<Mode>{Mode::kSlideFrictionless, Mode::kOpen};
    std::vector<std::vector<Mode>> next;
    for (const auto& partial : modes)
      for (Mode c : choices) {
        next.push_back(partial);
        next.back().push_back(c);
      }
    modes = std::move(next);
  }
  auto rank = [](const std::vector<Mode>& v) {
    int open = 0, slide = 0;
    for (Mode c : v) open += c == Mode::kOpen, slide += IsSlide(c);
    return std::make_pair(open, slide);
  };
  std::stable_sort(modes.begin(), modes.end(), [&](const auto& a, const auto& b) { return rank(a) < rank(b); });

  const double f_max = m.object_model().summary().f_max;
  const double eps = 1e-9;
  for (const std::vector<Mode>& mode : modes) {
    ++out.modes_tried;
    ModeSolution sol;
    if (!m.Solve(body, mode, &sol)) continue;
    // The inequalities of the mode.
    bool consistent = true;
    std::vector<Vec2> forces(count, Vec2::Zero());
    int j = 0;
    for (int i = 0; i < count && consistent; ++i) {
      const BodyContact& c = body[i];
      const Vec2 v = PointVelocityMap(c.r) * sol.xi;
      switch (mode[i]) {
        case Mode::kStick: {
          const double fn = sol.lambda(j), ft = sol.lambda(j + 1);
          consistent = fn >= -eps * f_max && std::abs(ft) <= c.mu * fn + eps * f_max;
          forces[i] = fn * c.n + ft * c.t;
          j += 2;
          break;
        }
        case Mode::kSlidePlus:
        case Mode::kSlideMinus:
        case Mode::kSlideFrictionless: {
          const int sign = SlideSign(mode[i]);
          consistent = sol.lambda(j) >= -eps * f_max && (sign == 0 || sign * (c.u - v).dot(c.t) >= -eps);
          forces[i] = sol.lambda(j) * (c.n + sign * c.mu * c.t);
          j += 1;
          break;
        }
        case Mode::kOpen:
          consistent = (v - c.u).dot(c.n) >= -eps;
          break;
      }
    }
    if (!consistent) continue;
    out.moving = true;
    out.twist = {speed * sol.xi(0), speed * sol.xi(1), speed * sol.xi(2)};
    out.load = sol.load;
    out.wrench_residual = sol.wrench_residual;
    out.kinematic_residual = sol.kinematic_residual;
    for (int i = 0; i < count; ++i) {
      ContactState& state = out.contacts[i];
      state.force = R * forces[i];
      switch (mode[i]) {
        case Mode::kStick: state.mode = ContactMode::kSticking; break;
        case Mode::kOpen: state.mode = ContactMode::kSeparated; break;
        default: {
          state.mode = ContactMode::kSliding;
          // Frictionless contacts slide either way: report the way the finger slips.
          const Vec2 v = PointVelocityMap(body[i].r) * sol.xi;
          const double slip = (body[i].u - v).dot(body[i].t);
          state.slip_direction = mode[i] == Mode::kSlideFrictionless ? (slip > 0.0 ? 1 : (slip < 0.0 ? -1 : 0))
                                                                     : SlideSign(mode[i]);
          break;
        }
      }
      out.finger_force[state.finger] += state.force;
    }
    return out;
  }
  throw PushError("MultiPushingModel::Respond: no consistent contact mode among " + std::to_string(modes.size()) +
                  " for " + std::to_string(count) +
                  " contacts: the fingers jam the object (it cannot move the way they push)");
}

MultiPushStep MultiPushingModel::Step(const Pose2& object_pose, const std::vector<Pose2>& finger_poses,
                                      const std::vector<Vec2>& displacements) const {
  const Impl& m = *impl_;
  CheckFingers("MultiPushingModel::Step", m.models.size(), finger_poses, &displacements);
  const double pen_tol = m.spec.penetration_tolerance;
  MultiPushStep out;
  out.object_pose = object_pose;
  out.finger_poses = finger_poses;
  double longest = 0.0;
  for (const Vec2& d : displacements) longest = std::max(longest, d.norm());
  auto move_fingers = [&](double fraction) {
    for (std::size_t i = 0; i < finger_poses.size(); ++i) {
      out.finger_poses[i].x = finger_poses[i].x + fraction * displacements[i].x();
      out.finger_poses[i].y = finger_poses[i].y + fraction * displacements[i].y();
    }
  };
  std::vector<Vec2> remaining = displacements;
  double sd = Separation(object_pose, finger_poses);
  if (sd > m.spec.contact_tolerance && longest > 0.0) {
    // Free motion until some finger touches: conservative advancement (each finger's separation
    // is 1-Lipschitz in its translation, and no finger travels farther than the longest).
    double fraction = 0.0;
    bool hit = false;
    for (int iteration = 0; iteration < 100000; ++iteration) {
      if (sd <= pen_tol) {
        hit = true;
        break;
      }
      fraction += sd / longest;
      if (fraction >= 1.0) break;
      move_fingers(fraction);
      sd = Separation(object_pose, out.finger_poses);
    }
    if (!hit) {
      move_fingers(1.0);
      out.separation_after = Separation(out.object_pose, out.finger_poses);
      return out;
    }
    fraction = std::min(fraction, 1.0);
    out.made_contact = true;
    move_fingers(fraction);
    for (Vec2& d : remaining) d *= 1.0 - fraction;
  }
  out.response = Respond(out.object_pose, out.finger_poses, remaining);
  out.pushing_motions = remaining;
  if (out.response.moving) out.object_pose = ApplyTwist(out.object_pose, out.response.twist);
  for (std::size_t i = 0; i < finger_poses.size(); ++i) {
    out.finger_poses[i].x += remaining[i].x();
    out.finger_poses[i].y += remaining[i].y();
  }
  // Penetration left by the first-order step: push it out, every penetrating finger at once.
  for (int iteration = 0; iteration < 50; ++iteration) {
    std::vector<Vec2> push(finger_poses.size(), Vec2::Zero());
    double deepest = 0.0;
    for (std::size_t i = 0; i < finger_poses.size(); ++i) {
      const geometry::ShapePairResult q = m.models[i].querier().Query(out.object_pose, out.finger_poses[i]);
      if (q.depth > pen_tol) push[i] = -q.depth * q.normal;
      deepest = std::max(deepest, q.depth);
    }
    if (deepest <= pen_tol) break;
    const MultiPushResponse fix = Respond(out.object_pose, out.finger_poses, push);
    if (!fix.moving) break;
    out.object_pose = ApplyTwist(out.object_pose, fix.twist);
  }
  out.separation_after = Separation(out.object_pose, out.finger_poses);
  return out;
}

}  // namespace pushgraph::push
