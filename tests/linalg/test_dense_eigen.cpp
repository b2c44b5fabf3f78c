// linalg::dense_eigen (LAPACK zgeev / dgeev): eigenpairs of general real and complex
// matrices. The real path rebuilds each conjugate pair's vectors from dgeev's two real
// columns; checked by the residual A v = lambda v of every pair, against the complex path on
// the same matrix, and against the closed-form eigenvalues of a damped oscillator.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <vector>

#include "linalg/dense_eigen.hpp"

namespace shroudsim::linalg {
namespace {

using Complex = std::complex<double>;
// Backward-stable QR: residuals and eigenvalue differences of a few hundred ulps of |A| for
// these well-conditioned sizes.
constexpr double kTolerance = 1e-11;

double worst_residual(const Eigen::MatrixXcd& a, const DenseEigen& e) {
  double worst = 0.0;
  for (Eigen::Index j = 0; j < e.values.size(); ++j) {
    const Eigen::VectorXcd v = e.vectors.col(j);
    worst = std::max(worst, (a * v - e.values[j] * v).norm() / (a.norm() * v.norm()));
  }
  return worst;
}

/// The largest distance from a value of a to the nearest value of b, and back (the two sets
/// agree to this; a conjugate pair's order differs between the paths by round-off).
double distance(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b) {
  auto one_way = [](const Eigen::VectorXcd& x, const Eigen::VectorXcd& y) {
    double worst = 0.0;
    for (Eigen::Index i = 0; i < x.size(); ++i) worst = std::max(worst, (y.array() - x[i]).abs().minCoeff());
    return worst;
  };
  return a.size() == b.size() ? std::max(one_way(a, b), one_way(b, a)) : INFINITY;
}

std::vector<Complex> sorted(const Eigen::VectorXcd& v) {
  std::vector<Complex> s(v.data(), v.data() + v.size());
  std::sort(s.begin(), s.end(),
            [](Complex a, Complex b) { return a.real() != b.real() ? a.real() < b.real() : a.imag() < b.imag(); });
  return s;
}

TEST(DenseEigen, RealAndComplexPathsGiveTheSameEigenpairs) {
  std::srand(7);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(60, 60);
  const DenseEigen r = dense_eigen(a, true), c = dense_eigen(Eigen::MatrixXcd(a.cast<Complex>()), true);
  const Eigen::MatrixXcd ac = a.cast<Complex>();
  EXPECT_LT(worst_residual(ac, r), kTolerance);
  EXPECT_LT(worst_residual(ac, c), kTolerance);
  int pairs = 0;
  for (Eigen::Index j = 0; j < r.values.size(); ++j) pairs += r.values[j].imag() > 0;
  EXPECT_GT(pairs, 10) << "a random real matrix has complex pairs: the pair rebuild is exercised";
  EXPECT_LT(distance(r.values, c.values), kTolerance * a.norm());
  // Without vectors: the same values, no vectors.
  const DenseEigen values_only = dense_eigen(a, false);
  EXPECT_EQ(values_only.vectors.size(), 0);
  EXPECT_LT(distance(r.values, values_only.values), kTolerance * a.norm());
}

TEST(DenseEigen, DampedOscillatorHasItsClosedFormEigenvaluesAtAnyScale) {
  // x'' + 2 zeta w x' + w^2 x = 0: lambda = -zeta w +- i w sqrt(1 - zeta^2).
  for (const double w : {1e-3, 1.0, 1e3}) {
    const double zeta = 0.05;
    Eigen::MatrixXd a(2, 2);
    a << 0.0, 1.0, -w * w, -2.0 * zeta * w;
    const DenseEigen e = dense_eigen(a, true);
    const auto s = sorted(e.values);
    EXPECT_NEAR(s[0].real(), -zeta * w, kTolerance * w);
    EXPECT_NEAR(s[1].imag(), w * std::sqrt(1.0 - zeta * zeta), kTolerance * w);
    EXPECT_NEAR(s[0].imag(), -s[1].imag(), kTolerance * w);
    EXPECT_LT(worst_residual(a.cast<Complex>(), e), kTolerance);
  }
}

TEST(DenseEigen, ANonSquareMatrixIsRefused) {
  EXPECT_THROW(dense_eigen(Eigen::MatrixXd(2, 3), false), std::invalid_argument);
  EXPECT_THROW(dense_eigen(Eigen::MatrixXcd(3, 2), true), std::invalid_argument);
  EXPECT_EQ(dense_eigen(Eigen::MatrixXd(0, 0), true).values.size(), 0);
}

}  // namespace
}  // namespace shroudsim::linalg
