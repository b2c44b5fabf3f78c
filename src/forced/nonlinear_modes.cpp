#include "forced/nonlinear_modes.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Samples per period for the response's peak max_t |u(t)|: low by at most
/// 1 - cos(pi / 512) = 1.9e-5 (relative) for a smooth motion.
constexpr int kPeakSamples = 512;
/// A linear mode whose largest contact motion is below this fraction of its largest DOF
/// motion does not load the contacts: the reduced form cannot carry it.
constexpr double kInvisibleMode = 1e-9;
/// Step growth after a corrector of at most kEasyIterations iterations.
constexpr double kGrowth = 1.5;
constexpr int kEasyIterations = 5;
/// Newton also stops when its step (scaled unknowns, of order 1) falls below kStagnation
/// while the scaled residual is below kResidualFloor: near a pole of the receptance (the
/// free mode, approached at small amplitude with a cubic spring or in gross slip) r_W = W + G F
/// is the difference of two terms each cond = w^2 / |w^2 - w_pole^2| times W, and round-off
/// in w alone leaves ~1e-16 cond of residual (3e-10 measured on the Duffing start).
constexpr double kStagnation = 1e-13;
constexpr double kResidualFloor = 1e-6;
/// Relative distance the first frequency guess keeps from the linear mode's frequency when
/// the contacts carry no linear stiffness (there G has a pole): far above round-off, far
/// below any amplitude-dependent shift that Newton then finds.
constexpr double kPoleOffset = 1e-9;
}  // namespace

bool NonlinearModeSettings::validate(std::vector<std::string>* errors) const {
  const std::size_t before = errors->size();
  if (!(amplitude_start > 0) || !std::isfinite(amplitude_start))
    errors->push_back("nlmodes.amplitude_start violates: > 0");
  if (!(amplitude_end > amplitude_start) || !std::isfinite(amplitude_end))
    errors->push_back("nlmodes.amplitude_end violates: > nlmodes.amplitude_start");
  if (mode < 1) errors->push_back("nlmodes.mode violates: >= 1");
  if (max_points < 2) errors->push_back("nlmodes.max_points violates: >= 2");
  if (!(initial_step > 0) || !(max_step >= initial_step) || !(min_step > 0) || !(min_step <= initial_step))
    errors->push_back("nlmodes steps violate: 0 < min_step <= initial_step <= max_step");
  if (!(tolerance > 0)) errors->push_back("nlmodes tolerance violates: > 0");
  if (max_newton_iterations < 1) errors->push_back("nlmodes max_newton_iterations violates: >= 1");
  return errors->size() == before;
}

NonlinearModeEquations::NonlinearModeEquations(const frf::LinearPart& linear, hbm::NonlinearForce& force)
    : linear_(linear), force_(force) {
  SHROUDSIM_CHECK(linear.n_contact() == 3 * force.n_pairs(), "one linear contact triple per nonlinear pair");
  SHROUDSIM_CHECK(force.pair_layout().n_harmonics() >= 1, "nonlinear modes need the fundamental harmonic");
  phase_index_ = index(0, 0, 1, true);
}

int NonlinearModeEquations::index(int pair, int direction, int harmonic, bool sine) const {
  return pair * force_.pair_layout().size() +
         force_.pair_layout().index(direction, harmonic,
                                    sine ? hbm::HarmonicLayout::Part::sine : hbm::HarmonicLayout::Part::cosine);
}

Eigen::VectorXcd NonlinearModeEquations::complex_harmonic(const Eigen::VectorXd& v, int n) const {
  Eigen::VectorXcd z = Eigen::VectorXcd::Zero(linear_.n_contact());
  const int nd = force_.pair_layout().n_directions();
  for (int p = 0; p < force_.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d)
      z[3 * p + d] = n == 0 ? std::complex<double>(v[index(p, d, 0, false)], 0.0)
                            : std::complex<double>(v[index(p, d, n, false)], -v[index(p, d, n, true)]);
  return z;
}

void NonlinearModeEquations::add_harmonic(const Eigen::VectorXcd& z, int n, Eigen::VectorXd& out) const {
  const int nd = force_.pair_layout().n_directions();
  for (int p = 0; p < force_.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d) {
      out[index(p, d, n, false)] += z[3 * p + d].real();
      if (n > 0) out[index(p, d, n, true)] -= z[3 * p + d].imag();
    }
}

void NonlinearModeEquations::receptances(double omega, double zeta) {
  if (omega == cached_omega_ && zeta == cached_zeta_) return;
  const int h = force_.pair_layout().n_harmonics();
  rec_.resize(static_cast<std::size_t>(h) + 1);
  for (int n = 0; n <= h; ++n)
    if (!linear_.damped_harmonic(n, omega, zeta, n == 1, rec_[static_cast<std::size_t>(n)]))
      throw NumericalError("the linear part has no damped receptance at w = " + std::to_string(omega) +
                           " rad/s, zeta = " + std::to_string(zeta) + " 1/s");
  cached_omega_ = omega;
  cached_zeta_ = zeta;
}

bool NonlinearModeEquations::evaluate(const Eigen::VectorXd& x, double amplitude, Eigen::VectorXd& r,
                                      Eigen::MatrixXd* J) {
  const int n = this->n(), h = force_.pair_layout().n_harmonics(), nd = force_.pair_layout().n_directions();
  const double omega = x[n], zeta = x[n + 1];
  if (!x.allFinite() || !(omega > 0)) return false;
  try {
    receptances(omega, zeta);
  } catch (const NumericalError&) {
    return false;
  }
  ++evaluations_;
  const Eigen::VectorXd w = x.head(n);
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> blocks;
  force_.evaluate(w, f, J ? &blocks : nullptr);
  const Eigen::VectorXcd f_static = force_.static_load();
  r.setZero(size());
  r.head(n) = w;
  Eigen::VectorXd dr_dw = Eigen::VectorXd::Zero(n), dr_dz = Eigen::VectorXd::Zero(n);
  std::vector<Eigen::VectorXcd> fn(static_cast<std::size_t>(h) + 1);
  for (int k = 0; k <= h; ++k) {
    const frf::DampedReceptance& rk = rec_[static_cast<std::size_t>(k)];
    fn[static_cast<std::size_t>(k)] = complex_harmonic(f, k);
    const Eigen::VectorXcd fk = k == 0 ? Eigen::VectorXcd(fn[0] - f_static) : fn[static_cast<std::size_t>(k)];
    Eigen::VectorXd rw = r.head(n);
    add_harmonic(rk.G * fk, k, rw);
    r.head(n) = rw;
    if (J && k > 0) {
      add_harmonic(rk.dG_dw * fk, k, dr_dw);
      add_harmonic(rk.dG_dzeta * fk, k, dr_dz);
    }
  }
  // Amplitude: sqrt(F_1^H N F_1) / a - 1.
  const frf::DampedReceptance& r1 = rec_[1];
  const Eigen::VectorXcd nf = r1.N * fn[1];
  const double q2 = std::max(fn[1].dot(nf).real(), 0.0), q = std::sqrt(q2);
  r[n] = q / amplitude - 1.0;
  r[n + 1] = w[phase_index_];
  if (J) {
    J->setZero(size(), size());
    // dr_W/dW = I + G_real blockdiag(dF_p/dW_p), G_real the real form of every harmonic.
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
    for (int k = 0; k <= h; ++k) {
      const Eigen::MatrixXcd& gk = rec_[static_cast<std::size_t>(k)].G;
      for (int p = 0; p < force_.n_pairs(); ++p)
        for (int d = 0; d < nd; ++d)
          for (int qp = 0; qp < force_.n_pairs(); ++qp)
            for (int e = 0; e < nd; ++e) {
              const std::complex<double> gij = gk(3 * p + d, 3 * qp + e);
              const int rc = index(p, d, k, false), cc = index(qp, e, k, false);
              g(rc, cc) = gij.real();
              if (k > 0) {
                const int rs = index(p, d, k, true), cs = index(qp, e, k, true);
                g(rc, cs) = gij.imag();
                g(rs, cc) = -gij.imag();
                g(rs, cs) = gij.real();
              }
            }
    }
    const int b = force_.pair_layout().size();
    Eigen::MatrixXd jw = Eigen::MatrixXd::Identity(n, n);
    for (int p = 0; p < force_.n_pairs(); ++p)
      jw.middleCols(p * b, b).noalias() += g.middleCols(p * b, b) * blocks[static_cast<std::size_t>(p)];
    J->topLeftCorner(n, n) = jw;
    J->col(n).head(n) = dr_dw;
    J->col(n + 1).head(n) = dr_dz;
    // d q2 / dF (real coefficients): 2 Re(N F)_k on the cosine, -2 Im(N F)_k on the sine.
    if (q > 0) {
      Eigen::VectorXd grad = Eigen::VectorXd::Zero(n);
      for (int p = 0; p < force_.n_pairs(); ++p)
        for (int d = 0; d < nd; ++d) {
          grad[index(p, d, 1, false)] = 2.0 * nf[3 * p + d].real();
          grad[index(p, d, 1, true)] = -2.0 * nf[3 * p + d].imag();
        }
      const double scale = 1.0 / (2.0 * q * amplitude);
      Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(n);
      for (int p = 0; p < force_.n_pairs(); ++p)
        row.segment(p * b, b) = grad.segment(p * b, b).transpose() * blocks[static_cast<std::size_t>(p)];
      J->row(n).head(n) = scale * row;
      (*J)(n, n) = scale * fn[1].dot(r1.dN_dw * fn[1]).real();
      (*J)(n, n + 1) = scale * fn[1].dot(r1.dN_dzeta * fn[1]).real();
    }
    (*J)(n + 1, phase_index_) = 1.0;
  }
  return r.allFinite() && (!J || J->allFinite());
}

NonlinearModePoint NonlinearModeEquations::analyse(const Eigen::VectorXd& x, double amplitude) {
  const int n = this->n(), h = force_.pair_layout().n_harmonics();
  NonlinearModePoint p;
  p.amplitude = amplitude;
  p.omega = x[n];
  p.frequency_hz = p.omega / kTwoPi;
  p.zeta = x[n + 1];
  p.damping_ratio = p.zeta / (2.0 * p.omega);
  p.w = x.head(n);
  receptances(p.omega, p.zeta);
  Eigen::VectorXd f;
  p.unconverged_pairs = force_.evaluate(p.w, f, nullptr).unconverged_pairs;
  const int b = force_.pair_layout().size();
  for (int q = 0; q < force_.n_pairs(); ++q)
    p.contact_dissipation += hbm::dissipated_energy(force_.pair_layout(), p.w.segment(q * b, b), f.segment(q * b, b));
  p.contact_damping_ratio = p.contact_dissipation / (kTwoPi * p.omega * p.omega * amplitude * amplitude);
  const Eigen::VectorXcd f_static = force_.static_load();
  std::vector<Eigen::VectorXcd> u(static_cast<std::size_t>(h) + 1);
  p.harmonic_amplitudes.resize(static_cast<std::size_t>(h) + 1);
  Eigen::VectorXcd f1;
  for (int k = 0; k <= h; ++k) {
    Eigen::VectorXcd fk = complex_harmonic(f, k);
    if (k == 0) fk -= f_static;
    if (k == 1) f1 = fk;
    u[static_cast<std::size_t>(k)] = -rec_[static_cast<std::size_t>(k)].H * fk;
    p.harmonic_amplitudes[static_cast<std::size_t>(k)] = u[static_cast<std::size_t>(k)].norm() / amplitude;
  }
  double peak = 0.0;
  for (int l = 0; l < kPeakSamples; ++l) {
    const double theta = kTwoPi * l / kPeakSamples;
    Eigen::VectorXd ut = u[0].real();
    for (int k = 1; k <= h; ++k)
      ut += (u[static_cast<std::size_t>(k)] * std::exp(std::complex<double>(0.0, k * theta))).real();
    peak = std::max(peak, ut.norm());
  }
  p.response_per_amplitude = peak / amplitude;
  // psi^H f = q_1^H f / a = -(X_1 F_1)^H f / a = -F_1^H e / a.
  p.modal_force = -f1.dot(rec_[1].e) / amplitude;
  return p;
}

LinearMode linear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force, int mode) {
  frf::SecondOrderForm so;
  if (!linear.second_order_form(1, so) || so.R.cwiseAbs().maxCoeff() > 0.0)
    throw InputError(
        "nonlinear modes: the model has no second-order form without a massless part "
        "(only lumped models are supported)");
  const int m = static_cast<int>(so.M.rows());
  if (mode < 1 || mode > m)
    throw InputError("nlmodes.mode = " + std::to_string(mode) + " violates: <= " + std::to_string(m) +
                     " (the model's DOFs)");
  // K_c: the force's first-harmonic stiffness at W = 0 (cosine row and column of harmonic 1
  // of every direction of each pair).
  const int c = linear.n_contact(), nd = force.pair_layout().n_directions();
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> blocks;
  force.evaluate(Eigen::VectorXd::Zero(force.n_unknowns()), f, &blocks);
  Eigen::MatrixXd kc = Eigen::MatrixXd::Zero(c, c);
  for (int p = 0; p < force.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d)
      for (int e = 0; e < nd; ++e)
        kc(3 * p + d, 3 * p + e) =
            blocks[static_cast<std::size_t>(p)](force.pair_layout().index(d, 1, hbm::HarmonicLayout::Part::cosine),
                                                force.pair_layout().index(e, 1, hbm::HarmonicLayout::Part::cosine));
  const Eigen::MatrixXd pr = so.P.real();
  Eigen::MatrixXd k_lin = so.K + pr.transpose() * kc * pr;
  k_lin = 0.5 * (k_lin + k_lin.transpose()).eval();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k_lin, so.M);
  if (eig.info() != Eigen::Success || eig.eigenvalues()[mode - 1] <= 0)
    throw NumericalError("nonlinear modes: the linear mode " + std::to_string(mode) + " has no positive frequency");
  LinearMode lm;
  lm.omega = std::sqrt(eig.eigenvalues()[mode - 1]);
  lm.phi = eig.eigenvectors().col(mode - 1);
  lm.phi /= std::sqrt(lm.phi.dot(so.M * lm.phi));
  lm.zeta = lm.phi.dot(so.C * lm.phi);
  lm.contact_stiffness = kc;
  return lm;
}

NonlinearModeCurve trace_nonlinear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force,
                                        const NonlinearModeSettings& settings) {
  std::vector<std::string> errors;
  if (!settings.validate(&errors)) throw InputError(errors.front());
  NonlinearModeCurve curve;
  curve.linear = linear_mode(linear, force, settings.mode);
  NonlinearModeEquations eq(linear, force);
  const int n = eq.n(), nd = force.pair_layout().n_directions();
  // Contact motion of the unit linear mode, the phase coefficient at its largest component.
  frf::SecondOrderForm so;
  linear.second_order_form(1, so);
  const Eigen::VectorXd bphi = (so.P * curve.linear.phi.cast<std::complex<double>>()).real();
  double c_w = 0.0;
  int j_pair = 0, j_dir = 0;
  for (int p = 0; p < force.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d)
      if (std::abs(bphi[3 * p + d]) > c_w) c_w = std::abs(bphi[3 * p + d]), j_pair = p, j_dir = d;
  if (c_w <= kInvisibleMode * curve.linear.phi.cwiseAbs().maxCoeff())
    throw InputError("nonlinear modes: linear mode " + std::to_string(settings.mode) +
                     " does not move the contacts; its nonlinear mode is the linear one");
  eq.set_phase_index(eq.index(j_pair, j_dir, 1, true));

  const double w0 = curve.linear.omega;
  // y = [W / a, w, zeta] as a function of lambda = log10 a: the predictor's variables.
  auto to_x = [&](const Eigen::VectorXd& y, double a) {
    Eigen::VectorXd x = y;
    x.head(n) *= a;
    return x;
  };
  auto to_y = [&](const Eigen::VectorXd& x, double a) {
    Eigen::VectorXd y = x;
    y.head(n) /= a;
    return y;
  };
  // Newton at amplitude a from x (in place), scaled by (a c_w, w0, w0).
  auto newton = [&](Eigen::VectorXd& x, double a, int& iterations) {
    Eigen::VectorXd s(n + 2), r;
    s.head(n).setConstant(a * c_w);
    s[n] = s[n + 1] = w0;
    Eigen::VectorXd rs(n + 2);
    rs.head(n).setConstant(a * c_w);
    rs[n] = 1.0;
    rs[n + 1] = a * c_w;
    Eigen::MatrixXd J;
    double last_step = std::numeric_limits<double>::infinity();
    for (iterations = 0; iterations <= settings.max_newton_iterations; ++iterations) {
      if (!eq.evaluate(x, a, r, &J)) return false;
      const Eigen::VectorXd r_scaled = r.cwiseQuotient(rs);
      const double norm = r_scaled.lpNorm<Eigen::Infinity>();
      if (norm <= settings.tolerance || (last_step <= kStagnation && norm <= kResidualFloor)) return true;
      if (iterations == settings.max_newton_iterations) break;
      const Eigen::MatrixXd js = rs.cwiseInverse().asDiagonal() * J * s.asDiagonal();
      const Eigen::PartialPivLU<Eigen::MatrixXd> lu(js);
      const Eigen::VectorXd dx = lu.solve(-r_scaled);
      if (!dx.allFinite()) return false;
      last_step = dx.lpNorm<Eigen::Infinity>();
      x += dx.cwiseProduct(s);
    }
    return false;
  };
  auto record = [&](const Eigen::VectorXd& x, double a, int iterations) {
    NonlinearModePoint p = eq.analyse(x, a);
    p.newton_iterations = iterations;
    curve.points.push_back(std::move(p));
  };

  const double lambda_end = std::log10(settings.amplitude_end);
  double lambda = std::log10(settings.amplitude_start);
  double a = settings.amplitude_start;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n + 2);
  for (int p = 0; p < force.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d) x[eq.index(p, d, 1, false)] = a * bphi[3 * p + d];
  // The frequency guess: the Rayleigh quotient of the first-harmonic balance projected on
  // phi, w^2 = phi^T K phi + phi^T B^H F_1(a B phi) / a, phi^T K phi = w0^2 - (B phi)^T K_c B phi.
  // Where K_c is zero (a cubic spring, an open contact) w0 itself is a pole of the receptance
  // (G is singular at the free mode): the guess moves off it by the force's own stiffening.
  {
    Eigen::VectorXd f;
    force.evaluate(x.head(n), f, nullptr);
    const Eigen::VectorXcd f1 = eq.complex_harmonic(f, 1);
    if (curve.linear.contact_stiffness.cwiseAbs().maxCoeff() == 0.0 && f1.cwiseAbs().maxCoeff() == 0.0)
      throw InputError("nlmodes.amplitude_start = " + std::to_string(a) +
                       ": the contacts carry no force at this amplitude of the linear mode (open): the reduced "
                       "equations have no solution there; start above the amplitude at which they close");
    const double w2 = w0 * w0 - bphi.dot(curve.linear.contact_stiffness * bphi) + bphi.dot(f1.real()) / a;
    x[n] = w2 > 0 ? std::sqrt(w2) : w0;
    if (std::abs(x[n] / w0 - 1) < kPoleOffset) x[n] = w0 * (1 + kPoleOffset);
  }
  x[n + 1] = curve.linear.zeta;
  int iterations = 0;
  if (!newton(x, a, iterations)) {
    curve.residual_evaluations = eq.evaluations();
    throw NumericalError("nonlinear modes: the first point (amplitude " + std::to_string(a) +
                         ") did not converge from the linear mode");
  }
  record(x, a, iterations);
  Eigen::VectorXd y = to_y(x, a), y_prev;
  double lambda_prev = lambda, step = settings.initial_step;
  bool have_prev = false;
  while (true) {
    if (lambda >= lambda_end - 1e-12) {
      curve.reached_end = true;
      curve.message = "reached amplitude_end";
      break;
    }
    if (static_cast<int>(curve.points.size()) >= settings.max_points) {
      curve.message = "max_points reached";
      break;
    }
    const double h = std::min(step, lambda_end - lambda), lambda_new = lambda + h, a_new = std::pow(10.0, lambda_new);
    Eigen::VectorXd y_pred = y;
    if (have_prev) y_pred += (h / (lambda - lambda_prev)) * (y - y_prev);
    Eigen::VectorXd x_new = to_x(y_pred, a_new);
    if (newton(x_new, a_new, iterations)) {
      y_prev = y;
      lambda_prev = lambda;
      have_prev = true;
      y = to_y(x_new, a_new);
      lambda = lambda_new;
      a = a_new;
      record(x_new, a, iterations);
      if (iterations <= kEasyIterations) step = std::min(step * kGrowth, settings.max_step);
    } else {
      ++curve.rejected_steps;
      step *= 0.5;
      if (step < settings.min_step) {
        std::ostringstream s;
        s << "step below min_step at amplitude " << a << ": the corrector fails beyond";
        curve.message = s.str();
        break;
      }
    }
  }
  curve.residual_evaluations = eq.evaluations();
  return curve;
}

}  // namespace shroudsim::forced
