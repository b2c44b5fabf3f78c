// `shroudsim mesh CASE`: builds meshes/<name>.msh from [geometry] (or checks a given mesh).
#include "app/context.hpp"
#include "core/log.hpp"

namespace shroudsim::app {

int cmd_mesh(Context& ctx) {
  obtain_mesh(ctx);
  return 0;
}

}  // namespace shroudsim::app
