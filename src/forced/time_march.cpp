#include "forced/time_march.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "forced/element_law.hpp"
#include "frf/lumped.hpp"
#include "hbm/harmonic_layout.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// Periods in a row below the tolerance before the motion counts as repeating (one period can
// match by chance, e.g. at a turning point of a slow drift).
constexpr int kSettledPeriods = 3;
// A subharmonic candidate is confirmed when, over about this many periods, the change over one
// period repeats to kSteadyChange (a steady p-periodic motion repeats it to round-off; a
// transient decaying at a damping ratio of 1e-5 changes it by ~1e-2 over 200 periods).
constexpr long long kConfirmPeriods = 200;
constexpr double kSteadyChange = 1e-6;

}  // namespace

bool TimeMarchOptions::validate(std::vector<std::string>* errors) const {
  const auto fail = [&](const std::string& m) {
    if (errors) errors->push_back(m);
    return false;
  };
  bool ok = detail::valid_steps(min_steps_per_period, steps_per_stiff_period, errors);
  if (max_periods < 1) ok = fail("max_periods >= 1");
  if (max_steps < 1) ok = fail("max_steps >= 1");
  if (max_period_multiple < 1) ok = fail("max_period_multiple >= 1");
  if (!(periodicity_tolerance > 0.0 && periodicity_tolerance < 1.0)) ok = fail("periodicity_tolerance in (0, 1)");
  if (output_samples < 1) ok = fail("output_samples >= 1");
  return ok;
}

std::string TimeMarchResult::describe() const {
  const std::string after = " after " + std::to_string(periods) + " excitation periods of time integration";
  switch (motion) {
    case Motion::periodic: return "periodic" + after;
    case Motion::subharmonic:
      return "subharmonic (repeats every " + std::to_string(period_multiple) + " excitation periods, not every one)" +
             after;
    case Motion::not_settled: {
      std::ostringstream change;
      change.precision(2);
      change << mismatch;
      return "not periodic" + after + " (the state still changes by " + change.str() +
             " of its size from one period to the next and over every multiple up to the search's limit)";
    }
    case Motion::not_applicable: return "not integrated: " + reason;
  }
  return "?";
}

LumpedSystem lumped_system(const frf::LumpedLinearPart& lumped) {
  return {lumped.mass(), lumped.damping(), lumped.stiffness(), lumped.contact_operator(), lumped.force_vector(), {}};
}

bool LumpedSystem::consistent(Eigen::Index elements) const {
  const Eigen::Index n = mass.rows();
  return n > 0 && mass.cols() == n && stiffness.rows() == n && stiffness.cols() == n && damping.rows() == n &&
         damping.cols() == n && force.size() == n && (force_sin.size() == 0 || force_sin.size() == n) &&
         contact_operator.rows() == 3 * elements && contact_operator.cols() == n;
}

double stuck_highest_circular_frequency(const LumpedSystem& s, const std::vector<contact::PairParameters>& pairs,
                                        contact::Model model) {
  const bool one_d = contact::n_directions(model) == 1;
  Eigen::MatrixXd k_stuck = s.stiffness;
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(e);
    const double k_dir[3] = {pairs[e].tangential_stiffness, one_d ? 0.0 : pairs[e].tangential_stiffness,
                             one_d ? 0.0 : pairs[e].normal_stiffness};
    for (int d = 0; d < 3; ++d)
      k_stuck += k_dir[d] * s.contact_operator.row(row + d).transpose() * s.contact_operator.row(row + d);
  }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k_stuck, s.mass, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

TimeMarchResult march_to_steady_state(const LumpedSystem& s, const std::vector<contact::PairParameters>& pairs,
                                      contact::Model model, double frequency_hz, const TimeMarchOptions& o) {
  std::vector<std::string> errors;
  if (!o.validate(&errors)) throw std::invalid_argument("time integration options: " + errors.front());
  const Eigen::Index n = s.mass.rows();
  const Eigen::Index c = 3 * static_cast<Eigen::Index>(pairs.size());
  if (!s.consistent(static_cast<Eigen::Index>(pairs.size())))
    throw std::invalid_argument("time integration: inconsistent sizes of M, C, K, B, f");
  if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz))
    throw std::invalid_argument("time integration: frequency > 0");

  TimeMarchResult r;
  const bool one_d = contact::n_directions(model) == 1;
  std::vector<detail::ElementLaw> laws;
  for (const auto& p : pairs) laws.push_back({p, one_d, model != contact::Model::quasi3d});

  const Eigen::LLT<Eigen::MatrixXd> mass_llt(s.mass);
  if (mass_llt.info() != Eigen::Success) {
    r.motion = TimeMarchResult::Motion::not_applicable;
    r.reason = "the mass matrix is not positive definite (a massless DOF needs an implicit scheme)";
    return r;
  }
  const double w_max = stuck_highest_circular_frequency(s, pairs, model);
  const double w = kTwoPi * frequency_hz;
  const double steps_needed = detail::steps_needed(o.min_steps_per_period, o.steps_per_stiff_period, w_max, w);
  // A whole number of steps per output sample, so the output falls on steps.
  const long long per_sample = static_cast<long long>(std::ceil(steps_needed / o.output_samples));
  const long long steps = per_sample * o.output_samples;
  if (steps > o.max_steps) {
    r.motion = TimeMarchResult::Motion::not_applicable;
    r.reason = "one period needs " + std::to_string(steps) + " steps (stiff contact against a slow excitation)";
    return r;
  }
  r.steps_per_period = static_cast<int>(steps);
  const double dt = (1.0 / frequency_hz) / static_cast<double>(steps);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lhs(s.mass + 0.5 * dt * s.damping);

  // Forces the structure already carries (contact.normal_preload = "static").
  const Eigen::VectorXd f_static = detail::static_load(pairs, one_d);

  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), v = Eigen::VectorXd::Zero(n), a(n), a1(n), v_half(n), wc(c), fc(c);
  Eigen::VectorXd slider = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(pairs.size()));
  // fc = F(B u) - F_s, the slider updated.
  const auto contact_force = [&]() {
    wc.noalias() = s.contact_operator * u;
    for (std::size_t e = 0; e < laws.size(); ++e)
      laws[e].force(wc.data() + 3 * e, slider.data() + 2 * e, fc.data() + 3 * e);
    fc -= f_static;
  };
  contact_force();
  a = mass_llt.solve(s.force - s.stiffness * u - s.contact_operator.transpose() * fc - s.damping * v);
  // (M + dt/2 C) a1 = f cos(w t1) - K u1 - B^T fc - C (v + dt/2 a), with the operator's
  // inverse applied once to each matrix.
  const Eigen::VectorXd a_force = lhs.solve(s.force), a_force_sin = lhs.solve(s.sine_force());
  const Eigen::MatrixXd a_stiffness = lhs.solve(s.stiffness), a_damping = lhs.solve(s.damping),
                        a_contact = lhs.solve(s.contact_operator.transpose());

  const long long max_periods = std::min<long long>(o.max_periods, o.max_steps / steps);
  std::deque<Eigen::VectorXd> history;  // period-boundary states, newest last
  std::vector<int> below(static_cast<std::size_t>(o.max_period_multiple) + 1, 0);
  r.contact_motion.resize(c, o.output_samples);
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> change_1_history;  // change over one period, per period
  long long confirm_from = -1;           // period from which a subharmonic candidate held
  for (long long period = 1; period <= max_periods; ++period) {
    double size = 0.0, vsize = 0.0;
    for (long long k = 0; k < steps; ++k) {
      if (k % per_sample == 0) r.contact_motion.col(k / per_sample).noalias() = s.contact_operator * u;
      const double t1 = static_cast<double>(k + 1) * dt;
      u += dt * v + (0.5 * dt * dt) * a;
      v_half = v + (0.5 * dt) * a;
      contact_force();
      a1 = std::cos(w * t1) * a_force + std::sin(w * t1) * a_force_sin;
      a1.noalias() -= a_stiffness * u;
      a1.noalias() -= a_contact * fc;
      a1.noalias() -= a_damping * v_half;
      v = v_half + (0.5 * dt) * a1;
      a.swap(a1);
      size = std::max(size, u.lpNorm<Eigen::Infinity>());
      vsize = std::max(vsize, v.lpNorm<Eigen::Infinity>() / w);
    }
    if (!u.allFinite() || !v.allFinite()) {
      r.motion = TimeMarchResult::Motion::not_applicable;
      r.reason = "the integration diverged (not finite after " + std::to_string(period) + " periods)";
      r.periods = static_cast<int>(period);
      return r;
    }
    Eigen::VectorXd state(2 * n + slider.size());
    state << u, v / w, slider;
    const double scale = std::max({size, vsize, std::numeric_limits<double>::min()});
    r.periods = static_cast<int>(period);
    best = std::numeric_limits<double>::infinity();
    int settled = 0;
    double change_1 = std::numeric_limits<double>::infinity();
    for (int p = 1; p <= o.max_period_multiple && p <= static_cast<int>(history.size()); ++p) {
      const double change =
          (state - history[history.size() - static_cast<std::size_t>(p)]).lpNorm<Eigen::Infinity>() / scale;
      if (p == 1) change_1 = change;
      best = std::min(best, change);
      below[static_cast<std::size_t>(p)] = change < o.periodicity_tolerance ? below[static_cast<std::size_t>(p)] + 1
                                                                            : 0;
      if (settled == 0 && below[static_cast<std::size_t>(p)] >= kSettledPeriods) settled = p;
    }
    history.push_back(state);
    if (static_cast<int>(history.size()) > o.max_period_multiple) history.pop_front();
    change_1_history.push_back(change_1);
    r.mismatch = best;
    r.change_one_period = change_1;
    if (settled == 1) {
      r.motion = TimeMarchResult::Motion::periodic;
      r.period_multiple = 1;
      break;
    }
    // A decaying transient whose frequency is nearly p times slower than the excitation's
    // repeats over p periods before it has died out: a subharmonic only once the change over
    // one period has stopped decaying too (it is then itself p-periodic).
    if (settled == 0) {
      confirm_from = -1;
      continue;
    }
    if (confirm_from < 0) confirm_from = period;
    const long long span = (kConfirmPeriods / settled) * settled;
    if (period - confirm_from < span) continue;
    const double now = change_1_history.back(), then = change_1_history[change_1_history.size() - 1 - span];
    if (std::abs(now - then) <= kSteadyChange * now) {
      r.motion = TimeMarchResult::Motion::subharmonic;
      r.period_multiple = settled;
      break;
    }
    confirm_from = period;
  }
  r.displacement = u;
  r.velocity = v;
  return r;
}

TimeMarchResult march_to_steady_state_cached(const LumpedSystem& system,
                                             const std::vector<contact::PairParameters>& pairs, contact::Model law,
                                             double frequency_hz, const TimeMarchOptions& options, bool* reused) {
  // The exact bytes of every input are the key.
  std::string key;
  auto put = [&key](const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); };
  auto put_matrix = [&](const auto& m) {
    const Eigen::Index r = m.rows(), c = m.cols();
    put(&r, sizeof r);
    put(&c, sizeof c);
    put(m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  };
  put_matrix(system.mass);
  put_matrix(system.damping);
  put_matrix(system.stiffness);
  put_matrix(system.contact_operator);
  put_matrix(system.force);
  put_matrix(system.force_sin);
  for (const contact::PairParameters& p : pairs) {
    for (double v : {p.tangential_stiffness, p.normal_stiffness, p.friction_coefficient, p.normal_preload})
      put(&v, sizeof v);
    put(&p.preload_in_equilibrium, sizeof p.preload_in_equilibrium);
  }
  put(&law, sizeof law);
  put(&frequency_hz, sizeof frequency_hz);
  for (double v : {static_cast<double>(options.min_steps_per_period), options.steps_per_stiff_period,
                   static_cast<double>(options.max_periods), static_cast<double>(options.max_steps),
                   static_cast<double>(options.max_period_multiple), options.periodicity_tolerance,
                   static_cast<double>(options.output_samples)})
    put(&v, sizeof v);
  static std::mutex mutex;
  static std::deque<std::pair<std::string, TimeMarchResult>> cache;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [k, r] : cache)
      if (k == key) {
        if (reused) *reused = true;
        return r;
      }
  }
  if (reused) *reused = false;
  TimeMarchResult r = march_to_steady_state(system, pairs, law, frequency_hz, options);
  const std::lock_guard<std::mutex> lock(mutex);
  cache.emplace_back(std::move(key), r);
  if (cache.size() > kMarchCacheEntries) cache.pop_front();
  return r;
}

Eigen::VectorXd harmonic_unknowns(const Eigen::MatrixXd& samples, int n_harmonics, int n_directions) {
  const hbm::HarmonicLayout layout(n_harmonics, n_directions);
  const Eigen::Index rows = samples.rows(), m = samples.cols();
  if (rows % 3 != 0 || m < 2 * n_harmonics + 1)
    throw std::invalid_argument("harmonic_unknowns: 3 rows per element and at least 2H + 1 samples");
  const Eigen::Index pairs = rows / 3;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(pairs * layout.size());
  for (Eigen::Index p = 0; p < pairs; ++p)
    for (int d = 0; d < n_directions; ++d) {
      const Eigen::VectorXd row = samples.row(3 * p + d).transpose();
      double* out = x.data() + p * layout.size();
      out[layout.index(d, 0)] = row.mean();
      for (int h = 1; h <= n_harmonics; ++h) {
        double cs = 0.0, sn = 0.0;
        for (Eigen::Index j = 0; j < m; ++j) {
          const double phase = kTwoPi * h * static_cast<double>(j) / static_cast<double>(m);
          cs += row[j] * std::cos(phase);
          sn += row[j] * std::sin(phase);
        }
        out[layout.index(d, h, hbm::HarmonicLayout::Part::cosine)] = 2.0 * cs / static_cast<double>(m);
        out[layout.index(d, h, hbm::HarmonicLayout::Part::sine)] = 2.0 * sn / static_cast<double>(m);
      }
    }
  return x;
}

}  // namespace shroudsim::forced
