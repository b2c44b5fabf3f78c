#include "study/curves.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace shroudsim::study {

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

}  // namespace shroudsim::study
