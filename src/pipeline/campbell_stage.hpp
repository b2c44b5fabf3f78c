#pragma once
// The Campbell stage (`shroudsim campbell`, a stage of `run`): natural frequencies against
// speed with the engine-order lines, from the modal stage (modal_stage.hpp) and the sweep and
// crossings of campbell/campbell.hpp -> modes.csv, campbell.csv, crossings.csv; with rotating
// effects also prestress.vtu (the centrifugal displacement and von Mises stress at the top
// speed) and run.json "campbell" (prestress, per-harmonic-index sweep cost, the static shroud
// contact at every speed for modal.shroud = "contact").
//
// rotating_effects = false: the frequencies at rest at every speed (flat lines). The prestress
// is computed once (stress scales with Omega^2); harmonic indices run in parallel
// (--threads); h and Nb - h share one sweep; speed 0 reuses the modes at rest.
#include <string>
#include <vector>

#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

struct CampbellOutcome {
  /// Harmonic indices (or speeds) whose modes failed, one message each; the result files
  /// hold what converged.
  std::vector<std::string> failures;
};

/// The Campbell diagram of ctx.config into ctx.out_dir. Throws InputError unless the case is
/// an FE sector.
CampbellOutcome run_campbell(Context& ctx);

}  // namespace shroudsim::pipeline
