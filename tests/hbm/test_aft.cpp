// HarmonicLayout ordering and the FFTW-based AFT transforms.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "hbm/aft.hpp"
#include "hbm/harmonic_layout.hpp"

namespace {

using shroudsim::hbm::Aft;
using shroudsim::hbm::HarmonicLayout;
// Transforms of length <= 1024 on O(1) data: a few ulps times log N.
constexpr double kRoundOff = 1e-13;

TEST(HarmonicLayout, OrderIsMeanThenCosineSinePairsPerDirection) {
  const HarmonicLayout l(3, 3);
  EXPECT_EQ(l.per_direction(), 7);
  EXPECT_EQ(l.size(), 21);
  EXPECT_EQ(l.index(0, 0), 0);
  EXPECT_EQ(l.index(0, 1, HarmonicLayout::Part::cosine), 1);
  EXPECT_EQ(l.index(0, 1, HarmonicLayout::Part::sine), 2);
  EXPECT_EQ(l.index(1, 3, HarmonicLayout::Part::sine), 13);
  EXPECT_EQ(l.index(2, 0), 14);
  EXPECT_EQ(l.min_time_samples(), 7);
  EXPECT_THROW(l.index(0, 0, HarmonicLayout::Part::sine), std::out_of_range);
  EXPECT_THROW(l.index(3, 0), std::out_of_range);
  EXPECT_THROW(HarmonicLayout(-1, 1), std::invalid_argument);
}

class AftRoundTrip : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(AftRoundTrip, TimeThenHarmonicsIsIdentityAndMatchesTheSeries) {
  const auto [h, n] = GetParam();
  const Aft aft(h, {.n_time_samples = n, .measure_plans = false});
  Aft::Workspace ws(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd c(2 * h + 1), back(2 * h + 1);
  for (int i = 0; i < c.size(); ++i) c[i] = u(rng);
  Eigen::VectorXd x(n);
  aft.to_time(c.data(), x.data(), ws);
  for (int l = 0; l < n; ++l) {
    double ref = c[0];
    for (int k = 1; k <= h; ++k) {
      const double t = 2.0 * std::numbers::pi * k * l / n;
      ref += c[2 * k - 1] * std::cos(t) + c[2 * k] * std::sin(t);
    }
    EXPECT_NEAR(x[l], ref, kRoundOff * h);
  }
  EXPECT_LE((aft.synthesis() * c - x).norm(), kRoundOff * x.norm());
  aft.to_harmonics(x.data(), back.data(), ws);
  EXPECT_LE((back - c).norm(), kRoundOff * c.norm());
  EXPECT_LE((aft.analysis().transpose() * x - c).norm(), kRoundOff * c.norm());
}

INSTANTIATE_TEST_SUITE_P(Sizes, AftRoundTrip,
                         ::testing::Values(std::pair{0, 1}, std::pair{1, 3}, std::pair{5, 11}, std::pair{5, 512},
                                           std::pair{7, 15}, std::pair{15, 64}, std::pair{50, 101},
                                           std::pair{50, 1024}));

// A^T diag(w) E from one FFT of w equals the direct product, also at N = 2H+1 where the
// frequencies up to 2H wrap past N/2.
TEST(Aft, WeightedGramEqualsTheDirectProduct) {
  for (auto [h, n] : {std::pair{5, 11}, std::pair{5, 64}, std::pair{15, 40}, std::pair{50, 512}}) {
    const Aft aft(h, {.n_time_samples = n, .measure_plans = false});
    Aft::Workspace ws(n);
    std::mt19937 rng(h + n);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::VectorXd w(n);
    for (int l = 0; l < n; ++l) w[l] = u(rng);
    Eigen::MatrixXd gram(2 * h + 1, 2 * h + 1);
    aft.weighted_gram(w.data(), gram, ws);
    const Eigen::MatrixXd direct = aft.analysis().transpose() * w.asDiagonal() * aft.synthesis();
    EXPECT_LE((gram - direct).norm(), kRoundOff * 10 * direct.norm()) << h << " " << n;
  }
}

TEST(Aft, RefusesTooFewSamplesClearly) {
  try {
    Aft aft(5, {.n_time_samples = 10});
    FAIL() << "N = 10 < 2H+1 = 11 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("time_samples >= 2*harmonics+1 (= 11)"), std::string::npos);
  }
  EXPECT_NO_THROW(Aft(5, {.n_time_samples = 11, .measure_plans = false}));
}

}  // namespace
