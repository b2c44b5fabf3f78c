#pragma once
// The nonlinear-mode stage of a case (`shroudsim nlmodes`): the lumped model of the case
// (forced_model.hpp) with its contact elements, the nonlinear mode [nlmodes].mode traced by
// the extended periodic motion concept from nlmodes.amplitude_start to amplitude_end
// (forced/nonlinear_modes.hpp) with the case's H, N, contact model and Jacobian, and the
// forced responses synthesized from it at the excitation levels nlmodes.synthesis_scales
// (forced/mode_synthesis.hpp, the mixed damping form).
//
// Result files (docs/contract.md): nlmodes.csv (one row per amplitude), nlmodes_synthesis.csv
// (one row per synthesized point of every level); run.json "nlmodes" (the linear start, the
// points, how the curve ended, the synthesized peaks and times).
#include <string>

#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

struct NonlinearModesOutcome {
  /// Empty: the curve reached nlmodes.amplitude_end. Otherwise why it stopped (the files hold
  /// the points traced).
  std::string failure;
};

/// Runs the stage into ctx.out_dir. Throws InputError for a case it cannot run (not lumped,
/// "auto" harmonics, a mode that does not move the contacts) and NumericalError when the
/// first point does not converge.
NonlinearModesOutcome run_nonlinear_modes(Context& ctx);

}  // namespace shroudsim::pipeline
