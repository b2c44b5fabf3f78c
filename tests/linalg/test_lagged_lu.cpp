// linalg::LaggedLuPreconditioner: z = M^{-1} v with M the single
// precision LU of A. Checked against the double-precision solve of the same systems (a
// nonsymmetric matrix that needs row interchanges, and a permutation matrix whose solve is
// exact), by GMRES reaching double precision with it, and by an exactly singular matrix being
// reported rather than solved.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "linalg/gmres.hpp"
#include "linalg/lagged_lu.hpp"

namespace shroudsim::linalg {
namespace {

// A single-precision LU solve has a relative error of about kappa * sqrt(n) * eps_float
// (~4e-6 for kappa < 10 at order 300; the worst-case bound kappa * n * eps_float is 2e-4).
constexpr double kSingleSolveTolerance = 1e-4;
constexpr double kMaxCondition = 10.0;  // the tolerance's premise

Eigen::MatrixXd test_matrix(int n) {
  // A cyclic shift (zero diagonal: row interchanges needed) plus a deterministic dense part of
  // norm below 1: well conditioned.
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = 0.15 * std::sin(1.0 + 0.37 * i + 1.91 * j * j) / std::sqrt(n);
  for (int i = 0; i < n; ++i) a(i, (i + 1) % n) += 1.0;
  return a;
}

TEST(LaggedLu, SolvesToSinglePrecisionAndLetsGmresReachDouble) {
  const int n = 300;
  const Eigen::MatrixXd a = test_matrix(n);
  Eigen::VectorXd x_true(n);
  for (int i = 0; i < n; ++i) x_true[i] = std::cos(0.1 * i);
  const Eigen::VectorXd b = a * x_true;

  LaggedLuPreconditioner m;
  EXPECT_FALSE(m.usable(n));
  m.factorize(a);
  ASSERT_TRUE(m.usable(n));
  EXPECT_FALSE(m.usable(n + 1));
  ASSERT_TRUE(m.nonsingular());
  Eigen::VectorXd z;
  m.apply(b, z);
  const Eigen::MatrixXd inverse = a.partialPivLu().inverse();
  ASSERT_LT(inverse.operatorNorm() * a.operatorNorm(), kMaxCondition);
  EXPECT_LT((z - x_true).norm() / x_true.norm(), kSingleSolveTolerance);
  EXPECT_GT((z - x_true).norm() / x_true.norm(), 0.0);  // single precision: not exact

  // Preconditioned GMRES reaches the double-precision tolerance in a few iterations.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  auto op = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y) { y = a * v; };
  auto pre = [&](const Eigen::VectorXd& v, Eigen::VectorXd& y) { m.apply(v, y); };
  const GmresResult g = gmres(op, pre, b, x, GmresOptions{50, 1e-12});
  ASSERT_TRUE(g.converged);
  EXPECT_LE(g.iterations, 6);
  EXPECT_LT((x - x_true).norm() / x_true.norm(), 1e-9);
}

TEST(LaggedLu, APermutationIsSolvedExactly) {
  // Row interchanges only: every entry 0 or 1, so the single-precision factors are exact.
  const int n = 7;
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) p(i, (3 * i + 2) % n) = 1.0;
  LaggedLuPreconditioner m;
  m.factorize(p);
  ASSERT_TRUE(m.nonsingular());
  Eigen::VectorXd v(n), z;
  for (int i = 0; i < n; ++i) v[i] = i + 0.25;
  m.apply(v, z);
  EXPECT_EQ((p * z - v).cwiseAbs().maxCoeff(), 0.0);
}

TEST(LaggedLu, AnExactlySingularMatrixIsReported) {
  Eigen::MatrixXd a = test_matrix(20);
  a.row(7).setZero();  // a zero row: the last pivot is exactly zero
  LaggedLuPreconditioner m;
  m.factorize(a);
  EXPECT_FALSE(m.nonsingular());
}

TEST(LaggedLu, RenewalIsDueOnlyAfterIterationsCostingAFactorization) {
  // Order 120: a factorization is worth 120 / 12 = 10 iterations (lagged_lu.hpp).
  LaggedLuPreconditioner m;
  m.factorize(test_matrix(120));
  m.add_iterations(9);
  m.decide_renewal(9, 5);
  EXPECT_TRUE(m.usable(120));  // 9 iterations cost less than the factorization
  m.add_iterations(2);
  m.decide_renewal(2, 5);
  EXPECT_TRUE(m.usable(120));  // the last solve took few iterations
  m.add_iterations(6);
  m.decide_renewal(6, 5);
  EXPECT_FALSE(m.usable(120));  // 17 > 10 and the last solve took more than 5
}

}  // namespace
}  // namespace shroudsim::linalg
