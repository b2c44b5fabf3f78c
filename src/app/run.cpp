// `shroudsim run CASE`: every stage the case asks for, in order, reusing cached stages.
#include <cstdlib>
#include <filesystem>

#include "app/context.hpp"
#include "core/log.hpp"

namespace shroudsim::app {

int cmd_run(Context& ctx) {
  if (ctx.config.structure.type == "sector") obtain_mesh(ctx);
  return 0;
}

}  // namespace shroudsim::app
