#pragma once
// Internal: scoped use of the gmsh API (a process-wide singleton, not thread-safe).
#include <gmsh.h>

#include <mutex>

namespace shroudsim::mesh::detail {

/// Initialises gmsh on construction and finalises it on destruction; serialises users.
class GmshSession {
 public:
  explicit GmshSession(bool verbose) : lock_(mutex()) {
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", verbose ? 1 : 0);
    gmsh::option::setNumber("General.Verbosity", verbose ? 2 : 1);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
};

}  // namespace shroudsim::mesh::detail
