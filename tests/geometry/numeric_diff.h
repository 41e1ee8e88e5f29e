#pragma once
// One harness checks every analytic Jacobian (manif style): a function R^n -> R^m given as a
// lambda over Eigen::VectorXd, its analytic Jacobian at x, and central differences.
//
//   auto f = [&](const Eigen::VectorXd& v) { return Compose(P(v), b).vector(); };
//   EXPECT_TRUE(JacobianMatches(f, a.vector(), J_analytic, "Compose/J_a"));
//
// Non-differentiable points (feature switches, the medial axis, wrap-around of angles) are
// detected per column by comparing the forward and backward one-sided differences: if they
// disagree by more than kink_tol * max(1, |central|) the column straddles a kink. A kink or a
// mismatch at step h is re-examined at step h / 8 (a kink just inside h is then outside); only a
// mismatch at both steps is a failure, a kink at both is JacobianCheck::kSkipped. Callers count
// skips (JacobianTally) and assert that most configurations were really checked, so a broken
// function cannot hide behind the detector.
#include <gtest/gtest.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

namespace pushgraph::geometry::testing {

struct NumericDiffOptions {
  double h = 1e-6;         ///< step (absolute)
  double rel_tol = 1e-6;   ///< |J - Jn| <= abs_tol + rel_tol * max(1, |Jn|) per entry
  double abs_tol = 1e-6;
  double kink_tol = 1e-2;  ///< |fwd - bwd| > kink_tol * max(1, |central|): kink
};

enum class JacobianCheck { kPassed, kFailed, kSkipped };

struct JacobianReport {
  JacobianCheck status = JacobianCheck::kPassed;
  Eigen::MatrixXd numeric;
  std::string message;
};

namespace detail {
/// Central differences at step h; returns false when some column straddles a kink.
template <class F>
bool CentralDifferences(F& f, const Eigen::VectorXd& x, const Eigen::VectorXd& f0, double h,
                        double kink_tol, Eigen::MatrixXd* J) {
  const Eigen::Index m = f0.size(), n = x.size();
  J->resize(m, n);
  bool smooth = true;
  for (Eigen::Index j = 0; j < n; ++j) {
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += h;
    xm[j] -= h;
    const Eigen::VectorXd fp = f(xp), fm = f(xm);
    const double hp = xp[j] - x[j], hm = x[j] - xm[j];  // the steps actually taken
    const Eigen::VectorXd central = (fp - fm) / (hp + hm);
    const Eigen::VectorXd fwd = (fp - f0) / hp, bwd = (f0 - fm) / hm;
    const Eigen::ArrayXd scale = central.array().abs().max(1.0);
    if (!fp.allFinite() || !fm.allFinite() ||
        ((fwd - bwd).array().abs() > kink_tol * scale).any())
      smooth = false;
    J->col(j) = central;
  }
  return smooth;
}

inline double WorstMismatch(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric,
                            double rel_tol, double abs_tol, bool* ok) {
  double worst = 0.0;
  *ok = true;
  for (Eigen::Index i = 0; i < analytic.rows(); ++i)
    for (Eigen::Index j = 0; j < analytic.cols(); ++j) {
      const double err = std::abs(analytic(i, j) - numeric(i, j));
      const double tol = abs_tol + rel_tol * std::max(1.0, std::abs(numeric(i, j)));
      if (!(err <= tol)) {  // also catches NaN
        *ok = false;
        worst = std::isnan(err) ? err : std::max(worst, err);
      }
    }
  return worst;
}
}  // namespace detail

/// Central-difference Jacobian of f at x plus a kink test; compares with `analytic`.
template <class F>
JacobianReport CheckJacobian(F&& f, const Eigen::VectorXd& x, const Eigen::MatrixXd& analytic,
                             const NumericDiffOptions& o = {}) {
  JacobianReport rep;
  const Eigen::VectorXd f0 = f(x);
  std::ostringstream msg;
  if (analytic.rows() != f0.size() || analytic.cols() != x.size()) {
    rep.status = JacobianCheck::kFailed;
    msg << "analytic Jacobian is " << analytic.rows() << "x" << analytic.cols() << ", expected "
        << f0.size() << "x" << x.size();
    rep.message = msg.str();
    return rep;
  }
  if (!analytic.allFinite()) {
    rep.status = JacobianCheck::kFailed;
    rep.message = "analytic Jacobian is not finite";
    return rep;
  }
  double worst = 0.0;
  for (const double h : {o.h, o.h / 8}) {
    const bool smooth = detail::CentralDifferences(f, x, f0, h, o.kink_tol, &rep.numeric);
    if (!smooth) {
      rep.status = JacobianCheck::kSkipped;
      continue;
    }
    bool ok = false;
    worst = detail::WorstMismatch(analytic, rep.numeric, o.rel_tol, o.abs_tol, &ok);
    rep.status = ok ? JacobianCheck::kPassed : JacobianCheck::kFailed;
    if (ok) break;
  }
  if (rep.status == JacobianCheck::kSkipped) rep.message = "kink within h: skipped";
  if (rep.status == JacobianCheck::kFailed) {
    Eigen::IOFormat fmt(Eigen::FullPrecision, 0, ", ", "\n", "  [", "]");
    msg << "Jacobian mismatch (worst |err| " << worst << ") at x = " << x.transpose().format(fmt)
        << "\nanalytic:\n"
        << analytic.format(fmt) << "\nnumeric (central differences):\n"
        << rep.numeric.format(fmt);
    rep.message = msg.str();
  }
  return rep;
}

/// Counts passes, skips and failures over many configurations.
class JacobianTally {
 public:
  explicit JacobianTally(std::string name) : name_(std::move(name)) {}
  ::testing::AssertionResult Record(const JacobianReport& r, const std::string& context = "") {
    switch (r.status) {
      case JacobianCheck::kPassed:
        ++passed_;
        return ::testing::AssertionSuccess();
      case JacobianCheck::kSkipped:
        ++skipped_;
        return ::testing::AssertionSuccess();
      default:
        ++failed_;
        return ::testing::AssertionFailure() << name_ << " " << context << ": " << r.message;
    }
  }
  void Skip() { ++skipped_; }
  int passed() const { return passed_; }
  int skipped() const { return skipped_; }
  int failed() const { return failed_; }
  /// Most configurations must really have been checked (a detector that skips everything
  /// would otherwise make the test vacuous).
  ::testing::AssertionResult MostlyChecked(double min_fraction = 0.5) const {
    const int total = passed_ + skipped_ + failed_;
    const int checked = passed_ + failed_;
    if (checked > 0 && checked >= min_fraction * total) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << name_ << ": only " << checked << " of " << total
                                         << " configurations were differentiable (skipped "
                                         << skipped_ << ")";
  }

 private:
  std::string name_;
  int passed_ = 0, skipped_ = 0, failed_ = 0;
};

/// Check one configuration that must be differentiable (no skipping allowed).
template <class F>
::testing::AssertionResult JacobianMatches(F&& f, const Eigen::VectorXd& x,
                                           const Eigen::MatrixXd& analytic,
                                           const std::string& name,
                                           const NumericDiffOptions& o = {}) {
  const JacobianReport r = CheckJacobian(std::forward<F>(f), x, analytic, o);
  if (r.status == JacobianCheck::kFailed)
    return ::testing::AssertionFailure() << name << ": " << r.message;
  if (r.status == JacobianCheck::kSkipped)
    return ::testing::AssertionFailure() << name << ": unexpectedly not differentiable here";
  return ::testing::AssertionSuccess();
}

}  // namespace pushgraph::geometry::testing
