// Static contact with interference and Coulomb friction against closed forms: one pair on
// springs (flexibility C = diag(ct, ct, cn)), then a coupled random flexibility.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "contact/static_contact.hpp"

namespace shroudsim::contact {
namespace {

// Converged solves end at 1e-10 of the problem's length scale; closed forms are checked to
// a few times that.
constexpr double kRel = 1e-9;

StaticPairParameters pair(double delta) {
  StaticPairParameters p;
  p.normal_stiffness = 2e6;
  p.tangential_stiffness = 5e5;
  p.friction_coefficient = 0.4;
  p.interference = delta;
  return p;
}

TEST(StaticContact, InterferenceLoadIsLinearWhileClosedAndZeroWhenOpen) {
  const double ct = 1e-6, cn = 2e-6;
  const Eigen::Matrix3d C = Eigen::Vector3d(ct, ct, cn).asDiagonal();
  for (double delta : {-1e-5, -1e-9, 0.0, 1e-9, 1e-6, 2e-6, 1e-3}) {
    StaticContact sc({pair(delta)});
    const StaticStep st = sc.solve(C, Eigen::Vector3d::Zero());
    ASSERT_TRUE(st.converged) << st.message;
    const auto& r = sc.pairs()[0];
    const double kn = pair(delta).normal_stiffness;
    if (delta > 0) {
      // N = kn (delta + g_n), g_n = -cn N  ->  N = kn delta / (1 + kn cn).
      EXPECT_NEAR(r.force[2], kn * delta / (1 + kn * cn), kRel * kn * delta) << delta;
      EXPECT_EQ(r.state, StaticState::stick);
      EXPECT_EQ(r.gap, 0.0);
    } else {
      EXPECT_EQ(r.force[2], 0.0) << delta;
      EXPECT_EQ(r.state, StaticState::open);
      EXPECT_NEAR(r.gap, -delta, 1e-18);
    }
    EXPECT_EQ(r.force.head<2>().norm(), 0.0);
  }
}

TEST(StaticContact, TangentialLoadSticksUpToTheSlipThresholdThenSlides) {
  const double ct = 1e-6, cn = 2e-6, delta = 1e-5;
  const Eigen::Matrix3d C = Eigen::Vector3d(ct, ct, cn).asDiagonal();
  const StaticPairParameters p = pair(delta);
  const double N = p.normal_stiffness * delta / (1 + p.normal_stiffness * cn);
  const double threshold = p.friction_coefficient * N * (1 + p.tangential_stiffness * ct) / p.tangential_stiffness;
  StaticContact sc({p});
  const Eigen::Vector2d dir = Eigen::Vector2d(3, -4).normalized();
  // Load the tangential motion in 20 increments to 1.5 times the threshold.
  for (int k = 1; k <= 20; ++k) {
    const double a = 1.5 * threshold * k / 20;
    Eigen::Vector3d g_ext;
    g_ext << a * dir, 0.0;
    ASSERT_TRUE(sc.solve(C, g_ext).converged) << k;
    const auto& r = sc.pairs()[0];
    EXPECT_NEAR(r.force[2], N, kRel * N);
    const double stuck = p.tangential_stiffness * a / (1 + p.tangential_stiffness * ct);
    if (a < threshold * (1 - 1e-9)) {
      EXPECT_EQ(r.state, StaticState::stick) << k;
      EXPECT_NEAR(r.force.head<2>().norm(), stuck, kRel * stuck) << k;
    } else if (a > threshold * (1 + 1e-9)) {
      EXPECT_EQ(r.state, StaticState::slip) << k;
      EXPECT_NEAR(r.force.head<2>().norm(), p.friction_coefficient * N, kRel * N) << k;
    }
    EXPECT_NEAR(r.force.head<2>().normalized().dot(dir), 1.0, 1e-12);
  }
  // Unloaded back to zero tangential motion the slider stays where it slid: a locked-in
  // tangential load -kt s / (1 + kt ct) = -0.5 mu N, stuck (a reversal of twice the
  // threshold would slip back).
  const Eigen::Vector2d s = sc.pairs()[0].slider;
  ASSERT_TRUE(sc.solve(C, Eigen::Vector3d::Zero()).converged);
  const auto& r = sc.pairs()[0];
  const Eigen::Vector2d locked = -p.tangential_stiffness * s / (1 + p.tangential_stiffness * ct);
  EXPECT_EQ(r.state, StaticState::stick);
  EXPECT_LT((r.force.head<2>() - locked).norm(), kRel * N);
  EXPECT_NEAR(locked.norm(), 0.5 * p.friction_coefficient * N, kRel * N);
}

// Several pairs coupled by a random SPD flexibility: the solution is a fixed point of the
// law (g = g_ext - C F(g)) and every pair's state is consistent.
TEST(StaticContact, CoupledPairsSatisfyTheLawAndTheFlexibility) {
  const int P = 6;
  std::srand(5);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(3 * P, 3 * P);
  const Eigen::MatrixXd C = 1e-6 * (A * A.transpose() / (3 * P) + 0.1 * Eigen::MatrixXd::Identity(3 * P, 3 * P));
  std::vector<StaticPairParameters> ps;
  for (int i = 0; i < P; ++i) ps.push_back(pair(i % 3 == 0 ? -2e-6 : 1e-6 * (1 + i)));
  StaticContact sc(ps);
  Eigen::VectorXd g_ext = 3e-6 * Eigen::VectorXd::Random(3 * P);
  for (int k = 1; k <= 5; ++k) {
    const StaticStep st = sc.solve(C, g_ext * k / 5.0);
    ASSERT_TRUE(st.converged) << st.message;
  }
  Eigen::VectorXd g(3 * P);
  for (int i = 0; i < P; ++i) g.segment<3>(3 * i) = sc.pairs()[i].g;
  EXPECT_LT((g - g_ext + C * sc.forces()).lpNorm<Eigen::Infinity>(), 1e-9 * g_ext.lpNorm<Eigen::Infinity>());
  int closed = 0;
  for (int i = 0; i < P; ++i) {
    const auto& r = sc.pairs()[i];
    const double pen = ps[i].interference + r.g[2];
    if (r.state == StaticState::open) {
      EXPECT_LE(pen, 0.0);
      EXPECT_EQ(r.force.norm(), 0.0);
    } else {
      ++closed;
      EXPECT_NEAR(r.force[2], ps[i].normal_stiffness * pen, 1e-12 * r.force[2]);
      EXPECT_LE(r.force.head<2>().norm(), ps[i].friction_coefficient * r.force[2] * (1 + 1e-12));
    }
  }
  EXPECT_GT(closed, 0);
}

TEST(StaticContact, NothingIsLoadedWithoutInterferenceOrLoad) {
  const int P = 4;
  const Eigen::MatrixXd C = 1e-6 * Eigen::MatrixXd::Identity(3 * P, 3 * P);
  StaticContact sc(std::vector<StaticPairParameters>(P, pair(0.0)));
  ASSERT_TRUE(sc.solve(C, Eigen::VectorXd::Zero(3 * P)).converged);
  EXPECT_EQ(sc.forces().norm(), 0.0);
}

TEST(StaticContact, SlipJacobianMatchesFiniteDifferences) {
  const StaticPairParameters p = pair(1e-6);
  const Eigen::Vector3d g(3e-6, -2e-6, 5e-7);
  const Eigen::Vector2d s(-1e-6, 0.5e-6);
  StaticState state;
  Eigen::Matrix3d dF;
  StaticContact::law(p, g, s, &state, &dF);
  ASSERT_EQ(state, StaticState::slip);
  const double h = 1e-12;
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d gp = g, gm = g;
    gp[j] += h, gm[j] -= h;
    const Eigen::Vector3d fd =
        (StaticContact::law(p, gp, s, nullptr, nullptr) - StaticContact::law(p, gm, s, nullptr, nullptr)) / (2 * h);
    EXPECT_LT((fd - dF.col(j)).norm(), 1e-5 * dF.norm()) << j;
  }
}

TEST(StaticContact, BadParametersAreRefused) {
  StaticPairParameters p = pair(0.0);
  p.normal_stiffness = 0.0;
  EXPECT_THROW(StaticContact({p}), std::invalid_argument);
  p = pair(std::nan(""));
  EXPECT_THROW(StaticContact({p}), std::invalid_argument);
  p = pair(0.0);
  p.friction_coefficient = -0.1;
  EXPECT_THROW(StaticContact({p}), std::invalid_argument);
}

}  // namespace
}  // namespace shroudsim::contact
