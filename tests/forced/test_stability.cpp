// Stability of the forced response by Hill's method (forced/stability.hpp), checked against
// independent references: the damped eigenvalues of a contact that stays stuck (a linear
// system, closed form), Floquet multipliers from shooting (the periodic orbit found by Newton
// on the period map of a fine Runge-Kutta integration, its monodromy by central differences)
// on a hardening gap oscillator with a fold pair, the branch geometry (the stretch between two
// folds, traced backwards in frequency, is the unstable one), and a time integration of a friction
// model with three coexisting solutions (it settles on the stable one). And the shooting on the
// time integration (forced/shooting.hpp), which judges the lumped models with friction: the
// same closed form, the same three solutions, and the points of a friction model that Hill's
// method on the harmonic balance's linearization (without the slider as a state) calls unstable
// while the integration from rest settles on them. And Hill's method with the slider as a state
// (ContactMemory) against the same references: the stuck closed form and the shooting's verdicts
// on two friction models.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <numbers>
#include <string>

#include "forced/frequency_response.hpp"
#include "forced/shooting.hpp"
#include "forced/stability.hpp"
#include "forced/time_march.hpp"
#include "frf/lumped.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;

struct Lumped {
  ForcedModel model;
  hbm::ContactEvaluatorOptions options;
  double f_start = 0.0, f_end = 0.0;
};

/// The model's curve over its range, with default continuation settings.
FrequencyResponse trace_whole_range(const Lumped& l, ReducedEquations& eq) {
  FrequencyResponseSettings settings;
  settings.frequency_start_hz = l.f_start;
  settings.frequency_end_hz = l.f_end;
  return trace_frequency_response(settings, l.model, l.options, eq);
}

/// Its equations of motion, for the time integration and the shooting.
LumpedSystem system_of(const Lumped& l) {
  return lumped_system(static_cast<const frf::LumpedLinearPart&>(*l.model.linear));
}

/// The 2-DOF chain M = s^2 I, K = [[2, -1], [-1, 2]], C = 0.02 s K with a Jenkins element on
/// DOF 0 (kt = 1) whose friction limit mu N0 is far above any force it sees: it stays stuck,
/// and the system is linear (K + kt e0 e0^T). s rescales time.
Lumped stuck_chain(double s) {
  Lumped l;
  Eigen::MatrixXd k(2, 2);
  k << 2, -1, -1, 2;
  frf::LumpedContact c;
  c.dof = {0, -1, -1};
  l.model.linear = std::make_unique<frf::LumpedLinearPart>(s * s * Eigen::MatrixXd::Identity(2, 2), k, 0.02 * s * k,
                                                           std::vector<frf::LumpedContact>{c}, 0, 1.0, 0);
  contact::PairParameters p;
  p.tangential_stiffness = 1.0;
  p.normal_stiffness = 1.0;
  p.friction_coefficient = 1.0;
  p.normal_preload = 1e6;
  l.model.pairs = {p};
  l.options.n_harmonics = 5;
  l.options.n_time_samples = 64;
  l.options.law.model = contact::Model::one_d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  return l;
}

/// The stuck chain's harmonic-balance solution at f (time scale s), from the stuck solution.
bool solve_stuck_point(const Lumped& l, ReducedEquations& eq, double s, double f, Eigen::VectorXd& w) {
  w = eq.stuck_solution(f);
  FrequencyResponseSettings st;
  st.frequency_start_hz = 0.8 / (2 * kPi * s);
  st.frequency_end_hz = 1.4 / (2 * kPi * s);
  return continuation::newton_fixed(eq, w, f, arclength_options(st, l.model, eq)) >= 0;
}

// The hardening gap oscillator: m u'' + c u' + k u + max(0, N0 + kn u) = F cos(w t), m = k = 1,
// c = 0.02 (1 % damping at 1 rad/s), kn = 3, gap 0.5 (N0 = -1.5), F = 0.1: the linear peak (5)
// is ten gaps, so the curve leans far to the right with a fold pair. H = 15, N = 1024: at
// N = 256 the sampled contact instants leave a spurious zigzag of the curve just past the upper
// fold (three turning points within 1e-3 relative in frequency), which shooting does not have.
constexpr double kGapKn = 3.0, kGapN0 = -1.5, kGapForce = 0.1, kGapDamping = 0.02;

Lumped gap_oscillator() {
  Lumped l;
  frf::LumpedContact c;
  c.dof = {-1, -1, 0};
  l.model.linear = std::make_unique<frf::LumpedLinearPart>(
      Eigen::MatrixXd::Identity(1, 1), Eigen::MatrixXd::Identity(1, 1), kGapDamping * Eigen::MatrixXd::Identity(1, 1),
      std::vector<frf::LumpedContact>{c}, 0, kGapForce, 0);
  contact::PairParameters p;
  p.tangential_stiffness = 1.0;
  p.normal_stiffness = kGapKn;
  p.friction_coefficient = 0.0;
  p.normal_preload = kGapN0;
  l.model.pairs = {p};
  l.options.n_harmonics = 15;
  l.options.n_time_samples = 1024;
  l.options.law.model = contact::Model::full3d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 0.6 / (2 * kPi);
  l.f_end = 2.0 / (2 * kPi);
  return l;
}

/// The gap oscillator's period map x(0) -> x(T), x = (u, v), by classical Runge-Kutta with
/// `steps` steps (the right-hand side is continuous, its derivative jumps at contact: the error
/// stays far below the tolerances here at 20000 steps).
Eigen::Vector2d gap_period_map(const Eigen::Vector2d& x0, double w, int steps = 20000) {
  auto rhs = [w](double t, const Eigen::Vector2d& x) {
    const double contact = std::max(0.0, kGapN0 + kGapKn * x[0]);
    return Eigen::Vector2d(x[1], kGapForce * std::cos(w * t) - kGapDamping * x[1] - x[0] - contact);
  };
  const double h = 2 * kPi / w / steps;
  Eigen::Vector2d x = x0;
  for (int i = 0; i < steps; ++i) {
    const double t = i * h;
    const Eigen::Vector2d k1 = rhs(t, x), k2 = rhs(t + 0.5 * h, x + 0.5 * h * k1),
                          k3 = rhs(t + 0.5 * h, x + 0.5 * h * k2), k4 = rhs(t + h, x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return x;
}

/// The largest Floquet multiplier modulus of the periodic orbit near x0 by shooting: Newton on
/// x(T) - x(0) = 0 with the monodromy by central differences, then its eigenvalues.
double shooting_spectral_radius(Eigen::Vector2d x0, double w, double* start_mismatch) {
  auto monodromy = [w](const Eigen::Vector2d& x) {
    Eigen::Matrix2d m;
    for (int j = 0; j < 2; ++j) {
      const double d = 1e-6 * std::max(1.0, std::abs(x[j]));
      Eigen::Vector2d xp = x, xm = x;
      xp[j] += d, xm[j] -= d;
      m.col(j) = (gap_period_map(xp, w) - gap_period_map(xm, w)) / (2 * d);
    }
    return m;
  };
  *start_mismatch = (gap_period_map(x0, w) - x0).norm() / x0.norm();
  for (int it = 0; it < 8; ++it) {
    const Eigen::Vector2d r = gap_period_map(x0, w) - x0;
    if (r.norm() < 1e-12 * x0.norm()) break;
    x0 -= (monodromy(x0) - Eigen::Matrix2d::Identity()).partialPivLu().solve(r);
  }
  const Eigen::EigenSolver<Eigen::Matrix2d> es(monodromy(x0));
  return es.eigenvalues().cwiseAbs().maxCoeff();
}

/// (u(0), v(0)) of the gap oscillator's harmonic balance solution (contact direction z = u).
Eigen::Vector2d gap_state_at_zero(const ReducedEquations& eq, const Eigen::VectorXd& w, double frequency_hz) {
  const auto& layout = eq.pair_layout();
  const double omega = 2 * kPi * frequency_hz;
  Eigen::Vector2d x(w[layout.index(2, 0)], 0.0);
  for (int n = 1; n <= layout.n_harmonics(); ++n) {
    x[0] += w[layout.index(2, n, hbm::HarmonicLayout::Part::cosine)];
    x[1] += n * omega * w[layout.index(2, n, hbm::HarmonicLayout::Part::sine)];
  }
  return x;
}

/// The stuck chain's damped eigenvalues in closed form: s^2 M + s C + K + kt e0 e0^T = 0 as a
/// 4 x 4 companion eigenproblem.
Eigen::VectorXcd stuck_eigenvalues(const Lumped& l) {
  const auto& lin = static_cast<const frf::LumpedLinearPart&>(*l.model.linear);
  Eigen::MatrixXd kk = lin.stiffness();
  kk(0, 0) += 1.0;
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(4, 4);
  a.topRightCorner(2, 2).setIdentity();
  a.bottomLeftCorner(2, 2) = -lin.mass().inverse() * kk;
  a.bottomRightCorner(2, 2) = -lin.mass().inverse() * lin.damping();
  return Eigen::EigenSolver<Eigen::MatrixXd>(a).eigenvalues();
}

TEST(Stability, AStuckContactHasTheDampedEigenvaluesOfTheStuckSystemAtAnyTimeScale) {
  for (double s : {1e-3, 1.0, 1e3}) {
    Lumped l = stuck_chain(s);
    hbm::ContactEvaluator ev(l.options, l.model.pairs);
    ReducedEquations eq(*l.model.linear, ev);
    const double f = 1.1 / (2 * kPi * s);
    Eigen::VectorXd w;
    ASSERT_TRUE(solve_stuck_point(l, eq, s, f, w));
    const Eigen::VectorXcd exact = stuck_eigenvalues(l);
    const double omega = 2 * kPi * f;
    for (ExponentSelection sel : {ExponentSelection::symmetry, ExponentSelection::imaginary}) {
      const FloquetResult r = floquet_exponents(eq, w, f, sel);
      ASSERT_TRUE(r.available);
      EXPECT_TRUE(r.stable);
      EXPECT_EQ(r.hill_size, 2 * 2 * 11);
      ASSERT_EQ(r.exponents.size(), 4u) << "s = " << s;
      // Exponents are defined up to i k w (the same multiplier exp(lambda T)); the symmetric
      // copy of a linear system's is its own eigenvalue (k = 0), the one nearest the real axis
      // may be shifted. The Hill problem of a linear system is exact at any H: what is left is
      // the round-off of a 44 x 44 companion matrix with entries up to (w_max / w)^2 ~ 3.
      constexpr double kEigenTol = 1e-10;
      for (Eigen::Index j = 0; j < exact.size(); ++j) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const auto& g : r.exponents)
          for (int k = -5; k <= 5; ++k) {
            if (sel == ExponentSelection::symmetry && k != 0) continue;
            nearest = std::min(nearest, std::abs(g - exact[j] - std::complex<double>(0.0, k * omega)));
          }
        EXPECT_LT(nearest, kEigenTol * std::abs(exact[j])) << "s = " << s << " eigenvalue " << exact[j];
      }
    }
    // Hill's method with the slider as a state (ContactMemory): the same damped eigenvalues, and
    // the damper position is a neutral direction (exponent 0: a shifted damper is another periodic
    // solution); the damper motions the 2H + 1 harmonics do not see are not exponents.
    const ContactMemory memory = contact_memory(eq, w);
    ASSERT_TRUE(memory.carries_memory());
    const FloquetResult r =
        floquet_exponents(eq, w, f, ExponentSelection::symmetry, kMaxHillSize, kModeCutoff, &memory);
    ASSERT_TRUE(r.available) << r.reason;
    EXPECT_TRUE(r.stable);
    EXPECT_EQ(r.hill_size, 2 * 2 * 11 + 64);  // the companion and one damper position per sample
    ASSERT_EQ(r.exponents.size(), 5u) << "s = " << s;
    // The round-off of a 108-wide pencil solved by a shifted inverse (entries up to (w_max / w)^2).
    constexpr double kEigenTol = 1e-10;
    for (Eigen::Index j = 0; j < exact.size(); ++j) {
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& g : r.exponents) nearest = std::min(nearest, std::abs(g - exact[j]));
      EXPECT_LT(nearest, kEigenTol * std::abs(exact[j])) << "s = " << s << " eigenvalue " << exact[j];
    }
    int neutral = 0;
    for (const auto& g : r.exponents) neutral += std::abs(g) < kNeutralTolerance * omega ? 1 : 0;
    EXPECT_EQ(neutral, 1) << "s = " << s;
  }
}

TEST(Stability, AProblemAboveTheSizeLimitIsNotAnalysedAndSaysWhy) {
  Lumped l = stuck_chain(1.0);
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const double f = 1.1 / (2 * kPi);
  const FloquetResult r = floquet_exponents(eq, eq.stuck_solution(f), f, ExponentSelection::symmetry, 40);
  EXPECT_FALSE(r.available);
  EXPECT_EQ(r.hill_size, 44);  // 2 DOFs x 11 harmonics x 2
  EXPECT_NE(r.reason.find("44 wide"), std::string::npos) << r.reason;
  EXPECT_TRUE(r.exponents.empty());
}

TEST(Stability, HillAgreesWithShootingOnAHardeningGapOscillatorWithAFoldPair) {
  Lumped l = gap_oscillator();
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd) << r.summary.message;
  // Every point: Hill's verdict; about 12 of them spread over the curve: shooting's.
  std::vector<FloquetResult> hill;
  std::vector<double> freq, amp;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    hill.push_back(floquet_exponents(eq, r.points[i].x, r.points[i].lambda));
    freq.push_back(r.points[i].lambda);
    amp.push_back(r.results[i].amplitude);
  }
  int unstable = 0, compared = 0;
  double largest_difference = 0.0;
  for (const auto& h : hill) unstable += h.stable ? 0 : 1;
  EXPECT_GT(unstable, 5) << "the middle branch between the folds";
  const std::size_t every = std::max<std::size_t>(1, r.points.size() / 12);
  for (std::size_t i = 0; i < r.points.size(); i += every) {
    const double f = r.points[i].lambda, omega = 2 * kPi * f;
    double mismatch = 0.0;
    const double rho_shoot = shooting_spectral_radius(gap_state_at_zero(eq, r.points[i].x, f), omega, &mismatch);
    const double rho_hill = hill[i].spectral_radius(f);
    // The harmonic balance orbit (H = 15) is close to the true one: the shooting starts there.
    EXPECT_LT(mismatch, 1e-2) << "f = " << f;
    // Away from a change of stability (|rho - 1| > 0.01) both agree on the side of 1; the
    // multipliers themselves agree to the truncation of the orbit (H = 15 of a kinked motion):
    constexpr double kRhoTol = 0.01;  // measured 0.004 over 13 points
    if (std::abs(rho_shoot - 1.0) > 0.01) {
      EXPECT_EQ(rho_hill > 1.0, rho_shoot > 1.0) << "f = " << f << " hill " << rho_hill << " shooting " << rho_shoot;
      ++compared;
    }
    EXPECT_NEAR(rho_hill, rho_shoot, kRhoTol) << "f = " << f;
    largest_difference = std::max(largest_difference, std::abs(rho_hill - rho_shoot));
  }
  RecordProperty("compared", compared);
  RecordProperty("largest_multiplier_difference", std::to_string(largest_difference));
  EXPECT_GE(compared, 8);
  // The branch's geometry: the points traced backwards in frequency (between the two folds)
  // are unstable, those traced forwards stable, and the two changes are folds at the turning
  // points. Next to a fold the curve is nearly vertical (frequency steps of 1e-5 relative while
  // the amplitude moves by 3 %), so the sampled turning point and the change of sign of the
  // exponent may lie kFoldPoints points apart.
  constexpr std::size_t kFoldPoints = 2;
  std::vector<std::size_t> turns;
  for (std::size_t i = 1; i + 1 < freq.size(); ++i)
    if ((freq[i] - freq[i - 1]) * (freq[i + 1] - freq[i]) <= 0) turns.push_back(i);
  EXPECT_EQ(turns.size(), 2u);
  auto near_turn = [&](std::size_t i) {
    for (std::size_t t : turns)
      if (i + kFoldPoints >= t && i <= t + kFoldPoints) return true;
    return false;
  };
  for (std::size_t i = 1; i + 1 < r.points.size(); ++i) {
    if (near_turn(i)) continue;
    const bool backwards = freq[i + 1] < freq[i];
    EXPECT_EQ(hill[i].stable, !backwards) << "f = " << freq[i];
  }
  const std::vector<int> piece(r.points.size(), 0);
  const auto changes = stability_changes(hill, freq, amp, piece);
  ASSERT_EQ(changes.size(), 2u);
  for (const auto& c : changes) {
    EXPECT_EQ(c.kind, StabilityChange::Kind::fold);
    EXPECT_TRUE(near_turn(c.point)) << "change at " << c.frequency_hz << " Hz";
  }
}

/// Stress corpus model 105 (4 DOFs, quasi3d friction with separation, N = 64): its curve closes
/// on itself near 770 Hz, where several solutions coexist.
Lumped model_105() {
  Lumped l;
  Eigen::MatrixXd m(4, 4), k(4, 4), c(4, 4);
  m << 20.527841424563977, 0, 0, 0, 0, 104.54819099206871, 0, 0, 0, 0, 87.97837496433017, 0, 0, 0, 0,
      119.01449762240684;
  k << 4268575626.744325, 196050792.3089846, -1600439918.6397486, -996650982.536285, 196050792.3089846,
      5899021123.720413, -1636841536.2168021, -3729562681.3690977, -1600439918.6397486, -1636841536.2168021,
      3402412039.4073896, 1061079982.3023541, -996650982.536285, -3729562681.3690977, 1061079982.3023541,
      8950267825.224955;
  c << 116.30663967447224, 4.038083160984023, -32.964465022106594, -20.528147336507942, 4.038083160984023,
      266.07388172002027, -33.71423377967842, -76.81827797836853, -32.964465022106594, -33.71423377967842,
      191.7378866934617, 21.855199657849077, -20.528147336507942, -76.81827797836853, 21.855199657849077,
      348.9250503828979;
  frf::LumpedContact e;
  e.dof = {3, 1, 0};
  l.model.linear =
      std::make_unique<frf::LumpedLinearPart>(m, k, c, std::vector<frf::LumpedContact>{e}, 1, 0.008188408188264853, 2);
  contact::PairParameters p;
  p.friction_coefficient = 0.19079267070287287;
  p.tangential_stiffness = 150483167.26757142;
  p.normal_stiffness = 7150255545.2713;
  p.normal_preload = 9.762483354157716;
  l.model.pairs = {p};
  l.options.n_harmonics = 4;
  l.options.n_time_samples = 64;
  l.options.law.model = contact::Model::quasi3d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 545.0431703885854;
  l.f_end = 1391.629964680137;
  return l;
}

TEST(Stability, WhereFrictionGivesSeveralSolutionsTheTimeIntegrationSettlesOnAStableOne) {
  Lumped l = model_105();
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  const LumpedSystem system = system_of(l);
  // At 770 and 780 Hz the curve has three solutions (the branch from 545 Hz and two on the loop
  // above it). Integrated in time from rest, the motion settles on the one Hill's method calls
  // stable (measured 1.6 % from it: the sampled law at N = 64 against the time-continuous one,
  // forced/time_march.hpp) and on neither unstable one (2.2 to 4.6 away, relative).
  constexpr double kSameMotion = 0.05, kOtherMotion = 0.5;
  for (double f : {770.0, 780.0}) {
    const auto solutions = solutions_at_frequency(r, eq, f);
    ASSERT_GE(solutions.size(), 3u) << "f = " << f;
    TimeMarchOptions to;
    to.output_samples = l.options.n_time_samples;
    const TimeMarchResult tm = march_to_steady_state(system, l.model.pairs, l.options.law.model, f, to);
    ASSERT_EQ(tm.motion, TimeMarchResult::Motion::periodic) << tm.describe();
    const Eigen::VectorXd wm = harmonic_unknowns(tm.contact_motion, l.options.n_harmonics, 3);
    int stable = 0, unstable = 0;
    for (const auto& w : solutions) {
      const FloquetResult fl = floquet_exponents(eq, w, f);
      ASSERT_TRUE(fl.available);
      const double d = (w - wm).norm() / wm.norm();
      if (fl.stable) {
        ++stable;
        EXPECT_LT(d, kSameMotion) << "f = " << f;
      } else {
        ++unstable;
        EXPECT_GT(d, kOtherMotion) << "f = " << f;
      }
    }
    EXPECT_EQ(stable, 1) << "f = " << f;
    EXPECT_GE(unstable, 2) << "f = " << f;
  }
}

/// The shooting's state at t = 0 of the solution w, and its result.
ShootingResult shoot(ReducedEquations& eq, const Lumped& l, const Eigen::VectorXd& w, double f) {
  const LumpedSystem system = system_of(l);
  Eigen::VectorXd u0, v0, d0;
  harmonic_balance_state(eq, system, l.model.pairs, l.options.law.model, w, f, u0, v0, d0);
  return shooting_floquet(system, l.model.pairs, l.options.law.model, f, u0, v0, d0);
}

TEST(Shooting, AStuckContactHasTheDampedMultipliersOfTheStuckSystemAndANeutralSliderAtAnyTimeScale) {
  for (double s : {1e-3, 1.0, 1e3}) {
    Lumped l = stuck_chain(s);
    hbm::ContactEvaluator ev(l.options, l.model.pairs);
    ReducedEquations eq(*l.model.linear, ev);
    const double f = 1.1 / (2 * kPi * s);
    Eigen::VectorXd w;
    ASSERT_TRUE(solve_stuck_point(l, eq, s, f, w));
    const ShootingResult r = shoot(eq, l, w, f);
    ASSERT_TRUE(r.available) << r.reason;
    EXPECT_TRUE(r.stable);
    // The harmonic balance of a linear system is exact at any H: the state it gives is the
    // integration's periodic orbit but for the scheme's O(dt^2) error.
    constexpr double kSchemeError = 1e-4;
    EXPECT_LT(r.start_mismatch, kSchemeError) << "s = " << s;
    ASSERT_EQ(r.state_size, 5);  // u, v of 2 DOFs and one slider
    ASSERT_EQ(r.multipliers.size(), 5u);
    // Closed form: exp(lambda T) of the stuck chain's eigenvalues, and 1 for the stuck slider
    // (a shifted anchor gives another periodic orbit). The explicit scheme's error over a
    // period at 4096 steps: a relative frequency error (w_max dt)^2 / 24 ~ 2.5e-7 times
    // w_max T = 2 pi 1.73 / 1.1, ~3e-6 (measured 4.3e-5 at 1024 steps, 16 times more); the
    // slider's 1 is exact but for the forward differences' round-off.
    const Eigen::VectorXcd exact = stuck_eigenvalues(l);
    constexpr double kMultiplierTol = 1e-5, kNeutralTol = 1e-7;
    for (Eigen::Index j = 0; j < exact.size(); ++j) {
      const std::complex<double> mu = std::exp(exact[j] / f);
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& m : r.multipliers) nearest = std::min(nearest, std::abs(m - mu));
      EXPECT_LT(nearest, kMultiplierTol) << "s = " << s << " multiplier " << mu;
    }
    double neutral = std::numeric_limits<double>::infinity();
    for (const auto& m : r.multipliers) neutral = std::min(neutral, std::abs(m - 1.0));
    EXPECT_LT(neutral, kNeutralTol) << "s = " << s;
  }
}

TEST(Shooting, WhereFrictionGivesSeveralSolutionsItCallsStableTheOneTheTimeIntegrationSettlesOn) {
  Lumped l = model_105();
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  const LumpedSystem system = system_of(l);
  constexpr double kSameMotion = 0.05, kOtherMotion = 0.5;  // as for Hill above
  for (double f : {770.0, 780.0}) {
    const auto solutions = solutions_at_frequency(r, eq, f);
    ASSERT_GE(solutions.size(), 3u) << "f = " << f;
    TimeMarchOptions to;
    to.output_samples = l.options.n_time_samples;
    const TimeMarchResult tm = march_to_steady_state(system, l.model.pairs, l.options.law.model, f, to);
    ASSERT_EQ(tm.motion, TimeMarchResult::Motion::periodic) << tm.describe();
    const Eigen::VectorXd wm = harmonic_unknowns(tm.contact_motion, l.options.n_harmonics, 3);
    // The other two are 2.2 to 4.6 away (relative): at H = 4, N = 64 they lie on a loop of the
    // sampled law, and the time integration has no periodic orbit near them (their state's
    // mismatch over one period is above 1); they are either not judged or unstable.
    int stable = 0, others = 0;
    for (const auto& w : solutions) {
      const ShootingResult sh = shoot(eq, l, w, f);
      const double d = (w - wm).norm() / wm.norm();
      if (d < kSameMotion) {
        ASSERT_TRUE(sh.available) << sh.reason;
        EXPECT_TRUE(sh.stable) << "f = " << f << " spectral radius " << sh.spectral_radius;
        ++stable;
      } else {
        EXPECT_GT(d, kOtherMotion) << "f = " << f;
        EXPECT_TRUE(!sh.available || !sh.stable) << "f = " << f;
        if (!sh.available) {
          EXPECT_NE(sh.reason.find("no periodic orbit"), std::string::npos) << sh.reason;
        }
        ++others;
      }
    }
    EXPECT_EQ(stable, 1) << "f = " << f;
    EXPECT_GE(others, 2) << "f = " << f;
  }
}

/// Stress corpus model 8 (3 DOFs, quasi3d friction, H = 15, N = 128): Hill's linearization
/// calls stretches of its curve unstable.
Lumped model_8() {
  Lumped l;
  Eigen::MatrixXd m(3, 3), k(3, 3), c(3, 3);
  m << 1.6066451485192936, 0, 0, 0, 3.1022110663309252, 0, 0, 0, 2.111869185489189;
  k << 7.043627933089065, 2.534038191691849, -1.3796205878592054, 2.534038191691849, 3.712810230293924,
      1.5670428633530467, -1.3796205878592054, 1.5670428633530467, 3.0050000077515504;
  c << 0.44199958292165586, 0.15901518854703842, -0.08657352861573811, 0.15901518854703842, 0.23298513051035977,
      0.098334593848804, -0.08657352861573811, 0.098334593848804, 0.18856884019472284;
  frf::LumpedContact e;
  e.dof = {0, 1, 2};
  l.model.linear =
      std::make_unique<frf::LumpedLinearPart>(m, k, c, std::vector<frf::LumpedContact>{e}, 1, 1.1286367840819407, 2);
  contact::PairParameters p;
  p.friction_coefficient = 0.28024622979545577;
  p.tangential_stiffness = 17.127970366335703;
  p.normal_stiffness = 4.789290774238505;
  p.normal_preload = 8.532175357752111;
  l.model.pairs = {p};
  l.options.n_harmonics = 15;
  l.options.n_time_samples = 128;
  l.options.law.model = contact::Model::quasi3d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 0.053803261612576106;
  l.f_end = 0.1156911635999745;
  return l;
}

TEST(Shooting, PointsHillCallsUnstableWhereTheTimeIntegrationSettlesAreStable) {
  Lumped l = model_8();
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd);
  const LumpedSystem system = system_of(l);
  // Four points spread over the stretches Hill calls unstable; at each the integration from
  // rest settles on the harmonic-balance solution (the sampled law at N = 128 against the
  // time-continuous one: measured 2e-4 at 0.0613 and 0.0690 Hz), so the solution attracts and
  // the shooting must call it stable.
  std::vector<std::size_t> hill_unstable;
  for (std::size_t i = 0; i < r.points.size(); ++i)
    if (!floquet_exponents(eq, r.points[i].x, r.points[i].lambda).stable) hill_unstable.push_back(i);
  ASSERT_GE(hill_unstable.size(), 4u) << "Hill's linearization no longer calls this curve unstable anywhere: "
                                         "the test's premise is gone";
  constexpr double kSettledOnIt = 1e-2;
  int checked = 0;
  for (int q = 0; q < 4; ++q) {
    const std::size_t i = hill_unstable[q * (hill_unstable.size() - 1) / 3];
    const double f = r.points[i].lambda;
    TimeMarchOptions to;
    to.output_samples = l.options.n_time_samples;
    const TimeMarchResult tm = march_to_steady_state(system, l.model.pairs, l.options.law.model, f, to);
    if (tm.motion != TimeMarchResult::Motion::periodic) continue;
    const Eigen::VectorXd wm = harmonic_unknowns(tm.contact_motion, l.options.n_harmonics, 3);
    const double d = (r.points[i].x - wm).norm() / wm.norm();
    if (d > kSettledOnIt) continue;  // another solution attracts here: nothing to conclude
    ++checked;
    const ShootingResult sh = shoot(eq, l, r.points[i].x, f);
    ASSERT_TRUE(sh.available) << sh.reason;
    EXPECT_TRUE(sh.stable) << "f = " << f << " spectral radius " << sh.spectral_radius;
  }
  EXPECT_GE(checked, 2);
}

// Against the shooting on the time integration (the law in continuous time), on stress model 8
// (quasi3d, H = 15, N = 128, every 5th point of its curve): the harmonic balance's dF/dW calls
// points unstable where the integration from rest settles on the solution; with the slider as a
// state every verdict is the shooting's, and the spectral radius exp(max_real T) is within
// kRadiusTol of the shooting's. The two are different discretizations of the law (sampled at
// N = 128 and truncated at H = 15, against the time-continuous law): measured 0.061 at worst
// (0.391 against 0.452 at 0.0999 Hz), 0.01 typically, over 41 points.
/// Hill's method with the slider as a state against the shooting at every 5th point of l's curve:
/// the same verdict wherever the shooting judges, and (radius_tol > 0) the spectral radius within
/// radius_tol. Returns the points judged; *old_disagree counts the harmonic balance
/// linearization's verdicts that differ from the shooting's. samples: the slider state's time
/// samples (0: the harmonic balance's N; contact_memory).
int compare_with_shooting(const Lumped& l, double radius_tol, int* old_disagree, int samples = 0) {
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  EXPECT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd);
  int judged = 0;
  *old_disagree = 0;
  for (std::size_t i = 0; i < r.points.size(); i += 5) {
    const double f = r.points[i].lambda;
    const ContactMemory memory = contact_memory(eq, r.points[i].x, samples);
    EXPECT_EQ(static_cast<int>(memory.steps.front().size()), samples > 0 ? samples : l.options.n_time_samples);
    const FloquetResult hill =
        floquet_exponents(eq, r.points[i].x, f, ExponentSelection::symmetry, kMaxHillSize, kModeCutoff, &memory);
    EXPECT_TRUE(hill.available) << hill.reason;
    const ShootingResult sh = shoot(eq, l, r.points[i].x, f);
    if (!sh.available || !hill.available) continue;
    ++judged;
    EXPECT_EQ(hill.stable, sh.stable) << "f = " << f;
    if (radius_tol > 0.0) {
      EXPECT_NEAR(hill.spectral_radius(f), sh.spectral_radius, radius_tol) << "f = " << f;
    }
    *old_disagree += floquet_exponents(eq, r.points[i].x, f).stable != sh.stable ? 1 : 0;
  }
  return judged;
}

// Against the shooting on the time integration (the law in continuous time), on stress model 8
// (quasi3d, H = 15, N = 128, every 5th point of its curve): the harmonic balance's dF/dW calls
// points unstable where the integration from rest settles on the solution; with the slider as a
// state every verdict is the shooting's, and the spectral radius exp(max_real T) is within
// kRadiusTol of the shooting's. The two are different discretizations of the law (sampled at
// N = 128 and truncated at H = 15, against the time-continuous law): measured 0.061 at worst
// (0.391 against 0.452 at 0.0999 Hz), 0.01 typically, over 41 points.
TEST(Stability, WithTheSliderAsAStateHillGivesTheShootingsVerdictWhereTheHarmonicBalanceLinearizationDoesNot) {
  constexpr double kRadiusTol = 0.08;
  int old_disagree = 0;
  EXPECT_GE(compare_with_shooting(model_8(), kRadiusTol, &old_disagree), 35);
  EXPECT_GE(old_disagree, 4) << "dF/dW no longer disagrees with the shooting here: the test's premise is gone";
}

// The slider state sampled at N / 2 (response.stability_samples; ContactMemory::correction keeps
// the harmonic balance's linearization at lambda = 0): on stress models 8 (N = 128, 64 samples)
// and 105 (N = 64, 32 samples) every verdict the shooting gives is the same, as at N. The radius
// is the coarser law's: on model 8 within 0.199 of the shooting's (0.061 at N; 0.417 at 32
// samples, where 2H + 1 = 31), so kCoarseRadiusTol = 0.25.
TEST(Stability, WithTheSliderStateSampledAtHalfTheHarmonicBalancesNHillKeepsTheShootingsVerdicts) {
  constexpr double kCoarseRadiusTol = 0.25;
  int old_disagree = 0;
  EXPECT_GE(compare_with_shooting(model_8(), kCoarseRadiusTol, &old_disagree, 64), 35);
  EXPECT_GE(compare_with_shooting(model_105(), 0.0, &old_disagree, 32), 40);
}

// The count of the slider state's samples (forced::memory_samples): what is asked for, within
// 2H + 1 and N; automatic: N where the dampers' positions fit, else the most that fit.
TEST(Stability, TheSliderStatesSamplesAreWhatIsAskedForWithin2HPlus1AndN) {
  EXPECT_EQ(memory_samples(64, 128, 15, 2), 64);
  EXPECT_EQ(memory_samples(16, 128, 15, 2), 31);                      // raised to 2H + 1
  EXPECT_EQ(memory_samples(4096, 128, 15, 2), 128);                   // at most N
  EXPECT_EQ(memory_samples(0, 128, 15, 2), 128);                      // 256 positions fit
  EXPECT_EQ(memory_samples(0, 512, 5, 10), kMaxMemoryUnknowns / 10);  // the default sector: 80
  EXPECT_EQ(memory_samples(0, 512, 60, 10), 121);                     // never below 2H + 1
  EXPECT_EQ(memory_samples(0, 64, 5, 0), 64);                         // no damper
}

// Stress model 105 (quasi3d with separation, N = 64), where the curve closes on itself near
// 770 Hz: at every 5th point the shooting judges, Hill's method with the slider as a state gives
// its verdict.
TEST(Stability, WithTheSliderAsAStateHillGivesTheShootingsVerdictWithSeparation) {
  int old_disagree = 0;
  EXPECT_GE(compare_with_shooting(model_105(), 0.0, &old_disagree), 40);
}

/// Stress model 10: full3d, tangential stiffness 9.2e3 times the structure's, friction limit
/// 0.35 N that the contact passes at 6e-11 m of elastic slip, so the contact slides all period
/// (gross slip in 2D, never sticking).
Lumped model_10() {
  Lumped l;
  Eigen::MatrixXd m(3, 3), k(3, 3), c(3, 3);
  m << 29.85034057698487, 0, 0, 0, 102.93873162168062, 0, 0, 0, 84.84222353890458;
  k << 1086424.1901091582, -330048.6731427646, 0, -330048.6731427646, 571251.5511153011, -241202.8779725365, 0,
      -241202.8779725365, 241202.8779725365;
  c << 480.84762201385143, -125.24120660006022, 0, -125.24120660006022, 453.3010138083131, -91.52752890971529, 0,
      -91.52752890971529, 286.47771057043695;
  frf::LumpedContact e;
  e.dof = {2, 0, 1};
  e.frame_angle = 17.788066177852645 * kPi / 180.0;
  l.model.linear =
      std::make_unique<frf::LumpedLinearPart>(m, k, c, std::vector<frf::LumpedContact>{e}, 0, 1.7488591893641139, 0);
  contact::PairParameters p;
  p.friction_coefficient = 0.9706320699252488;
  p.tangential_stiffness = 5828512117.593811;
  p.normal_stiffness = 27145.21545948309;
  p.normal_preload = 0.36283099536729657;
  l.model.pairs = {p};
  l.options.n_harmonics = 4;
  l.options.n_time_samples = 64;
  l.options.law.model = contact::Model::full3d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 7.429184386875069;
  l.f_end = 20.578211974288244;
  return l;
}

// A contact that slides at the period's start has its slider on the friction limit, where the
// explicit scheme's period map has a kink the time-continuous motion does not (a difference
// that moves the trial force inside the limit holds the slider for a whole first step). On
// stress model 10, whose contact slides all period, one-sided differences gave spectral radii
// 1.1 to 4.5 (145 of 203 points unstable) where the time integration from rest settles on the
// solution within 30 to 72 periods. At every 20th point: the integration from rest settles
// within kSettledOnIt of the harmonic-balance solution (its own truncation at H = 4, N = 64:
// measured 1.3 to 3.4 %), so the solution attracts and the shooting must call it stable; and
// the shooting's spectral radius is Hill's (slider as a state) within kRadiusTol, the tolerance
// measured on model 8 (here: 0.059 at worst, 0.458 / 0.465 at the first point).
TEST(Shooting, AContactSlidingAtThePeriodsStartIsDifferencedAlongItsSlidingMotion) {
  constexpr double kSettledOnIt = 0.05, kRadiusTol = 0.08;
  const Lumped l = model_10();
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  const FrequencyResponse r = trace_whole_range(l, eq);
  ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd);
  const LumpedSystem system = system_of(l);
  int settled = 0;
  for (std::size_t i = 0; i < r.points.size(); i += 20) {
    const double f = r.points[i].lambda;
    TimeMarchOptions to;
    to.output_samples = l.options.n_time_samples;
    const TimeMarchResult tm = march_to_steady_state(system, l.model.pairs, l.options.law.model, f, to);
    ASSERT_EQ(tm.motion, TimeMarchResult::Motion::periodic) << "f = " << f << ": " << tm.describe();
    const Eigen::VectorXd wm = harmonic_unknowns(tm.contact_motion, l.options.n_harmonics, 3);
    if ((r.points[i].x - wm).norm() / wm.norm() <= kSettledOnIt) ++settled;
    const ShootingResult sh = shoot(eq, l, r.points[i].x, f);
    ASSERT_TRUE(sh.available) << "f = " << f << ": " << sh.reason;
    EXPECT_TRUE(sh.stable) << "f = " << f << " spectral radius " << sh.spectral_radius;
    const ContactMemory memory = contact_memory(eq, r.points[i].x);
    const FloquetResult hill =
        floquet_exponents(eq, r.points[i].x, f, ExponentSelection::symmetry, kMaxHillSize, kModeCutoff, &memory);
    ASSERT_TRUE(hill.available) << hill.reason;
    EXPECT_NEAR(sh.spectral_radius, hill.spectral_radius(f), kRadiusTol) << "f = " << f;
  }
  EXPECT_EQ(settled, static_cast<int>((r.points.size() + 19) / 20));
}

}  // namespace
}  // namespace shroudsim::forced
