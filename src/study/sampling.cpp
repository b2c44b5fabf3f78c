#include "study/sampling.hpp"

#include <algorithm>
#include <boost/math/special_functions/erf.hpp>
#include <boost/random/sobol.hpp>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

namespace shroudsim::study {

double normal_quantile(double u) { return std::sqrt(2.0) * boost::math::erf_inv(2.0 * u - 1.0); }

double Distribution::quantile(double u) const {
  switch (kind) {
    case Kind::uniform: return a + u * (b - a);
    case Kind::normal: return a + b * normal_quantile(u);
    case Kind::lognormal: return a * std::exp(b * normal_quantile(u));
  }
  return a;
}

std::string Distribution::describe() const {
  std::ostringstream s;
  s.precision(6);
  switch (kind) {
    case Kind::uniform: s << "uniform on [" << a << ", " << b << "]"; break;
    case Kind::normal: s << "normal, mean " << a << ", std " << b; break;
    case Kind::lognormal: s << "lognormal, median " << a << ", log std " << b; break;
  }
  return s.str();
}

std::vector<std::vector<double>> unit_samples(SampleMethod method, int n, int dims, std::uint64_t seed) {
  if (n < 1 || dims < 1) throw std::invalid_argument("unit_samples: n and dims must be positive");
  std::vector<std::vector<double>> u(static_cast<std::size_t>(n), std::vector<double>(static_cast<std::size_t>(dims)));
  std::mt19937_64 gen(seed);
  // (0, 1): a zero would map to an infinite normal quantile.
  std::uniform_real_distribution<double> open01(std::nextafter(0.0, 1.0), 1.0);
  switch (method) {
    case SampleMethod::random:
      for (auto& row : u)
        for (double& x : row) x = open01(gen);
      break;
    case SampleMethod::latin_hypercube:
      for (int d = 0; d < dims; ++d) {
        std::vector<int> strata(static_cast<std::size_t>(n));
        std::iota(strata.begin(), strata.end(), 0);
        std::shuffle(strata.begin(), strata.end(), gen);
        for (int i = 0; i < n; ++i)
          u[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)] =
              (strata[static_cast<std::size_t>(i)] + open01(gen)) / n;
      }
      break;
    case SampleMethod::sobol: {
      if (static_cast<unsigned>(dims) > boost::random::default_sobol_table::max_dimension)
        throw std::invalid_argument("unit_samples: more dimensions than the Sobol table has");
      boost::random::sobol engine(static_cast<std::size_t>(dims));
      engine.discard(seed * static_cast<std::uint64_t>(dims));
      const double scale = std::ldexp(1.0, -64);
      for (auto& row : u)
        for (double& x : row) x = static_cast<double>(engine()) * scale;
      break;
    }
  }
  return u;
}

double percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) throw std::invalid_argument("percentile of no values");
  const double h = p * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

SampleStatistics summarize(std::vector<double> values) {
  if (values.empty()) throw std::invalid_argument("summarize: no values");
  std::sort(values.begin(), values.end());
  SampleStatistics s;
  s.count = static_cast<int>(values.size());
  s.mean = std::accumulate(values.begin(), values.end(), 0.0) / s.count;
  double ss = 0.0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.std_dev = s.count > 1 ? std::sqrt(ss / (s.count - 1)) : 0.0;
  s.min = values.front(), s.max = values.back();
  s.p05 = percentile(values, 0.05), s.p25 = percentile(values, 0.25), s.p50 = percentile(values, 0.5);
  s.p75 = percentile(values, 0.75), s.p95 = percentile(values, 0.95);
  return s;
}

Exceedance exceedance(const std::vector<double>& values, double threshold) {
  Exceedance e;
  e.count = static_cast<int>(values.size());
  for (double v : values) e.above += v > threshold;
  if (e.count == 0) return e;
  const double n = e.count, p = e.above / n, z = 1.959963984540054;  // Phi^-1(0.975)
  e.probability = p;
  const double centre = (p + z * z / (2 * n)) / (1 + z * z / n);
  const double half = z / (1 + z * z / n) * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n));
  // Exactly 0 (1) when none (all) are above; the formula leaves round-off there.
  e.low = e.above == 0 ? 0.0 : std::max(0.0, centre - half);
  e.high = e.above == e.count ? 1.0 : std::min(1.0, centre + half);
  return e;
}

namespace {
std::vector<double> ranks(const std::vector<double>& x) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  std::vector<double> r(x.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && x[order[j + 1]] == x[order[i]]) ++j;
    const double mean_rank = 0.5 * static_cast<double>(i + j) + 1.0;
    for (std::size_t k = i; k <= j; ++k) r[order[k]] = mean_rank;
    i = j + 1;
  }
  return r;
}
}  // namespace

std::optional<double> spearman(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 3) return std::nullopt;
  const std::vector<double> rx = ranks(x), ry = ranks(y);
  const double n = static_cast<double>(x.size()), mean = 0.5 * (n + 1);
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < rx.size(); ++i) {
    sxy += (rx[i] - mean) * (ry[i] - mean);
    sxx += (rx[i] - mean) * (rx[i] - mean);
    syy += (ry[i] - mean) * (ry[i] - mean);
  }
  if (sxx <= 0.0 || syy <= 0.0) return std::nullopt;
  return sxy / std::sqrt(sxx * syy);
}

}  // namespace shroudsim::study
