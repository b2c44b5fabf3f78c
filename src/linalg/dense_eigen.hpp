#pragma once
// Eigenvalues (and right eigenvectors) of a general dense complex or real matrix through
// LAPACK's zgeev / dgeev (OpenBLAS's LAPACK on a machine set up by tools/setup.sh: blocked Hessenberg
// reduction and multishift QR). For the Hill eigenproblems of forced/stability.cpp, where
// Eigen's unblocked ComplexSchur took two thirds of a lumped forced response's time
// (a 190-wide problem: 58 ms per point).
#include <Eigen/Core>

namespace shroudsim::linalg {

struct DenseEigen {
  Eigen::VectorXcd values;
  Eigen::MatrixXcd vectors;  ///< right eigenvectors as columns (unit 2-norm); empty unless asked
};

/// The eigen-decomposition of the square matrix a. Throws NumericalError when LAPACK reports
/// that the QR algorithm did not converge, std::invalid_argument for a non-square matrix.
DenseEigen dense_eigen(const Eigen::MatrixXcd& a, bool with_vectors);
/// The same for a real matrix (LAPACK dgeev, about a quarter of the complex cost): complex
/// conjugate pairs of eigenvalues, each with its own (conjugate) eigenvector.
DenseEigen dense_eigen(const Eigen::MatrixXd& a, bool with_vectors);

}  // namespace shroudsim::linalg
