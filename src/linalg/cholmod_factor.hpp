#pragma once
// Sparse Cholesky factorization A = L L^H of a symmetric (real) or Hermitian (complex)
// positive definite matrix by CHOLMOD (SuiteSparse), owning the CHOLMOD workspace and factor.
//
// Usage:
//   linalg::CholmodFactor<linalg::Complex> f;
//   f.analyze(A);                 // fill-reducing ordering, once per sparsity pattern
//   if (f.factorize(A) != linalg::FactorStatus::Success) ...   // every new value set
//   Eigen::VectorXcd x = f.solve(b);
// A is given in full (both triangles); only its lower triangle is read.
// Not copyable (owns CHOLMOD memory); movable.
#include <Eigen/Core>
#include <memory>
#include <string>

#include "linalg/sparse.hpp"

namespace shroudsim::linalg {

enum class FactorStatus {
  Success,
  NotPositiveDefinite,  ///< the matrix (or the shifted matrix) is not positive definite
  Failed                ///< out of memory or another CHOLMOD failure
};
std::string to_string(FactorStatus status);

enum class FactorMethod {
  Supernodal,  ///< BLAS-3 supernodes: fastest for 3D FE matrices of more than a few 1e4 rows
  Simplicial   ///< column by column, no BLAS: faster for small matrices
};

template <typename Scalar>
class CholmodFactor {
 public:
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

  explicit CholmodFactor(FactorMethod method = FactorMethod::Supernodal);
  ~CholmodFactor();
  CholmodFactor(CholmodFactor&&) noexcept;
  CholmodFactor& operator=(CholmodFactor&&) noexcept;
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;

  /// Symbolic analysis of A's pattern (square, both triangles stored).
  void analyze(const SparseMatrix<Scalar>& A);
  /// Numeric factorization; A must have the pattern given to analyze().
  FactorStatus factorize(const SparseMatrix<Scalar>& A);
  /// analyze() then factorize().
  FactorStatus compute(const SparseMatrix<Scalar>& A);
  /// The symbolic analysis copied from `analysed` instead of computed: a factor of either
  /// scalar type on which analyze() has been called and factorize() has not. The analysis
  /// depends on the pattern only, so every matrix of one pattern (every harmonic index of a
  /// cyclic sector, real or complex) can share one; `analysed` is only read (several threads
  /// may copy it at once). Its matrix must have A's pattern; then factorize(A).
  template <typename Other>
  void analyze_like(const CholmodFactor<Other>& analysed);
  /// True once analyze() has run and factorize() has not: a source for analyze_like().
  bool symbolic_only() const;

  /// x = A^{-1} b for one or several right-hand sides (columns). Requires status() == Success.
  Matrix solve(const Matrix& b) const;
  /// x = A^{-1} b on raw arrays of length rows().
  void solve(const Scalar* b, Scalar* x) const;
  /// Half solves with the factor P A P^T = L L^H (P the fill-reducing permutation):
  /// forward x = L^{-1} P b, backward x = P^T L^{-H} b; backward(forward(b)) = A^{-1} b.
  /// Used for the symmetric form L^{-1} P M P^T L^{-H} of a generalized eigenproblem.
  void solve_forward(const Scalar* b, Scalar* x) const;
  void solve_backward(const Scalar* b, Scalar* x) const;
  /// The half solves for several right-hand sides (columns) at once: CHOLMOD's supernodal
  /// solve then runs BLAS-3 kernels, a block of 16 columns costing a few single solves.
  Matrix solve_forward(const Matrix& b) const;
  Matrix solve_backward(const Matrix& b) const;

  FactorStatus status() const { return status_; }
  Eigen::Index rows() const { return rows_; }
  /// Number of stored entries of L (memory: this times sizeof(Scalar), plus indices).
  double factor_nonzeros() const;

 private:
  template <typename>
  friend class CholmodFactor;
  struct Impl;
  /// x = the half solve (CHOLMOD systems `first` then `second`) of ncol columns of b, after
  /// checking the factor; `name` is the calling function's, for the messages.
  void half_solve(int first, int second, const Scalar* b, Scalar* x, Eigen::Index ncol, const char* name) const;
  std::unique_ptr<Impl> impl_;
  FactorStatus status_ = FactorStatus::Failed;
  Eigen::Index rows_ = 0;
};

extern template class CholmodFactor<double>;
extern template class CholmodFactor<Complex>;

}  // namespace shroudsim::linalg
