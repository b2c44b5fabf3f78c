// `shroudsim run CASE`: every stage the case asks for, in order, reusing cached stages
// (mesh, K and M, modes): sector cases mesh -> modes -> campbell -> frf; lumped cases frf.
#include "app/context.hpp"
#include "core/log.hpp"

namespace shroudsim::app {

int cmd_run(Context& ctx) {
  if (ctx.config.structure.type == "lumped") return cmd_frf(ctx);
  for (auto* stage : {cmd_modes, cmd_campbell, cmd_frf}) {
    const int status = stage(ctx);
    if (status != 0) return status;
  }
  return 0;
}

}  // namespace shroudsim::app
