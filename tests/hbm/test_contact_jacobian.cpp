// The analytic contact Jacobian (differentiated time recursion, Fourier-projected) against
// central differences of the same discrete map, for every model and both tangential
// updates, over seeded random states. The full sweep (H = 1, 5, 15; N = 64, 512, 2048)
// is bench/contact/contact_accuracy; this is its small version.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <tuple>

#include "contact_test_support.hpp"
#include "hbm/contact_evaluator.hpp"

namespace {

using shroudsim::contact::Model;
using shroudsim::contact::TangentialUpdate;
using shroudsim::hbm::ContactEvaluator;
using shroudsim::hbm::JacobianMethod;

// A central difference reproduces the exact derivative of a piecewise-smooth map to
// O(h^2) + round-off (~1e-10 at h = 1e-6 relative), except for states where a sample
// switches stick/slip/separation inside the step (measure zero, but random states hit it
// now and then): the median must be tight, the worst case only bounded.
constexpr double kMedianTol = 1e-7;
// Residuals of the two evaluation paths: 64 units of round-off of the largest force (the
// differences come from the order of summation only).
constexpr double kSameResidualTol = 64 * std::numeric_limits<double>::epsilon();
constexpr double kShareTol = 1e-5;      // error bound met by ...
constexpr double kShareRequired = 0.8;  // ... at least this share of the states

// The pair of every test here: sticking, slipping and separating states all occur.
shroudsim::contact::PairParameters test_pair() {
  shroudsim::contact::PairParameters p;
  p.tangential_stiffness = 2.0e5;
  p.normal_stiffness = 5.0e5;
  p.friction_coefficient = 0.4;
  p.normal_preload = 3.0;
  return p;
}

// One seeded random state per pair of ev (all pairs with parameters p).
Eigen::VectorXd random_states(const ContactEvaluator& ev, const shroudsim::contact::PairParameters& p, unsigned seed) {
  std::mt19937 rng(seed);
  Eigen::VectorXd w(ev.size());
  const int s = ev.pair_layout().size();
  for (int k = 0; k < ev.n_pairs(); ++k)
    w.segment(k * s, s) = shroudsim::testing::random_contact_state(ev.pair_layout(), p, rng);
  return w;
}

// Evaluator options for H harmonics and N samples; FFTW plans estimated, not measured (the
// tests time nothing).
shroudsim::hbm::ContactEvaluatorOptions evaluator_options(int h, int n) {
  shroudsim::hbm::ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.measure_plans = false;
  return o;
}

class JacobianVsFd : public ::testing::TestWithParam<std::tuple<Model, TangentialUpdate, int, int>> {};

TEST_P(JacobianVsFd, MatchesCentralDifferences) {
  const auto [model, update, h, n] = GetParam();
  const shroudsim::contact::PairParameters p = test_pair();
  shroudsim::hbm::ContactEvaluatorOptions o = evaluator_options(h, n);
  o.law.model = model;
  o.law.update = update;
  constexpr int kStates = 24;
  ContactEvaluator ev(o, std::vector<shroudsim::contact::PairParameters>(kStates, p));
  const Eigen::VectorXd w = random_states(ev, p, 20261122);
  Eigen::VectorXd fa, ff;
  std::vector<Eigen::MatrixXd> ja, jf;
  const auto sa = ev.evaluate(w, fa, &ja, JacobianMethod::analytic);
  ev.evaluate(w, ff, &jf, JacobianMethod::finite_difference);
  EXPECT_EQ(sa.unconverged_pairs, 0);
  // The same residual whatever the Jacobian method, to round-off: the analytic path runs
  // the recursion on dual numbers (scalar code), the other on doubles, which the compiler
  // may vectorize (-march=native: AVX-512 sums of 8 terms at a time), so sums can be
  // associated differently; a few units in the last place, never more.
  EXPECT_LE((fa - ff).cwiseAbs().maxCoeff(), kSameResidualTol * std::max(1.0, ff.cwiseAbs().maxCoeff()))
      << (fa - ff).cwiseAbs().maxCoeff();
  std::vector<double> err;
  int within = 0;
  for (int s = 0; s < kStates; ++s) {
    ASSERT_TRUE(ja[s].allFinite());
    err.push_back(shroudsim::testing::relative_error(ja[s], jf[s]));
    within += err.back() <= kShareTol;
  }
  EXPECT_LE(shroudsim::testing::median(err), kMedianTol);
  EXPECT_GE(within, kShareRequired * kStates);
}

INSTANTIATE_TEST_SUITE_P(Models, JacobianVsFd,
                         ::testing::Values(std::tuple{Model::full3d, TangentialUpdate::radial_return, 3, 64},
                                           std::tuple{Model::full3d, TangentialUpdate::exact_linear, 3, 64},
                                           std::tuple{Model::quasi3d, TangentialUpdate::radial_return, 3, 64},
                                           std::tuple{Model::quasi3d, TangentialUpdate::exact_linear, 3, 64},
                                           std::tuple{Model::one_d, TangentialUpdate::radial_return, 3, 64},
                                           std::tuple{Model::one_d, TangentialUpdate::exact_linear, 3, 64},
                                           std::tuple{Model::full3d, TangentialUpdate::exact_linear, 1, 256},
                                           std::tuple{Model::full3d, TangentialUpdate::radial_return, 5, 128},
                                           std::tuple{Model::one_d_exact, TangentialUpdate::exact_linear, 1, 64}));

// A pressed pair that does not move tangentially (a static state: every harmonic above 0 zero)
// sticks at every sample, so any small tangential motion is resisted by kt: the analytic
// Jacobian must be that stuck stiffness, as central differences say. (The coupled
// exact_linear step once returned its slipping derivative where a sample had no tangential
// motion: about 1e-11 of kt instead of kt.)
TEST(ContactEvaluator, APairAtRestHasTheStuckStiffness) {
  const shroudsim::contact::PairParameters p = test_pair();
  for (auto [model, update] : {std::pair{Model::full3d, TangentialUpdate::exact_linear},
                               std::pair{Model::full3d, TangentialUpdate::radial_return},
                               std::pair{Model::quasi3d, TangentialUpdate::exact_linear}}) {
    shroudsim::hbm::ContactEvaluatorOptions o = evaluator_options(3, 64);
    o.law.model = model;
    o.law.update = update;
    ContactEvaluator ev(o, {p});
    const Eigen::VectorXd w = Eigen::VectorXd::Zero(ev.size());  // pressed by the preload alone
    Eigen::VectorXd fa, ff;
    std::vector<Eigen::MatrixXd> ja, jf;
    ev.evaluate(w, fa, &ja, JacobianMethod::analytic);
    ev.evaluate(w, ff, &jf, JacobianMethod::finite_difference);
    ASSERT_TRUE(ja[0].allFinite());
    // Stuck throughout: the forces are linear in the motion here, so the difference is exact
    // to round-off of kt.
    EXPECT_LE(shroudsim::testing::relative_error(ja[0], jf[0]), kMedianTol)
        << "model " << static_cast<int>(model) << ", update " << static_cast<int>(update);
    EXPECT_GT(jf[0].cwiseAbs().maxCoeff(), 0.5 * p.tangential_stiffness);
  }
}

// Block diagonal and parallel: evaluating pairs together, threaded, equals one at a time.
TEST(ContactEvaluator, PairsAreIndependentAndThreadingChangesNothing) {
  shroudsim::contact::PairParameters p;
  std::vector<shroudsim::contact::PairParameters> pairs(7, p);
  for (int i = 0; i < 7; ++i) pairs[i].normal_preload = 0.1 + 0.2 * i;
  shroudsim::hbm::ContactEvaluatorOptions o = evaluator_options(3, 64);
  o.threads = 2;
  ContactEvaluator par(o, pairs);
  o.threads = 1;
  ContactEvaluator ser(o, pairs);
  std::mt19937 rng(7);
  Eigen::VectorXd w(par.size());
  const int s = par.pair_layout().size();
  for (int i = 0; i < 7; ++i)
    w.segment(i * s, s) = shroudsim::testing::random_contact_state(par.pair_layout(), pairs[i], rng);
  Eigen::VectorXd f1, f2;
  std::vector<Eigen::MatrixXd> j1, j2;
  par.evaluate(w, f1, &j1);
  ser.evaluate(w, f2, &j2);
  EXPECT_EQ(f1, f2);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(j1[i], j2[i]);
  // Pair 3 alone gives the same block.
  ContactEvaluator one(o, {pairs[3]});
  Eigen::VectorXd f3;
  std::vector<Eigen::MatrixXd> j3;
  one.evaluate(w.segment(3 * s, s), f3, &j3);
  EXPECT_EQ(f3, f1.segment(3 * s, s));
  EXPECT_EQ(j3[0], j1[3]);
}

}  // namespace

namespace {

TEST(JacobianMethods, WholeVectorFiniteDifferenceEqualsThePerPairOne) {
  // finite_difference_full perturbs every unknown and evaluates all pairs; each pair's force
  // depends only on its own W, so its blocks are the per-pair differences, evaluated on the
  // same perturbed states: equal to round-off (the same arithmetic on each pair).
  const shroudsim::contact::PairParameters p = test_pair();
  const shroudsim::hbm::ContactEvaluatorOptions o = evaluator_options(2, 64);
  constexpr int kPairs = 3;
  ContactEvaluator ev(o, std::vector<shroudsim::contact::PairParameters>(kPairs, p));
  const Eigen::VectorXd w = random_states(ev, p, 20261201);
  Eigen::VectorXd f1, f2;
  std::vector<Eigen::MatrixXd> j1, j2;
  ev.evaluate(w, f1, &j1, JacobianMethod::finite_difference);
  ev.evaluate(w, f2, &j2, JacobianMethod::finite_difference_full);
  EXPECT_EQ(f1, f2);
  ASSERT_EQ(j2.size(), j1.size());
  for (int s = 0; s < kPairs; ++s) EXPECT_LE((j1[s] - j2[s]).norm(), 1e-12 * j1[s].norm()) << "pair " << s;
  EXPECT_EQ(shroudsim::hbm::to_string(JacobianMethod::finite_difference_full), "finite_difference_full");
}

}  // namespace
