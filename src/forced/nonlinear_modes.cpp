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
/// The static contact state: Newton on harmonic 0 to kStaticTolerance of the preload's
/// static displacement (piecewise-linear contact laws converge in a few iterations).
constexpr int kStaticIterations = 50;
constexpr double kStaticTolerance = 1e-13;
/// The probe of the contacts' linearization at the start, relative to the larger of the static
/// state's largest displacement and the force's rest_displacement(): far below any slip or
/// lift-off, far above round-off.
constexpr double kProbe = 1e-7;
/// The largest change of w, and of zeta (in units of w), per unit arclength step: the
/// continuation's frequency unit (a step moves w by at most this fraction), far below the
/// distance to another mode family.
constexpr double kMaxJump = 0.02;
/// The largest turn of the branch's direction per accepted step (scaled variables).
constexpr double kMaxTurnDeg = 45.0;
/// How far (decades) the branch may turn back below amplitude_start before it stops.
constexpr double kBelowStart = 1.0;
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

Eigen::VectorXd static_contact_state(const frf::LinearPart& linear, hbm::NonlinearForce& force) {
  const int n = force.n_unknowns(), c = linear.n_contact(), nd = force.pair_layout().n_directions();
  const hbm::HarmonicLayout& layout = force.pair_layout();
  const int b = layout.size();
  frf::DampedReceptance r0;
  if (!linear.damped_harmonic(0, 1.0, 0.0, false, r0))
    throw NumericalError("nonlinear modes: the linear part has no static flexibility");
  const Eigen::MatrixXd g0 = r0.G.real();
  const Eigen::VectorXd f_static = force.static_load().real();
  // z: harmonic 0 of W (c entries, 3 per pair, the unused directions zero).
  auto to_w = [&](const Eigen::VectorXd& z) {
    Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
    for (int p = 0; p < force.n_pairs(); ++p)
      for (int d = 0; d < nd; ++d) w[p * b + layout.index(d, 0, hbm::HarmonicLayout::Part::cosine)] = z[3 * p + d];
    return w;
  };
  Eigen::VectorXd z = Eigen::VectorXd::Zero(c), f;
  std::vector<Eigen::MatrixXd> blocks;
  double scale = 0.0;
  for (int it = 0; it < kStaticIterations; ++it) {
    force.evaluate(to_w(z), f, &blocks);
    Eigen::VectorXd f0 = Eigen::VectorXd::Zero(c);
    Eigen::MatrixXd df = Eigen::MatrixXd::Zero(c, c);
    for (int p = 0; p < force.n_pairs(); ++p)
      for (int d = 0; d < nd; ++d) {
        const int i = layout.index(d, 0, hbm::HarmonicLayout::Part::cosine);
        f0[3 * p + d] = f[p * b + i];
        for (int e = 0; e < nd; ++e)
          df(3 * p + d, 3 * p + e) =
              blocks[static_cast<std::size_t>(p)](i, layout.index(e, 0, hbm::HarmonicLayout::Part::cosine));
      }
    const Eigen::VectorXd load = g0 * (f0 - f_static);
    if (it == 0) scale = load.cwiseAbs().maxCoeff();
    if (scale == 0.0) return to_w(z);  // the static state is W = 0
    const Eigen::VectorXd r = z + load;
    if (r.cwiseAbs().maxCoeff() <= kStaticTolerance * std::max(scale, z.cwiseAbs().maxCoeff())) return to_w(z);
    const Eigen::MatrixXd j = Eigen::MatrixXd::Identity(c, c) + g0 * df;
    z -= j.partialPivLu().solve(r);
    if (!z.allFinite()) break;
  }
  throw NumericalError("nonlinear modes: the static contact state (harmonic 0 without vibration) did not converge");
}

LinearMode linear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force, int mode,
                       const Eigen::VectorXd& state) {
  using Complex = std::complex<double>;
  frf::SecondOrderForm so;
  if (!linear.second_order_form(1, so))
    throw InputError("nonlinear modes: the model has no second-order form (docs/physics.md section 10)");
  const int m = static_cast<int>(so.M.rows());
  if (mode < 1 || mode > m)
    throw InputError("nlmodes.mode = " + std::to_string(mode) + " violates: <= " + std::to_string(m) +
                     " (the model's DOFs or modes)");
  // K_c: the force's first-harmonic stiffness at W = 0 (cosine row and column of harmonic 1
  // of every direction of each pair).
  const int c = linear.n_contact(), nd = force.pair_layout().n_directions();
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> blocks;
  // The small vibration is taken through a probe of harmonic 1 in every direction, kProbe of
  // the state's size (of the pairs' slip and lift-off displacements at rest): the Jacobian at
  // a state without motion is that of a slipping contact (the sampled law's derivative where
  // a sample does not move), and about a static load at the friction limit it is the slipping
  // one where a small periodic motion, once the slider has settled, sticks.
  Eigen::VectorXd probe = state.size() == 0 ? Eigen::VectorXd(Eigen::VectorXd::Zero(force.n_unknowns())) : state;
  const double size = std::max(probe.cwiseAbs().maxCoeff(), force.rest_displacement());
  for (int p = 0; p < force.n_pairs(); ++p)
    for (int d = 0; d < force.pair_layout().n_directions(); ++d)
      probe[p * force.pair_layout().size() + force.pair_layout().index(d, 1, hbm::HarmonicLayout::Part::cosine)] +=
          kProbe * size;
  force.evaluate(probe, f, &blocks);
  Eigen::MatrixXd kc = Eigen::MatrixXd::Zero(c, c);
  for (int p = 0; p < force.n_pairs(); ++p)
    for (int d = 0; d < nd; ++d)
      for (int e = 0; e < nd; ++e)
        kc(3 * p + d, 3 * p + e) =
            blocks[static_cast<std::size_t>(p)](force.pair_layout().index(d, 1, hbm::HarmonicLayout::Part::cosine),
                                                force.pair_layout().index(e, 1, hbm::HarmonicLayout::Part::cosine));
  // The massless part condensed into the contact: W = P q - R F, F = K_c W give
  // W = S P q with S = (I + R K_c)^-1 and F = K_c S P q.
  const Eigen::MatrixXcd kcc = kc.cast<Complex>();
  Eigen::MatrixXcd s = Eigen::MatrixXcd::Identity(c, c);
  if (so.R.size() > 0 && so.R.cwiseAbs().maxCoeff() > 0.0)
    s = (Eigen::MatrixXcd::Identity(c, c) + so.R * kcc).partialPivLu().inverse();
  Eigen::MatrixXcd k_lin = so.K.cast<Complex>() + so.P.adjoint() * kcc * s * so.P;
  k_lin = 0.5 * (k_lin + k_lin.adjoint()).eval();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXcd> eig(k_lin, so.M.cast<Complex>());
  if (eig.info() != Eigen::Success || eig.eigenvalues()[mode - 1] <= 0)
    throw NumericalError("nonlinear modes: the linear mode " + std::to_string(mode) + " has no positive frequency");
  LinearMode lm;
  lm.omega = std::sqrt(eig.eigenvalues()[mode - 1]);
  lm.phi = eig.eigenvectors().col(mode - 1);
  lm.phi /= std::sqrt(lm.phi.dot(so.M.cast<Complex>() * lm.phi).real());
  lm.contact_motion = s * so.P * lm.phi;
  // The phase: the contact component that moves most is real and positive.
  Eigen::Index j = 0;
  lm.contact_motion.cwiseAbs().maxCoeff(&j);
  if (std::abs(lm.contact_motion[j]) > 0) {
    const Complex turn = std::abs(lm.contact_motion[j]) / lm.contact_motion[j];
    lm.phi *= turn;
    lm.contact_motion *= turn;
  }
  lm.zeta = lm.phi.dot(so.C.cast<Complex>() * lm.phi).real();
  lm.contact_stiffness = kc;
  return lm;
}

NonlinearModeCurve trace_nonlinear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force,
                                        const NonlinearModeSettings& settings) {
  std::vector<std::string> errors;
  if (!settings.validate(&errors)) throw InputError(errors.front());
  NonlinearModeCurve curve;
  const Eigen::VectorXd w_static = static_contact_state(linear, force);
  curve.linear = linear_mode(linear, force, settings.mode, w_static);
  NonlinearModeEquations eq(linear, force);
  const int n = eq.n(), nd = force.pair_layout().n_directions();
  // Contact motion of the unit linear mode, the phase coefficient at its largest component.
  const Eigen::VectorXcd& bphi = curve.linear.contact_motion;
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
  // y = [(W - W_s) / a, w, zeta] as a function of lambda = log10 a (W_s the static state).
  auto to_x = [&](const Eigen::VectorXd& y, double a) {
    Eigen::VectorXd x = y;
    x.head(n) = w_static + a * y.head(n);
    return x;
  };
  auto to_y = [&](const Eigen::VectorXd& x, double a) {
    Eigen::VectorXd y = x;
    y.head(n) = (x.head(n) - w_static) / a;
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
  Eigen::VectorXd x_start = w_static;
  eq.add_harmonic(a * bphi, 1, x_start);
  x.head(n) = x_start;
  // The frequency guess: the Rayleigh quotient of the first-harmonic balance projected on
  // phi, w^2 = phi^H K phi + (P phi)^H F_1(a W_phi) / a, phi^H K phi = w0^2 - (P phi)^H K_c W_phi
  // (W_phi the unit mode's contact motion; exact for a linear force).
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
    // With a massless part the projection is on P phi, the motion (I + R K_c)^-1 P phi.
    frf::SecondOrderForm so;
    linear.second_order_form(1, so);
    const Eigen::VectorXcd pphi = so.P * curve.linear.phi;
    const Eigen::VectorXcd kb = curve.linear.contact_stiffness.cast<std::complex<double>>() * bphi;
    const double w2 = w0 * w0 - pphi.dot(kb).real() + pphi.dot(f1).real() / a;
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

  // Pseudo-arclength in z = ((W - W_s) / a, w, zeta, lambda = log10 a), scaled by S = (c_w, kMaxJump w0,
  // kMaxJump w0, max_step): a unit step moves at most max_step decades in amplitude, kMaxJump
  // of the frequency (and of zeta in units of w0) and one unit mode's contact motion, so the
  // curve is resolved where it turns in amplitude (a contact that opens, a fold) as where it
  // moves along it. Predictor: the secant (the amplitude direction at the linear start);
  // corrector: Newton on the equations and t . (z - z_pred) = 0.
  const int nz = n + 3;
  Eigen::VectorXd scale(nz);
  scale.head(n).setConstant(c_w);
  scale[n] = scale[n + 1] = kMaxJump * w0;
  scale[n + 2] = settings.max_step;
  auto residual_scale = [&](double amp) {
    Eigen::VectorXd rs(n + 2);
    rs.head(n).setConstant(amp * c_w);
    rs[n] = 1.0;
    rs[n + 1] = amp * c_w;
    return rs;
  };
  auto x_of = [&](const Eigen::VectorXd& z) { return to_x(z.head(n + 2), std::pow(10.0, z[n + 2])); };
  const double ln10 = std::log(10.0);
  auto corrector = [&](Eigen::VectorXd& z, const Eigen::VectorXd& z_pred, const Eigen::VectorXd& t, int& its) {
    Eigen::VectorXd r;
    Eigen::MatrixXd J;
    double last_step = std::numeric_limits<double>::infinity();
    for (its = 0; its <= settings.max_newton_iterations; ++its) {
      const double amp = std::pow(10.0, z[n + 2]);
      const Eigen::VectorXd xz = to_x(z.head(n + 2), amp);
      if (!eq.evaluate(xz, amp, r, &J)) return false;
      const Eigen::VectorXd rs = residual_scale(amp);
      const Eigen::VectorXd r_scaled = r.cwiseQuotient(rs);
      const double arc = t.dot((z - z_pred).cwiseQuotient(scale));
      const double norm = std::max(r_scaled.lpNorm<Eigen::Infinity>(), std::abs(arc));
      if (norm <= settings.tolerance || (last_step <= kStagnation && norm <= kResidualFloor)) return true;
      if (its == settings.max_newton_iterations) break;
      // dx/dy = diag(a (W), 1, 1); dr/dlambda = ln10 (J_W (x_W - W_s) - e_a (r_a + 1)), and the
      // scaled rows r / (a c_w) also move with a.
      Eigen::MatrixXd A(nz, nz);
      Eigen::VectorXd dxdy = Eigen::VectorXd::Ones(n + 2);
      dxdy.head(n).setConstant(amp);
      A.topLeftCorner(n + 2, n + 2) =
          rs.cwiseInverse().asDiagonal() * J * (dxdy.cwiseProduct(scale.head(n + 2))).asDiagonal();
      Eigen::VectorXd dr = ln10 * (J.leftCols(n) * (xz.head(n) - w_static));
      dr[n] -= ln10 * (r[n] + 1.0);
      Eigen::VectorXd drs = dr.cwiseQuotient(rs);
      drs.head(n) -= ln10 * r_scaled.head(n);
      drs[n + 1] -= ln10 * r_scaled[n + 1];
      A.col(n + 2).head(n + 2) = drs * scale[n + 2];
      A.row(n + 2) = t.transpose();
      Eigen::VectorXd rhs(nz);
      rhs.head(n + 2) = -r_scaled;
      rhs[n + 2] = -arc;
      const Eigen::VectorXd dz = Eigen::PartialPivLU<Eigen::MatrixXd>(A).solve(rhs);
      if (!dz.allFinite()) return false;
      last_step = dz.lpNorm<Eigen::Infinity>();
      z += dz.cwiseProduct(scale);
    }
    return false;
  };
  Eigen::VectorXd z(nz);
  z.head(n + 2) = to_y(x, a);
  z[n + 2] = lambda;
  Eigen::VectorXd tangent = Eigen::VectorXd::Unit(nz, n + 2);  // scaled, unit
  double step = settings.initial_step / settings.max_step;
  const double min_step = settings.min_step / settings.max_step;
  const double cos_max_turn = std::cos(kMaxTurnDeg * std::numbers::pi / 180.0);
  while (true) {
    if (z[n + 2] >= lambda_end - 1e-12) {
      curve.reached_end = true;
      curve.message = "reached amplitude_end";
      break;
    }
    if (static_cast<int>(curve.points.size()) >= settings.max_points) {
      curve.message = "max_points reached";
      break;
    }
    if (z[n + 2] < lambda - kBelowStart) {
      std::ostringstream m;
      m << "the mode's branch turned back in amplitude and fell a decade below amplitude_start (amplitude "
        << std::pow(10.0, z[n + 2]) << ")";
      curve.message = m.str();
      break;
    }
    double h = step;
    // The last step lands on amplitude_end when the branch heads there.
    const bool last = tangent[n + 2] > 0 && z[n + 2] + h * tangent[n + 2] * scale[n + 2] >= lambda_end;
    if (last) h = (lambda_end - z[n + 2]) / (tangent[n + 2] * scale[n + 2]);
    const Eigen::VectorXd z_pred = z + h * tangent.cwiseProduct(scale);
    Eigen::VectorXd z_new = z_pred;
    bool ok = false;
    if (last) {
      Eigen::VectorXd x_end = x_of(z_pred);
      ok = newton(x_end, settings.amplitude_end, iterations);
      if (ok) z_new << to_y(x_end, settings.amplitude_end), lambda_end;
    } else {
      ok = corrector(z_new, z_pred, tangent, iterations);
    }
    Eigen::VectorXd secant = (z_new - z).cwiseQuotient(scale);
    const double length = secant.norm();
    if (ok && length > 0) {
      secant /= length;
      // A step whose secant turns too far from the tangent has jumped to another branch.
      if (secant.dot(tangent) < cos_max_turn && h > min_step) ok = false;
    } else {
      ok = false;
    }
    if (ok) {
      z = z_new;
      tangent = secant;
      record(x_of(z), std::pow(10.0, z[n + 2]), iterations);
      if (iterations <= kEasyIterations) step = std::min(step * kGrowth, 1.0);
    } else {
      ++curve.rejected_steps;
      step = 0.5 * h;
      if (step < min_step) {
        std::ostringstream m;
        m << "step below min_step at amplitude " << std::pow(10.0, z[n + 2])
          << ": beyond it the corrector fails or the solution jumps to another branch";
        curve.message = m.str();
        break;
      }
    }
  }
  curve.residual_evaluations = eq.evaluations();
  return curve;
}

}  // namespace shroudsim::forced
