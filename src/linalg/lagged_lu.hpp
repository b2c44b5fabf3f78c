#pragma once
// A lagged single-precision LU preconditioner for a sequence of slowly changing dense real
// systems A_k x = b_k (the Newton systems along a continuation), solved by GMRES
// (linalg/gmres.hpp):
//
//     M = P^{-1} L U  of an earlier A_j, factorized in single precision;  z = M^{-1} v.
//
// v and z are double; only the factors and the triangular solves are single precision (half
// the memory traffic of the solves, twice the vector width of the factorization), so with
// GMRES and its true-residual check in double only the iteration count can suffer.
//
// Renewal: the caller factorizes when it has no usable factors or a solve with them failed.
// After a converged solve, a renewal is due when that solve took more than `refactor_after`
// iterations and the iterations since the factorization have cost more than the
// factorization did. The costs are counted, not timed, so the decision is the same on every
// run and machine: a factorization of order m is (2/3) m^3 flops at BLAS-3 speed, an
// iteration is dominated by its two triangular solves, 2 m^2 flops at BLAS-2 speed,
// kTriangularSlowdown = 4 times slower per flop: a factorization is worth m / 12 iterations.
//
// Eigen's own LU, compiled for the build machine (-march=native): at order 4,588 on the
// development machine it factorizes in 0.91 s and solves in 4.1 ms, against 0.90 s and 4.3 ms
// for OpenBLAS's sgetrf / sgetrs on one thread (BENCHMARKS.md, "Many contact pairs").
#include <Eigen/Core>
#include <Eigen/LU>

namespace shroudsim::linalg {

class LaggedLuPreconditioner {
 public:
  /// Factorizes A (square) in single precision; the iteration count starts afresh and no
  /// renewal is due.
  void factorize(const Eigen::MatrixXd& A);
  /// Factors of a matrix of order `size` are held and no renewal is due.
  bool usable(Eigen::Index size) const { return valid_ && !renew_ && lu_.rows() == size; }
  /// False when the factorization met an exactly zero pivot (the solves would divide by it).
  bool nonsingular() const { return valid_ && nonsingular_; }
  /// z = M^{-1} v. Requires factors.
  void apply(const Eigen::VectorXd& v, Eigen::VectorXd& z) const;
  /// Counts the iterations of a solve preconditioned with the held factors.
  void add_iterations(int iterations) { iterations_since_factor_ += iterations; }
  /// After a converged solve of `iterations` iterations with the held factors (counted by
  /// add_iterations): decides whether a renewal is due (the rule above).
  void decide_renewal(int iterations, int refactor_after);
  /// Forgets the factors (the next solve factorizes).
  void invalidate() { valid_ = false; }

 private:
  Eigen::PartialPivLU<Eigen::MatrixXf> lu_;
  bool valid_ = false, renew_ = false, nonsingular_ = false;
  long iterations_since_factor_ = 0;  // preconditioned iterations since the factorization
};

}  // namespace shroudsim::linalg
