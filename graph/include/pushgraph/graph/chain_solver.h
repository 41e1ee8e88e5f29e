#pragma once
// A Gauss-Newton solver for the push's chain-structured least-squares problems, with a
// Levenberg-Marquardt safeguard. It takes a ceres::Problem as built (the same cost functions,
// losses, constant blocks and bounds: one copy of every residual and Jacobian) and accumulates
// the normal equations J^T J straight into a sparse matrix whose pattern is fixed once: every
// factor touches at most three consecutive steps, so the matrix is block-banded (plus a dense
// border for the blocks shared by the whole trajectory: c, mu, the shape frame). The iterations
// factorize the band with LAPACK's banded Cholesky (dpbtrf) where it is at most 64 wide, and
// otherwise (a border) with Eigen's SimplicialLLT, AMD-ordered, its symbolic analysis done once
// per problem; the covariances take that sparse factor at the solution
// (SparseMarginals::Compute(ChainSolver&)).
//
//   ceres::Problem problem;                  // residual blocks added step by step, in time order
//   ...
//   graph::ChainSolver solver(problem);      // structure and ordering, once
//   graph::ChainSolverOptions options;       // tolerances as ceres::Solver::Options'
//   graph::ChainSolverSummary s = solver.Solve(options);  // throws GraphError (non-finite, ...)
//   graph::SparseMarginals marginals;
//   marginals.Compute(solver);               // at the solution, from the same symbolic factor
//
// Each iteration evaluates every residual block once, with its Jacobians (a rejected step costs
// the same as an accepted one; Ceres evaluates an accepted point twice). Robust losses weight a
// residual block by rho'(|r|^2) (iteratively reweighted Gauss-Newton: the same gradient as
// Ceres', so the same minimum). Bounds are kept by projecting the step onto the box.
#include <ceres/problem.h>

#include <functional>
#include <memory>
#include <string>

namespace pushgraph::graph {

struct ChainSolverOptions {
  int max_iterations = 100;
  /// Converged when a successful step changes the cost by less than this fraction of it (and,
  /// with model_confirms_convergence, its linear model predicted at most 4 times that: a step
  /// accepted at rho 0.03 changes the cost little because its model failed, not because the
  /// cost is flat).
  double function_tolerance = 1e-6;
  bool model_confirms_convergence = true;
  /// A soft iteration budget (0: none). From this iteration on, a successful step that changes
  /// the cost by less than soft_function_tolerance of it ends the solve, unconverged ("soft
  /// limit"): the fixed-lag smoother's windows at the sensor rate, which later updates refine,
  /// stop there once they are near their minimum, and go on where they are not (a hard cap of 3
  /// left a slow real push's first windows far from it, and the estimate diverged).
  int soft_iteration_limit = 0;
  /// 3e-4: 1e-3 left one rect1 recording's finger NEES at 9.9 on docs/results.md's set at the
  /// sensor rate (2.05 with no limit, with 3e-4 and with 1e-4); on a slow ellip1 push 3e-4 costs
  /// 8 % more time per update than 1e-3, 1e-4 27 %.
  double soft_function_tolerance = 3e-4;
  /// Converged when max_i |x_i - Project(x_i - g_i)| is below this (g the gradient).
  double gradient_tolerance = 1e-12;
  /// Converged when |dx| <= parameter_tolerance (|x| + parameter_tolerance).
  double parameter_tolerance = 1e-10;
  /// The Levenberg-Marquardt damping lambda of the first step, relative to diag(J^T J) (Ceres'
  /// initial trust-region radius 1e4 is lambda 1e-4): nearly a Gauss-Newton step.
  double initial_damping = 1e-4;
  /// Names a residual block in error messages (for example "D at step 17, t = 0.068 s"); the
  /// default names it by its position in the problem.
  std::function<std::string(ceres::ResidualBlockId)> describe;
  /// Prints one line per iteration to stderr.
  bool log_iterations = false;
};

struct ChainSolverSummary {
  int iterations = 0;          ///< steps tried (successful + unsuccessful)
  int successful_steps = 0;
  int unsuccessful_steps = 0;
  double initial_cost = 0.0;   ///< 1/2 sum rho(|r|^2)
  double final_cost = 0.0;
  bool converged = false;      ///< a tolerance was met (else: the iteration limit, a soft limit, or a stall)
  bool stalled = false;        ///< stopped by a stall (termination says which residual jumps)
  /// Which tolerance, or why it stopped: "iteration limit (N)", or "stalled: ..." when the only
  /// step accepted came under a damping of 1e3 or more and changed the cost by less than the
  /// function tolerance while the step rejected before it had raised the cost by 1 or more (and
  /// 0.1 % of it): a residual that jumps next to the current point; the text names the residual
  /// block whose cost rose most on that rejected step.
  std::string termination;
  int unknowns = 0;
  long hessian_nonzeros = 0;   ///< stored lower triangle of J^T J
  long factor_nonzeros = 0;    ///< of its Cholesky factor
  /// Floating-point operations of one iteration's factorization and solve (sum over columns of
  /// the factor of nnz_j^2 plus 4 nnz(L)), for comparing the achieved rate with the machine's.
  double factor_flops = 0.0;
  /// Wall time (s): residual and Jacobian evaluation with the J^T J accumulation, the numeric
  /// factorizations and solves, and everything.
  double evaluate_s = 0.0, linear_solve_s = 0.0, total_s = 0.0;
};

class ChainSolver {
 public:
  /// Reads the problem's structure (its parameter blocks must not change while this solver is
  /// used; their values may). Throws GraphError for a block with a manifold.
  explicit ChainSolver(ceres::Problem& problem);
  ~ChainSolver();
  ChainSolver(ChainSolver&&) noexcept;
  ChainSolver& operator=(ChainSolver&&) noexcept;

  /// Minimizes the problem's cost from the parameter blocks' current values, which it leaves at
  /// the solution. Throws GraphError naming the residual block (options.describe) when a residual
  /// or Jacobian is not finite or fails to evaluate at the start, and naming the unknown when
  /// J^T J stays singular under any damping; a step that fails to evaluate is rejected and the
  /// damping raised (the documented fallback, as Ceres shortens the step).
  ChainSolverSummary Solve(const ChainSolverOptions& options = {});

  /// For SparseMarginals: J^T J at the current values (the solution after Solve), factorized
  /// with the solver's symbolic analysis. Internal types, see chain_solver.cpp.
  struct Impl;
  const Impl& impl() const { return *impl_; }
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace pushgraph::graph
