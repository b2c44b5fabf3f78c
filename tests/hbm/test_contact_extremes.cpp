// Extremes: each result finite and right, or the input refused with a clear message.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "contact/jenkins.hpp"
#include "contact_test_support.hpp"
#include "hbm/contact_evaluator.hpp"

namespace {

using shroudsim::contact::Model;
using shroudsim::contact::PairParameters;
using shroudsim::contact::TangentialUpdate;
using shroudsim::hbm::ContactEvaluator;
using shroudsim::hbm::ContactEvaluatorOptions;
using shroudsim::hbm::JacobianMethod;
constexpr double kPi = std::numbers::pi;

ContactEvaluatorOptions opts(Model model, TangentialUpdate update, int h, int n) {
  ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.law.model = model;
  o.law.update = update;
  o.measure_plans = false;
  return o;
}

// Analytic vs finite-difference Jacobian on random states of the contact's own scale: the
// median must stay at the clean-state level whatever the units (see test_contact_jacobian).
constexpr double kJacobianMedianTol = 1e-6;

class StiffnessExtremes : public ::testing::TestWithParam<std::tuple<double, double, Model, TangentialUpdate>> {};

TEST_P(StiffnessExtremes, FiniteAndJacobianStillExact) {
  const auto [kt, kn, model, update] = GetParam();
  const PairParameters p{
      .tangential_stiffness = kt, .normal_stiffness = kn, .friction_coefficient = 0.3, .normal_preload = 5.0};
  constexpr int kStates = 8;
  ContactEvaluator ev(opts(model, update, 3, 64), std::vector<PairParameters>(kStates, p));
  std::mt19937 rng(99);
  const int s = ev.pair_layout().size();
  Eigen::VectorXd w(ev.size());
  for (int i = 0; i < kStates; ++i)
    w.segment(i * s, s) = shroudsim::testing::random_contact_state(ev.pair_layout(), p, rng);
  Eigen::VectorXd fa, ff;
  std::vector<Eigen::MatrixXd> ja, jf;
  EXPECT_EQ(ev.evaluate(w, fa, &ja, JacobianMethod::analytic).unconverged_pairs, 0);
  ev.evaluate(w, ff, &jf, JacobianMethod::finite_difference);
  ASSERT_TRUE(fa.allFinite());
  std::vector<double> err;
  for (int i = 0; i < kStates; ++i) {
    ASSERT_TRUE(ja[i].allFinite());
    err.push_back(shroudsim::testing::relative_error(ja[i], jf[i]));
  }
  EXPECT_LE(shroudsim::testing::median(err), kJacobianMedianTol);
  // A circular orbit of radius 3 mu N0/kt at constant N: |T| = mu N0 at every sample
  // (docs/physics.md section 6), whatever the units.
  {
    const int m = ev.pair_layout().per_direction();
    Eigen::VectorXd wc = Eigen::VectorXd::Zero(s);
    const double r = 3.0 * 0.3 * 5.0 / kt;
    wc[1] = r;
    wc[m + 2] = r;
    shroudsim::hbm::PairDetail dc;
    ev.evaluate_pair(0, wc, dc, false);
    for (int l = 0; l < dc.f.rows(); ++l) {
      if (model == Model::full3d) {
        EXPECT_NEAR(std::hypot(dc.f(l, 0), dc.f(l, 1)), 1.5, 1e-9);
      }
      EXPECT_NEAR(dc.f(l, 2), 5.0, 1e-12);
    }
  }
  // Forces bounded by the physics: |T| <= mu N, N >= 0 at every sample.
  shroudsim::hbm::PairDetail d;
  ev.evaluate_pair(0, w.head(s), d, false);
  for (int l = 0; l < d.f.rows(); ++l) {
    const double t = model == Model::full3d ? std::hypot(d.f(l, 0), d.f(l, 1))
                                            : std::max(std::abs(d.f(l, 0)), std::abs(d.f(l, 1)));
    EXPECT_LE(t, 0.3 * d.f(l, 2) * (1 + 1e-12) + 1e-300);
    EXPECT_GE(d.f(l, 2), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Stiffness, StiffnessExtremes,
                         ::testing::Combine(::testing::Values(1e2, 1e12), ::testing::Values(1e2, 1e12),
                                            ::testing::Values(Model::full3d, Model::quasi3d),
                                            ::testing::Values(TangentialUpdate::radial_return,
                                                              TangentialUpdate::exact_linear)));

TEST(FrictionExtremes, MuZeroGivesNoTangentialForceMuHugeIsLinear) {
  const int h = 3, n = 64;
  for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
    PairParameters p{
        .tangential_stiffness = 1e6, .normal_stiffness = 1e6, .friction_coefficient = 0.0, .normal_preload = 1.0};
    ContactEvaluator ev(opts(Model::full3d, update, h, n), {p});
    const int m = ev.pair_layout().per_direction();
    Eigen::VectorXd w = Eigen::VectorXd::Zero(ev.size());
    w[1] = 1e-3;
    w[m + 2] = 1e-3;
    w[2 * m + 1] = 0.5e-6;  // normal force 1 +- 0.5 N, always in contact
    Eigen::VectorXd f;
    std::vector<Eigen::MatrixXd> j;
    ev.evaluate(w, f, &j);
    EXPECT_EQ(f.head(2 * m).norm(), 0.0);
    EXPECT_EQ(j[0].topRows(2 * m).norm(), 0.0);
    EXPECT_NEAR(f[2 * m], 1.0, 1e-12);
    EXPECT_NEAR(f[2 * m + 1], 0.5, 1e-12);
    p.friction_coefficient = 1e6;
    ContactEvaluator stick(opts(Model::full3d, update, h, n), {p});
    stick.evaluate(w, f, &j);
    EXPECT_NEAR(f[1], 1e3, 1e-9);  // kt x: mu N = 5e5 N > 1e3 N, pure stick
    EXPECT_NEAR(f[m + 2], 1e3, 1e-9);
    EXPECT_NEAR(j[0](1, 1), 1e6, 1e-6);
  }
}

TEST(PreloadExtremes, ZeroPreloadAndAGapThatNeverCloses) {
  const int h = 4, n = 2048;
  // N0 = 0 with z = z1 cos t: contact exactly half the period, N = kn z1 max(0, cos t):
  // F0 = A/pi, F1 = A/2, F2 = 2A/(3 pi) (clipped cosine at al = pi/2).
  PairParameters p{
      .tangential_stiffness = 1e6, .normal_stiffness = 1e6, .friction_coefficient = 0.3, .normal_preload = 0.0};
  ContactEvaluator ev(opts(Model::full3d, TangentialUpdate::exact_linear, h, n), {p});
  const int m = ev.pair_layout().per_direction();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(ev.size());
  w[1] = 2e-6;
  w[2 * m + 1] = 1e-6;
  Eigen::VectorXd f;
  std::vector<Eigen::MatrixXd> j;
  EXPECT_EQ(ev.evaluate(w, f, &j).unconverged_pairs, 0);
  ASSERT_TRUE(f.allFinite());
  ASSERT_TRUE(j[0].allFinite());
  const double amp = 1.0;                                     // kn z1 [N]
  const double tol = 2.0 * std::pow(2.0 * kPi / n, 2) * amp;  // kink sampled: O(h^2)
  EXPECT_NEAR(f[2 * m], amp / kPi, tol);
  EXPECT_NEAR(f[2 * m + 1], amp / 2.0, tol);
  EXPECT_NEAR(f[2 * m + 3], 2.0 * amp / (3.0 * kPi), tol);
  // N0 < 0 and |kn z| never reaching the gap: nothing, for every model and update.
  p.normal_preload = -2.0;
  for (Model model : {Model::full3d, Model::quasi3d})
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      ContactEvaluator gap(opts(model, update, h, 64), {p});
      gap.evaluate(w, f, &j);
      EXPECT_EQ(f.norm(), 0.0);
      EXPECT_EQ(j[0].norm(), 0.0);
    }
}

TEST(SamplingExtremes, MinimumSamplesAndFiftyHarmonics) {
  const PairParameters p{
      .tangential_stiffness = 2e5, .normal_stiffness = 5e5, .friction_coefficient = 0.4, .normal_preload = 3.0};
  for (auto [h, n] : {std::pair{5, 11}, std::pair{50, 101}, std::pair{50, 256}}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      ContactEvaluator ev(opts(Model::full3d, update, h, n), {p, p});
      std::mt19937 rng(h * 1000 + n);
      const int s = ev.pair_layout().size();
      Eigen::VectorXd w(ev.size());
      w.head(s) = shroudsim::testing::random_contact_state(ev.pair_layout(), p, rng);
      // Pair 1: small enough to stick everywhere -> exactly the linear springs, even at N = 2H+1.
      w.tail(s) = 1e-3 * w.head(s);
      Eigen::VectorXd fa, ff;
      std::vector<Eigen::MatrixXd> ja, jf;
      EXPECT_EQ(ev.evaluate(w, fa, &ja, JacobianMethod::analytic).unconverged_pairs, 0);
      ev.evaluate(w, ff, &jf, JacobianMethod::finite_difference);
      ASSERT_TRUE(fa.allFinite());
      ASSERT_TRUE(ja[0].allFinite());
      EXPECT_LE(shroudsim::testing::relative_error(ja[0], jf[0]), 1e-5) << h << " " << n;
      const int m = 2 * h + 1;
      Eigen::VectorXd lin = w.tail(s);
      lin.head(2 * m) *= p.tangential_stiffness;
      lin.tail(m) *= p.normal_stiffness;
      lin[2 * m] += p.normal_preload;
      EXPECT_LE((fa.tail(s) - lin).norm(), 1e-11 * lin.norm()) << h << " " << n;
    }
  }
}

TEST(AmplitudeExtremes, PicometreSticksMetreSlipsGrossly) {
  // kt = 1e6 N/m, Fs = 0.075 N: slip starts at 7.5e-8 m.
  const PairParameters p{
      .tangential_stiffness = 1e6, .normal_stiffness = 1e6, .friction_coefficient = 0.3, .normal_preload = 0.25};
  const double fs = 0.075;
  for (Model model : {Model::one_d, Model::full3d}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      ContactEvaluator ev(opts(model, update, 3, 512), {p});
      Eigen::VectorXd w = Eigen::VectorXd::Zero(ev.size());
      Eigen::VectorXd f;
      std::vector<Eigen::MatrixXd> j;
      w[1] = 1e-12;
      ev.evaluate(w, f, &j);
      ASSERT_TRUE(f.allFinite() && j[0].allFinite());
      EXPECT_NEAR(f[1], 1e-6, 1e-18);  // kt x
      w[1] = 1.0;
      ev.evaluate(w, f, &j);
      ASSERT_TRUE(f.allFinite() && j[0].allFinite());
      // Gross slip: the stick phase (beta ~ 5e-4 rad) is far shorter than one sample, so the
      // force is a square wave of height Fs whose two switches the samples place within one
      // step 2 pi/N: each moves a coefficient by at most (1/pi) 2 Fs (2 pi/N), hence 8 Fs/N.
      const auto ref = shroudsim::contact::jenkins_single_harmonic(1e6, fs, 0.0, 1.0, 0.0);
      EXPECT_NEAR(f[1], ref.fc, 8.0 * fs / 512);
      EXPECT_NEAR(f[2], ref.fs, 8.0 * fs / 512);
    }
  }
}

TEST(InputRefusal, BadOptionsAndParametersAreNamed) {
  auto message = [](const ContactEvaluatorOptions& o, const PairParameters& p) {
    try {
      ContactEvaluator ev(o, {p});
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const PairParameters ok;
  auto o = opts(Model::full3d, TangentialUpdate::exact_linear, 5, 10);
  EXPECT_NE(message(o, ok).find("time_samples = 10 violates: time_samples >= 2*harmonics+1 (= 11)"), std::string::npos);
  o.n_time_samples = 64;
  EXPECT_NE(message(o, {.tangential_stiffness = 0.0}).find("tangential_stiffness > 0"), std::string::npos);
  EXPECT_NE(message(o, {.normal_stiffness = -1e6}).find("normal_stiffness > 0"), std::string::npos);
  EXPECT_NE(message(o, {.friction_coefficient = -0.1}).find("friction_coefficient >= 0"), std::string::npos);
  EXPECT_NE(message(o, {.normal_preload = INFINITY}).find("normal_preload"), std::string::npos);
  EXPECT_NE(message(opts(Model::one_d_exact, TangentialUpdate::exact_linear, 2, 64), ok).find("harmonics = 1"),
            std::string::npos);
  EXPECT_NE(message(opts(Model::one_d, TangentialUpdate::exact_linear, 2, 64), {.normal_preload = -1.0})
                .find("normal_preload >= 0"),
            std::string::npos);
  ContactEvaluator ev(o, {ok});
  Eigen::VectorXd w = Eigen::VectorXd::Zero(ev.size()), f;
  w[3] = std::nan("");
  EXPECT_THROW(ev.evaluate(w, f, nullptr), std::invalid_argument);
}

}  // namespace
