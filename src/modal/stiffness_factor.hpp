#pragma once
// A kept factorization of a stiffness matrix K (real symmetric, or complex Hermitian K_h of
// a harmonic index, docs/physics.md section 1) for static solves x = K^{-1} b with complex
// right-hand sides: the static flexibility of the receptance (docs/physics.md section 2).
// A real K solves the real and imaginary parts of b together (one real solve of 2 columns
// per column of b); `conjugated` solves with conj(K), the factor of harmonic index Nb - h,
// through the factor of h: conj(K)^{-1} b = conj(K^{-1} conj(b)).
//
// Made by factor_stiffness, or by the eigensolver when it factors K itself (shift 0,
// modal/eigensolver.hpp). Copies share the CHOLMOD factor (immutable once made).
// Units: K in N/m, b in N, x in m.
#include <Eigen/Core>
#include <memory>
#include <type_traits>

#include "linalg/cholmod_factor.hpp"
#include "linalg/sparse.hpp"

namespace shroudsim::modal {

using linalg::Complex;

class StiffnessFactor {
 public:
  StiffnessFactor() = default;
  explicit StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<double>> real);
  StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<Complex>> complex, bool conjugated);
  bool valid() const { return real_ || complex_; }
  Eigen::Index rows() const;
  /// x = K^{-1} b (columns).
  Eigen::MatrixXcd solve(const Eigen::MatrixXcd& b) const;
  /// The factor of conj(K) (for Nb - h), sharing the same CHOLMOD factor.
  StiffnessFactor conjugate() const;

 private:
  std::shared_ptr<const linalg::CholmodFactor<double>> real_;
  std::shared_ptr<const linalg::CholmodFactor<Complex>> complex_;
  bool conjugated_ = false;
};

/// The StiffnessFactor holding a (successful) factor of K itself, not conjugated.
template <typename Scalar>
StiffnessFactor make_stiffness_factor(std::shared_ptr<const linalg::CholmodFactor<Scalar>> f) {
  if constexpr (std::is_same_v<Scalar, double>) return StiffnessFactor(std::move(f));
  else return StiffnessFactor(std::move(f), false);
}

/// Factorizes K (throws NumericalError if it is not positive definite).
StiffnessFactor factor_stiffness(const linalg::SparseMatrixD& K,
                                 linalg::FactorMethod method = linalg::FactorMethod::Supernodal);
StiffnessFactor factor_stiffness(const linalg::SparseMatrixC& K,
                                 linalg::FactorMethod method = linalg::FactorMethod::Supernodal);

}  // namespace shroudsim::modal
