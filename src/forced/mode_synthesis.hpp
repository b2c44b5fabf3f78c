#pragma once
// Single-nonlinear-mode synthesis of the forced response (docs/physics.md section 10): near
// the resonance of one mode, the forced motion is taken as that nonlinear mode at modal
// amplitude a, driven by the modal force p(a) = psi(a)^H f (psi = q_1 / a, unit modal mass).
// Two forms of the modal equation at excitation frequency W:
//   viscous (Krack 2015):  (w^2 - W^2 + 2 i D w W) a = p
//       all of the mode's damping taken as viscous (proportional to W);
//   mixed (the default):   (w^2 - W^2 + 2 i D_v w W + 2 i D_c w^2) a = p,  D_v = D - D_c
//       the contacts' share D_c = E_contact / (2 pi w^2 a^2) taken as hysteretic (friction
//       dissipates per cycle by amplitude, not by rate), the rest viscous. For a 1-DOF model
//       at H = 1 this is exactly the harmonic balance of the forced system at amplitude a
//       (m (w^2 - W^2) a + i c (W - w) a + i zeta w m a = f, zeta m - c = 2 D_c w m);
//       the viscous form differs from it by i (W - w)(c - zeta m) a, which at a friction
//       damping of 10 % moves the peak down by D^2 in frequency (1 %).
// For each a of a nonlinear-mode curve the frequencies W solve |den(W)| = s |p| / a: two
// (below and above the backbone) while s |p| / a >= min_W |den(W)|, none beyond; the peak is
// where that holds with equality (located by bisection in log a with w, D, D_c, |p| and the
// response interpolated linearly in log a between the mode's points). The response at the
// response DOFs is a times the mode's max_t |u(t)| per unit modal amplitude. Any excitation
// level s (f -> s f) is one pass over the curve: microseconds per curve.
//
// Usage:
//   const auto curve = forced::synthesize(mode.points, /*scale=*/2.0);
//   const forced::SynthesisPeak peak = forced::synthesis_peak(mode.points, 2.0);
#include <vector>

#include "forced/nonlinear_modes.hpp"

namespace shroudsim::forced {

enum class SynthesisDamping { mixed, viscous };

struct SynthesisPoint {
  double frequency_hz = 0.0;
  double amplitude = 0.0;        ///< max_t |u_resp(t)| [m]
  double modal_amplitude = 0.0;  ///< a
  bool above_backbone = false;   ///< the upper root
};

struct SynthesisPeak {
  bool found = false;  ///< false: the curve does not reach the peak (amplitude range too small)
  double frequency_hz = 0.0;
  double amplitude = 0.0;  ///< max_t |u_resp(t)| [m]
  double modal_amplitude = 0.0;
};

/// The synthesized response curve at excitation scale s in branch order: the lower root for
/// increasing a up to the peak (it may lean back in frequency: softening), the peak itself,
/// then the upper root back down. Stops at the peak when the mode's curve reaches it, else at its end.
std::vector<SynthesisPoint> synthesize(const std::vector<NonlinearModePoint>& mode, double scale,
                                       SynthesisDamping damping = SynthesisDamping::mixed);
/// The peak of that curve.
SynthesisPeak synthesis_peak(const std::vector<NonlinearModePoint>& mode, double scale,
                             SynthesisDamping damping = SynthesisDamping::mixed);

}  // namespace shroudsim::forced
