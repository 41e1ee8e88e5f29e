#pragma once
// Marginal covariances of the parameter blocks of a solved ceres::Problem, by sparse Cholesky of
// the Gauss-Newton information matrix H = J^T J and selected inversion: only the entries of
// H^-1 inside the Cholesky factor's sparsity pattern are computed, with the recursion of
// Takahashi, Fagan and Chen (1973), as in Kaess and Dellaert, "Covariance recovery from a
// square root information matrix for data association" (RAS 2009). For a trajectory (a chain of
// steps, possibly with a few variables shared by all steps) this costs O(n w^2) for n unknowns
// and band width w, where ceres::Covariance (SPARSE_QR) solves for every requested column:
// O(n^2 w). On a 1000-step QS problem (10000 unknowns): 45 ms against about 4 s
// (bench/graph: BM_BatchQsWithCovariance against BM_BatchQsWithCeresCovariance).
//
//   ceres::Solve(options, &problem, &summary);
//   graph::SparseMarginals marginals;
//   if (!marginals.Compute(problem)) std::cerr << marginals.error() << "\n";
//   Eigen::MatrixXd cov = marginals.Covariance(pose);  // 3x3 for a 3-vector block
//
// The Jacobian is the one Ceres uses (loss functions applied, as ceres::Covariance does);
// constant parameter blocks, and blocks no residual uses, are held fixed. Blocks with a manifold
// are not supported. Forming J^T J squares J's condition: when that could cost more than 4
// digits in double (see min_pivot_ratio), Compute forms, factorizes and inverts J^T J again in
// long double (extended_precision()), and refuses only when even that could; ceres::Covariance's
// QR on J is the tool then.
#include <ceres/problem.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <chrono>

#include <memory>
#include <string>
#include <vector>

namespace pushgraph::graph {

class ChainSolver;

class SparseMarginals {
 public:
  SparseMarginals();
  ~SparseMarginals();
  SparseMarginals(SparseMarginals&&) noexcept;
  SparseMarginals& operator=(SparseMarginals&&) noexcept;

  /// Factorizes H at the problem's current parameter values and computes the selected inverse.
  /// Returns false, with error() saying why, when: there is no variable block; a block has a
  /// manifold; a residual block fails to evaluate or gives a non-finite value; H is not positive
  /// definite, or a pivot keeps less than 1e-9 of its unknown's information in double
  /// (min_pivot_ratio(): below it the result could lose more than 4 digits, measured against a QR
  /// on J) and less than 4.9e-13 in the long double pass that follows (x86's 64-bit significand;
  /// where long double is double there is no such pass); below 1e-14 the direction is
  /// unobservable. failed_block() then names the block when known.
  /// Parameter bounds are ignored (as ceres::Covariance does): a variable on its bound gets the
  /// unconstrained Gaussian covariance.
  bool Compute(ceres::Problem& problem);
  /// The same from a ChainSolver (after its Solve): its J^T J at the solution (no second
  /// evaluation when the values have not moved) and its symbolic factorization; the unknowns in
  /// the solver's fill-reducing order, so the factor is banded and the selected inverse costs O(n w^2).
  bool Compute(ChainSolver& solver);

  /// The marginal covariance of one parameter block (size x size); zero for a block held fixed
  /// (constant, or used by no residual), as ceres::Covariance does. Throws std::logic_error
  /// before a successful Compute or for a block the problem did not have.
  Eigen::MatrixXd Covariance(const double* block) const;
  /// The cross-covariance of two blocks; only pairs that share a factor (or are linked through
  /// the factorization's fill) are available (HasCrossCovariance): others throw std::logic_error.
  Eigen::MatrixXd CrossCovariance(const double* a, const double* b) const;
  bool HasCrossCovariance(const double* a, const double* b) const;

  const std::string& error() const { return error_; }
  /// After a failed Compute: the parameter block whose pivot failed, when one did (else nullptr).
  const double* failed_block() const { return failed_block_; }
  /// After a successful Compute: whether it took the long double pass (a pivot ratio below the
  /// accepted one in double; about 10 times the double pass' time).
  bool extended_precision() const { return extended_precision_; }
  /// Diagnostics: unknowns, nonzeros of the Cholesky factor, and the wall time (s) of the last
  /// Compute's phases: Jacobian evaluation, J^T J, sparse Cholesky, selected inversion.
  int num_unknowns() const;
  long num_factor_nonzeros() const;
  struct Timings {
    double jacobian = 0.0, normal_equations = 0.0, factorization = 0.0, inversion = 0.0;
  };
  const Timings& timings() const { return timings_; }
  /// The smallest L_jj^2 / H_jj of the last factorization: the fraction of an unknown's
  /// information left after conditioning on the ones eliminated before it (1 for independent
  /// unknowns; small for nearly dependent directions, where J^T J loses digits).
  double min_pivot_ratio() const { return min_pivot_ratio_; }
  /// The smallest pivot ratio Compute accepts in double (default 1e-9, about 4 digits kept; at
  /// least 1e-14, below which a direction has no information of its own); the long double pass
  /// accepts this times eps(long double) / eps(double), about 4.9e-4 times it on x86. A user that needs fewer digits
  /// (the self-diagnosis' leverages) may accept more ill-conditioned problems.
  void set_accepted_pivot_ratio(double ratio);

 private:
  struct Impl;
  // Checks the pivots of L (factor order; h_diag the diagonal of H in that order) against
  // accepted_ratio and computes the selected inverse into impl (Scalar: double, or long double
  // for the extended pass).
  template <typename Scalar>
  bool SelectedInverse(const Eigen::SparseMatrix<Scalar>& L, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& h_diag,
                       const std::vector<double*>& variable, Impl& impl, std::chrono::steady_clock::time_point phase,
                       double accepted_ratio);
  // J^T J formed, factorized and inverted again in long double (after an ill-conditioned pivot).
  bool ComputeExtended(const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>& J,
                       const std::vector<double*>& variable, Impl& impl);
  std::unique_ptr<Impl> impl_;
  std::string error_;
  const double* failed_block_ = nullptr;
  Timings timings_;
  double min_pivot_ratio_ = 0.0;
  double accepted_pivot_ratio_ = 1e-9;
  bool ill_conditioned_ = false;     // the last pivot check failed on the ratio alone
  bool extended_precision_ = false;  // the last successful Compute needed the extended pass
};

}  // namespace pushgraph::graph
