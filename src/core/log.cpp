#include "core/log.hpp"

#include <atomic>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

namespace shroudsim::log {
namespace {
std::atomic<bool> g_verbose{true};
std::mutex g_mutex;
}  // namespace

void set_verbose(bool verbose) { g_verbose = verbose; }
bool verbose() { return g_verbose; }

void info(const std::string& line) {
  if (!g_verbose) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  std::cerr << "shroudsim: " << line << '\n';
}

void warn(const std::string& line) {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::cerr << "shroudsim: warning: " << line << '\n';
}

double peak_memory_mib() {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      double kib = 0.0;
      status >> kib;
      return kib / 1024.0;
    }
    std::string rest;
    std::getline(status, rest);
  }
  return 0.0;
}

}  // namespace shroudsim::log
