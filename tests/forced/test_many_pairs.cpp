// Many contact pairs: the structured Jacobian product, the exact frequency derivative of the
// residual and the preconditioned GMRES solve of the augmented Newton system against the
// plain dense forms they replace (forced/reduced_equations.hpp), on a lumped model with three
// 3D contacts and on a coarse FE sector with all its shroud pairs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>

#include "continuation/arclength.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "fe/assembly.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/lumped.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/sector_generator.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::forced {
namespace {

constexpr double kPi = std::numbers::pi;
// Dense products and LU solves of these sizes (n < 200) agree to ~1e-15 relative; the
// structured product only reorders the same sums.
constexpr double kRoundOff = 1e-12;

/// Three point masses (x, y, z each: 9 DOFs) on springs to ground and to each other, modes
/// near 8 to 30 Hz, 1 % stiffness-proportional damping, each mass with a full3d contact to
/// ground; 1 N on DOF 0.
struct ThreeContacts {
  frf::LumpedLinearPart linear;
  std::vector<contact::PairParameters> pairs;

  static frf::LumpedLinearPart make() {
    const int n = 9;
    Eigen::MatrixXd m = Eigen::MatrixXd::Identity(n, n), k = Eigen::MatrixXd::Zero(n, n);
    const double k0 = std::pow(2 * kPi * 8.0, 2);
    for (int node = 0; node < 3; ++node)
      for (int d = 0; d < 3; ++d) {
        const int i = 3 * node + d;
        k(i, i) += k0 * (1.0 + 0.3 * d);
        if (node < 2) {  // spring to the next mass, same direction
          const int j = i + 3;
          k(i, i) += 2 * k0, k(j, j) += 2 * k0, k(i, j) -= 2 * k0, k(j, i) -= 2 * k0;
        }
      }
    std::vector<frf::LumpedContact> contacts;
    for (int node = 0; node < 3; ++node) {
      frf::LumpedContact c;
      c.dof = {3 * node, 3 * node + 1, 3 * node + 2};
      c.frame_angle = 0.2 * node;
      contacts.push_back(c);
    }
    return frf::LumpedLinearPart(m, k, 1e-3 * k, contacts, 0, 1.0, 3);
  }
  ThreeContacts() : linear(make()) {
    for (int i = 0; i < 3; ++i) {
      contact::PairParameters p;
      p.tangential_stiffness = 2000.0 * (1 + i);
      p.normal_stiffness = 3000.0;
      p.friction_coefficient = 0.3;
      p.normal_preload = 0.5;
      pairs.push_back(p);
    }
  }
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

TEST(ManyPairs, KrylovSolveEqualsTheDenseSolveAndFallsBackWhenThePreconditionerIsPoor) {
  const ThreeContacts sys;
  hbm::ContactEvaluator ev(evaluator_options(3), sys.pairs);
  ReducedEquations eq(sys.linear, ev);
  LinearSolverOptions so;
  so.kind = LinearSolverOptions::Kind::krylov;
  so.krylov_tolerance = 1e-13;
  eq.set_linear_solver(so);
  const int n = eq.size();
  auto augmented = [&](const Eigen::VectorXd& w, double f) {
    Eigen::VectorXd r, dl;
    Eigen::MatrixXd J;
    EXPECT_TRUE(eq.evaluate(w, f, r, &J, &dl));
    Eigen::MatrixXd a(n + 1, n + 1);
    a.topLeftCorner(n, n) = J;
    a.topRightCorner(n, 1) = dl * 1e-4;  // a scaled lambda column
    a.bottomRows(1).setOnes();
    a(n, n) = 2.0;
    return a;
  };
  const Eigen::VectorXd w0 = mixed_state(ev, 7, 3e-4);
  Eigen::VectorXd w1 = w0;
  w1.array() *= 1.0 + 1e-3 * Eigen::ArrayXd::LinSpaced(n, -1.0, 1.0);  // a nearby Newton iterate
  const Eigen::MatrixXd a0 = augmented(w0, 12.0), a1 = augmented(w1, 12.01);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n + 1, 1.0, 2.0);
  Eigen::VectorXd d0, d1;
  ASSERT_TRUE(eq.solve_augmented(a0, b, d0));  // first solve: factorizes a0
  EXPECT_EQ(eq.statistics().dense_factorizations, 1);
  ASSERT_TRUE(eq.solve_augmented(a1, b, d1));  // second: GMRES preconditioned by a0's factors
  EXPECT_EQ(eq.statistics().krylov_solves, 1);
  EXPECT_GT(eq.statistics().krylov_iterations, 0);
  const Eigen::VectorXd ref = Eigen::PartialPivLU<Eigen::MatrixXd>(a1).solve(b);
  EXPECT_LE((d1 - ref).norm(), 1e-10 * ref.norm());
  EXPECT_LE((a1 * d1 - b).norm(), so.krylov_tolerance * b.norm());
  // A matrix the lagged factors do not resemble: GMRES does not converge within its
  // iteration cap and the solve falls back to a new LU, still exact.
  so.krylov_max_iterations = 3;
  so.refactor_after = 3;
  eq.set_linear_solver(so);
  ASSERT_TRUE(eq.solve_augmented(a0, b, d0));  // factors a0 again (set_linear_solver dropped them)
  Eigen::MatrixXd far = a1;
  far.topLeftCorner(n, n) += Eigen::MatrixXd::Identity(n, n) * 5.0 + Eigen::MatrixXd::Constant(n, n, 0.01);
  Eigen::VectorXd d2;
  const int factorizations = eq.statistics().dense_factorizations;
  ASSERT_TRUE(eq.solve_augmented(far, b, d2));
  EXPECT_EQ(eq.statistics().krylov_failures, 1);
  EXPECT_EQ(eq.statistics().dense_factorizations, factorizations + 1);
  const Eigen::VectorXd ref2 = Eigen::PartialPivLU<Eigen::MatrixXd>(far).solve(b);
  EXPECT_LE((d2 - ref2).norm(), kRoundOff * ref2.norm());
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

struct Sector {
  mesh::Mesh mesh;
  linalg::SparsePair<double> km;
  std::unique_ptr<cyclic::CyclicSector> sector;
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;

  Sector() {
    mesh::SectorGeometry g;
    g.element_order = 1;
    g.mesh_size = 0.03;
    const auto file = std::filesystem::temp_directory_path() / ("shroudsim_many_" + std::to_string(::getpid()) + ".msh");
    mesh::generate_sector_mesh(g, file, false);
    mesh = mesh::read_sector_mesh(file, {g.sectors, 1e-9});
    std::filesystem::remove(file);
    km = fe::assemble(mesh, fe::Material{});
    sector = std::make_unique<cyclic::CyclicSector>(mesh, km);
    modal::ModalOptions mo;
    mo.modes = 8;
    for (int h : {0, 1, 2}) {
      auto r = modal::solve_harmonic(*sector, h, mo);
      bases[h] = r.basis;
      factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*sector, h);
    }
  }
  frf::SectorLinearPart linear(bool residual) const {
    std::vector<frf::SectorContactPair> pairs;
    for (const auto& [low, high] : mesh.shroud_pairs) {
      frf::SectorContactPair p;
      p.low_node = low;
      p.high_node = high;
      // Any orthonormal frame serves the algebra; the normal roughly circumferential.
      const Eigen::Vector3d x = mesh.nodes.row(high);
      Eigen::Vector3d n(-x.y(), x.x(), 0.0);
      n.normalize();
      p.frame.row(2) = n;
      p.frame.row(0) = Eigen::Vector3d::UnitZ();
      p.frame.row(1) = n.cross(Eigen::Vector3d::UnitZ());
      pairs.push_back(p);
    }
    frf::SectorForcing forcing;
    forcing.engine_order = 1;
    forcing.excitation_node = mesh.n_nodes() / 2;
    forcing.response_node = mesh.n_nodes() / 3;
    forcing.force = Eigen::Vector3d(1.0, 1.0, 1.0);
    forcing.residual_flexibility = residual;
    return frf::SectorLinearPart(*sector, bases, [&](int h) { return factors.at(h); }, pairs, forcing, 2);
  }
};

const Sector& sector() {
  static const Sector s;
  return s;
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

TEST(ManyPairsSector, AllShroudPairsKrylovAndDenseSolvesAgree) {
  const frf::SectorLinearPart part = sector().linear(true);
  std::vector<contact::PairParameters> pairs(sector().mesh.shroud_pairs.size());
  for (auto& p : pairs) {
    p.tangential_stiffness = 2e5;
    p.normal_stiffness = 2e5;
    p.friction_coefficient = 0.3;
    p.normal_preload = 0.05;
  }
  hbm::ContactEvaluator ev(evaluator_options(2), pairs);
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
  Eigen::MatrixXd a0(n + 1, n + 1);
  a0.topLeftCorner(n, n) = J;
  a0.topRightCorner(n, 1) = dl;
  a0.bottomRows(1).setConstant(1.0 / std::sqrt(n + 1.0));
  // The next Newton iterate's matrix: the contacts a little further on.
  Eigen::VectorXd r1, dl1;
  Eigen::MatrixXd J1;
  ASSERT_TRUE(eq.evaluate(1.01 * w, f * 1.001, r1, &J1, &dl1));
  Eigen::MatrixXd a1 = a0;
  a1.topLeftCorner(n, n) = J1;
  a1.topRightCorner(n, 1) = dl1;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n + 1, -1.0, 1.0);
  Eigen::VectorXd d;
  ASSERT_TRUE(eq.solve_augmented(a0, b, d));
  ASSERT_TRUE(eq.solve_augmented(a1, b, d));
  const Eigen::VectorXd ref = Eigen::PartialPivLU<Eigen::MatrixXd>(a1).solve(b);
  EXPECT_LE((d - ref).norm(), 1e-9 * ref.norm());
  EXPECT_EQ(eq.statistics().krylov_solves, 1);
  // a1's Jacobian block is the last evaluated J: GMRES used the structured product.
  EXPECT_EQ(eq.statistics().krylov_structured, 1);
  // A scaled Jacobian block (not the last J): the probe sees it, the dense A is used, and
  // the solve is still right.
  Eigen::MatrixXd a2 = a1;
  a2.topLeftCorner(n, n) *= 1.0001;
  ASSERT_TRUE(eq.solve_augmented(a2, b, d));
  const Eigen::VectorXd ref2 = Eigen::PartialPivLU<Eigen::MatrixXd>(a2).solve(b);
  EXPECT_LE((d - ref2).norm(), 1e-9 * ref2.norm());
  EXPECT_EQ(eq.statistics().krylov_structured, 1);
}

}  // namespace
}  // namespace shroudsim::forced
