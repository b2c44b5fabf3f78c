#pragma once
// The symmetric shift-invert operator of the generalized eigenproblem K phi = lambda M phi
// (K, M symmetric or Hermitian, M positive semidefinite, lambda = w^2 in (rad/s)^2):
//
//     C = L^{-1} P M P^T L^{-H},      P (K - sigma M) P^T = L L^H   (CHOLMOD, P its ordering).
//
// C is Hermitian positive semidefinite; its eigenvalues are nu = 1 / (lambda - sigma), so the
// modes nearest above sigma have the largest nu, and its eigenvectors are y = L^H P phi.
// An eigensolver on C therefore works in the Euclidean inner product: one forward and one
// backward half solve and one product with M per vector. The mode is
// phi = P^T L^{-H} y / sqrt(nu) (the backward half solve), mass-normalised when ||y|| = 1
// (phi^H M phi = nu y^H y / nu).
//
// Precondition: K - sigma M positive definite (sigma below the lowest eigenvalue; sigma < 0
// for a singular K); factor_shifted reports otherwise through the factor's status().
#include <Eigen/Core>
#include <memory>

#include "linalg/cholmod_factor.hpp"
#include "linalg/sparse.hpp"

namespace shroudsim::modal {

using linalg::Complex;

/// A CHOLMOD symbolic analysis kept across solves of matrices with one sparsity pattern
/// (a speed sweep K + Omega^2 D: the same pattern at every speed). The first solve given a
/// FactorReuse analyzes and factorizes; later ones of the same size only refactorize
/// numerically (a matrix of another size or number of stored entries is analyzed afresh;
/// the caller guarantees that equal counts mean an equal pattern). Not thread-safe: one per
/// worker. Solves given a FactorReuse return no StiffnessFactor (the factor is overwritten
/// by the next solve).
struct FactorReuse {
  std::shared_ptr<linalg::CholmodFactor<double>> real;
  std::shared_ptr<linalg::CholmodFactor<Complex>> complex;
  Eigen::Index real_nonzeros = -1, complex_nonzeros = -1;  ///< stored entries of the analyzed patterns
  int analyses = 0;                                        ///< symbolic analyses done through this object
  int factorizations = 0;                                  ///< numeric factorizations done through this object
};

/// One symbolic analysis (fill-reducing ordering, supernodes) shared by the factorizations of
/// K_h - sigma M_h of every harmonic index: the reduced matrices of a cyclic sector all have
/// one pattern (cyclic/cyclic_sector.hpp), real or complex, and the analysis depends on the
/// pattern only, so the factors are the ones a fresh analysis gives. Made once before the
/// workers start; only read afterwards (several threads copy it at once).
struct SharedAnalysis {
  std::shared_ptr<const linalg::CholmodFactor<double>> symbolic;  ///< analysed, never factorized
  Eigen::Index rows = 0, nonzeros = 0;                            ///< of the analysed pattern
};

/// The analysis of the pattern of K - sigma M (K when sigma == 0), by `method`.
template <typename Scalar>
std::shared_ptr<const SharedAnalysis> analyse_pattern(const linalg::SparsePair<Scalar>& km, double sigma,
                                                      linalg::FactorMethod method);

/// Factorizes K - sigma M (K itself when sigma == 0), reusing reuse's symbolic analysis when
/// the pattern matches (reuse may be null), else `shared`'s when its pattern has the same
/// size and number of entries (may be null), else analysing afresh. Never null; check
/// status() before use.
template <typename Scalar>
std::shared_ptr<linalg::CholmodFactor<Scalar>> factor_shifted(const linalg::SparsePair<Scalar>& km, double sigma,
                                                              linalg::FactorMethod method, FactorReuse* reuse,
                                                              const SharedAnalysis* shared = nullptr);

/// C applied to vectors or blocks, for Scalar S = double or Complex. `factor` is the
/// successful factor of K - sigma M and `M` the mass matrix of the same problem; both must
/// outlive the operator. Not thread-safe (scratch vectors).
template <typename S>
class ShiftInvertOperator {
 public:
  using Scalar = double;  ///< Spectra's operator interface: the real representation
  using Block = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  ShiftInvertOperator(const linalg::CholmodFactor<S>& factor, const linalg::SparseMatrix<S>& M);

  /// Spectra's operator interface (SymEigsSolver) on the real representation: n for real S,
  /// [Re; Im] of length 2n for complex S (the real symmetric 2n embedding of the Hermitian C).
  Eigen::Index rows() const;
  Eigen::Index cols() const { return rows(); }
  /// y = C x on raw arrays of length rows().
  void perform_op(const double* x, double* y) const;

  /// Y = C X in the problem's own scalar type, a block of columns at once (CHOLMOD's
  /// supernodal half solves then run BLAS-3 kernels).
  Block apply(const Block& X) const;

  /// Vectors C has been applied to (each one product with M).
  long products() const { return products_; }

 private:
  const linalg::CholmodFactor<S>& factor_;
  const linalg::SparseMatrix<S>& M_;
  Eigen::Index n_;
  mutable Eigen::Matrix<S, Eigen::Dynamic, 1> a_, b_;
  mutable long products_ = 0;
};

extern template class ShiftInvertOperator<double>;
extern template class ShiftInvertOperator<Complex>;

}  // namespace shroudsim::modal
