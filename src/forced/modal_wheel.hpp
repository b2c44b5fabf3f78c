#pragma once
// The whole wheel of an FE sector model in modal coordinates, as a lumped system for the time
// integration and the shooting (docs/physics.md section 9, "The FE sector against its whole
// wheel"): an independent reference for the perturbation families of Hill's method, which
// split the same wheel by cyclic symmetry and truncate each at H harmonics.
//
// Coordinates: every mode r kept of every harmonic index g = 0..Nb/2 (the modes of Nb - g are
// those of g conjugated). Sector j moves as
//   x_j = sum_r phi_0r q_0r + sum_{0<g<Nb/2} sum_r 2 Re(phi_gr e^{i j g alpha} (a_gr + i b_gr))
//       + sum_r phi_{Nb/2,r} (-1)^j q_{Nb/2,r},
// so that the wheel's kinetic energy is Nb q^2 / 2 per mode of a real index and
// Nb (a^2 + b^2) per mode of a complex one (mass-normalised sector modes): M = mu I,
// K = mu diag(w_r^2), C = mu diag(2 z w_r), mu = Nb or 2 Nb. Pair i between sectors j and j + 1
// (element j x pairs + i) sees W = sum over the coordinates of Re(kappa P_gr e^{i j g alpha}),
// kappa = 1 (real index), 2 (a) or 2i (b); sector j carries the excitation
// Re(f e^{i j m alpha} e^{i w t}), the engine order's travelling wave, in cosine and sine.
//
// The linear model is the sector's modes and nothing else: compare it with the harmonic balance
// of frf::SectorLinearPart::modes_only() (no residual flexibility, the static harmonic through
// index 0's modes), which has exactly this linear part.
#include <Eigen/Core>
#include <vector>

#include "contact/contact_law.hpp"
#include "forced/time_march.hpp"

namespace shroudsim::frf {
class SectorLinearPart;
}

namespace shroudsim::forced {

class ReducedEquations;

struct ModalWheel {
  LumpedSystem system;
  /// One per contact element: element j x pairs + i is pair i between sectors j and j + 1.
  std::vector<contact::PairParameters> pairs;
  int sectors = 0, engine_order = 0;
  /// Coordinate c: mode `mode` of harmonic index `index` (0..Nb/2), `part` 0 (q, or a of
  /// a + i b) or 1 (b).
  struct Coordinate {
    int index = 0, mode = 0, part = 0;
  };
  /// A mode of a real index (0, Nb/2) is turned by one phase so that it is real.
  std::vector<Coordinate> coordinates;
};

/// The wheel of `sector` (every index 0..Nb/2 must have modes: the case's harmonic_indices =
/// "all") with `pairs` on every sector, the excitation at `excitation_scale` times the model's.
/// Throws std::invalid_argument where an index has no modes or a mode of a real index is not
/// real to 1e-8 (relative) after one turn.
ModalWheel modal_wheel(const frf::SectorLinearPart& sector, const std::vector<contact::PairParameters>& pairs,
                       double excitation_scale = 1.0);

/// The wheel's state at t = 0 of the harmonic-balance solution x of `equations` (whose linear
/// part is `sector`, the one the wheel was built from) at `frequency_hz`: forced::periodic_state
/// of the wheel under the contact force harmonics, every sector's pairs phase-shifted by
/// e^{i j h_n alpha}. Not thread-safe (it evaluates the contact forces through `equations`).
void modal_wheel_state(const ModalWheel& wheel, const frf::SectorLinearPart& sector, ReducedEquations& equations,
                       contact::Model model, const Eigen::VectorXd& x, double frequency_hz, Eigen::VectorXd& u0,
                       Eigen::VectorXd& v0, Eigen::VectorXd& sliders0);

}  // namespace shroudsim::forced
