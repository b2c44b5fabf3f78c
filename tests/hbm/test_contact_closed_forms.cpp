// Contact forces against closed forms (docs/physics.md sections 4 and 6): Jenkins single
// harmonic, its convergence with N, the circular orbit, the clipped-cosine normal force,
// frame invariance, pure stick and a gap that never closes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>

#include "hbm/contact_evaluator.hpp"

namespace {

using shroudsim::contact::Model;
using shroudsim::contact::PairParameters;
using shroudsim::contact::TangentialUpdate;
using shroudsim::hbm::ContactEvaluator;
using shroudsim::hbm::ContactEvaluatorOptions;
constexpr double kPi = std::numbers::pi;

Eigen::VectorXd forces(Model model, TangentialUpdate update, int h, int n, const PairParameters& p,
                       const Eigen::VectorXd& w, std::vector<Eigen::MatrixXd>* jac = nullptr) {
  ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.law.model = model;
  o.law.update = update;
  o.measure_plans = false;
  ContactEvaluator ev(o, {p});
  Eigen::VectorXd f;
  const auto st = ev.evaluate(w, f, jac);
  EXPECT_EQ(st.unconverged_pairs, 0);
  return f;
}

// The Jenkins coefficients written out independently of the library (docs/physics.md sec. 4).
struct JenkinsRef {
  double a1, b1;
};
JenkinsRef jenkins_ref(double kt, double fs, double a) {
  if (kt * a <= fs) return {kt * a, 0.0};
  const double beta = std::acos(1.0 - 2.0 * fs / (kt * a));
  return {kt * a / kPi * (beta - std::sin(2.0 * beta) / 2.0), -4.0 * fs / kPi * (1.0 - fs / (kt * a))};
}

const PairParameters kPair{
    .tangential_stiffness = 2e5, .normal_stiffness = 5e5, .friction_coefficient = 0.4, .normal_preload = 3.0};

TEST(Jenkins, OneDExactEqualsTheClosedFormToRoundOff) {
  const double fs = kPair.friction_coefficient * kPair.normal_preload;
  const double a_slip = fs / kPair.tangential_stiffness;
  constexpr double kRoundOff = 1e-14;
  for (double ratio : {0.5, 1.0, 1.01, 2.0, 10.0, 1e4}) {
    for (double phase : {0.0, 0.3, 2.5, -1.7}) {
      const double a = ratio * a_slip;
      Eigen::VectorXd w(3);
      w << 0.1 * a_slip, a * std::cos(phase), a * std::sin(phase);
      const Eigen::VectorXd f = forces(Model::one_d_exact, TangentialUpdate::exact_linear, 1, 64, kPair, w);
      const JenkinsRef r = jenkins_ref(kPair.tangential_stiffness, fs, a);
      // Rotate (a1, b1) from the frame of the motion back: x = a cos(theta - phase).
      const double fc = r.a1 * std::cos(phase) - r.b1 * std::sin(phase);
      const double fsn = r.a1 * std::sin(phase) + r.b1 * std::cos(phase);
      const double scale = std::hypot(r.a1, r.b1);
      EXPECT_NEAR(f[1], fc, kRoundOff * 10 * scale) << ratio << " " << phase;
      EXPECT_NEAR(f[2], fsn, kRoundOff * 10 * scale) << ratio << " " << phase;
      EXPECT_NEAR(f[0], ratio <= 1.0 ? kPair.tangential_stiffness * w[0] : 0.0, kRoundOff * scale);
      // Energy per cycle 4 Fs (a - Fs/kt) in slip.
      const shroudsim::hbm::HarmonicLayout l(1, 1);
      const double e_ref = ratio > 1.0 ? 4.0 * fs * (a - fs / kPair.tangential_stiffness) : 0.0;
      EXPECT_NEAR(shroudsim::hbm::dissipated_energy(l, w, f), e_ref, 1e-12 * fs * a);
    }
  }
}

// The discrete 1d law converges to the time-continuous Jenkins force as 1/N^2. The error at
// one N oscillates with where the stick/slip switch falls between samples, so the measure is
// the worst case over 16 shifts of the sampling grid within one step, and the order is the
// least-squares slope of log(error) against log(N) over N = 32 .. 4096.
TEST(Jenkins, DiscreteOneDConvergesAtSecondOrder) {
  const double fs = kPair.friction_coefficient * kPair.normal_preload;
  for (double ratio : {1.5, 3.7}) {
    const double a = ratio * fs / kPair.tangential_stiffness;
    const JenkinsRef r = jenkins_ref(kPair.tangential_stiffness, fs, a);
    std::vector<double> lx, ly;
    for (int n = 32; n <= 4096; n *= 2) {
      double worst = 0.0;
      for (int k = 0; k < 16; ++k) {
        const double phase = 2.0 * kPi * k / (16.0 * n);
        Eigen::VectorXd w(3);
        w << 0.0, a * std::cos(phase), a * std::sin(phase);
        const Eigen::VectorXd f = forces(Model::one_d, TangentialUpdate::radial_return, 1, n, kPair, w);
        const Eigen::VectorXd g = forces(Model::one_d, TangentialUpdate::exact_linear, 1, n, kPair, w);
        EXPECT_LE((f - g).norm(), 1e-12 * f.norm());  // the 1D updates coincide
        const double fc = r.a1 * std::cos(phase) - r.b1 * std::sin(phase);
        const double fsn = r.a1 * std::sin(phase) + r.b1 * std::cos(phase);
        worst = std::max(worst, std::hypot(f[1] - fc, f[2] - fsn) / std::hypot(r.a1, r.b1));
      }
      lx.push_back(std::log(n));
      ly.push_back(std::log(worst));
    }
    const double mx = std::accumulate(lx.begin(), lx.end(), 0.0) / lx.size();
    const double my = std::accumulate(ly.begin(), ly.end(), 0.0) / ly.size();
    double sxy = 0.0, sxx = 0.0;
    for (size_t i = 0; i < lx.size(); ++i) {
      sxy += (lx[i] - mx) * (ly[i] - my);
      sxx += (lx[i] - mx) * (lx[i] - mx);
    }
    const double order = -sxy / sxx;
    // Second order expected; the fit over 8 doublings is good to about +-0.2.
    EXPECT_GT(order, 1.8) << "ratio " << ratio;
    EXPECT_LT(order, 2.2) << "ratio " << ratio;
    EXPECT_LT(std::exp(ly.back()), 1e-5);  // and small in absolute terms at N = 4096
  }
}

// Circle of radius r > mu N/kt at constant N: |T| = mu N, lead acos(mu N/(kt r)), pure first
// harmonic (the sampled orbit is invariant under a rotation by one sample, so the discrete
// steady force is too: higher harmonics vanish to round-off for both updates).
TEST(CircularOrbit, ConstantForceLeadAndNoHigherHarmonics) {
  const double fs = kPair.friction_coefficient * kPair.normal_preload;
  const double a_slip = fs / kPair.tangential_stiffness;
  const double r = 3.0 * a_slip;
  const double lead = std::acos(a_slip / r);
  const int h = 5;
  const shroudsim::hbm::HarmonicLayout layout(h, 3);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.size());
  w[layout.index(0, 1)] = r;
  w[layout.index(1, 1, shroudsim::hbm::HarmonicLayout::Part::sine)] = r;
  constexpr double kRoundOff = 1e-10;  // steady-state tolerance 1e-12 amplified by the loop
  std::vector<double> lead_err_rr, lead_err_el;
  for (int n : {256, 512, 1024}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      const Eigen::VectorXd f = forces(Model::full3d, update, h, n, kPair, w);
      const double fc = f[layout.index(0, 1)];
      const double fsn = f[layout.index(0, 1, shroudsim::hbm::HarmonicLayout::Part::sine)];
      EXPECT_NEAR(std::hypot(fc, fsn), fs, kRoundOff * fs);  // |T| = mu N at every sample
      // Tx = |T| cos(t + lead): fc = |T| cos(lead), fs = -|T| sin(lead).
      const double e = std::abs(std::atan2(-fsn, fc) - lead);
      (update == TangentialUpdate::radial_return ? lead_err_rr : lead_err_el).push_back(e);
      for (int k = 2; k <= h; ++k)
        for (int d = 0; d < 2; ++d) {
          EXPECT_NEAR(f[layout.index(d, k)], 0.0, kRoundOff * fs);
          EXPECT_NEAR(f[layout.index(d, k, shroudsim::hbm::HarmonicLayout::Part::sine)], 0.0, kRoundOff * fs);
        }
      EXPECT_NEAR(f[layout.index(2, 0)], kPair.normal_preload, kRoundOff * fs);
    }
  }
  // radial_return lags about pi/N (first order); exact_linear is second order.
  for (size_t i = 0; i < 3; ++i) {
    const double pi_over_n = kPi / (256 << i);
    EXPECT_GT(lead_err_rr[i], 0.5 * pi_over_n);
    EXPECT_LT(lead_err_rr[i], 1.5 * pi_over_n);
  }
  EXPECT_NEAR(std::log2(lead_err_rr[0] / lead_err_rr[2]) / 2.0, 1.0, 0.1);
  EXPECT_NEAR(std::log2(lead_err_el[0] / lead_err_el[2]) / 2.0, 2.0, 0.1);
}

// Unilateral spring N = max(0, N0 + A cos t), A = kn z1: for |N0| < A it is A (cos t - cos al)
// on |t| < al, cos al = -N0/A, and its Fourier coefficients are
//   F0 = (A/pi)(sin al - al cos al),  F1 = (A/pi)(al - sin al cos al),
//   Fn = (2A/pi)[sin((n-1)al)/(2(n-1)) + sin((n+1)al)/(2(n+1)) - cos al sin(n al)/n], n >= 2,
// sine coefficients zero.
TEST(NormalForce, ClippedCosineWithPreloadAndWithGap) {
  const int h = 6, n = 4096;
  const double z1 = 2e-5;
  const double amp = kPair.normal_stiffness * z1;
  const shroudsim::hbm::HarmonicLayout layout(h, 3);
  // Sampling a kinked signal: trapezoidal-rule error O((2 pi/N)^2) times the amplitude.
  const double tol = 2.0 * std::pow(2.0 * kPi / n, 2) * amp;
  for (double ratio : {0.3, 0.0, -0.3, -0.9}) {
    PairParameters p = kPair;
    p.normal_preload = ratio * amp;
    Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.size());
    w[layout.index(2, 1)] = z1;
    const Eigen::VectorXd f = forces(Model::full3d, TangentialUpdate::exact_linear, h, n, p, w);
    const double al = std::acos(-ratio);
    const double ca = std::cos(al), sa = std::sin(al);
    EXPECT_NEAR(f[layout.index(2, 0)], amp / kPi * (sa - al * ca), tol) << ratio;
    EXPECT_NEAR(f[layout.index(2, 1)], amp / kPi * (al - sa * ca), tol) << ratio;
    for (int k = 2; k <= h; ++k) {
      const double ref = 2.0 * amp / kPi *
                         (std::sin((k - 1) * al) / (2.0 * (k - 1)) + std::sin((k + 1) * al) / (2.0 * (k + 1)) -
                          ca * std::sin(k * al) / k);
      EXPECT_NEAR(f[layout.index(2, k)], ref, tol) << ratio << " n=" << k;
    }
    for (int k = 1; k <= h; ++k)
      EXPECT_NEAR(f[layout.index(2, k, shroudsim::hbm::HarmonicLayout::Part::sine)], 0.0, tol);
    EXPECT_EQ(f.head(2 * (2 * h + 1)).norm(), 0.0);  // no tangential motion, no friction force
  }
}

// Harmonics: rotating the tangential plane by psi rotates F and conjugates the Jacobian
// for full3d; quasi3d changes.
TEST(FrameInvariance, Full3dInvariantQuasi3dNot) {
  const int h = 3, n = 128;
  const shroudsim::hbm::HarmonicLayout layout(h, 3);
  const int m = layout.per_direction();
  const double a_slip = kPair.friction_coefficient * kPair.normal_preload / kPair.tangential_stiffness;
  Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.size());
  w[1] = 3 * a_slip;
  w[2] = 0.5 * a_slip;
  w[3] = 0.4 * a_slip;
  w[m + 1] = 0.7 * a_slip;
  w[m + 2] = 2.0 * a_slip;
  w[2 * m + 3] = 0.5 * kPair.normal_preload / kPair.normal_stiffness;
  const double psi = 1.1, c = std::cos(psi), s = std::sin(psi);
  Eigen::MatrixXd rot = Eigen::MatrixXd::Identity(layout.size(), layout.size());
  rot.block(0, 0, m, m) = c * Eigen::MatrixXd::Identity(m, m);
  rot.block(0, m, m, m) = -s * Eigen::MatrixXd::Identity(m, m);
  rot.block(m, 0, m, m) = s * Eigen::MatrixXd::Identity(m, m);
  rot.block(m, m, m, m) = c * Eigen::MatrixXd::Identity(m, m);
  constexpr double kInvariant = 1e-9;  // steady-state tolerance and round-off
  for (Model model : {Model::full3d, Model::quasi3d}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      std::vector<Eigen::MatrixXd> j, jr;
      const Eigen::VectorXd f = forces(model, update, h, n, kPair, w, &j);
      const Eigen::VectorXd fr = forces(model, update, h, n, kPair, rot * w, &jr);
      const double df = (rot.transpose() * fr - f).norm() / f.norm();
      const double dj = (rot.transpose() * jr[0] * rot - j[0]).norm() / j[0].norm();
      if (model == Model::full3d) {
        EXPECT_LE(df, kInvariant);
        EXPECT_LE(dj, kInvariant);
      } else {
        EXPECT_GE(df, 1e-2);  // per-axis limits: a visible change
      }
    }
  }
}

TEST(Limits, PureStickIsALinearSpringAndAGapThatNeverClosesIsNothing) {
  const int h = 4, n = 64;
  const shroudsim::hbm::HarmonicLayout layout(h, 3);
  const int m = layout.per_direction();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.size());
  for (int i = 0; i < layout.size(); ++i) w[i] = 1e-7 * std::sin(1.0 + i);  // small, all harmonics
  PairParameters stick = kPair;
  stick.friction_coefficient = 1e6;
  stick.normal_preload = 100.0;  // kn |z| <= 5e5 * 9 * 1e-7 = 0.45 N: never separates
  Eigen::VectorXd k(layout.size());
  k << Eigen::VectorXd::Constant(2 * m, stick.tangential_stiffness),
      Eigen::VectorXd::Constant(m, stick.normal_stiffness);
  constexpr double kRoundOff = 1e-12;
  for (Model model : {Model::full3d, Model::quasi3d}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      std::vector<Eigen::MatrixXd> j;
      Eigen::VectorXd f = forces(model, update, h, n, stick, w, &j);
      f[2 * m] -= stick.normal_preload;
      EXPECT_LE((f - k.cwiseProduct(w)).norm(), kRoundOff * k.cwiseProduct(w).norm());
      EXPECT_LE((j[0] - Eigen::MatrixXd(k.asDiagonal())).norm(), kRoundOff * k.norm());
      PairParameters gap = kPair;
      gap.normal_preload = -1.0;  // kn |z| <= 0.45 N < 1 N
      Eigen::VectorXd wg = 20.0 * w;
      wg.segment(2 * m, m) = w.segment(2 * m, m);
      j.clear();
      const Eigen::VectorXd fg = forces(model, update, h, n, gap, wg, &j);
      EXPECT_EQ(fg.norm(), 0.0);
      EXPECT_EQ(j[0].norm(), 0.0);
    }
  }
}

}  // namespace
