// The engine-order crossings of campbell/campbell.hpp against closed forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "campbell/campbell.hpp"

using namespace shroudsim;

namespace {
// Every speed solved, frequencies f(s) per mode given by a function of the speed.
campbell::HarmonicSweep sweep_of(const std::vector<double>& rpm, const std::function<Eigen::VectorXd(double)>& f) {
  campbell::HarmonicSweep s;
  for (double r : rpm) s.f.push_back(f(r));
  return s;
}
}  // namespace

TEST(Campbell, SpeedPointsEndExactlyAtTheTopSpeed) {
  const std::vector<double> rpm = campbell::speed_points(0.0, 3600.0, 13);
  ASSERT_EQ(rpm.size(), 13u);
  EXPECT_EQ(rpm.front(), 0.0);
  EXPECT_EQ(rpm.back(), 3600.0);
  EXPECT_DOUBLE_EQ(rpm[1], 300.0);
}

TEST(Campbell, FlatLinesCrossAtSixtyFOverE) {
  // Frequencies independent of speed: the crossing is exactly s = 60 f / e (linear g).
  const std::vector<double> rpm = campbell::speed_points(0.0, 10000.0, 7);
  std::map<int, campbell::HarmonicSweep> sweeps;
  sweeps[1] = sweep_of(rpm, [](double) { return Eigen::Vector2d(40.0, 95.0); });
  sweeps[2] = sweep_of(rpm, [](double) { return Eigen::Vector2d(70.0, 150.0); });
  // Nb = 8: EO 1 -> h 1, EO 7 -> h 7 (ND 1, canonical 1), EO 2 -> ND 2, EO 10 -> h 2 (ND 2).
  const auto rows = campbell::crossings(rpm, sweeps, {1, 2, 7, 10}, 8);
  // EO 1: 40 Hz at 2400 rpm, 95 Hz at 5700 rpm; EO 2: 70 Hz at 2100, 150 Hz at 4500;
  // EO 7: 40 Hz at 342.86, 95 Hz at 814.29; EO 10: 70 Hz at 420, 150 Hz at 900.
  ASSERT_EQ(rows.size(), 8u);
  for (const campbell::Crossing& x : rows) {
    EXPECT_NEAR(x.speed_rpm * x.engine_order / 60.0, x.frequency_hz, 1e-9 * x.frequency_hz);
    const double f = (x.engine_order % 8 == 1 || x.engine_order % 8 == 7) ? (x.mode == 1 ? 40.0 : 95.0)
                                                                          : (x.mode == 1 ? 70.0 : 150.0);
    EXPECT_NEAR(x.frequency_hz, f, 1e-9 * f) << "EO " << x.engine_order << " mode " << x.mode;
    EXPECT_EQ(x.nodal_diameter, x.engine_order % 8 == 2 ? 2 : (x.engine_order == 10 ? 2 : 1));
  }
  EXPECT_TRUE(std::is_sorted(rows.begin(), rows.end()));
}

TEST(Campbell, StiffeningLineCrossesWhereTheInterpolatedGapVanishes) {
  // f(s) = 50 + 0.01 s [Hz] is linear in s, so the interpolated crossing is exact:
  // 50 + 0.01 s = e s / 60  ->  s = 50 / (e / 60 - 0.01).
  const std::vector<double> rpm = campbell::speed_points(0.0, 12000.0, 5);
  std::map<int, campbell::HarmonicSweep> sweeps;
  sweeps[3] = sweep_of(rpm, [](double s) { return Eigen::VectorXd::Constant(1, 50.0 + 0.01 * s); });
  const auto rows = campbell::crossings(rpm, sweeps, {3}, 12);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NEAR(rows[0].speed_rpm, 50.0 / (3.0 / 60.0 - 0.01), 1e-9);
  EXPECT_EQ(rows[0].nodal_diameter, 3);
}

TEST(Campbell, AFailedSweepCountsOnlyTheSpeedsBeforeItsFirstMissingOne) {
  const std::vector<double> rpm = campbell::speed_points(0.0, 6000.0, 4);  // 0, 2000, 4000, 6000
  std::map<int, campbell::HarmonicSweep> sweeps;
  campbell::HarmonicSweep s = sweep_of(rpm, [](double) { return Eigen::VectorXd::Constant(1, 60.0); });
  s.f[2] = Eigen::VectorXd();  // failed at 4000 rpm: the crossing at 3600 rpm (EO 1) is lost
  sweeps[1] = s;
  EXPECT_TRUE(campbell::crossings(rpm, sweeps, {1}, 8).empty());
  // EO 2 crosses at 1800 rpm, inside the converged part.
  const auto rows = campbell::crossings(rpm, sweeps, {2}, 8);
  EXPECT_TRUE(rows.empty());  // EO 2 excites h = 2, which has no sweep
  sweeps[2] = s;
  ASSERT_EQ(campbell::crossings(rpm, sweeps, {2}, 8).size(), 1u);
  EXPECT_NEAR(campbell::crossings(rpm, sweeps, {2}, 8)[0].speed_rpm, 1800.0, 1e-9);
}
