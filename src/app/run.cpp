// `shroudsim run CASE`: every stage the case asks for, in order, reusing cached stages
// (mesh, K and M, modes): sector cases mesh -> modes -> campbell -> static (when the case
// gives a static speed or an interference) -> frf; lumped cases frf.
#include "app/context.hpp"
#include "core/log.hpp"
#include "pipeline/forced_model.hpp"

namespace shroudsim::app {

int cmd_run(Context& ctx) {
  if (ctx.config.structure.type == io::StructureType::lumped) return cmd_frf(ctx);
  const io::Case& c = ctx.config;
  // Inputs that only the forced response reads, checked on the mesh before any modal work.
  check_forced_points(c, obtain_mesh(ctx));
  const bool static_contact = c.static_contact.speed_rpm > 0.0 || c.contact.interference != 0.0;
  for (auto* stage : {cmd_modes, cmd_campbell, cmd_static, cmd_frf}) {
    if (stage == cmd_static && !static_contact) continue;
    const int status = stage(ctx);
    if (status != 0) return status;
  }
  return 0;
}

}  // namespace shroudsim::app
