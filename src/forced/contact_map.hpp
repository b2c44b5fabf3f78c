#pragma once
// What each contact pair does over one period of a forced-response solution: the range of its
// normal load, how far its slider slips, the fractions of the period it sticks, slips and is
// open, and the energy it dissipates per cycle (docs/contract.md, contact_map.csv and
// contact.vtu). Computed from the time samples of the discrete law (contact/periodic_law.hpp)
// at the solution's contact motion.
#include <Eigen/Core>
#include <vector>

#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {

struct PairState {
  double normal_load_min_n = 0.0, normal_load_max_n = 0.0;  ///< over the period [N]
  /// Largest excursion of the slider (damper position d = w_t - T/kt) from its mean over the
  /// period [m]: 0 for a pair that only sticks.
  double slip_amplitude_m = 0.0;
  /// Fractions of the N samples: open (N = 0), slipping (|T| at mu N to 1e-9), stuck (the
  /// rest); they add up to 1.
  double stick_fraction = 0.0, slip_fraction = 0.0, open_fraction = 0.0;
  double energy_per_cycle_j = 0.0;  ///< dissipated by friction per period [J] (>= 0 up to round-off)
};

/// One state per pair of the evaluator at the contact motion w (its layout).
std::vector<PairState> pair_states(hbm::ContactEvaluator& evaluator, const Eigen::VectorXd& w);

}  // namespace shroudsim::forced
