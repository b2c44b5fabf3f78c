#pragma once
// Forced-response curves as written to frf.csv, read back (`study --convergence` compares
// its runs' curves with forced::peaks_change), and the mesh ladder's Richardson estimate.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "forced/discretization_search.hpp"

namespace shroudsim::study {

/// The whole file as text ("" when it cannot be read).
std::string read_file(const std::filesystem::path& p);

/// (frequency [Hz], amplitude [m]) of every row of an frf.csv, in continuation order.
std::vector<std::pair<double, double>> read_curve(const std::filesystem::path& file);

/// Curve comparison (peaks_change, peaks_shift_hz) lives in forced/discretization_search.hpp.
using forced::peaks_change;
using forced::peaks_shift_hz;

/// Richardson extrapolation of a mesh ladder (`study --convergence`).
struct MeshConvergence {
  bool monotone = false;      ///< the last three values change in one direction, shrinking
  double order = 0.0;         ///< observed order p: |e_k| ~ h^p
  double extrapolated = 0.0;  ///< finest + e2 / (r^p - 1)
  double case_error = 0.0;    ///< |first value - best estimate| / |best estimate|
};

/// From values on sizes h, h / r, h / r^2, ... (coarse to fine, at least three): with e1, e2
/// the last two changes, p = ln(e1 / e2) / ln r and the extrapolated value
/// finest + e2 / (r^p - 1) when they have one sign and shrink. Otherwise (not yet in the
/// asymptotic range) the best estimate is the finest value, and the error of the first
/// (the case's) value is taken against it.
MeshConvergence mesh_convergence(const std::vector<double>& values, double r);

}  // namespace shroudsim::study
