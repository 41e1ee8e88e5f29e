// Selected inversion of a sparse Cholesky factor (Takahashi, Fagan and Chen 1973; the form of
// Kaess and Dellaert 2009, Sec. 4): with H = L L^T and Z = H^-1, L^T Z = L^-1 is lower
// triangular with diagonal 1 / L_jj, so for each column j (from the last) and each row i > j of
// L's pattern
//   Z_ij = -(1 / L_jj) sum_{k > j, L_kj != 0} L_kj Z_ki,
//   Z_jj = (1 / L_jj) (1 / L_jj - sum_{k > j, L_kj != 0} L_kj Z_kj).
// Every Z_ki needed lies in L's pattern (the rows of a column of L form a clique of the filled
// graph), so only that pattern is ever computed.
#include <pushgraph/graph/marginals.h>

#include "chain_solver_impl.h"

#include <ceres/crs_matrix.h>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace pushgraph::graph {
namespace {
// The pivot ratio L_jj^2 / H_jj is the fraction of an unknown's information left after the
// ones eliminated before it (1 - R^2). Forming J^T J squares J's conditioning: against
// ceres::Covariance's QR on J, the selected inverse's worst relative error was 1e-16 to 1.3e-13
// divided by the smallest ratio (a simulated push with C and S made stiff on purpose, ratios
// 2e-3 to 3e-14; MIT ellip1 recordings at their full rate, about 3e-8, where 250 Hz steps make
// V stiff: errors 1e-6 to 5e-6). Below 1e-9 (accepted_pivot_ratio_'s default) it could lose more
// than 4 digits in double: the factorization and inversion are then redone in extended precision
// (long double: a 64-bit significand on x86, eps 5.4e-20 against 1.1e-16), where the same 4 digits
// hold down to a ratio 2000 times smaller (ExtendedPivotRatio); below that, refuse (the estimator
// then uses the QR); below kSingular the direction has no information of its own.
constexpr double kSingular = 1e-14;

// The accepted ratio scaled to long double's rounding (the error bound is eps / ratio); where
// long double is double (MSVC), nothing is gained and the extended pass is skipped.
double ExtendedPivotRatio(double accepted) {
  const double gain = static_cast<double>(std::numeric_limits<long double>::epsilon()) / std::numeric_limits<double>::epsilon();
  return std::max(accepted * gain, kSingular);
}
bool HaveExtendedPrecision() {
  return std::numeric_limits<long double>::epsilon() < std::numeric_limits<double>::epsilon();
}

std::string FormatRatio(double ratio) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", ratio);
  return text;
}
}  // namespace

struct SparseMarginals::Impl {
  std::unordered_map<const double*, std::pair<int, int>> blocks;  // offset, size
  std::unordered_map<const double*, int> fixed;                   // constant or unused: size
  Eigen::VectorXi perm;                                           // original -> factor order
  // The factor's pattern (column-major, rows sorted, the diagonal first) and Z on it.
  std::vector<int> col_start, row;
  std::vector<double> z;

  // Z(a, b) in factor order; nullptr when outside the pattern.
  const double* Find(int a, int b) const {
    const int c = std::min(a, b), r = std::max(a, b);
    const auto first = row.begin() + col_start[c], last = row.begin() + col_start[c + 1];
    const auto it = std::lower_bound(first, last, r);
    if (it == last || *it != r) return nullptr;
    return &z[it - row.begin()];
  }
};

SparseMarginals::SparseMarginals() = default;
SparseMarginals::~SparseMarginals() = default;
SparseMarginals::SparseMarginals(SparseMarginals&&) noexcept = default;
SparseMarginals& SparseMarginals::operator=(SparseMarginals&&) noexcept = default;

int SparseMarginals::num_unknowns() const { return impl_ ? static_cast<int>(impl_->perm.size()) : 0; }
long SparseMarginals::num_factor_nonzeros() const { return impl_ ? static_cast<long>(impl_->row.size()) : 0; }

bool SparseMarginals::Compute(ceres::Problem& problem) {
  impl_.reset();
  error_.clear();
  failed_block_ = nullptr;
  extended_precision_ = false;
  auto impl = std::make_unique<Impl>();
  std::vector<double*> all, variable;
  problem.GetParameterBlocks(&all);
  // Blocks no residual uses carry no information: like ceres::Covariance, they are held fixed.
  std::unordered_map<const double*, bool> used;
  {
    std::vector<ceres::ResidualBlockId> residual_blocks;
    problem.GetResidualBlocks(&residual_blocks);
    std::vector<double*> ps;
    for (ceres::ResidualBlockId id : residual_blocks) {
      problem.GetParameterBlocksForResidualBlock(id, &ps);
      for (double* p : ps) used[p] = true;
    }
  }
  int n = 0;
  for (double* b : all) {
    if (problem.IsParameterBlockConstant(b) || !used.count(b)) {
      impl->fixed[b] = problem.ParameterBlockSize(b);
      continue;
    }
    if (problem.GetManifold(b) != nullptr) {
      error_ = "a parameter block has a manifold (not supported)";
      return false;
    }
    const int size = problem.ParameterBlockSize(b);
    impl->blocks[b] = {n, size};
    variable.push_back(b);
    n += size;
  }
  if (n == 0) {
    error_ = "no variable parameter blocks";
    return false;
  }
  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  timings_ = Timings{};
  auto phase = Clock::now();
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = variable;
  eval.apply_loss_function = true;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(eval, nullptr, nullptr, nullptr, &crs)) {
    error_ = "a residual block failed to evaluate or gave a non-finite residual or Jacobian";
    return false;
  }
  for (std::size_t k = 0; k < crs.values.size(); ++k) {
    if (!std::isfinite(crs.values[k])) {
      error_ = "the Jacobian has a non-finite entry (row " + std::to_string(
                   std::upper_bound(crs.rows.begin(), crs.rows.end(), static_cast<int>(k)) - crs.rows.begin() - 1) + ")";
      return false;
    }
  }
  timings_.jacobian = seconds_since(phase);
  phase = Clock::now();
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> J(
      crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(), crs.cols.data(),
      crs.values.data());
  const Eigen::SparseMatrix<double> H = Eigen::SparseMatrix<double>(J.transpose()) * J;
  timings_.normal_equations = seconds_since(phase);
  phase = Clock::now();
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(H);
  if (llt.info() != Eigen::Success) {
    error_ = "the information matrix J^T J is not positive definite (an unobservable direction: gauge "
             "freedom or too few factors)";
    return false;
  }
  impl->perm = llt.permutationP().indices();
  Eigen::VectorXd h_diag(n);
  for (int a = 0; a < n; ++a) h_diag[impl->perm[a]] = H.coeff(a, a);
  bool ok = SelectedInverse(llt.matrixL().nestedExpression(), h_diag, variable, *impl, phase, accepted_pivot_ratio_);
  if (!ok && ill_conditioned_) ok = ComputeExtended(J, variable, *impl);
  if (ok) impl_ = std::move(impl);
  return ok;
}

bool SparseMarginals::ComputeExtended(const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>& J,
                                      const std::vector<double*>& variable, Impl& impl) {
  if (!HaveExtendedPrecision()) return false;
  // J^T J formed, factorized and inverted in long double: J's entries are exact in it, so the
  // squaring of J's condition costs the extended format's digits instead of double's.
  using Long = long double;
  const auto phase = std::chrono::steady_clock::now();
  const Eigen::SparseMatrix<Long, Eigen::RowMajor> Jl = J.cast<Long>();
  const Eigen::SparseMatrix<Long> H = Eigen::SparseMatrix<Long>(Jl.transpose()) * Jl;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<Long>, Eigen::Lower, Eigen::AMDOrdering<int>> llt(H);
  if (llt.info() != Eigen::Success) return false;
  error_.clear();
  failed_block_ = nullptr;
  impl.perm = llt.permutationP().indices();
  impl.col_start.clear();
  impl.row.clear();
  impl.z.clear();
  const int n = static_cast<int>(H.rows());
  Eigen::Matrix<Long, Eigen::Dynamic, 1> h_diag(n);
  for (int a = 0; a < n; ++a) h_diag[impl.perm[a]] = H.coeff(a, a);
  const bool ok = SelectedInverse(llt.matrixL().nestedExpression(), h_diag, variable, impl, phase,
                                  ExtendedPivotRatio(accepted_pivot_ratio_));
  if (ok) extended_precision_ = true;
  else error_ += " (in extended precision too)";
  return ok;
}

void SparseMarginals::set_accepted_pivot_ratio(double ratio) {
  accepted_pivot_ratio_ = std::max(ratio, kSingular);
}

template <typename Scalar>
bool SparseMarginals::SelectedInverse(const Eigen::SparseMatrix<Scalar>& L, const Eigen::Matrix<Scalar, Eigen::Dynamic, 1>& h_diag,
                                      const std::vector<double*>& variable, Impl& impl_ref,
                                      std::chrono::steady_clock::time_point phase, double accepted_ratio) {
  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  Impl* impl = &impl_ref;
  const int n = static_cast<int>(h_diag.size());
  // A pivot that keeps almost none of its variable's information (L_jj^2 against H_jj: 1 - R^2
  // of that unknown on the earlier ones) is a numerically dependent direction.
  impl->col_start.assign(n + 1, 0);
  std::vector<std::pair<int, Scalar>> column;
  std::vector<Scalar> values;
  min_pivot_ratio_ = INFINITY;
  ill_conditioned_ = false;
  for (int j = 0; j < n; ++j) {
    column.clear();
    for (typename Eigen::SparseMatrix<Scalar>::InnerIterator it(L, j); it; ++it) column.emplace_back(static_cast<int>(it.row()), it.value());
    std::sort(column.begin(), column.end());
    const double ratio = column.empty() || column.front().first != j
                             ? 0.0
                             : static_cast<double>(column.front().second * column.front().second / h_diag[j]);
    if (!(ratio > accepted_ratio) || !std::isfinite(static_cast<double>(h_diag[j])) || !(column.front().second > 0)) {
      int a = 0;
      while (a < n && impl->perm[a] != j) ++a;
      for (double* b : variable) {
        const auto [offset, size] = impl->blocks[b];
        if (a >= offset && a < offset + size) {
          failed_block_ = b;
          const std::string component = "(component " + std::to_string(a - offset) + ")";
          if (!std::isfinite(static_cast<double>(h_diag[j]))) {
            error_ = "the information matrix J^T J overflows at a parameter block " + component;
          } else if (!(ratio > kSingular)) {
            error_ = "the information matrix J^T J is (numerically) singular at a parameter block " + component +
                     ": it has no information independent of the others (unobservable or gauge freedom)";
          } else {
            ill_conditioned_ = true;
            error_ = "the information matrix J^T J is ill-conditioned at a parameter block " + component +
                     ": pivot ratio " + FormatRatio(ratio) +
                     " below " + FormatRatio(accepted_ratio) +
                     ", the selected inverse could lose more than 4 digits (use a QR on J)";
          }
          break;
        }
      }
      return false;
    }
    min_pivot_ratio_ = std::min(min_pivot_ratio_, ratio);
    for (const auto& [r, v] : column) {
      impl->row.push_back(r);
      values.push_back(v);
    }
    impl->col_start[j + 1] = static_cast<int>(impl->row.size());
  }
  timings_.factorization = seconds_since(phase);
  phase = Clock::now();
  std::vector<Scalar> zs(values.size(), Scalar(0));
  // Per column j: Z_RR (R = the rows below the diagonal) gathered densely, each column r_a of Z
  // merged with R (R's rows from r_a on are a subset of that column's pattern), then one matvec.
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  Matrix z_rr;
  Vector l_r;
  const std::vector<int>& rows = impl->row;
  for (int j = n - 1; j >= 0; --j) {
    const int begin = impl->col_start[j], end = impl->col_start[j + 1];
    const int m = end - begin - 1;
    const Scalar ljj = values[begin];
    if (m == 0) {
      zs[begin] = Scalar(1) / (ljj * ljj);
      continue;
    }
    z_rr.resize(m, m);
    l_r = Eigen::Map<const Vector>(&values[begin + 1], m);
    for (int a = 0; a < m; ++a) {
      const int ra = rows[begin + 1 + a];
      int p = impl->col_start[ra];
      const int p_end = impl->col_start[ra + 1];
      for (int b = a; b < m; ++b) {
        const int rb = rows[begin + 1 + b];
        while (p < p_end && rows[p] < rb) ++p;
        if (p == p_end || rows[p] != rb) {  // cannot happen for a Cholesky pattern (chordal)
          error_ = "internal error: the Cholesky factor's pattern is not chordal";
          return false;
        }
        z_rr(a, b) = z_rr(b, a) = zs[p];
      }
    }
    const Vector z_rj = -(z_rr * l_r) / ljj;
    Eigen::Map<Vector>(&zs[begin + 1], m) = z_rj;
    zs[begin] = (Scalar(1) / ljj - l_r.dot(z_rj)) / ljj;
  }
  impl->z.assign(zs.begin(), zs.end());
  timings_.inversion = seconds_since(phase);
  return true;
}

bool SparseMarginals::Compute(ChainSolver& solver) {
  impl_.reset();
  error_.clear();
  failed_block_ = nullptr;
  extended_precision_ = false;
  timings_ = Timings{};
  min_pivot_ratio_ = 0.0;
  ChainSolver::Impl& s = solver.impl();
  if (s.n == 0) {
    error_ = "no variable parameter blocks";
    return false;
  }
  const auto phase = std::chrono::steady_clock::now();
  if (!s.FactorizeAtCurrentValues(&error_)) return false;
  auto impl = std::make_unique<Impl>();
  std::vector<double*> variable;
  for (const ChainSolver::Impl::Block& b : s.blocks) {
    impl->blocks[b.ptr] = {b.offset, b.size};
    variable.push_back(b.ptr);
  }
  for (const auto& [ptr, size] : s.fixed) impl->fixed[ptr] = size;
  impl->perm = s.llt.permutationP().indices();
  Eigen::VectorXd h_diag(s.n);
  for (int a = 0; a < s.n; ++a) h_diag[impl->perm[a]] = s.values[s.diagonal[a]];
  bool ok = SelectedInverse(s.llt.matrixL().nestedExpression(), h_diag, variable, *impl, phase, accepted_pivot_ratio_);
  if (!ok && ill_conditioned_) {
    // The extended pass needs J itself (the solver keeps only J^T J): Ceres evaluates it at the
    // solution, its columns in the solver's block order.
    ceres::Problem::EvaluateOptions eval;
    eval.parameter_blocks = variable;
    eval.apply_loss_function = true;
    ceres::CRSMatrix crs;
    if (s.problem->Evaluate(eval, nullptr, nullptr, nullptr, &crs)) {
      const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> J(
          crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(), crs.cols.data(),
          crs.values.data());
      ok = ComputeExtended(J, variable, *impl);
    }
  }
  if (ok) impl_ = std::move(impl);
  return ok;
}

Eigen::MatrixXd SparseMarginals::CrossCovariance(const double* a, const double* b) const {
  if (!impl_) throw std::logic_error("SparseMarginals: no successful Compute");
  const auto ia = impl_->blocks.find(a), ib = impl_->blocks.find(b);
  const auto fa = impl_->fixed.find(a), fb = impl_->fixed.find(b);
  if ((ia == impl_->blocks.end() && fa == impl_->fixed.end()) || (ib == impl_->blocks.end() && fb == impl_->fixed.end())) {
    throw std::logic_error("SparseMarginals: the block is not a parameter block of the problem");
  }
  if (fa != impl_->fixed.end() || fb != impl_->fixed.end()) {  // held fixed: no uncertainty
    return Eigen::MatrixXd::Zero(fa != impl_->fixed.end() ? fa->second : ia->second.second,
                                 fb != impl_->fixed.end() ? fb->second : ib->second.second);
  }
  const auto [oa, sa] = ia->second;
  const auto [ob, sb] = ib->second;
  Eigen::MatrixXd out(sa, sb);
  for (int u = 0; u < sa; ++u) {
    for (int v = 0; v < sb; ++v) {
      const double* z = impl_->Find(impl_->perm[oa + u], impl_->perm[ob + v]);
      if (z == nullptr) throw std::logic_error("SparseMarginals: the two blocks are not linked in the factor");
      out(u, v) = *z;
    }
  }
  return out;
}

Eigen::MatrixXd SparseMarginals::Covariance(const double* block) const { return CrossCovariance(block, block); }

bool SparseMarginals::HasCrossCovariance(const double* a, const double* b) const {
  try {
    CrossCovariance(a, b);
  } catch (const std::logic_error&) {
    return false;
  }
  return true;
}

}  // namespace pushgraph::graph
