// `shroudsim campbell`: not built yet (issue 3). Says so and exits 2 until then.
#include "app/context.hpp"
#include "core/log.hpp"

#include <iostream>

namespace shroudsim::app {

int cmd_campbell(Context&) {
  std::cerr << "shroudsim: the 'campbell' command is not available yet (planned in issue 3)\n";
  return 2;
}

}  // namespace shroudsim::app
