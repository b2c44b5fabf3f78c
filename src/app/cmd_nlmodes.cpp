// `shroudsim nlmodes CASE`: the nonlinear mode of a lumped case by the extended periodic
// motion concept and the forced responses synthesized from it (pipeline/nonlinear_modes_stage.hpp)
// -> nlmodes.csv, nlmodes_synthesis.csv, run.json "nlmodes"; then the plots. A curve that stops
// before nlmodes.amplitude_end is drawn and exits 3.
#include "app/context.hpp"
#include "core/error.hpp"
#include "pipeline/nonlinear_modes_stage.hpp"

namespace shroudsim::app {

int cmd_nlmodes(Context& ctx) {
  const NonlinearModesOutcome outcome = run_nonlinear_modes(ctx);
  draw_plots(ctx);
  if (!outcome.failure.empty()) throw NumericalError(outcome.failure);
  return 0;
}

}  // namespace shroudsim::app
