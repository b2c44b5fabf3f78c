#pragma once
// Lowest modes of K phi = w^2 M phi (real symmetric, or complex Hermitian from the cyclic
// reduction, docs/physics.md section 1): the driver that checks the problem, picks a method,
// and checks every mode before returning it.
//
// The sparse methods work on the symmetric shift-invert operator
// C = L^{-1} P M P^T L^{-H},  P (K - sigma M) P^T = L L^H  (modal/shift_invert.hpp): its
// eigenvalues nu = 1 / (w^2 - sigma) are largest for the lowest modes, and an eigenvector y
// gives the mass-normalised mode phi = P^T L^{-H} y / sqrt(nu).
//  - Block (the default): block Krylov-Schur on C in the problem's own scalar type
//    (modal/block_krylov_schur.hpp), blocks of `block_size` vectors per application of C.
//    Complex Hermitian problems need no 2n embedding and no doubled eigenvalues.
//  - Spectra: Spectra's SymEigsSolver (implicitly restarted Lanczos) on C. Complex Hermitian
//    problems are solved through the real symmetric 2n embedding
//      H = A + i B  ->  [A  -B]        z = a + i b  ->  [a; b],
//                       [B   A],
//    applied with complex CHOLMOD half solves (cheaper than factoring the 2n real matrix).
//    Every physical mode z appears twice there ([a; b] and the embedding of i z, [-b; a]):
//    Spectra is asked for 2 * modes + 4 eigenvalues, the Ritz vectors are mapped back to
//    complex vectors, grouped by eigenvalue, and each group's complex span is reduced to its
//    physical modes (M-orthonormalised, Rayleigh-Ritz when a group holds more than one
//    physical mode). Each mode is returned once. Kept selectable; the tests compare the two.
//  - Dense (Eigen's generalized solver) for n <= 300, or when the method's basis would not
//    fit in n.
//
// Every returned mode is checked: ||K phi - w^2 M phi|| <= residual_tolerance * ||K phi||.
// Failure (factorization, no convergence, residual too large, too few modes) is reported
// in ModalReport (status + message), never by silently returning modes.
//
// Units: K in N/m, M in kg, omega in rad/s, shift in (rad/s)^2.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "linalg/cholmod_factor.hpp"
#include "linalg/sparse.hpp"
#include "modal/shift_invert.hpp"
#include "modal/stiffness_factor.hpp"

namespace shroudsim::modal {

using linalg::Complex;

enum class EigenMethod {
  Block,   ///< block Krylov-Schur on the shift-invert operator (default)
  Spectra  ///< Spectra's SymEigsSolver (implicitly restarted Lanczos; 2n embedding for complex)
};
std::string to_string(EigenMethod method);

struct ModalOptions {
  int modes = 50;  ///< lowest modes wanted per problem (>= 1)
  EigenMethod method = EigenMethod::Block;
  int block_size = 0;                ///< Block: vectors per block; 0: 4
  double shift = 0.0;                ///< sigma [(rad/s)^2]; 0 factors K itself (kept for static solves).
                                     ///< Use sigma < 0 for an unclamped (singular) K.
  int ncv = 0;                       ///< basis size; 0: Spectra max(2 nev + 1, nev + 20),
                                     ///< Block max(3 modes, modes + 3 block_size)
  int max_restarts = 1000;           ///< Spectra maxit; Block: thick restarts allowed
  double tolerance = 1e-10;          ///< Spectra's relative tolerance on the Ritz values
  double residual_tolerance = 1e-6;  ///< accepted ||K phi - w^2 M phi|| / ||K phi||
  linalg::FactorMethod factor_method = linalg::FactorMethod::Supernodal;
  /// The symbolic analysis of K - shift M's pattern, shared by the solves of every harmonic
  /// index (modal/shift_invert.hpp); null, or a pattern of another size: each solve analyses.
  /// Not part of the result: the factors are the same either way.
  std::shared_ptr<const SharedAnalysis> analysis;
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

struct ModalResult {
  ModalBasis basis;  ///< the converged modes (empty unless report.ok())
  ModalReport report;
  StiffnessFactor stiffness;  ///< the factor of K when shift == 0 and it succeeded
};

/// Lowest options.modes modes of a real symmetric pair (basis.phi is real-valued).
ModalResult solve_modes(const linalg::SparsePair<double>& km, int harmonic_index, const ModalOptions& options);
/// Lowest options.modes modes of a complex Hermitian pair (Spectra: through the real 2n embedding).
ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int harmonic_index, const ModalOptions& options);

/// The same, reusing `reuse`'s symbolic analysis (FactorReuse, modal/shift_invert.hpp).
ModalResult solve_modes(const linalg::SparsePair<double>& km, int harmonic_index, const ModalOptions& options,
                        FactorReuse& reuse);
ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int harmonic_index, const ModalOptions& options,
                        FactorReuse& reuse);

}  // namespace shroudsim::modal
