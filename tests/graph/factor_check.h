#pragma once
// The graph module's Jacobian-check harness: any ceres::CostFunction's analytic Jacobians against
// central differences (the geometry tests' CheckJacobian, with its kink detector), block by
// block, relative to each block's scale. tests/graph/test_factors.cpp runs it over every factor.
//
//   JacobianTally tally("touching");
//   WorstError worst{"touching"};
//   CheckCost(TouchingFactor(querier, 1e-3), {V(object_pose), V(finger_pose)}, tally, worst, "case 3");
#include "geometry/numeric_diff.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <pushgraph/geometry/pose.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

namespace pushgraph::graph::testing {

using geometry::testing::CheckJacobian;
using geometry::testing::JacobianTally;
using geometry::testing::NumericDiffOptions;

// Worst relative error of all checked Jacobians, per factor (printed for the report).
struct WorstError {
  const char* name;
  double worst = 0.0;
  ~WorstError() { std::printf("[jacobian] %-28s worst |J - Jnum| / max(1, max|Jnum|) = %.3g\n", name, worst); }
};

// Checks all parameter blocks of `cost` at `values` (one vector per block).
inline void CheckCost(const ceres::CostFunction& cost, std::vector<Eigen::VectorXd> values, JacobianTally& tally,
               WorstError& worst, const std::string& context) {
  const int m = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  ASSERT_EQ(values.size(), sizes.size());
  std::vector<const double*> ptrs;
  for (auto& v : values) ptrs.push_back(v.data());
  Eigen::VectorXd r(m);
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(sizes.size());
  std::vector<double*> jp;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    J[k].resize(m, sizes[k]);
    jp.push_back(J[k].data());
  }
  ASSERT_TRUE(cost.Evaluate(ptrs.data(), r.data(), jp.data())) << context;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    auto f = [&](const Eigen::VectorXd& v) {
      std::vector<Eigen::VectorXd> vv = values;
      vv[k] = v;
      std::vector<const double*> pp;
      for (auto& x : vv) pp.push_back(x.data());
      Eigen::VectorXd out(m);
      if (!cost.Evaluate(pp.data(), out.data(), nullptr)) out.setConstant(NAN);
      return out;
    };
    NumericDiffOptions o;
    o.h = 1e-7;
    o.rel_tol = 1e-5;
    // Entries are compared relative to the whole block's scale: whitened residuals and
    // 1/dt velocities make some entries 1e5 times larger than others in the same block.
    o.abs_tol = 1e-5 + 1e-6 * J[k].cwiseAbs().maxCoeff();
    const auto rep = CheckJacobian(f, values[k], Eigen::MatrixXd(J[k]), o);
    if (rep.status == geometry::testing::JacobianCheck::kPassed) {
      const Eigen::MatrixXd d = Eigen::MatrixXd(J[k]) - rep.numeric;
      for (int i = 0; i < d.rows(); ++i)
        for (int j = 0; j < d.cols(); ++j)
          worst.worst = std::max(worst.worst, std::abs(d(i, j)) / std::max(1.0, rep.numeric.cwiseAbs().maxCoeff()));
    }
    EXPECT_TRUE(tally.Record(rep, context + " block " + std::to_string(k)));
  }
}

inline Eigen::VectorXd V(std::initializer_list<double> l) {
  Eigen::VectorXd v(l.size());
  int i = 0;
  for (double x : l) v[i++] = x;
  return v;
}
inline Eigen::VectorXd V(const geometry::Pose2& p) { return p.vector(); }
inline Eigen::VectorXd V(const geometry::Vec2& p) { return Eigen::VectorXd(p); }

}  // namespace pushgraph::graph::testing
