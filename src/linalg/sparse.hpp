#pragma once
// Sparse matrix value types shared by the FE, cyclic and modal stages.
#include <Eigen/SparseCore>
#include <complex>

namespace shroudsim::linalg {

using Complex = std::complex<double>;
template <typename Scalar>
using SparseMatrix = Eigen::SparseMatrix<Scalar, Eigen::ColMajor, int>;
using SparseMatrixD = SparseMatrix<double>;
using SparseMatrixC = SparseMatrix<Complex>;

/// Stiffness K [N/m] and mass M [kg] on the same DOF numbering (and, from assembly, on the
/// same sparsity pattern). Both are stored in full (both triangles), symmetric for real
/// Scalar and Hermitian for complex Scalar.
template <typename Scalar>
struct SparsePair {
  SparseMatrix<Scalar> K;
  SparseMatrix<Scalar> M;
  Eigen::Index size() const { return K.rows(); }
};

}  // namespace shroudsim::linalg
