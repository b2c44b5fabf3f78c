#include "forced/discretization_search.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace shroudsim::forced {

namespace {

/// For every local maximum of either curve at least 20 % of its largest: the window peaks
/// (amplitude, frequency) of both curves within +-2 % of its frequency.
struct PeakPair {
  double a = 0.0, fa = 0.0, b = 0.0, fb = 0.0;
};
std::vector<PeakPair> peak_pairs(const Curve& a, const Curve& b) {
  std::vector<PeakPair> out;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& x = pass == 0 ? a : b;
    const auto& y = pass == 0 ? b : a;
    double top = 0.0;
    for (const auto& p : x) top = std::max(top, p.second);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double v = x[i].second, f0 = x[i].first;
      if (v < 0.2 * top || (i > 0 && x[i - 1].second > v) || (i + 1 < x.size() && x[i + 1].second > v)) continue;
      // Window peaks of both curves (a fold's local maximum next to a taller peak compares
      // that peak, in both).
      PeakPair p;
      for (const auto& q : x)
        if (std::abs(q.first - f0) <= 0.02 * f0 && q.second > p.a) p.a = q.second, p.fa = q.first;
      for (const auto& q : y)
        if (std::abs(q.first - f0) <= 0.02 * f0 && q.second > p.b) p.b = q.second, p.fb = q.first;
      if (pass == 1) std::swap(p.a, p.b), std::swap(p.fa, p.fb);
      out.push_back(p);
    }
  }
  return out;
}

}  // namespace

double peaks_change(const Curve& a, const Curve& b) {
  double worst = 0.0;
  for (const auto& p : peak_pairs(a, b))
    worst = std::max(worst, p.a > 0 && p.b > 0 ? std::abs(p.a - p.b) / std::max(p.a, p.b) : 1.0);
  return worst;
}

double peaks_shift_hz(const Curve& a, const Curve& b) {
  double worst = 0.0;
  for (const auto& p : peak_pairs(a, b))
    if (p.a > 0 && p.b > 0) worst = std::max(worst, std::abs(p.fa - p.fb));
  return worst;
}

namespace {

int pow2_at_least(int v) {
  int p = 1;
  while (p < v) p *= 2;
  return p;
}

}  // namespace

DiscretizationSearch search_discretization(const DiscretizationSettings& s,
                                           const std::function<DiscretizationTrial(int h, int n)>& run,
                                           const std::function<void(const DiscretizationTrial&)>& on_trial) {
  DiscretizationSearch out;
  auto& trials = out.trials;
  auto trial = [&](int h, int n, std::optional<std::size_t> previous) {
    const auto t0 = std::chrono::steady_clock::now();
    DiscretizationTrial t = run(h, n);
    t.harmonics = h;
    t.time_samples = n;
    t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (previous && t.ok && trials[*previous].ok && t.peak_amplitude_m > 0)
      t.relative_change = peaks_change(trials[*previous].curve, t.curve);
    trials.push_back(std::move(t));
    if (on_trial) on_trial(trials.back());
    return trials.size() - 1;
  };
  out.harmonics_converged = !s.harmonics_auto;
  out.time_samples_converged = !s.time_samples_auto;
  int h = s.harmonics, n = s.time_samples;
  if (s.harmonics_auto) {
    std::vector<int> ladder = {1, 3, 5, 7, 10, 15, 20, 25};
    for (int k = 35; k <= 200; k += 10) ladder.push_back(k);
    for (int hk : ladder) {
      if (hk > s.max_harmonics) break;
      const int nk = s.time_samples_auto ? std::max(256, pow2_at_least(16 * (2 * hk + 1))) : s.time_samples;
      if (nk < 2 * hk + 1) break;  // a fixed N limits H
      const std::size_t i =
          trial(hk, nk, trials.empty() ? std::nullopt : std::optional<std::size_t>(trials.size() - 1));
      h = hk, n = nk;
      if (trials[i].relative_change >= 0 && trials[i].relative_change < s.tolerance) {
        out.harmonics_converged = true;
        break;
      }
    }
  }
  if (s.time_samples_auto) {
    std::optional<std::size_t> last;  // the previous trial of this search
    for (int nk = std::max(64, pow2_at_least(4 * (2 * h + 1))); nk <= s.max_time_samples; nk *= 2) {
      // The trial at (h, nk) may have been run while H was sought: reuse it.
      std::optional<std::size_t> here;
      for (std::size_t i = 0; i < trials.size(); ++i)
        if (trials[i].harmonics == h && trials[i].time_samples == nk) here = i;
      if (!here) {
        here = trial(h, nk, last);
      } else if (last) {
        DiscretizationTrial& t = trials[*here];
        const DiscretizationTrial& p = trials[*last];
        t.relative_change = t.ok && p.ok && t.peak_amplitude_m > 0 ? peaks_change(p.curve, t.curve) : -1.0;
      }
      n = nk;
      const double change = last ? trials[*here].relative_change : -1.0;
      last = here;
      if (change >= 0 && change < s.tolerance) {
        out.time_samples_converged = true;
        break;
      }
    }
  }
  bool found = false;
  for (std::size_t i = 0; i < trials.size(); ++i)
    if (trials[i].harmonics == h && trials[i].time_samples == n) out.chosen = i, found = true;
  if (!found)
    throw std::invalid_argument(
        "no H/N candidate fits the limits (auto_max_harmonics, auto_max_time_samples, time_samples >= 2H+1)");
  out.harmonics = h;
  out.time_samples = n;
  return out;
}

}  // namespace shroudsim::forced
