#pragma once
// Right-preconditioned GMRES for a real linear system A x = b given by products only:
//
//     A M^{-1} u = b,  x = M^{-1} u,
//
// `op` applies A (y = A x) and `precondition` applies M^{-1} (z = M^{-1} v); neither matrix
// is formed. The Arnoldi basis is orthogonalized by classical Gram-Schmidt applied twice, the
// Hessenberg matrix reduced by Givens rotations; no restart: at most max_iterations basis
// vectors. The iteration stops when the recurrence's residual estimate falls below
// 0.1 tolerance ||b|| (or the Krylov space is exhausted), and the result is accepted only if
// its true residual, recomputed with `op`, satisfies ||A x - b|| <= tolerance ||b||: round-off
// in the recurrence or a stagnating Krylov space cannot pass for convergence.
//
// Deterministic (no randomness, a fixed order of operations). b = 0 gives x = 0 at once.
#include <Eigen/Core>
#include <functional>

namespace shroudsim::linalg {

/// y = A x (or z = M^{-1} v); the output is resized by the callee.
using VectorOperator = std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>;

struct GmresOptions {
  int max_iterations = 40;   ///< basis vectors (one product with A and one with M^{-1} each), >= 1
  double tolerance = 1e-11;  ///< relative true residual ||A x - b|| / ||b||
};

struct GmresResult {
  bool converged = false;  ///< the true residual met the tolerance
  int iterations = 0;      ///< iterations done (0 when the iteration broke down)
};

/// Solves A x = b (x: the solution, resized; meaningful when converged).
GmresResult gmres(const VectorOperator& op, const VectorOperator& precondition, const Eigen::VectorXd& b,
                  Eigen::VectorXd& x, const GmresOptions& options);

}  // namespace shroudsim::linalg
