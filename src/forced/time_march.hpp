#pragma once
// Direct time integration of a lumped model with its contact elements (docs/continuation.md,
// "Time integration"): M u'' + C u' + K u + B^T (F(B u) - F_s) = f cos(w t), the contact law
// of docs/physics.md section 4 in continuous time (a slider per pair, Coulomb friction limited
// by the normal load max(0, N0 + kn z), separation), marched from rest until the motion
// repeats. It is independent of the harmonic balance (no Fourier series, no sampled period,
// no Newton), so it tells whether a periodic motion exists at a frequency, and when one does,
// its contact motion is a start for the harmonic balance where the start search fails.
//
// Scheme: explicit Newmark (central differences in u, the damping taken at mid-step, which is
// second order), with at least `min_steps_per_period` steps per excitation period and
// `steps_per_stiff_period` per period of the highest natural frequency of the structure with
// every contact stuck (the scheme is stable below two radians per step). After each period
// the state (u, v / w, sliders) is compared with the states 1..max_period_multiple periods
// before; the motion is periodic with the smallest multiple p whose relative change stays
// below `periodicity_tolerance` for three periods in a row.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"

namespace shroudsim::frf {
class LumpedLinearPart;
}

namespace shroudsim::forced {

/// The lumped equations of motion: f(t) = force cos(w t) + force_sin sin(w t) (force_sin
/// empty: none; a travelling wave on a whole wheel needs both); contact_operator B (3 rows per
/// contact element: x, y, z of its frame, docs/physics.md section 3).
struct LumpedSystem {
  Eigen::MatrixXd mass, damping, stiffness, contact_operator;
  Eigen::VectorXd force, force_sin;

  /// force_sin, or zeros of force's size where it is empty.
  Eigen::VectorXd sine_force() const { return force_sin.size() == 0 ? Eigen::VectorXd::Zero(force.size()) : force_sin; }
  /// Sizes of M, C, K, f (and f_sin when given) n x n and n, B (3 elements) x n.
  bool consistent(Eigen::Index elements) const;
};

/// The equations of motion of a lumped linear part (its M, C, K, B and excitation).
LumpedSystem lumped_system(const frf::LumpedLinearPart& lumped);

struct TimeMarchOptions {
  int min_steps_per_period = 4096;
  double steps_per_stiff_period = 32.0;  ///< steps per period of the stuck system's highest mode
  int max_periods = 20000;
  long long max_steps = 100'000'000;  ///< bound on the work (about a minute for 6 DOFs)
  int max_period_multiple = 8;        ///< subharmonic motions up to this many excitation periods
  double periodicity_tolerance = 1e-9;
  /// Contact motion output: this many samples per period (the harmonic balance's N).
  int output_samples = 256;

  /// Appends one message per violated constraint; true when valid.
  bool validate(std::vector<std::string>* errors) const;
};

struct TimeMarchResult {
  enum class Motion { periodic, subharmonic, not_settled, not_applicable };
  Motion motion = Motion::not_settled;
  int period_multiple = 0;  ///< periodic: 1; subharmonic: p > 1; otherwise 0
  int periods = 0;          ///< excitation periods marched
  int steps_per_period = 0;
  double mismatch = 0.0;           ///< smallest relative change over 1..max_period_multiple periods, last period
  double change_one_period = 0.0;  ///< relative change over the last period
  std::string reason;              ///< not_applicable: why
  /// Contact motion B u over the last excitation period (3 rows per element, output_samples
  /// columns at t = k T + j T / output_samples).
  Eigen::MatrixXd contact_motion;
  Eigen::VectorXd displacement, velocity;  ///< at the end (a period boundary)

  /// "periodic after 312 periods", "subharmonic (3 excitation periods) after ...", ...
  std::string describe() const;
};

/// The highest natural circular frequency [rad/s] of the structure with every contact stuck
/// (springs kt, kt, kn; kt only for the 1d models): the explicit scheme's step bound. The mass
/// must be positive definite.
double stuck_highest_circular_frequency(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs,
                                        contact::Model model);

/// Marches from rest (u = 0, v = 0, sliders at 0) at frequency f [Hz]. Throws
/// std::invalid_argument for inconsistent sizes or invalid options.
TimeMarchResult march_to_steady_state(const LumpedSystem& system, const std::vector<contact::PairParameters>& pairs,
                                      contact::Model model, double frequency_hz, const TimeMarchOptions& options);

/// march_to_steady_state, remembered for the process: a call with the same inputs (every
/// byte of system, pairs, law, frequency and options) returns the earlier result (*reused set
/// true when given) instead of marching again (up to a minute at 20,000 periods). The start
/// search marches where the harmonic balance finds no start, and the attempts with a raised
/// N (hbm.raise_time_samples) ask again at the same frequencies. Thread-safe; the last
/// kMarchCacheEntries results are kept.
constexpr std::size_t kMarchCacheEntries = 64;
TimeMarchResult march_to_steady_state_cached(const LumpedSystem& system,
                                             const std::vector<contact::PairParameters>& pairs, contact::Model law,
                                             double frequency_hz, const TimeMarchOptions& options,
                                             bool* reused = nullptr);

/// Real Fourier coefficients [c0 | c1 s1 | ... | cH sH] per row of `samples` (equally spaced
/// over one period), in the contact evaluator's layout (pairs one after the other, each with
/// the first `n_directions` of its rows x, y, z): the harmonic-balance unknowns W.
Eigen::VectorXd harmonic_unknowns(const Eigen::MatrixXd& samples, int n_harmonics, int n_directions);

}  // namespace shroudsim::forced
