#include "modal/eigensolver.hpp"

#include <Spectra/SymEigsSolver.h>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>

#include "core/error.hpp"
#include "core/log.hpp"
#include "modal/block_krylov_schur.hpp"

namespace shroudsim::modal {

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

ModalBasis ModalBasis::conjugate(int new_harmonic_index) const { return {new_harmonic_index, omega, phi.conjugate()}; }

std::string to_string(EigenMethod method) { return method == EigenMethod::Block ? "block" : "spectra"; }

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

namespace {

template <typename S>
constexpr bool kIsComplex = !std::is_same_v<S, double>;

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
      result.report.message = "only " + std::to_string(k) + " modes exist (" + std::to_string(phi.rows()) + " DOFs); " +
                              std::to_string(options.modes) + " were asked for";
    } else {
      result.report.status = ModalStatus::TooFewModes;
      result.report.message =
          "found " + std::to_string(k) + " distinct modes, " + std::to_string(options.modes) + " were asked for";
    }
  }
  if (!result.report.ok()) return result;
  if (!check_residuals(km, lam, vec, options, result.report)) return result;
  result.basis.harmonic_index = h;
  result.basis.omega = lam.cwiseMax(0.0).cwiseSqrt();
  if constexpr (kIsComplex<S>) result.basis.phi = vec;
  else result.basis.phi = vec.template cast<Complex>();
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

// Factorizes K - sigma M (modal/shift_invert.hpp). Fills report.factor_seconds /
// factor_nonzeros; on failure sets the report's status and message and returns null.
template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>> factor_checked(const linalg::SparsePair<S>& km, const ModalOptions& options,
                                                         FactorReuse* reuse, ModalReport& report) {
  log::Stopwatch watch;
  std::shared_ptr<linalg::CholmodFactor<S>> factor =
      factor_shifted<S>(km, options.shift, options.factor_method, reuse, options.analysis.get());
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

// The Ritz pairs (ritz, Z) of the 2n embedding, mapped back to complex vectors, hold each
// physical mode z up to twice (z and i z). Grouped by Ritz value (kGroupRelTol), each group's
// complex span is reduced to its physical modes (kRankRelTol; Rayleigh-Ritz on K and M when
// it holds more than one): lambda and phi get each mode once, mass-normalised.
void physical_modes(const linalg::SparsePair<Complex>& km, const Eigen::VectorXd& ritz, const Eigen::MatrixXcd& Z,
                    Eigen::VectorXd& lambda, Eigen::MatrixXcd& phi) {
  const Eigen::Index n = km.K.rows();
  std::vector<Eigen::Index> order(ritz.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return ritz(a) < ritz(b); });
  const double scale = ritz.cwiseAbs().maxCoeff();
  std::vector<double> lam;
  std::vector<Eigen::VectorXcd> vecs;
  for (std::size_t g0 = 0; g0 < order.size();) {
    std::size_t g1 = g0 + 1;
    while (g1 < order.size() && std::abs(ritz(order[g1]) - ritz(order[g0])) <=
                                    kGroupRelTol * std::max(std::abs(ritz(order[g0])), 1e-12 * scale))
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
  lambda = Eigen::Map<const Eigen::VectorXd>(lam.data(), static_cast<Eigen::Index>(lam.size()));
  phi.resize(n, static_cast<Eigen::Index>(vecs.size()));
  for (std::size_t j = 0; j < vecs.size(); ++j) phi.col(static_cast<Eigen::Index>(j)) = vecs[j];
}

template <typename S>
ModalResult solve_spectra(const linalg::SparsePair<S>& km, int h, const ModalOptions& options, FactorReuse* reuse) {
  const Eigen::Index n = km.K.rows();
  const Eigen::Index real_n = kIsComplex<S> ? 2 * n : n;
  ModalReport report;
  report.method = kIsComplex<S> ? "spectra-complex-2n" : "spectra-real";
  const Eigen::Index nev = std::min<Eigen::Index>(kIsComplex<S> ? 2 * options.modes + 4 : options.modes, real_n - 1);
  Eigen::Index ncv = options.ncv > 0 ? options.ncv : std::max<Eigen::Index>(2 * nev + 1, nev + 20);
  ncv = std::min(std::max(ncv, nev + 1), real_n);
  report.requested_eigenvalues = static_cast<int>(nev);

  log::Stopwatch watch;
  const auto factor = factor_checked<S>(km, options, reuse, report);
  if (!factor) {
    ModalResult r;
    r.report = report;
    return r;
  }
  ShiftInvertOperator<S> op(*factor, km.M);
  Spectra::SymEigsSolver<ShiftInvertOperator<S>> solver(op, nev, ncv);
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
                     " eigenvalues converged after " + std::to_string(report.iterations) + " restarts (CompInfo " +
                     std::to_string(report.spectra_info) + ")";
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
      else yc = Y.col(j);
      factor->solve_backward(yc.data(), xc.data());
      Xs.col(j) = xc / std::sqrt(nu(j));
    }
  }
  report.solve_seconds = watch.seconds();

  ModalResult result;
  if constexpr (!kIsComplex<S>) {
    result = finish<S>(km, h, ritz, Xs, options, report);
  } else {
    Eigen::VectorXd lambda;
    Eigen::MatrixXcd phi;
    physical_modes(km, ritz, Xs, lambda, phi);
    result = finish<S>(km, h, lambda, phi, options, report);
  }
  if (result.report.ok() && options.shift == 0.0 && !reuse) result.stiffness = make_stiffness_factor<S>(factor);
  return result;
}

template <typename S>
ModalResult solve_block(const linalg::SparsePair<S>& km, int h, const ModalOptions& options, FactorReuse* reuse) {
  const Eigen::Index n = km.K.rows();
  ModalReport report;
  report.method = kIsComplex<S> ? "block-complex" : "block-real";
  const BlockKrylovSchurOptions sizes = block_krylov_schur_sizes(n, options.modes, options.block_size, options.ncv,
                                                                 options.max_restarts, options.tolerance);
  const Eigen::Index nev = sizes.nev;
  report.requested_eigenvalues = static_cast<int>(nev);

  const auto factor = factor_checked<S>(km, options, reuse, report);
  if (!factor) {
    ModalResult r;
    r.report = report;
    return r;
  }
  log::Stopwatch watch;
  const ShiftInvertOperator<S> op(*factor, km.M);
  const BlockKrylovSchurResult<S> ks =
      block_krylov_schur<S>([&](const MatrixS<S>& X) { return op.apply(X); }, n, sizes);
  report.iterations = ks.steps;
  report.operations = static_cast<int>(op.products());
  report.mass_products = static_cast<int>(op.products());
  report.converged_eigenvalues = ks.converged_values;
  if (!ks.converged) {
    report.solve_seconds = watch.seconds();
    report.status = ModalStatus::NotConverged;
    report.message = "block Krylov-Schur (shift-invert, block " + std::to_string(sizes.block) + ", basis " +
                     std::to_string(sizes.basis) + "): " + std::to_string(report.converged_eigenvalues) + " of " +
                     std::to_string(nev) + " eigenvalues converged after " + std::to_string(report.iterations) +
                     " steps, " + std::to_string(ks.restarts) + " restarts";
    ModalResult r;
    r.report = report;
    return r;
  }
  // nu = 1 / (lambda - sigma); x = P^T L^{-H} V y / sqrt(nu) is mass-normalised.
  const Eigen::VectorXd nu = ks.theta;
  MatrixS<S> X = factor->solve_backward(ks.vectors);
  for (Eigen::Index j = 0; j < nev; ++j) X.col(j) /= std::sqrt(nu(j));
  const Eigen::VectorXd lambda = (1.0 / nu.array() + options.shift).matrix();
  report.solve_seconds = watch.seconds();
  ModalResult result = finish<S>(km, h, lambda, X, options, report);
  if (result.report.ok() && options.shift == 0.0 && !reuse) result.stiffness = make_stiffness_factor<S>(factor);
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

ModalResult solve_modes(const linalg::SparsePair<double>& km, int h, const ModalOptions& options, FactorReuse& reuse) {
  return solve_any<double>(km, h, options, &reuse);
}

ModalResult solve_modes(const linalg::SparsePair<Complex>& km, int h, const ModalOptions& options, FactorReuse& reuse) {
  return solve_any<Complex>(km, h, options, &reuse);
}

}  // namespace shroudsim::modal
