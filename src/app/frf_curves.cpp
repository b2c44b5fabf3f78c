#include "app/frf_curves.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace shroudsim::app {

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::pair<double, double>> read_curve(const std::filesystem::path& file) {
  std::vector<std::pair<double, double>> curve;
  std::istringstream in(read_file(file));
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string f, a;
    if (std::getline(row, f, ',') && std::getline(row, a, ',')) curve.emplace_back(std::stod(f), std::stod(a));
  }
  return curve;
}

namespace {

/// For every local maximum of either curve at least 20 % of its largest: the window peaks
/// (amplitude, frequency) of both curves within +-2 % of its frequency.
struct PeakPair {
  double a = 0.0, fa = 0.0, b = 0.0, fb = 0.0;
};
std::vector<PeakPair> peak_pairs(const std::vector<std::pair<double, double>>& a,
                                 const std::vector<std::pair<double, double>>& b) {
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

double peaks_change(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) {
  double worst = 0.0;
  for (const auto& p : peak_pairs(a, b))
    worst = std::max(worst, p.a > 0 && p.b > 0 ? std::abs(p.a - p.b) / std::max(p.a, p.b) : 1.0);
  return worst;
}

double peaks_shift_hz(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) {
  double worst = 0.0;
  for (const auto& p : peak_pairs(a, b))
    if (p.a > 0 && p.b > 0) worst = std::max(worst, std::abs(p.fa - p.fb));
  return worst;
}

MeshConvergence mesh_convergence(const std::vector<double>& peaks, double r) {
  MeshConvergence mc;
  const std::size_t n = peaks.size();
  if (n == 0) return mc;
  if (n < 3) {
    mc.case_error = peaks.back() != 0.0 ? std::abs(peaks.front() - peaks.back()) / std::abs(peaks.back()) : 0.0;
    return mc;
  }
  const double e1 = peaks[n - 2] - peaks[n - 3], e2 = peaks[n - 1] - peaks[n - 2];
  double best = peaks[n - 1];
  if (e1 * e2 > 0 && std::abs(e2) < std::abs(e1)) {
    mc.monotone = true;
    mc.order = std::log(e1 / e2) / std::log(r);
    mc.extrapolated = peaks[n - 1] + e2 / (std::pow(r, mc.order) - 1.0);
    best = mc.extrapolated;
  }
  mc.case_error = best != 0.0 ? std::abs(peaks.front() - best) / std::abs(best) : 0.0;
  return mc;
}

}  // namespace shroudsim::app
