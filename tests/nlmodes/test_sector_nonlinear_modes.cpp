// Nonlinear modes of an FE sector (forced/nonlinear_modes.hpp with frf::SectorLinearPart):
// the sector's damped receptance and second-order form against its own receptance and
// finite differences, and the stuck nonlinear mode against the linear mode of the sector with
// the contact springs.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <iostream>
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

TEST(SectorNonlinearModes, StuckModeIsTheSectorsModeWithTheContactSprings) {
  // Independent: the modes of the sector with the three pairs tied by springs in the cyclic
  // FE model itself (cyclic::CyclicSector::set_interface, all DOFs), against the EPMC of the
  // modal model (8 modes + residual flexibility) with stuck contacts.
  const Sector& f = sector();
  const frf::SectorLinearPart part = f.linear(2);
  hbm::ContactEvaluator ev(options(2, 16), stuck_pairs());
  cyclic::CyclicSector tied(f.mesh, f.km);
  std::vector<cyclic::InterfaceSpring> springs;
  for (const auto& p : f.pairs) springs.push_back({p.high_node, p.low_node, p.frame, Eigen::Vector3d(2e5, 2e5, 2e5)});
  tied.set_interface(springs);
  modal::ModalOptions mo;
  mo.modes = 4;
  const modal::ModalBasis exact = modal::solve_harmonic(tied, 1, mo).basis;
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

TEST(SectorStability, StuckContactsGiveTheDampedModesOfTheTiedSector) {
  // With stuck contacts the exponents are those of the tied sector's damped modes. A mode of
  // harmonic index h_1 lives in the blocks k = +-1; its copies shifted by k w would lie in
  // blocks of other indices and do not exist, so its exponent is -zeta/2 +- i (w_j - w), once.
  // Without the modes of index 0 (block 0 massless) the "imaginary" selection keeps it; the
  // pipeline does not analyse sectors yet (the centroid selection would not judge it).
  const Sector& f = sector();
  const int harmonics = 2;
  std::map<int, modal::ModalBasis> no_index_0 = f.bases;
  no_index_0.erase(0);
  const frf::SectorLinearPart part(
      *f.sector, no_index_0, [&](int h) { return f.factors.at(h); }, f.pairs,
      testing_support::test_forcing(f.mesh, true), harmonics);
  hbm::ContactEvaluator ev(options(harmonics, 16), stuck_pairs());
  const double hz = 0.6 * f.bases.at(1).omega[0] / (2 * kPi), omega = 2 * kPi * hz;
  ReducedEquations eq(part, ev);
  const Eigen::VectorXd w = eq.stuck_solution(hz);
  EXPECT_FALSE(floquet_exponents(eq, w, hz).available);
  const FloquetResult r = floquet_exponents(eq, w, hz, ExponentSelection::symmetry, kMaxHillSize, true);
  ASSERT_TRUE(r.available) << r.reason;
  EXPECT_EQ(r.selection, ExponentSelection::imaginary);
  EXPECT_TRUE(r.stable);
  for (int mode : {1, 2}) {
    const LinearMode m = linear_mode(part, ev, mode);
    bool found = false;
    for (const auto& e : r.exponents)
      found = found || (std::abs(std::abs(e.imag()) - std::abs(m.omega - omega)) <= kStuckExponent * m.omega &&
                        std::abs(e.real() + m.zeta / 2) <= kStuckExponent * m.omega);
    EXPECT_TRUE(found) << "mode " << mode << " at " << m.omega << " rad/s, zeta " << m.zeta << ", w " << omega;
  }
}

TEST(SectorNonlinearModes, FrictionModeBalancesItsEnergyPerCycle) {
  // Over one period the artificial damping supplies what the modal damping and the contacts
  // dissipate: pi w zeta sum_n n^2 |eta_n|^2 = pi w sum_n n^2 sum_r 2 z w_r |eta_n,r|^2 + E_c,
  // with the modal motions eta_n = -diag(1/den) psi_c^H F_n recomputed here from the modes
  // (psi_c = B T phi) and the solution's contact forces; the residual part is massless.
  const Sector& f = sector();
  const int harmonics = 2;
  const frf::SectorLinearPart part = f.linear(harmonics);
  std::vector<contact::PairParameters> pairs = stuck_pairs();
  for (auto& p : pairs) p.friction_coefficient = 0.3, p.normal_preload = 2.0;
  hbm::ContactEvaluator ev(options(harmonics, 64), pairs);
  NonlinearModeSettings s;
  s.amplitude_start = 1e-7;
  s.amplitude_end = 1e-3;
  const NonlinearModeCurve curve = trace_nonlinear_mode(part, ev, s);
  ASSERT_TRUE(curve.reached_end) << curve.message;
  NonlinearModeEquations eq(part, ev);
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
  const int harmonics = 2;
  const frf::SectorLinearPart part = f.linear(harmonics);
  std::vector<contact::PairParameters> pairs = stuck_pairs();
  for (auto& p : pairs) p.friction_coefficient = 0.3, p.normal_preload = 2.0;
  hbm::ContactEvaluator ev(options(harmonics, 64), pairs);
  NonlinearModeSettings s;
  s.amplitude_start = 1e-7;
  s.amplitude_end = 1e-3;
  const NonlinearModeCurve curve = trace_nonlinear_mode(part, ev, s);
  ASSERT_TRUE(curve.reached_end) << curve.message;
  NonlinearModeEquations eq(part, ev);
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
