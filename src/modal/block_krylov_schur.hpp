#pragma once
// Block Krylov-Schur (thick-restarted block Lanczos with full reorthogonalization) for the
// `nev` largest eigenvalues of a Hermitian positive semidefinite operator C of size n, given
// by its action on blocks of b vectors (the shift-invert operator of modal/shift_invert.hpp),
// real (S = double) or complex (S = Complex).
//
// State: an orthonormal basis V (n x m), the projection T = V^H C V and a pending block Q
// (n x b, orthonormal, Q ⟂ V) with C V = V T + Q S for some S. A step appends Q to V, applies
// C to it (one block), orthogonalizes the product against V twice (classical Gram-Schmidt,
// BLAS-3: linalg/orthogonalization.hpp), which gives T's new columns and, by a QR of what is
// left, the next pending block: C V = V T + Q B E^T with E picking V's last block. The Ritz
// pairs (theta, V y) of T then have residual norms ||C V y - theta V y|| = ||B E^T y||, known
// without touching an n-vector. When V is full (m + b > basis) it is contracted to its `keep`
// best Ritz vectors (thick restart): T becomes diagonal and the relation keeps its form, the
// pending block unchanged. Converged: the nev largest theta are > 0 and have
// ||B E^T y|| <= tolerance * theta.
//
// Deterministic: the start block is linalg::deterministic_block, so the same C gives the
// same Ritz vectors (and signs) on every run. Sizes as block_krylov_schur_sizes makes them
// (nev < n, basis <= n, keep <= basis - b).
#include <Eigen/Core>
#include <functional>

namespace shroudsim::modal {

/// Sizes and stopping rule of one solve.
struct BlockKrylovSchurOptions {
  Eigen::Index nev = 0;    ///< wanted eigenvalues (the largest)
  Eigen::Index block = 0;  ///< b, vectors per block
  Eigen::Index basis = 0;  ///< largest basis (columns of V) before a thick restart
  Eigen::Index keep = 0;   ///< Ritz vectors kept at a restart
  int max_restarts = 1000;
  double tolerance = 1e-10;  ///< relative residual of the Ritz pairs, see the header comment
};

/// The sizes for `modes` wanted eigenvalues of an operator of size n: nev = min(modes, n - 1);
/// block `block_size` (0: 4, the fastest measured in BENCHMARKS.md; a block of b also resolves
/// eigenvalues of multiplicity up to b), at most n / 4; basis `ncv` (0: max(3 nev, nev + 3 b)),
/// at least nev + 2 b and at most n; keep: the wanted Ritz vectors and one block of the next.
BlockKrylovSchurOptions block_krylov_schur_sizes(Eigen::Index n, int modes, int block_size, int ncv, int max_restarts,
                                                 double tolerance);

template <typename S>
struct BlockKrylovSchurResult {
  using Block = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  bool converged = false;
  Eigen::VectorXd theta;     ///< converged: the nev largest Ritz values, ascending (else empty)
  Block vectors;             ///< converged: their Ritz vectors V y (n x nev, orthonormal)
  int converged_values = 0;  ///< of the nev largest Ritz values at the end, those converged
  int steps = 0;             ///< block steps (applications of C to a block)
  int restarts = 0;          ///< thick restarts
};

/// The nev largest eigenpairs of C, `apply` returning C X for a block X (n x b).
template <typename S>
BlockKrylovSchurResult<S> block_krylov_schur(const std::function<Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>(
                                                 const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>&)>& apply,
                                             Eigen::Index n, const BlockKrylovSchurOptions& options);

}  // namespace shroudsim::modal
