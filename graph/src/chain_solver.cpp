// Levenberg-Marquardt on a fixed sparse pattern (Nielsen's damping update, as Ceres'
// LEVENBERG_MARQUARDT strategy: lambda *= max(1/3, 1 - (2 rho - 1)^3) after a successful step,
// lambda *= nu, nu *= 2 after a rejected one; K. Madsen, H. B. Nielsen, O. Tingleff, "Methods
// for non-linear least squares problems", 2004, Sec. 3.2). The normal equations are scattered
// straight into the stored lower triangle of J^T J through offsets computed once.
#include "chain_solver_impl.h"

#include <pushgraph/graph/factors.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <numeric>
#include <unordered_map>

// LAPACK's banded Cholesky (Fortran ABI; the reference LAPACK and every optimized one export it).
extern "C" {
void dpbtrf_(const char* uplo, const int* n, const int* kd, double* ab, const int* ldab, int* info);
void dpbtrs_(const char* uplo, const int* n, const int* kd, const int* nrhs, const double* ab, const int* ldab, double* b,
             const int* ldb, int* info);
}

namespace pushgraph::graph {

namespace {

// The iterations factorize with LAPACK's banded Cholesky up to this band width kd (n kd^2 flops:
// at 1000 QS steps kd is 22, 6.4 Mflop in about 1.7 ms an iteration against the sparse factor's
// 3.0 Mflop in 2.7 ms); a block shared by the whole trajectory (shape frame, c, mu) makes the band
// as wide as the problem, and the sparse factor stays. PUSHGRAPH_BAND=0 selects the sparse factor
// always (for comparing the two, docs/estimation.md's Speed).
constexpr int kMaxBandWidth = 64;

// A hint to load the cache line at p (GCC and Clang; nothing elsewhere).
inline void PrefetchForRead(const void* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(p);
#else
  (void)p;
#endif
}

using Clock = std::chrono::steady_clock;
double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Ceres' defaults: the smallest relative decrease of an accepted step, and the clamp of
// diag(J^T J) in the damping.
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kMinDiagonal = 1e-6, kMaxDiagonal = 1e32;

// A step accepted under this much damping (relative to diag(J^T J)) is a gradient step of a
// vanishing size: its small change says the solver is stuck, not that it converged, when the
// step rejected before it raised the cost by at least kStallRise (in cost units, and 0.1 % of
// the cost): a residual that jumps next to the current point. Near a minimum, rounding rejects
// steps too, but they raise the cost by far less (a flat pusher's push: 0.005).
constexpr double kStallDamping = 1e3;
constexpr double kStallRise = 1.0;

// A small change is convergence only when the step's model agreed it is small: within this
// multiple of the function tolerance (any step with rho >= 1/4 passes). A step accepted at a
// small rho changes the cost little because its model failed: on the MIT ellip1 recording v=50
// t=-0.349 the solve "converged" at 1125.44 where Ceres went on to 1121.56; now 1120.70.
constexpr double kModelDecreaseSlack = 4.0;

// weight * Ja^T Jb into the lower triangle, sizes known at compile time where M, R, C > 0 (the
// loops then unroll: the accumulation was a fifth of a QS batch solve with run-time sizes). The
// same products in the same order either way, so the same sums.
template <int M, int R, int C, bool kDiagonal>
void AccumulatePair(const double* Ja, const double* Jb, double weight, int m, int rows, int cols, const int* offsets,
                    double* h) {
  if constexpr (M > 0) m = M, rows = R, cols = C;
  for (int c = 0; c < cols; ++c) {
    double* column = h + offsets[c];
    for (int u = kDiagonal ? c : 0, o = 0; u < rows; ++u, ++o) {
      double sum = 0.0;
      for (int i = 0; i < m; ++i) sum += Ja[i * rows + u] * Jb[i * cols + c];
      column[o] += weight * sum;
    }
  }
}

template <int M, int R, int C>
ChainSolver::Impl::PairKernel SizedKernel(bool diagonal) {
  return diagonal ? &AccumulatePair<M, R, C, true> : &AccumulatePair<M, R, C, false>;
}

template <int M, int R>
ChainSolver::Impl::PairKernel KernelForCols(int cols, bool diagonal) {
  switch (cols) {
    case 1: return SizedKernel<M, R, 1>(diagonal);
    case 2: return SizedKernel<M, R, 2>(diagonal);
    case 3: return SizedKernel<M, R, 3>(diagonal);
    default: return nullptr;
  }
}

template <int M>
ChainSolver::Impl::PairKernel KernelForRows(int rows, int cols, bool diagonal) {
  switch (rows) {
    case 1: return KernelForCols<M, 1>(cols, diagonal);
    case 2: return KernelForCols<M, 2>(cols, diagonal);
    case 3: return KernelForCols<M, 3>(cols, diagonal);
    default: return nullptr;
  }
}

ChainSolver::Impl::PairKernel KernelFor(int m, int rows, int cols, bool diagonal) {
  ChainSolver::Impl::PairKernel k = nullptr;
  switch (m) {
    case 1: k = KernelForRows<1>(rows, cols, diagonal); break;
    case 2: k = KernelForRows<2>(rows, cols, diagonal); break;
    case 3: k = KernelForRows<3>(rows, cols, diagonal); break;
    default: break;
  }
  if (k != nullptr) return k;
  return diagonal ? &AccumulatePair<0, 0, 0, true> : &AccumulatePair<0, 0, 0, false>;
}

std::string FormatNumber(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

std::string DefaultDescription(int index, const ChainSolver::Impl::Residual& r) {
  return "residual block " + std::to_string(index) + " (" + std::to_string(r.m) + " residuals, " +
         std::to_string(r.num_params) + " parameter blocks)";
}

}  // namespace

ChainSolver::Impl::Impl(ceres::Problem& p) : problem(&p) {
  std::vector<double*> all;
  problem->GetParameterBlocks(&all);
  std::vector<ceres::ResidualBlockId> ids;
  problem->GetResidualBlocks(&ids);
  // Every parameter block's place in `all`, looked up once per residual parameter and kept
  // (a set of the used pointers and a second map lookup per parameter were a third of the
  // constructor's time, which an incremental update pays three times).
  std::unordered_map<const double*, int> position;
  position.reserve(2 * all.size());
  for (std::size_t i = 0; i < all.size(); ++i) position.emplace(all[i], static_cast<int>(i));
  std::vector<char> used(all.size(), 0);
  std::vector<int> param_position;
  residuals.resize(ids.size());
  param_ptrs.reserve(4 * ids.size());
  param_position.reserve(4 * ids.size());
  std::vector<double*> params;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    problem->GetParameterBlocksForResidualBlock(ids[k], &params);
    residuals[k].param_begin = static_cast<int>(param_ptrs.size());
    residuals[k].num_params = static_cast<int>(params.size());
    for (double* q : params) {
      const int i = position.at(q);
      used[i] = 1;
      param_ptrs.push_back(q);
      param_position.push_back(i);
    }
  }
  // Offsets in the order the blocks were added (time order for the estimator: the band).
  std::vector<int> block_of_position(all.size(), -1);
  int offset = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    double* b = all[i];
    const int size = problem->ParameterBlockSize(b);
    if (problem->IsParameterBlockConstant(b) || !used[i] || size == 0) {
      fixed[b] = size;
      continue;
    }
    if (problem->GetManifold(b) != nullptr) throw GraphError("ChainSolver: a parameter block has a manifold (not supported)");
    Block block;
    block.ptr = b;
    block.offset = offset;
    block.size = size;
    for (int j = 0; j < size; ++j) {
      lower.push_back(problem->GetParameterLowerBound(b, j));
      upper.push_back(problem->GetParameterUpperBound(b, j));
      block.bounded |= lower.back() > -std::numeric_limits<double>::max() || upper.back() < std::numeric_limits<double>::max();
    }
    block_of_position[i] = static_cast<int>(blocks.size());
    blocks.push_back(block);
    offset += size;
  }
  n = offset;
  // Residual blocks, their Jacobian storage, and for every variable block b the blocks a >= b
  // it shares a residual block with (J^T J's block pattern below the diagonal: a few per block
  // in a chain, all of them for a block shared by the trajectory such as c; sorting every pair,
  // setFromTriplets and a binary search per entry were 40 % of the constructor's time).
  std::vector<std::vector<int>> below(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b) below[b].push_back(static_cast<int>(b));
  int jacobian_size = 0, residual_size = 0;
  param_block.resize(param_ptrs.size());
  param_offset.resize(param_ptrs.size());
  param_size.resize(param_ptrs.size());
  std::vector<int> jacobian_offset(param_ptrs.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    Residual& r = residuals[k];
    r.id = ids[k];
    r.cost = problem->GetCostFunctionForResidualBlock(ids[k]);
    r.loss = problem->GetLossFunctionForResidualBlock(ids[k]);
    r.m = r.cost->num_residuals();
    r.residual_offset = residual_size;
    residual_size += r.m;
    r.constant = true;
    for (int q = r.param_begin; q < r.param_begin + r.num_params; ++q) {
      const int b = block_of_position[param_position[q]];
      param_block[q] = b;
      param_offset[q] = b < 0 ? -1 : blocks[b].offset;
      param_size[q] = b < 0 ? 0 : blocks[b].size;
      jacobian_offset[q] = jacobian_size;
      jacobian_size += r.m * param_size[q];
      // A residual block on constant blocks only adds a constant to the cost (Ceres' fixed
      // cost): it is evaluated once per Solve, not in every iteration.
      r.constant = r.constant && b < 0;
    }
    for (int qa = r.param_begin; qa < r.param_begin + r.num_params; ++qa) {
      for (int qb = r.param_begin; qb < r.param_begin + r.num_params; ++qb) {
        const int a = param_block[qa], b = param_block[qb];
        if (a > b && b >= 0) below[b].push_back(a);  // duplicates removed below
      }
    }
  }
  jacobian_values.assign(jacobian_size, 0.0);
  residual_values.assign(residual_size, 0.0);
  param_jacobian.resize(param_ptrs.size());
  for (std::size_t q = 0; q < param_ptrs.size(); ++q) {
    param_jacobian[q] = param_block[q] < 0 ? nullptr : jacobian_values.data() + jacobian_offset[q];
  }
  // The pattern, column by column: block b's column k holds rows k.. of b itself, then every row
  // of each block below it in order. rows_before[b][i]: the rows of below[b][1..i-1].
  std::vector<std::vector<int>> rows_before(blocks.size());
  std::size_t nonzeros = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    std::vector<int>& rows = below[b];
    std::sort(rows.begin() + 1, rows.end());
    rows.erase(std::unique(rows.begin() + 1, rows.end()), rows.end());
    rows_before[b].assign(rows.size(), 0);
    for (std::size_t i = 2; i < rows.size(); ++i) rows_before[b][i] = rows_before[b][i - 1] + blocks[rows[i - 1]].size;
    const std::size_t size = static_cast<std::size_t>(blocks[b].size);
    const std::size_t rows_below = rows.size() < 2 ? 0 : static_cast<std::size_t>(rows_before[b].back() + blocks[rows.back()].size);
    nonzeros += size * (size + 1) / 2 + size * rows_below;
  }
  // Written straight into H's compressed storage (a copy through a Map of separate index arrays
  // was an eighth of the constructor's time).
  H.resize(n, n);
  H.resizeNonZeros(static_cast<Eigen::Index>(nonzeros));
  int* outer = H.outerIndexPtr();
  int* inner = H.innerIndexPtr();
  std::fill(H.valuePtr(), H.valuePtr() + nonzeros, 0.0);
  outer[0] = 0;
  int written = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const std::vector<int>& rows = below[b];
    const Block& cb = blocks[b];
    for (int k = 0; k < cb.size; ++k) {
      for (std::size_t i = 0; i < rows.size(); ++i) {
        const Block& ra = blocks[rows[i]];
        for (int u = (i == 0 ? k : 0); u < ra.size; ++u) inner[written++] = ra.offset + u;
      }
      outer[cb.offset + k + 1] = written;
    }
  }
  if (static_cast<std::size_t>(written) != nonzeros) throw GraphError("ChainSolver: internal error in the J^T J pattern");
  diagonal.assign(outer, outer + n);  // each column starts at its diagonal
  pairs.reserve(3 * param_ptrs.size());
  column_offsets.reserve(9 * param_ptrs.size());
  for (Residual& r : residuals) {
    r.pair_begin = static_cast<int>(pairs.size());
    for (int a = 0; a < r.num_params; ++a) {
      for (int b = 0; b < r.num_params; ++b) {
        const int row_block = param_block[r.param_begin + a], col_block = param_block[r.param_begin + b];
        if (row_block < 0 || col_block < 0 || row_block < col_block) continue;
        Pair pair;
        pair.row_param = a;
        pair.col_param = b;
        pair.offsets_begin = static_cast<int>(column_offsets.size());
        const Block& ra = blocks[row_block];
        const Block& cb = blocks[col_block];
        pair.kernel = KernelFor(r.m, ra.size, cb.size, a == b);
        pair.rows = ra.size;
        pair.cols = cb.size;
        const std::vector<int>& rows = below[col_block];
        const std::size_t i = row_block == col_block ? 0 : static_cast<std::size_t>(std::lower_bound(rows.begin() + 1, rows.end(), row_block) - rows.begin());
        for (int k = 0; k < cb.size; ++k) {
          column_offsets.push_back(outer[cb.offset + k] + (i == 0 ? 0 : cb.size - k + rows_before[col_block][i]));
        }
        pairs.push_back(pair);
      }
    }
    r.pair_end = static_cast<int>(pairs.size());
  }
  values.assign(H.nonZeros(), 0.0);
  trial_values.assign(H.nonZeros(), 0.0);
  for (int j = 0; j < n; ++j) {
    const int last = H.outerIndexPtr()[j + 1] - 1;
    if (last >= H.outerIndexPtr()[j]) band_width = std::max(band_width, H.innerIndexPtr()[last] - j);
  }
  const char* band_env = std::getenv("PUSHGRAPH_BAND");
  banded = band_width <= kMaxBandWidth && !(band_env && band_env[0] == '0');
  if (banded) {
    band_index.resize(H.nonZeros());
    const int ld = band_width + 1;
    for (int j = 0; j < n; ++j) {
      for (int k = H.outerIndexPtr()[j]; k < H.outerIndexPtr()[j + 1]; ++k) band_index[k] = j * ld + (H.innerIndexPtr()[k] - j);
    }
    band.assign(static_cast<std::size_t>(ld) * n, 0.0);
  }
  gradient = Eigen::VectorXd::Zero(n);
  trial_gradient = Eigen::VectorXd::Zero(n);
}

void ChainSolver::Impl::Gather(Eigen::VectorXd& x) const {
  x.resize(n);
  for (const Block& b : blocks) std::copy(b.ptr, b.ptr + b.size, x.data() + b.offset);
}

void ChainSolver::Impl::Scatter(const Eigen::VectorXd& x) {
  for (const Block& b : blocks) std::copy(x.data() + b.offset, x.data() + b.offset + b.size, b.ptr);
}

void ChainSolver::Impl::Project(Eigen::VectorXd& x) const {
  for (const Block& b : blocks) {
    if (!b.bounded) continue;
    for (int i = b.offset; i < b.offset + b.size; ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);
  }
}

bool ChainSolver::Impl::Evaluate(std::vector<double>& h, Eigen::VectorXd& g, double* cost, int* failed) {
  std::fill(h.begin(), h.end(), 0.0);
  g.setZero();
  double total = 0.0;
  for (std::size_t k = 0; k < residuals.size(); ++k) {
    const Residual& r = residuals[k];
    // The cost functions are separate heap objects, each read once an iteration: without this,
    // the load of the next one's size was a third of this loop's own time (a cache miss).
    if (k + 2 < residuals.size()) PrefetchForRead(residuals[k + 2].cost);
    if (r.constant) continue;
    const int m = r.m;
    double* const* jacobians = param_jacobian.data() + r.param_begin;
    const int* offset = param_offset.data() + r.param_begin;
    const int* size = param_size.data() + r.param_begin;
    double* res = residual_values.data() + r.residual_offset;
    bool ok = r.cost->Evaluate(param_ptrs.data() + r.param_begin, res, const_cast<double**>(jacobians));
    double sq = 0.0;
    for (int i = 0; ok && i < m; ++i) {
      ok = std::isfinite(res[i]);
      sq += res[i] * res[i];
    }
    for (int q = 0; ok && q < r.num_params; ++q) {
      const double* J = jacobians[q];
      for (int i = 0, count = m * size[q]; ok && i < count; ++i) ok = std::isfinite(J[i]);
    }
    if (!ok) {
      *failed = static_cast<int>(k);
      return false;
    }
    double weight = 1.0;
    if (r.loss != nullptr) {
      double rho[3];
      r.loss->Evaluate(sq, rho);
      total += 0.5 * rho[0];
      weight = std::max(rho[1], 0.0);
    } else {
      total += 0.5 * sq;
    }
    // J^T J straight from the blocks' row-major Jacobians into the stored lower triangle, pair
    // by pair, and J^T r: no copy into one m x k matrix, and only the lower triangle's products
    // (the blocks are tiny, m <= 3 and k <= 11 but for marginal priors: Eigen's dynamic-size
    // products of the whole k x k cost more than the arithmetic; BM_BatchQs/1000's last-stage
    // evaluation 120 to 153 ms before, 96 to 97 ms after).
    for (int q = 0; q < r.num_params; ++q) {
      if (offset[q] < 0) continue;
      const double* J = jacobians[q];
      double* gq = g.data() + offset[q];
      for (int i = 0; i < m; ++i) {
        const double wr = weight * res[i];
        const double* row = J + i * size[q];
        for (int u = 0; u < size[q]; ++u) gq[u] += wr * row[u];
      }
    }
    for (int pi = r.pair_begin; pi < r.pair_end; ++pi) {
      const Pair& pair = pairs[pi];
      pair.kernel(jacobians[pair.row_param], jacobians[pair.col_param], weight, m, pair.rows, pair.cols,
                  column_offsets.data() + pair.offsets_begin, h.data());
    }
  }
  *cost = total;
  return std::isfinite(total);
}

bool ChainSolver::Impl::FixedCost(double* cost, int* failed) {
  double total = 0.0;
  for (std::size_t k = 0; k < residuals.size(); ++k) {
    const Residual& r = residuals[k];
    if (!r.constant) continue;
    double* res = residual_values.data() + r.residual_offset;
    if (!r.cost->Evaluate(param_ptrs.data() + r.param_begin, res, nullptr)) {
      *failed = static_cast<int>(k);
      return false;
    }
    double sq = 0.0;
    for (int i = 0; i < r.m; ++i) sq += res[i] * res[i];
    if (r.loss != nullptr) {
      double rho[3];
      r.loss->Evaluate(sq, rho);
      sq = rho[0];
    }
    if (!std::isfinite(sq)) {
      *failed = static_cast<int>(k);
      return false;
    }
    total += 0.5 * sq;
  }
  *cost = total;
  return true;
}

std::string ChainSolver::Impl::Describe(const ChainSolverOptions& options, int k) const {
  return options.describe ? options.describe(residuals[k].id) : DefaultDescription(k, residuals[k]);
}

std::string ChainSolver::Impl::DescribeUnknown(int unknown) const {
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    if (unknown >= blocks[b].offset && unknown < blocks[b].offset + blocks[b].size) {
      return "parameter block " + std::to_string(b) + " (component " + std::to_string(unknown - blocks[b].offset) + ")";
    }
  }
  return "unknown " + std::to_string(unknown);
}

bool ChainSolver::Impl::Factorize(const std::vector<double>& h, double lambda) {
  std::copy(h.begin(), h.end(), H.valuePtr());
  if (lambda > 0.0) {
    for (int j = 0; j < n; ++j) {
      double& d = H.valuePtr()[diagonal[j]];
      d += lambda * std::clamp(d, kMinDiagonal, kMaxDiagonal);
    }
  }
  if (!analyzed) {
    llt.analyzePattern(H);
    analyzed = true;
  }
  llt.factorize(H);
  return llt.info() == Eigen::Success;
}

bool ChainSolver::Impl::FactorizeIteration(const std::vector<double>& h, double lambda) {
  if (!banded) return Factorize(h, lambda);
  std::fill(band.begin(), band.end(), 0.0);
  for (std::size_t k = 0; k < h.size(); ++k) band[band_index[k]] = h[k];
  const int ld = band_width + 1;
  if (lambda > 0.0) {
    for (int j = 0; j < n; ++j) {
      double& d = band[static_cast<std::size_t>(j) * ld];
      d += lambda * std::clamp(d, kMinDiagonal, kMaxDiagonal);
    }
  }
  int info = 0;
  dpbtrf_("L", &n, &band_width, band.data(), &ld, &info);
  return info == 0;
}

Eigen::VectorXd ChainSolver::Impl::SolveIteration(const Eigen::VectorXd& rhs) {
  if (!banded) return llt.solve(rhs);
  Eigen::VectorXd x = rhs;
  const int ld = band_width + 1, one = 1;
  int info = 0;
  dpbtrs_("L", &n, &band_width, &one, band.data(), &ld, x.data(), &n, &info);
  return x;
}

std::string ChainSolver::Impl::LargestJump(const ChainSolverOptions& options, const Eigen::VectorXd& x,
                                           const Eigen::VectorXd& near) {
  // Each residual block's cost at the solution and at the last rejected point next to it.
  auto block_costs = [this](const Eigen::VectorXd& at, std::vector<double>* costs) {
    Scatter(at);
    costs->assign(residuals.size(), 0.0);
    std::vector<double> r;
    for (std::size_t k = 0; k < residuals.size(); ++k) {
      const Residual& b = residuals[k];
      if (b.constant) continue;
      r.resize(b.m);
      if (!b.cost->Evaluate(param_ptrs.data() + b.param_begin, r.data(), nullptr)) {
        (*costs)[k] = INFINITY;
        continue;
      }
      double sq = 0.0;
      for (double v : r) sq += v * v;
      if (b.loss != nullptr) {
        double rho[3];
        b.loss->Evaluate(sq, rho);
        sq = rho[0];
      }
      (*costs)[k] = 0.5 * sq;
    }
  };
  std::vector<double> here, there;
  block_costs(near, &there);
  block_costs(x, &here);
  int worst = -1;
  for (std::size_t k = 0; k < residuals.size(); ++k)
    if (!residuals[k].constant && (worst < 0 || there[k] - here[k] > there[worst] - here[worst])) worst = static_cast<int>(k);
  if (worst < 0) return "no residual to name";
  return "the largest jump, " + FormatNumber(here[worst]) + " to " + FormatNumber(there[worst]) + " for a step of " +
         FormatNumber((near - x).norm()) + ": " + Describe(options, worst) +
         " (a residual not smooth there: a contact feature that switches, a shape corner)";
}

ChainSolver::ChainSolver(ceres::Problem& problem) : impl_(std::make_unique<Impl>(problem)) {}
ChainSolver::~ChainSolver() = default;
ChainSolver::ChainSolver(ChainSolver&&) noexcept = default;
ChainSolver& ChainSolver::operator=(ChainSolver&&) noexcept = default;

ChainSolverSummary ChainSolver::Solve(const ChainSolverOptions& options) {
  Impl& s = *impl_;
  const auto start = Clock::now();
  ChainSolverSummary summary;
  summary.unknowns = s.n;
  summary.hessian_nonzeros = static_cast<long>(s.values.size());
  s.evaluated_at_current = false;
  if (s.n == 0) {
    summary.converged = true;
    summary.termination = "no variable parameter blocks";
    return summary;
  }
  Eigen::VectorXd x, x_trial, step, rejected_trial;  // the last rejected point, and how much it raised the cost
  double rejected_rise = 0.0;
  s.Gather(x);
  double cost = 0.0;
  int failed = -1;
  auto timed_evaluate = [&](std::vector<double>& h, Eigen::VectorXd& g, double* c) {
    const auto t = Clock::now();
    const bool ok = s.Evaluate(h, g, c, &failed);
    summary.evaluate_s += SecondsSince(t);
    return ok;
  };
  double fixed_cost = 0.0;
  if (!s.FixedCost(&fixed_cost, &failed)) {
    throw GraphError("solver: " + s.Describe(options, failed) + " (on constant blocks) fails to evaluate or is not finite");
  }
  if (!timed_evaluate(s.values, s.gradient, &cost)) {
    throw GraphError("solver: " + s.Describe(options, failed) +
                     " fails to evaluate or is not finite at the starting point");
  }
  s.x_evaluated = x;
  s.evaluated_at_current = true;
  summary.initial_cost = summary.final_cost = cost + fixed_cost;
  double lambda = options.initial_damping, nu = 2.0;
  auto gradient_converged = [&](const Eigen::VectorXd& at, const Eigen::VectorXd& g) {
    Eigen::VectorXd projected = at - g;
    s.Project(projected);
    return (at - projected).lpNorm<Eigen::Infinity>() <= options.gradient_tolerance;
  };
  if (gradient_converged(x, s.gradient)) {
    summary.converged = true;
    summary.termination = "gradient tolerance";
  }
  int failed_factorizations = 0;
  while (!summary.converged && summary.iterations < options.max_iterations) {
    ++summary.iterations;
    const auto t_linear = Clock::now();
    const bool factorized = s.FactorizeIteration(s.values, lambda);
    if (factorized) step = -s.SolveIteration(s.gradient);
    summary.linear_solve_s += SecondsSince(t_linear);
    if (summary.factor_flops == 0.0 && factorized) {
      // Per column j with c_j entries below the diagonal: c_j^2 + 3 c_j for the factorization,
      // 4 per entry of the factor for the two triangular solves.
      double flops = 0.0, nonzeros = 0.0;
      for (int j = 0; j < s.n; ++j) {
        double c = 0.0;
        if (s.banded) {
          c = std::min(s.band_width, s.n - 1 - j);
        } else {
          const auto& L = s.llt.matrixL().nestedExpression();
          c = L.outerIndexPtr()[j + 1] - L.outerIndexPtr()[j] - 1;
        }
        flops += c * c + 3.0 * c;
        nonzeros += c + 1.0;
      }
      summary.factor_nonzeros = static_cast<long>(nonzeros);
      summary.factor_flops = flops + 4.0 * nonzeros;
    }
    if (!factorized || !step.allFinite()) {
      // Not positive definite under this damping: more damping (a gradient-descent-like step).
      ++summary.unsuccessful_steps;
      lambda *= nu;
      nu *= 2.0;
      if (++failed_factorizations > 30) {
        int worst = 0;
        for (int j = 0; j < s.n; ++j) {
          if (!(s.values[s.diagonal[j]] > s.values[s.diagonal[worst]])) worst = j;
        }
        throw GraphError("solver: J^T J is singular or not finite under any damping; smallest diagonal at " +
                         s.DescribeUnknown(worst));
      }
      continue;
    }
    failed_factorizations = 0;
    x_trial = x + step;
    s.Project(x_trial);
    step = x_trial - x;
    if (step.norm() <= options.parameter_tolerance * (x.norm() + options.parameter_tolerance)) {
      summary.converged = true;
      summary.termination = "parameter tolerance";
      --summary.iterations;
      break;
    }
    const Eigen::VectorXd h_step = s.H_undamped_times(step);
    const double model_decrease = -(s.gradient.dot(step) + 0.5 * step.dot(h_step));
    s.Scatter(x_trial);
    double trial_cost = 0.0;
    const bool evaluated = timed_evaluate(s.trial_values, s.trial_gradient, &trial_cost);
    const double rho = evaluated && model_decrease > 0.0 ? (cost - trial_cost) / model_decrease : -1.0;
    if (options.log_iterations) {
      std::fprintf(stderr, "chain solver %3d: cost %.6e -> %.6e, model decrease %.3e, rho %.3f, lambda %.2e, |dx| %.3e\n",
                   summary.iterations, cost, evaluated ? trial_cost : NAN, model_decrease, rho, lambda, step.norm());
    }
    if (evaluated && rho > kMinRelativeDecrease) {
      const double lambda_used = lambda;
      ++summary.successful_steps;
      const double change = cost - trial_cost;
      x.swap(x_trial);
      std::swap(s.values, s.trial_values);
      s.gradient.swap(s.trial_gradient);
      cost = trial_cost;
      s.x_evaluated = x;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      lambda = std::max(lambda, 1e-16);
      nu = 2.0;
      if (change <= options.function_tolerance * cost && lambda_used >= kStallDamping && rejected_trial.size() == s.n &&
          rejected_rise >= std::max(kStallRise, 1e-3 * cost)) {
        summary.stalled = true;
        summary.termination = "stalled: every step but vanishing ones raised the cost (damping " +
                              FormatNumber(lambda_used) + "); " + s.LargestJump(options, x, rejected_trial);
        break;
      } else if (change <= options.function_tolerance * cost &&
                 (!options.model_confirms_convergence ||
                  model_decrease <= kModelDecreaseSlack * options.function_tolerance * cost)) {
        summary.converged = true;
        summary.termination = "function tolerance";
      } else if (gradient_converged(x, s.gradient)) {
        summary.converged = true;
        summary.termination = "gradient tolerance";
      } else if (options.soft_iteration_limit > 0 && summary.iterations >= options.soft_iteration_limit &&
                 change <= options.soft_function_tolerance * cost) {
        summary.termination = "soft limit (" + std::to_string(options.soft_iteration_limit) + " iterations, change below " +
                              FormatNumber(options.soft_function_tolerance) + " of the cost)";
        break;
      }
    } else {
      ++summary.unsuccessful_steps;
      if (evaluated) {
        rejected_trial = x_trial;
        rejected_rise = trial_cost - cost;
      }
      s.Scatter(x);
      lambda *= nu;
      nu *= 2.0;
    }
  }
  if (!summary.converged && summary.termination.empty())
    summary.termination = "iteration limit (" + std::to_string(options.max_iterations) + ")";
  s.Scatter(x);
  summary.final_cost = cost + fixed_cost;
  summary.total_s = SecondsSince(start);
  return summary;
}

Eigen::VectorXd ChainSolver::Impl::H_undamped_times(const Eigen::VectorXd& v) {
  // `values` on H's pattern, without copying them into H.
  const Eigen::Map<const Eigen::SparseMatrix<double>> undamped(n, n, static_cast<Eigen::Index>(values.size()),
                                                               H.outerIndexPtr(), H.innerIndexPtr(), values.data());
  return undamped.selfadjointView<Eigen::Lower>() * v;
}

bool ChainSolver::Impl::FactorizeAtCurrentValues(std::string* error) {
  Eigen::VectorXd x;
  Gather(x);
  if (!evaluated_at_current || x_evaluated.size() != x.size() || x_evaluated != x) {
    double cost = 0.0;
    int failed = -1;
    if (!Evaluate(values, gradient, &cost, &failed)) {
      *error = "a residual block failed to evaluate or gave a non-finite residual or Jacobian (" +
               DefaultDescription(failed, residuals[failed]) + ")";
      return false;
    }
    x_evaluated = x;
    evaluated_at_current = true;
  }
  if (!Factorize(values, 0.0)) {
    *error = "the information matrix J^T J is not positive definite (an unobservable direction: gauge "
             "freedom or too few factors)";
    return false;
  }
  return true;
}

}  // namespace pushgraph::graph
