// Many contact pairs: the structured Jacobian product, the exact frequency derivative of the
// residual and the preconditioned GMRES solve of the augmented Newton system against the
// plain dense forms they replace (forced/reduced_equations.hpp), on a lumped model with three
// 3D contacts and on a coarse FE sector with all its shroud pairs.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <random>

#include "../common/coarse_sector.hpp"
#include "../common/sector_contacts.hpp"
#include "continuation/arclength.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/lumped.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"
#include "modal/harmonic.hpp"
#include "three_contacts.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;
// Dense products and LU solves of these sizes (n < 200) agree to ~1e-15 relative; the
// structured product only reorders the same sums.
constexpr double kRoundOff = 1e-12;

/// The shared three-contact model (three_contacts.hpp).
struct ThreeContacts {
  frf::LumpedLinearPart linear = testing::three_contacts_linear();
  std::vector<contact::PairParameters> pairs = testing::three_contacts_pairs();
};

hbm::ContactEvaluatorOptions evaluator_options(int h) {
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = 64;
  o.threads = 1;
  o.measure_plans = false;
  return o;
}

/// A state where the contacts stick, slip and open over the period: random harmonics of
/// the size of the slip displacement, normal mean near zero.
Eigen::VectorXd mixed_state(const hbm::ContactEvaluator& ev, unsigned seed, double scale) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd w(ev.size());
  for (Eigen::Index i = 0; i < w.size(); ++i) w[i] = scale * u(gen);
  return w;
}

TEST(ManyPairs, StructuredJacobianEqualsTheDenseProduct) {
  const ThreeContacts sys;
  hbm::ContactEvaluator ev(evaluator_options(3), sys.pairs);
  ReducedEquations eq(sys.linear, ev);
  const Eigen::VectorXd w = mixed_state(ev, 3, 3e-4);
  Eigen::VectorXd r, f;
  Eigen::MatrixXd J;
  ASSERT_TRUE(eq.evaluate(w, 12.0, r, &J, nullptr));
  std::vector<Eigen::MatrixXd> blocks;
  ev.evaluate(w, f, &blocks);
  const Eigen::MatrixXd dense = eq.dense_jacobian(12.0, blocks);
  EXPECT_LE((J - dense).norm(), kRoundOff * dense.norm());
  // The residual without the dense G: r = W - W_lin + G F.
  Eigen::VectorXd r_dense = w - eq.linear_motion(12.0);
  // G F from the dense real G (I + G D with D = I gives G).
  std::vector<Eigen::MatrixXd> unit(blocks.size(), Eigen::MatrixXd::Identity(blocks[0].rows(), blocks[0].cols()));
  const Eigen::MatrixXd g = eq.dense_jacobian(12.0, unit) - Eigen::MatrixXd::Identity(J.rows(), J.cols());
  r_dense += g * f;
  EXPECT_LE((r - r_dense).norm(), kRoundOff * r_dense.norm());
}

TEST(ManyPairs, FrequencyDerivativeMatchesCentralDifferencesOfTheResidual) {
  const ThreeContacts sys;
  hbm::ContactEvaluator ev(evaluator_options(3), sys.pairs);
  ReducedEquations eq(sys.linear, ev);
  const Eigen::VectorXd w = mixed_state(ev, 5, 3e-4);
  Eigen::VectorXd r, dl, rp, rm;
  ASSERT_TRUE(eq.evaluate(w, 11.0, r, nullptr, &dl));
  const double h = 1e-5;
  ASSERT_TRUE(eq.evaluate(w, 11.0 + h, rp, nullptr, nullptr));
  ASSERT_TRUE(eq.evaluate(w, 11.0 - h, rm, nullptr, nullptr));
  const Eigen::VectorXd fd = (rp - rm) / (2 * h);
  // The lumped part's derivative is itself a central difference (step 1e-6 w): both are
  // O(h^2) accurate on a smooth function of f.
  EXPECT_LE((dl - fd).norm(), 1e-6 * fd.norm());
}

/// The bordered matrix solve_bordered() receives in factored form, formed densely from the
/// Jacobian J: [diag(1/rs) J diag(xs), column; row^T].
Eigen::MatrixXd dense_bordered(const Eigen::MatrixXd& J, const continuation::BorderedMatrix& a) {
  const Eigen::Index n = J.rows();
  Eigen::MatrixXd ad(n + 1, n + 1);
  ad.topLeftCorner(n, n) = a.r_scale.cwiseInverse().asDiagonal() * J * a.x_scale.asDiagonal();
  ad.col(n).head(n) = a.column;
  ad.row(n) = a.row.transpose();
  return ad;
}

/// The continuation's bordered system at (w, f): the dense J (for the reference) and the
/// column and row of a bordered matrix with the given scales; eq is linearized there.
struct Bordered {
  Eigen::MatrixXd J;
  Eigen::VectorXd column, row;
};
Bordered linearize_at(ReducedEquations& eq, const Eigen::VectorXd& w, double f, const Eigen::VectorXd& rs,
                      double lambda_scale) {
  Bordered out;
  Eigen::VectorXd r, dl, r_lin, dl_lin;
  EXPECT_TRUE(eq.evaluate(w, f, r, &out.J, &dl));
  EXPECT_TRUE(eq.linearize(w, f, r_lin, &dl_lin));
  EXPECT_EQ(r_lin, r);
  out.column = dl.cwiseQuotient(rs) * lambda_scale;
  out.row = Eigen::VectorXd::Constant(w.size() + 1, 1.0 / std::sqrt(w.size() + 1.0));
  return out;
}

TEST(ManyPairs, BorderedKrylovSolveEqualsTheDenseSolveAndRefactorsWhenThePreconditionerIsPoor) {
  const ThreeContacts sys;
  hbm::ContactEvaluator ev(evaluator_options(3), sys.pairs);
  ReducedEquations eq(sys.linear, ev);
  LinearSolverOptions so;
  so.kind = LinearSolverOptions::Kind::krylov;
  so.krylov_tolerance = 1e-13;
  eq.set_linear_solver(so);
  ASSERT_TRUE(eq.matrix_free());
  const int n = eq.size();
  // Scales as the continuation's: x and r in units of 1e-4 m, but not uniform, so that the
  // scaling does not cancel.
  const Eigen::VectorXd xs = 1e-4 * (1.0 + 0.5 * Eigen::ArrayXd::LinSpaced(n, 0.0, 1.0)).matrix();
  const Eigen::VectorXd rs = Eigen::VectorXd::Constant(n, 1e-4);
  const Eigen::VectorXd w0 = mixed_state(ev, 7, 3e-4);
  Eigen::VectorXd w1 = w0;
  w1.array() *= 1.0 + 1e-3 * Eigen::ArrayXd::LinSpaced(n, -1.0, 1.0);  // a nearby Newton iterate
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n + 1, 1.0, 2.0);

  // First solve: no factors yet, the bordered matrix is formed and factorized.
  const Bordered l0 = linearize_at(eq, w0, 12.0, rs, 1.0);
  const continuation::BorderedMatrix a0{rs, xs, l0.column, l0.row};
  Eigen::VectorXd d0;
  ASSERT_TRUE(eq.solve_bordered(a0, b, d0));
  EXPECT_EQ(eq.statistics().dense_factorizations, 1);
  const Eigen::MatrixXd ad0 = dense_bordered(l0.J, a0);
  EXPECT_LE((ad0 * d0 - b).norm(), so.krylov_tolerance * b.norm());

  // Second: GMRES with the structured product, preconditioned by the first point's factors.
  const Bordered l1 = linearize_at(eq, w1, 12.01, rs, 1.0);
  const continuation::BorderedMatrix a1{rs, xs, l1.column, l1.row};
  const int krylov_before = eq.statistics().krylov_solves;
  Eigen::VectorXd d1;
  ASSERT_TRUE(eq.solve_bordered(a1, b, d1));
  EXPECT_EQ(eq.statistics().dense_factorizations, 1);
  EXPECT_EQ(eq.statistics().krylov_solves, krylov_before + 1);
  const Eigen::MatrixXd ad1 = dense_bordered(l1.J, a1);
  const Eigen::VectorXd ref = Eigen::PartialPivLU<Eigen::MatrixXd>(ad1).solve(b);
  EXPECT_LE((d1 - ref).norm(), 1e-10 * ref.norm());
  EXPECT_LE((ad1 * d1 - b).norm(), so.krylov_tolerance * b.norm());

  // A matrix the lagged factors do not resemble (columns rescaled up to 6 times): GMRES
  // does not converge within its iteration cap and the solve renews the factors, still exact.
  so.krylov_max_iterations = 3;
  eq.set_linear_solver(so);                   // drops the factors
  ASSERT_TRUE(eq.solve_bordered(a1, b, d1));  // factors a1 again
  const Eigen::VectorXd far_xs =
      xs.cwiseProduct((1.0 + 5.0 * Eigen::ArrayXd::LinSpaced(n, 0.0, 1.0).square()).matrix());
  const continuation::BorderedMatrix far{rs, far_xs, l1.column, l1.row};
  const int factorizations = eq.statistics().dense_factorizations, failures = eq.statistics().krylov_failures;
  Eigen::VectorXd d2;
  ASSERT_TRUE(eq.solve_bordered(far, b, d2));
  EXPECT_GE(eq.statistics().krylov_failures,
            failures + 1);  // + 1 more if 3 iterations on the new factors fall short too
  EXPECT_EQ(eq.statistics().dense_factorizations, factorizations + 1);
  const Eigen::MatrixXd ad2 = dense_bordered(l1.J, far);
  const Eigen::VectorXd ref2 = Eigen::PartialPivLU<Eigen::MatrixXd>(ad2).solve(b);
  EXPECT_LE((d2 - ref2).norm(), 1e-10 * ref2.norm());
}

TEST(ManyPairs, ContinuationWithTheKrylovSolveTracesTheSameCurveAsTheDenseOne) {
  const ThreeContacts sys;
  std::vector<continuation::Branch> branches;
  std::vector<SolverStatistics> stats;
  for (auto kind : {LinearSolverOptions::Kind::dense, LinearSolverOptions::Kind::krylov}) {
    hbm::ContactEvaluator ev(evaluator_options(3), sys.pairs);
    ReducedEquations eq(sys.linear, ev);
    LinearSolverOptions so;
    so.kind = kind;
    so.krylov_tolerance = 1e-13;
    eq.set_linear_solver(so);
    continuation::ArclengthOptions o;
    o.lambda_start = 6.0;
    o.lambda_end = 11.0;
    o.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-4);
    o.initial_step = 0.1;
    o.tolerance = 1e-10;
    o.max_points = 2000;
    branches.push_back(continuation::trace(eq, eq.stuck_solution(o.lambda_start), o));
    stats.push_back(eq.statistics());
  }
  ASSERT_EQ(branches[0].status, continuation::BranchStatus::kReachedEnd) << branches[0].message;
  ASSERT_EQ(branches[1].status, continuation::BranchStatus::kReachedEnd) << branches[1].message;
  EXPECT_GT(stats[1].krylov_solves, stats[1].dense_factorizations);  // the structure was used
  // Same path: the Newton steps differ by ~1e-13 relative, far below the tolerance.
  ASSERT_EQ(branches[0].points.size(), branches[1].points.size());
  double dx = 0.0, xmax = 0.0, dlambda = 0.0;
  for (std::size_t i = 0; i < branches[0].points.size(); ++i) {
    dx = std::max(dx, (branches[0].points[i].x - branches[1].points[i].x).lpNorm<Eigen::Infinity>());
    xmax = std::max(xmax, branches[0].points[i].x.lpNorm<Eigen::Infinity>());
    dlambda = std::max(dlambda, std::abs(branches[0].points[i].lambda - branches[1].points[i].lambda));
  }
  EXPECT_LE(dx, 1e-8 * xmax);
  EXPECT_LE(dlambda, 1e-8);
}

// ---- FE sector: every shroud pair of a coarse mesh ------------------------------------

struct Sector : testing_support::CoarseSector {
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;

  Sector() : CoarseSector("many") {
    modal::ModalOptions mo;
    mo.modes = 8;
    for (int h : {0, 1, 2}) {
      auto r = modal::solve_harmonic(*sector, h, mo);
      bases[h] = r.basis;
      factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*sector, h);
    }
  }
  frf::SectorLinearPart linear(bool residual, int threads = 1) const {
    std::vector<frf::SectorContactPair> pairs;
    for (const auto& [low, high] : mesh.shroud_pairs)
      pairs.push_back(testing_support::circumferential_pair(mesh, low, high));
    const frf::SectorForcing forcing = testing_support::test_forcing(mesh, residual);
    return frf::SectorLinearPart(
        *sector, bases, [&](int h) { return factors.at(h); }, pairs, forcing, 2, threads);
  }
};

const Sector& sector() {
  static const Sector s;
  return s;
}

/// Every shroud pair of the sector with the same contact parameters.
std::vector<contact::PairParameters> sector_pairs(bool preload_in_equilibrium) {
  std::vector<contact::PairParameters> pairs(sector().mesh.shroud_pairs.size());
  for (auto& p : pairs) {
    p.tangential_stiffness = 2e5;
    p.normal_stiffness = 2e5;
    p.friction_coefficient = 0.3;
    p.normal_preload = 0.05;
    p.preload_in_equilibrium = preload_in_equilibrium;
  }
  return pairs;
}

TEST(ManyPairsSector, ExactFrequencyDerivativeOfTheModalReceptanceMatchesCentralDifferences) {
  const frf::SectorLinearPart part = sector().linear(true);
  const double w = 0.7 * sector().bases.at(1).omega[0];
  for (int n : {0, 1, 2}) {
    Eigen::MatrixXcd dg, dg_fd;
    Eigen::VectorXcd dw, dw_fd;
    part.harmonic_derivative(n, w, dg, dw);
    part.frf::LinearPart::harmonic_derivative(n, w, dg_fd, dw_fd);  // the central-difference default
    if (n == 0) {
      EXPECT_EQ(dg.norm(), 0.0);
      EXPECT_LE(dg_fd.norm(), 1e-12);
      continue;
    }
    EXPECT_LE((dg - dg_fd).norm(), 1e-6 * dg.norm()) << "n " << n;
    if (n == 1) {
      EXPECT_LE((dw - dw_fd).norm(), 1e-6 * dw.norm());
    }
  }
}

TEST(ManyPairsSector, FactoredReceptanceEqualsTheDenseOne) {
  for (bool residual : {true, false}) {
    const frf::SectorLinearPart part = sector().linear(residual);
    const int c = part.n_contact();
    const double w = 0.9 * sector().bases.at(1).omega[0];
    for (int n : {0, 1, 2}) {
      frf::HarmonicReceptance rec;
      part.harmonic(n, w, rec);
      Eigen::MatrixXcd dg;
      Eigen::VectorXcd dw;
      part.harmonic_derivative(n, w, dg, dw);
      frf::FactoredReceptance f;
      ASSERT_TRUE(part.factored_harmonic(n, w, true, f));
      Eigen::MatrixXcd g = f.flex ? Eigen::MatrixXcd(f.flex->topLeftCorner(c, c)) : Eigen::MatrixXcd::Zero(c, c);
      Eigen::MatrixXcd dg_f = Eigen::MatrixXcd::Zero(c, c);
      if (f.psi) {
        g += f.psi->topRows(c) * f.s.asDiagonal() * f.psi->topRows(c).adjoint();
        dg_f = f.psi->topRows(c) * f.ds.asDiagonal() * f.psi->topRows(c).adjoint();
      }
      EXPECT_EQ(f.flex == nullptr, n > 0 && !residual) << "n " << n;
      EXPECT_LE((g - rec.G).norm(), kRoundOff * rec.G.norm()) << "n " << n << " residual " << residual;
      EXPECT_LE((f.w_lin - rec.w_lin).norm(), kRoundOff * std::max(rec.w_lin.norm(), 1e-300)) << "n " << n;
      EXPECT_LE((dg_f - dg).norm(), kRoundOff * std::max(dg.norm(), 1e-300)) << "n " << n;
      EXPECT_LE((f.dw_lin - dw).norm(), kRoundOff * std::max(dw.norm(), 1e-300)) << "n " << n;
      // The response rows alone, as analyse() takes them.
      Eigen::MatrixXcd h_rows;
      Eigen::VectorXcd u_lin;
      part.response_harmonic(n, w, h_rows, u_lin);
      EXPECT_LE((h_rows - rec.H).norm(), kRoundOff * rec.H.norm()) << "n " << n;
      EXPECT_LE((u_lin - rec.u_lin).norm(), kRoundOff * std::max(rec.u_lin.norm(), 1e-300)) << "n " << n;
    }
    // Without contact forces the excitation's work per period is what the modal damping
    // dissipates (the massless residual flexibility does no work): an independent check of
    // the excitation's displacement energy() takes from Q_1's excitation row.
    std::vector<Eigen::VectorXcd> no_forces(3, Eigen::VectorXcd::Zero(c));
    double work = 0.0, viscous = 0.0;
    part.energy(w, no_forces, work, viscous);
    ASSERT_GT(viscous, 0.0);
    EXPECT_NEAR(work, viscous, kRoundOff * viscous) << "residual " << residual;
  }
}

TEST(ManyPairsSector, ReceptancesBuiltOnTwoThreadsAreBitwiseThoseOfOne) {
  // The harmonic indices' flexibilities are computed in parallel, each by the same operations.
  const frf::SectorLinearPart one = sector().linear(true, 1), two = sector().linear(true, 2);
  const double w = 0.9 * sector().bases.at(1).omega[0];
  for (int n : {0, 1, 2}) {
    frf::HarmonicReceptance a, b;
    one.harmonic(n, w, a);
    two.harmonic(n, w, b);
    EXPECT_TRUE(a.G == b.G) << "n " << n;
    EXPECT_TRUE(a.H == b.H) << "n " << n;
    EXPECT_TRUE(a.w_lin == b.w_lin) << "n " << n;
  }
}

/// The sector's linear part without its factored form: the harmonic balance then forms every
/// G_n densely, as it does for lumped models.
class DenseOnly : public frf::LinearPart {
 public:
  explicit DenseOnly(const frf::LinearPart& part) : part_(part) {}
  int n_contact() const override { return part_.n_contact(); }
  int n_response() const override { return part_.n_response(); }
  void harmonic(int n, double w, frf::HarmonicReceptance& out) const override { part_.harmonic(n, w, out); }
  void harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const override {
    part_.harmonic_derivative(n, w, dG, dw_lin);
  }
  void energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& work, double& viscous) const override {
    part_.energy(w, forces, work, viscous);
  }
  std::string describe() const override { return part_.describe(); }

 private:
  const frf::LinearPart& part_;
};

TEST(ManyPairsSector, ResidualWithTheFactoredReceptancesEqualsTheDenseOne) {
  const frf::SectorLinearPart part = sector().linear(true);
  const DenseOnly dense_part(part);
  // preload_in_equilibrium: the static term G_0 F_s too.
  hbm::ContactEvaluator ev(evaluator_options(2), sector_pairs(/*preload_in_equilibrium=*/true));
  ReducedEquations factored(part, ev), plain(dense_part, ev);
  const Eigen::VectorXd w = mixed_state(ev, 5, 2e-6);
  for (double f : {0.8, 1.1}) {
    const double hz = f * sector().bases.at(1).omega[0] / (2 * kPi);
    Eigen::VectorXd r1, r2, d1, d2;
    Eigen::MatrixXd j1, j2;
    ASSERT_TRUE(factored.evaluate(w, hz, r1, &j1, &d1));
    ASSERT_TRUE(plain.evaluate(w, hz, r2, &j2, &d2));
    EXPECT_LE((r1 - r2).norm(), kRoundOff * r2.norm());
    EXPECT_LE((d1 - d2).norm(), kRoundOff * d2.norm());
    EXPECT_LE((j1 - j2).norm(), kRoundOff * j2.norm());
  }
}

TEST(ManyPairsSector, AllShroudPairsBorderedKrylovAndDenseSolvesAgree) {
  const frf::SectorLinearPart part = sector().linear(true);
  hbm::ContactEvaluator ev(evaluator_options(2), sector_pairs(false));
  ReducedEquations eq(part, ev);
  ASSERT_GE(ev.n_pairs(), 5);
  const int n = eq.size();
  const double f = 0.9 * sector().bases.at(1).omega[0] / (2 * kPi);
  const Eigen::VectorXd w = mixed_state(ev, 11, 2e-6);
  Eigen::VectorXd r, dl, f_contact;
  Eigen::MatrixXd J;
  ASSERT_TRUE(eq.evaluate(w, f, r, &J, &dl));
  std::vector<Eigen::MatrixXd> blocks;
  ev.evaluate(w, f_contact, &blocks);
  const Eigen::MatrixXd dense = eq.dense_jacobian(f, blocks);
  EXPECT_LE((J - dense).norm(), kRoundOff * dense.norm());
  LinearSolverOptions so;
  so.kind = LinearSolverOptions::Kind::krylov;
  so.krylov_tolerance = 1e-13;
  eq.set_linear_solver(so);
  // The first Newton iterate factorizes; the next (the contacts a little further on) is
  // solved by GMRES with the structured product and the lagged factors.
  const Eigen::VectorXd xs = Eigen::VectorXd::Constant(n, 2e-6), rs = xs;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n + 1, -1.0, 1.0);
  const Bordered l0 = linearize_at(eq, w, f, rs, 1.0);
  Eigen::VectorXd d;
  ASSERT_TRUE(eq.solve_bordered(continuation::BorderedMatrix{rs, xs, l0.column, l0.row}, b, d));
  const Bordered l1 = linearize_at(eq, 1.01 * w, f * 1.001, rs, 1.0);
  const continuation::BorderedMatrix a1{rs, xs, l1.column, l1.row};
  ASSERT_TRUE(eq.solve_bordered(a1, b, d));
  EXPECT_EQ(eq.statistics().dense_factorizations, 1);
  EXPECT_EQ(eq.statistics().krylov_failures, 0);
  const Eigen::VectorXd ref = Eigen::PartialPivLU<Eigen::MatrixXd>(dense_bordered(l1.J, a1)).solve(b);
  EXPECT_LE((d - ref).norm(), 1e-9 * ref.norm());
}

}  // namespace
}  // namespace shroudsim::forced
