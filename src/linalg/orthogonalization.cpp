#include "linalg/orthogonalization.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>

namespace shroudsim::linalg {

template <typename Scalar>
DenseMatrix<Scalar> deterministic_block(Eigen::Index n, Eigen::Index b) {
  std::mt19937_64 gen(20261201);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  DenseMatrix<Scalar> X(n, b);
  for (Eigen::Index j = 0; j < b; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      if constexpr (!std::is_same_v<Scalar, double>) X(i, j) = Scalar(u(gen), u(gen));
      else X(i, j) = u(gen);
    }
  return X;
}

template <typename Scalar>
DenseMatrix<Scalar> orthogonalize(const BlockRef<Scalar>& V, DenseMatrix<Scalar>& X) {
  DenseMatrix<Scalar> H = DenseMatrix<Scalar>::Zero(V.cols(), X.cols());
  if (V.cols() == 0) return H;
  DenseMatrix<Scalar> h(V.cols(), X.cols());
  for (int pass = 0; pass < 2; ++pass) {
    gemm<Scalar>(Op::Adjoint, Scalar(1), V, X, Scalar(0), h);
    gemm<Scalar>(Op::None, Scalar(-1), V, h, Scalar(1), X);
    H += h;
  }
  return H;
}

template <typename Scalar>
void block_qr(const BlockRef<Scalar>& V, DenseMatrix<Scalar>& X, DenseMatrix<Scalar>& R) {
  const Eigen::Index n = X.rows(), b = X.cols();
  const double scale = std::max(X.colwise().norm().maxCoeff(), std::numeric_limits<double>::min());
  Eigen::HouseholderQR<DenseMatrix<Scalar>> qr(X);
  R = qr.matrixQR().topRows(b).template triangularView<Eigen::Upper>();
  X = qr.householderQ() * DenseMatrix<Scalar>::Identity(n, b);
  bool refill = false;
  for (Eigen::Index j = 0; j < b; ++j)
    if (std::abs(R(j, j)) < 1e-12 * scale) {
      R.row(j).setZero();
      refill = true;
    }
  if (!refill) return;
  DenseMatrix<Scalar> fresh = deterministic_block<Scalar>(n, b);
  for (Eigen::Index j = 0; j < b; ++j)
    if (R.row(j).isZero(0.0)) X.col(j) = fresh.col(j);
  DenseMatrix<Scalar> all(n, V.cols() + b);
  all << V, X;
  for (Eigen::Index j = 0; j < b; ++j) {
    if (!R.row(j).isZero(0.0)) continue;
    DenseMatrix<Scalar> x = X.col(j);
    orthogonalize<Scalar>(all, x);
    X.col(j) = x.normalized();
    all.col(V.cols() + j) = X.col(j);
  }
}

template DenseMatrix<double> deterministic_block<double>(Eigen::Index, Eigen::Index);
template DenseMatrix<Complex> deterministic_block<Complex>(Eigen::Index, Eigen::Index);
template DenseMatrix<double> orthogonalize<double>(const BlockRef<double>&, DenseMatrix<double>&);
template DenseMatrix<Complex> orthogonalize<Complex>(const BlockRef<Complex>&, DenseMatrix<Complex>&);
template void block_qr<double>(const BlockRef<double>&, DenseMatrix<double>&, DenseMatrix<double>&);
template void block_qr<Complex>(const BlockRef<Complex>&, DenseMatrix<Complex>&, DenseMatrix<Complex>&);

}  // namespace shroudsim::linalg
