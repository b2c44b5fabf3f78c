#include "core/error.hpp"

#include <sstream>

namespace shroudsim::detail {

void check_failed(const char* condition, const std::string& message, const char* file, int line) {
  std::ostringstream s;
  s << "internal check failed: " << condition << " (" << message << ") at " << file << ":" << line;
  throw std::logic_error(s.str());
}

}  // namespace shroudsim::detail
