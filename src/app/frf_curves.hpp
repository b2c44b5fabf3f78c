#pragma once
// Forced-response curves as written to frf.csv, read back and compared: the measure of
// convergence shared by hbm "auto" (cmd_frf.cpp) and `study --convergence` (cmd_study.cpp).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace shroudsim::app {

/// The whole file as text ("" when it cannot be read).
std::string read_file(const std::filesystem::path& p);

/// (frequency [Hz], amplitude [m]) of every row of an frf.csv, in continuation order.
std::vector<std::pair<double, double>> read_curve(const std::filesystem::path& file);

/// The largest relative change between two forced-response curves at their resonance peaks:
/// for every local maximum of either curve at least 20 % of its largest, the two curves'
/// peaks within +-2 % of its frequency are compared (relative to the larger). One number for
/// the whole range, so that a resonance smaller than the largest (and maybe the one that
/// needs more harmonics) counts; a fold's local maximum beside a taller peak compares that
/// peak. 1 when a peak has no counterpart at all.
double peaks_change(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b);

/// The largest shift [Hz] of a resonance peak between two curves, over the same peaks as
/// peaks_change (the frequency of each curve's window peak).
double peaks_shift_hz(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b);

}  // namespace shroudsim::app
