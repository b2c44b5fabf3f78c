#include "core/log.hpp"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

namespace shroudsim::log {
namespace {
std::atomic<bool> g_verbose{true};
std::atomic<bool> g_detailed{false};
std::mutex g_mutex;
bool g_live = false;  // a live progress line is on the terminal (guarded by g_mutex)
std::chrono::steady_clock::time_point g_last_progress{};
bool g_progress_shown = false;

bool stderr_is_terminal() {
  static const bool terminal = ::isatty(STDERR_FILENO) == 1;
  return terminal;
}

void end_live_line() {  // g_mutex held
  if (g_live) std::cerr << '\n';
  g_live = false;
}
}  // namespace

void set_verbose(bool verbose) { g_verbose = verbose; }
bool verbose() { return g_verbose; }
void set_detailed(bool detailed) { g_detailed = detailed; }
bool detailed() { return g_detailed; }

void info(const std::string& line) {
  if (!g_verbose) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  end_live_line();
  std::cerr << "shroudsim: " << line << '\n';
}

void warn(const std::string& line) {
  std::lock_guard<std::mutex> lock(g_mutex);
  end_live_line();
  std::cerr << "shroudsim: warning: " << line << '\n';
}

void progress(const std::string& line) {
  if (!g_verbose) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  const auto now = std::chrono::steady_clock::now();
  const bool terminal = stderr_is_terminal();
  const auto interval = terminal ? std::chrono::milliseconds(200) : std::chrono::milliseconds(10000);
  if (g_progress_shown && now - g_last_progress < interval) return;
  g_last_progress = now;
  g_progress_shown = true;
  if (terminal) {
    std::cerr << "\rshroudsim: " << line << "\033[K" << std::flush;
    g_live = true;
  } else {
    std::cerr << "shroudsim: " << line << '\n';
  }
}

void progress_done() {
  std::lock_guard<std::mutex> lock(g_mutex);
  end_live_line();
  g_progress_shown = false;
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
