// Forced response of lumped models against independent closed forms.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

#include "contact/jenkins.hpp"
#include "continuation/arclength.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/lumped.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;

/// 1-DOF oscillator, f_n = 10 Hz, zeta = 1 %, a Jenkins element to ground (kt = k, slip
/// force mu N0 = 0.3 N), forced by F cos(w t).
struct OneDof {
  double m = 1.0, k = std::pow(2 * kPi * 10.0, 2), zeta = 0.01, force = 0.5;
  double kt = k, mu = 0.3, n0 = 1.0;
  double c() const { return 2 * zeta * std::sqrt(k * m); }
  frf::LumpedLinearPart linear() const {
    frf::LumpedContact e;
    e.dof = {0, -1, -1};
    return frf::LumpedLinearPart(Eigen::MatrixXd::Constant(1, 1, m), Eigen::MatrixXd::Constant(1, 1, k),
                                 Eigen::MatrixXd::Constant(1, 1, c()), {e}, 0, force, 0);
  }
  contact::PairParameters pair() const {
    contact::PairParameters p;
    p.tangential_stiffness = kt;
    p.normal_stiffness = 1.0;
    p.friction_coefficient = mu;
    p.normal_preload = n0;
    return p;
  }
  /// Relative residual of the describing-function amplitude relation at amplitude a:
  /// (k + kt_eq - m w^2)^2 + (c w + d)^2 = F^2 / a^2, with F_J1 = a1 cos + b1 sin,
  /// kt_eq = a1 / a, d = -b1 / a (docs/physics.md section 4, time-continuous Jenkins).
  double describing_function_error(double a, double w) const {
    const double fs = mu * n0;
    double a1 = kt * a, b1 = 0.0;
    if (kt * a > fs) {
      const double beta = std::acos(1 - 2 * fs / (kt * a));
      a1 = kt * a / kPi * (beta - std::sin(2 * beta) / 2);
      b1 = -4 * fs / kPi * (1 - fs / (kt * a));
    }
    const double s = k + a1 / a - m * w * w, d = c() * w - b1 / a;
    return std::abs((s * s + d * d) * a * a - force * force) / (force * force);
  }
};

continuation::ArclengthOptions options(double scale) {
  continuation::ArclengthOptions o;
  o.lambda_start = 5.0;
  o.lambda_end = 25.0;
  o.x_scale = Eigen::VectorXd::Constant(1, scale);
  o.initial_step = 0.2;
  o.tolerance = 1e-10;
  return o;
}

continuation::Branch trace_one_dof(const OneDof& sys, contact::Model model, int h, int n, hbm::JacobianMethod jac,
                                   frf::LumpedLinearPart& linear, std::unique_ptr<hbm::ContactEvaluator>& ev,
                                   std::unique_ptr<ReducedEquations>& eq) {
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.law.model = model;
  o.jacobian = jac;
  o.threads = 1;
  ev = std::make_unique<hbm::ContactEvaluator>(o, std::vector<contact::PairParameters>{sys.pair()});
  eq = std::make_unique<ReducedEquations>(linear, *ev);
  auto opt = options(1e-3);
  opt.x_scale = Eigen::VectorXd::Constant(eq->size(), 1e-3);
  return continuation::trace(*eq, eq->stuck_solution(opt.lambda_start), opt);
}

TEST(ForcedLumped, JenkinsOscillatorFollowsTheDescribingFunction) {
  const OneDof sys;
  frf::LumpedLinearPart linear = sys.linear();
  std::unique_ptr<hbm::ContactEvaluator> ev;
  std::unique_ptr<ReducedEquations> eq;
  const auto b = trace_one_dof(sys, contact::Model::one_d_exact, 1, 64, hbm::JacobianMethod::analytic, linear, ev, eq);
  ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << b.message;
  ASSERT_GT(b.points.size(), 20u);
  // 1d_exact is the time-continuous law: HBM-1 and the describing function are the same
  // equations, so they agree to the Newton tolerance (1e-10 of the 1 mm scale).
  constexpr double kTol = 1e-6;
  double peak = 0.0;
  for (const auto& p : b.points) {
    const double a = std::hypot(p.x[1], p.x[2]);  // first-harmonic amplitude of x
    EXPECT_LT(sys.describing_function_error(a, 2 * kPi * p.lambda), kTol) << p.lambda;
    const PointResult r = eq->analyse(p.x, p.lambda);
    EXPECT_LT(r.energy_error, 1e-6) << p.lambda;
    peak = std::max(peak, r.amplitude);
  }
  // The friction damps the peak well below the free one (F / c w_n) and above the stuck one.
  EXPECT_LT(peak, sys.force / (sys.c() * 2 * kPi * 10.0));
}

/// Den Hartog's exact steady state of m x'' + k x + Fs sgn(x') = F cos(w t) without viscous
/// damping, for motion without stops: x0 = (F/k) sqrt(V^2 - (Fs/F)^2 U^2), V = 1/(1 - r^2),
/// U = sin(pi/r) / (r (1 + cos(pi/r))), r = w/w_n (Den Hartog 1931). Derived again from the two
/// half-period boundary conditions x(0) = x0, x'(0) = 0, x(pi/w) = -x0, x'(pi/w) = 0.
double den_hartog_amplitude(double k, double force, double fs, double r) {
  const double v = 1.0 / (1.0 - r * r), u = std::sin(kPi / r) / (r * (1.0 + std::cos(kPi / r)));
  return force / k * std::sqrt(v * v - std::pow(fs / force * u, 2));
}

TEST(ForcedLumped, StiffJenkinsWithManyHarmonicsApproachesDenHartog) {
  // Coulomb friction = a Jenkins element whose spring is very stiff (kt = 1e4 k: the stuck
  // element moves Fs/kt, 1e-4 of the static deflection). No viscous damping: below resonance
  // (r = 0.6..0.9, where the motion has no stops for Fs = 0.3 F) the HBM amplitude
  // max_t |x(t)| must approach Den Hartog's x0 as the harmonics grow. (Measured: 2.3 %, 0.86 %,
  // 0.39 % at H = 3, 9, 27. Above resonance, r = 1.2..2, the curve settles 0.3 % to 0.8 % above
  // x0 and converges no further with H; a time integration of the same stiff Jenkins oscillator
  // lands above x0 there too, so that branch is not asserted.)
  OneDof sys;
  sys.zeta = 0.0;
  sys.kt = 1e4 * sys.k;
  sys.force = 1.0;
  sys.mu = 0.3;
  sys.n0 = 1.0;
  const double fn = 10.0, fs = sys.mu * sys.n0;
  frf::LumpedLinearPart linear = sys.linear();
  std::vector<double> worst;
  for (int h : {3, 9, 27}) {
    hbm::ContactEvaluatorOptions o;
    o.n_harmonics = h;
    o.n_time_samples = 2048;  // sampling error (1/N^2) well below the truncation error
    o.law.model = contact::Model::one_d;
    o.threads = 1;
    hbm::ContactEvaluator ev(o, {sys.pair()});
    ReducedEquations eq(linear, ev);
    double err = 0.0;
    {
      auto opt = options(1e-3);
      opt.lambda_start = 0.6 * fn;
      opt.lambda_end = 0.9 * fn;
      opt.initial_step = 0.1;
      opt.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-5);
      const auto b = continuation::trace(eq, eq.linear_motion(opt.lambda_start), opt);
      ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << "H = " << h << ": " << b.message;
      ASSERT_GT(b.points.size(), 10u);
      for (const auto& p : b.points) {
        const double exact = den_hartog_amplitude(sys.k, sys.force, fs, p.lambda / fn);
        err = std::max(err, std::abs(eq.analyse(p.x, p.lambda, 4096).amplitude - exact) / exact);
      }
    }
    worst.push_back(err);
  }
  // Each tripling of H must cut the worst relative error (the Coulomb force is a square wave:
  // its harmonics fall as 1/n, those of x as 1/n^3), and at H = 27 it must be below 0.5 %.
  constexpr double kFinalTol = 5e-3;
  EXPECT_LT(worst[1], worst[0] / 2) << worst[0] << " -> " << worst[1];
  EXPECT_LT(worst[2], worst[1] / 2) << worst[1] << " -> " << worst[2];
  EXPECT_LT(worst[2], kFinalTol) << "H = 3, 9, 27: " << worst[0] << ", " << worst[1] << ", " << worst[2];
}

TEST(ForcedLumped, DiscreteJenkinsConvergesToTheDescribingFunction) {
  // "1d" with N samples approaches the time-continuous law as 1/N^2 (docs/physics.md section 4).
  const OneDof sys;
  frf::LumpedLinearPart linear = sys.linear();
  double previous = 0.0;
  for (int n : {64, 256}) {
    std::unique_ptr<hbm::ContactEvaluator> ev;
    std::unique_ptr<ReducedEquations> eq;
    const auto b = trace_one_dof(sys, contact::Model::one_d, 1, n, hbm::JacobianMethod::analytic, linear, ev, eq);
    ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << b.message;
    double worst = 0.0;
    for (const auto& p : b.points)
      worst = std::max(worst, sys.describing_function_error(std::hypot(p.x[1], p.x[2]), 2 * kPi * p.lambda));
    if (previous > 0) {
      EXPECT_LT(worst, previous / 8.0) << "four times the samples should cut the error ~16x";
    }
    previous = worst;
  }
}

TEST(ForcedLumped, FiniteDifferenceJacobianGivesTheSameCurve) {
  const OneDof sys;
  frf::LumpedLinearPart linear = sys.linear();
  std::unique_ptr<hbm::ContactEvaluator> ev1, ev2;
  std::unique_ptr<ReducedEquations> eq1, eq2;
  const auto a = trace_one_dof(sys, contact::Model::one_d, 3, 128, hbm::JacobianMethod::analytic, linear, ev1, eq1);
  const auto f =
      trace_one_dof(sys, contact::Model::one_d, 3, 128, hbm::JacobianMethod::finite_difference, linear, ev2, eq2);
  ASSERT_EQ(a.status, continuation::BranchStatus::kReachedEnd);
  ASSERT_EQ(f.status, continuation::BranchStatus::kReachedEnd);
  // Each finite-difference point lies on the analytic curve: its residual with the analytic
  // evaluator is at the Newton tolerance (the curves may be sampled at different points).
  Eigen::VectorXd r;
  for (const auto& p : f.points) {
    eq1->evaluate(p.x, p.lambda, r, nullptr, nullptr);
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-9) << p.lambda;
  }
}

TEST(ForcedLumped, ExactFrequencyDerivativeOfTheReceptanceAtEveryTimeScale) {
  // A 2-DOF chain (zeta 1e-3 at its first mode), one quasi3d contact acting between the DOFs,
  // rescaled in time by s (M -> s^2 M, C -> s C: frequencies / s). At w near the first
  // resonance the receptance turns over a width zeta w, so a difference step must be relative.
  // G(w / s) of the rescaled model equals G(w) of the original, hence dG/dw scales by s.
  const Eigen::Matrix2d m{{1.0, 0.0}, {0.0, 2.0}}, k{{2.0, -1.0}, {-1.0, 1.5}};
  frf::LumpedContact e;
  e.dof = {0, 1, -1};
  e.other = {1, -1, -1};
  e.frame_angle = 0.3;
  const double w1 = std::sqrt(
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d>(k, m, Eigen::EigenvaluesOnly).eigenvalues()[0]);
  const Eigen::Matrix2d c = (2 * 1e-3 / w1) * k;
  Eigen::MatrixXcd dg1;
  Eigen::VectorXcd dw1;
  for (double s : {1.0, 1e-3, 1e3}) {
    const frf::LumpedLinearPart part(s * s * m, k, s * c, {e}, 0, 1.0, 1);
    const double w = 1.0003 * w1 / s;
    for (int n : {1, 2}) {
      Eigen::MatrixXcd dg;
      Eigen::VectorXcd dw;
      part.harmonic_derivative(n, w, dg, dw);
      // Richardson-extrapolated central differences with a step of 1e-3 of the width.
      const double h = 1e-6 * w;
      auto central = [&](double step, Eigen::MatrixXcd& g, Eigen::VectorXcd& l) {
        frf::HarmonicReceptance plus, minus;
        part.harmonic(n, w + step, plus);
        part.harmonic(n, w - step, minus);
        g = (plus.G - minus.G) / (2 * step);
        l = (plus.w_lin - minus.w_lin) / (2 * step);
      };
      Eigen::MatrixXcd g_h, g_2h;
      Eigen::VectorXcd l_h, l_2h;
      central(h, g_h, l_h);
      central(2 * h, g_2h, l_2h);
      const Eigen::MatrixXcd g_fd = (4 * g_h - g_2h) / 3;
      const Eigen::VectorXcd l_fd = (4 * l_h - l_2h) / 3;
      constexpr double kDifferenceError = 1e-7;  // round-off of G / h at h = 1e-6 w, and O(h^4)
      EXPECT_LE((dg - g_fd).norm(), kDifferenceError * dg.norm()) << "s " << s << ", n " << n;
      if (n == 1) {
        EXPECT_LE((dw - l_fd).norm(), kDifferenceError * dw.norm()) << "s " << s;
        if (s == 1.0) {
          dg1 = dg, dw1 = dw;
        } else {
          // Exact arithmetic gives s dG_1 exactly; the products differ in round-off only.
          constexpr double kRescaled = 1e-12;
          EXPECT_LE((dg - s * dg1).norm(), kRescaled * dg.norm()) << "s " << s;
          EXPECT_LE((dw - s * dw1).norm(), kRescaled * dw.norm()) << "s " << s;
        }
      }
    }
  }
}

TEST(ForcedLumped, HugeFrictionGivesTheLinearResponseWithTheContactSpring) {
  OneDof sys;
  sys.mu = 1e6;  // never slips
  frf::LumpedLinearPart linear = sys.linear();
  std::unique_ptr<hbm::ContactEvaluator> ev;
  std::unique_ptr<ReducedEquations> eq;
  const auto b = trace_one_dof(sys, contact::Model::one_d, 3, 64, hbm::JacobianMethod::analytic, linear, ev, eq);
  ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << b.message;
  for (const auto& p : b.points) {
    const double w = 2 * kPi * p.lambda;
    const double exact = sys.force / std::abs(std::complex<double>(sys.k + sys.kt - sys.m * w * w, sys.c() * w));
    EXPECT_NEAR(eq->analyse(p.x, p.lambda).amplitude / exact, 1.0, 1e-8) << p.lambda;
  }
}

TEST(ForcedLumped, GapThatNeverClosesGivesTheFreeResponse) {
  // 3D contact to ground on a 3-DOF point mass; a 1 m gap never closes.
  const double k = std::pow(2 * kPi * 10.0, 2), c = 2 * 0.01 * std::sqrt(k);
  frf::LumpedContact e;
  e.dof = {0, 1, 2};
  frf::LumpedLinearPart linear(Eigen::MatrixXd::Identity(3, 3), k * Eigen::MatrixXd::Identity(3, 3),
                               c * Eigen::MatrixXd::Identity(3, 3), {e}, 0, 0.5, 0);
  contact::PairParameters pair;
  pair.normal_preload = -1e6;  // gap -N0/kn = 1 m
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 3;
  o.n_time_samples = 64;
  o.threads = 1;
  hbm::ContactEvaluator ev(o, {pair});
  ReducedEquations eq(linear, ev);
  auto opt = options(1e-3);
  opt.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-3);
  const auto b = continuation::trace(eq, eq.stuck_solution(5.0), opt);
  ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << b.message;
  for (const auto& p : b.points) {
    const PointResult r = eq.analyse(p.x, p.lambda);
    EXPECT_NEAR(r.amplitude / r.linear_amplitude, 1.0, 1e-10);
    EXPECT_EQ(r.contact_dissipation, 0.0);
  }
}

}  // namespace
}  // namespace shroudsim::forced

namespace shroudsim::forced {
namespace {

/// A 3-DOF point mass on springs with a full 3D contact to ground, preloaded.
struct PointMass3d {
  double k = std::pow(2 * kPi * 10.0, 2);
  frf::LumpedLinearPart linear(double angle = 0.0) const {
    frf::LumpedContact e;
    e.dof = {0, 1, 2};
    e.frame_angle = angle;
    Eigen::MatrixXd kk = k * Eigen::MatrixXd::Identity(3, 3);
    kk(2, 2) *= 1.5;
    return frf::LumpedLinearPart(Eigen::MatrixXd::Identity(3, 3), kk,
                                 2 * 0.01 * std::sqrt(k) * Eigen::MatrixXd::Identity(3, 3), {e}, 0, 0.5, 0);
  }
  contact::PairParameters pair() const {
    contact::PairParameters p;
    p.tangential_stiffness = k;
    p.normal_stiffness = 2 * k;
    p.friction_coefficient = 0.3;
    p.normal_preload = 1.0;
    return p;
  }
};

TEST(ForcedLumped, ReducedJacobianMatchesCentralDifferencesFull3d) {
  const PointMass3d sys;
  frf::LumpedLinearPart linear = sys.linear();
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 3;
  o.n_time_samples = 64;
  o.threads = 1;
  hbm::ContactEvaluator ev(o, {sys.pair()});
  ReducedEquations eq(linear, ev);
  // A state with stick, slip and separation within the period.
  Eigen::VectorXd w = eq.stuck_solution(11.0);
  w += 2e-4 * Eigen::VectorXd::LinSpaced(w.size(), -1.0, 1.0).array().sin().matrix();
  Eigen::VectorXd r, rp, rm;
  Eigen::MatrixXd j;
  ASSERT_TRUE(eq.evaluate(w, 11.0, r, &j, nullptr));
  Eigen::MatrixXd fd(w.size(), w.size());
  constexpr double kStep = 1e-9;  // m: small against the 1e-4 m motion, far above round-off
  for (Eigen::Index i = 0; i < w.size(); ++i) {
    Eigen::VectorXd a = w, b = w;
    a[i] += kStep;
    b[i] -= kStep;
    eq.evaluate(a, 11.0, rp, nullptr, nullptr);
    eq.evaluate(b, 11.0, rm, nullptr, nullptr);
    fd.col(i) = (rp - rm) / (2 * kStep);
  }
  // Central differences of a piecewise-smooth map: 1e-5 relative still catches a dropped term.
  EXPECT_LT((j - fd).norm(), 1e-5 * fd.norm());
}

TEST(ForcedLumped, Full3dResponseKeepsItsEnergyBalanceAndIsFrameInvariant) {
  const PointMass3d sys;
  double peaks[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    frf::LumpedLinearPart linear = sys.linear(k == 0 ? 0.0 : kPi / 4);
    hbm::ContactEvaluatorOptions o;
    o.n_harmonics = 3;
    o.n_time_samples = 128;
    o.threads = 1;
    hbm::ContactEvaluator ev(o, {sys.pair()});
    ReducedEquations eq(linear, ev);
    auto opt = options(1e-3);
    opt.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-4);
    const auto b = continuation::trace(eq, eq.stuck_solution(opt.lambda_start), opt);
    ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << b.message;
    for (const auto& p : b.points) {
      const PointResult r = eq.analyse(p.x, p.lambda);
      EXPECT_LT(r.energy_error, 1e-6) << p.lambda;
      peaks[k] = std::max(peaks[k], r.amplitude);
    }
  }
  // The coupled law does not depend on the frame angle (docs/physics.md section 6).
  EXPECT_NEAR(peaks[1] / peaks[0], 1.0, 1e-4);
}

// A preload that a static equilibrium already carries (contact.normal_preload = "static"):
// the forced response is written about that state, so without excitation the solution is
// W = 0 with every contact force at its static value; the paper's preload instead acts on
// the structure at zero relative displacement, which the static harmonic relaxes to the
// closed form N = N0 / (1 + kn c_n) of a spring in series with the structure's static
// flexibility c_n (3 uncoupled DOFs to ground here: c_n = 1 / k_z).
TEST(ForcedLumped, APreloadInEquilibriumIsTheStaticStateAndAnAppliedOneRelaxes) {
  const double kz = 2.0e4, kn = 3.0e4, n0 = 5.0, f = 12.0;
  frf::LumpedContact e;
  e.dof = {0, 1, 2};
  const Eigen::Vector3d k(1.0e4, 1.5e4, kz);
  frf::LumpedLinearPart linear(Eigen::Matrix3d::Identity(), Eigen::Matrix3d(k.asDiagonal()),
                               Eigen::Matrix3d(0.01 * k.asDiagonal()), {e}, 0, 1.0, 0);
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 3;
  o.n_time_samples = 32;
  o.law.model = contact::Model::full3d;
  o.threads = 1;
  for (const bool in_equilibrium : {true, false}) {
    contact::PairParameters p;
    p.tangential_stiffness = 1.0e4;
    p.normal_stiffness = kn;
    p.friction_coefficient = 0.3;
    p.normal_preload = n0;
    p.preload_in_equilibrium = in_equilibrium;
    hbm::ContactEvaluator ev(o, {p});
    ReducedEquations eq(linear, ev);
    eq.set_excitation_scale(0.0);
    const Eigen::VectorXd w = eq.stuck_solution(f);
    Eigen::VectorXd r;
    ASSERT_TRUE(eq.evaluate(w, f, r, nullptr, nullptr));
    // The stuck solution solves the equations to round-off (the contact stays closed and
    // stuck: its law is the linear one there). Scale: the preload's static deflection n0 / kz.
    EXPECT_LT(r.lpNorm<Eigen::Infinity>(), 1e-12 * n0 / kz) << in_equilibrium;
    hbm::PairDetail d;
    ev.evaluate_pair(0, w, d, false);
    const double normal = d.f.col(2).mean();
    if (in_equilibrium) {
      EXPECT_EQ(w.lpNorm<Eigen::Infinity>(), 0.0);
      EXPECT_NEAR(normal, n0, 1e-12 * n0);
    } else {
      EXPECT_NEAR(normal, n0 / (1.0 + kn / kz), 1e-12 * n0);
    }
    EXPECT_NEAR(d.f.col(0).cwiseAbs().maxCoeff(), 0.0, 1e-12 * n0) << in_equilibrium;
  }
}

}  // namespace
}  // namespace shroudsim::forced
