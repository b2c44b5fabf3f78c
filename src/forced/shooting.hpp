#pragma once
// Stability of a lumped model's periodic solution by shooting (docs/physics.md section 9,
// "Friction in a lumped model: shooting"): the Floquet multipliers are the eigenvalues of the
// monodromy matrix, the derivative of the period map of the time integration
// (forced/time_march.hpp: the same explicit scheme, the contact law in continuous time with a
// slider per element). The state holds the sliders, so the friction's memory, which the
// harmonic balance's dF/dW does not carry into Hill's method, is part of the linearization.
//
// From a harmonic-balance solution: the state at t = 0 (u, v of every DOF from the harmonics,
// the sliders from the contact force at t = 0) is corrected by Newton on P(z) - z = 0 (the
// integration's own periodic orbit differs from the truncated harmonic balance's), the
// monodromy by forward differences of the period map, then its eigenvalues. A friction slider
// that stays stuck is neutral (multiplier 1: a shifted anchor gives another periodic orbit),
// so the verdict allows kShootingNeutral above 1. Where Newton stalls between the map's pieces
// a short march decides, or the point is left undecided.
#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"
#include "forced/stability.hpp"
#include "forced/time_march.hpp"

namespace shroudsim::forced {

class ReducedEquations;

/// Largest spectral radius of the monodromy counted as stable: a stuck slider's multiplier is 1
/// and its forward differences carry round-off of ~1e-16 / kShootingStep relative, times the
/// monodromy's conditioning, and a coupled slip's curvature times kShootingStep; a fold's
/// multiplier is within this of 1 only very near the fold.
constexpr double kShootingNeutral = 1e-6;
/// Forward-difference step, relative to the state's size (largest |u|, |v| / w, |slider|).
constexpr double kShootingStep = 1e-7;
/// The Newton on the period map stops at this mismatch |P(z) - z| / |z|; an orbit is one
/// where it reaches kShootingMismatch (the explicit scheme's own error over a period at 4096
/// steps is ~1e-6 relative).
constexpr double kShootingTolerance = 1e-10;
constexpr double kShootingMismatch = 1e-6;
/// The monodromy taken at the harmonic-balance state serves the orbit Newton finds within
/// this distance of it (relative to the state's size): exact where both lie on one piece of
/// the map with a linear law, within this where the law curves (a coupled slip).
constexpr double kShootingReuse = 1e-3;
/// Where Newton stalls between the period map's pieces, the motion is marched from the best
/// state for at most kShootingMarchPeriods periods. Settled (one period's change below
/// kShootingMismatch) before going `leaves` away: the orbit it settled on attracts (stable).
/// Left: it went more than `leaves` from where it started, relative to the state's size, with
/// leaves = max(kShootingLeaves, kShootingLeavesFactor x the harmonic-balance state's own
/// mismatch over one period): a stable orbit near the harmonic-balance solution lies about
/// that mismatch / (1 - rho) from it, within the bound for spectral radii up to 0.99 (unstable).
/// Neither: not judged. (On stress model 46, H and N where the harmonic balance is 5 to 20 %
/// from the integration's orbits, a fixed bound of 0.1 called stable solutions unstable.)
constexpr int kShootingMarchPeriods = 50;
constexpr double kShootingLeaves = 0.1;
constexpr double kShootingLeavesFactor = 100.0;

struct ShootingOptions {
  int min_steps_per_period = 4096;
  double steps_per_stiff_period = 32.0;  ///< steps per period of the stuck system's highest mode
  /// A point whose period needs more steps is not analysed (the cost per point is about
  /// (d + 1) x steps x n^2 per monodromy, d the state's size, and one or two monodromies a point).
  long long max_steps_per_period = 1 << 16;
  int max_newton_iterations = 8;

  bool validate(std::vector<std::string>* errors) const;
};

struct ShootingResult {
  bool available = false;
  std::string reason;  ///< why not available
  bool stable = true;
  /// The monodromy's eigenvalues, by decreasing modulus, zero ones included (sliders that slip
  /// forget their anchor); empty when the motion left the solution.
  std::vector<std::complex<double>> multipliers;
  double spectral_radius = 0.0;
  double start_mismatch = 0.0;  ///< |P(z0) - z0| / |z0| at the harmonic-balance state
  double mismatch = 0.0;        ///< the same at the orbit the monodromy is taken on
  int newton_iterations = 0;
  int march_periods = 0;        ///< periods marched where Newton stalled (0: it did not)
  double march_distance = 0.0;  ///< the largest distance from the start state they reached
  bool settled = false;         ///< the march settled on an orbit, where the multipliers were taken
  bool left = false;            ///< the march left the solution: unstable, no multipliers
  int steps_per_period = 0;
  int state_size = 0;  ///< 2 DOFs + one slider per tangential direction of each element

  /// The Floquet exponents log(mu) / T of the nonzero multipliers as a FloquetResult
  /// (stable, max_real = log(spectral radius) / T), for the frf's stability report.
  FloquetResult to_floquet(double frequency_hz) const;
};

/// Shooting from the state (u0, v0, sliders0) at t = 0; sliders0 holds one value per tangential
/// direction of each element (x for the 1d models, x and y otherwise). Throws
/// std::invalid_argument on inconsistent sizes or options.
ShootingResult shooting_floquet(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs,
                                contact::Model model, double frequency_hz, const Eigen::VectorXd& u0,
                                const Eigen::VectorXd& v0, const Eigen::VectorXd& sliders0,
                                const ShootingOptions& options = {});

/// The most state-steps shooting_floquet can take at this frequency (two monodromies of d + 1
/// states and the march), for the work bound.
double shooting_work(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs,
                     contact::Model model, double frequency_hz, const ShootingOptions& options = {});

/// The state at t = 0 of a periodic motion of `system` whose contact elements carry the force
/// harmonics `forces` (F_n, n = 0..H, 3 per element; harmonic 0 without the load the structure
/// already carries): u and v from U_n = (K - (n w)^2 M + i n w C)^-1 (f_n - B^T F_n), with
/// f_1 = force - i force_sin; each slider = relative displacement - tangential force / kt at
/// t = 0 (= the relative displacement where the contact is open).
void periodic_state(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs, contact::Model model,
                    const std::vector<Eigen::VectorXcd>& forces, double frequency_hz, Eigen::VectorXd& u0,
                    Eigen::VectorXd& v0, Eigen::VectorXd& sliders0);

/// periodic_state of the harmonic-balance solution w of `equations`, whose contact elements are
/// `system`'s (a lumped model, or a whole wheel's equations). Not thread-safe (it evaluates the
/// contact forces through `equations`).
void harmonic_balance_state(ReducedEquations& equations, const LumpedSystem& system,
                            const std::vector<contact::PairParameters>& pairs, contact::Model model,
                            const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& u0, Eigen::VectorXd& v0,
                            Eigen::VectorXd& sliders0);

}  // namespace shroudsim::forced
