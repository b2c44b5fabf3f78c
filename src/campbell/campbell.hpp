#pragma once
// The Campbell diagram of a cyclic sector (docs/physics.md section 1; the command is
// `shroudsim campbell`, docs/contract.md).
//
// Speeds s_i [rpm], i = 0..n-1, evenly spaced over [s0, s1]. At each speed,
// Omega = 2 pi s / 60 [rad/s], the modes of harmonic index h are those of
//     (K_h + Omega^2 D_h) phi = w^2 M_h phi,   D_h = T_h^H (K_sigma1 - M_spin) T_h
// (centrifugal stiffening at unit Omega^2 and spin softening; Coriolis neglected;
// modal/rotating.hpp). With the shroud contact followed (modal.shroud = "contact"), the
// pairs the static shroud contact closes at each speed are tied by their springs and the
// others are free (docs/physics.md section 8); the static contact is carried from speed to
// speed in increasing order (its friction state is path dependent).
//
// Engine order e excites harmonic index h = e mod Nb (nodal diameter min(h, Nb - h)). A
// crossing of mode r is where g(s) = f_r(s) - e s / 60 changes sign between two speed points
// (or is zero at one): s by linear interpolation of g, f = e s / 60 on the line. With
// frequencies independent of speed this is exactly s = 60 f_r / e. Modes are numbered by
// frequency at each speed, so where two families cross the numbering swaps.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "cyclic/cyclic_sector.hpp"
#include "frf/static_shroud.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::campbell {

/// n >= 2 speeds evenly spaced over [s0, s1] (the last is exactly s1).
std::vector<double> speed_points(double s0, double s1, int n);

/// The static shroud contact at every speed of a sweep.
struct ShroudStates {
  std::vector<cyclic::InterfaceSpring> springs;  ///< one per matched pair, the solver's order
  std::vector<std::vector<bool>> closed;         ///< per solved speed: which springs are closed
  std::vector<int> slipping;                     ///< per solved speed: pairs in slip
  std::vector<double> normal_load_n;             ///< per solved speed: total normal load [N]
  std::string failure;                           ///< why the sweep stopped ("" when every speed was solved)
  int solved() const { return static_cast<int>(closed.size()); }
};

/// Steps `solver` (at rest on entry) through the speeds rpm (increasing); when rpm[0] > 0, first
/// `increments` steps of Omega^2 up to it. Stops at the first speed whose contact fails
/// (ShroudStates::failure; the speeds before it are kept).
ShroudStates shroud_states(frf::StaticShroudSolver& solver, const std::vector<double>& rpm, int increments);

/// The frequencies [Hz] of one harmonic index at each speed of the sweep.
struct HarmonicSweep {
  std::vector<Eigen::VectorXd> f;  ///< per speed (empty vector: not solved)
  std::string failure;             ///< first failure (the later speeds are not solved)
  double seconds = 0.0;            ///< solves only
  double factor_seconds = 0.0, lanczos_seconds = 0.0;
  int solves = 0;
  int analyses = 0;  ///< symbolic analyses of K_h + Omega^2 D_h (1 when reused)
};

/// The rotating sweep of harmonic index h: `sector` the cyclic reduction of {K, M} (its
/// springs included), `rotating` that of {K_sigma1, M_spin}. at_rest: the modes' frequencies at
/// rest, used for speed 0 (unless the contact is followed). states: null, or the shroud contact
/// per speed (then `sector` is the open one). A failure names h, the speed and, when the lowest
/// mode is falling, where f^2 extrapolates to zero (a divergence).
HarmonicSweep sweep_harmonic(const cyclic::CyclicSector& sector, const cyclic::CyclicSector& rotating, int h,
                             const std::vector<double>& rpm, const modal::ModalOptions& options,
                             const Eigen::VectorXd& at_rest, const ShroudStates* states);

struct Crossing {
  int engine_order = 0;
  double speed_rpm = 0.0;
  int nodal_diameter = 0;
  int mode = 0;  ///< numbered from 1 at each speed
  double frequency_hz = 0.0;
  bool operator<(const Crossing& o) const;  ///< by engine order, speed, ND, mode, frequency
};

/// Crossings of the engine-order lines with the modes. sweeps: per canonical harmonic index
/// min(h, Nb - h); an engine order whose canonical index has no sweep is skipped; a sweep with
/// a missing speed counts up to the first missing one. Sorted.
std::vector<Crossing> crossings(const std::vector<double>& rpm, const std::map<int, HarmonicSweep>& sweeps,
                                const std::vector<int>& engine_orders, int sectors);

}  // namespace shroudsim::campbell
