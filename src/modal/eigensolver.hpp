#pragma once
// Lowest modes of K phi = w^2 M phi (real symmetric, or complex Hermitian from the cyclic
// reduction) by Spectra's Lanczos (SymEigsSolver, implicit restarts) on the symmetric
// shift-invert operator  L^{-1} P M P^T L^{-H},  P (K - sigma M) P^T = L L^H  (CHOLMOD,
// supernodal). Its eigenvalues are nu = 1 / (w^2 - sigma), its eigenvectors y = L^H P phi;
// Lanczos then needs the Euclidean inner product only: one solve and one product with M
// per step (Spectra 1.0.1's SymGEigsShiftSolver, with M-inner products, applies M about
// eight times per step).
//
// Complex Hermitian problems are solved through the real symmetric 2n embedding
//   H = A + i B  ->  [A  -B]        z = a + i b  ->  [a; b],
//                    [B   A],
// applied with complex CHOLMOD half solves (cheaper than factoring the 2n real matrix).
// Every physical mode z appears twice there ([a; b] and the embedding of i z, [-b; a]);
// Spectra is asked for 2 * modes + 4 eigenvalues, the Ritz vectors are mapped back to
// complex vectors, grouped by eigenvalue, and each group's complex span is reduced to its
// physical modes (M-orthonormalised, Rayleigh-Ritz when a group holds more than one
// physical mode). Each mode is returned once.
//
// The default method for large problems is a block Krylov-Schur iteration (thick-restarted
// block Lanczos with full reorthogonalization) on the same operator, in the problem's own
// scalar type: complex Hermitian problems need no 2n embedding and no doubled eigenvalues,
// and the operator is applied to blocks of `block_size` vectors (CHOLMOD's supernodal
// solve runs BLAS-3 kernels on a block; single-vector solves are memory bound). At 2e5
// DOFs, complex, it needs a third of the solve time of Spectra's Lanczos on the embedding
// (92 vectors against 130, each cheaper). Spectra stays selectable (ModalOptions::method)
// and the tests compare the two.
//
// Every returned mode is checked: ||K phi - w^2 M phi|| <= residual_tolerance * ||K phi||.
// Failure (factorization, Spectra not converging, residual too large, too few modes) is
// reported in ModalReport (status + message), never by silently returning modes.
//
// Units: K in N/m, M in kg, omega in rad/s, shift in (rad/s)^2.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "linalg/cholmod_factor.hpp"
#include "linalg/sparse.hpp"

namespace shroudsim::modal {

using linalg::Complex;

enum class EigenMethod {
  Block,   ///< block Krylov-Schur on the shift-invert operator (default)
  Spectra  ///< Spectra's SymEigsSolver (implicitly restarted Lanczos; 2n embedding for complex)
};
std::string to_string(EigenMethod method);

struct ModalOptions {
  int modes = 50;                  ///< lowest modes wanted per problem (>= 1)
  EigenMethod method = EigenMethod::Block;
  int block_size = 0;              ///< Block: vectors per block; 0: 4
  double shift = 0.0;              ///< sigma [(rad/s)^2]; 0 factors K itself (kept for static solves).
                                   ///< Use sigma < 0 for an unclamped (singular) K.
  int ncv = 0;                     ///< basis size; 0: Spectra max(2 nev + 1, nev + 20),
                                   ///< Block max(3 modes, modes + 3 block_size)
  int max_restarts = 1000;         ///< Spectra maxit; Block: thick restarts allowed
  double tolerance = 1e-10;        ///< Spectra's relative tolerance on the Ritz values
  double residual_tolerance = 1e-6;  ///< accepted ||K phi - w^2 M phi|| / ||K phi||
  linalg::FactorMethod factor_method = linalg::FactorMethod::Supernodal;
  /// Returns false and appends messages if a value is out of range.
  bool validate(std::vector<std::string>* errors) const;
};

/// Mass-normalised modes of one harmonic index, on the reduced DOFs of that index.
struct ModalBasis {
  int harmonic_index = 0;
  Eigen::VectorXd omega;  ///< rad/s, ascending, >= 0
  Eigen::MatrixXcd phi;   ///< n_reduced x n_modes, phi^H M_h phi = I
  int size() const { return static_cast<int>(omega.size()); }
  Eigen::VectorXd frequency_hz() const;
  /// The basis of harmonic index new_h = Nb - h: conj(phi), same omega.
  ModalBasis conjugate(int new_harmonic_index) const;
};

enum class ModalStatus {
  Converged,
  FactorizationFailed,  ///< K - sigma M not positive definite (sigma above the lowest mode, or K singular)
  NotConverged,         ///< Spectra stopped with unconverged Ritz pairs
  ResidualTooLarge,     ///< a returned pair fails the explicit residual check
  TooFewModes           ///< fewer distinct modes than asked for were found
};
std::string to_string(ModalStatus status);

struct ModalReport {
  ModalStatus status = ModalStatus::Converged;
  std::string message;            ///< empty when converged
  std::string method;             ///< "block-real", "block-complex", "spectra-real", "spectra-complex-2n" or "dense"
  int spectra_info = 0;           ///< Spectra::CompInfo as int (0 = Successful)
  int requested_eigenvalues = 0;  ///< nev asked of Spectra
  int converged_eigenvalues = 0;  ///< nconv
  int iterations = 0;             ///< restarts (Spectra), block steps (Block)
  int operations = 0;             ///< operator applications (solves)
  int mass_products = 0;          ///< products with M (one per operator application)
  double max_residual = 0.0;      ///< max relative residual of the returned modes
  double factor_nonzeros = 0.0;
  double factor_seconds = 0.0, solve_seconds = 0.0;
  bool ok() const { return status == ModalStatus::Converged; }
};

/// A kept factorization of K (real or complex Hermitian) for static solves K x = b with
/// complex right-hand sides; `conjugated` solves with conj(K) (harmonic index Nb - h).
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

/// Factorizes K (throws NumericalError if it is not positive definite).
StiffnessFactor factor_stiffness(const linalg::SparseMatrixD& K,
                                 linalg::FactorMethod method = linalg::FactorMethod::Supernodal);
StiffnessFactor factor_stiffness(const linalg::SparseMatrixC& K,
                                 linalg::FactorMethod method = linalg::FactorMethod::Supernodal);

struct ModalResult {
  ModalBasis basis;           ///< the converged modes (empty unless report.ok())
  ModalReport report;
  StiffnessFactor stiffness;  ///< the factor of K when shift == 0 and it succeeded
};

/// Lowest options.modes modes of a real symmetric pair (basis.phi is real-valued).
ModalResult solve_modes(const linalg::SparsePair<double>& km, int harmonic_index, const ModalOptions& options);
/// Lowest options.modes modes of a complex Hermitian pair (real 2n embedding).
ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int harmonic_index, const ModalOptions& options);

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
  int analyses = 0;           ///< symbolic analyses done through this object
  int factorizations = 0;     ///< numeric factorizations done through this object
};
ModalResult solve_modes(const linalg::SparsePair<double>& km, int harmonic_index, const ModalOptions& options,
                        FactorReuse& reuse);
ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int harmonic_index, const ModalOptions& options,
                        FactorReuse& reuse);

}  // namespace shroudsim::modal
