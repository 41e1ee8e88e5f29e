// SE(2) operations on (x, y, theta) coordinates with analytic Jacobians.
// Log/Exp follow Sola, Deray, Atchuthan, "A micro Lie theory for state estimation in
// robotics" (2018), Appendix C; the Jacobians here are with respect to (x, y, theta).
#include <pushgraph/geometry/pose.h>

#include <cmath>
#include <cstdint>
#include <cstring>

namespace pushgraph::geometry {
namespace {

// cos and sin of theta, remembering the last two angles of this thread: a factor graph's
// evaluation asks for the same pose's rotation several times in a row (every factor on x_k and
// x_{k-1}, and Jacobians beside the values), and sincos was 8 to 13 % of a QS batch solve and of
// the shape registration. Keyed on the bits of theta, so the values are the same as computed.
void CosSin(double theta, double* c, double* s) {
  struct Entry {
    std::uint64_t bits = 0;  // +0.0, whose cos and sin are exactly 1 and 0
    double c = 1.0, s = 0.0;
  };
  thread_local Entry cache[2];
  thread_local int next = 0;
  std::uint64_t bits = 0;
  std::memcpy(&bits, &theta, sizeof bits);
  for (const Entry& e : cache) {
    if (e.bits == bits) {
      *c = e.c;
      *s = e.s;
      return;
    }
  }
  Entry& e = cache[next];
  next ^= 1;
  e.bits = bits;
  e.c = *c = std::cos(theta);
  e.s = *s = std::sin(theta);
}

// d R(theta) / d theta
Eigen::Matrix2d RotationDerivative(double theta) {
  double c = 0.0, s = 0.0;
  CosSin(theta, &c, &s);
  Eigen::Matrix2d dR;
  dR << -s, -c, c, -s;
  return dR;
}

// sin(phi) - phi without cancellation: its Taylor series where |phi| < 1.
double SinMinusX(double phi) {
  if (std::abs(phi) >= 1.0) return std::sin(phi) - phi;
  const double p2 = phi * phi;
  double term = -phi * p2 / 6.0, sum = 0.0;
  for (int k = 1; k < 12 && term != 0.0; ++k) {  // term_k = (-1)^k phi^(2k+1) / (2k+1)!
    sum += term;
    term *= -p2 / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
  }
  return sum;
}

// A(phi) = (phi / 2) cot(phi / 2) and dA/dphi = (sin(phi) - phi) / (4 sin^2(phi / 2)), written
// without cancellation; series at the origin. V(phi)^-1 = [[A, B], [-B, A]], B = phi / 2.
void HalfCotTerm(double phi, double* a, double* da) {
  if (std::abs(phi) < 1e-4) {
    const double p2 = phi * phi;
    *a = 1.0 - p2 / 12.0 - p2 * p2 / 720.0;
    *da = -phi / 6.0 - p2 * phi / 180.0;
    return;
  }
  const double half_sin = std::sin(0.5 * phi);
  *a = 0.5 * phi / std::tan(0.5 * phi);
  *da = SinMinusX(phi) / (4.0 * half_sin * half_sin);
}

// sin(phi)/phi, (1 - cos(phi))/phi and their derivatives, for V(phi) in Exp, using
// 1 - cos(phi) = 2 sin^2(phi / 2) and phi cos(phi) - sin(phi) = -phi (1 - cos(phi)) - (sin(phi) - phi).
void ExpTerms(double phi, double* sa, double* cb, double* dsa, double* dcb) {
  if (std::abs(phi) < 1e-4) {
    const double p2 = phi * phi;
    *sa = 1.0 - p2 / 6.0 + p2 * p2 / 120.0;
    *cb = phi / 2.0 - p2 * phi / 24.0 + p2 * p2 * phi / 720.0;
    *dsa = -phi / 3.0 + p2 * phi / 30.0 - p2 * p2 * phi / 840.0;
    *dcb = 0.5 - p2 / 8.0 + p2 * p2 / 144.0;
    return;
  }
  const double s = std::sin(phi), half_sin = std::sin(0.5 * phi);
  const double one_minus_cos = 2.0 * half_sin * half_sin;
  *sa = s / phi;
  *cb = one_minus_cos / phi;
  *dsa = (-phi * one_minus_cos - SinMinusX(phi)) / (phi * phi);
  *dcb = (s * phi - one_minus_cos) / (phi * phi);
}

}  // namespace

Eigen::Matrix2d Pose2::rotation() const {
  double c = 0.0, s = 0.0;
  CosSin(theta, &c, &s);
  Eigen::Matrix2d R;
  R << c, -s, s, c;
  return R;
}

double WrapAngle(double angle) {
  double wrapped = std::remainder(angle, 2.0 * M_PI);  // in [-pi, pi]
  if (wrapped <= -M_PI) wrapped += 2.0 * M_PI;
  return wrapped;
}

Pose2 Compose(const Pose2& a, const Pose2& b, Eigen::Matrix3d* J_out_a, Eigen::Matrix3d* J_out_b) {
  const Eigen::Matrix2d Ra = a.rotation();
  const Vec2 t = a.translation() + Ra * b.translation();
  if (J_out_a) {
    J_out_a->setIdentity();
    J_out_a->block<2, 1>(0, 2) = RotationDerivative(a.theta) * b.translation();
  }
  if (J_out_b) {
    J_out_b->setIdentity();
    J_out_b->block<2, 2>(0, 0) = Ra;
  }
  return {t.x(), t.y(), a.theta + b.theta};
}

Pose2 Inverse(const Pose2& a, Eigen::Matrix3d* J_out_a) {
  const Eigen::Matrix2d Rt = a.rotation().transpose();
  const Vec2 t = -Rt * a.translation();
  if (J_out_a) {
    J_out_a->setZero();
    J_out_a->block<2, 2>(0, 0) = -Rt;
    J_out_a->block<2, 1>(0, 2) = -RotationDerivative(a.theta).transpose() * a.translation();
    (*J_out_a)(2, 2) = -1.0;
  }
  return {t.x(), t.y(), -a.theta};
}

Pose2 Between(const Pose2& a, const Pose2& b, Eigen::Matrix3d* J_out_a, Eigen::Matrix3d* J_out_b) {
  Eigen::Matrix3d J_inv_a, J_c_inv;
  const Pose2 inv = Inverse(a, J_out_a ? &J_inv_a : nullptr);
  const Pose2 out = Compose(inv, b, J_out_a ? &J_c_inv : nullptr, J_out_b);
  if (J_out_a) *J_out_a = J_c_inv * J_inv_a;
  return out;
}

Vec2 Act(const Pose2& a, const Vec2& p, Eigen::Matrix<double, 2, 3>* J_out_a, Eigen::Matrix2d* J_out_p) {
  const Eigen::Matrix2d R = a.rotation();
  if (J_out_a) {
    J_out_a->block<2, 2>(0, 0).setIdentity();
    J_out_a->col(2) = RotationDerivative(a.theta) * p;
  }
  if (J_out_p) *J_out_p = R;
  return a.translation() + R * p;
}

Vec2 InverseAct(const Pose2& a, const Vec2& p, Eigen::Matrix<double, 2, 3>* J_out_a, Eigen::Matrix2d* J_out_p) {
  const Eigen::Matrix2d Rt = a.rotation().transpose();
  const Vec2 d = p - a.translation();
  if (J_out_a) {
    J_out_a->block<2, 2>(0, 0) = -Rt;
    J_out_a->col(2) = RotationDerivative(a.theta).transpose() * d;
  }
  if (J_out_p) *J_out_p = Rt;
  return Rt * d;
}

Eigen::Vector3d Log(const Pose2& a, Eigen::Matrix3d* J_out_a) {
  const double phi = WrapAngle(a.theta);
  double A = 0.0, dA = 0.0;
  HalfCotTerm(phi, &A, &dA);
  const double B = 0.5 * phi;
  Eigen::Matrix2d Vinv;
  Vinv << A, B, -B, A;
  const Vec2 rho = Vinv * a.translation();
  if (J_out_a) {
    Eigen::Matrix2d dVinv;
    dVinv << dA, 0.5, -0.5, dA;
    J_out_a->setZero();
    J_out_a->block<2, 2>(0, 0) = Vinv;
    J_out_a->block<2, 1>(0, 2) = dVinv * a.translation();  // d phi / d theta = 1 (away from the cut)
    (*J_out_a)(2, 2) = 1.0;
  }
  return {rho.x(), rho.y(), phi};
}

Pose2 Exp(const Eigen::Vector3d& tangent, Eigen::Matrix3d* J_out_tangent) {
  const double phi = tangent.z();
  double sa = 0, cb = 0, dsa = 0, dcb = 0;
  ExpTerms(phi, &sa, &cb, &dsa, &dcb);
  Eigen::Matrix2d V;
  V << sa, -cb, cb, sa;
  const Vec2 rho = tangent.head<2>();
  const Vec2 t = V * rho;
  if (J_out_tangent) {
    Eigen::Matrix2d dV;
    dV << dsa, -dcb, dcb, dsa;
    J_out_tangent->setZero();
    J_out_tangent->block<2, 2>(0, 0) = V;
    J_out_tangent->block<2, 1>(0, 2) = dV * rho;
    (*J_out_tangent)(2, 2) = 1.0;
  }
  return {t.x(), t.y(), phi};
}

}  // namespace pushgraph::geometry
