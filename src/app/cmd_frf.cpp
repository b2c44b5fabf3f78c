// `shroudsim frf CASE`: the nonlinear forced response by multiharmonic balance with
// pseudo-arclength continuation (pipeline/forced_response.hpp) -> frf.csv, loops.csv,
// peaks.csv, run.json "frf"; then the plots. A curve that fails its own checks is drawn and
// exits 3.
#include "app/context.hpp"
#include "core/error.hpp"
#include "pipeline/forced_response.hpp"

namespace shroudsim::app {

int cmd_frf(Context& ctx) {
  const ForcedResponseOutcome outcome = run_forced_response(ctx);
  draw_plots(ctx);
  if (!outcome.failure.empty()) throw NumericalError(outcome.failure);
  return 0;
}

}  // namespace shroudsim::app
