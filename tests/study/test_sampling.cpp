// Sampling and statistics of sampled studies (study/sampling.hpp) against properties that hold
// exactly (Latin hypercube strata, the Sobol sequence's first points, Spearman's extremes) and
// closed forms (normal quantiles, moments of large samples, the Wilson interval).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "study/sampling.hpp"

namespace shroudsim::study {
namespace {

TEST(Sampling, ALatinHypercubeHasOnePointInEveryStratumOfEveryInput) {
  constexpr int n = 37, dims = 4;
  const auto u = unit_samples(SampleMethod::latin_hypercube, n, dims, 7);
  ASSERT_EQ(u.size(), static_cast<std::size_t>(n));
  for (int d = 0; d < dims; ++d) {
    std::vector<int> count(n, 0);
    for (const auto& row : u) {
      ASSERT_GT(row[d], 0.0);
      ASSERT_LT(row[d], 1.0);
      ++count[static_cast<std::size_t>(std::floor(row[d] * n))];
    }
    for (int c : count) EXPECT_EQ(c, 1) << "dimension " << d;
  }
}

TEST(Sampling, TheSameSeedGivesTheSamePointsAndAnotherSeedOthers) {
  for (SampleMethod m : {SampleMethod::random, SampleMethod::latin_hypercube, SampleMethod::sobol}) {
    EXPECT_EQ(unit_samples(m, 10, 3, 1), unit_samples(m, 10, 3, 1)) << to_string(m);
    EXPECT_NE(unit_samples(m, 10, 3, 1), unit_samples(m, 10, 3, 2)) << to_string(m);
  }
}

TEST(Sampling, SobolStartsWithTheKnownPointsAndFillsDyadicBoxesExactly) {
  const auto u = unit_samples(SampleMethod::sobol, 4, 2, 0);
  const double expected[4][2] = {{0.5, 0.5}, {0.75, 0.25}, {0.25, 0.75}, {0.375, 0.375}};
  for (int i = 0; i < 4; ++i)
    for (int d = 0; d < 2; ++d) EXPECT_EQ(u[i][d], expected[i][d]);
  // The first 16 points of the sequence are a (0, 4, 2)-net: each of the 4 x 4 boxes
  // [a/4, (a+1)/4) x [b/4, (b+1)/4) holds one. Boost skips the first, the origin: its next 15
  // fill every box but the origin's.
  const auto v = unit_samples(SampleMethod::sobol, 15, 2, 0);
  std::vector<int> box(16, 0);
  for (const auto& p : v) ++box[static_cast<std::size_t>(std::floor(p[0] * 4) * 4 + std::floor(p[1] * 4))];
  EXPECT_EQ(box[0], 0);
  for (std::size_t b = 1; b < box.size(); ++b) EXPECT_EQ(box[b], 1) << "box " << b;
}

TEST(Sampling, QuantilesMatchTheirClosedForms) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959963984540054, 1e-12);
  EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-15);
  EXPECT_NEAR(normal_quantile(0.15865525393145707), -1.0, 1e-12);
  const Distribution uni{Distribution::Kind::uniform, 0.1, 0.5};
  EXPECT_DOUBLE_EQ(uni.quantile(0.25), 0.2);
  const Distribution nor{Distribution::Kind::normal, 2.0, 0.5};
  EXPECT_NEAR(nor.quantile(0.975), 2.0 + 0.5 * 1.959963984540054, 1e-12);
  const Distribution logn{Distribution::Kind::lognormal, 3.0, 0.2};
  EXPECT_NEAR(logn.quantile(0.5), 3.0, 1e-12);
  EXPECT_NEAR(logn.quantile(0.975), 3.0 * std::exp(0.2 * 1.959963984540054), 1e-11);
}

TEST(Sampling, MomentsOfALargeSampleApproachTheDistributions) {
  // 4096 Latin hypercube points of a normal(1, 0.3): the sample mean and standard deviation
  // within 4 standard errors (stratification makes them far closer; 0.3 / 64 per error).
  const Distribution nor{Distribution::Kind::normal, 1.0, 0.3};
  std::vector<double> v;
  for (const auto& row : unit_samples(SampleMethod::latin_hypercube, 4096, 1, 3)) v.push_back(nor.quantile(row[0]));
  const SampleStatistics s = summarize(v);
  EXPECT_NEAR(s.mean, 1.0, 4 * 0.3 / 64);
  EXPECT_NEAR(s.std_dev, 0.3, 4 * 0.3 / std::sqrt(2.0 * 4096));
  EXPECT_NEAR(s.p50, 1.0, 0.02);
  EXPECT_NEAR(s.p95, 1.0 + 0.3 * 1.6448536269514722, 0.02);
}

TEST(Sampling, PercentilesInterpolateBetweenOrderStatistics) {
  const SampleStatistics s = summarize({4.0, 1.0, 3.0, 2.0, 5.0});
  EXPECT_DOUBLE_EQ(s.p50, 3.0);
  EXPECT_DOUBLE_EQ(s.p25, 2.0);
  EXPECT_DOUBLE_EQ(s.p05, 1.2);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 5.0);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_NEAR(s.std_dev, std::sqrt(2.5), 1e-15);
}

TEST(Sampling, ExceedanceAndItsWilsonInterval) {
  std::vector<double> v(100, 0.0);
  for (int i = 0; i < 20; ++i) v[static_cast<std::size_t>(i)] = 2.0;
  const Exceedance e = exceedance(v, 1.0);
  EXPECT_EQ(e.above, 20);
  EXPECT_DOUBLE_EQ(e.probability, 0.2);
  // Wilson 95 % for 20 of 100: [0.1333, 0.2888] (closed form).
  EXPECT_NEAR(e.low, 0.13330, 1e-4);
  EXPECT_NEAR(e.high, 0.28883, 1e-4);
  const Exceedance none = exceedance(v, 5.0);
  EXPECT_EQ(none.above, 0);
  EXPECT_DOUBLE_EQ(none.low, 0.0);
  EXPECT_GT(none.high, 0.0);  // none of 100 above still leaves up to ~3.7 %
}

TEST(Sampling, SpearmanIsOneForAnyIncreasingRelationAndMinusOneForDecreasing) {
  std::vector<double> x, up, down, flat;
  for (int i = 0; i < 20; ++i) {
    x.push_back(i * 0.1);
    up.push_back(std::exp(i * 0.3));
    down.push_back(-i * i);
    flat.push_back(1.0);
  }
  EXPECT_NEAR(*spearman(x, up), 1.0, 1e-15);
  EXPECT_NEAR(*spearman(x, down), -1.0, 1e-15);
  EXPECT_FALSE(spearman(x, flat).has_value());
  // With ties: x = 1 2 2 3, y = 1 3 2 4 -> ranks 1 2.5 2.5 4 and 1 3 2 4: rho = 4.5 / sqrt(4.5 * 5).
  EXPECT_NEAR(*spearman({1, 2, 2, 3}, {1, 3, 2, 4}), 4.5 / std::sqrt(4.5 * 5.0), 1e-15);
}

}  // namespace
}  // namespace shroudsim::study
