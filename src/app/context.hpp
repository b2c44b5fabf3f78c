#pragma once
// The subcommands: each maps the case onto pipeline stages and library calls and writes its
// result files. They are written against the pipeline library (src/pipeline), whose names
// they use unqualified.
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/context.hpp"
#include "pipeline/forced_model.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::app {

using namespace shroudsim::pipeline;  // NOLINT(google-build-using-namespace): the commands' vocabulary

/// Subcommands. Each returns the process exit status (0, 2, 3) or throws
/// InputError (-> 2) / NumericalError (-> 3).
int cmd_mesh(Context& ctx);
int cmd_modes(Context& ctx);
int cmd_campbell(Context& ctx);
int cmd_frf(Context& ctx);
int cmd_nlmodes(Context& ctx);
int cmd_contact(Context& ctx);
int cmd_static(Context& ctx);
int cmd_study(Context& ctx);
/// Every stage the case asks for, in order.
int cmd_run(Context& ctx);

/// run.json of a finished command (docs/contract.md): the stage report, command, status and
/// message, the case as run, time, memory and versions.
nlohmann::json run_report(const Context& ctx, const std::string& command, const std::string& status,
                          const std::string& message);

/// Runs tools/plot.py on the result folder when /usr/bin/python3 has matplotlib; otherwise
/// says that plots are skipped. A plotting failure is a warning, not an error. Uses the
/// process an EarlyPlotter started, when there is one. `meanwhile` (writing result files
/// that no plot reads) runs while that process draws, and in every case where no plot is drawn.
void draw_plots(Context& ctx, const std::function<void()>& meanwhile = {});

/// Starts `tools/plot.py --wait` now, so that Python and matplotlib load (0.5 s) while the
/// command computes; draw_plots then only sends it the arguments. Destroyed before
/// draw_plots ran (a failed command, a command without plots), it ends that process unused.
/// One per process.
class EarlyPlotter {
 public:
  EarlyPlotter();
  ~EarlyPlotter();
  EarlyPlotter(const EarlyPlotter&) = delete;
  EarlyPlotter& operator=(const EarlyPlotter&) = delete;
};

}  // namespace shroudsim::app
