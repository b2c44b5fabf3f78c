#pragma once
// Automatic harmonics H and time samples N of the forced response (hbm.harmonics and/or
// hbm.time_samples = "auto", docs/continuation.md): a ladder of trials, each a full curve,
// compared at their resonance peaks in memory.
//
//   H is raised through 1, 3, 5, 7, 10, 15, 20, 25, 35, 45, ... (up to max_harmonics; no
//   H = 2 step: a symmetric motion has no even harmonics, and 1 -> 2 would "converge"), with
//   N the power of two >= 16 (2H + 1), at least 256, while N is "auto" too (else the fixed N,
//   which then bounds H: 2H + 1 <= N); then N is doubled from the power of two >= 4 (2H + 1),
//   at least 64, up to max_time_samples. Each search stops when the peaks change by less than
//   `tolerance` (peaks_change) from the previous trial. The accepted trial is the last one run
//   at the chosen (H, N).
//
// Usage:
//   DiscretizationSearch s = search_discretization(settings, [&](int h, int n) {
//     DiscretizationTrial t; ... trace the curve with (h, n), fill ok, peak and curve ...
//     return t;
//   });
//   s.trials[s.chosen]
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace shroudsim::forced {

/// (frequency [Hz], amplitude [m]) of every point of a forced response, in continuation order.
using Curve = std::vector<std::pair<double, double>>;

/// The largest relative change between two forced-response curves at their resonance peaks:
/// for every local maximum of either curve at least 20 % of its largest, the two curves'
/// peaks within +-2 % of its frequency are compared (relative to the larger). One number for
/// the whole range, so that a resonance smaller than the largest (and maybe the one that
/// needs more harmonics) counts; a fold's local maximum beside a taller peak compares that
/// peak. 1 when a peak has no counterpart at all.
double peaks_change(const Curve& a, const Curve& b);

/// The largest shift [Hz] of a resonance peak between two curves, over the same peaks as
/// peaks_change (the frequency of each curve's window peak).
double peaks_shift_hz(const Curve& a, const Curve& b);

struct DiscretizationSettings {
  bool harmonics_auto = false, time_samples_auto = false;
  int harmonics = 5, time_samples = 512;  ///< the fixed values (or ignored when "auto")
  int max_harmonics = 25, max_time_samples = 4096;
  double tolerance = 0.01;  ///< relative change of the peaks that stops a search
};

struct DiscretizationTrial {
  int harmonics = 0, time_samples = 0;
  bool ok = false;      ///< the curve reached the end (the trial's own status)
  std::string message;  ///< why not, when !ok
  double peak_amplitude_m = 0.0, peak_frequency_hz = 0.0;
  double seconds = 0.0;
  double relative_change = -1.0;  ///< peaks_change against the trial it was compared with (-1: none)
  Curve curve;
};

struct DiscretizationSearch {
  std::vector<DiscretizationTrial> trials;  ///< every trial, in the order run
  int harmonics = 0, time_samples = 0;      ///< chosen
  bool harmonics_converged = false, time_samples_converged = false;
  std::size_t chosen = 0;  ///< index into trials
};

/// run(h, n) traces one trial (filling ok, message, peaks, curve; seconds are measured here);
/// on_trial (may be empty) sees each trial once compared. Throws std::invalid_argument when
/// no candidate fits the limits (max_harmonics, max_time_samples, 2H + 1 <= N).
DiscretizationSearch search_discretization(const DiscretizationSettings& settings,
                                           const std::function<DiscretizationTrial(int h, int n)>& run,
                                           const std::function<void(const DiscretizationTrial&)>& on_trial = {});

}  // namespace shroudsim::forced
