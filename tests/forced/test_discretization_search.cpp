// The automatic H and N search (forced/discretization_search.hpp) on synthetic curves whose
// peak converges in H and N at known rates: the ladder, the stop, the reuse of a trial, the
// limits.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "forced/discretization_search.hpp"

namespace shroudsim::forced {
namespace {

// A resonance curve with peak 1 + 0.5^H + 2 / N at 100 Hz.
DiscretizationTrial synthetic(int h, int n, int* calls) {
  ++*calls;
  DiscretizationTrial t;
  t.ok = true;
  const double peak = 1.0 + std::pow(0.5, h) + 2.0 / n;
  for (int i = 0; i <= 40; ++i) {
    const double f = 90.0 + 0.5 * i;
    t.curve.emplace_back(f, peak / (1.0 + 0.1 * (f - 100.0) * (f - 100.0)));
  }
  t.peak_amplitude_m = peak;
  t.peak_frequency_hz = 100.0;
  return t;
}

TEST(DiscretizationSearch, RaisesHThenNUntilThePeaksSettle) {
  DiscretizationSettings s;
  s.harmonics_auto = s.time_samples_auto = true;
  s.tolerance = 0.01;
  int calls = 0;
  std::vector<std::pair<int, int>> seen;
  const DiscretizationSearch r = search_discretization(
      s, [&](int h, int n) { return synthetic(h, n, &calls); },
      [&](const DiscretizationTrial& t) { seen.emplace_back(t.harmonics, t.time_samples); });
  // H: 1, 3, 5, 7, 10, 15 with N = 16 (2H + 1) rounded up to a power of two, at least 256;
  // 10 -> 15 changes the peak by 0.09 % (< 1 %): H = 15. Then N from 4 (2H + 1) = 124 -> 128:
  // 128 -> 256 changes it by 0.77 %: N = 256.
  const std::vector<std::pair<int, int>> expected = {{1, 256},  {3, 256},  {5, 256},  {7, 256},
                                                     {10, 512}, {15, 512}, {15, 128}, {15, 256}};
  EXPECT_EQ(seen, expected);
  EXPECT_EQ(r.harmonics, 15);
  EXPECT_TRUE(r.harmonics_converged);
  EXPECT_EQ(r.time_samples, 256);
  EXPECT_TRUE(r.time_samples_converged);
  // No (H, N) is traced twice.
  for (std::size_t i = 0; i < r.trials.size(); ++i)
    for (std::size_t j = i + 1; j < r.trials.size(); ++j)
      EXPECT_FALSE(r.trials[i].harmonics == r.trials[j].harmonics &&
                   r.trials[i].time_samples == r.trials[j].time_samples);
  EXPECT_EQ(calls, static_cast<int>(r.trials.size()));
  const DiscretizationTrial& chosen = r.trials[r.chosen];
  EXPECT_EQ(chosen.harmonics, 15);
  EXPECT_EQ(chosen.time_samples, 256);
  EXPECT_LT(chosen.relative_change, s.tolerance);
  EXPECT_GE(chosen.relative_change, 0.0);
}

TEST(DiscretizationSearch, AFixedNBoundsHAndNoCandidateIsAnError) {
  DiscretizationSettings s;
  s.harmonics_auto = true;
  s.time_samples = 16;  // fixed: 2H + 1 <= 16 stops H at 7
  s.tolerance = 1e-9;   // never converges
  int calls = 0;
  const DiscretizationSearch r = search_discretization(s, [&](int h, int n) { return synthetic(h, n, &calls); });
  EXPECT_EQ(r.harmonics, 7);
  EXPECT_FALSE(r.harmonics_converged);
  EXPECT_EQ(r.time_samples, 16);
  s.time_samples = 2;  // not even H = 1 fits
  EXPECT_THROW(search_discretization(s, [&](int h, int n) { return synthetic(h, n, &calls); }), std::invalid_argument);
}

TEST(DiscretizationSearch, PeaksChangeComparesEveryResonance) {
  Curve a, b;
  for (int i = 0; i <= 200; ++i) {
    const double f = 50.0 + 0.5 * i;
    auto res = [&](double f0, double h) { return h / (1.0 + (f - f0) * (f - f0)); };
    a.emplace_back(f, res(80.0, 1.0) + res(120.0, 0.5));
    b.emplace_back(f, res(80.0, 1.0) + res(120.0, 0.45));  // the smaller peak 10 % lower
  }
  EXPECT_NEAR(peaks_change(a, b), 0.1, 0.01);
  EXPECT_EQ(peaks_change(a, a), 0.0);
  EXPECT_EQ(peaks_shift_hz(a, a), 0.0);
}

}  // namespace
}  // namespace shroudsim::forced
