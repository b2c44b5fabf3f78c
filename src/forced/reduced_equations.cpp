#include "forced/reduced_equations.hpp"

#include <Eigen/LU>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/log.hpp"
#include "linalg/gmres.hpp"

namespace shroudsim::forced {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Largest Jacobian (entries) kept as a copy for repeated evaluations (64 MB).
constexpr double kCopyLimit = 8.0e6;

/// max over theta of |Re sum_n U_n exp(i n theta)|: sampled on `samples` points, then the
/// best sample refined by golden-section search (the sampled maximum alone is low by up to
/// 1 - cos(pi / samples)).
double peak_norm(const std::vector<Eigen::VectorXcd>& u, int samples) {
  auto norm_at = [&](double theta) {
    Eigen::VectorXd ut = u[0].real();
    for (std::size_t n = 1; n < u.size(); ++n)
      ut += (u[n] * std::exp(std::complex<double>(0.0, static_cast<double>(n) * theta))).real();
    return ut.norm();
  };
  double best = -1.0, best_theta = 0.0;
  for (int l = 0; l < samples; ++l) {
    const double theta = kTwoPi * l / samples, v = norm_at(theta);
    if (v > best) best = v, best_theta = theta;
  }
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = best_theta - kTwoPi / samples, b = best_theta + kTwoPi / samples;
  double c = b - golden * (b - a), d = a + golden * (b - a), fc = norm_at(c), fd = norm_at(d);
  for (int it = 0; it < 60; ++it) {
    if (fc > fd) {
      b = d, d = c, fd = fc, c = b - golden * (b - a), fc = norm_at(c);
    } else {
      a = c, c = d, fc = fd, d = a + golden * (b - a), fd = norm_at(d);
    }
  }
  return std::max({best, fc, fd});
}
}  // namespace

ReducedEquations::ReducedEquations(const frf::LinearPart& linear, hbm::ContactEvaluator& contacts)
    : linear_(linear), contacts_(contacts), n_directions_(contacts.pair_layout().n_directions()) {
  SHROUDSIM_CHECK(linear.n_contact() == 3 * contacts.n_pairs(), "one linear contact triple per contact pair");
}

int ReducedEquations::index(int pair, int direction, int harmonic, bool sine) const {
  return pair * contacts_.pair_layout().size() +
         contacts_.pair_layout().index(direction, harmonic,
                                       sine ? hbm::HarmonicLayout::Part::sine : hbm::HarmonicLayout::Part::cosine);
}

Eigen::VectorXcd ReducedEquations::complex_harmonic(const Eigen::VectorXd& v, int n) const {
  Eigen::VectorXcd z = Eigen::VectorXcd::Zero(linear_.n_contact());
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    for (int d = 0; d < n_directions_; ++d)
      z[3 * p + d] = n == 0 ? std::complex<double>(v[index(p, d, 0, false)], 0.0)
                            : std::complex<double>(v[index(p, d, n, false)], -v[index(p, d, n, true)]);
  return z;
}

void ReducedEquations::assemble(double frequency_hz, Eigen::MatrixXd& g, Eigen::VectorXd* w_lin,
                                std::vector<frf::HarmonicReceptance>* receptances) const {
  const int size = contacts_.size(), pairs = contacts_.n_pairs(), h = contacts_.pair_layout().n_harmonics();
  const double w = kTwoPi * frequency_hz;
  g.setZero(size, size);
  if (w_lin) w_lin->setZero(size);
  if (receptances) receptances->resize(h + 1);
  frf::HarmonicReceptance rec;
  for (int n = 0; n <= h; ++n) {
    linear_.harmonic(n, w, rec);
    for (int p = 0; p < pairs; ++p)
      for (int d = 0; d < n_directions_; ++d) {
        const int ci = 3 * p + d;
        if (w_lin) {
          if (n == 0) {
            (*w_lin)[index(p, d, 0, false)] = rec.w_lin[ci].real();
          } else {
            (*w_lin)[index(p, d, n, false)] = rec.w_lin[ci].real();
            (*w_lin)[index(p, d, n, true)] = -rec.w_lin[ci].imag();
          }
        }
        for (int q = 0; q < pairs; ++q)
          for (int e = 0; e < n_directions_; ++e) {
            const std::complex<double> gij = rec.G(ci, 3 * q + e);
            if (n == 0) {
              g(index(p, d, 0, false), index(q, e, 0, false)) = gij.real();
            } else {
              const int ic = index(p, d, n, false), is = index(p, d, n, true);
              const int jc = index(q, e, n, false), js = index(q, e, n, true);
              g(ic, jc) = gij.real();
              g(ic, js) = gij.imag();
              g(is, jc) = -gij.imag();
              g(is, js) = gij.real();
            }
          }
      }
    if (receptances) (*receptances)[n] = rec;
  }
}

void ReducedEquations::add_harmonic(const Eigen::VectorXcd& z, int n, Eigen::VectorXd& out) const {
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    for (int d = 0; d < n_directions_; ++d) {
      const std::complex<double> v = z[3 * p + d];
      out[index(p, d, n, false)] += v.real();
      if (n > 0) out[index(p, d, n, true)] -= v.imag();
    }
}

const ReducedEquations::Harmonics& ReducedEquations::harmonics(double frequency_hz, bool derivative) {
  if (harmonics_.frequency_hz == frequency_hz && (!derivative || harmonics_.derivative)) return harmonics_;
  log::Stopwatch clock;
  const int h = contacts_.pair_layout().n_harmonics();
  const double w = kTwoPi * frequency_hz;
  // The factored form when the linear part has one (the modal sector): G_n is then never
  // formed per frequency, only where a dense Jacobian is factorized.
  frf::FactoredReceptance probe;
  const bool factored = linear_.factored_harmonic(0, w, false, probe);
  if (factored) {
    const bool fresh = harmonics_.frequency_hz != frequency_hz;
    Harmonics& hs = harmonics_;
    hs.g.factored = hs.dg.factored = true;
    hs.g.dense.clear();
    hs.dg.dense.clear();
    hs.g.factors.resize(h + 1);
    hs.dg.factors.resize(h + 1);
    hs.w_lin.resize(h + 1);
    hs.dw_lin.resize(h + 1);
    for (int n = 0; n <= h; ++n) {
      frf::FactoredReceptance& f = hs.g.factors[n];
      linear_.factored_harmonic(n, w, derivative, f);
      hs.w_lin[n] = f.w_lin;
      if (derivative) {
        frf::FactoredReceptance& df = hs.dg.factors[n];
        df.flex = nullptr;  // the massless part does not depend on the frequency
        df.psi = f.psi;
        df.s = f.ds;
        hs.dw_lin[n] = f.dw_lin;
      }
    }
    if (fresh) {
      hs.g_dense.clear();
      hs.w_static = times(hs.g, 0, static_contact_load());
    }
    hs.frequency_hz = frequency_hz;
    hs.derivative = derivative;
    stats_.receptance_seconds += clock.seconds();
    return harmonics_;
  }
  if (harmonics_.frequency_hz != frequency_hz) {
    harmonics_.g.factored = harmonics_.dg.factored = false;
    harmonics_.g.dense.resize(h + 1);
    harmonics_.w_lin.resize(h + 1);
    frf::HarmonicReceptance rec;
    for (int n = 0; n <= h; ++n) {
      linear_.harmonic(n, w, rec);
      harmonics_.g.dense[n] = std::move(rec.G);
      harmonics_.w_lin[n] = std::move(rec.w_lin);
    }
    harmonics_.g_dense.clear();
    harmonics_.w_static = harmonics_.g.dense[0] * static_contact_load();
    harmonics_.frequency_hz = frequency_hz;
    harmonics_.derivative = false;
  }
  if (derivative) {
    harmonics_.dg.dense.resize(h + 1);
    harmonics_.dw_lin.resize(h + 1);
    for (int n = 0; n <= h; ++n) linear_.harmonic_derivative(n, w, harmonics_.dg.dense[n], harmonics_.dw_lin[n]);
    harmonics_.derivative = true;
  }
  stats_.receptance_seconds += clock.seconds();
  return harmonics_;
}

const std::vector<Eigen::MatrixXcd>& ReducedEquations::dense_receptances(double frequency_hz) {
  const Harmonics& hs = harmonics(frequency_hz, false);
  if (!hs.g.factored) return hs.g.dense;
  if (harmonics_.g_dense.empty()) {
    log::Stopwatch clock;
    harmonics_.g_dense = dense(hs.g);
    stats_.receptance_seconds += clock.seconds();
  }
  return harmonics_.g_dense;
}

std::vector<Eigen::MatrixXcd> ReducedEquations::dense(const HarmonicMatrices& m) const {
  if (!m.factored) return m.dense;
  const int c = linear_.n_contact();
  std::vector<Eigen::MatrixXcd> out(m.factors.size());
  for (std::size_t n = 0; n < m.factors.size(); ++n) {
    const frf::FactoredReceptance& f = m.factors[n];
    if (f.flex) out[n] = f.flex->topLeftCorner(c, c).selfadjointView<Eigen::Lower>();
    else out[n] = Eigen::MatrixXcd::Zero(c, c);
    if (f.psi && f.s.size() > 0) {
      const auto psi = f.psi->topRows(c);
      out[n].noalias() += psi * f.s.asDiagonal() * psi.adjoint();
    }
  }
  return out;
}

Eigen::VectorXcd ReducedEquations::times(const HarmonicMatrices& m, int n, const Eigen::VectorXcd& z) const {
  if (!m.factored) return m.dense[static_cast<std::size_t>(n)] * z;
  const int c = linear_.n_contact();
  const frf::FactoredReceptance& f = m.factors[static_cast<std::size_t>(n)];
  Eigen::VectorXcd y = Eigen::VectorXcd::Zero(c);
  // F is Hermitian: its lower triangle is half the memory traffic of the full product (the
  // products with F are a good part of a GMRES iteration on many pairs).
  if (f.flex) y.noalias() = f.flex->topLeftCorner(c, c).selfadjointView<Eigen::Lower>() * z;
  if (f.psi && f.s.size() > 0) {
    const auto psi = f.psi->topRows(c);
    const Eigen::VectorXcd modal = f.s.cwiseProduct(psi.adjoint() * z);
    y.noalias() += psi * modal;
  }
  return y;
}

void ReducedEquations::apply(const HarmonicMatrices& m, const Eigen::VectorXd& v, Eigen::VectorXd& out) const {
  out.setZero(size());
  const std::size_t count = m.factored ? m.factors.size() : m.dense.size();
  for (std::size_t n = 0; n < count; ++n)
    add_harmonic(times(m, static_cast<int>(n), complex_harmonic(v, static_cast<int>(n))), static_cast<int>(n), out);
}

void ReducedEquations::jacobian(double frequency_hz, const std::vector<Eigen::MatrixXd>& blocks, Eigen::MatrixXd& J) {
  jacobian_from(dense_receptances(frequency_hz), blocks, J);
}

void ReducedEquations::jacobian_from(const std::vector<Eigen::MatrixXcd>& g_n,
                                     const std::vector<Eigen::MatrixXd>& blocks, Eigen::MatrixXd& J) {
  log::Stopwatch clock;
  const auto& layout = contacts_.pair_layout();
  const int h = layout.n_harmonics(), pairs = contacts_.n_pairs(), block = layout.size(), nd = n_directions_;
  J.setIdentity(size(), size());
  Eigen::MatrixXd gr, dsub, prod;
  std::vector<int> rows;
  for (int n = 0; n <= h; ++n) {
    const int parts = n == 0 ? 1 : 2, per_pair = nd * parts, m = pairs * per_pair;
    // Real form of G_n in the harmonic-local order (pair, direction, part) and the global
    // row of each local index.
    gr.resize(m, m);
    rows.resize(static_cast<std::size_t>(m));
    const Eigen::MatrixXcd& g = g_n[static_cast<std::size_t>(n)];
    for (int q = 0; q < pairs; ++q)
      for (int e = 0; e < nd; ++e) {
        const int lq = (q * nd + e) * parts;
        rows[static_cast<std::size_t>(lq)] = index(q, e, n, false);
        if (n > 0) rows[static_cast<std::size_t>(lq + 1)] = index(q, e, n, true);
        for (int p = 0; p < pairs; ++p)
          for (int d = 0; d < nd; ++d) {
            const int lp = (p * nd + d) * parts;
            const std::complex<double> gij = g(3 * p + d, 3 * q + e);
            if (n == 0) {
              gr(lp, lq) = gij.real();
            } else {
              gr(lp, lq) = gij.real();
              gr(lp, lq + 1) = gij.imag();
              gr(lp + 1, lq) = -gij.imag();
              gr(lp + 1, lq + 1) = gij.real();
            }
          }
      }
    dsub.resize(per_pair, block);
    for (int q = 0; q < pairs; ++q) {
      const Eigen::MatrixXd& dq = blocks[static_cast<std::size_t>(q)];
      // Rows of harmonic n of D_q, in the local order (direction, part).
      for (int e = 0; e < nd; ++e) {
        dsub.row(e * parts) = dq.row(layout.index(e, n, hbm::HarmonicLayout::Part::cosine));
        if (n > 0) dsub.row(e * parts + 1) = dq.row(layout.index(e, n, hbm::HarmonicLayout::Part::sine));
      }
      prod.noalias() = gr.middleCols(q * per_pair, per_pair) * dsub;
      for (int col = 0; col < block; ++col) {
        double* jc = J.col(q * block + col).data();
        const double* pc = prod.col(col).data();
        for (int l = 0; l < m; ++l) jc[rows[static_cast<std::size_t>(l)]] += pc[l];
      }
    }
  }
  stats_.jacobian_seconds += clock.seconds();
}

Eigen::MatrixXd ReducedEquations::dense_jacobian(double frequency_hz,
                                                 const std::vector<Eigen::MatrixXd>& blocks) const {
  Eigen::MatrixXd g;
  assemble(frequency_hz, g, nullptr);
  const int block = contacts_.pair_layout().size();
  Eigen::MatrixXd J = Eigen::MatrixXd::Identity(size(), size());
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    J.middleCols(p * block, block).noalias() += g.middleCols(p * block, block) * blocks[static_cast<std::size_t>(p)];
  return J;
}

bool ReducedEquations::evaluate(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                                Eigen::VectorXd* dr_dlambda) {
  return evaluate_impl(w, frequency_hz, r, J, dr_dlambda, false);
}

std::vector<Eigen::MatrixXd> ReducedEquations::contact_jacobian(const Eigen::VectorXd& w) {
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> blocks;
  contacts_.evaluate(w, f, &blocks);
  for (const auto& b : blocks)
    if (!b.allFinite()) throw NumericalError("the contact Jacobian is not finite");
  return blocks;
}

bool ReducedEquations::matrix_free() const {
  return solver_.kind == LinearSolverOptions::Kind::krylov ||
         (solver_.kind == LinearSolverOptions::Kind::automatic && size() + 1 >= solver_.krylov_min_size);
}

bool ReducedEquations::linearize(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r,
                                 Eigen::VectorXd* dr_dlambda) {
  return evaluate_impl(w, frequency_hz, r, nullptr, dr_dlambda, true);
}

bool ReducedEquations::evaluate_impl(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r,
                                     Eigen::MatrixXd* J, Eigen::VectorXd* dr_dlambda, bool linearize) {
  if (!w.allFinite() || !std::isfinite(frequency_hz) || frequency_hz <= 0) return false;
  // The continuation evaluates its converged point once more for the tangent: a repeat.
  // (A linearization is repeated only if the last evaluation linearized: its factors are
  // then still those of this point.)
  if (previous_.valid && previous_.frequency_hz == frequency_hz && previous_.scale == excitation_scale_ &&
      (!J || previous_.has_jacobian) && (!linearize || previous_.linearized) &&
      (!dr_dlambda || previous_.has_derivative) && previous_.w.size() == w.size() && previous_.w == w) {
    ++stats_.repeated_evaluations;
    r = previous_.r;
    if (J) *J = previous_.J;
    if (dr_dlambda) *dr_dlambda = previous_.dl;
    return true;
  }
  previous_.valid = false;
  const Harmonics& hs = harmonics(frequency_hz, dr_dlambda != nullptr);
  {
    log::Stopwatch clock;
    contacts_.evaluate(w, f_, J || linearize ? &blocks_ : nullptr);
    stats_.contact_seconds += clock.seconds();
  }
  ++stats_.evaluations;
  if (J || linearize) ++stats_.jacobian_evaluations;
  Eigen::VectorXd gf;
  apply(hs.g, f_, gf);
  r = w + gf;
  for (int n = 0; n <= contacts_.pair_layout().n_harmonics(); ++n)
    add_harmonic(-excitation_scale_ * hs.w_lin[static_cast<std::size_t>(n)], n, r);
  // r_0 = W_0 + G_0 (F_0 - F_s) about a static state (G_0 does not depend on the frequency).
  add_harmonic(-hs.w_static, 0, r);
  if (dr_dlambda) {
    apply(hs.dg, f_, *dr_dlambda);
    for (int n = 0; n <= contacts_.pair_layout().n_harmonics(); ++n)
      add_harmonic(-excitation_scale_ * hs.dw_lin[static_cast<std::size_t>(n)], n, *dr_dlambda);
    *dr_dlambda *= kTwoPi;  // d/df = 2 pi d/dw
  }
  if (J) jacobian_from(dense_receptances(frequency_hz), blocks_, *J);
  if (linearize) {  // the factors solve_bordered() multiplies with
    jac_g_ = hs.g;
    jac_blocks_ = blocks_;
    jac_valid_ = true;
  }
  bool ok = r.allFinite() && (!J || J->allFinite()) && (!dr_dlambda || dr_dlambda->allFinite());
  if (linearize)
    for (const auto& b : blocks_) ok = ok && b.allFinite();
  if (ok && (!J || static_cast<double>(J->size()) <= kCopyLimit)) {
    previous_.valid = true;
    previous_.has_jacobian = J != nullptr;
    previous_.linearized = linearize;
    previous_.has_derivative = dr_dlambda != nullptr;
    previous_.frequency_hz = frequency_hz;
    previous_.scale = excitation_scale_;
    previous_.w = w;
    previous_.r = r;
    if (J) previous_.J = *J;
    if (dr_dlambda) previous_.dl = *dr_dlambda;
  }
  return ok;
}

void ReducedEquations::apply_jacobian(const Eigen::VectorXd& z, Eigen::VectorXd& y) const {
  const int block = contacts_.pair_layout().size();
  Eigen::VectorXd dz(size());
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    dz.segment(p * block, block).noalias() = jac_blocks_[static_cast<std::size_t>(p)] * z.segment(p * block, block);
  apply(jac_g_, dz, y);
  y += z.head(size());
}

bool ReducedEquations::solve_augmented(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) {
  // Only below krylov_min_size unknowns (or with the dense solver): larger systems are
  // matrix-free and go through solve_bordered().
  log::Stopwatch clock;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  ++stats_.dense_factorizations;
  d = lu.solve(b);
  stats_.solve_seconds += clock.seconds();
  return d.allFinite();
}

bool ReducedEquations::solve_bordered(const continuation::BorderedMatrix& A, const Eigen::VectorXd& b,
                                      Eigen::VectorXd& d) {
  SHROUDSIM_CHECK(jac_valid_, "ReducedEquations::solve_bordered before a linearization");
  log::Stopwatch clock;
  const int n = size();
  // y = A z with the factors of the linearization: (I + G D) per pair and harmonic.
  Eigen::VectorXd xz(n), jz;
  auto op = [&](const Eigen::VectorXd& z, Eigen::VectorXd& y) {
    xz = z.head(n).cwiseProduct(A.x_scale);
    apply_jacobian(xz, jz);
    y.resize(n + 1);
    y.head(n) = jz.cwiseQuotient(A.r_scale) + A.column * z[n];
    y[n] = A.row.dot(z);
  };
  // The lagged preconditioner, single precision (linalg/lagged_lu.hpp).
  auto precondition = [&](const Eigen::VectorXd& v, Eigen::VectorXd& z) { preconditioner_.apply(v, z); };
  const linalg::GmresOptions gmres_options{solver_.krylov_max_iterations, solver_.krylov_tolerance};
  bool ok = false;
  if (preconditioner_.usable(n + 1)) {
    const linalg::GmresResult g = linalg::gmres(op, precondition, b, d, gmres_options);
    ok = g.converged;
    preconditioner_.add_iterations(g.iterations);
    stats_.krylov_iterations += g.iterations;
    if (ok) {
      ++stats_.krylov_solves;
      // Renew the factors when the lagged ones have become poor (the rule of lagged_lu.hpp).
      preconditioner_.decide_renewal(g.iterations, solver_.refactor_after);
    } else {
      ++stats_.krylov_failures;
    }
  }
  if (!ok) {
    // New preconditioner: the dense bordered matrix at this linearization, factorized.
    Eigen::MatrixXd J;
    jacobian_from(dense(jac_g_), jac_blocks_, J);
    Eigen::MatrixXd Ad(n + 1, n + 1);
    Ad.topLeftCorner(n, n).noalias() = A.r_scale.cwiseInverse().asDiagonal() * J * A.x_scale.asDiagonal();
    Ad.col(n).head(n) = A.column;
    Ad.row(n) = A.row.transpose();
    preconditioner_.factorize(Ad);
    ++stats_.dense_factorizations;
    // With the factors of this very matrix GMRES needs a few iterations (single precision
    // against double); if even that fails (A too ill-conditioned for single precision, or a
    // pivot exactly zero in it), a direct solve in double answers.
    if (preconditioner_.nonsingular()) {
      const linalg::GmresResult g = linalg::gmres(op, precondition, b, d, gmres_options);
      ok = g.converged;
      stats_.krylov_iterations += g.iterations;
    }
    if (ok) {
      ++stats_.krylov_solves;
    } else {
      ++stats_.krylov_failures;
      ++stats_.double_solves;
      const Eigen::PartialPivLU<Eigen::MatrixXd> lu(Ad);
      d = lu.solve(b);
      ok = d.allFinite();
    }
  }
  stats_.solve_seconds += clock.seconds();
  return ok;
}

Eigen::VectorXd ReducedEquations::linear_motion(double frequency_hz) const {
  const int h = contacts_.pair_layout().n_harmonics();
  Eigen::VectorXd w_lin = Eigen::VectorXd::Zero(size());
  frf::HarmonicReceptance rec;
  frf::FactoredReceptance factored;
  for (int n = 0; n <= h; ++n) {
    if (linear_.factored_harmonic(n, kTwoPi * frequency_hz, false, factored)) {  // without forming G_n
      add_harmonic(factored.w_lin, n, w_lin);
      continue;
    }
    linear_.harmonic(n, kTwoPi * frequency_hz, rec);
    add_harmonic(rec.w_lin, n, w_lin);
  }
  return w_lin;
}

Eigen::VectorXcd ReducedEquations::static_contact_load() const { return contacts_.static_load(); }

Eigen::VectorXd ReducedEquations::stuck_solution(double frequency_hz) const {
  // Stuck, closed contacts: F = Kc W + F_pre (F_pre: the preload in the static normal term).
  // Kc is diagonal and the same in every harmonic, so each harmonic is one complex c x c
  // solve: (I + G_n Kc) W_n = s W_lin,n - G_n (F_pre,n - F_s,n), F_s the static state's load
  // (static_contact_load(): about a static state that carries the preload, W_0 = 0).
  const int h = contacts_.pair_layout().n_harmonics(), c = linear_.n_contact();
  Eigen::VectorXd kc = Eigen::VectorXd::Zero(c);
  Eigen::VectorXcd f_pre = Eigen::VectorXcd::Zero(c);
  for (int p = 0; p < contacts_.n_pairs(); ++p) {
    const auto& pp = contacts_.pairs()[static_cast<std::size_t>(p)];
    for (int d = 0; d < n_directions_; ++d) {
      const bool normal = n_directions_ == 3 && d == 2;
      kc[3 * p + d] = normal ? pp.normal_stiffness : pp.tangential_stiffness;
    }
    if (n_directions_ == 3) f_pre[3 * p + 2] = std::max(0.0, pp.normal_preload);
  }
  Eigen::VectorXd w = Eigen::VectorXd::Zero(size());
  frf::HarmonicReceptance rec;
  for (int n = 0; n <= h; ++n) {
    linear_.harmonic(n, kTwoPi * frequency_hz, rec);
    Eigen::MatrixXcd a = rec.G * kc.asDiagonal();
    a.diagonal().array() += 1.0;
    Eigen::VectorXcd rhs = excitation_scale_ * rec.w_lin;
    if (n == 0) rhs -= rec.G * (f_pre - static_contact_load());
    add_harmonic(Eigen::PartialPivLU<Eigen::MatrixXcd>(a).solve(rhs), n, w);
  }
  return w;
}

PointResult ReducedEquations::analyse(const Eigen::VectorXd& w, double frequency_hz, int time_points) {
  PointResult res;
  res.frequency_hz = frequency_hz;
  const int h = contacts_.pair_layout().n_harmonics();
  const hbm::EvaluationStatus status = contacts_.evaluate(w, f_, nullptr);
  res.unconverged_pairs = status.unconverged_pairs;
  const double omega = kTwoPi * frequency_hz;
  // The response rows only (the contact block G_n is not needed here).
  std::vector<Eigen::MatrixXcd> resp(h + 1);
  std::vector<Eigen::VectorXcd> u_lin(h + 1);
  for (int n = 0; n <= h; ++n) linear_.response_harmonic(n, omega, resp[n], u_lin[n]);
  std::vector<Eigen::VectorXcd> u(h + 1), forces(h + 1);
  res.harmonic_amplitudes.resize(h + 1);
  const Eigen::VectorXcd f_static = static_contact_load();
  for (int n = 0; n <= h; ++n) {
    forces[n] = complex_harmonic(f_, n);
    // The response about the static state (its own load F_s excluded from the static part).
    u[n] = u_lin[n] - resp[n] * (n == 0 ? Eigen::VectorXcd(forces[n] - f_static) : forces[n]);
    res.harmonic_amplitudes[n] = u[n].norm();
  }
  // max over one period of |u(t)|, u(t) = Re sum_n U_n exp(i n theta).
  res.amplitude = peak_norm(u, time_points);
  if (h >= 1) {  // free response: harmonic 1 only, no contact forces
    std::vector<Eigen::VectorXcd> free = {Eigen::VectorXcd::Zero(u_lin[1].size()), u_lin[1]};
    res.linear_amplitude = peak_norm(free, time_points);
  }
  linear_.energy(omega, forces, res.excitation_work, res.viscous_dissipation);
  const int block = contacts_.pair_layout().size();
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    res.contact_dissipation +=
        hbm::dissipated_energy(contacts_.pair_layout(), w.segment(p * block, block), f_.segment(p * block, block));
  const double scale =
      std::max({std::abs(res.excitation_work), res.viscous_dissipation, std::abs(res.contact_dissipation)});
  res.energy_error =
      scale > 0 ? std::abs(res.excitation_work - res.viscous_dissipation - res.contact_dissipation) / scale : 0.0;
  return res;
}

std::vector<Eigen::VectorXcd> ReducedEquations::contact_force_harmonics(const Eigen::VectorXd& w) {
  contacts_.evaluate(w, f_, nullptr);
  const int h = contacts_.pair_layout().n_harmonics();
  std::vector<Eigen::VectorXcd> forces(h + 1);
  for (int n = 0; n <= h; ++n) forces[n] = complex_harmonic(f_, n);
  forces[0] -= static_contact_load();
  return forces;
}

}  // namespace shroudsim::forced
