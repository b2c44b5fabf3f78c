// The sector's modal receptances (with residual flexibility) against a direct solve of
// the cyclic system (K_h - W^2 M_h)^-1 at the contact, response and excitation DOFs.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/SparseLU>
#include <algorithm>
#include <mutex>
#include <numbers>
#include <random>
#include <set>

#include "../common/coarse_sector.hpp"
#include "../common/sector_contacts.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "frf/sector.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::frf {
namespace {

using Complex = std::complex<double>;

struct Fixture : testing_support::CoarseSector {
  Fixture() : CoarseSector("rec") {}
};

/// `count` matched shroud pairs (every `stride`-th), frames turned about `axis` by
/// offset + step * i.
std::vector<SectorContactPair> some_pairs(const Fixture& f, std::size_t count, std::size_t stride, double offset,
                                          double step, const Eigen::Vector3d& axis) {
  std::vector<SectorContactPair> pairs;
  for (std::size_t i = 0; i < count; ++i) {
    SectorContactPair p;
    p.low_node = f.mesh.shroud_pairs[i * stride].first;
    p.high_node = f.mesh.shroud_pairs[i * stride].second;
    p.frame = Eigen::AngleAxis<double>(offset + step * static_cast<double>(i), axis.normalized()).toRotationMatrix();
    pairs.push_back(p);
  }
  return pairs;
}

/// Direct Q = C R C^H with R = T_h (K_h - W^2 M_h)^-1 T_h^H (no damping), via the same C rows
/// the sector part uses: contact pairs, response node, excitation force.
Eigen::MatrixXcd direct(const Fixture& f, const std::vector<SectorContactPair>& pairs, const SectorForcing& forcing,
                        int h, double w) {
  const auto kmh = f.sector->reduce(h);
  Eigen::SparseMatrix<Complex> a = kmh.K - w * w * kmh.M;
  a.makeCompressed();
  Eigen::SparseLU<Eigen::SparseMatrix<Complex>> lu(a);
  const double alpha = 2 * std::numbers::pi / f.sector->sectors();
  const Eigen::Matrix3d rot = cyclic::rotation_z(alpha);
  const Complex phase = std::exp(Complex(0, h * alpha));
  const int c = 3 * static_cast<int>(pairs.size());
  Eigen::MatrixXcd rows = Eigen::MatrixXcd::Zero(c + 4, f.sector->n_full());
  for (std::size_t i = 0; i < pairs.size(); ++i)
    for (int a3 = 0; a3 < 3; ++a3)
      for (int b = 0; b < 3; ++b) {
        rows(3 * i + a3, 3 * pairs[i].high_node + b) += pairs[i].frame(a3, b);
        rows(3 * i + a3, 3 * pairs[i].low_node + b) -= phase * (pairs[i].frame * rot)(a3, b);
      }
  for (int a3 = 0; a3 < 3; ++a3) rows(c + a3, 3 * forcing.response_node + a3) = 1.0;
  for (int a3 = 0; a3 < 3; ++a3) rows(c + 3, 3 * forcing.excitation_node + a3) = forcing.force[a3];
  const Eigen::MatrixXcd ct = rows * Eigen::MatrixXcd(f.sector->expansion(h));
  const Eigen::MatrixXcd y = lu.solve(Eigen::MatrixXcd(ct.adjoint()));
  return ct * y;
}

TEST(SectorReceptance, ModalSumWithResidualFlexibilityMatchesTheDirectSolve) {
  const Fixture f;
  // Three shroud pairs with a turned frame, response and excitation on the blade.
  std::vector<SectorContactPair> pairs;
  for (std::size_t i = 0; i < 3; ++i) {
    SectorContactPair p;
    p.low_node = f.mesh.shroud_pairs[i * 2].first;
    p.high_node = f.mesh.shroud_pairs[i * 2].second;
    p.frame = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    pairs.push_back(p);
  }
  SectorForcing forcing;
  forcing.engine_order = 3;  // harmonic 1 -> h = 3, harmonic 2 -> h = 6 (= conj of 2)
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(1.0, -0.5, 0.25);
  forcing.damping_ratio = 0.0;

  modal::ModalOptions mo;
  mo.modes = 20;
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;
  for (int h : {0, 3, 6}) {
    auto r = modal::solve_harmonic(*f.sector, h, mo);
    ASSERT_TRUE(r.report.ok()) << r.report.message;
    bases[h] = r.basis;
    factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*f.sector, h);
  }
  auto factor = [&](int h) { return factors.at(h); };
  for (bool residual : {true, false}) {
    forcing.residual_flexibility = residual;
    const SectorLinearPart part(*f.sector, bases, factor, pairs, forcing, /*n_harmonics=*/2);
    for (int n : {1, 2}) {
      const int h = part.harmonic_index(n);
      // Below the first mode of h: truncation error of the modal sum ~ (W / w_21)^2 with
      // residual flexibility, ~ the static share of the truncated modes without it.
      const double w = 0.5 * bases.at(h).omega[0] / n;
      HarmonicReceptance rec;
      part.harmonic(n, w, rec);
      const Eigen::MatrixXcd q = direct(f, pairs, forcing, h, n * w);
      const int c = part.n_contact();
      const double err_g = (rec.G - q.topLeftCorner(c, c)).norm() / q.topLeftCorner(c, c).norm();
      const double err_h = (rec.H - q.block(c, 0, 3, c)).norm() / q.block(c, 0, 3, c).norm();
      // The excitation acts in temporal harmonic 1 only: u_lin of other harmonics is zero.
      const double err_u = n == 1 ? (rec.u_lin - q.block(c, c + 3, 3, 1)).norm() / q.block(c, c + 3, 3, 1).norm()
                                  : rec.u_lin.norm();
      if (residual) {
        constexpr double kTruncation = 1e-3;  // (0.5 w_1 / w_21)^2 is far below this here
        EXPECT_LT(err_g, kTruncation) << "n " << n;
        EXPECT_LT(err_h, kTruncation) << "n " << n;
        EXPECT_LT(err_u, kTruncation) << "n " << n;
      } else {
        EXPECT_GT(err_g, 1e-3) << "without residual flexibility the local contact flexibility is missed";
      }
    }
    // The static harmonic is exact: T_0 K_0^-1 T_0^T.
    HarmonicReceptance r0;
    part.harmonic(0, 1.0, r0);
    const Eigen::MatrixXcd q0 = direct(f, pairs, forcing, 0, 0.0);
    EXPECT_LT((r0.G - q0.topLeftCorner(9, 9)).norm(), 1e-10 * q0.topLeftCorner(9, 9).norm());
  }
}

/// The shapes tests' forcing: excitation and response at two interior nodes.
SectorForcing shape_forcing(const Fixture& f, int engine_order) {
  SectorForcing forcing;
  forcing.engine_order = engine_order;
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(1.0, -0.5, 0.25);
  return forcing;
}

/// Seeded random contact-force harmonics F_0..F_H (c each; F_0 real, as the static harmonic is).
std::vector<Eigen::VectorXcd> random_forces(int n_harmonics, int c, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Eigen::VectorXcd> forces(static_cast<std::size_t>(n_harmonics) + 1, Eigen::VectorXcd(c));
  for (auto& fn : forces)
    for (int i = 0; i < c; ++i) fn[i] = Complex(g(rng), g(rng));
  forces[0] = forces[0].real().cast<Complex>();
  return forces;
}

// The receptance data is linear in the force (its excitation row): a part built for f and
// scaled by a (scale_force, what a cache entry of another excitation level gets) has the data,
// receptances and kept static solutions of a part built for a f, to round-off.
TEST(SectorReceptance, ScalingTheForceIsBuildingWithTheScaledForce) {
  const Fixture f;
  const std::vector<SectorContactPair> pairs = some_pairs(f, 3, 2, 0.3, 0.2, Eigen::Vector3d(1, 2, 3));
  SectorForcing forcing = shape_forcing(f, 3);
  forcing.damping_ratio = 0.01;
  modal::ModalOptions mo;
  mo.modes = 10;
  std::map<int, modal::ModalBasis> bases;
  for (int h : {0, 3, 6}) {
    auto r = modal::solve_harmonic(*f.sector, h, mo);
    ASSERT_TRUE(r.report.ok()) << r.report.message;
    bases[h] = r.basis;
  }
  auto factor = [&](int h) { return modal::factor_harmonic_stiffness(*f.sector, h); };
  constexpr double a = -2.5;
  SectorForcing scaled = forcing;
  scaled.force = a * forcing.force;
  SectorLinearPart part(*f.sector, bases, factor, pairs, forcing, 2);
  const SectorLinearPart direct_part(*f.sector, bases, factor, pairs, scaled, 2);
  part.scale_force(a, scaled.force);
  constexpr double kRoundOff = 1e-12;  // relative: the same solves, a real factor applied after
  auto near = [&](const Eigen::MatrixXcd& x, const Eigen::MatrixXcd& y, const std::string& what) {
    ASSERT_EQ(x.rows(), y.rows()) << what;
    ASSERT_EQ(x.cols(), y.cols()) << what;
    EXPECT_LE((x - y).norm(), kRoundOff * y.norm()) << what;
  };
  const auto p = part.precomputed(), q = direct_part.precomputed();
  near(p.statics.flex, q.statics.flex, "static flexibility");
  ASSERT_EQ(p.dynamic.size(), q.dynamic.size());
  for (const auto& [h, d] : q.dynamic) {
    near(p.dynamic.at(h).psi, d.psi, "psi of index " + std::to_string(h));
    // The residual flexibility is the static solution less the kept modes' part, and the two
    // are solved with differently rounded right-hand sides (a f against f): its round-off is
    // relative to those terms, not to their difference (2e-3 to 5e-3 of them here: measured
    // 1.0e-12 of the difference on one machine, 2e-15 of the terms).
    const Eigen::MatrixXcd kept = d.psi * d.omega.cwiseAbs2().cwiseInverse().asDiagonal() * d.psi.adjoint();
    const double terms = kept.norm() + (kept + d.flex).norm();
    EXPECT_LE((p.dynamic.at(h).flex - d.flex).norm(), kRoundOff * terms) << "flex of index " << h;
  }
  const double w = 0.7 * bases.at(3).omega[0];
  for (int n : {0, 1, 2}) {
    HarmonicReceptance r1, r2;
    part.harmonic(n, w, r1);
    direct_part.harmonic(n, w, r2);
    near(r1.G, r2.G, "G_" + std::to_string(n));
    near(r1.w_lin, r2.w_lin, "w_lin_" + std::to_string(n));
    near(r1.u_lin, r2.u_lin, "u_lin_" + std::to_string(n));
  }
  // The excitation moves with a: harmonic 1's free motion is a times the unscaled one's.
  const SectorLinearPart unscaled(*f.sector, bases, factor, pairs, forcing, 2);
  HarmonicReceptance r0, r1;
  unscaled.harmonic(1, w, r0);
  part.harmonic(1, w, r1);
  near(r1.w_lin, a * r0.w_lin, "w_lin scales with the force");
  for (int h : {0, 3}) {
    bool c1 = false, c2 = false;
    const Eigen::MatrixXcd* y1 = part.static_solution(h, c1);
    const Eigen::MatrixXcd* y2 = direct_part.static_solution(h, c2);
    ASSERT_TRUE(y1 && y2) << "the coarse sector keeps its static solutions";
    near(*y1, *y2, "static solution of index " + std::to_string(h));
  }
}

// The whole-sector displacement of the shapes (frf.vtu): its contact and response rows are the
// receptance's (w_lin - G F, u_lin - H F) to round-off, for the static and dynamic harmonics
// with and without residual flexibility; and below the first mode the whole field agrees with
// a direct solve of (K_h - W^2 M_h) u = f over every DOF within the modal truncation.
TEST(SectorShapes, WholeFieldHasTheReceptancesRowsAndMatchesTheDirectSolve) {
  const Fixture f;
  std::vector<SectorContactPair> pairs = some_pairs(f, 3, 2, 0.3, 0.2, Eigen::Vector3d(1, 2, 3));
  SectorForcing forcing = shape_forcing(f, 3);
  modal::ModalOptions mo;
  mo.modes = 20;
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;
  for (int h : {0, 3, 6}) {
    auto r = modal::solve_harmonic(*f.sector, h, mo);
    ASSERT_TRUE(r.report.ok()) << r.report.message;
    bases[h] = r.basis;
    factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*f.sector, h);
  }
  auto factor = [&](int h) { return factors.at(h); };
  const int c = 9;
  const std::vector<Eigen::VectorXcd> forces = random_forces(2, c, 5);
  for (bool residual : {true, false}) {
    for (double zeta : {0.02, 0.0}) {
      forcing.residual_flexibility = residual;
      forcing.damping_ratio = zeta;
      const SectorLinearPart part(*f.sector, bases, factor, pairs, forcing, 2);
      const double w = 0.5 * bases.at(3).omega[0];
      const auto u = sector_displacements(*f.sector, bases, factor, pairs, forcing, {{w, forces}});
      ASSERT_EQ(u.size(), 1u);
      ASSERT_EQ(u[0].size(), 3u);
      for (int n = 0; n <= 2; ++n) {
        HarmonicReceptance rec;
        part.harmonic(n, w, rec);
        const int h = n == 0 ? 0 : part.harmonic_index(n);
        const Eigen::VectorXcd w_rows = contact_rows(pairs, *f.sector, h, f.sector->n_full()) * u[0][n];
        const Eigen::VectorXcd w_ref = rec.w_lin - rec.G * forces[n];
        const Eigen::VectorXcd u_ref = rec.u_lin - rec.H * forces[n];
        // Round-off of the two summation orders of the same modal sum and solves.
        constexpr double kRoundOff = 1e-9;
        EXPECT_LT((w_rows - w_ref).norm(), kRoundOff * w_ref.norm()) << "n " << n << " residual " << residual;
        EXPECT_LT((u[0][n].segment(3 * forcing.response_node, 3) - u_ref).norm(), kRoundOff * u_ref.norm())
            << "n " << n << " residual " << residual;
      }
      if (residual && zeta == 0.0) {
        // Direct: u = T_h (K_h - W^2 M_h)^-1 T_h^H C^H y, y = (-F_1, 0, 1).
        const int h = part.harmonic_index(1);
        const auto kmh = f.sector->reduce(h);
        Eigen::SparseMatrix<Complex> a = kmh.K - w * w * kmh.M;
        a.makeCompressed();
        Eigen::SparseLU<Eigen::SparseMatrix<Complex>> lu(a);
        Eigen::SparseMatrix<Complex> rows = contact_rows(pairs, *f.sector, h, f.sector->n_full());
        Eigen::VectorXcd load = Eigen::VectorXcd(rows.adjoint() * Eigen::VectorXcd(-forces[1]));
        load.segment(3 * forcing.excitation_node, 3) += forcing.force.cast<Complex>();
        const Eigen::SparseMatrix<Complex> t = f.sector->expansion(h);
        const Eigen::VectorXcd ref = t * Eigen::VectorXcd(lu.solve(Eigen::VectorXcd(t.adjoint() * load)));
        constexpr double kTruncation = 1e-3;  // as in ModalSumWithResidualFlexibilityMatchesTheDirectSolve
        EXPECT_LT((u[0][1] - ref).norm(), kTruncation * ref.norm());
      }
    }
  }
}

}  // namespace
}  // namespace shroudsim::frf

#include "forced/excitation_homotopy.hpp"
#include "forced/reduced_equations.hpp"

namespace shroudsim::frf {
namespace {

TEST(SectorForced, EnergyBalanceAndOpenGapOnTheSector) {
  const Fixture f;
  std::vector<SectorContactPair> pairs;
  std::vector<contact::PairParameters> params;
  for (std::size_t i = 0; i < 3; ++i) {
    SectorContactPair p;
    p.low_node = f.mesh.shroud_pairs[i * 3].first;
    p.high_node = f.mesh.shroud_pairs[i * 3].second;
    pairs.push_back(p);
    contact::PairParameters pp;
    pp.tangential_stiffness = 2e5;
    pp.normal_stiffness = 2e5;
    pp.normal_preload = 0.02;
    params.push_back(pp);
  }
  SectorForcing forcing;
  forcing.engine_order = 1;
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(1.0, 1.0, 1.0);
  forcing.damping_ratio = 0.01;
  modal::ModalOptions mo;
  mo.modes = 15;
  std::map<int, modal::ModalBasis> bases;
  for (int h : {1, 2, 3}) bases[h] = modal::solve_harmonic(*f.sector, h, mo).basis;
  const SectorLinearPart part(
      *f.sector, bases, [&](int h) { return modal::factor_harmonic_stiffness(*f.sector, h); }, pairs, forcing, 3);
  const double f_hz = 0.8 * bases.at(1).omega[0] / (2 * std::numbers::pi);
  for (const contact::Model model : {contact::Model::one_d, contact::Model::quasi3d}) {
    hbm::ContactEvaluatorOptions o;
    o.n_harmonics = 3;
    o.n_time_samples = 64;
    o.law.model = model;
    o.threads = 1;
    hbm::ContactEvaluator ev(o, params);
    forced::ReducedEquations eq(part, ev);
    continuation::ArclengthOptions ao;
    ao.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-6);
    ao.tolerance = 1e-9;
    Eigen::VectorXd w;
    const auto b = forced::solve_by_excitation_homotopy(eq, f_hz, ao, w);
    ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << contact::to_string(model) << ": " << b.message;
    const forced::PointResult r = eq.analyse(w, f_hz);
    // Excitation work = modal viscous + contact dissipation, to the Newton tolerance.
    EXPECT_LT(r.energy_error, 1e-5) << contact::to_string(model);
    EXPECT_GT(r.contact_dissipation, 0.0) << contact::to_string(model);
  }
  // A gap that never closes: the free response.
  for (auto& p : params) p.normal_preload = -1e3;  // gap of 5 mm
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 3;
  o.n_time_samples = 64;
  o.threads = 1;
  hbm::ContactEvaluator ev(o, params);
  forced::ReducedEquations eq(part, ev);
  continuation::ArclengthOptions ao;
  ao.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-6);
  Eigen::VectorXd w = eq.linear_motion(f_hz);
  ASSERT_GE(continuation::newton_fixed(eq, w, f_hz, ao), 0);
  const forced::PointResult r = eq.analyse(w, f_hz);
  EXPECT_NEAR(r.amplitude / r.linear_amplitude, 1.0, 1e-12);
}

}  // namespace
}  // namespace shroudsim::frf

namespace shroudsim::frf {
namespace {

TEST(SectorForced, HugeFrictionGivesTheLinearSectorWithContactSprings) {
  // Independent reference: the cyclic system of harmonic index h with the contact springs
  // (kt, kt, kn in each pair's frame, joining q and the next sector's p') assembled into
  // K_h, solved directly: U = D T_h (K_h + S_h - W^2 M_h)^-1 T_h^H f.
  const Fixture f;
  const auto pairs = some_pairs(f, 4, 2, 0.0, 0.7, Eigen::Vector3d(0.2, 1, 0.5));
  std::vector<contact::PairParameters> params;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    contact::PairParameters pp;
    pp.tangential_stiffness = 3e6;
    pp.normal_stiffness = 5e6;
    pp.friction_coefficient = 1e6;  // never slips
    pp.normal_preload = 10.0;       // never opens
    params.push_back(pp);
  }
  SectorForcing forcing;
  forcing.engine_order = 2;
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(0.3, 1.0, -0.2);
  forcing.damping_ratio = 0.0;
  modal::ModalOptions mo;
  mo.modes = 20;
  std::map<int, modal::ModalBasis> bases;
  for (int h : {2, 4}) bases[h] = modal::solve_harmonic(*f.sector, h, mo).basis;
  const SectorLinearPart part(
      *f.sector, bases, [&](int h) { return modal::factor_harmonic_stiffness(*f.sector, h); }, pairs, forcing, 2);
  const int h = 2;
  const double w = 0.4 * bases.at(h).omega[0];
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 2;
  o.n_time_samples = 32;
  o.threads = 1;
  hbm::ContactEvaluator ev(o, params);
  forced::ReducedEquations eq(part, ev);
  continuation::ArclengthOptions ao;
  ao.x_scale = Eigen::VectorXd::Constant(eq.size(), 1e-6);
  ao.tolerance = 1e-12;
  Eigen::VectorXd sol = eq.stuck_solution(w / (2 * std::numbers::pi));
  ASSERT_GE(continuation::newton_fixed(eq, sol, w / (2 * std::numbers::pi), ao), 0);
  const forced::PointResult r = eq.analyse(sol, w / (2 * std::numbers::pi));

  const auto kmh = f.sector->reduce(h);
  const double alpha = 2 * std::numbers::pi / f.sector->sectors();
  const Complex phase = std::exp(Complex(0, h * alpha));
  const Eigen::Matrix3d rot = cyclic::rotation_z(alpha);
  std::vector<Eigen::Triplet<Complex>> t;
  for (std::size_t i = 0; i < pairs.size(); ++i)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        t.emplace_back(3 * i + a, 3 * pairs[i].high_node + b, pairs[i].frame(a, b));
        t.emplace_back(3 * i + a, 3 * pairs[i].low_node + b, -phase * (pairs[i].frame * rot)(a, b));
      }
  Eigen::SparseMatrix<Complex> bmat(3 * pairs.size(), f.sector->n_full());
  bmat.setFromTriplets(t.begin(), t.end());
  const Eigen::SparseMatrix<Complex> bt = bmat * f.sector->expansion(h);
  Eigen::SparseMatrix<Complex> kc(3 * pairs.size(), 3 * pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    kc.insert(3 * i, 3 * i) = params[i].tangential_stiffness;
    kc.insert(3 * i + 1, 3 * i + 1) = params[i].tangential_stiffness;
    kc.insert(3 * i + 2, 3 * i + 2) = params[i].normal_stiffness;
  }
  Eigen::SparseMatrix<Complex> a = kmh.K + Eigen::SparseMatrix<Complex>(bt.adjoint()) * kc * bt - w * w * kmh.M;
  a.makeCompressed();
  Eigen::SparseLU<Eigen::SparseMatrix<Complex>> lu(a);
  Eigen::VectorXcd fext = Eigen::VectorXcd::Zero(f.sector->n_full());
  for (int k = 0; k < 3; ++k) fext[3 * forcing.excitation_node + k] = forcing.force[k];
  const Eigen::MatrixXcd tf = Eigen::MatrixXcd(f.sector->expansion(h)).adjoint() * fext;
  const Eigen::VectorXcd u = f.sector->expand(h, lu.solve(tf));
  const double exact = u.segment(3 * forcing.response_node, 3).norm();
  // Modal truncation with residual flexibility at 0.4 w_1: well below 1e-3.
  constexpr double kTruncation = 1e-3;
  EXPECT_NEAR(r.harmonic_amplitudes[1] / exact, 1.0, kTruncation);
}

}  // namespace
}  // namespace shroudsim::frf

namespace shroudsim::frf {
namespace {

TEST(SectorReceptance, ConjugatedBasisAndFactorServeHarmonicIndexNbMinusH) {
  // The modal stage serves h > Nb/2 from h' = Nb - h by conjugation (modes and K factor):
  // the receptance built that way must equal the direct solve of h itself.
  const Fixture f;
  const auto pairs = some_pairs(f, 3, 2, 0.1, 0.4, Eigen::Vector3d(1, -1, 2));
  SectorForcing forcing;
  forcing.engine_order = 5;  // harmonic 1 -> h = 5 = conj of 3
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(1.0, 0.5, -0.25);
  forcing.damping_ratio = 0.0;
  modal::ModalOptions mo;
  mo.modes = 20;
  auto r3 = modal::solve_harmonic(*f.sector, 3, mo);
  ASSERT_TRUE(r3.report.ok());
  std::map<int, modal::ModalBasis> bases{{5, r3.basis.conjugate(5)}};
  const modal::StiffnessFactor k3 = modal::factor_harmonic_stiffness(*f.sector, 3);
  const modal::StiffnessFactor k0 = modal::factor_harmonic_stiffness(*f.sector, 0);
  auto factor = [&](int h) { return h == 5 ? k3.conjugate() : k0; };
  const SectorLinearPart part(*f.sector, bases, factor, pairs, forcing, 1);
  const double w = 0.5 * bases.at(5).omega[0];
  HarmonicReceptance rec;
  part.harmonic(1, w, rec);
  const Eigen::MatrixXcd q = direct(f, pairs, forcing, 5, w);
  const int c = part.n_contact();
  EXPECT_LT((rec.G - q.topLeftCorner(c, c)).norm(), 1e-3 * q.topLeftCorner(c, c).norm());
  EXPECT_LT((rec.w_lin - q.block(0, c + 3, c, 1)).norm(), 1e-3 * q.block(0, c + 3, c, 1).norm());
}

// The shapes reuse the receptances' static solutions K_h^-1 C_h^H (SectorLinearPart keeps
// them when they fit in kKeptSolutionBytes): the displacements through them equal those
// through a new factorization to round-off, for the static harmonic, the dynamic ones, and a
// harmonic whose index is the conjugate of the one solved; and without kept solutions the
// factorizations, one per pair of conjugate indices in parallel, give the same field on one
// thread and on two.
TEST(SectorShapes, KeptStaticSolutionsGiveTheFactorsDisplacements) {
  const Fixture f;
  const int nb = f.sector->sectors();
  std::vector<SectorContactPair> pairs = some_pairs(f, 3, 2, 0.3, 0.2, Eigen::Vector3d(1, 2, 3));
  SectorForcing forcing = shape_forcing(f, 2);
  forcing.damping_ratio = 0.01;
  modal::ModalOptions mo;
  mo.modes = 12;
  // Harmonics n = 0..H with engine order 2: indices 2 n mod Nb, so that some harmonic falls
  // on the conjugate Nb - h of another's index.
  const int n_harmonics = nb - 1;
  std::map<int, modal::ModalBasis> bases;
  for (int n = 0; n <= n_harmonics; ++n) {
    const int h = (2 * n) % nb;
    if (bases.count(h)) continue;
    auto r = modal::solve_harmonic(*f.sector, h, mo);
    ASSERT_TRUE(r.report.ok()) << r.report.message;
    bases[h] = r.basis;
  }
  int factorizations = 0;
  std::mutex lock;
  auto factor = [&](int h) {
    {
      const std::lock_guard<std::mutex> g(lock);
      ++factorizations;
    }
    return modal::factor_harmonic_stiffness(*f.sector, h);
  };
  const int c = 9;
  const std::vector<Eigen::VectorXcd> forces = random_forces(n_harmonics, c, 11);
  const double w = 0.7 * bases.at(2).omega[0];
  forcing.residual_flexibility = true;
  const SectorLinearPart part(*f.sector, bases, factor, pairs, forcing, n_harmonics, 2);
  bool conjugated = true;
  ASSERT_NE(part.static_solution(0, conjugated), nullptr);
  EXPECT_FALSE(conjugated);
  bool has_conjugate = false;  // a harmonic index whose solution is its conjugate's
  for (int n = 1; n <= n_harmonics; ++n) {
    ASSERT_NE(part.static_solution(part.harmonic_index(n), conjugated), nullptr) << "n " << n;
    has_conjugate = has_conjugate || conjugated;
  }
  ASSERT_TRUE(has_conjugate);

  factorizations = 0;
  const auto kept = sector_displacements(*f.sector, bases, factor, pairs, forcing, {{w, forces}}, &part, 2);
  EXPECT_EQ(factorizations, 0);
  factorizations = 0;
  const auto one = sector_displacements(*f.sector, bases, factor, pairs, forcing, {{w, forces}}, nullptr, 1);
  std::set<int> groups;  // one factorization per pair of conjugate indices {h, Nb - h}
  for (int n = 0; n <= n_harmonics; ++n) groups.insert(std::min((2 * n) % nb, (nb - (2 * n) % nb) % nb));
  EXPECT_EQ(factorizations, static_cast<int>(groups.size()));
  const auto two = sector_displacements(*f.sector, bases, factor, pairs, forcing, {{w, forces}}, nullptr, 2);
  // K_h^-1 (C^H y) against (K_h^-1 C^H) y: two orders of the same solves, held to the
  // round-off bound of the test above.
  constexpr double kRoundOff = 1e-9;
  for (int n = 0; n <= n_harmonics; ++n) {
    EXPECT_LT((kept[0][n] - one[0][n]).norm(), kRoundOff * one[0][n].norm()) << "n " << n;
    EXPECT_TRUE(one[0][n] == two[0][n]) << "n " << n;  // bitwise: each index's arithmetic on any thread count
  }
}

}  // namespace
}  // namespace shroudsim::frf

#include "forced/frequency_response.hpp"

namespace shroudsim::frf {
namespace {

// The start search's harmonic stepping reaches a level that Newton does not reach from the
// level below by the excitation homotopy at that level (docs/continuation.md, "Start"). On the
// coarse sector with all 10 shroud pairs (full3d, H = 5) that happens near the first family's
// resonance, at one level or several. Each such start is checked against an independent route
// to it: the excitation homotopy with all five harmonics from the preload-only state. Both end
// at the corrector's tolerance (1e-8 of the x unit per residual), so they agree to about that
// relative to the solution; kSameSolution allows a factor 100 for the equations' conditioning.
TEST(SectorForced, AStartThroughTheHomotopyAtALowerLevelIsTheFullHomotopysSolution) {
  constexpr double kSameSolution = 1e-6;
  const Fixture f;
  std::vector<SectorContactPair> pairs;
  std::vector<contact::PairParameters> params;
  for (const auto& [low, high] : f.mesh.shroud_pairs) {
    pairs.push_back(testing_support::circumferential_pair(f.mesh, low, high));
    contact::PairParameters pp;
    pp.tangential_stiffness = 2e5;
    pp.normal_stiffness = 2e5;
    pp.normal_preload = 0.02;
    params.push_back(pp);
  }
  SectorForcing forcing = testing_support::test_forcing(f.mesh, true);
  forcing.damping_ratio = 0.01;
  modal::ModalOptions mo;
  mo.modes = 15;
  std::map<int, modal::ModalBasis> bases;
  for (int h : {1, 2, 3, 4, 5}) bases[h] = modal::solve_harmonic(*f.sector, h, mo).basis;
  forced::ForcedModel model;
  model.linear = std::make_unique<SectorLinearPart>(
      *f.sector, bases, [&](int h) { return modal::factor_harmonic_stiffness(*f.sector, h); }, pairs, forcing, 5);
  model.pairs = params;
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = 5;
  o.n_time_samples = 128;
  o.law.model = contact::Model::full3d;
  o.threads = 1;
  hbm::ContactEvaluator ev(o, params);
  forced::ReducedEquations eq(*model.linear, ev);
  const double f1 = bases.at(1).omega[0] / (2 * std::numbers::pi);
  forced::FrequencyResponseSettings s;
  s.frequency_start_hz = 0.7 * f1;
  s.frequency_end_hz = 1.3 * f1;
  const continuation::ArclengthOptions ao = forced::arclength_options(s, model, eq);
  int checked = 0, several_levels = 0;
  for (double ratio : {0.98, 1.0, 1.02, 1.04, 1.06}) {  // of the first family's free frequency
    const double fr = ratio * f1;
    std::string how;
    const Eigen::VectorXd w = forced::find_start(model, o, eq, ao, fr, how);
    const auto at = how.find("the excitation homotopy at H = ");
    if (at == std::string::npos) continue;
    Eigen::VectorXd reference;
    const auto b = forced::solve_by_excitation_homotopy(eq, fr, ao, reference);
    ASSERT_EQ(b.status, continuation::BranchStatus::kReachedEnd) << fr << " Hz: " << b.message;
    EXPECT_LT((w - reference).norm(), kSameSolution * reference.norm()) << fr << " Hz, " << how;
    ++checked;
    if (how.find(',', at) != std::string::npos) ++several_levels;
  }
  EXPECT_GE(checked, 2);
  EXPECT_GE(several_levels, 1);
  // The stepping solves the equations at their own excitation scale (nlmodes' comparison traces
  // scaled excitations): at half the excitation the start is the half-excitation solution.
  eq.set_excitation_scale(0.5);
  const double fr = 1.02 * f1;
  std::string how;
  const Eigen::VectorXd w = forced::find_start(model, o, eq, ao, fr, how);
  ASSERT_NE(how.find("harmonic stepping"), std::string::npos) << how;
  Eigen::VectorXd reference;
  ASSERT_EQ(forced::solve_by_excitation_homotopy(eq, fr, ao, reference).status,
            continuation::BranchStatus::kReachedEnd);
  EXPECT_LT((w - reference).norm(), kSameSolution * reference.norm()) << how;
}

}  // namespace
}  // namespace shroudsim::frf
