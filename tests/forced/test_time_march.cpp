// The time integration of lumped models (forced/time_march.hpp) against closed forms (the
// linear response, exactly subharmonic and quasi-periodic undamped motions), and the harmonic
// balance against it (Jenkins element; full-3D contact that separates over part of the period).
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <string>

#include "continuation/arclength.hpp"
#include "forced/frequency_response.hpp"
#include "forced/reduced_equations.hpp"
#include "forced/time_march.hpp"
#include "frf/lumped.hpp"
#include "hbm/contact_evaluator.hpp"
#include "hbm/harmonic_layout.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
using Motion = TimeMarchResult::Motion;

// The scheme's relative error at 4096 steps per period is O((w dt)^2) ~ 2e-6 on the motion's
// amplitude near the modes used here (Newmark's period error (w dt)^2 / 12, amplified by at
// most ~5 by the resonance 30 % away): 2e-5 bounds it with margin.
constexpr double kSchemeError = 2e-5;

LumpedSystem system_of(const frf::LumpedLinearPart& p) {
  return {p.mass(), p.damping(), p.stiffness(), p.contact_operator(), p.force_vector(), {}};
}

contact::PairParameters pair(double kt, double kn, double mu, double n0) {
  contact::PairParameters p;
  p.tangential_stiffness = kt;
  p.normal_stiffness = kn;
  p.friction_coefficient = mu;
  p.normal_preload = n0;
  return p;
}

/// A 3-DOF chain (masses 1, 2, 1.5 kg; springs 4e4, 3e4, 2e4 N/m; C = 1e-3 K), a 1d element on
/// DOF 2 (to ground), unit force on DOF 0.
frf::LumpedLinearPart chain(double damping_factor = 1e-3) {
  Eigen::MatrixXd m = Eigen::Vector3d(1.0, 2.0, 1.5).asDiagonal(), k(3, 3);
  k << 7e4, -3e4, 0, -3e4, 5e4, -2e4, 0, -2e4, 2e4;
  frf::LumpedContact e;
  e.dof = {2, -1, -1};
  return frf::LumpedLinearPart(m, k, damping_factor * k, {e}, 0, 1.0, 0);
}

TEST(TimeMarch, WithoutFrictionTheMotionIsTheExactLinearResponse) {
  const frf::LumpedLinearPart linear = chain();
  const std::vector<contact::PairParameters> pairs{pair(1e4, 1.0, 0.0, 1.0)};  // mu = 0: no force
  for (double f_hz : {3.0, 30.0}) {  // below the first mode (~14 Hz) and between modes 2 and 3
    TimeMarchOptions o;
    o.output_samples = 64;
    const TimeMarchResult r = march_to_steady_state(system_of(linear), pairs, contact::Model::one_d, f_hz, o);
    ASSERT_EQ(r.motion, Motion::periodic) << r.describe();
    const Eigen::VectorXd x = harmonic_unknowns(r.contact_motion, 1, 1);
    const double w = kTwoPi * f_hz;
    const Eigen::MatrixXcd dyn = linear.stiffness().cast<std::complex<double>>() -
                                 w * w * linear.mass().cast<std::complex<double>>() +
                                 std::complex<double>(0, w) * linear.damping().cast<std::complex<double>>();
    const std::complex<double> exact = dyn.partialPivLu().solve(linear.force_vector().cast<std::complex<double>>())[2];
    const std::complex<double> marched(x[1], -x[2]);  // U_1 = c1 - i s1
    EXPECT_LT(std::abs(marched - exact), kSchemeError * std::abs(exact)) << f_hz << " Hz";
    EXPECT_LT(std::abs(x[0]), kSchemeError * std::abs(exact));
  }
}

TEST(TimeMarch, ASineExcitationGivesTheCosineOnesMotionAQuarterPeriodLater) {
  // f sin(w t) = f cos(w (t - T / 4)): the law is time-invariant, so the steady motion under the
  // sine part (LumpedSystem::force_sin, a travelling wave's other half) is the cosine part's
  // shifted by a quarter period, Jenkins slip included. Output at 64 samples: the shift is 16
  // samples, on the march's steps; the two marches differ only in where their transients
  // started, so their steady motions agree to the periodicity tolerance times the conditioning.
  const frf::LumpedLinearPart linear = chain();
  const std::vector<contact::PairParameters> pairs{pair(1e4, 1.0, 0.3, 0.2)};
  TimeMarchOptions o;
  o.output_samples = 64;
  const LumpedSystem cosine = system_of(linear);
  LumpedSystem sine = cosine;
  sine.force_sin = sine.force;
  sine.force.setZero();
  const double f_hz = 13.0;  // near the first mode (~14 Hz): the element slips
  const TimeMarchResult a = march_to_steady_state(cosine, pairs, contact::Model::one_d, f_hz, o);
  const TimeMarchResult b = march_to_steady_state(sine, pairs, contact::Model::one_d, f_hz, o);
  ASSERT_EQ(a.motion, Motion::periodic) << a.describe();
  ASSERT_EQ(b.motion, Motion::periodic) << b.describe();
  const double size = a.contact_motion.cwiseAbs().maxCoeff();
  double worst = 0.0;
  for (int j = 0; j < 64; ++j)
    worst = std::max(worst, std::abs(b.contact_motion(0, (j + 16) % 64) - a.contact_motion(0, j)));
  EXPECT_LT(worst, 1e-6 * size);
  RecordProperty("largest_difference_relative", std::to_string(worst / size));
}

TEST(TimeMarch, TheRememberedMarchIsTheMarchOfTheSameInputsAndOnlyOfThem) {
  // A Jenkins element that slips: the cached call marches once, a second identical call returns
  // the same motion without marching, and a change of any input (frequency, friction, output
  // samples) marches anew, giving that input's own result.
  const frf::LumpedLinearPart linear = chain();
  std::vector<contact::PairParameters> pairs{pair(1e4, 1.0, 0.3, 0.2)};
  TimeMarchOptions o;
  o.output_samples = 64;
  o.max_periods = 400;
  const LumpedSystem sys = system_of(linear);
  const double f_hz = 12.345678;  // a frequency no other test of this process marches at
  bool reused = true;
  const TimeMarchResult first = march_to_steady_state_cached(sys, pairs, contact::Model::one_d, f_hz, o, &reused);
  EXPECT_FALSE(reused);
  const TimeMarchResult again = march_to_steady_state_cached(sys, pairs, contact::Model::one_d, f_hz, o, &reused);
  EXPECT_TRUE(reused);
  EXPECT_EQ(again.periods, first.periods);
  EXPECT_EQ(again.contact_motion, first.contact_motion);
  // The uncached march of the same inputs is the same, bit for bit.
  const TimeMarchResult direct = march_to_steady_state(sys, pairs, contact::Model::one_d, f_hz, o);
  EXPECT_EQ(direct.contact_motion, first.contact_motion);
  // Any other input: marched, and its own answer.
  const TimeMarchResult other_f =
      march_to_steady_state_cached(sys, pairs, contact::Model::one_d, f_hz * 1.01, o, &reused);
  EXPECT_FALSE(reused);
  EXPECT_NE(other_f.contact_motion, first.contact_motion);
  pairs[0].friction_coefficient = 0.31;
  const TimeMarchResult other_mu = march_to_steady_state_cached(sys, pairs, contact::Model::one_d, f_hz, o, &reused);
  EXPECT_FALSE(reused);
  EXPECT_NE(other_mu.contact_motion, first.contact_motion);
  pairs[0].friction_coefficient = 0.3;
  o.output_samples = 128;
  const TimeMarchResult other_n = march_to_steady_state_cached(sys, pairs, contact::Model::one_d, f_hz, o, &reused);
  EXPECT_FALSE(reused);
  EXPECT_EQ(other_n.contact_motion.cols(), 128);
}

TEST(TimeMarch, AnUndampedModeAtAFractionOfTheExcitationGivesASubharmonicMotion) {
  // m u'' + k u = cos(w t) from rest: u = A (cos w t - cos w_n t), periodic over p excitation
  // periods when w_n = w / p, never periodic when w / w_n is irrational. The scheme (central
  // differences, 4096 steps per period here) turns a mode w into 2 asin(w dt / 2) / dt, so k
  // is chosen to give the discrete motion the mode w / p exactly.
  const std::vector<contact::PairParameters> pairs{pair(1.0, 1.0, 0.0, 1.0)};
  TimeMarchOptions o;
  o.max_periods = 600;
  // Round-off accumulates in an undamped recurrence over ~1e6 steps (~1e-10 of the motion).
  o.periodicity_tolerance = 1e-8;
  const auto oscillator = [](double w_n) {
    frf::LumpedContact e;
    e.dof = {0, -1, -1};
    return frf::LumpedLinearPart(Eigen::MatrixXd::Constant(1, 1, 1.0), Eigen::MatrixXd::Constant(1, 1, w_n * w_n),
                                 Eigen::MatrixXd::Zero(1, 1), {e}, 0, 1.0, 0);
  };
  for (int p : {2, 3}) {
    const double f = 10.0 * p, dt = 1.0 / f / o.min_steps_per_period;
    const double w_discrete = kTwoPi * f / p, w_n = 2.0 / dt * std::sin(w_discrete * dt / 2.0);
    const TimeMarchResult r = march_to_steady_state(system_of(oscillator(w_n)), pairs, contact::Model::one_d, f, o);
    EXPECT_EQ(r.motion, Motion::subharmonic) << r.describe();
    EXPECT_EQ(r.period_multiple, p) << r.describe();
  }
  const TimeMarchResult r = march_to_steady_state(system_of(oscillator(kTwoPi * 10.0)), pairs, contact::Model::one_d,
                                                  10.0 * std::sqrt(2.0), o);
  EXPECT_EQ(r.motion, Motion::not_settled) << r.describe();
  EXPECT_EQ(r.periods, o.max_periods);
  EXPECT_GT(r.mismatch, 1e-3);
}

/// The harmonic balance (H, N) from the marched motion's harmonics: Newton converges, and the
/// solution's harmonics equal the marched ones within `tolerance` of the largest.
void expect_harmonic_balance_agrees(const frf::LumpedLinearPart& linear,
                                    const std::vector<contact::PairParameters>& pairs, contact::Model model,
                                    double f_hz, int h, int n, double tolerance) {
  TimeMarchOptions o;
  o.output_samples = n;
  const TimeMarchResult r = march_to_steady_state(system_of(linear), pairs, model, f_hz, o);
  ASSERT_EQ(r.motion, Motion::periodic) << r.describe();
  hbm::ContactEvaluatorOptions eo;
  eo.n_harmonics = h;
  eo.n_time_samples = n;
  eo.law.model = model;
  hbm::ContactEvaluator evaluator(eo, pairs);
  ReducedEquations equations(linear, evaluator);
  const Eigen::VectorXd marched = harmonic_unknowns(r.contact_motion, h, contact::n_directions(model));
  Eigen::VectorXd x = marched;
  continuation::ArclengthOptions ao;
  ao.x_scale = Eigen::VectorXd::Constant(x.size(), marched.lpNorm<Eigen::Infinity>());
  ao.tolerance = 1e-10;
  ASSERT_GE(continuation::newton_fixed(equations, x, f_hz, ao), 0);
  EXPECT_LT((x - marched).lpNorm<Eigen::Infinity>(), tolerance * marched.lpNorm<Eigen::Infinity>());
}

TEST(TimeMarch, HarmonicBalanceOfAJenkinsElementAgreesWithTheMarchedMotion) {
  // The 3-DOF chain with a Jenkins element (kt = 1e4 N/m, mu N0 = 0.3 N) in slip over part of
  // the period near its first mode. The two differ by the harmonic balance's truncation
  // (H = 15) and sampling (N = 1024) of the stick-slip corners and by the scheme's step error:
  // measured 1.8e-6 of the largest coefficient; 2e-5 leaves a factor 10.
  constexpr double kHarmonicBalanceError = 2e-5;
  const frf::LumpedLinearPart linear = chain(2e-3);
  expect_harmonic_balance_agrees(linear, {pair(1e4, 1.0, 0.3, 1.0)}, contact::Model::one_d, 13.0, 15, 1024,
                                 kHarmonicBalanceError);
}

TEST(TimeMarch, HarmonicBalanceOfAFullThreeDimensionalContactThatSeparatesAgreesWithTheMarchedMotion) {
  // A mass with x, y, z DOFs (10 Hz, 12 Hz, 25 Hz), coupled in x and z, pressed with 0.5 N on
  // a full-3D contact (kt = kn = 2e4 N/m, mu = 0.4) and forced in x: the normal motion opens
  // the contact over part of the period. H = 20, N = 2048: measured 6.0e-6 of the largest
  // coefficient, mostly the truncation at H = 20 (1.7e-6 at H = 40, 5.4e-7 at H = 40 and
  // N = 8192; the march with 4x its steps moves it by 4e-7); 5e-5 leaves a factor 8.
  constexpr double kHarmonicBalanceError = 5e-5;
  Eigen::MatrixXd k =
      Eigen::Vector3d(std::pow(kTwoPi * 10, 2), std::pow(kTwoPi * 12, 2), std::pow(kTwoPi * 25, 2)).asDiagonal();
  k(0, 2) = k(2, 0) = 0.5 * std::sqrt(k(0, 0) * k(2, 2));
  frf::LumpedContact e;
  e.dof = {0, 1, 2};
  const frf::LumpedLinearPart linear(Eigen::Matrix3d::Identity(), k, 1e-3 * k, {e}, 0, 3.0, 0);
  TimeMarchOptions o;
  const std::vector<contact::PairParameters> pairs{pair(2e4, 2e4, 0.4, 0.5)};
  const TimeMarchResult r = march_to_steady_state(system_of(linear), pairs, contact::Model::full3d, 11.0, o);
  ASSERT_EQ(r.motion, Motion::periodic) << r.describe();
  // It does separate: the normal load max(0, N0 + kn z) is zero at some samples.
  EXPECT_LT(r.contact_motion.row(2).minCoeff(), -0.5 / 2e4);
  EXPECT_GT(r.contact_motion.row(2).maxCoeff(), -0.5 / 2e4);
  expect_harmonic_balance_agrees(linear, pairs, contact::Model::full3d, 11.0, 20, 2048, kHarmonicBalanceError);
  expect_harmonic_balance_agrees(linear, pairs, contact::Model::quasi3d, 11.0, 20, 2048, kHarmonicBalanceError);
}

TEST(TimeMarch, HarmonicUnknownsFollowTheEvaluatorLayout) {
  // x(t) = 1 + 2 cos(t) - 3 sin(2 t) in direction y of the second element.
  const int m = 16;
  Eigen::MatrixXd samples = Eigen::MatrixXd::Zero(6, m);
  for (int j = 0; j < m; ++j) {
    const double t = kTwoPi * j / m;
    samples(4, j) = 1 + 2 * std::cos(t) - 3 * std::sin(2 * t);
  }
  const Eigen::VectorXd x = harmonic_unknowns(samples, 2, 3);
  const hbm::HarmonicLayout layout(2, 3);
  ASSERT_EQ(x.size(), 2 * layout.size());
  const double* y = x.data() + layout.size();
  EXPECT_NEAR(y[layout.index(1, 0)], 1.0, 1e-14);
  EXPECT_NEAR(y[layout.index(1, 1, hbm::HarmonicLayout::Part::cosine)], 2.0, 1e-14);
  EXPECT_NEAR(y[layout.index(1, 2, hbm::HarmonicLayout::Part::sine)], -3.0, 1e-14);
  EXPECT_NEAR(x.norm(), std::sqrt(14.0), 1e-13);
}

TEST(TimeMarch, RejectsInconsistentInput) {
  const frf::LumpedLinearPart linear = chain();
  LumpedSystem s = system_of(linear);
  TimeMarchOptions o;
  EXPECT_THROW(march_to_steady_state(s, {}, contact::Model::one_d, 10.0, o), std::invalid_argument);
  EXPECT_THROW(march_to_steady_state(s, {pair(1, 1, 0.1, 1)}, contact::Model::one_d, 0.0, o), std::invalid_argument);
  o.steps_per_stiff_period = 2.0;
  EXPECT_THROW(march_to_steady_state(s, {pair(1, 1, 0.1, 1)}, contact::Model::one_d, 10.0, o), std::invalid_argument);
  s.mass(0, 0) = -1.0;
  const TimeMarchResult r = march_to_steady_state(s, {pair(1, 1, 0.1, 1)}, contact::Model::one_d, 10.0, {});
  EXPECT_EQ(r.motion, Motion::not_applicable);
}

// A start found by time integration is found for the excitation the equations carry: with the
// excitation scaled (the nonlinear-mode stage's comparison runs the harmonic balance at scaled
// levels), the integration runs at the scaled force. The stress-corpus model of the CLI's
// subharmonic test (3 DOFs, full-3D contact) with a preload of 2 N at 4.27 Hz has no
// harmonic-balance start; integrated at the force F it settles on a motion that repeats every
// two periods (no start), at 0.4 F on a periodic one (the start). The model with force F and
// the excitation scaled by 0.4 must say exactly what the model with force 0.4 F says. (Without
// preload the model is homogeneous in the force, and the two integrations settle alike.)
TEST(TimeMarchStart, AScaledExcitationIsIntegratedAtTheScaledForce) {
  Eigen::Matrix3d m = Eigen::Vector3d(18.15501439951414, 42.8550096420159, 10.490537497208551).asDiagonal();
  Eigen::Matrix3d k, c;
  k << 370681.8733347799, -186888.25051647378, 0.0, -186888.25051647378, 319495.4706231562, -132607.2201066824, 0.0,
      -132607.2201066824, 223491.84451767677;
  c << 266.1261834145856, -94.91376025229103, 0.0, -94.91376025229103, 346.07344752183434, -67.34639476877648, 0.0,
      -67.34639476877648, 158.49930917894164;
  frf::LumpedContact e;
  e.dof = {2, 0, 1};
  e.frame_angle = 15.335515728693025 * std::numbers::pi / 180.0;
  contact::PairParameters pp;
  pp.friction_coefficient = 0.49809335994186493;
  pp.tangential_stiffness = 4453169.612587134;
  pp.normal_stiffness = 13937757.214890867;
  pp.normal_preload = 2.0;
  hbm::ContactEvaluatorOptions eo;
  eo.n_harmonics = 12;
  eo.n_time_samples = 128;
  eo.law.model = contact::Model::full3d;
  eo.threads = 1;
  constexpr double kForce = 3.498485488581492, kScale = 0.4, kFrequency = 4.269022959253111;
  auto attempt = [&](double force, double scale) {
    ForcedModel model;
    model.linear = std::make_unique<frf::LumpedLinearPart>(m, k, c, std::vector<frf::LumpedContact>{e}, 2, force, 0);
    model.pairs = {pp};
    hbm::ContactEvaluator ev(eo, model.pairs);
    ReducedEquations eq(*model.linear, ev);
    eq.set_excitation_scale(scale);
    FrequencyResponseSettings fs;
    fs.frequency_start_hz = kFrequency;
    fs.frequency_end_hz = 12.316202486923972;
    const continuation::ArclengthOptions ao = arclength_options(fs, model, eq);
    std::string how;
    try {
      find_start(model, eo, eq, ao, kFrequency, how);
      return "start by " + how;
    } catch (const std::exception& error) {
      return std::string(error.what());
    }
  };
  const std::string scaled = attempt(kForce, kScale), direct = attempt(kScale * kForce, 1.0);
  EXPECT_NE(direct.find("start by time integration"), std::string::npos) << direct;  // a periodic motion
  EXPECT_EQ(scaled, direct);
}

}  // namespace
}  // namespace shroudsim::forced
