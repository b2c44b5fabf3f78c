#pragma once
// The stages of a case run from Python, each as the command of the same name runs it: a
// pipeline::Context like the command line's (the case with its overrides, --threads), the
// same library calls (pipeline/*.hpp and the commands of app/context.hpp), the same result
// files and run.json, written into a results folder (`out`, replaced atomically as with
// --out) or into a temporary folder removed afterwards. The stage runs without the GIL; its
// result is read back into a Result object (numpy arrays, dicts), and its errors become the
// module's exceptions (errors.hpp). One stage at a time per process: the log verbosity and
// gmsh are process-wide.
#include <pybind11/pybind11.h>

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "io/case.hpp"

namespace shroudsim::python {

namespace py = pybind11;

/// A case as the module holds it: parsed, and how it was given (to parse it again with more
/// overrides).
struct CaseSource {
  io::Case config;                            ///< the case as run (defaults, overrides)
  std::optional<std::filesystem::path> path;  ///< a case file, as named
  std::string text;                           ///< a dict case: the TOML text it was parsed from
  std::filesystem::path name;                 ///< a dict case: its name in messages, <directory>/<dict>
  std::vector<std::string> overrides;         ///< KEY=VALUE, in order

  /// The names the case's messages start with (for ErrorLocation::file).
  std::vector<std::string> message_names() const;
};

/// A case file with overrides. Sets shroudsim.InputError and throws py::error_already_set
/// when the case is bad.
CaseSource load_file_case(const std::filesystem::path& path, const std::vector<std::string>& overrides);
/// A case given as a dict (convert.hpp), relative paths and caches in `directory`.
CaseSource load_dict_case(const py::dict& case_dict, const std::vector<std::string>& overrides,
                          const std::filesystem::path& directory);
/// The same case with more overrides (after its own).
CaseSource with_overrides(const CaseSource& source, const std::vector<std::string>& more);

/// The command line's common options.
struct RunOptions {
  std::optional<std::filesystem::path> out;  ///< results folder (--out); none: a temporary one
  int threads = 0;                           ///< --threads (0: all cores)
  bool quiet = false;                        ///< --quiet
  bool verbose = false;                      ///< --verbose
  bool plots = false;                        ///< draw the plots into `out` (tools/plot.py)
};

/// The result objects: attributes set per stage (docs/python.md); one class per stage.
struct Result {};
struct MeshResult : Result {};
struct ModesResult : Result {};
struct CampbellResult : Result {};
struct StaticContactResult : Result {};
struct FrfResult : Result {};
struct RunResult : Result {};

/// `shroudsim mesh`: the sector mesh (nodes, elements, node sets, matched pairs).
py::object run_mesh(const CaseSource& c, const RunOptions& o);
/// `shroudsim modes`: frequencies per harmonic index; with shapes, the mode shapes on every
/// node of the sector (the cyclic expansion of the reduced modes).
py::object run_modes(const CaseSource& c, const RunOptions& o, bool shapes);
/// `shroudsim campbell`: campbell.csv, crossings.csv, modes.csv as tables.
py::object run_campbell(const CaseSource& c, const RunOptions& o);
/// `shroudsim static`: the static shroud contact per matched pair (state, gap, loads).
py::object run_static_contact(const CaseSource& c, const RunOptions& o);
/// `shroudsim frf`: the forced response curve, peaks and hysteresis loops.
py::object run_frf(const CaseSource& c, const RunOptions& o);
/// `shroudsim run`: every stage the case asks for; every table written.
py::object run_all(const CaseSource& c, const RunOptions& o);

}  // namespace shroudsim::python
