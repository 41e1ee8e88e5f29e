#pragma once
// Internal: the chain solver's structure, shared with SparseMarginals (marginals.cpp), which
// takes its factor at the solution instead of assembling and factorizing J^T J again.
#include <pushgraph/graph/chain_solver.h>

#include <ceres/ceres.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <string>
#include <unordered_map>
#include <vector>

namespace pushgraph::graph {

struct ChainSolver::Impl {
  struct Block {
    double* ptr = nullptr;
    int offset = 0, size = 0;
    bool bounded = false;  // its bounds are lower[offset..] and upper[offset..]
  };
  // A residual block's parameter blocks are param_ptrs[param_begin .. param_begin + num_params),
  // with param_block, param_jacobian, param_offset and param_size at the same places: flat
  // arrays, read in order by every evaluation (a residual's own vectors were separate heap
  // objects, whose loads missed the cache a third of the evaluation loop's time, and whose
  // allocations were much of the constructor's).
  struct Residual {
    ceres::ResidualBlockId id = nullptr;
    const ceres::CostFunction* cost = nullptr;
    const ceres::LossFunction* loss = nullptr;
    int m = 0;                         // residuals
    int param_begin = 0, num_params = 0;
    int residual_offset = 0;
    int pair_begin = 0, pair_end = 0;  // into pairs
    bool constant = false;             // every block held fixed
  };
  // Adds weight * Ja^T Jb (Ja m x rows, Jb m x cols, row-major) to the stored lower triangle:
  // column c's entries start at h[offsets[c]] (from row c on a diagonal block).
  using PairKernel = void (*)(const double* Ja, const double* Jb, double weight, int m, int rows, int cols,
                              const int* offsets, double* h);
  // One block pair (row >= column in the ordering) of a residual block's J^T J contribution:
  // column c of it starts at values[column_offsets[offsets_begin + c]] (contiguous rows).
  struct Pair {
    int row_param = 0, col_param = 0, offsets_begin = 0;
    int rows = 0, cols = 0;       // the two blocks' sizes
    PairKernel kernel = nullptr;  // sized at compile time for the common m, rows, cols
  };
  explicit Impl(ceres::Problem& problem);
  void Gather(Eigen::VectorXd& x) const;
  void Scatter(const Eigen::VectorXd& x);
  void Project(Eigen::VectorXd& x) const;
  // J^T J (lower triangle, into h) and the gradient J^T r at the blocks' current values, loss
  // weights applied; false (with the residual block's index) for a failed or non-finite block.
  bool Evaluate(std::vector<double>& h, Eigen::VectorXd& g, double* cost, int* failed);
  bool Factorize(const std::vector<double>& h, double lambda);
  // The cost of the residual blocks on constant blocks only (skipped by Evaluate).
  bool FixedCost(double* cost, int* failed);
  Eigen::VectorXd H_undamped_times(const Eigen::VectorXd& v);
  // The undamped factor at the blocks' current values (reusing the last evaluation when they
  // have not moved since).
  bool FactorizeAtCurrentValues(std::string* error);
  std::string Describe(const ChainSolverOptions& options, int residual) const;
  std::string DescribeUnknown(int unknown) const;
  // The residual block whose cost rises most from x to `near` (a rejected point next to it),
  // described; leaves the blocks at x.
  std::string LargestJump(const ChainSolverOptions& options, const Eigen::VectorXd& x, const Eigen::VectorXd& near);

  ceres::Problem* problem = nullptr;
  std::vector<Block> blocks;                          // in the order they were added (time order)
  std::unordered_map<const double*, int> fixed;       // constant or unused: size
  std::vector<Residual> residuals;
  std::vector<const double*> param_ptrs;
  std::vector<int> param_block;          // index into blocks, -1 for a block held fixed
  std::vector<double*> param_jacobian;   // into jacobian_values (row-major, m x size); nullptr if fixed
  std::vector<int> param_offset, param_size;  // the block's place in x and size (-1 and 0 if fixed)
  std::vector<double> lower, upper;      // bounds of the unknowns
  std::vector<Pair> pairs;
  std::vector<int> column_offsets, diagonal;
  std::vector<double> jacobian_values, residual_values;
  int n = 0;
  // The pattern (lower triangle); values copied in to factorize. The fill-reducing ordering
  // (AMD, computed once with the symbolic analysis) keeps the factor within the band and its
  // border; on a 276-step push it has 26% fewer nonzeros than the plain time order (40668 against
  // 55083, PUSHGRAPH_SOLVER_LOG=1).
  Eigen::SparseMatrix<double> H;
  std::vector<double> values, trial_values;  // J^T J at the current point and at a trial point
  Eigen::VectorXd gradient, trial_gradient;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt;
  bool analyzed = false;
  // The iterations' factorization when the time-ordered band is narrow (every factor within a
  // few consecutive steps, no block shared by the whole trajectory): LAPACK's banded Cholesky
  // (dpbtrf/dpbtrs) on the lower band, kd + 1 rows by n columns, column-major. Its flops,
  // n kd^2, exceed the sparse factor's, but it runs them at dense-kernel rate with no
  // permutation copy. The covariances keep the sparse factor (its selected inversion).
  int band_width = 0;                // kd: the largest row - column of the pattern, time order
  bool banded = false;
  std::vector<int> band_index;       // H's nonzero k -> its place in band
  std::vector<double> band;          // the factor after FactorizeIteration
  // The iterations' factorization (banded or sparse) and solve of (J^T J + damping) x = rhs.
  bool FactorizeIteration(const std::vector<double>& h, double lambda);
  Eigen::VectorXd SolveIteration(const Eigen::VectorXd& rhs);
  Eigen::VectorXd x_evaluated;  // where `values` and `gradient` were computed
  bool evaluated_at_current = false;
};

}  // namespace pushgraph::graph
