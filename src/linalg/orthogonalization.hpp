#pragma once
// Orthogonalization of a block of vectors X (n x b) against an orthonormal basis V (n x m),
// for block Krylov methods (modal/block_krylov_schur.hpp), real (Scalar double) or complex
// (Scalar Complex), Euclidean inner product:
//
//   orthogonalize:  X <- (I - V V^H) X applied twice (classical Gram-Schmidt, each pass two
//                   BLAS-3 products through linalg::gemm); returns H = V^H X summed over
//                   both passes (m x b), so X_in = V H + X_out.
//   block_qr:       X = Q R with Q (n x b) orthonormal and R (b x b) upper triangular,
//                   by Householder QR; X is overwritten by Q. A column whose diagonal
//                   |R(j, j)| is below 1e-12 of the largest column norm of X (a Krylov
//                   breakdown: X lies in span V up to round-off) gets a zero row in R and a
//                   new direction in Q, from deterministic_block, so that X = Q R still holds
//                   up to what was dropped. Known defect of that (rare) path: the new
//                   direction is orthogonalized against [V, Q] while Q still holds it, which
//                   leaves it orthogonal neither to V nor to the other columns of Q; the
//                   breakdown-free path is unaffected.
//
// Preconditions: V has orthonormal columns (m may be 0); for block_qr, X's columns are
// orthogonal to V (orthogonalize first). Random directions are deterministic: the same
// (n, b) always gives the same block, so the methods using them are reproducible.
#include <Eigen/Core>

#include "linalg/blas.hpp"

namespace shroudsim::linalg {

/// Column-major block with any outer stride (a leading part of a larger basis).
template <typename Scalar>
using BlockRef = Eigen::Ref<const DenseMatrix<Scalar>, 0, Eigen::OuterStride<>>;

/// n x b entries uniform in [-1, 1] (real and imaginary parts for complex Scalar), from a
/// fixed seed: the same block on every call and every run.
template <typename Scalar>
DenseMatrix<Scalar> deterministic_block(Eigen::Index n, Eigen::Index b);

/// X <- X - V (V^H X), twice; returns the accumulated V^H X (m x b).
template <typename Scalar>
DenseMatrix<Scalar> orthogonalize(const BlockRef<Scalar>& V, DenseMatrix<Scalar>& X);

/// Q R = X, Q orthonormal and orthogonal to V, written over X (see the header comment).
template <typename Scalar>
void block_qr(const BlockRef<Scalar>& V, DenseMatrix<Scalar>& X, DenseMatrix<Scalar>& R);

}  // namespace shroudsim::linalg
