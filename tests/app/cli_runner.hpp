#pragma once
// Runs the shroudsim executable in a scratch folder and captures its exit status and output.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace shroudsim::testing {

struct CliResult {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The rows of a CSV text (header included), split at commas.
inline std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream s(text);
  for (std::string line; std::getline(s, line);) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    for (std::string c; std::getline(l, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

/// A scratch folder per test, removed at the end.
class Scratch {
 public:
  explicit Scratch(const std::string& name)
      : dir_(std::filesystem::temp_directory_path() / ("shroudsim_cli_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  ~Scratch() { std::filesystem::remove_all(dir_); }
  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const auto p = dir_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  /// `shroudsim ARGS` with the scratch folder as working directory.
  CliResult run(const std::string& args) const { return run_command("'" SHROUDSIM_EXE "' " + args); }
  /// A shell command line (e.g. a launcher in front of shroudsim) in the scratch folder.
  CliResult run_command(const std::string& command) const {
    const auto out = dir_ / ".stdout", err = dir_ / ".stderr";
    const std::string cmd =
        "cd '" + dir_.string() + "' && " + command + " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int raw = std::system(cmd.c_str());
    CliResult r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

 private:
  std::filesystem::path dir_;
};

// A coarse sector (4-node tets, 10 modes per index), 3 shroud pairs, full3d contact, H = 3,
// N = 64, traced from f0 to f1 Hz.
inline std::string coarse_sector_case(double f0, double f1) {
  std::ostringstream c;
  c << R"(name = "sector"
[geometry]
element_order = 1
mesh_size = 0.03
[modal]
modes = 10
damping_ratio = 0.005
[contact]
pairs = 3
[hbm]
harmonics = 3
time_samples = 64
[continuation]
initial_step = 0.5
frequency_start_hz = )"
    << f0 << "\nfrequency_end_hz = " << f1 << "\n";
  return c.str();
}

}  // namespace shroudsim::testing
