// The frequency response as the commands trace it (forced/frequency_response.hpp): invariance
// under a rescaling of time, the default settings on a small chain against a fine reference,
// resonance peaks located independently of the step, the same curve whatever the thread
// count, and where the start search resumes a lower level's homotopy path.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

#include "forced/frequency_response.hpp"
#include "frf/lumped.hpp"
#include "three_contacts.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;

/// A lumped model with its contact pairs and the evaluator options it is traced with.
struct Lumped {
  ForcedModel model;
  hbm::ContactEvaluatorOptions options;
  double f_start = 0.0, f_end = 0.0;
};

/// The 2-DOF chain: M = s^2 I, K = [[2, -1], [-1, 2]], C = 0.02 s K, a Jenkins element on
/// DOF 0 (kt = 1, mu N0 = 1.5), 1 N on DOF 0, 0.8 to 1.4 rad/s (divided by s). s rescales
/// time: every curve is the same with frequencies divided by s.
Lumped chain(double s, int h = 7, int n = 256) {
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
  p.friction_coefficient = 1.5;
  p.normal_preload = 1.0;
  l.model.pairs = {p};
  l.options.n_harmonics = h;
  l.options.n_time_samples = n;
  l.options.law.model = contact::Model::one_d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 0.8 / (2 * kPi * s);
  l.f_end = 1.4 / (2 * kPi * s);
  return l;
}

/// A point mass (x, y, z; 10 Hz, 1 kg, 1 % damping; time rescaled by s) on a full3d contact
/// to ground with preload: stick, slip and separation over the period near resonance.
Lumped mass_on_full3d(double s) {
  Lumped l;
  const double k0 = std::pow(2 * kPi * 10.0, 2);
  const Eigen::MatrixXd id = Eigen::MatrixXd::Identity(3, 3);
  frf::LumpedContact c;
  c.dof = {0, 1, 2};
  c.frame_angle = 0.3;
  l.model.linear = std::make_unique<frf::LumpedLinearPart>(s * s * id, k0 * id, s * 2 * 0.01 * std::sqrt(k0) * id,
                                                           std::vector<frf::LumpedContact>{c}, 0, 1.0, 0);
  contact::PairParameters p;
  p.tangential_stiffness = k0;
  p.normal_stiffness = k0;
  p.friction_coefficient = 0.3;
  p.normal_preload = 1.0;
  l.model.pairs = {p};
  l.options.n_harmonics = 5;
  l.options.n_time_samples = 128;
  l.options.law.model = contact::Model::full3d;
  l.options.threads = 1;
  l.options.measure_plans = false;
  l.f_start = 5.0 / s;
  l.f_end = 25.0 / s;
  return l;
}

/// Three masses in a chain, each on a full3d contact (three_contacts.hpp), H = 3,
/// N = 64, 6 to 12 Hz.
Lumped three_contacts(int threads) {
  Lumped l;
  l.model.linear = std::make_unique<frf::LumpedLinearPart>(testing::three_contacts_linear());
  l.model.pairs = testing::three_contacts_pairs();
  l.options.n_harmonics = 3;
  l.options.n_time_samples = 64;
  l.options.law.model = contact::Model::full3d;
  l.options.threads = threads;
  l.options.measure_plans = false;
  l.f_start = 6.0;
  l.f_end = 12.0;
  return l;
}

FrequencyResponse trace(Lumped& l, double initial_step_hz = 0.0) {
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  FrequencyResponseSettings s;  // the defaults of the case file
  s.frequency_start_hz = l.f_start;
  s.frequency_end_hz = l.f_end;
  s.initial_step_hz = initial_step_hz;
  return trace_frequency_response(s, l.model, l.options, eq);
}

const ResponsePeak& largest(const FrequencyResponse& r) {
  const ResponsePeak* best = &r.peaks.front();
  for (const auto& p : r.peaks)
    if (p.amplitude_m > best->amplitude_m) best = &p;
  return *best;
}

// Two curves whose scaled equations agree to round-off: the located peaks agree to the
// corrector's tolerance (1e-8 on residuals of the size of the x unit, 1/20 of the free peak).
constexpr double kPeakTol = 1e-6;

void expect_time_rescaling_invariance(Lumped (*make)(double)) {
  std::vector<FrequencyResponse> r;
  const std::vector<double> scales = {1e-3, 1.0, 1e3};
  for (double s : scales) {
    Lumped l = make(s);
    r.push_back(trace(l));
    ASSERT_EQ(r.back().summary.status, continuation::BranchStatus::kReachedEnd)
        << "s = " << s << ": " << r.back().summary.message;
    ASSERT_FALSE(r.back().peaks.empty());
  }
  for (std::size_t i = 0; i < r.size(); ++i) {
    EXPECT_EQ(r[i].points.size(), r[1].points.size()) << "s = " << scales[i];
    EXPECT_EQ(r[i].peaks.size(), r[1].peaks.size()) << "s = " << scales[i];
    const ResponsePeak &a = largest(r[i]), &b = largest(r[1]);
    EXPECT_TRUE(a.located);
    EXPECT_NEAR(a.amplitude_m, b.amplitude_m, kPeakTol * b.amplitude_m) << "s = " << scales[i];
    EXPECT_NEAR(a.frequency_hz * scales[i], b.frequency_hz, kPeakTol * b.frequency_hz) << "s = " << scales[i];
  }
}

TEST(StartSearch, TheResumedHomotopyStartsAtTheLastPointThatServesNotAtABoundaryInTheMiddle) {
  // last_serving_point on patterns of where Newton at the next level converges from a lower
  // path's points (0..85, the last the full excitation, where it failed). Each pattern names
  // the answer; the attempts are counted (each is a Newton solve at the new level).
  struct Pattern {
    const char* what;
    std::function<bool(int)> serves;
    int expected;
  };
  const std::vector<Pattern> patterns = {
      // Like the 227-pair sector's H = 2 path at 96 Hz (BENCHMARKS.md: served at 21, 27, 69 and
      // 71; failed at 28 to 43 where tried, and from 72 on). A bisection from the middle finds 27.
      {"two stretches", [](int i) { return (i >= 1 && i <= 27) || (i >= 44 && i <= 71); }, 71},
      {"one stretch up to 60", [](int i) { return i >= 1 && i <= 60; }, 60},
      {"only the point before the end", [](int i) { return i == 84; }, 84},
      {"only the first point", [](int i) { return i == 1; }, 1},
      {"none", [](int) { return false; }, -1},
  };
  for (const Pattern& p : patterns) {
    int attempts = 0;
    const int found = last_serving_point(85, [&](int i) {
      EXPECT_GE(i, 1) << p.what;   // the preload-only state is never tried
      EXPECT_LT(i, 85) << p.what;  // nor the full excitation, where Newton failed
      ++attempts;
      return p.serves(i);
    });
    EXPECT_EQ(found, p.expected) << p.what;
    // The descent takes at most 8 attempts over 85 points and the bisection after it fewer
    // than the gap it bisects: never more than two bisections of the whole path.
    EXPECT_LE(attempts, 16) << p.what;
  }
}

TEST(StartSearch, TheResumedHomotopyStartsAtTheHighestExcitationLevelThatServes) {
  // Like the 227-pair sector's H = 1 path at 104 Hz (129 points, highest_serving_point): the
  // excitation level rises to 0.334 at point 44, falls back to 0.035 at point 97 and rises to
  // the full level 1 at point 128, where Newton at H = 2 failed. Newton serves from points 1 to
  // 72 but 34, 35 and 69, and from 90 to 102.
  constexpr int kPoints = 129;
  std::vector<double> levels(kPoints);
  for (int i = 0; i < kPoints; ++i)
    levels[static_cast<std::size_t>(i)] = i <= 44   ? 0.334 * i / 44
                                          : i <= 97 ? 0.334 + (0.035 - 0.334) * (i - 44) / 53
                                                    : 0.035 + (1.0 - 0.035) * (i - 97) / 31;
  auto serves = [](int i) { return (i >= 1 && i <= 72 && i != 34 && i != 35 && i != 69) || (i >= 90 && i <= 102); };
  int attempts = 0;
  const int found = highest_serving_point(levels, 1.0, [&](int i) {
    EXPECT_GE(i, 1);            // the preload-only state is never tried
    EXPECT_LT(i, kPoints - 1);  // nor the full excitation
    ++attempts;
    return serves(i);
  });
  EXPECT_EQ(found, 44);  // the highest level at which Newton serves
  // The same bound as the search along the path: 8 attempts to descend, fewer than the gap after.
  EXPECT_LE(attempts, 16);
  // The search along the path stops at the last stretch, at a tenth of that level.
  EXPECT_EQ(last_serving_point(kPoints - 1, serves), 102);
  // Nothing serves: -1, and every attempt is within the candidates.
  EXPECT_EQ(highest_serving_point(levels, 1.0, [](int) { return false; }), -1);
  // Levels at or above the full one (a path that overshot it) are not candidates.
  std::vector<double> overshoot = levels;
  overshoot[44] = 1.0;
  EXPECT_EQ(highest_serving_point(overshoot, 1.0, serves), 45);
}

TEST(FrequencyResponse, TimeRescalingGivesTheSameCurveOneDimensionalJenkinsChain) {
  expect_time_rescaling_invariance(+[](double s) { return chain(s); });
}

TEST(FrequencyResponse, TimeRescalingGivesTheSameCurveFullThreeDimensionalContact) {
  expect_time_rescaling_invariance(&mass_on_full3d);
}

TEST(FrequencyResponse, TwoDofChainWithDefaultSettingsMatchesAFineReference) {
  Lumped l = chain(1.0);
  const FrequencyResponse r = trace(l);
  ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd) << r.summary.message;
  EXPECT_FALSE(r.two_pieces);
  // Reference: H = 25, N = 2048 (converged in H and N to ~1e-5 on this curve).
  Lumped fine = chain(1.0, 25, 2048);
  const FrequencyResponse ref = trace(fine);
  ASSERT_EQ(ref.summary.status, continuation::BranchStatus::kReachedEnd) << ref.summary.message;
  // The goal: the peak within 2e-3 of a fine reference (H = 7 truncates the
  // harmonics; measured 8e-5).
  constexpr double kReferenceTol = 2e-3;
  EXPECT_NEAR(largest(r).amplitude_m, largest(ref).amplitude_m, kReferenceTol * largest(ref).amplitude_m);
  EXPECT_NEAR(largest(r).frequency_hz, largest(ref).frequency_hz, kReferenceTol * largest(ref).frequency_hz);
}

TEST(FrequencyResponse, PeakLocationDoesNotDependOnTheStep) {
  std::vector<ResponsePeak> peaks;
  for (double step_hz : {0.0, 2e-5, 1e-4}) {  // auto (0.25 units = 2.4e-4 Hz), and two smaller
    Lumped l = chain(1.0);
    const FrequencyResponse r = trace(l, step_hz);
    ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd) << r.summary.message;
    peaks.push_back(largest(r));
    EXPECT_TRUE(peaks.back().located);
  }
  for (const auto& p : peaks) {
    EXPECT_NEAR(p.amplitude_m, peaks[0].amplitude_m, kPeakTol * peaks[0].amplitude_m);
    EXPECT_NEAR(p.frequency_hz, peaks[0].frequency_hz, kPeakTol * peaks[0].frequency_hz);
  }
}

TEST(FrequencyResponse, TheLocatedPeakIsTheHighestOfADenseScanAtFixedFrequencies) {
  // Three masses on full3d contacts: the located largest peak against Newton at fixed
  // frequency on kScan + 1 frequencies across 0.2 % of it (each started from the last), solved
  // to 1e-12 of the peak's motion. No scanned amplitude may exceed the located one beyond that
  // tolerance, and the highest scanned one lies within a scan spacing of it.
  Lumped l = three_contacts(1);
  hbm::ContactEvaluator ev(l.options, l.model.pairs);
  ReducedEquations eq(*l.model.linear, ev);
  FrequencyResponseSettings s;
  s.frequency_start_hz = l.f_start;
  s.frequency_end_hz = l.f_end;
  const FrequencyResponse r = trace_frequency_response(s, l.model, l.options, eq);
  ASSERT_EQ(r.summary.status, continuation::BranchStatus::kReachedEnd) << r.summary.message;
  const ResponsePeak& pk = largest(r);
  ASSERT_TRUE(pk.located);
  constexpr double kScanTol = 1e-12;
  continuation::ArclengthOptions o = r.options;
  o.tolerance = kScanTol * pk.x.lpNorm<Eigen::Infinity>() / o.x_scale.maxCoeff();
  constexpr int kScan = 1001;  // odd: the located frequency itself is not on the grid
  const double width = 2e-3 * pk.frequency_hz;
  Eigen::VectorXd x = pk.x;
  double best = 0, best_f = 0;
  for (int j = 0; j <= kScan; ++j) {
    const double f = pk.frequency_hz - width / 2 + width * j / kScan;
    ASSERT_GE(continuation::newton_fixed(eq, x, f, o), 0) << f;
    const double a = eq.analyse(x, f).amplitude;
    if (a > best) best = a, best_f = f;
  }
  EXPECT_LE(best, pk.amplitude_m * (1 + 1e3 * kScanTol));  // amplitude error of the scan's solutions
  EXPECT_NEAR(best_f, pk.frequency_hz, width / kScan);
}

TEST(FrequencyResponse, TheSameCurveBitForBitWhateverTheThreadCount) {
  // Three masses in a chain, each on a full3d contact; the GMRES path of the bordered solves
  // (forced) as well as the dense one.
  for (auto kind : {LinearSolverOptions::Kind::dense, LinearSolverOptions::Kind::krylov}) {
    std::vector<FrequencyResponse> r;
    for (int threads : {1, 2}) {
      Lumped l = three_contacts(threads);
      hbm::ContactEvaluator ev(l.options, l.model.pairs);
      ReducedEquations eq(*l.model.linear, ev);
      LinearSolverOptions so;
      so.kind = kind;
      eq.set_linear_solver(so);
      FrequencyResponseSettings s;
      s.frequency_start_hz = l.f_start;
      s.frequency_end_hz = l.f_end;
      r.push_back(trace_frequency_response(s, l.model, l.options, eq));
    }
    ASSERT_EQ(r[0].points.size(), r[1].points.size());
    for (std::size_t i = 0; i < r[0].points.size(); ++i) {
      ASSERT_EQ(r[0].points[i].lambda, r[1].points[i].lambda) << i;
      ASSERT_TRUE(r[0].points[i].x == r[1].points[i].x) << i;
    }
  }
}

TEST(FrequencyResponse, APeakFoundTwiceIsReportedOnce) {
  // A peak located twice on one piece (the default case at N = 512 had copies 1.3e-8 Hz apart),
  // a copy on an overlapping piece, a distinct peak 0.1 % of a unit away with the same amplitude
  // to 1e-6, and a sampled (not located) maximum at the same place: four peaks, by frequency
  // (ties in input order).
  constexpr double kUnit = 0.6;  // Hz
  std::vector<ResponsePeak> peaks{{200.1231711440621, 4.410422618626866e-05, 7, 0, true, {}},
                                  {206.7, 4.03e-05, 90, 1, false, {}},
                                  {200.12317113133594, 4.410422618629212e-05, 5, 0, true, {}},
                                  {200.1231712, 4.4104226186e-05, 300, 1, true, {}},
                                  {200.1237711, 4.41042e-05, 9, 0, true, {}},
                                  {200.12317113133594, 4.410422618629212e-05, 6, 0, false, {}}};
  const std::vector<ResponsePeak> d = distinct_peaks(peaks, kUnit);
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[0].point, 5u);  // the lowest-frequency copy is kept
  EXPECT_FALSE(d[1].located);
  EXPECT_EQ(d[2].point, 9u);
  EXPECT_EQ(d[3].point, 90u);
}

TEST(FrequencyResponse, ATopPassedAgainIsRecognisedFromItsLocatedPeak) {
  // The curve samples a top at three points (unit scales); peaks located on an earlier pass.
  auto point = [](double lambda, double x) {
    continuation::BranchPoint p;
    p.lambda = lambda;
    p.x = Eigen::VectorXd::Constant(1, x);
    return p;
  };
  const continuation::BranchPoint a = point(99.0, 0.90), b = point(100.0, 1.00), c = point(101.0, 0.92);
  const std::array<const continuation::BranchPoint*, 3> top = {&a, &b, &c};
  const Eigen::VectorXd unit = Eigen::VectorXd::Ones(1);
  auto peak = [](double lambda, double x, double amplitude, bool located) {
    ResponsePeak p;
    p.frequency_hz = lambda;
    p.amplitude_m = amplitude;
    p.located = located;
    p.x = Eigen::VectorXd::Constant(1, x);
    return p;
  };
  // The steps are ~1 long: the top located 0.1 beside the sampled maximum, higher than it.
  EXPECT_TRUE(is_sampled_top(peak(100.1, 1.01, 1.01, true), top, 1.0, unit, 1.0));
  // The same with the frequency in a unit of 0.5: the steps double, the peak stays by the polyline.
  EXPECT_TRUE(is_sampled_top(peak(100.1, 1.01, 1.01, true), top, 1.0, unit, 0.5));
  // Lower than the sampled maximum (beyond the corrector's precision): another top.
  EXPECT_FALSE(is_sampled_top(peak(100.1, 1.01, 0.999, true), top, 1.0, unit, 1.0));
  // Higher, but 0.3 steps off the polyline (in x): another top.
  EXPECT_FALSE(is_sampled_top(peak(100.0, 1.3, 1.3, true), top, 1.0, unit, 1.0));
  // Beyond the bracket: another top.
  EXPECT_FALSE(is_sampled_top(peak(101.5, 0.95, 1.01, true), top, 1.0, unit, 1.0));
  // A sampled maximum (not located) is never taken for a top.
  EXPECT_FALSE(is_sampled_top(peak(100.1, 1.01, 1.01, false), top, 1.0, unit, 1.0));
}

}  // namespace
}  // namespace shroudsim::forced
