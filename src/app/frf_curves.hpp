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

/// Richardson extrapolation of a mesh ladder (`study --convergence`).
struct MeshConvergence {
  bool monotone = false;     ///< the last three values change in one direction, shrinking
  double order = 0.0;        ///< observed order p: |e_k| ~ h^p
  double extrapolated = 0.0; ///< finest + e2 / (r^p - 1)
  double case_error = 0.0;   ///< |first value - best estimate| / |best estimate|
};

/// From values on sizes h, h / r, h / r^2, ... (coarse to fine, at least three): with e1, e2
/// the last two changes, p = ln(e1 / e2) / ln r and the extrapolated value
/// finest + e2 / (r^p - 1) when they have one sign and shrink. Otherwise (not yet in the
/// asymptotic range) the best estimate is the finest value, and the error of the first
/// (the case's) value is taken against it.
MeshConvergence mesh_convergence(const std::vector<double>& values, double r);

}  // namespace shroudsim::app
