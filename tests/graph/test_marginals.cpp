// SparseMarginals (selected inversion) against ceres::Covariance on random nonlinear chains with
// a variable shared by every link, robust losses and a constant block; failures on singular
// problems; and the estimator's covariances by both methods.
#include <pushgraph/graph/estimator.h>
#include <pushgraph/graph/marginals.h>

#include "graph/push_generator.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/covariance.h>
#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/problem.h>

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <limits>
#include <random>

namespace pushgraph::graph {
namespace {

// r = A (b - a) + sin(b - a) * k: a nonlinear link between two 3-vectors (or a prior with a = 0).
struct Link {
  Eigen::Matrix3d A;
  Eigen::Vector3d k;
  template <class T>
  bool operator()(const T* a, const T* b, T* r) const {
    for (int i = 0; i < 3; ++i) {
      r[i] = T(k[i]) * sin(b[i] - a[i]);
      for (int j = 0; j < 3; ++j) r[i] += T(A(i, j)) * (b[j] - a[j]);
    }
    return true;
  }
};
struct Prior {
  Eigen::Vector3d mean, w;
  template <class T>
  bool operator()(const T* x, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = T(w[i]) * (x[i] - T(mean[i]));
    return true;
  }
};
// Couples a step to the shared variable g (like the estimated c in the QS graph).
struct Shared {
  double w;
  template <class T>
  bool operator()(const T* x, const T* g, T* r) const {
    r[0] = T(w) * (x[0] * g[0] - x[1]);
    return true;
  }
};

struct RandomChain {
  ceres::Problem problem;
  std::vector<std::array<double, 3>> x;
  double g[1] = {0.7};
  double fixed[3] = {0.1, 0.2, 0.3};

  RandomChain(int n, unsigned seed, bool shared, bool losses, bool constant_block, bool cycle = false) : x(n) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> N;
    std::uniform_real_distribution<double> U(0.1, 3.0), S(-1.0, 1.0);
    // Seeded (Eigen's Random() would draw from std::rand's global state).
    auto M3 = [&] { Eigen::Matrix3d m; for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = S(rng); return m; };
    auto V3 = [&] { return Eigen::Vector3d(S(rng), S(rng), S(rng)); };
    for (auto& v : x) v = {N(rng), N(rng), N(rng)};
    auto* first = new ceres::AutoDiffCostFunction<Prior, 3, 3>(new Prior{V3(), Eigen::Vector3d(U(rng), U(rng), U(rng))});
    problem.AddResidualBlock(first, nullptr, x[0].data());
    for (int i = 1; i < n; ++i) {
      Link l{M3() + 2.0 * Eigen::Matrix3d::Identity(), V3()};
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Link, 3, 3, 3>(new Link(l)),
                               losses && i % 3 == 0 ? new ceres::HuberLoss(0.5) : nullptr, x[i - 1].data(), x[i].data());
      if (i >= 2 && i % 4 == 0) {  // skip links: fill beyond the band
        Link s{M3(), V3()};
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Link, 3, 3, 3>(new Link(s)),
                                 losses ? new ceres::CauchyLoss(1.0) : nullptr, x[i - 2].data(), x[i].data());
      }
      if (i % 5 == 0) {
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Prior, 3, 3>(new Prior{V3(), Eigen::Vector3d(U(rng), U(rng), U(rng))}),
                                 nullptr, x[i].data());
      }
      if (shared) {
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Shared, 1, 3, 1>(new Shared{U(rng)}), nullptr,
                                 x[i].data(), g);
      }
    }
    if (shared) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Prior, 3, 3>(new Prior{Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()}),
                               nullptr, x[n / 2].data());  // keeps it well posed whatever the links
    }
    if (cycle) {  // a loop closure: eliminating it fills in far pairs
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Link, 3, 3, 3>(new Link{M3(), V3()}), nullptr,
                               x[0].data(), x[n - 1].data());
    }
    if (constant_block) {
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Link, 3, 3, 3>(new Link{Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()}),
                               nullptr, fixed, x[n - 1].data());
      problem.SetParameterBlockConstant(fixed);
    }
  }
};

double RelativeDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
}

TEST(SparseMarginals, MatchCeresCovarianceOnRandomChains) {
  int checked = 0;
  for (unsigned seed = 1; seed <= 24; ++seed) {
    const bool shared = seed % 2 == 0, losses = seed % 3 == 0, constant = seed % 4 == 1;
    RandomChain chain(5 + static_cast<int>(seed) * 5, seed, shared, losses, constant);
    SparseMarginals marginals;
    ASSERT_TRUE(marginals.Compute(chain.problem)) << marginals.error();
    ceres::Covariance::Options options;
    options.algorithm_type = ceres::DENSE_SVD;  // the plain definition: (J^T J)^-1
    ceres::Covariance reference(options);
    std::vector<std::pair<const double*, const double*>> pairs;
    for (std::size_t i = 0; i < chain.x.size(); ++i) {
      pairs.emplace_back(chain.x[i].data(), chain.x[i].data());
      if (i > 0) pairs.emplace_back(chain.x[i - 1].data(), chain.x[i].data());
    }
    if (shared) pairs.emplace_back(chain.g, chain.g);
    ASSERT_TRUE(reference.Compute(pairs, &chain.problem));
    for (const auto& [a, b] : pairs) {
      const int ra = chain.problem.ParameterBlockSize(a), rb = chain.problem.ParameterBlockSize(b);
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> expected(ra, rb);
      ASSERT_TRUE(reference.GetCovarianceBlock(a, b, expected.data()));
      const Eigen::MatrixXd got = marginals.CrossCovariance(a, b);
      EXPECT_LT(RelativeDifference(got, expected), 1e-9) << "seed " << seed;
      ++checked;
    }
    if (constant) {
      EXPECT_EQ(marginals.Covariance(chain.fixed), Eigen::MatrixXd::Zero(3, 3));  // no uncertainty
    }
  }
  EXPECT_GT(checked, 1000);
}

// Every pair the factor links (including pairs linked only by fill-in) against the dense inverse
// of J^T J built from the same Jacobian; pairs outside the pattern throw.
TEST(SparseMarginals, EveryAvailablePairEqualsTheDenseInverse) {
  int fill_only = 0, available = 0, unavailable = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    RandomChain chain(30, seed, seed % 2 == 0, true, false, true);
    SparseMarginals marginals;
    ASSERT_TRUE(marginals.Compute(chain.problem)) << marginals.error();
    std::vector<double*> blocks;
    for (auto& v : chain.x) blocks.push_back(v.data());
    if (seed % 2 == 0) blocks.push_back(chain.g);
    ceres::Problem::EvaluateOptions eval;
    eval.parameter_blocks = blocks;
    ceres::CRSMatrix crs;
    ASSERT_TRUE(chain.problem.Evaluate(eval, nullptr, nullptr, nullptr, &crs));
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
    for (int r = 0; r < crs.num_rows; ++r) {
      for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) J(r, crs.cols[k]) = crs.values[k];
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::MatrixXd inverse = H.inverse();
    std::vector<int> offset;
    int o = 0;
    for (double* b : blocks) { offset.push_back(o); o += chain.problem.ParameterBlockSize(b); }
    for (std::size_t a = 0; a < blocks.size(); ++a) {
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        if (!marginals.HasCrossCovariance(blocks[a], blocks[b])) {
          EXPECT_THROW(marginals.CrossCovariance(blocks[a], blocks[b]), std::logic_error);
          ++unavailable;
          continue;
        }
        const Eigen::MatrixXd got = marginals.CrossCovariance(blocks[a], blocks[b]);
        ++available;
        const int a_size = chain.problem.ParameterBlockSize(blocks[a]), b_size = chain.problem.ParameterBlockSize(blocks[b]);
        const Eigen::MatrixXd expected = inverse.block(offset[a], offset[b], a_size, b_size);
        EXPECT_LT(RelativeDifference(got, expected), 1e-8) << "seed " << seed << " blocks " << a << ", " << b;
        const std::size_t last = chain.x.size() - 1;
        const bool direct = a == b || (a < chain.x.size() && b < chain.x.size() && (a > b ? a - b : b - a) <= 2) ||
                            a >= chain.x.size() || b >= chain.x.size() || (a == 0 && b == last) || (b == 0 && a == last);
        if (!direct) ++fill_only;
      }
    }
  }
  EXPECT_GT(fill_only, 0);  // the pattern's fill was exercised, not only the factors' pairs
  EXPECT_GT(unavailable, 0);
  std::printf("[marginals] %d block pairs equal to the dense inverse (%d linked only by fill), %d outside the pattern\n",
              available, fill_only, unavailable);
}

TEST(SparseMarginals, FixedAndUnusedBlocksHaveZeroCovarianceLikeCeres) {
  RandomChain chain(12, 3, false, false, true);
  double unused[2] = {1.0, 2.0};
  chain.problem.AddParameterBlock(unused, 2);  // no residual uses it
  SparseMarginals marginals;
  ASSERT_TRUE(marginals.Compute(chain.problem)) << marginals.error();
  EXPECT_EQ(marginals.Covariance(unused), Eigen::MatrixXd::Zero(2, 2));
  EXPECT_EQ(marginals.Covariance(chain.fixed), Eigen::MatrixXd::Zero(3, 3));
  EXPECT_EQ(marginals.CrossCovariance(chain.fixed, chain.x[0].data()), Eigen::MatrixXd::Zero(3, 3));
  double stranger[3] = {0, 0, 0};
  EXPECT_THROW(marginals.Covariance(stranger), std::logic_error);
  // Every block fixed: nothing to compute, said so.
  ceres::Problem empty;
  double a[3] = {0, 0, 0};
  empty.AddParameterBlock(a, 3);
  empty.SetParameterBlockConstant(a);
  EXPECT_FALSE(marginals.Compute(empty));
  EXPECT_NE(marginals.error().find("no variable"), std::string::npos);
}

struct ScaledAuto {
  double w;
  template <class T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = T(w) * (b[0] - a[0]);
    return true;
  }
};
struct UnitAuto {
  template <class T>
  bool operator()(const T* a, T* r) const {
    r[0] = a[0];
    return true;
  }
};

// A residual that evaluates to NaN in its Jacobian.
struct NanJacobian {
  template <class T>
  bool operator()(const T* x, T* r) const {
    r[0] = sqrt(x[0] - x[0]);  // d sqrt(u) / du at u = 0: infinite, times 0: NaN
    return true;
  }
};

TEST(SparseMarginals, RefusesSingularProblemsAndEarlyQueries) {
  SparseMarginals m;
  double x[3] = {0, 0, 0};
  EXPECT_THROW(m.Covariance(x), std::logic_error);
  // Relative links only: the chain can slide as a whole (gauge freedom).
  ceres::Problem problem;
  std::vector<std::array<double, 3>> v(6, {0.0, 0.0, 0.0});
  for (int i = 1; i < 6; ++i) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Link, 3, 3, 3>(new Link{Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()}),
                             nullptr, v[i - 1].data(), v[i].data());
  }
  EXPECT_FALSE(m.Compute(problem));
  EXPECT_NE(m.error().find("unobservable"), std::string::npos) << m.error();
  EXPECT_THROW(m.Covariance(v[0].data()), std::logic_error);
  // Fixing the first block makes it well posed.
  problem.SetParameterBlockConstant(v[0].data());
  ASSERT_TRUE(m.Compute(problem)) << m.error();
  EXPECT_NEAR(m.Covariance(v[5].data())(0, 0), 5.0, 1e-9);  // five unit-variance links in series
  EXPECT_NEAR(m.Covariance(v[5].data())(0, 1), 0.0, 1e-12);
  // A NaN in the Jacobian is named, not factorized.
  double y[1] = {0.5};
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<NanJacobian, 1, 1>(new NanJacobian), nullptr, y);
  EXPECT_FALSE(m.Compute(problem));
  EXPECT_NE(m.error().find("non-finite"), std::string::npos) << m.error();
  problem.RemoveParameterBlock(y);
  // A nearly dependent direction (a link 3e7 times stiffer than the only prior: cond(J) 3e7,
  // pivot ratio about 1e-15) names its block.
  ceres::Problem stiff;
  double p0[1] = {0.0}, p1[1] = {0.0};
  stiff.AddResidualBlock(new ceres::AutoDiffCostFunction<UnitAuto, 1, 1>(new UnitAuto), nullptr, p0);
  stiff.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledAuto, 1, 1, 1>(new ScaledAuto{3e7}), nullptr, p0, p1);
  EXPECT_FALSE(m.Compute(stiff));
  EXPECT_TRUE(m.failed_block() == p0 || m.failed_block() == p1) << m.error();
  EXPECT_NE(m.error().find("singular"), std::string::npos) << m.error();
  // 1e5 times stiffer (pivot ratio about 1e-10): well posed, but J^T J in double could cost 4+
  // digits; in long double (where it has 64 bits) Var(x0) = 1 and Var(x1) = 1 + 1e-10 come out
  // right to about 5.4e-20 / 1e-10 = 5.4e-10, where double would give only about 1e-6.
  ceres::Problem conditioned;
  conditioned.AddResidualBlock(new ceres::AutoDiffCostFunction<UnitAuto, 1, 1>(new UnitAuto), nullptr, p0);
  conditioned.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledAuto, 1, 1, 1>(new ScaledAuto{1e5}), nullptr, p0, p1);
  if (std::numeric_limits<long double>::digits >= 64) {
    ASSERT_TRUE(m.Compute(conditioned)) << m.error();
    EXPECT_TRUE(m.extended_precision());
    EXPECT_NEAR(m.Covariance(p1)(0, 0), 1.0 + 1e-10, 1e-9);
    EXPECT_NEAR(m.Covariance(p0)(0, 0), 1.0, 1e-9);
    // 3e6 (ratio about 1e-13): past what even long double keeps 4 digits of, refused as such.
    ceres::Problem worse;
    worse.AddResidualBlock(new ceres::AutoDiffCostFunction<UnitAuto, 1, 1>(new UnitAuto), nullptr, p0);
    worse.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledAuto, 1, 1, 1>(new ScaledAuto{3e6}), nullptr, p0, p1);
    EXPECT_FALSE(m.Compute(worse));
    EXPECT_NE(m.error().find("ill-conditioned"), std::string::npos) << m.error();
    EXPECT_NE(m.error().find("extended precision too"), std::string::npos) << m.error();
  } else {
    EXPECT_FALSE(m.Compute(conditioned));
    EXPECT_NE(m.error().find("ill-conditioned"), std::string::npos) << m.error();
  }
  // 1e3 (ratio about 1e-6): accepted, and right to about 1e-16 / ratio = 1e-10.
  ceres::Problem fine;
  fine.AddResidualBlock(new ceres::AutoDiffCostFunction<UnitAuto, 1, 1>(new UnitAuto), nullptr, p0);
  fine.AddResidualBlock(new ceres::AutoDiffCostFunction<ScaledAuto, 1, 1, 1>(new ScaledAuto{1e3}), nullptr, p0, p1);
  ASSERT_TRUE(m.Compute(fine)) << m.error();
  EXPECT_FALSE(m.extended_precision());
  EXPECT_NEAR(m.Covariance(p1)(0, 0), 1.0 + 1e-6, 1e-9);  // Var(x0) + 1/w^2
  EXPECT_GT(m.min_pivot_ratio(), 1e-8);
  EXPECT_LT(m.min_pivot_ratio(), 1e-4);
  // A user that needs fewer digits (the self-diagnosis' leverages) accepts the 1e5 link, with
  // Var(x1) = 1 + 1e-10 right to about 1e-16 / 1e-10 = 1e-6; the 3e7 link stays singular.
  SparseMarginals relaxed;
  relaxed.set_accepted_pivot_ratio(1e-13);
  ASSERT_TRUE(relaxed.Compute(conditioned)) << relaxed.error();
  EXPECT_FALSE(relaxed.extended_precision());
  EXPECT_NEAR(relaxed.Covariance(p1)(0, 0), 1.0, 1e-5);
  EXPECT_LT(relaxed.min_pivot_ratio(), 1e-9);
  EXPECT_FALSE(relaxed.Compute(stiff));
  relaxed.set_accepted_pivot_ratio(0.0);  // clamped to 1e-14
  EXPECT_FALSE(relaxed.Compute(stiff));
}

// The push generator's 2 cm off-centre push.
push::Trajectory OffsetPush(unsigned seed, double duration) {
  testing::PushSpec spec;
  spec.contact_offset = 0.02;
  spec.duration = duration;
  spec.seed = seed;
  return testing::GeneratePush(spec);
}

// The estimator's covariances with its geometric factors (C, S, touching, intersection) at
// `sigma` against ceres::Covariance's on the same push: the largest relative difference of the
// object and finger pose covariances over the steps.
double StiffPushCovarianceDifference(double sigma) {
  const push::Trajectory traj = OffsetPush(4, 0.4);
  EstimatorConfig stiff;
  stiff.touching_sigma = stiff.contact_object_sigma = stiff.contact_finger_sigma = stiff.intersection_sigma = sigma;
  EstimatorConfig reference = stiff;
  reference.covariance_method = EstimatorConfig::CovarianceMethod::kCeres;
  const EstimationResult a = Estimate(traj, Model::kCp, Mode::kBatch, stiff);
  const EstimationResult b = Estimate(traj, Model::kCp, Mode::kBatch, reference);
  EXPECT_EQ(a.solver.covariance_status, "ok");
  EXPECT_EQ(b.solver.covariance_status, "ok");
  double worst = 0.0;
  for (std::size_t i = 0; i < a.states.size() && i < b.states.size(); ++i) {
    if (!a.states[i].object_pose_cov || !b.states[i].object_pose_cov) return INFINITY;
    worst = std::max({worst, RelativeDifference(*a.states[i].object_pose_cov, *b.states[i].object_pose_cov),
                      RelativeDifference(*a.states[i].finger_pose_cov, *b.states[i].finger_pose_cov)});
  }
  return worst;
}

// Stiff geometric factors make the estimator's J^T J ill-conditioned: the default method falls
// back to the QR of ceres::Covariance and reports the same covariances as asking for it.
// (Sigmas of 3e-11 m: J^T J is not even positive definite in double, past the long double pass.)
TEST(SparseMarginals, EstimatorFallsBackToTheQrWhenIllConditioned) {
  EXPECT_LT(StiffPushCovarianceDifference(3e-11), 1e-9);
}

// Less stiff (1e-9 m: smallest pivot ratio 5.2e-13; a 2061-step MIT recording at 250 Hz has
// 2.7e-11, where the fallback to the QR took 7.5 of 13.6 s): the double pass refuses, the long
// double pass answers, and its covariances equal the QR's to 1e-5 (measured 6.5e-7, about
// eps(long double) / ratio; the double pass forced to answer was off by 1.4e-3).
TEST(SparseMarginals, EstimatorIllConditionedInDoubleIsAnsweredInLongDouble) {
  if (std::numeric_limits<long double>::digits < 64) GTEST_SKIP() << "long double is double here";
  EXPECT_LT(StiffPushCovarianceDifference(1e-9), 1e-5);
}

TEST(SparseMarginals, EstimatorCovariancesEqualCeresCovariance) {
  const push::Trajectory traj = OffsetPush(3, 0.8);
  for (Mode mode : {Mode::kBatch, Mode::kIncremental}) {
    EstimatorConfig fast, reference;
    fast.estimate_c = reference.estimate_c = mode == Mode::kBatch;
    fast.estimate_mu = reference.estimate_mu = mode == Mode::kBatch;
    reference.covariance_method = EstimatorConfig::CovarianceMethod::kCeres;
    const EstimationResult a = Estimate(traj, Model::kQs, mode, fast);
    const EstimationResult b = Estimate(traj, Model::kQs, mode, reference);
    ASSERT_EQ(a.solver.covariance_status, "ok");
    ASSERT_EQ(b.solver.covariance_status, "ok");
    ASSERT_EQ(a.states.size(), b.states.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < a.states.size(); ++i) {
      worst = std::max(worst, RelativeDifference(*a.states[i].object_pose_cov, *b.states[i].object_pose_cov));
      worst = std::max(worst, RelativeDifference(*a.states[i].finger_pose_cov, *b.states[i].finger_pose_cov));
      if (b.states[i].contact_cov) worst = std::max(worst, RelativeDifference(*a.states[i].contact_cov, *b.states[i].contact_cov));
      if (b.states[i].force_cov) worst = std::max(worst, RelativeDifference(*a.states[i].force_cov, *b.states[i].force_cov));
    }
    EXPECT_LT(worst, 1e-7) << ModeName(mode);
    std::printf("[marginals] %s: worst relative difference to ceres::Covariance over %zu states %.2e\n",
                ModeName(mode).c_str(), a.states.size(), worst);
    if (mode == Mode::kBatch) {
      ASSERT_TRUE(a.c_sigma && b.c_sigma && a.mu_sigma && b.mu_sigma);
      EXPECT_NEAR(*a.c_sigma, *b.c_sigma, 1e-9 * *b.c_sigma);
      EXPECT_NEAR(*a.mu_sigma, *b.mu_sigma, 1e-9 * *b.mu_sigma);
    }
  }
}

}  // namespace
}  // namespace pushgraph::graph
