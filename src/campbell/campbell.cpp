#include "campbell/campbell.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

#include "core/error.hpp"
#include "core/log.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "modal/rotating.hpp"

namespace shroudsim::campbell {
namespace {}  // namespace

std::vector<double> speed_points(double s0, double s1, int n) {
  std::vector<double> rpm(n);
  for (int i = 0; i < n; ++i) rpm[i] = s0 + (s1 - s0) * i / (n - 1);
  return rpm;
}

ShroudStates shroud_states(frf::StaticShroudSolver& solver, const std::vector<double>& rpm, int increments) {
  ShroudStates out;
  out.springs = solver.state().springs;
  try {
    const int pre = !rpm.empty() && rpm[0] > 0.0 ? std::max(1, increments) : 0;
    for (int k = 1; k <= pre; ++k)
      solver.step_to(modal::rpm_to_rad_s(rpm[0]) * std::sqrt(static_cast<double>(k) / (pre + 1)));
    for (double s : rpm) {
      solver.step_to(modal::rpm_to_rad_s(s));
      const frf::StaticShroud& st = solver.state();
      std::vector<bool> closed(st.results.size());
      for (std::size_t p = 0; p < st.results.size(); ++p) closed[p] = st.results[p].state != contact::StaticState::open;
      out.closed.push_back(std::move(closed));
      out.slipping.push_back(st.count(contact::StaticState::slip));
      out.normal_load_n.push_back(st.normal_load());
    }
  } catch (const NumericalError& e) {
    out.failure = std::string("static shroud contact: ") + e.what();
  }
  return out;
}

HarmonicSweep sweep_harmonic(const cyclic::CyclicSector& sector, const cyclic::CyclicSector& rotating, int h,
                             const std::vector<double>& rpm, const modal::ModalOptions& options,
                             const Eigen::VectorXd& at_rest, const ShroudStates* states) {
  const int np = static_cast<int>(rpm.size());
  HarmonicSweep s;
  s.f.assign(np, Eigen::VectorXd());
  try {
    modal::RotatingHarmonic hr(sector, rotating, h);
    if (states) hr.set_variable_springs(sector, states->springs);
    for (int i = 0; i < np; ++i) {
      if (rpm[i] == 0.0 && !states) {  // K(0) = K: the modes at rest
        s.f[i] = at_rest;
        continue;
      }
      if (states && i >= states->solved()) {
        s.failure =
            "harmonic index " + std::to_string(h) + ": no static shroud contact state at " + shortest(rpm[i]) + " rpm";
        break;
      }
      log::Stopwatch solve_clock;
      const modal::ModalResult r = states ? hr.solve(modal::rpm_to_rad_s(rpm[i]), options, states->closed[i])
                                          : hr.solve(modal::rpm_to_rad_s(rpm[i]), options);
      s.seconds += solve_clock.seconds();
      s.factor_seconds += r.report.factor_seconds;
      s.lanczos_seconds += r.report.solve_seconds;
      ++s.solves;
      if (!r.report.ok()) {
        s.failure = "harmonic index " + std::to_string(h) + " at " + shortest(rpm[i]) +
                    " rpm: " + modal::to_string(r.report.status) + ": " + r.report.message +
                    (r.report.status == modal::ModalStatus::FactorizationFailed
                         ? " (K + K_sigma - Omega^2 M_spin is not positive definite: a mode diverges)"
                         : "");
        // Where: between the last converged speed and this one; the lowest f^2 extrapolated
        // linearly in Omega^2 from the last two speeds, when that lands in between.
        if (i >= 1 && s.f[i - 1].size() > 0) {
          const double fb = s.f[i - 1](0);
          s.failure += "; the lowest mode is " + fixed(fb, 1) + " Hz at " + shortest(rpm[i - 1]) +
                       " rpm and diverges below " + shortest(rpm[i]) + " rpm";
          if (i >= 2 && s.f[i - 2].size() > 0 && fb < s.f[i - 2](0)) {
            const double fa = s.f[i - 2](0);
            const double wa = rpm[i - 2] * rpm[i - 2], wb = rpm[i - 1] * rpm[i - 1];
            const double at = std::sqrt(wb + (0.0 - fb * fb) * (wb - wa) / (fb * fb - fa * fa));
            if (at > rpm[i - 1] && at < rpm[i]) s.failure += " (f^2 extrapolated to 0 near " + fixed(at, 0) + " rpm)";
          }
        }
        break;
      }
      s.f[i] = r.basis.frequency_hz();
    }
    s.analyses = hr.reuse().analyses;
  } catch (const std::exception& e) {
    s.failure = "harmonic index " + std::to_string(h) + ": " + e.what();
  }
  return s;
}

bool Crossing::operator<(const Crossing& o) const {
  return std::tie(engine_order, speed_rpm, nodal_diameter, mode, frequency_hz) <
         std::tie(o.engine_order, o.speed_rpm, o.nodal_diameter, o.mode, o.frequency_hz);
}

std::vector<Crossing> crossings(const std::vector<double>& rpm, const std::map<int, HarmonicSweep>& sweeps,
                                const std::vector<int>& engine_orders, int sectors) {
  const int nb = sectors;
  const int np = static_cast<int>(rpm.size());
  std::vector<Crossing> rows;
  for (int e : engine_orders) {
    const int h = e % nb;
    const auto it = sweeps.find(cyclic::canonical_index(h, nb));
    if (it == sweeps.end()) continue;
    const HarmonicSweep& s = it->second;
    const int nd = cyclic::nodal_diameter(h, nb);
    int last = np - 1;  // a failed sweep: speeds up to the first missing one
    for (int i = 0; i < np; ++i)
      if (s.f[i].size() == 0) {
        last = i - 1;
        break;
      }
    if (last < 0) continue;
    const Eigen::Index n_modes = s.f[0].size();
    for (Eigen::Index r = 0; r < n_modes; ++r) {
      auto g = [&](int i) { return s.f[i](r) - e * rpm[i] / 60.0; };
      for (int i = 0; i <= last; ++i) {
        if (s.f[i].size() <= r) break;
        const double gi = g(i);
        if (gi == 0.0) {
          rows.push_back({e, rpm[i], nd, static_cast<int>(r) + 1, s.f[i](r)});
          continue;
        }
        if (i == last || s.f[i + 1].size() <= r) break;
        const double gj = g(i + 1);
        if (gj == 0.0 || (gi > 0.0) == (gj > 0.0)) continue;
        const double t = gi / (gi - gj);
        const double at = rpm[i] + t * (rpm[i + 1] - rpm[i]);
        rows.push_back({e, at, nd, static_cast<int>(r) + 1, e * at / 60.0});
      }
    }
  }
  std::sort(rows.begin(), rows.end());
  return rows;
}

}  // namespace shroudsim::campbell
