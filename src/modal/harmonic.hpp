#pragma once
// Modes and static factors of one harmonic index of a cyclic sector: the real path for
// h = 0 and h = Nb/2 (real K_h, M_h), the complex 2n-embedding path otherwise.
//
// For the forced response of harmonic index h:
//   ModalResult r = modal::solve_harmonic(sector, h, options);      // r.basis: ModalBasis
//   linalg::SparseMatrixC T = sector.expansion(h);                  // reduced -> sector DOFs
//   Eigen::MatrixXcd phi_full = T * r.basis.phi;                    // every sector node
//   StiffnessFactor Kh = r.stiffness.valid() ? r.stiffness
//                                            : modal::factor_harmonic_stiffness(sector, h);
//   Eigen::MatrixXcd x = Kh.solve(f_reduced);                       // K_h^{-1} f (static flexibility)
// Modes of Nb - h are those of h conjugated (ModalBasis::conjugate); their factor is
// StiffnessFactor::conjugate().
#include <memory>
#include <mutex>

#include "cyclic/cyclic_sector.hpp"
#include "modal/eigensolver.hpp"
#include "modal/shift_invert.hpp"

namespace shroudsim::modal {

/// Lowest options.modes mass-normalised modes of K_h phi = w^2 M_h phi (reduced DOFs).
ModalResult solve_harmonic(const cyclic::CyclicSector& sector, int harmonic_index, const ModalOptions& options);

/// The symbolic analysis (fill-reducing ordering, supernodes) of the one pattern every K_h of
/// the sector has, real or complex: made once and shared by the factorizations of several
/// harmonic indices (at 238k DOFs a fresh analysis cost as much as the numeric factorization).
std::shared_ptr<const SharedAnalysis> analyse_harmonic_pattern(
    const cyclic::CyclicSector& sector, linalg::FactorMethod method = linalg::FactorMethod::Supernodal);

/// A kept CHOLMOD factorization of K_h, on `shared`'s analysis when given (the factor is the
/// one a fresh analysis gives: the analysis depends on the pattern only). Throws
/// NumericalError if K_h is not positive definite.
StiffnessFactor factor_harmonic_stiffness(const cyclic::CyclicSector& sector, int harmonic_index,
                                          linalg::FactorMethod method = linalg::FactorMethod::Supernodal,
                                          const SharedAnalysis* shared = nullptr);

/// factor_harmonic_stiffness for the harmonic indices a stage asks for, from any number of
/// threads at once: the first call makes the shared analysis (the others wait for it), so a
/// stage that needs no factor makes none.
class HarmonicStiffnessFactors {
 public:
  HarmonicStiffnessFactors(const cyclic::CyclicSector& sector, linalg::FactorMethod method)
      : sector_(sector), method_(method) {}
  StiffnessFactor operator()(int harmonic_index) const;

 private:
  const cyclic::CyclicSector& sector_;
  linalg::FactorMethod method_;
  mutable std::once_flag analysed_;
  mutable std::shared_ptr<const SharedAnalysis> analysis_;
};

}  // namespace shroudsim::modal
