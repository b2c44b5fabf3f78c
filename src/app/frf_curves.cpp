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

double peaks_change(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) {
  double worst = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& x = pass == 0 ? a : b;
    const auto& y = pass == 0 ? b : a;
    double top = 0.0;
    for (const auto& p : x) top = std::max(top, p.second);
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double v = x[i].second;
      if (v < 0.2 * top || (i > 0 && x[i - 1].second > v) || (i + 1 < x.size() && x[i + 1].second > v)) continue;
      // Window peaks of both curves (a fold's local maximum next to a taller peak compares
      // that peak, in both).
      double mine = 0.0, other = 0.0;
      for (const auto& q : x)
        if (std::abs(q.first - x[i].first) <= 0.02 * x[i].first) mine = std::max(mine, q.second);
      for (const auto& q : y)
        if (std::abs(q.first - x[i].first) <= 0.02 * x[i].first) other = std::max(other, q.second);
      worst = std::max(worst, other > 0 ? std::abs(mine - other) / std::max(mine, other) : 1.0);
    }
  }
  return worst;
}

}  // namespace shroudsim::app
