// Richardson extrapolation of `study --convergence`'s mesh ladder (study/curves.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "study/curves.hpp"

namespace shroudsim::study {
namespace {

TEST(MeshConvergence, RecoversOrderAndLimitOfAPowerLaw) {
  const double r = std::cbrt(2.0);
  for (double p : {1.0, 2.0, 3.5})
    for (double c : {-0.3, 0.2}) {
      // f(h) = f0 + c h^p on h = 1, 1/r, 1/r^2, 1/r^3.
      const double f0 = 6.9e-5;
      std::vector<double> v;
      for (int i = 0; i < 4; ++i) v.push_back(f0 * (1.0 + c * std::pow(r, -p * i)));
      const MeshConvergence mc = mesh_convergence(v, r);
      ASSERT_TRUE(mc.monotone);
      EXPECT_NEAR(mc.order, p, 1e-9 * p);
      EXPECT_NEAR(mc.extrapolated, f0, 1e-12 * f0);
      EXPECT_NEAR(mc.case_error, std::abs(c), 1e-9);
    }
}

TEST(MeshConvergence, OscillatingLadderIsNotExtrapolated) {
  // The last three changes alternate in sign: no order; the error is against the finest.
  const MeshConvergence mc = mesh_convergence({7.25, 6.81, 7.03, 6.91}, std::cbrt(2.0));
  EXPECT_FALSE(mc.monotone);
  EXPECT_NEAR(mc.case_error, (7.25 - 6.91) / 6.91, 1e-14);
  // Growing changes are not in the asymptotic range either.
  EXPECT_FALSE(mesh_convergence({1.0, 1.1, 1.3}, 2.0).monotone);
}

}  // namespace
}  // namespace shroudsim::study
