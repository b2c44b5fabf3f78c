// Nonlinear modes of an FE sector (forced/nonlinear_modes.hpp with frf::SectorLinearPart):
// the sector's damped receptance and second-order form against its own receptance and
// finite differences, and the stuck nonlinear mode against the linear mode of the sector with
// the contact springs.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>

#include "../common/coarse_sector.hpp"
#include "../common/sector_contacts.hpp"
#include "forced/nonlinear_modes.hpp"
#include "forced/reduced_equations.hpp"
#include "forced/stability.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::forced {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
// Products of dense matrices of this size (c = 9, 8 modes) in another order.
constexpr double kRoundOff = 1e-12;
// The EPMC frequency and damping of a damped linear system differ from the undamped mode's
// frequency and phi^H C phi / (2 w) at second order in the damping (D = 1e-3 here): 1e-6.
constexpr double kDampingShift = 1e-6;
// The stuck frequencies of 8 modes with residual flexibility against the full FE model with the
// springs: measured 1.5e-6 (mode 1) and 5e-8 (mode 2).
constexpr double kTruncation = 1e-5;
// A stuck contact's Floquet exponents against the linear mode with the springs: the mode's
// decay zeta/2 = phi^H C phi / 2 is exact only to first order in the damping (D = 1e-3).
constexpr double kStuckExponent = 1e-6;
// The shapes' contact rows against the solution's W: the Newton tolerance (1e-10 of the scaled
// residual) times the receptances' conditioning.
constexpr double kShapeTolerance = 1e-8;

struct Sector : testing_support::CoarseSector {
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;
  std::vector<frf::SectorContactPair> pairs;

  Sector() : CoarseSector("nlsector") {
    modal::ModalOptions mo;
    mo.modes = 8;
    for (int h : {0, 1, 2}) {
      auto r = modal::solve_harmonic(*sector, h, mo);
      bases[h] = r.basis;
      factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*sector, h);
    }
    // Three shroud pairs, the normal roughly circumferential.
    for (std::size_t i = 0; i < 3; ++i) {
      const auto [low, high] = mesh.shroud_pairs[i * 3];
      pairs.push_back(testing_support::circumferential_pair(mesh, low, high));
    }
  }
  /// The cyclic FE sector with the three pairs tied by springs of 2e5 N/m in every direction
  /// (stuck_pairs' stiffnesses, set_interface on all DOFs): the stuck tests' reference.
  std::unique_ptr<cyclic::CyclicSector> tied() const {
    auto out = std::make_unique<cyclic::CyclicSector>(mesh, km);
    std::vector<cyclic::InterfaceSpring> springs;
    for (const auto& p : pairs) springs.push_back({p.high_node, p.low_node, p.frame, Eigen::Vector3d(2e5, 2e5, 2e5)});
    out->set_interface(springs);
    return out;
  }
  frf::SectorLinearPart linear(int harmonics, bool residual = true) const {
    return frf::SectorLinearPart(
        *sector, bases, [&](int h) { return factors.at(h); }, pairs, testing_support::test_forcing(mesh, residual),
        harmonics);
  }
};

const Sector& sector() {
  static const Sector s;
  return s;
}

TEST(SectorNonlinearModes, DampedReceptanceIsTheReceptanceAndItsDerivativesMatchFiniteDifferences) {
  const Sector& f = sector();
  const frf::SectorLinearPart part = f.linear(2);
  const double w = 0.8 * f.bases.at(1).omega[0], zeta = 0.3;
  // At zeta = 0 the damped receptance is the harmonic balance's (G and H), and the second-order
  // form gives it at s = i n w.
  for (int n : {0, 1, 2}) {
    frf::HarmonicReceptance hr;
    frf::DampedReceptance dr;
    frf::SecondOrderForm so;
    part.harmonic(n, w, hr);
    ASSERT_TRUE(part.damped_harmonic(n, w, 0.0, n == 1, dr));
    ASSERT_TRUE(part.second_order_form(n, so));
    EXPECT_LT((dr.G - hr.G).norm(), kRoundOff * hr.G.norm()) << n;
    EXPECT_LT((dr.H - hr.H).norm(), kRoundOff * hr.H.norm()) << n;
    const double big_w = n * w;
    const Eigen::MatrixXcd dyn =
        so.K.cast<Complex>() - big_w * big_w * so.M.cast<Complex>() + Complex(0, big_w) * so.C.cast<Complex>();
    const Eigen::MatrixXcd g = (so.M.rows() ? Eigen::MatrixXcd(so.P * dyn.inverse() * so.P.adjoint())
                                            : Eigen::MatrixXcd::Zero(hr.G.rows(), hr.G.cols())) +
                               so.R;
    EXPECT_LT((g - hr.G).norm(), kRoundOff * hr.G.norm()) << n;
  }
  // N = X^H M X over the modes: q^H q of the modal coordinates of a unit force on each contact
  // row, recomputed from the modes (psi_c = B T phi) rather than from the part.
  {
    frf::DampedReceptance dr;
    ASSERT_TRUE(part.damped_harmonic(1, w, zeta, true, dr));
    const modal::ModalBasis& b = f.bases.at(1);
    const Eigen::MatrixXcd psi =
        frf::contact_rows(f.pairs, *f.sector, 1, f.sector->n_full()) * f.sector->expansion(1) * b.phi;
    Eigen::VectorXcd inv(b.omega.size());
    for (Eigen::Index r = 0; r < inv.size(); ++r)
      inv[r] = 1.0 / Complex(b.omega[r] * b.omega[r] - w * w, w * (2.0 * 1e-3 * b.omega[r] - zeta));
    const Eigen::MatrixXcd eta = inv.asDiagonal() * psi.adjoint();  // modal motion per unit force
    EXPECT_LT((dr.N - eta.adjoint() * eta).norm(), kRoundOff * dr.N.norm());
  }
  // Central differences: truncation O(h^2) ~ 1e-12 relative at h = 1e-6 relative, round-off
  // ~ 1e-16 / 1e-6 = 1e-10: the derivatives must agree to 1e-7.
  constexpr double kFdTolerance = 1e-7;
  const double hw = 1e-6 * w, hz = 1e-6 * w;
  for (int n : {1, 2}) {
    frf::DampedReceptance r, rp, rm;
    ASSERT_TRUE(part.damped_harmonic(n, w, zeta, true, r));
    ASSERT_TRUE(part.damped_harmonic(n, w + hw, zeta, true, rp));
    ASSERT_TRUE(part.damped_harmonic(n, w - hw, zeta, true, rm));
    EXPECT_LT(((rp.G - rm.G) / (2 * hw) - r.dG_dw).norm(), kFdTolerance * r.dG_dw.norm()) << n;
    if (n == 1) {
      EXPECT_LT(((rp.N - rm.N) / (2 * hw) - r.dN_dw).norm(), kFdTolerance * r.dN_dw.norm());
    }
    ASSERT_TRUE(part.damped_harmonic(n, w, zeta + hz, true, rp));
    ASSERT_TRUE(part.damped_harmonic(n, w, zeta - hz, true, rm));
    EXPECT_LT(((rp.G - rm.G) / (2 * hz) - r.dG_dzeta).norm(), kFdTolerance * r.dG_dzeta.norm()) << n;
    if (n == 1) {
      EXPECT_LT(((rp.N - rm.N) / (2 * hz) - r.dN_dzeta).norm(), kFdTolerance * r.dN_dzeta.norm());
    }
  }
}

/// Stuck, closed contacts (huge friction and preload carried by the static state) on the three
/// pairs: kt = kn = 2e5 N/m.
std::vector<contact::PairParameters> stuck_pairs() {
  std::vector<contact::PairParameters> pairs(3);
  for (auto& p : pairs) {
    p.tangential_stiffness = 2e5;
    p.normal_stiffness = 2e5;
    p.friction_coefficient = 1e3;  // never slips
    p.normal_preload = 1e3;        // never opens
    p.preload_in_equilibrium = true;
  }
  return pairs;
}

hbm::ContactEvaluatorOptions options(int h, int n) {
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.threads = 1;
  o.measure_plans = false;
  return o;
}

/// The friction mode both energy and shape tests follow: mu = 0.3, a 2 N preload on each of the
/// three pairs, H = 2, N = 64, from a modal amplitude of 1e-7 to 1e-3 (stick, slip, lift-off).
struct FrictionMode {
  static constexpr int kHarmonics = 2;
  frf::SectorLinearPart part;
  hbm::ContactEvaluator ev;
  NonlinearModeCurve curve;
  static std::vector<contact::PairParameters> pairs() {
    std::vector<contact::PairParameters> out = stuck_pairs();
    for (auto& p : out) p.friction_coefficient = 0.3, p.normal_preload = 2.0;
    return out;
  }
  static NonlinearModeSettings settings() {
    NonlinearModeSettings s;
    s.amplitude_start = 1e-7;
    s.amplitude_end = 1e-3;
    return s;
  }
  explicit FrictionMode(const Sector& f)
      : part(f.linear(kHarmonics)),
        ev(options(kHarmonics, 64), pairs()),
        curve(trace_nonlinear_mode(part, ev, settings())) {}
};

TEST(SectorNonlinearModes, StuckModeIsTheSectorsModeWithTheContactSprings) {
  // Independent: the modes of the sector with the three pairs tied by springs in the cyclic
  // FE model itself (cyclic::CyclicSector::set_interface, all DOFs), against the EPMC of the
  // modal model (8 modes + residual flexibility) with stuck contacts.
  const Sector& f = sector();
  const frf::SectorLinearPart part = f.linear(2);
  hbm::ContactEvaluator ev(options(2, 16), stuck_pairs());
  const std::unique_ptr<cyclic::CyclicSector> tied = f.tied();
  modal::ModalOptions mo;
  mo.modes = 4;
  const modal::ModalBasis exact = modal::solve_harmonic(*tied, 1, mo).basis;
  for (int mode : {1, 2}) {
    NonlinearModeSettings s;
    s.mode = mode;
    s.amplitude_start = 1e-6;
    s.amplitude_end = 1e-5;
    const NonlinearModeCurve curve = trace_nonlinear_mode(part, ev, s);
    ASSERT_TRUE(curve.reached_end) << curve.message;
    EXPECT_NEAR(curve.linear.omega / exact.omega[mode - 1], 1.0, kTruncation);
    for (const auto& p : curve.points) {
      EXPECT_NEAR(p.omega / curve.linear.omega, 1.0, kDampingShift);
      EXPECT_NEAR(p.damping_ratio / (curve.linear.zeta / (2 * curve.linear.omega)), 1.0, kDampingShift);
      EXPECT_LE(p.contact_dissipation, 1e-12 * p.omega * p.omega * p.amplitude * p.amplitude);
    }
  }
}

TEST(SectorStability, StuckContactsGiveTheDampedModesOfTheTiedSectorInEveryFamily) {
  // With stuck contacts the exponents of perturbation family p are the damped modes of the tied
  // sector's harmonic index p: lambda = -zeta_j / 2 +- i w_j on block 0, once (their copies
  // shifted by i k w belong to family p + k m). Independent references: the frequencies of the
  // cyclic FE sector with the three pairs tied by springs (set_interface, all DOFs), and the
  // decay phi^H C phi / 2 of the tied mode of the modal form itself (8 modes, residual
  // flexibility condensed). With the modes of indices 0..Nb/2 every family is analysed; with
  // those of the harmonic balance's h_n only (1 and 2 here, engine order 1), none is complete.
  const Sector& f = sector();
  const int harmonics = 2, nb = f.sector->sectors();
  std::map<int, modal::ModalBasis> bases;
  std::map<int, modal::StiffnessFactor> factors;
  modal::ModalOptions mo;
  mo.modes = 8;
  for (int h = 0; h <= nb / 2; ++h) {
    auto r = modal::solve_harmonic(*f.sector, h, mo);
    bases[h] = r.basis;
    factors[h] = r.stiffness.valid() ? r.stiffness : modal::factor_harmonic_stiffness(*f.sector, h);
  }
  auto part_with = [&](const std::map<int, modal::ModalBasis>& b) {
    return frf::SectorLinearPart(
        *f.sector, b, [&](int h) { return factors.at(h); }, f.pairs, testing_support::test_forcing(f.mesh, true),
        harmonics);
  };
  hbm::ContactEvaluator ev(options(harmonics, 16), stuck_pairs());
  const double hz = 0.6 * bases.at(1).omega[0] / (2 * kPi), omega = 2 * kPi * hz;
  {
    std::map<int, modal::ModalBasis> forced_only = {{1, bases.at(1)}, {2, bases.at(2)}};
    const frf::SectorLinearPart part = part_with(forced_only);
    ReducedEquations eq(part, ev);
    const FloquetResult r = floquet_exponents(eq, eq.stuck_solution(hz), hz);
    EXPECT_FALSE(r.available);
    EXPECT_NE(r.reason.find("index 0"), std::string::npos) << r.reason;
  }
  const frf::SectorLinearPart part = part_with(bases);
  ReducedEquations eq(part, ev);
  const Eigen::VectorXd stuck = eq.stuck_solution(hz);
  // Every mode kept (mode_cutoff 0): the exponents are the tied modes'. With the default cutoff
  // (kModeCutoff (H + 1) w = 3.6 w_1 here) the modes above it enter frozen at s = i k w, exact
  // at lambda = 0 only: the exponents of the modes kept move by kFrozenModes at most.
  const FloquetResult r = floquet_exponents(eq, stuck, hz, ExponentSelection::symmetry, kMaxHillSize, 0.0);
  const FloquetResult cut = floquet_exponents(eq, stuck, hz);
  ASSERT_TRUE(r.available) << r.reason;
  ASSERT_TRUE(cut.available) << cut.reason;
  ASSERT_EQ(r.families.size(), static_cast<std::size_t>(nb / 2 + 1));
  EXPECT_TRUE(r.stable);
  EXPECT_TRUE(cut.stable);
  const std::unique_ptr<cyclic::CyclicSector> tied = f.tied();
  modal::ModalOptions four;
  four.modes = 4;
  for (int p = 0; p <= nb / 2; ++p) {
    const modal::ModalBasis exact = modal::solve_harmonic(*tied, p, four).basis;
    // The modal form's own tied modes: K + P^H K_c (I + R K_c)^-1 P with K_c = 2e5 I.
    frf::SecondOrderForm so;
    ASSERT_TRUE(part.perturbation_form(p, 0, omega, 0.0, so));
    const Eigen::Index c = so.P.rows();
    const Eigen::MatrixXcd kc = 2e5 * Eigen::MatrixXcd::Identity(c, c);
    const Eigen::MatrixXcd stiff =
        so.K.cast<Complex>() +
        so.P.adjoint() * kc * (Eigen::MatrixXcd::Identity(c, c) + so.R * kc).partialPivLu().solve(so.P);
    const Eigen::ComplexEigenSolver<Eigen::MatrixXcd> tied_modal(stiff);
    for (int mode = 0; mode < 2; ++mode) {
      const double wj = exact.omega[mode];
      // The modal form's mode nearest the FE one: its decay phi^H C phi / 2 (phi^H phi = 1).
      Eigen::Index best = 0;
      for (Eigen::Index j = 1; j < tied_modal.eigenvalues().size(); ++j)
        if (std::abs(std::sqrt(tied_modal.eigenvalues()[j]).real() - wj) <
            std::abs(std::sqrt(tied_modal.eigenvalues()[best]).real() - wj))
          best = j;
      const Eigen::VectorXcd phi = tied_modal.eigenvectors().col(best).normalized();
      const double decay = (phi.adjoint() * so.C.cast<Complex>() * phi)(0, 0).real() / 2;
      bool found = false;
      for (std::size_t e = 0; e < r.exponents.size(); ++e)
        found = found ||
                (r.exponent_family[e] == p && std::abs(std::abs(r.exponents[e].imag()) - wj) <= kTruncation * wj &&
                 std::abs(r.exponents[e].real() + decay) <= kStuckExponent * wj);
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t e = 0; e < cut.exponents.size(); ++e)
        if (cut.exponent_family[e] == p && cut.exponents[e].imag() > 0)
          nearest = std::min(nearest, std::abs(cut.exponents[e] - Complex(-decay, wj)) / wj);
      std::printf("index %d mode %d: %.6g rad/s, with the cutoff %.2e\n", p, mode + 1, wj, nearest);
      EXPECT_TRUE(found) << "index " << p << ", mode " << mode + 1 << " at " << wj << " rad/s, decay " << decay;
    }
  }
}

TEST(SectorNonlinearModes, FrictionModeBalancesItsEnergyPerCycle) {
  // Over one period the artificial damping supplies what the modal damping and the contacts
  // dissipate: pi w zeta sum_n n^2 |eta_n|^2 = pi w sum_n n^2 sum_r 2 z w_r |eta_n,r|^2 + E_c,
  // with the modal motions eta_n = -diag(1/den) psi_c^H F_n recomputed here from the modes
  // (psi_c = B T phi) and the solution's contact forces; the residual part is massless.
  const Sector& f = sector();
  const int harmonics = FrictionMode::kHarmonics;
  FrictionMode mode(f);
  const NonlinearModeCurve& curve = mode.curve;
  ASSERT_TRUE(curve.reached_end) << curve.message;
  hbm::ContactEvaluator& ev = mode.ev;
  NonlinearModeEquations eq(mode.part, ev);
  double worst = 0.0, d_max = 0.0;
  for (const auto& p : curve.points) {
    Eigen::VectorXd force;
    ev.evaluate(p.w, force, nullptr);
    double supplied = 0.0, viscous = 0.0;
    for (int n = 1; n <= harmonics; ++n) {
      const modal::ModalBasis& b = f.bases.at(n);
      const Eigen::MatrixXcd psi =
          frf::contact_rows(f.pairs, *f.sector, n, f.sector->n_full()) * f.sector->expansion(n) * b.phi;
      const Eigen::VectorXcd load = psi.adjoint() * eq.complex_harmonic(force, n);
      const double big_w = n * p.omega;
      for (Eigen::Index r = 0; r < b.omega.size(); ++r) {
        const double wr = b.omega[r];
        const double eta2 = std::norm(load[r] / Complex(wr * wr - big_w * big_w, big_w * (2e-3 * wr - p.zeta)));
        supplied += kPi * p.omega * p.zeta * n * n * eta2;
        viscous += kPi * p.omega * n * n * 2e-3 * wr * eta2;
      }
    }
    worst = std::max(worst, std::abs(supplied - viscous - p.contact_dissipation) / supplied);
    d_max = std::max(d_max, p.damping_ratio);
  }
  std::printf("sector mode 1: %.4f -> %.4f Hz, D %.2e -> max %.2e over %zu points; worst energy balance %.2e\n",
              curve.points.front().frequency_hz, curve.points.back().frequency_hz, curve.points.front().damping_ratio,
              d_max, curve.points.size(), worst);
  // An identity of the converged equations, to the Newton tolerance times the receptances'
  // conditioning (as for the lumped models).
  constexpr double kEnergyBalance = 1e-6;
  EXPECT_LT(worst, kEnergyBalance);
  EXPECT_GT(d_max, 2 * curve.points.front().damping_ratio);
  EXPECT_LT(curve.points.back().frequency_hz, curve.points.front().frequency_hz);  // softening in slip
}

TEST(SectorNonlinearModes, ModeShapesCarryTheModesContactMotion) {
  // The shapes nlmodes writes (frf::sector_displacements without excitation, with -zeta M):
  // their contact rows B_h U_n are the solution's contact motion W_n, at every point kind.
  const Sector& f = sector();
  const int harmonics = FrictionMode::kHarmonics;
  FrictionMode mode(f);
  const NonlinearModeCurve& curve = mode.curve;
  ASSERT_TRUE(curve.reached_end) << curve.message;
  hbm::ContactEvaluator& ev = mode.ev;
  NonlinearModeEquations eq(mode.part, ev);
  std::vector<frf::ShapeLoad> loads;
  const std::vector<std::size_t> at = {0, curve.points.size() / 2, curve.points.size() - 1};
  for (std::size_t i : at) {
    Eigen::VectorXd force;
    ev.evaluate(curve.points[i].w, force, nullptr);
    frf::ShapeLoad load;
    load.w = curve.points[i].omega;
    load.zeta = curve.points[i].zeta;
    load.excitation = false;
    for (int n = 0; n <= harmonics; ++n)  // harmonic 0 about the static state (F_0 - F_s)
      load.forces.push_back(n == 0 ? Eigen::VectorXcd(eq.complex_harmonic(force, 0) - ev.static_load())
                                   : eq.complex_harmonic(force, n));
    loads.push_back(load);
  }
  const auto u = frf::sector_displacements(
      *f.sector, f.bases, [&](int h) { return f.factors.at(h); }, f.pairs, testing_support::test_forcing(f.mesh, true),
      loads);
  for (std::size_t l = 0; l < at.size(); ++l)
    for (int n = 0; n <= harmonics; ++n) {
      const Eigen::VectorXcd w = frf::contact_rows(f.pairs, *f.sector, n, f.sector->n_full()) * u[l][n];
      const Eigen::VectorXcd expected = eq.complex_harmonic(curve.points[at[l]].w, n);
      EXPECT_LT((w - expected).norm(), kShapeTolerance * std::max(expected.norm(), curve.points[at[l]].w.norm()))
          << "point " << at[l] << ", harmonic " << n;
    }
}

}  // namespace
}  // namespace shroudsim::forced
