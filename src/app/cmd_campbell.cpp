// `shroudsim campbell`: natural frequencies against speed with engine-order lines
// (pipeline/campbell_stage.hpp) -> campbell.csv, crossings.csv, modes.csv, campbell.png,
// nd_map.png (and prestress.vtu with rotating effects). What converged is written and drawn
// even when a sweep failed; the command then exits 3.
#include <cstdlib>
#include <string>

#include "app/context.hpp"
#include "core/error.hpp"
#include "pipeline/campbell_stage.hpp"

namespace shroudsim::app {

int cmd_campbell(Context& ctx) {
  const CampbellOutcome outcome = run_campbell(ctx);
  // run.json (where tools/plot.py reads why a sweep stopped) is written after the command
  // returns, so the plot of this run gets the reason from the environment of the plotting
  // process. (Only when this command plots: study points run in threads and never plot.)
  if (ctx.plots && !outcome.failures.empty())
    ::setenv("SHROUDSIM_CAMPBELL_STOPPED", outcome.failures.front().c_str(), 1);
  draw_plots(ctx);
  if (!outcome.failures.empty()) {
    std::string msg = "modal analysis failed for";
    for (const auto& f : outcome.failures) msg += "\n  " + f;
    throw NumericalError(msg +
                         "\n(campbell.csv and crossings.csv hold the harmonic indices and speeds that converged)");
  }
  return 0;
}

}  // namespace shroudsim::app
