#pragma once
// What every stage of a run receives and fills: the parsed case, the result folder, and the
// run report that becomes run.json. The pipeline stages (mesh, modal stage, forced-response
// model) map io::Case onto the stage libraries' own *Options, run them, write their result
// files atomically (io/output.hpp), print one progress line per stage (log::info), and
// record timings in the report. The commands of src/app are drivers over these.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "io/case.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::pipeline {

struct ModalModel;

/// Collects what run.json reports: stage timings, what was reused, statistics, warnings.
class RunReport {
 public:
  /// One finished stage: name, wall time in seconds, whether it came from the cache.
  void stage(const std::string& name, double seconds, bool reused = false);
  /// A warning: printed to stderr now (never silenced) and listed in run.json.
  void warn(const std::string& message);
  /// Free-form statistics under a top-level key (e.g. "mesh", "modal", "newton").
  nlohmann::json& section(const std::string& key) { return json_[key]; }
  const nlohmann::json& json() const { return json_; }
  double total_seconds() const;

 private:
  nlohmann::json json_ = nlohmann::json::object();
};

struct Context {
  io::Case config;                     ///< the case as run (after --set)
  std::filesystem::path out_dir;       ///< result folder (created on demand)
  int threads = 0;                     ///< 0: all cores
  std::vector<std::string> overrides;  ///< the command line's --set KEY=VALUE, in order
  bool plots = true;                   ///< draw plots after a command (off for study points)
  bool no_plots = false;               ///< `--no-plots`: no plotting process, no plots (run.json plots.reason)
  bool convergence = false;            ///< `study --convergence`: the accuracy/speed trade
  bool resume = false;                 ///< `study --resume`: reuse the finished points in out_dir
  /// (frequency [Hz], amplitude [m]) of the forced response cmd_frf traced (as in frf.csv).
  std::vector<std::pair<double, double>> frf_curve;
  /// The modal model (mesh, K and M, the modes; no factors) that make_sector_model built the
  /// forced response on, kept for its shapes (sector_shapes), which would otherwise read the
  /// mesh, assemble and load the modes again.
  std::shared_ptr<ModalModel> forced_modal;
  RunReport report;
};

/// The sector mesh of the case: [structure] mesh read and checked, or generated from
/// [geometry] into meshes/<name>.msh (reused when the cached mesh matches the geometry).
/// Throws InputError for a bad mesh. Records the "mesh" stage in the report.
mesh::Mesh obtain_mesh(Context& ctx);

}  // namespace shroudsim::pipeline
