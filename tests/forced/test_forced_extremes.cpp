// The extremes matrix of the forced response (issue 6): contact stiffness, preload, friction,
// damping, harmonics and samples at the edges of what users set, on small lumped models.
// Every run must reach the end of its range (or stop with a message and the points it has),
// with no non-finite value, energy balance at every point, and the answer the limit implies:
// the free response where the contact can do nothing (mu = 0, a gap that never closes), the
// stuck linear response where it cannot slip (huge friction or preload), and in between a
// response no larger than the larger of those two.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "continuation/arclength.hpp"
#include "forced/frequency_response.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/lumped.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;

enum class Expect { free, stuck, bounded };

struct Extreme {
  const char* name;
  contact::Model model;
  double kt, kn, mu, n0, zeta;
  int h, n;
  Expect expect;
};

std::string name_of(const ::testing::TestParamInfo<Extreme>& info) { return info.param.name; }

/// A 3-DOF point mass (x, y, z; f_n = 10 Hz each, m = 1 kg) on a contact element to ground,
/// forced along x and y (1 N each: F = 1 N in x; the y DOF is driven through the coupled law)
/// with the normal DOF z carrying the preload; the 1d models use x alone.
class Extremes : public ::testing::TestWithParam<Extreme> {};

TEST_P(Extremes, ConvergeToTheLimitOrStopCleanly) {
  const Extreme& e = GetParam();
  const bool one_d = e.model == contact::Model::one_d;
  const int dofs = one_d ? 1 : 3;
  const double m = 1.0, k = std::pow(2 * kPi * 10.0, 2), c = 2 * e.zeta * std::sqrt(k * m), force = 1.0;
  frf::LumpedContact lc;
  lc.dof = one_d ? std::array<int, 3>{0, -1, -1} : std::array<int, 3>{0, 1, 2};
  ForcedModel model;
  model.linear = std::make_unique<frf::LumpedLinearPart>(
      Eigen::MatrixXd::Identity(dofs, dofs) * m, Eigen::MatrixXd::Identity(dofs, dofs) * k,
      Eigen::MatrixXd::Identity(dofs, dofs) * c, std::vector<frf::LumpedContact>{lc}, 0, force, 0);
  contact::PairParameters pair;
  pair.tangential_stiffness = e.kt;
  pair.normal_stiffness = e.kn;
  pair.friction_coefficient = e.mu;
  pair.normal_preload = e.n0;
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = e.h;
  o.n_time_samples = e.n;
  o.law.model = e.model;
  o.threads = 1;
  model.pairs = {pair};
  hbm::ContactEvaluator ev(o, model.pairs);
  ReducedEquations eq(*model.linear, ev);

  // The frequency response as the frf command traces it (units from the problem, start
  // search, second piece), with the default continuation settings.
  FrequencyResponseSettings settings;
  settings.frequency_start_hz = 5.0;
  settings.frequency_end_hz = 25.0;
  settings.max_points = 4000;
  settings.tolerance = 1e-9;
  const FrequencyResponse response = trace_frequency_response(settings, model, o, eq);
  continuation::Branch b = response.summary;
  b.points = response.points;
  ASSERT_FALSE(b.points.empty()) << b.message;
  if (b.status != continuation::BranchStatus::kReachedEnd) {
    // A stop is allowed only with a reason and what was computed; this matrix expects none.
    EXPECT_FALSE(b.message.empty());
    ADD_FAILURE() << e.name << ": stopped at " << b.points.back().lambda << " Hz: " << b.message;
  }

  // Energy balance is relative to the excitation work; Newton converges to 1e-9 of W's scale.
  constexpr double kEnergyTol = 1e-5;
  // Limits: the same linear equations solved two ways (continuation vs direct solve).
  constexpr double kLimitTol = 1e-6;
  // Bounded: the peak over the range is at most the larger of the free and the stuck peaks
  // (the contact adds stiffness between 0 and its own, and damping >= 0, so the resonance it
  // makes lies between the two linear ones, no less damped); max_t |u| also holds the higher
  // harmonics, which the first-harmonic argument leaves out: 2 % of room for them.
  constexpr double kBoundSlack = 1.02;
  double worst_energy = 0.0, peak = 0.0, free_peak = 0.0, stuck_peak = 0.0;
  for (const auto& p : b.points) {
    ASSERT_TRUE(p.x.allFinite()) << p.lambda;
    const PointResult r = eq.analyse(p.x, p.lambda);
    ASSERT_TRUE(std::isfinite(r.amplitude) && std::isfinite(r.energy_error)) << p.lambda;
    worst_energy = std::max(worst_energy, r.energy_error);
    const PointResult stuck = eq.analyse(eq.stuck_solution(p.lambda), p.lambda);
    switch (e.expect) {
      case Expect::free:
        EXPECT_NEAR(r.amplitude, r.linear_amplitude, kLimitTol * r.linear_amplitude) << p.lambda;
        break;
      case Expect::stuck: EXPECT_NEAR(r.amplitude, stuck.amplitude, kLimitTol * stuck.amplitude) << p.lambda; break;
      case Expect::bounded: break;
    }
    peak = std::max(peak, r.amplitude);
    free_peak = std::max(free_peak, r.linear_amplitude);
    stuck_peak = std::max(stuck_peak, stuck.amplitude);
  }
  EXPECT_LT(worst_energy, kEnergyTol);
  if (e.expect == Expect::bounded) {
    EXPECT_LE(peak, kBoundSlack * std::max(free_peak, stuck_peak));
  }
}

constexpr auto full3d = contact::Model::full3d;
constexpr auto quasi3d = contact::Model::quasi3d;
constexpr auto one_d = contact::Model::one_d;
const double k0 = std::pow(2 * kPi * 10.0, 2);  // the structure's own stiffness, 3948 N/m

INSTANTIATE_TEST_SUITE_P(Matrix, Extremes,
                         ::testing::Values(
                             // contact stiffness 1e3 .. 1e11 N/m (0.25 .. 2.5e7 times the structure's)
                             Extreme{"kt_1e3", full3d, 1e3, 1e3, 0.3, 1.0, 0.01, 5, 256, Expect::bounded},
                             Extreme{"kt_1e11", full3d, 1e11, 1e11, 0.3, 1.0, 0.01, 5, 256, Expect::bounded},
                             Extreme{"kt_1e11_1d", one_d, 1e11, 1.0, 0.3, 1.0, 0.01, 5, 256, Expect::bounded},
                             Extreme{"kn_1e3_kt_1e11", full3d, 1e11, 1e3, 0.3, 1.0, 0.01, 5, 256, Expect::bounded},
                             // preload: a gap that never closes, zero, large (never slips)
                             Extreme{"gap", full3d, k0, k0, 0.3, -1e3, 0.01, 5, 256, Expect::free},
                             Extreme{"zero_preload", full3d, k0, k0, 0.3, 0.0, 0.01, 5, 256, Expect::bounded},
                             Extreme{"huge_preload", full3d, k0, k0, 0.3, 1e6, 0.01, 5, 256, Expect::stuck},
                             // friction 0 .. 1e3
                             Extreme{"mu_0", full3d, k0, k0, 0.0, 1.0, 0.01, 5, 256, Expect::free},
                             Extreme{"mu_0_quasi3d", quasi3d, k0, k0, 0.0, 1.0, 0.01, 5, 256, Expect::free},
                             Extreme{"mu_1e3", full3d, k0, k0, 1e3, 1.0, 0.01, 5, 256, Expect::stuck},
                             Extreme{"mu_1e3_1d", one_d, k0, 1.0, 1e3, 1.0, 0.01, 5, 256, Expect::stuck},
                             // damping ratio 1e-5 .. 0.1
                             Extreme{"zeta_1em5", full3d, k0, k0, 0.3, 1.0, 1e-5, 5, 256, Expect::bounded},
                             Extreme{"zeta_1em5_1d", one_d, k0, 1.0, 0.3, 1.0, 1e-5, 5, 256, Expect::bounded},
                             Extreme{"zeta_0p1", full3d, k0, k0, 0.3, 1.0, 0.1, 5, 256, Expect::bounded},
                             // harmonics and samples
                             Extreme{"H_25", full3d, k0, k0, 0.3, 1.0, 0.01, 25, 256, Expect::bounded},
                             Extreme{"H_25_N_51", one_d, k0, 1.0, 0.3, 1.0, 0.01, 25, 51, Expect::bounded},
                             Extreme{"N_4096", full3d, k0, k0, 0.3, 1.0, 0.01, 3, 4096, Expect::bounded}),
                         name_of);

}  // namespace
}  // namespace shroudsim::forced
