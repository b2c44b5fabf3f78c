// Time-domain contact laws of one pair (no FFT): the exact_linear step, stick, separation,
// steady-state iteration, frame invariance, input validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "contact/friction_step.hpp"
#include "contact/periodic_law.hpp"
#include "separation_reference.hpp"

namespace {

using shroudsim::contact::LawOptions;
using shroudsim::contact::Model;
using shroudsim::contact::PairParameters;
using shroudsim::contact::PeriodicLaw;
using shroudsim::contact::TangentialUpdate;
constexpr double kPi = std::numbers::pi;

// Round-off of a few dozen operations on O(1) numbers.
constexpr double kRoundOff = 1e-12;

Eigen::MatrixX3d orbit(int n, double ax, double ay, double phase_y, double z0, double az) {
  Eigen::MatrixX3d w(n, 3);
  for (int l = 0; l < n; ++l) {
    const double t = 2.0 * kPi * l / n;
    w(l, 0) = ax * std::cos(t);
    w(l, 1) = ay * std::sin(t + phase_y);
    w(l, 2) = z0 + az * std::cos(2.0 * t);
  }
  return w;
}

TEST(ExactLinearStep, JacobianMatchesCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Central differences at h = 1e-7 on O(1) data: O(h^2) + eps/h ~ 1e-9; states where the
  // stick/slip switch falls inside the difference step are rare and only bounded.
  constexpr double kH = 1e-7, kTol = 1e-6;
  int good = 0;
  constexpr int kStates = 200;
  for (int k = 0; k < kStates; ++k) {
    const double a0 = 0.5 + 0.5 * std::abs(u(rng)), a1 = 0.5 + 0.5 * std::abs(u(rng));
    Eigen::Vector2d e0(u(rng), u(rng));
    if (e0.norm() > a0) e0 *= a0 / e0.norm() * std::abs(u(rng));
    const Eigen::Vector2d dw(1.5 * u(rng), 1.5 * u(rng));
    Eigen::Matrix<double, 2, 6> jac, fd;
    shroudsim::contact::exact_linear_step(e0, dw, a0, a1, &jac);
    for (int c = 0; c < 6; ++c) {
      auto eval = [&](double step) {
        Eigen::Vector2d e = e0, d = dw;
        double b0 = a0, b1 = a1;
        (c < 2 ? e[c] : c < 4 ? d[c - 2] : c == 4 ? b0 : b1) += step;
        return shroudsim::contact::exact_linear_step(e, d, b0, b1);
      };
      fd.col(c) = (eval(kH) - eval(-kH)) / (2.0 * kH);
    }
    good += (jac - fd).norm() <= kTol * (1.0 + fd.norm());
  }
  EXPECT_GE(good, 0.97 * kStates);
}

// Without tangential motion the step sticks, and its derivative in dw is the identity (the
// stuck stiffness); it used to be zero, the slipping derivative, with the stuck flag unset.
TEST(ExactLinearStep, WithoutMotionItSticksWithTheStuckDerivative) {
  constexpr double kH = 1e-7, kTol = 1e-8;
  const Eigen::Vector2d e0(0.3, -0.2), dw = Eigen::Vector2d::Zero();
  for (double a1 : {0.5, 1.0}) {  // the radius shrinks or grows, staying above |e0|
    Eigen::Matrix<double, 2, 6> jac, fd;
    bool stuck = false;
    const Eigen::Vector2d e1 = shroudsim::contact::exact_linear_step(e0, dw, 0.8, a1, &jac, &stuck);
    EXPECT_TRUE(stuck);
    EXPECT_EQ(e1, e0);
    for (int c = 0; c < 6; ++c) {
      auto eval = [&](double step) {
        Eigen::Vector2d e = e0, d = dw;
        double b0 = 0.8, b1 = a1;
        (c < 2 ? e[c] : c < 4 ? d[c - 2] : c == 4 ? b0 : b1) += step;
        return shroudsim::contact::exact_linear_step(e, d, b0, b1);
      };
      fd.col(c) = (eval(kH) - eval(-kH)) / (2.0 * kH);
    }
    EXPECT_LE((jac - fd).norm(), kTol) << "a1 = " << a1 << "\n" << jac << "\n" << fd;
    EXPECT_LE((jac.middleCols<2>(2) - Eigen::Matrix2d::Identity()).norm(), kRoundOff);
  }
}

// Exact integration composes: one step over [0, 1] equals two half steps, the radius linear
// throughout (mid radius (a0 + a1)/2), for stick, stick-then-slip and slip from the start.
TEST(ExactLinearStep, TwoHalfStepsEqualOneStep) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 100; ++k) {
    const double a0 = 0.6 + 0.4 * std::abs(u(rng)), a1 = 0.6 + 0.4 * std::abs(u(rng));
    Eigen::Vector2d e0(u(rng), u(rng));
    if (e0.norm() > a0) e0 *= a0 / e0.norm();
    const Eigen::Vector2d dw(2.0 * u(rng), 2.0 * u(rng));
    const Eigen::Vector2d one = shroudsim::contact::exact_linear_step(e0, dw, a0, a1);
    const double am = 0.5 * (a0 + a1);
    const Eigen::Vector2d half = shroudsim::contact::exact_linear_step(e0, 0.5 * dw, a0, am);
    const Eigen::Vector2d two = shroudsim::contact::exact_linear_step(half, 0.5 * dw, am, a1);
    EXPECT_LE((one - two).norm(), 1e3 * kRoundOff) << "state " << k;  // tan/atan conditioning
    EXPECT_LE(one.norm(), a1 * (1.0 + kRoundOff));
  }
}

TEST(PeriodicLaw, PureStickIsALinearSpring) {
  PairParameters p{
      .tangential_stiffness = 3e5, .normal_stiffness = 7e5, .friction_coefficient = 1e6, .normal_preload = 10.0};
  const Eigen::MatrixX3d w = orbit(64, 2e-6, 1e-6, 0.3, 1e-6, 2e-6);
  for (Model model : {Model::full3d, Model::quasi3d, Model::one_d}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      PeriodicLaw law({.model = model, .update = update});
      Eigen::MatrixX3d f;
      const auto st = law.evaluate(p, w, f);
      EXPECT_TRUE(st.converged);
      EXPECT_EQ(st.periods, 1);  // the damper never moves
      for (int l = 0; l < 64; ++l) {
        EXPECT_NEAR(f(l, 0), p.tangential_stiffness * w(l, 0), kRoundOff);
        if (model != Model::one_d) {
          EXPECT_NEAR(f(l, 1), p.tangential_stiffness * w(l, 1), kRoundOff);
          EXPECT_NEAR(f(l, 2), p.normal_preload + p.normal_stiffness * w(l, 2), kRoundOff * 10);
        }
      }
    }
  }
}

TEST(PeriodicLaw, GapThatNeverClosesGivesZeroForceAndDerivative) {
  PairParameters p{
      .tangential_stiffness = 3e5, .normal_stiffness = 7e5, .friction_coefficient = 0.3, .normal_preload = -1.0};
  // |kn z| <= 7e5 * 1.2e-6 = 0.84 N < gap force 1 N.
  const Eigen::MatrixX3d w = orbit(32, 1e-3, 1e-3, 0.0, 0.2e-6, 1e-6);
  Eigen::MatrixXd basis = Eigen::MatrixXd::Random(32, 3);
  for (Model model : {Model::full3d, Model::quasi3d}) {
    PeriodicLaw law({.model = model});
    Eigen::MatrixX3d f;
    shroudsim::contact::LinearizedPeriod lin;
    law.evaluate(p, w, f, &basis, &lin);
    EXPECT_EQ(f.norm(), 0.0);
    std::array<shroudsim::contact::RowMatrix, 3> df;
    lin.expand(basis, df);
    for (const auto& d : df) EXPECT_EQ(d.norm(), 0.0);
    for (int i = 0; i < 2; ++i) {
      EXPECT_TRUE(lin.runs[i].empty());
      EXPECT_TRUE(lin.dense_index[i].empty());
    }
  }
}

TEST(PeriodicLaw, OneDimensionalUpdatesAgreeAtConstantNormalLoad) {
  // In 1D, clamping the trial force is the exact integration of a piecewise-linear motion.
  PairParameters p{.tangential_stiffness = 1e5, .friction_coefficient = 0.5, .normal_preload = 2.0};
  const Eigen::MatrixX3d w = orbit(100, 5e-5, 0.0, 0.0, 0.0, 0.0);
  PeriodicLaw rr({.model = Model::one_d, .update = TangentialUpdate::radial_return});
  PeriodicLaw el({.model = Model::one_d, .update = TangentialUpdate::exact_linear});
  Eigen::MatrixX3d f1, f2;
  rr.evaluate(p, w, f1);
  el.evaluate(p, w, f2);
  EXPECT_LE((f1 - f2).norm(), kRoundOff * f1.norm());
}

TEST(PeriodicLaw, SteadyStateIsFlaggedWhenTheCapIsHit) {
  PairParameters p{.tangential_stiffness = 1e5, .friction_coefficient = 0.5, .normal_preload = 2.0};
  const Eigen::MatrixX3d w = orbit(64, 5e-5, 3e-5, 0.4, 0.0, 0.0);
  Eigen::MatrixX3d f;
  PeriodicLaw capped({.model = Model::full3d, .max_periods = 1});
  const auto s1 = capped.evaluate(p, w, f);
  EXPECT_FALSE(s1.converged);  // from d = 0 the first period cannot be the steady one here
  EXPECT_EQ(s1.periods, 1);
  PeriodicLaw free({.model = Model::full3d});
  const auto s2 = free.evaluate(p, w, f);
  EXPECT_TRUE(s2.converged);
  EXPECT_GE(s2.periods, 2);
  EXPECT_TRUE(f.allFinite());
}

// The coupled law does not care how t1, t2 are turned about n; the uncoupled one does.
TEST(PeriodicLaw, CoupledLawIsFrameInvariantUncoupledIsNot) {
  PairParameters p{
      .tangential_stiffness = 1e5, .normal_stiffness = 2e5, .friction_coefficient = 0.5, .normal_preload = 2.0};
  const Eigen::MatrixX3d w = orbit(128, 4e-5, 2e-5, 1.0, 2e-6, 4e-6);
  const double psi = 0.7;
  const double c = std::cos(psi), s = std::sin(psi);
  Eigen::MatrixX3d wr = w;
  wr.col(0) = c * w.col(0) - s * w.col(1);
  wr.col(1) = s * w.col(0) + c * w.col(1);
  auto rotated_difference = [&](Model model, TangentialUpdate update) {
    PeriodicLaw law({.model = model, .update = update});
    Eigen::MatrixX3d f, fr;
    law.evaluate(p, w, f);
    law.evaluate(p, wr, fr);
    Eigen::MatrixX3d back = fr;
    back.col(0) = c * fr.col(0) + s * fr.col(1);
    back.col(1) = -s * fr.col(0) + c * fr.col(1);
    return (back - f).norm() / f.norm();
  };
  // Steady-state tolerance 1e-12 relative and rotation round-off.
  constexpr double kInvariant = 1e-9;
  // Uncoupled: the friction limit applies per axis, a visible change (tens of percent here).
  constexpr double kNotInvariant = 1e-2;
  EXPECT_LE(rotated_difference(Model::full3d, TangentialUpdate::radial_return), kInvariant);
  EXPECT_LE(rotated_difference(Model::full3d, TangentialUpdate::exact_linear), kInvariant);
  EXPECT_GE(rotated_difference(Model::quasi3d, TangentialUpdate::radial_return), kNotInvariant);
  EXPECT_GE(rotated_difference(Model::quasi3d, TangentialUpdate::exact_linear), kNotInvariant);
}

// Columns c of the compact derivative of the period (expanded sample by sample) that equal
// central differences of the sampled forces, ||df - fd|| <= tol ||fd||, when the unknowns move
// the samples along the basis, w_j(l) = w0_j(l) + sum_k E(l, k) c_{j m + k}; worst: the
// largest relative difference.
int columns_matching_central_differences(PeriodicLaw& law, const PairParameters& p, const Eigen::MatrixX3d& w0,
                                         const Eigen::MatrixXd& basis, double step, double tol, double* worst) {
  const int m = static_cast<int>(basis.cols());
  const int dirs = shroudsim::contact::n_directions(law.options().model);
  Eigen::MatrixX3d f;
  shroudsim::contact::LinearizedPeriod lin;
  law.evaluate(p, w0, f, &basis, &lin);
  std::array<shroudsim::contact::RowMatrix, 3> df;
  lin.expand(basis, df);
  int good = 0;
  *worst = 0.0;
  for (int c = 0; c < dirs * m; ++c) {
    Eigen::MatrixX3d wp = w0, wm = w0, fp, fm;
    wp.col(c / m) += step * basis.col(c % m);
    wm.col(c / m) -= step * basis.col(c % m);
    law.evaluate(p, wp, fp);
    law.evaluate(p, wm, fm);
    const Eigen::MatrixX3d fd = (fp - fm) / (2.0 * step);
    double err = 0.0, ref = 0.0;
    for (int i = 0; i < (dirs == 3 ? 3 : 1); ++i) {
      err += (df[i].col(c) - fd.col(i)).squaredNorm();
      ref += fd.col(i).squaredNorm();
    }
    *worst = std::max(*worst, ref > 0.0 ? std::sqrt(err / ref) : std::sqrt(err));
    good += std::sqrt(err) <= tol * std::sqrt(ref) + 1e-300;
  }
  return good;
}

Eigen::MatrixXd random_basis(int n, int m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd basis(n, m);
  for (int l = 0; l < n; ++l)
    for (int k = 0; k < m; ++k) basis(l, k) = u(rng);
  return basis;
}

// The compact derivative of the time recursion against central differences of the sampled
// forces, without any Fourier transform.
TEST(PeriodicLaw, SampledDerivativeMatchesCentralDifferences) {
  constexpr int kN = 48, kM = 5;
  PairParameters p{
      .tangential_stiffness = 1e5, .normal_stiffness = 2e5, .friction_coefficient = 0.5, .normal_preload = 2.0};
  // Amplitudes chosen so that no sample sits exactly on a stick/slip switch (a kink); the
  // normal load varies between 0.6 and 3.8 N.
  const Eigen::MatrixX3d w0 = orbit(kN, 4.3e-5, 3.1e-5, 0.8, 1e-6, 8e-6);
  const Eigen::MatrixXd basis = random_basis(kN, kM, 17);
  // Central differences: O(h^2) + round-off (~1e-16 * 1e-5 m / 1e-11 m = 1e-10 relative);
  // the state is away from kinks, so every column must agree.
  constexpr double kH = 1e-11;  // m, against displacements of 1e-5 m
  constexpr double kTol = 1e-6;
  for (Model model : {Model::full3d, Model::quasi3d, Model::one_d}) {
    for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
      PeriodicLaw law({.model = model, .update = update});
      double worst = 0.0;
      EXPECT_EQ(columns_matching_central_differences(law, p, w0, basis, kH, kTol, &worst),
                shroudsim::contact::n_directions(model) * kM)
          << shroudsim::contact::to_string(model) << " " << shroudsim::contact::to_string(update) << " worst " << worst;
    }
  }
}

// The same at states that separate over about a third of the period and stick right after
// each closing (tests/contact/separation_reference.hpp): the closing instant moves with the
// normal motion, and exact_linear carries its derivative.
TEST(PeriodicLaw, DerivativeThroughClosingMatchesCentralDifferences) {
  constexpr int kN = 96, kM = 6;
  const PairParameters p{
      .tangential_stiffness = 2.0e5, .normal_stiffness = 5.0e5, .friction_coefficient = 0.4, .normal_preload = 3.0};
  const Eigen::MatrixXd basis = random_basis(kN, kM, 23);
  // As above; the grid shift keeps every sample away from a stick/slip/separation switch.
  constexpr double kH = 1e-11;  // m, against displacements of 1e-5 m
  constexpr double kTol = 1e-6;
  for (double theta : {0.5, -1.0}) {
    const Eigen::MatrixX3d w0 = shroudsim::testing::separating_motion(p, theta).sample(kN, 0.37);
    for (Model model : {Model::full3d, Model::quasi3d}) {
      for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
        PeriodicLaw law({.model = model, .update = update});
        Eigen::MatrixX3d f;
        law.evaluate(p, w0, f);
        EXPECT_GT((f.col(2).array() == 0.0).count(), kN / 4);  // open over a quarter or more
        double worst = 0.0;
        EXPECT_EQ(columns_matching_central_differences(law, p, w0, basis, kH, kTol, &worst), 3 * kM)
            << shroudsim::contact::to_string(model) << " " << shroudsim::contact::to_string(update) << " theta "
            << theta << " worst " << worst;
      }
    }
  }
}

// The samples' recursion (PeriodicLaw::sample_steps), solved around the period, is the
// analytical derivative of the steady period: the recursion is that derivative unrolled in
// time, so the two must agree to round-off for every model and update, with slip and with
// separation (states where every direction slips or separates somewhere in the period, so
// the periodic damper state is unique).
Eigen::MatrixXd unrolled_derivative(const std::vector<shroudsim::contact::SampleStep>& steps, const PairParameters& p,
                                    Model model, const Eigen::MatrixXd& basis) {
  const int n = static_cast<int>(steps.size()), m = static_cast<int>(basis.cols());
  const int nd = shroudsim::contact::n_directions(model), nt = model == Model::one_d ? 1 : 2;
  Eigen::MatrixXd cyclic = Eigen::MatrixXd::Identity(2 * n, 2 * n);
  for (int l = 0; l < n; ++l) cyclic.block(2 * l, 2 * ((l + n - 1) % n), 2, 2) -= steps[l].a;
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(cyclic);
  Eigen::MatrixXd df = Eigen::MatrixXd::Zero(nd * n, nd * m);  // rows: direction i, sample l
  for (int j = 0; j < nd; ++j)
    for (int k = 0; k < m; ++k) {
      Eigen::MatrixX3d u = Eigen::MatrixX3d::Zero(n, 3);
      u.col(model == Model::one_d ? 0 : j) = basis.col(k);
      Eigen::VectorXd rhs(2 * n);
      for (int l = 0; l < n; ++l)
        rhs.segment<2>(2 * l) = steps[l].b * u.row(l).transpose() + steps[l].c * u.row((l + n - 1) % n).transpose();
      const Eigen::VectorXd d = lu.solve(rhs);
      for (int l = 0; l < n; ++l) {
        for (int i = 0; i < nt; ++i) df(i * n + l, j * m + k) = p.tangential_stiffness * (u(l, i) - d(2 * l + i));
        if (nd == 3) df(2 * n + l, j * m + k) = steps[l].pressed ? p.normal_stiffness * u(l, 2) : 0.0;
      }
    }
  return df;
}

TEST(PeriodicLaw, TheSamplesRecursionAroundThePeriodIsTheAnalyticalDerivative) {
  constexpr int kN = 64, kM = 5;
  const PairParameters p{
      .tangential_stiffness = 2.0e5, .normal_stiffness = 5.0e5, .friction_coefficient = 0.4, .normal_preload = 3.0};
  const Eigen::MatrixXd basis = random_basis(kN, kM, 31);
  // Two motions: a slipping elliptical orbit with a varying load, and one that separates
  // over about a third of the period (tests/contact/separation_reference.hpp).
  const std::vector<Eigen::MatrixX3d> motions{orbit(kN, 4.3e-5, 3.1e-5, 0.8, 1e-6, 8e-6),
                                              shroudsim::testing::separating_motion(p, 0.5).sample(kN, 0.37)};
  // Both sides are the same products and sums in another order: round-off of a 2N-wide
  // dense solve on O(1) entries.
  constexpr double kTol = 1e-9;
  for (std::size_t motion = 0; motion < motions.size(); ++motion)
    for (Model model : {Model::full3d, Model::quasi3d, Model::one_d})
      for (auto update : {TangentialUpdate::radial_return, TangentialUpdate::exact_linear}) {
        PeriodicLaw law({.model = model, .update = update});
        Eigen::MatrixX3d f, f_steps;
        shroudsim::contact::LinearizedPeriod lin;
        law.evaluate(p, motions[motion], f, &basis, &lin);
        std::array<shroudsim::contact::RowMatrix, 3> expanded;
        lin.expand(basis, expanded);
        std::vector<shroudsim::contact::SampleStep> steps;
        law.sample_steps(p, motions[motion], f_steps, steps);
        ASSERT_EQ(steps.size(), static_cast<std::size_t>(kN));
        EXPECT_LT((f_steps - f).cwiseAbs().maxCoeff(), 1e-9 * f.cwiseAbs().maxCoeff());
        const int nd = shroudsim::contact::n_directions(model);
        Eigen::MatrixXd reference(nd * kN, nd * kM);
        for (int i = 0; i < nd; ++i) reference.middleRows(i * kN, kN) = expanded[static_cast<std::size_t>(i)];
        const Eigen::MatrixXd unrolled = unrolled_derivative(steps, p, model, basis);
        EXPECT_LT((unrolled - reference).cwiseAbs().maxCoeff(), kTol * reference.cwiseAbs().maxCoeff())
            << "motion " << motion << " " << shroudsim::contact::to_string(model) << " "
            << shroudsim::contact::to_string(update);
      }
}

TEST(PairParameters, RefusesBadValuesNamingTheKey) {
  auto first_error = [](PairParameters p, Model m) {
    std::vector<std::string> e;
    EXPECT_FALSE(p.validate(m, &e));
    return e.empty() ? std::string() : e[0];
  };
  EXPECT_NE(first_error({.tangential_stiffness = 0.0}, Model::full3d).find("tangential_stiffness > 0"),
            std::string::npos);
  EXPECT_NE(first_error({.normal_stiffness = -1.0}, Model::full3d).find("normal_stiffness > 0"), std::string::npos);
  EXPECT_NE(first_error({.friction_coefficient = -0.1}, Model::quasi3d).find("friction_coefficient >= 0"),
            std::string::npos);
  EXPECT_NE(first_error({.normal_preload = std::nan("")}, Model::full3d).find("normal_preload"), std::string::npos);
  EXPECT_NE(first_error({.normal_preload = -1.0}, Model::one_d).find("normal_preload >= 0"), std::string::npos);
  EXPECT_NE(first_error({.tangential_stiffness = INFINITY}, Model::one_d).find("tangential_stiffness"),
            std::string::npos);
  std::vector<std::string> e;
  EXPECT_TRUE(PairParameters{}.validate(Model::full3d, &e));
  EXPECT_FALSE((LawOptions{.max_periods = 0}.validate(&e)));
  EXPECT_THROW(PeriodicLaw({.model = Model::one_d_exact}), std::invalid_argument);
}

}  // namespace

namespace shroudsim_periodic_test {
// A state of the FE sector case (H = 5, N = 512, exact_linear; pair 1 of 5 along the
// excitation homotopy): a static tangential load at the slip limit with a small oscillation
// around it. Plain repetition of the period contracts the damper position by only ~0.998 per
// period in one direction (measured: not converged after 1000 periods); the Newton iteration
// on the period map reaches the fixed point in ~12 periods. Fourier coefficients [m] of
// x, y, z: mean, then (cos, sin) of harmonics 1..5.
constexpr double kSlowState[3][11] = {
    {-2.3861836895969348e-07, -2.0075137437260313e-11, 2.2377888325625604e-09, 2.3127830441543172e-11,
     -1.6748904296434294e-11, -1.319754061046417e-10, -2.2094410576048938e-10, -2.6968012311562516e-11,
     1.4624263416765001e-10, -5.7085578478589358e-11, 2.348140084122621e-11},
    {1.4715261953148681e-08, 8.013396369907968e-11, 7.0566930041783911e-10, -4.8319421326800296e-12,
     -2.6291846382345826e-12, 2.688503179286269e-11, 4.8123016457959118e-11, 1.3150988081728142e-11,
     -5.024879406239328e-11, 3.5189064607296702e-11, -8.2670834196303699e-12},
    {-2.4139807748845657e-07, -3.4143417361790177e-10, -1.847380886386832e-09, -6.0361289272754121e-12,
     -8.3979942839995937e-12, 1.8267500158645393e-11, 6.3552339590949839e-11, -1.4422927022086165e-12,
     7.7407441254422051e-14, -3.4811833382449979e-11, -7.7743370808662483e-12}};

// A state of the 36-blade wheel (cases/shrouded_wheel.toml with full3d, 5 contact patches,
// excitation 3 N per component, H = 5, N = 512, exact_linear; one patch near 223.86 Hz along
// the forced response, issue 13): a steady tangential load with two short slips per period
// (near samples 100 and 360) that nearly cancel. The period map contracts strongly in one
// direction and by only ~0.998 (after the plain periods) to ~0.9998 (at the fixed point) per
// period along a slow direction that bends. The full Newton step follows the slow direction's
// tangent and lands off the bent curve, where max|g| is larger (8.6e-11 m against 6.3e-11 m
// at the start, measured): it was rejected at every iteration, the evaluation fell back to
// plain repetition (which needs ~80000 periods here, measured) and hit the 200-period cap, in
// ~620 evaluations of the wheel's forced response (energy-balance error 3.4e-3 there).
// Fourier coefficients [m] as above.
constexpr double kWheelState[3][11] = {
    {-5.0215755278163612e-05, 2.4278628154641253e-06, 7.170340185525978e-06, 5.5059361609455716e-10,
     -1.6593330808535089e-09, -2.8791508509427156e-09, -2.0645505752110153e-08, -4.1540323976990678e-08,
     -2.256731142231276e-08, -1.4840958995975403e-08, -4.3054980458791254e-09},
    {-1.8158362692569062e-06, -4.2021426269019911e-07, 3.3494923594536346e-07, -8.7339964501024181e-10,
     -9.1326419293645856e-10, -9.8499501616692639e-09, -6.2740061069967129e-09, -2.1605048581220918e-09,
     -1.4492741687016892e-09, 2.5717318729628794e-10, 4.0681181024750026e-10},
    {-5.0177648107435128e-05, -2.1603325927279498e-06, -6.8557221636634838e-06, -1.1319374777626891e-09,
     -1.8079031568526333e-09, 2.4765936442613564e-08, 4.4470748971202145e-09, -8.2893967667429551e-09,
     -4.0228103394997454e-08, 2.3831863961237862e-09, 3.6904484460345472e-09}};

// Samples (N x 2H+1) of 1, cos(h t), sin(h t), t = 2 pi l / N (the AFT's synthesis).
Eigen::MatrixXd fourier_basis(int n, int harmonics) {
  Eigen::MatrixXd basis(n, 2 * harmonics + 1);
  for (int l = 0; l < n; ++l) {
    const double t = 2.0 * std::numbers::pi * l / n;
    basis(l, 0) = 1.0;
    for (int h = 1; h <= harmonics; ++h) {
      basis(l, 2 * h - 1) = std::cos(h * t);
      basis(l, 2 * h) = std::sin(h * t);
    }
  }
  return basis;
}

// Samples of x, y, z from their Fourier coefficients (rows of `state`).
template <int kM>
Eigen::MatrixX3d motion(const Eigen::MatrixXd& basis, const double (&state)[3][kM]) {
  Eigen::MatrixX3d w(basis.rows(), 3);
  for (int j = 0; j < 3; ++j) w.col(j) = basis * Eigen::Map<const Eigen::VectorXd>(state[j], kM);
  return w;
}

// The analytical derivative `df` of the converged periodic map against central differences
// (step `step` in every harmonic column of x, y, z): the worst column error relative to the
// largest column, and that largest column norm. Every perturbed evaluation must converge.
struct ColumnErrors {
  double worst = 0.0;  ///< max over columns of |df_c - fd_c| / scale
  double scale = 0.0;  ///< the largest column norm of the central differences
};
inline ColumnErrors central_difference_columns(shroudsim::contact::PeriodicLaw& law,
                                               const shroudsim::contact::PairParameters& p, const Eigen::MatrixX3d& w0,
                                               const Eigen::MatrixXd& basis,
                                               const std::array<shroudsim::contact::RowMatrix, 3>& df, double step) {
  const int m = static_cast<int>(basis.cols());
  std::vector<double> err(3 * m), ref(3 * m);
  for (int c = 0; c < 3 * m; ++c) {
    Eigen::MatrixX3d wp = w0, wm = w0, fp, fm;
    wp.col(c / m) += step * basis.col(c % m);
    wm.col(c / m) -= step * basis.col(c % m);
    EXPECT_TRUE(law.evaluate(p, wp, fp).converged) << "column " << c;
    EXPECT_TRUE(law.evaluate(p, wm, fm).converged) << "column " << c;
    const Eigen::MatrixX3d fd = (fp - fm) / (2.0 * step);
    for (int i = 0; i < 3; ++i) {
      err[c] += (df[i].col(c) - fd.col(i)).squaredNorm();
      ref[c] += fd.col(i).squaredNorm();
    }
  }
  ColumnErrors out;
  out.scale = std::sqrt(*std::max_element(ref.begin(), ref.end()));
  for (int c = 0; c < 3 * m; ++c) out.worst = std::max(out.worst, std::sqrt(err[c]) / out.scale);
  return out;
}

// Translation invariance of the periodic limit: a uniform tangential shift moves the slider
// along and leaves the forces unchanged, so d(T)/d(mean x) and d(T)/d(mean y) vanish. Returns
// the larger of the two column norms relative to `scale`.
inline double mean_tangential_columns(const std::array<shroudsim::contact::RowMatrix, 3>& df, int m, double scale) {
  double worst = 0.0;
  for (int c : {0, m}) {
    double col = 0.0;
    for (int i = 0; i < 2; ++i) col += df[i].col(c).squaredNorm();
    worst = std::max(worst, std::sqrt(col) / scale);
  }
  return worst;
}
}  // namespace shroudsim_periodic_test

// The coupled law's steady state by Newton on the period map: a state that plain repetition
// does not resolve within the cap converges in a handful of periods, deterministically, and
// the derivative (through dd*/dc = (I - Phi_d)^{-1} Phi_c) matches central differences of the
// converged map in every harmonic column.
TEST(PeriodicLaw, SlowlyContractingStateConvergesInFewPeriodsWithExactDerivative) {
  constexpr int kN = 512, kH = 5, kM = 2 * kH + 1;
  const PairParameters p{.tangential_stiffness = 125055.35484647941,
                         .normal_stiffness = 125055.35484647941,
                         .friction_coefficient = 0.3,
                         .normal_preload = 0.031263838711619855};
  const Eigen::MatrixXd basis = shroudsim_periodic_test::fourier_basis(kN, kH);
  const Eigen::MatrixX3d w0 = shroudsim_periodic_test::motion(basis, shroudsim_periodic_test::kSlowState);
  for (auto update : {TangentialUpdate::exact_linear, TangentialUpdate::radial_return}) {
    SCOPED_TRACE(shroudsim::contact::to_string(update));
    // The first 4 periods are plain repetition: not yet periodic here.
    PeriodicLaw plain({.model = Model::full3d, .update = update, .max_periods = 4});
    Eigen::MatrixX3d f;
    EXPECT_FALSE(plain.evaluate(p, w0, f).converged);
    PeriodicLaw law({.model = Model::full3d, .update = update});
    const auto st = law.evaluate(p, w0, f);
    EXPECT_TRUE(st.converged);
    constexpr int kFewPeriods = 20;  // measured 12 for both updates
    EXPECT_LE(st.periods, kFewPeriods);
    Eigen::MatrixX3d f2;
    law.evaluate(p, w0, f2);
    EXPECT_EQ((f2 - f).cwiseAbs().maxCoeff(), 0.0);  // deterministic
    shroudsim::contact::LinearizedPeriod lin;
    Eigen::MatrixX3d fl;
    const auto sl = law.evaluate(p, w0, fl, &basis, &lin);
    EXPECT_TRUE(sl.converged);
    EXPECT_LE((fl - f).cwiseAbs().maxCoeff(), 1e-12 * f.cwiseAbs().maxCoeff());
    std::array<shroudsim::contact::RowMatrix, 3> df;
    lin.expand(basis, df);
    // Central differences of the converged map. The map is strongly curved here (the error
    // falls as h^2: 6e-2 at h = 1e-12 m, 7e-4 at 1e-13, 7e-6 at 1e-14, measured), and the
    // fixed point is resolved to |g| ~ 1e-22 m (quadratic Newton steps), i.e. ~1e-7 of the
    // difference at 1e-15; h = 1e-14 m leaves ~1e-5. Errors are measured against the largest
    // column: the mean tangential columns are zero in the periodic limit (a uniform tangential
    // shift moves d* along and leaves the forces unchanged), which the old truncated
    // repetition did not reproduce.
    constexpr double kStep = 1e-14;  // m
    constexpr double kTol = 1e-4;    // relative to the largest column (a dropped dd*/dc term is O(1))
    const auto fd = shroudsim_periodic_test::central_difference_columns(law, p, w0, basis, df, kStep);
    EXPECT_LE(fd.worst, kTol);
    // Translation invariance of the periodic limit: d(T)/d(mean x), d(T)/d(mean y) vanish.
    constexpr double kInvariant = 1e-6;  // relative; round-off of the 2 x 2 solve and the sums
    EXPECT_LE(shroudsim_periodic_test::mean_tangential_columns(df, kM, fd.scale), kInvariant);
  }
}

// The state of issue 13 (kWheelState): the damped Newton step (halved until max|g| falls)
// follows the bent slow direction and reaches the fixed point in a few periods, and the
// derivative of the converged map matches central differences in every harmonic column.
TEST(PeriodicLaw, BentSlowDirectionConvergesWithDampedNewtonAndExactDerivative) {
  constexpr int kN = 512, kH = 5, kM = 2 * kH + 1;
  const PairParameters p{.tangential_stiffness = 249431.8596016521,
                         .normal_stiffness = 249431.8596016521,
                         .friction_coefficient = 0.3,
                         .normal_preload = 18.804283429376937};
  const Eigen::MatrixXd basis = shroudsim_periodic_test::fourier_basis(kN, kH);
  const Eigen::MatrixX3d w0 = shroudsim_periodic_test::motion(basis, shroudsim_periodic_test::kWheelState);
  for (auto update : {TangentialUpdate::exact_linear, TangentialUpdate::radial_return}) {
    SCOPED_TRACE(shroudsim::contact::to_string(update));
    PeriodicLaw plain({.model = Model::full3d, .update = update, .max_periods = 4});
    Eigen::MatrixX3d f;
    EXPECT_FALSE(plain.evaluate(p, w0, f).converged);
    PeriodicLaw law({.model = Model::full3d, .update = update});
    const auto st = law.evaluate(p, w0, f);
    EXPECT_TRUE(st.converged);       // before issue 13: not converged, 200 periods
    constexpr int kFewPeriods = 30;  // measured 20 for both updates
    EXPECT_LE(st.periods, kFewPeriods);
    Eigen::MatrixX3d f2;
    law.evaluate(p, w0, f2);
    EXPECT_EQ((f2 - f).cwiseAbs().maxCoeff(), 0.0);  // deterministic
    shroudsim::contact::LinearizedPeriod lin;
    Eigen::MatrixX3d fl;
    EXPECT_TRUE(law.evaluate(p, w0, fl, &basis, &lin).converged);
    // The forces-only and the derivative evaluation iterate alike up to round-off (the step in
    // double and in dual numbers: 4e-15 N apart after one period, measured), which the slow
    // direction amplifies within the period tolerance (1e-12 max|w_t| = 5.8e-17 m, i.e.
    // kt times that = 1.4e-11 N): measured 1.1e-11 N, 1.4e-12 of max|f|.
    constexpr double kAgree = 1e-11;  // relative to max|f|
    EXPECT_LE((fl - f).cwiseAbs().maxCoeff(), kAgree * f.cwiseAbs().maxCoeff());
    std::array<shroudsim::contact::RowMatrix, 3> df;
    lin.expand(basis, df);
    // Central differences of the converged map; the worst column error relative to the
    // largest column, measured (exact_linear / radial_return): 1.5e-2 / 1.0e-1 at h = 1e-10 m,
    // 9.6e-5 / 9.3e-4 at 1e-11 (truncation: samples change state within the step), 4.5e-5 /
    // 2.3e-5 at 1e-12, 3.7e-4 / 2.9e-5 at 1e-13, 4.3e-3 / 7.6e-5 at 1e-14 (round-off: the
    // fixed point is resolved to ~1e-17 m and (I - Phi_d)^-1 amplifies by ~6e3 along the slow
    // direction). At the optimum h = 1e-12 m the tolerance leaves a factor 4 over the larger
    // measured error; the derivative of another fixed point, or without the dd*/dc term, is
    // off by O(1).
    constexpr double kStep = 1e-12;  // m, against displacements of 5e-5 m
    constexpr double kTol = 2e-4;    // relative to the largest column
    const auto fd = shroudsim_periodic_test::central_difference_columns(law, p, w0, basis, df, kStep);
    EXPECT_LE(fd.worst, kTol);
    constexpr double kInvariant = 1e-6;  // as above
    EXPECT_LE(shroudsim_periodic_test::mean_tangential_columns(df, kM, fd.scale), kInvariant);
  }
}
