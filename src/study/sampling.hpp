#pragma once
// Sampled studies (`[study] sample`): points of the unit cube by plain random numbers, a Latin
// hypercube or a Sobol sequence, mapped to each uncertain input's distribution, and the
// statistics of a result over the points: mean, standard deviation, percentiles, the
// probability of exceeding a threshold (with its 95 % Wilson interval) and Spearman's rank
// correlation with each input (docs/contract.md, "Sampled studies").
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/case.hpp"

namespace shroudsim::study {

/// The case's study.method (one enum for the case file and the sampler).
using SampleMethod = io::SampleMethod;
using io::to_string;

/// One uncertain input: uniform on [a, b], normal with mean a and standard deviation b, or
/// lognormal with median a and standard deviation b of its logarithm.
struct Distribution {
  enum class Kind { uniform, normal, lognormal };
  Kind kind = Kind::uniform;
  double a = 0.0, b = 1.0;
  /// The value with cumulative probability u in (0, 1).
  double quantile(double u) const;
  /// "uniform on [0.1, 0.5]", ...
  std::string describe() const;
};

/// n points of the unit cube [0, 1)^dims (row i = point i), every coordinate in (0, 1):
///   random          independent uniforms (std::mt19937_64 seeded with `seed`);
///   latin_hypercube each coordinate has exactly one point in each of the n strata [k/n, (k+1)/n),
///                   the strata of each dimension in a random order and the point uniform in its
///                   stratum (same generator);
///   sobol           the Sobol sequence (boost::random::sobol, Joe-Kuo directions), starting
///                   `seed` points in; at most boost's maximum dimension.
/// Throws std::invalid_argument for n < 1, dims < 1 or too many Sobol dimensions.
std::vector<std::vector<double>> unit_samples(SampleMethod method, int n, int dims, std::uint64_t seed);

/// Standard normal quantile Phi^-1(u), u in (0, 1).
double normal_quantile(double u);

struct SampleStatistics {
  int count = 0;
  double mean = 0.0, std_dev = 0.0, min = 0.0, max = 0.0;
  double p05 = 0.0, p25 = 0.0, p50 = 0.0, p75 = 0.0, p95 = 0.0;  ///< linear interpolation between order statistics
};
/// Throws std::invalid_argument for no values.
SampleStatistics summarize(std::vector<double> values);
/// The p-quantile (0 <= p <= 1) of sorted values, by linear interpolation (type 7).
double percentile(const std::vector<double>& sorted, double p);

/// The share of values above threshold and its 95 % Wilson score interval.
struct Exceedance {
  double probability = 0.0, low = 0.0, high = 0.0;
  int above = 0, count = 0;
};
Exceedance exceedance(const std::vector<double>& values, double threshold);

/// Spearman's rank correlation of x and y (average ranks for ties); nullopt when fewer than 3
/// pairs or when either has no spread.
std::optional<double> spearman(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace shroudsim::study
