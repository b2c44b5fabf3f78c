// `shroudsim contact`: not built yet (issue 4). Says so and exits 2 until then.
#include "app/context.hpp"
#include "core/log.hpp"

#include <iostream>

namespace shroudsim::app {

int cmd_contact(Context&) {
  std::cerr << "shroudsim: the 'contact' command is not available yet (planned in issue 4)\n";
  return 2;
}

}  // namespace shroudsim::app
