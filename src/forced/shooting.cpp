#include "forced/shooting.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "forced/element_law.hpp"
#include "forced/reduced_equations.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kNewtonStall = 0.5;

/// One excitation period of the explicit scheme of forced/time_march.cpp, applied to several
/// states at once (the columns of a matrix: the forward differences march together). A state
/// is z = (u, v / w, sliders), the sliders one per tangential direction of each element.
class PeriodMap {
 public:
  PeriodMap(const LumpedSystem& s, const std::vector<contact::PairParameters>& pairs, contact::Model model,
            double frequency_hz, long long steps)
      : s_(s), w_(kTwoPi * frequency_hz), steps_(steps), one_d_(contact::n_directions(model) == 1) {
    for (const auto& p : pairs) laws_.push_back({p, one_d_, model != contact::Model::quasi3d});
    n_ = s.mass.rows();
    dirs_ = one_d_ ? 1 : 2;
    dt_ = (1.0 / frequency_hz) / static_cast<double>(steps);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lhs(s.mass + 0.5 * dt_ * s.damping);
    a_force_ = lhs.solve(s.force);
    a_force_sin_ = lhs.solve(s.sine_force());
    a_stiffness_ = lhs.solve(s.stiffness);
    a_damping_ = lhs.solve(s.damping);
    a_contact_ = lhs.solve(s.contact_operator.transpose());
    mass_llt_.compute(s.mass);
    f_static_ = detail::static_load(pairs, one_d_);
    excitation_.resize(steps);
    excitation_sin_.resize(steps);
    for (long long k = 0; k < steps; ++k) {
      excitation_[k] = std::cos(w_ * static_cast<double>(k + 1) * dt_);
      excitation_sin_[k] = std::sin(w_ * static_cast<double>(k + 1) * dt_);
    }
  }
  Eigen::Index size() const { return 2 * n_ + dirs_ * static_cast<Eigen::Index>(laws_.size()); }

  /// One period from each column of z. sliding_at_limit: the sliders the law moves at t = 0 in
  /// any column (those on the friction limit, sliding there) are put on the limit in every
  /// column, whatever its trial force (ElementLaw::force's at_limit; map_and_derivative).
  Eigen::MatrixXd apply(const Eigen::MatrixXd& z, bool sliding_at_limit = false) const {
    const Eigen::Index m = z.cols(), c = 3 * static_cast<Eigen::Index>(laws_.size());
    Eigen::MatrixXd u = z.topRows(n_), v = w_ * z.middleRows(n_, n_);
    Eigen::MatrixXd slider = Eigen::MatrixXd::Zero(2 * static_cast<Eigen::Index>(laws_.size()), m);
    const auto slider_rows = [&](Eigen::Index e) { return z.middleRows(2 * n_ + dirs_ * e, dirs_); };
    for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(laws_.size()); ++e)
      slider.middleRows(2 * e, dirs_) = slider_rows(e);
    Eigen::MatrixXd wc(c, m), fc(c, m), a(n_, m), a1(n_, m), v_half(n_, m);
    const auto contact_force = [&](const std::vector<unsigned>* limit) {
      wc.noalias() = s_.contact_operator.lazyProduct(u);
      for (Eigen::Index j = 0; j < m; ++j)
        for (std::size_t e = 0; e < laws_.size(); ++e)
          laws_[e].force(wc.col(j).data() + 3 * e, slider.col(j).data() + 2 * e, fc.col(j).data() + 3 * e,
                         limit != nullptr ? (*limit)[e] : 0U);
      fc.colwise() -= f_static_;
    };
    contact_force(nullptr);
    if (sliding_at_limit) {
      std::vector<unsigned> at_limit(laws_.size(), 0U);
      bool any = false;
      for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(laws_.size()); ++e)
        for (Eigen::Index k = 0; k < dirs_; ++k)
          if (slider.row(2 * e + k) != slider_rows(e).row(k)) {
            at_limit[static_cast<std::size_t>(e)] |= 1U << k;
            any = true;
          }
      if (any) {
        for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(laws_.size()); ++e)
          slider.middleRows(2 * e, dirs_) = slider_rows(e);
        contact_force(&at_limit);
      }
    }
    a = s_.force.replicate(1, m) - s_.stiffness * u - s_.contact_operator.transpose() * fc - s_.damping * v;
    a = mass_llt_.solve(a);
    for (long long k = 0; k < steps_; ++k) {
      u += dt_ * v + (0.5 * dt_ * dt_) * a;
      v_half = v + (0.5 * dt_) * a;
      contact_force(nullptr);
      // Products of a few DOFs by a few states: lazy (no blocking, no packing).
      a1 = (excitation_[k] * a_force_ + excitation_sin_[k] * a_force_sin_).replicate(1, m);
      a1.noalias() -= a_stiffness_.lazyProduct(u);
      a1.noalias() -= a_contact_.lazyProduct(fc);
      a1.noalias() -= a_damping_.lazyProduct(v_half);
      v = v_half + (0.5 * dt_) * a1;
      a.swap(a1);
    }
    Eigen::MatrixXd out(size(), m);
    out.topRows(n_) = u;
    out.middleRows(n_, n_) = v / w_;
    for (Eigen::Index e = 0; e < static_cast<Eigen::Index>(laws_.size()); ++e)
      out.middleRows(2 * n_ + dirs_ * e, dirs_) = slider.middleRows(2 * e, dirs_);
    return out;
  }

 private:
  const LumpedSystem& s_;
  double w_;
  long long steps_;
  bool one_d_;
  Eigen::Index n_ = 0, dirs_ = 2;
  double dt_ = 0.0;
  std::vector<detail::ElementLaw> laws_;
  Eigen::VectorXd a_force_, a_force_sin_, f_static_;
  Eigen::VectorXd excitation_, excitation_sin_;  // cos(w t_{k+1}), sin(w t_{k+1})
  Eigen::MatrixXd a_stiffness_, a_damping_, a_contact_;
  Eigen::LLT<Eigen::MatrixXd> mass_llt_;
};

double state_size(const Eigen::VectorXd& z) { return std::max(z.lpNorm<Eigen::Infinity>(), 1e-300); }

/// P(z) and dP/dz by forward differences (one march of d + 1 states): within a piece of the
/// map the differences are exact but for round-off (~1e-16 / kShootingStep relative) where the
/// law is linear (stick, lift-off, 1D slip), and within kShootingStep of the curvature where it
/// is not (the direction of a coupled 2D slip).
/// A contact sliding at t = 0 has its slider on the friction limit, where the scheme's map has a
/// kink that the time-continuous motion does not: a difference that moves the trial force
/// inside the limit sticks the slider for a whole first step (a force change of kt h for dt),
/// where the continuous motion sticks for a time of order h and changes the force by O(h^2).
/// The two one-sided differences then differ by about kt dt / (m w), whatever h: on stress
/// model 10 (kt / k = 9e3), spectral radii 3.45 forward and 2.81 backward where perturbed
/// motions decay by about 0.45 a period. So every difference keeps the sliders that slide at z (or
/// that any difference pushes past the limit) on the limit at t = 0, as the continuous motion
/// does: the derivative of the sliding motion, 0.467 there.
Eigen::VectorXd map_and_derivative(const PeriodMap& map, const Eigen::VectorXd& z, Eigen::MatrixXd& monodromy) {
  const Eigen::Index d = z.size();
  const double h = kShootingStep * state_size(z);
  Eigen::MatrixXd batch = z.replicate(1, d + 1);
  for (Eigen::Index i = 0; i < d; ++i) batch(i, 1 + i) += h;
  const Eigen::MatrixXd out = map.apply(batch, true);
  monodromy.resize(d, d);
  for (Eigen::Index i = 0; i < d; ++i) monodromy.col(i) = (out.col(1 + i) - out.col(0)) / h;
  return out.col(0);
}

}  // namespace

bool ShootingOptions::validate(std::vector<std::string>* errors) const {
  const auto fail = [&](const std::string& m) {
    if (errors) errors->push_back(m);
    return false;
  };
  bool ok = detail::valid_steps(min_steps_per_period, steps_per_stiff_period, errors);
  if (max_steps_per_period < min_steps_per_period) ok = fail("max_steps_per_period >= min_steps_per_period");
  if (max_newton_iterations < 0) ok = fail("max_newton_iterations >= 0");
  return ok;
}

FloquetResult ShootingResult::to_floquet(double frequency_hz) const {
  FloquetResult f;
  f.available = available;
  f.reason = reason;
  if (!available) return f;
  f.stable = stable;
  const double period = 1.0 / frequency_hz;
  for (const auto& mu : multipliers)
    if (std::abs(mu) > 0.0) {
      f.exponents.push_back(std::log(mu) / period);
      f.exponent_family.push_back(0);
    }
  std::stable_sort(f.exponents.begin(), f.exponents.end(),
                   [](const auto& a, const auto& b) { return a.real() > b.real(); });
  f.families = {0};
  if (left) return f;  // no multipliers: the motion left the solution (exponents empty, max_real 0)
  // The verdict is the spectral radius's: max_real crosses 0 where it crosses 1 + kShootingNeutral.
  f.max_real = std::log(spectral_radius / (1.0 + kShootingNeutral)) / period;
  return f;
}

ShootingResult shooting_floquet(const LumpedSystem& s, const std::vector<contact::PairParameters>& pairs,
                                contact::Model model, double frequency_hz, const Eigen::VectorXd& u0,
                                const Eigen::VectorXd& v0, const Eigen::VectorXd& sliders0, const ShootingOptions& o) {
  std::vector<std::string> errors;
  if (!o.validate(&errors)) throw std::invalid_argument("shooting options: " + errors.front());
  const Eigen::Index n = s.mass.rows();
  const Eigen::Index dirs = contact::n_tangential_directions(model);
  if (!s.consistent(static_cast<Eigen::Index>(pairs.size())) || u0.size() != n || v0.size() != n ||
      sliders0.size() != dirs * static_cast<Eigen::Index>(pairs.size()))
    throw std::invalid_argument("shooting: inconsistent sizes of M, C, K, B, f and the state");
  if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz)) throw std::invalid_argument("shooting: frequency > 0");

  ShootingResult r;
  if (Eigen::LLT<Eigen::MatrixXd>(s.mass).info() != Eigen::Success) {
    r.reason = "the mass matrix is not positive definite (a massless DOF needs an implicit scheme)";
    return r;
  }
  const double w = kTwoPi * frequency_hz;
  const double w_max = stuck_highest_circular_frequency(s, pairs, model);
  const double steps_needed = detail::steps_needed(o.min_steps_per_period, o.steps_per_stiff_period, w_max, w);
  if (steps_needed > static_cast<double>(o.max_steps_per_period)) {
    r.reason = "one period needs " + std::to_string(static_cast<long long>(std::ceil(steps_needed))) +
               " steps (stiff contact against a slow excitation; the limit is " +
               std::to_string(o.max_steps_per_period) + ")";
    return r;
  }
  const long long steps = static_cast<long long>(std::ceil(steps_needed));
  r.steps_per_period = static_cast<int>(steps);
  const PeriodMap map(s, pairs, model, frequency_hz, steps);
  r.state_size = static_cast<int>(map.size());

  Eigen::VectorXd z(map.size());
  z << u0, v0 / w, sliders0;
  if (!z.allFinite()) {
    r.reason = "the harmonic-balance state is not finite";
    return r;
  }
  auto mismatch_of = [](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return (a - b).lpNorm<Eigen::Infinity>() / state_size(b);
  };
  Eigen::MatrixXd monodromy;
  // Newton on P(z) - z = 0 from z, in place; returns the mismatch reached, with `monodromy`
  // taken at the final z. A stuck slider makes M - I singular (a neutral direction: any anchor
  // gives an orbit): the least-squares step of the complete orthogonal decomposition. The
  // monodromy is reused (a chord step) while it halves the mismatch, and taken afresh when not.
  // `start`, when given, gets the mismatch at x itself.
  const auto newton = [&](Eigen::VectorXd& x, double* start) {
    const Eigen::VectorXd x0 = x;
    Eigen::VectorXd px = map_and_derivative(map, x, monodromy);
    bool fresh = true;
    double mismatch = px.allFinite() ? mismatch_of(px, x) : INFINITY;
    if (start) *start = mismatch;
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(1e-10);
    cod.compute(monodromy - Eigen::MatrixXd::Identity(x.size(), x.size()));
    for (int it = 0; mismatch > kShootingTolerance && it < o.max_newton_iterations; ++it) {
      const Eigen::VectorXd dx = cod.solve(-(px - x));
      ++r.newton_iterations;
      const double before = mismatch;
      bool improved = false;
      double step = 1.0;
      for (int backtrack = 0; backtrack < 6 && !improved; ++backtrack, step *= 0.5) {
        const Eigen::VectorXd trial = x + step * dx;
        Eigen::VectorXd trial_px = map.apply(trial);
        const double m = trial_px.allFinite() ? mismatch_of(trial_px, trial) : INFINITY;
        if (m < mismatch) {
          x = trial;
          px = std::move(trial_px);
          mismatch = m;
          improved = true;
        }
      }
      // Within one piece of the map Newton converges in a step or two; an iteration with a
      // fresh monodromy that does not halve the mismatch is stepping between pieces, and the
      // march decides instead.
      if (improved && mismatch <= kNewtonStall * before) {
        fresh = false;
        continue;
      }
      if (fresh) break;
      px = map_and_derivative(map, x, monodromy);
      fresh = true;
      cod.compute(monodromy - Eigen::MatrixXd::Identity(x.size(), x.size()));
    }
    // The monodromy of a piece of the map is that of any state in it: taken again only when the
    // orbit lies more than kShootingReuse from where it was taken.
    if (!fresh && mismatch_of(x, x0) > kShootingReuse) px = map_and_derivative(map, x, monodromy);
    return mismatch;
  };
  r.mismatch = newton(z, &r.start_mismatch);
  if (!(r.mismatch <= kShootingMismatch) && std::isfinite(r.mismatch)) {
    // The period map is piecewise smooth (stick-slip, lift-off, and the step's quantization of
    // their instants), and Newton can stall between its pieces. Then the motion decides: marched
    // from the best state, it either settles on a periodic orbit near it (stable), or leaves it
    // (unstable: a motion started on the solution does not stay near it), or neither within
    // kShootingMarchPeriods (not judged).
    const Eigen::VectorXd from = z;
    const double leaves = std::max(kShootingLeaves, kShootingLeavesFactor * r.start_mismatch);
    Eigen::VectorXd x = z;
    double change = INFINITY;
    for (r.march_periods = 1; r.march_periods <= kShootingMarchPeriods; ++r.march_periods) {
      const Eigen::VectorXd next = map.apply(x);
      if (!next.allFinite()) break;
      change = mismatch_of(next, x);
      r.march_distance = std::max(r.march_distance, mismatch_of(next, from));
      x = next;
      if (r.march_distance > leaves || change <= kShootingMismatch) break;
    }
    if (r.march_distance > leaves) {
      r.available = true;
      r.stable = false;
      r.left = true;
      return r;
    }
    if (!(change <= kShootingMismatch)) {
      r.reason =
          "no periodic orbit of the time integration found near the harmonic-balance solution (Newton on the "
          "period map left a mismatch of " +
          std::to_string(r.mismatch) + ", and the motion marched from it for " + std::to_string(kShootingMarchPeriods) +
          " periods neither settled nor went " + std::to_string(leaves) + " of its size away)";
      return r;
    }
    // Settled: the orbit there attracts; its multipliers from Newton on it.
    z = x;
    r.settled = true;
    r.mismatch = newton(z, nullptr);
    if (!(r.mismatch <= kShootingMismatch)) r.mismatch = change;
  }
  if (!(r.mismatch <= kShootingMismatch)) {
    r.reason =
        "no periodic orbit of the time integration near the harmonic-balance solution (Newton on the period "
        "map left a mismatch of " +
        std::to_string(r.mismatch) + ")";
    return r;
  }
  if (!monodromy.allFinite()) {
    r.reason = "the monodromy is not finite";
    return r;
  }
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(monodromy, false);
  if (eig.info() != Eigen::Success) {
    r.reason = "the monodromy's eigenvalues did not converge";
    return r;
  }
  for (Eigen::Index i = 0; i < eig.eigenvalues().size(); ++i) r.multipliers.push_back(eig.eigenvalues()[i]);
  std::stable_sort(r.multipliers.begin(), r.multipliers.end(),
                   [](const auto& a, const auto& b) { return std::abs(a) > std::abs(b); });
  r.spectral_radius = r.multipliers.empty() ? 0.0 : std::abs(r.multipliers.front());
  r.stable = r.spectral_radius <= 1.0 + kShootingNeutral;
  r.available = true;
  return r;
}

double shooting_work(const LumpedSystem& s, const std::vector<contact::PairParameters>& pairs, contact::Model model,
                     double frequency_hz, const ShootingOptions& o) {
  const double w = kTwoPi * frequency_hz;
  const double steps = std::min(static_cast<double>(o.max_steps_per_period),
                                detail::steps_needed(o.min_steps_per_period, o.steps_per_stiff_period,
                                                     stuck_highest_circular_frequency(s, pairs, model), w));
  if (!std::isfinite(steps)) return 0.0;  // no positive-definite mass: shooting_floquet declines at once
  const double d = 2.0 * static_cast<double>(s.mass.rows()) +
                   (contact::n_directions(model) == 1 ? 1.0 : 2.0) * static_cast<double>(pairs.size());
  return steps * (2.0 * (d + 1.0) + kShootingMarchPeriods);
}

void periodic_state(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs, contact::Model model,
                    const std::vector<Eigen::VectorXcd>& forces, double frequency_hz, Eigen::VectorXd& u0,
                    Eigen::VectorXd& v0, Eigen::VectorXd& sliders0) {
  using Complex = std::complex<double>;
  const double omega = kTwoPi * frequency_hz;
  const bool one_d = contact::n_directions(model) == 1;
  const Eigen::Index n = system.mass.rows();
  u0 = Eigen::VectorXd::Zero(n);
  v0 = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd f0 = detail::static_load(pairs, one_d);
  for (std::size_t h = 0; h < forces.size(); ++h) {
    // x(t) = Re sum_h X_h e^{i h w t}: at t = 0 Re X_h, and the velocity Re(i h w X_h).
    const double big_w = static_cast<double>(h) * omega;
    const Eigen::MatrixXcd dynamic = system.stiffness.cast<Complex>() - big_w * big_w * system.mass.cast<Complex>() +
                                     Complex(0.0, big_w) * system.damping.cast<Complex>();
    Eigen::VectorXcd f = -system.contact_operator.transpose().cast<Complex>() * forces[h];
    if (h == 1) {  // f cos + f_s sin = Re((f - i f_s) e^{i w t})
      f += system.force.cast<Complex>();
      if (system.force_sin.size() > 0) f -= Complex(0.0, 1.0) * system.force_sin.cast<Complex>();
    }
    const Eigen::VectorXcd u = Eigen::PartialPivLU<Eigen::MatrixXcd>(dynamic).solve(f);
    u0 += u.real();
    v0 -= big_w * u.imag();
    f0 += forces[h].real();
  }
  const Eigen::VectorXd wc = system.contact_operator * u0;
  const int dirs = one_d ? 1 : 2;
  sliders0.resize(dirs * static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(e);
    const bool closed = one_d || pairs[e].normal_preload + pairs[e].normal_stiffness * wc[row + 2] > 0.0;
    for (int d = 0; d < dirs; ++d)
      sliders0[dirs * static_cast<Eigen::Index>(e) + d] =
          wc[row + d] - (closed ? f0[row + d] / pairs[e].tangential_stiffness : 0.0);
  }
}

void harmonic_balance_state(ReducedEquations& equations, const LumpedSystem& system,
                            const std::vector<contact::PairParameters>& pairs, contact::Model model,
                            const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& u0, Eigen::VectorXd& v0,
                            Eigen::VectorXd& sliders0) {
  // contact_force_harmonics: harmonic 0 without the load the structure already carries.
  periodic_state(system, pairs, model, equations.contact_force_harmonics(w), frequency_hz, u0, v0, sliders0);
}

}  // namespace shroudsim::forced
