#include "modal/eigensolver.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Spectra/SymEigsSolver.h>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "linalg/blas.hpp"

#include "core/error.hpp"
#include "core/log.hpp"

namespace shroudsim::modal {

using linalg::SparseMatrixC;
using linalg::SparseMatrixD;

bool ModalOptions::validate(std::vector<std::string>* errors) const {
  const auto n0 = errors ? errors->size() : 0;
  auto fail = [&](const std::string& m) {
    if (errors) errors->push_back(m);
  };
  if (modes < 1) fail("modes = " + std::to_string(modes) + " violates: modes >= 1");
  if (!std::isfinite(shift)) fail("shift must be finite");
  if (ncv < 0) fail("ncv must be >= 0");
  if (block_size < 0) fail("block_size must be >= 0");
  if (max_restarts < 1) fail("max_restarts must be >= 1");
  if (!(tolerance > 0.0 && tolerance < 1e-2)) fail("tolerance must be in (0, 1e-2)");
  if (!(residual_tolerance > 0.0 && residual_tolerance < 1.0)) fail("residual_tolerance must be in (0, 1)");
  return !errors || errors->size() == n0;
}

Eigen::VectorXd ModalBasis::frequency_hz() const { return omega / (2.0 * M_PI); }

ModalBasis ModalBasis::conjugate(int new_harmonic_index) const {
  return {new_harmonic_index, omega, phi.conjugate()};
}

std::string to_string(EigenMethod method) {
  return method == EigenMethod::Block ? "block" : "spectra";
}

std::string to_string(ModalStatus status) {
  switch (status) {
    case ModalStatus::Converged: return "converged";
    case ModalStatus::FactorizationFailed: return "factorization failed";
    case ModalStatus::NotConverged: return "not converged";
    case ModalStatus::ResidualTooLarge: return "residual too large";
    case ModalStatus::TooFewModes: return "too few modes";
  }
  return "unknown";
}

// ---------------------------------------------------------------------------------------------
// StiffnessFactor

StiffnessFactor::StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<double>> real)
    : real_(std::move(real)) {}
StiffnessFactor::StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<Complex>> complex, bool conjugated)
    : complex_(std::move(complex)), conjugated_(conjugated) {}

Eigen::Index StiffnessFactor::rows() const {
  return real_ ? real_->rows() : complex_ ? complex_->rows() : 0;
}

Eigen::MatrixXcd StiffnessFactor::solve(const Eigen::MatrixXcd& b) const {
  SHROUDSIM_CHECK(valid(), "StiffnessFactor::solve without a factor");
  if (real_) {
    Eigen::MatrixXd parts(b.rows(), 2 * b.cols());
    parts << b.real(), b.imag();
    const Eigen::MatrixXd x = real_->solve(parts);
    Eigen::MatrixXcd out(b.rows(), b.cols());
    out.real() = x.leftCols(b.cols());
    out.imag() = x.rightCols(b.cols());
    return out;
  }
  if (conjugated_) return complex_->solve(b.conjugate()).conjugate();
  return complex_->solve(b);
}

StiffnessFactor StiffnessFactor::conjugate() const {
  if (real_) return *this;
  return StiffnessFactor(complex_, !conjugated_);
}

// The StiffnessFactor holding a factor of K itself (not conjugated).
template <typename Scalar>
static StiffnessFactor stiffness_factor(std::shared_ptr<const linalg::CholmodFactor<Scalar>> f) {
  if constexpr (std::is_same_v<Scalar, double>)
    return StiffnessFactor(std::move(f));
  else
    return StiffnessFactor(std::move(f), false);
}

template <typename Scalar>
static StiffnessFactor factor_stiffness_impl(const linalg::SparseMatrix<Scalar>& K, linalg::FactorMethod method) {
  auto f = std::make_shared<linalg::CholmodFactor<Scalar>>(method);
  const auto status = f->compute(K);
  if (status != linalg::FactorStatus::Success)
    throw NumericalError("factorization of the stiffness matrix failed: " + linalg::to_string(status));
  return stiffness_factor<Scalar>(f);
}

StiffnessFactor factor_stiffness(const SparseMatrixD& K, linalg::FactorMethod method) {
  return factor_stiffness_impl(K, method);
}
StiffnessFactor factor_stiffness(const SparseMatrixC& K, linalg::FactorMethod method) {
  return factor_stiffness_impl(K, method);
}

// ---------------------------------------------------------------------------------------------
// Spectra operators on the real representation (n for real, 2n = [Re; Im] for complex).

namespace {

template <typename S>
constexpr bool kIsComplex = !std::is_same_v<S, double>;

/// The symmetric shift-invert operator y = L^{-1} P M P^T L^{-H} x, with P (K - sigma M) P^T
/// = L L^H, on the real representation (n for real, [Re; Im] of length 2n for complex).
/// Its eigenvalues are nu = 1 / (lambda - sigma) and its eigenvectors y = L^H P x, so Lanczos
/// runs in the Euclidean inner product: one solve and one product with M per step (the
/// B-inner-product form of SymGEigsShiftSolver applies M about eight times per step).
template <typename S>
class SymmetricShiftInvertOp {
 public:
  using Scalar = double;
  SymmetricShiftInvertOp(const linalg::CholmodFactor<S>& factor, const linalg::SparseMatrix<S>& M)
      : factor_(factor), M_(M), n_(M.rows()), a_(n_), b_(n_) {}
  Eigen::Index rows() const { return kIsComplex<S> ? 2 * n_ : n_; }
  Eigen::Index cols() const { return rows(); }
  void perform_op(const double* x, double* y) const {
    ++products_;
    if constexpr (kIsComplex<S>) {
      for (Eigen::Index i = 0; i < n_; ++i) a_[i] = S(x[i], x[n_ + i]);
      factor_.solve_backward(a_.data(), b_.data());
      a_.noalias() = M_ * b_;
      factor_.solve_forward(a_.data(), b_.data());
      for (Eigen::Index i = 0; i < n_; ++i) {
        y[i] = b_[i].real();
        y[n_ + i] = b_[i].imag();
      }
    } else {
      factor_.solve_backward(x, b_.data());
      a_.noalias() = M_ * b_;
      factor_.solve_forward(a_.data(), y);
    }
  }
  long products() const { return products_; }

 private:
  const linalg::CholmodFactor<S>& factor_;
  const linalg::SparseMatrix<S>& M_;
  Eigen::Index n_;
  mutable Eigen::Matrix<S, Eigen::Dynamic, 1> a_, b_;
  mutable long products_ = 0;
};

// Problems up to this size go to a dense solver (Lanczos brings nothing there).
constexpr Eigen::Index kDenseThreshold = 300;

// Two Ritz values belong to one group (one physical eigenvalue, possibly several modes)
// when they agree to this relative tolerance; a group is then resolved by Rayleigh-Ritz,
// so a loose value only costs a few sparse products.
constexpr double kGroupRelTol = 1e-6;
// Complex rank of a group: eigenvalues of its Euclidean Gram matrix below this fraction of
// the largest are copies (i z of a z already present). Copies agree to ~sqrt(tolerance);
// distinct modes give O(1).
constexpr double kRankRelTol = 1e-4;

template <typename S>
using MatrixS = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;

// Explicit residual check; fills report.max_residual and returns false if above tolerance.
template <typename S>
bool check_residuals(const linalg::SparsePair<S>& km, const Eigen::VectorXd& lambda, const MatrixS<S>& phi,
                     const ModalOptions& options, ModalReport& report) {
  report.max_residual = 0.0;
  int worst = -1;
  // K and M are symmetric/Hermitian and stored in full, so K^H (a row-major view of the same
  // storage) multiplies all modes in one pass over the matrix.
  const MatrixS<S> KP = km.K.adjoint() * phi;
  const MatrixS<S> MP = km.M.adjoint() * phi;
  for (Eigen::Index j = 0; j < phi.cols(); ++j) {
    const double denom = std::max(KP.col(j).norm(), std::numeric_limits<double>::min());
    const double rel = (KP.col(j) - lambda(j) * MP.col(j)).norm() / denom;
    if (!(rel <= report.max_residual)) {
      report.max_residual = std::isfinite(rel) ? rel : std::numeric_limits<double>::infinity();
      worst = static_cast<int>(j);
    }
  }
  if (!(report.max_residual <= options.residual_tolerance)) {
    report.status = ModalStatus::ResidualTooLarge;
    report.message = "mode " + std::to_string(worst + 1) + " has relative residual " +
                     std::to_string(report.max_residual) + " > " + std::to_string(options.residual_tolerance);
    return false;
  }
  return true;
}

template <typename S>
ModalResult finish(const linalg::SparsePair<S>& km, int h, Eigen::VectorXd lambda, MatrixS<S> phi,
                   const ModalOptions& options, ModalReport report) {
  // Ascending order, lowest `modes`.
  std::vector<Eigen::Index> order(lambda.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return lambda(a) < lambda(b); });
  const Eigen::Index k = std::min<Eigen::Index>(options.modes, lambda.size());
  ModalResult result;
  result.report = std::move(report);
  Eigen::VectorXd lam(k);
  MatrixS<S> vec(phi.rows(), k);
  for (Eigen::Index j = 0; j < k; ++j) {
    lam(j) = lambda(order[j]);
    vec.col(j) = phi.col(order[j]);
  }
  if (k < options.modes && result.report.status == ModalStatus::Converged) {
    if (phi.rows() <= k) {
      result.report.message = "only " + std::to_string(k) + " modes exist (" + std::to_string(phi.rows()) +
                              " DOFs); " + std::to_string(options.modes) + " were asked for";
    } else {
      result.report.status = ModalStatus::TooFewModes;
      result.report.message = "found " + std::to_string(k) + " distinct modes, " +
                              std::to_string(options.modes) + " were asked for";
    }
  }
  if (!result.report.ok()) return result;
  if (!check_residuals(km, lam, vec, options, result.report)) return result;
  result.basis.harmonic_index = h;
  result.basis.omega = lam.cwiseMax(0.0).cwiseSqrt();
  if constexpr (kIsComplex<S>)
    result.basis.phi = vec;
  else
    result.basis.phi = vec.template cast<Complex>();
  return result;
}

template <typename S>
ModalResult solve_dense(const linalg::SparsePair<S>& km, int h, const ModalOptions& options) {
  ModalReport report;
  report.method = "dense";
  log::Stopwatch watch;
  const MatrixS<S> K(km.K), M(km.M);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixS<S>> es(K - S(options.shift) * M, M);
  report.solve_seconds = watch.seconds();
  if (es.info() != Eigen::Success) {
    report.status = ModalStatus::NotConverged;
    report.message = "dense generalized eigensolver failed";
    ModalResult r;
    r.report = report;
    return r;
  }
  Eigen::VectorXd lambda = es.eigenvalues().array() + options.shift;
  return finish<S>(km, h, lambda, es.eigenvectors(), options, report);
}

template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>>& reuse_slot(FactorReuse& reuse) {
  if constexpr (kIsComplex<S>)
    return reuse.complex;
  else
    return reuse.real;
}
template <typename S>
Eigen::Index& reuse_nonzeros(FactorReuse& reuse) {
  if constexpr (kIsComplex<S>)
    return reuse.complex_nonzeros;
  else
    return reuse.real_nonzeros;
}

// Factorizes K - sigma M (reusing reuse's symbolic analysis when the pattern matches).
// Fills report.factor_seconds / factor_nonzeros; on failure sets the report's status and
// message and returns null.
template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>> factor_shifted(const linalg::SparsePair<S>& km, const ModalOptions& options,
                                                         FactorReuse* reuse, ModalReport& report) {
  log::Stopwatch watch;
  std::shared_ptr<linalg::CholmodFactor<S>> factor;
  {
    linalg::SparseMatrix<S> A = options.shift == 0.0 ? linalg::SparseMatrix<S>(km.K)
                                                     : linalg::SparseMatrix<S>(km.K - S(options.shift) * km.M);
    A.makeCompressed();
    if (reuse && reuse_slot<S>(*reuse) && reuse_slot<S>(*reuse)->rows() == A.rows() &&
        reuse_nonzeros<S>(*reuse) == A.nonZeros()) {
      factor = reuse_slot<S>(*reuse);
      factor->factorize(A);  // symbolic analysis of an earlier solve, same pattern
    } else {
      factor = std::make_shared<linalg::CholmodFactor<S>>(options.factor_method);
      factor->compute(A);
      if (reuse) {
        reuse_slot<S>(*reuse) = factor;
        reuse_nonzeros<S>(*reuse) = A.nonZeros();
        ++reuse->analyses;
      }
    }
    if (reuse) ++reuse->factorizations;
  }
  report.factor_seconds = watch.seconds();
  report.factor_nonzeros = factor->factor_nonzeros();
  if (factor->status() != linalg::FactorStatus::Success) {
    report.status = ModalStatus::FactorizationFailed;
    report.message = "CHOLMOD factorization of K - sigma M (sigma = " + std::to_string(options.shift) +
                     ") failed: " + linalg::to_string(factor->status());
    return nullptr;
  }
  return factor;
}

template <typename S>
ModalResult solve_spectra(const linalg::SparsePair<S>& km, int h, const ModalOptions& options,
                          FactorReuse* reuse) {
  const Eigen::Index n = km.K.rows();
  const Eigen::Index real_n = kIsComplex<S> ? 2 * n : n;
  ModalReport report;
  report.method = kIsComplex<S> ? "spectra-complex-2n" : "spectra-real";
  const Eigen::Index nev = std::min<Eigen::Index>(kIsComplex<S> ? 2 * options.modes + 4 : options.modes, real_n - 1);
  Eigen::Index ncv = options.ncv > 0 ? options.ncv : std::max<Eigen::Index>(2 * nev + 1, nev + 20);
  ncv = std::min(std::max(ncv, nev + 1), real_n);
  report.requested_eigenvalues = static_cast<int>(nev);

  log::Stopwatch watch;
  const auto factor = factor_shifted<S>(km, options, reuse, report);
  if (!factor) {
    ModalResult r;
    r.report = report;
    return r;
  }
  SymmetricShiftInvertOp<S> op(*factor, km.M);
  Spectra::SymEigsSolver<SymmetricShiftInvertOp<S>> solver(op, nev, ncv);
  watch.restart();
  solver.init();
  const Eigen::Index nconv = solver.compute(Spectra::SortRule::LargestAlge, options.max_restarts, options.tolerance);
  report.spectra_info = static_cast<int>(solver.info());
  report.converged_eigenvalues = static_cast<int>(nconv);
  report.iterations = static_cast<int>(solver.num_iterations());
  report.operations = static_cast<int>(solver.num_operations());
  report.mass_products = static_cast<int>(op.products());
  if (solver.info() != Spectra::CompInfo::Successful || nconv < nev) {
    report.solve_seconds = watch.seconds();
    report.status = ModalStatus::NotConverged;
    report.message = "Spectra SymEigsSolver (shift-invert): " + std::to_string(nconv) + " of " + std::to_string(nev) +
                     " eigenvalues converged after " + std::to_string(report.iterations) +
                     " restarts (CompInfo " + std::to_string(report.spectra_info) + ")";
    ModalResult r;
    r.report = report;
    return r;
  }
  // nu = 1 / (lambda - sigma) > 0 (K - sigma M positive definite); x = P^T L^{-H} y / sqrt(nu)
  // is mass-normalised (x^H M x = nu y^H y).
  const Eigen::VectorXd nu = solver.eigenvalues();
  const Eigen::MatrixXd Y = solver.eigenvectors();
  if (!(nu.minCoeff() > 0.0)) {
    report.solve_seconds = watch.seconds();
    report.status = ModalStatus::NotConverged;
    report.message = "shift-invert operator returned a non-positive eigenvalue";
    ModalResult r;
    r.report = report;
    return r;
  }
  const Eigen::VectorXd ritz = (1.0 / nu.array() + options.shift).matrix();
  MatrixS<S> Xs(n, nu.size());
  {
    Eigen::Matrix<S, Eigen::Dynamic, 1> yc(n), xc(n);
    for (Eigen::Index j = 0; j < nu.size(); ++j) {
      if constexpr (kIsComplex<S>)
        yc = Y.col(j).head(n).template cast<S>() + S(0, 1) * Y.col(j).tail(n).template cast<S>();
      else
        yc = Y.col(j);
      factor->solve_backward(yc.data(), xc.data());
      Xs.col(j) = xc / std::sqrt(nu(j));
    }
  }
  report.solve_seconds = watch.seconds();

  ModalResult result;
  if constexpr (!kIsComplex<S>) {
    result = finish<S>(km, h, ritz, Xs, options, report);
  } else {
    // Back to complex vectors; each physical mode may appear up to twice (z and i z).
    const Eigen::MatrixXcd& Z = Xs;
    std::vector<Eigen::Index> order(ritz.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](auto a, auto b) { return ritz(a) < ritz(b); });
    const double scale = ritz.cwiseAbs().maxCoeff();
    std::vector<double> lam;
    std::vector<Eigen::VectorXcd> vecs;
    for (std::size_t g0 = 0; g0 < order.size();) {
      std::size_t g1 = g0 + 1;
      while (g1 < order.size() &&
             std::abs(ritz(order[g1]) - ritz(order[g0])) <= kGroupRelTol * std::max(std::abs(ritz(order[g0])), 1e-12 * scale))
        ++g1;
      const auto size = static_cast<Eigen::Index>(g1 - g0);
      if (size == 1) {
        // Already mass-normalised (z^H M z = 1).
        lam.push_back(ritz(order[g0]));
        vecs.push_back(Z.col(order[g0]));
      } else {
        Eigen::MatrixXcd Zg(n, size);
        for (Eigen::Index j = 0; j < size; ++j) Zg.col(j) = Z.col(order[g0 + j]);
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd> gram(Zg.adjoint() * Zg);
        const Eigen::VectorXd g = gram.eigenvalues();  // ascending
        Eigen::Index rank = 0;
        for (Eigen::Index j = 0; j < size; ++j) rank += g(j) > kRankRelTol * g(size - 1);
        if (rank == 1) {
          lam.push_back(ritz(order[g0]));
          vecs.push_back(Zg.col(0));
        } else {
          // Several physical modes: Rayleigh-Ritz on the group's complex span.
          const Eigen::MatrixXcd W = Zg * gram.eigenvectors().rightCols(rank);
          const Eigen::MatrixXcd MW = km.M * W, KW = km.K * W;
          Eigen::MatrixXcd Gm = W.adjoint() * MW, Km = W.adjoint() * KW;
          Gm = 0.5 * (Gm + Gm.adjoint()).eval();
          Km = 0.5 * (Km + Km.adjoint()).eval();
          Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXcd> rr(Km, Gm);
          for (Eigen::Index j = 0; j < rank; ++j) {
            lam.push_back(rr.eigenvalues()(j));
            vecs.push_back(W * rr.eigenvectors().col(j));
          }
        }
      }
      g0 = g1;
    }
    Eigen::VectorXd lambda = Eigen::Map<const Eigen::VectorXd>(lam.data(), static_cast<Eigen::Index>(lam.size()));
    Eigen::MatrixXcd phi(n, static_cast<Eigen::Index>(vecs.size()));
    for (std::size_t j = 0; j < vecs.size(); ++j) phi.col(static_cast<Eigen::Index>(j)) = vecs[j];
    result = finish<S>(km, h, lambda, phi, options, report);
  }
  if (result.report.ok() && options.shift == 0.0 && !reuse) result.stiffness = stiffness_factor<S>(factor);
  return result;
}

// ---------------------------------------------------------------------------------------------
// Block Krylov-Schur on the symmetric shift-invert operator C = L^{-1} P M P^T L^{-H}.
//
// State: an orthonormal basis V (n x m), the projection T = V^H C V and a pending block Q
// (n x b, orthonormal, Q ⟂ V) with C V = V T + Q S for some S. A step appends Q to V, applies
// C to it (one block of solves), orthogonalizes the product against V twice (classical
// Gram-Schmidt, BLAS-3), which gives T's new columns and, by a QR of what is left, the next
// pending block: C V = V T + Q B E^T with E picking V's last block. The Ritz pairs
// (theta, V y) of T then have residual norms ||C V y - theta V y|| = ||B E^T y||, known
// without touching an n-vector. When V is full it is contracted to its best Ritz vectors
// (thick restart): T becomes diagonal and the relation keeps its form, the pending block
// unchanged. Converged: the `modes` largest theta have ||B E^T y|| <= tolerance * theta.

template <typename S>
using Block = MatrixS<S>;

// Default block size. Measured on the 194,034-DOF complex K_h, 30 modes (BENCHMARKS.md):
// the solve of a block of 4 costs 0.6 single solves per vector, and the block basis needs
// more vectors than single-vector Lanczos (92 against 59 at a basis of 3 modes): block 1,
// 2, 4, 8 took 11.3, 12.2, 10.8, 14.8 s. A block above 1 also resolves eigenvalues of
// multiplicity up to its size.
constexpr Eigen::Index kDefaultBlock = 4;

// Deterministic start block (reproducible modes, same sign convention run to run).
template <typename S>
Block<S> start_block(Eigen::Index n, Eigen::Index b) {
  std::mt19937_64 gen(20261201);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Block<S> X(n, b);
  for (Eigen::Index j = 0; j < b; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      if constexpr (kIsComplex<S>)
        X(i, j) = S(u(gen), u(gen));
      else
        X(i, j) = u(gen);
    }
  return X;
}

// X <- X - V (V^H X), twice; returns the accumulated V^H X (m x b).
template <typename S>
Block<S> orthogonalize(const Eigen::Ref<const Block<S>, 0, Eigen::OuterStride<>>& V, Block<S>& X) {
  using linalg::Op;
  Block<S> H = Block<S>::Zero(V.cols(), X.cols());
  if (V.cols() == 0) return H;
  Block<S> h(V.cols(), X.cols());
  for (int pass = 0; pass < 2; ++pass) {
    linalg::gemm<S>(Op::Adjoint, S(1), V, X, S(0), h);
    linalg::gemm<S>(Op::None, S(-1), V, h, S(1), X);
    H += h;
  }
  return H;
}

// Q R = X with Q orthonormal and orthogonal to V. A column X has lost to round-off (a
// Krylov breakdown: C has an invariant subspace inside V) is replaced by a fresh random
// direction, its row of R zeroed: the relation C V = V T + Q R E^T still holds.
template <typename S>
void block_qr(const Eigen::Ref<const Block<S>, 0, Eigen::OuterStride<>>& V, Block<S>& X, Block<S>& R) {
  const Eigen::Index n = X.rows(), b = X.cols();
  const double scale = std::max(X.colwise().norm().maxCoeff(), std::numeric_limits<double>::min());
  Eigen::HouseholderQR<Block<S>> qr(X);
  R = qr.matrixQR().topRows(b).template triangularView<Eigen::Upper>();
  X = qr.householderQ() * Block<S>::Identity(n, b);
  bool refill = false;
  for (Eigen::Index j = 0; j < b; ++j)
    if (std::abs(R(j, j)) < 1e-12 * scale) {
      R.row(j).setZero();
      refill = true;
    }
  if (!refill) return;
  Block<S> fresh = start_block<S>(n, b);
  for (Eigen::Index j = 0; j < b; ++j)
    if (R.row(j).isZero(0.0)) X.col(j) = fresh.col(j);
  Block<S> all(n, V.cols() + b);
  all << V, X;
  for (Eigen::Index j = 0; j < b; ++j) {
    if (!R.row(j).isZero(0.0)) continue;
    Block<S> x = X.col(j);
    orthogonalize<S>(all, x);
    X.col(j) = x.normalized();
    all.col(V.cols() + j) = X.col(j);
  }
}

template <typename S>
ModalResult solve_block(const linalg::SparsePair<S>& km, int h, const ModalOptions& options, FactorReuse* reuse) {
  const Eigen::Index n = km.K.rows();
  ModalReport report;
  report.method = kIsComplex<S> ? "block-complex" : "block-real";
  const Eigen::Index nev = std::min<Eigen::Index>(options.modes, n - 1);
  const Eigen::Index b = std::min<Eigen::Index>(options.block_size > 0 ? options.block_size : kDefaultBlock, n / 4);
  Eigen::Index mmax = options.ncv > 0 ? options.ncv : std::max<Eigen::Index>(3 * nev, nev + 3 * b);
  mmax = std::min(std::max(mmax, nev + 2 * b), n);
  // Ritz vectors kept at a restart: the wanted ones and one block of the next.
  const Eigen::Index keep = std::min(nev + b, mmax - b);
  report.requested_eigenvalues = static_cast<int>(nev);

  const auto factor = factor_shifted<S>(km, options, reuse, report);
  if (!factor) {
    ModalResult r;
    r.report = report;
    return r;
  }
  log::Stopwatch watch;
  auto apply = [&](const Block<S>& X) {
    report.operations += static_cast<int>(X.cols());
    report.mass_products += static_cast<int>(X.cols());
    const Block<S> Y = factor->solve_backward(X);
    const Block<S> MY = km.M * Y;
    return factor->solve_forward(MY);
  };

  Block<S> V(n, mmax), T = Block<S>::Zero(mmax, mmax), Q = start_block<S>(n, b), B;
  block_qr<S>(V.leftCols(0), Q, B);
  Eigen::Index m = 0;
  Eigen::VectorXd theta;
  Block<S> Y;
  bool converged = false;
  int restarts = 0;
  while (!converged) {
    if (m + b > mmax) {
      if (restarts == options.max_restarts) break;
      // Thick restart on the `keep` largest Ritz pairs (theta ascending: the last columns).
      const Block<S> Yk = Y.rightCols(keep);
      Block<S> U(n, keep);
      linalg::gemm<S>(linalg::Op::None, S(1), V.leftCols(m), Yk, S(0), U);
      V.leftCols(keep) = U;
      T.setZero();
      T.topLeftCorner(keep, keep).diagonal() = theta.tail(keep).template cast<S>();
      m = keep;
      ++restarts;
    }
    V.middleCols(m, b) = Q;
    m += b;
    Block<S> W = apply(Q);
    const Block<S> H = orthogonalize<S>(V.leftCols(m), W);
    T.block(0, m - b, m, b) = H;
    T.block(m - b, 0, b, m) = H.adjoint();
    T.block(m - b, m - b, b, b) = (0.5 * (H.bottomRows(b) + H.bottomRows(b).adjoint())).eval();
    Q = std::move(W);
    block_qr<S>(V.leftCols(m), Q, B);
    ++report.iterations;

    if (m < nev) continue;
    Eigen::SelfAdjointEigenSolver<Block<S>> es(T.topLeftCorner(m, m));
    if (es.info() != Eigen::Success) break;
    theta = es.eigenvalues();  // ascending; the wanted are the largest
    Y = es.eigenvectors();
    const Block<S> resid = B * Y.bottomRows(b).rightCols(nev);
    converged = true;
    for (Eigen::Index j = 0; j < nev; ++j) {
      const double th = theta(m - nev + j);
      if (!(th > 0.0) || !(resid.col(j).norm() <= options.tolerance * th)) converged = false;
    }
  }
  report.converged_eigenvalues = 0;
  if (theta.size() > 0)
    for (Eigen::Index j = 0; j < nev; ++j)
      if (theta(m - nev + j) > 0.0 &&
          (B * Y.bottomRows(b).col(m - nev + j)).norm() <= options.tolerance * theta(m - nev + j))
        ++report.converged_eigenvalues;
  if (!converged) {
    report.solve_seconds = watch.seconds();
    report.status = ModalStatus::NotConverged;
    report.message = "block Krylov-Schur (shift-invert, block " + std::to_string(b) + ", basis " +
                     std::to_string(mmax) + "): " + std::to_string(report.converged_eigenvalues) + " of " +
                     std::to_string(nev) + " eigenvalues converged after " + std::to_string(report.iterations) +
                     " steps, " + std::to_string(restarts) + " restarts";
    ModalResult r;
    r.report = report;
    return r;
  }
  // nu = 1 / (lambda - sigma); x = P^T L^{-H} V y / sqrt(nu) is mass-normalised.
  const Eigen::VectorXd nu = theta.tail(nev);
  Block<S> Z(n, nev);
  linalg::gemm<S>(linalg::Op::None, S(1), V.leftCols(m), Y.rightCols(nev), S(0), Z);
  Block<S> X = factor->solve_backward(Z);
  for (Eigen::Index j = 0; j < nev; ++j) X.col(j) /= std::sqrt(nu(j));
  const Eigen::VectorXd lambda = (1.0 / nu.array() + options.shift).matrix();
  report.solve_seconds = watch.seconds();
  ModalResult result = finish<S>(km, h, lambda, X, options, report);
  if (result.report.ok() && options.shift == 0.0 && !reuse) result.stiffness = stiffness_factor<S>(factor);
  return result;
}

template <typename S>
ModalResult solve_any(const linalg::SparsePair<S>& km, int h, const ModalOptions& options,
                      FactorReuse* reuse = nullptr) {
  std::vector<std::string> errors;
  SHROUDSIM_CHECK(options.validate(&errors), errors.empty() ? "invalid ModalOptions" : errors.front());
  SHROUDSIM_CHECK(km.K.rows() == km.K.cols() && km.M.rows() == km.K.rows() && km.M.cols() == km.K.rows(),
                  "solve_modes: K and M must be square and of equal size");
  SHROUDSIM_CHECK(km.K.rows() > 0, "solve_modes: empty problem (every DOF clamped?)");
  const Eigen::Index n = km.K.rows();
  const Eigen::Index real_n = kIsComplex<S> ? 2 * n : n;
  const bool spectra = options.method == EigenMethod::Spectra;
  const Eigen::Index nev = kIsComplex<S> && spectra ? 2 * options.modes + 4 : options.modes;
  // The block method needs room for its basis (2 modes + a few blocks) in n.
  const Eigen::Index room = spectra ? nev + 1 : 3 * nev + 16;
  if (n <= kDenseThreshold || room >= (spectra ? real_n : n)) return solve_dense<S>(km, h, options);
  return spectra ? solve_spectra<S>(km, h, options, reuse) : solve_block<S>(km, h, options, reuse);
}

}  // namespace

ModalResult solve_modes(const linalg::SparsePair<double>& km, int h, const ModalOptions& options) {
  return solve_any<double>(km, h, options);
}

ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int h, const ModalOptions& options) {
  return solve_any<Complex>(km, h, options);
}

ModalResult solve_modes(const linalg::SparsePair<double>& km, int h, const ModalOptions& options,
                        FactorReuse& reuse) {
  return solve_any<double>(km, h, options, &reuse);
}

ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int h, const ModalOptions& options,
                        FactorReuse& reuse) {
  return solve_any<Complex>(km, h, options, &reuse);
}

}  // namespace shroudsim::modal
