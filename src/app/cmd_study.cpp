// `shroudsim study CASE`: the case over the Cartesian product of the [study] vary lists ->
// study.csv, study.png; `study --convergence CASE`: the accuracy/speed trade of the case's
// knobs -> trade.csv, trade.png (pipeline/study_stage.hpp). Each point runs `run`; the points
// of a sampled study ([study] sample) run `frf`.
#include "app/context.hpp"
#include "pipeline/study_stage.hpp"

namespace shroudsim::app {

int cmd_study(Context& ctx) {
  const StudyOutcome outcome = run_study(ctx, cmd_run, cmd_frf);
  draw_plots(ctx);
  if (outcome.warning.empty()) return 0;
  ctx.report.warn(outcome.warning);
  return 3;
}

}  // namespace shroudsim::app
