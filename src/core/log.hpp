#pragma once
// Progress reporting for the application layer. Kernels never print: they report through
// observers, and app/ decides what reaches stderr. Thread-safe; silenced by --quiet.
#include <chrono>
#include <string>

namespace shroudsim::log {

/// Global verbosity: false after --quiet.
void set_verbose(bool verbose);
bool verbose();

/// One line to stderr (prefixed "shroudsim: ") when verbose.
void info(const std::string& line);
/// One line to stderr, always (warnings are never silenced).
void warn(const std::string& line);

/// Per-step detail (e.g. every continuation point): off unless --verbose.
void set_detailed(bool detailed);
bool detailed();

/// A progress report that replaces the previous one: on a terminal one live line (rewritten
/// in place, at most every 0.2 s); otherwise a plain line at most every 10 s. Silenced with
/// info(). The next info() or warn() line, or progress_done(), ends the live line.
void progress(const std::string& line);
/// Ends the live progress line (a newline on a terminal), if one is shown.
void progress_done();

/// Wall-clock stopwatch, seconds.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

/// Peak resident set size of this process so far, in MiB (from /proc/self/status; 0 if unknown).
double peak_memory_mib();

}  // namespace shroudsim::log
