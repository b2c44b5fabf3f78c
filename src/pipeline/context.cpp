#include "pipeline/context.hpp"

#include "core/log.hpp"

namespace shroudsim::pipeline {

void RunReport::stage(const std::string& name, double seconds, bool reused) {
  json_["stages"].push_back({{"name", name}, {"seconds", seconds}, {"reused", reused}});
}

void RunReport::warn(const std::string& message) {
  log::warn(message);
  json_["warnings"].push_back(message);
}

double RunReport::total_seconds() const {
  double total = 0.0;
  if (json_.contains("stages"))
    for (const auto& s : json_["stages"]) total += s.value("seconds", 0.0);
  return total;
}

}  // namespace shroudsim::pipeline
