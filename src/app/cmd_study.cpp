// `shroudsim study`: not built yet (issue 5). Says so and exits 2 until then.
#include "app/context.hpp"
#include "core/log.hpp"

#include <iostream>

namespace shroudsim::app {

int cmd_study(Context&) {
  std::cerr << "shroudsim: the 'study' command is not available yet (planned in issue 5)\n";
  return 2;
}

}  // namespace shroudsim::app
