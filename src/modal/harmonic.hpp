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
#include "cyclic/cyclic_sector.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::modal {

/// Lowest options.modes mass-normalised modes of K_h phi = w^2 M_h phi (reduced DOFs).
ModalResult solve_harmonic(const cyclic::CyclicSector& sector, int harmonic_index, const ModalOptions& options);

/// A kept CHOLMOD factorization of K_h. Throws NumericalError if K_h is not positive definite.
StiffnessFactor factor_harmonic_stiffness(const cyclic::CyclicSector& sector, int harmonic_index,
                                          linalg::FactorMethod method = linalg::FactorMethod::Supernodal);

}  // namespace shroudsim::modal
