#include "io/output.hpp"

#include <cmath>
#include <fstream>
#include <random>

#include "core/error.hpp"
#include "core/format.hpp"

namespace shroudsim::io {

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
  namespace fs = std::filesystem;
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  std::random_device rd;
  const fs::path tmp = path.string() + ".tmp" + std::to_string(rd() % 1000000);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    out << content;
    out.flush();
    if (!out) {
      fs::remove(tmp);
      throw std::runtime_error("writing " + tmp.string() + " failed (disk full?)");
    }
  }
  fs::rename(tmp, path);
}

std::string format_number(double value) {
  if (!std::isfinite(value)) throw NumericalError("a non-finite value (NaN or Inf) would reach a result file");
  return shortest(value);
}

}  // namespace shroudsim::io
