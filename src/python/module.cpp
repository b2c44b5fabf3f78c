// The Python module `shroudsim` (docs/python.md): a case from a TOML file or a dict, with the
// command line's overrides, run stage by stage (mesh, modes, campbell, static contact, forced
// response) through the pipeline library; results as numpy arrays and dicts; the command
// line's errors as shroudsim.InputError / shroudsim.NumericalError.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <string>

#include "io/case.hpp"
#include "python/convert.hpp"
#include "python/errors.hpp"
#include "python/stages.hpp"

namespace py = pybind11;
using namespace pybind11::literals;  // NOLINT(google-build-using-namespace): "name"_a for keyword arguments

namespace shroudsim::python {
namespace {

/// "FrfResult(status='ok', frequency_hz=float64[412], peaks={4 columns}, ...)": arrays by
/// type and shape, dicts by size, the rest by repr (shortened).
std::string result_repr(const py::object& self) {
  std::string s = std::string(py::str(py::type::of(self).attr("__name__"))) + "(";
  bool first = true;
  for (const auto& [k, v] : py::dict(self.attr("__dict__"))) {
    std::string text;
    if (py::hasattr(v, "dtype") && py::hasattr(v, "shape")) {
      text = std::string(py::str(v.attr("dtype"))) + "[";
      bool first_dim = true;
      for (const auto& d : v.attr("shape")) {
        text += (first_dim ? "" : ", ") + std::string(py::str(d));
        first_dim = false;
      }
      text += "]";
    } else if (py::isinstance<py::dict>(v)) {
      text = "{" + std::to_string(py::len(v)) + " keys}";
    } else {
      text = py::repr(v);
      if (text.size() > 60) text = text.substr(0, 57) + "...";
    }
    s += (first ? "" : ", ") + std::string(py::str(k)) + "=" + text;
    first = false;
  }
  return s + ")";
}

std::string case_repr(const CaseSource& c) {
  std::string s = "Case(name='" + c.config.name + "', type='" + io::to_string(c.config.structure.type) + "', ";
  s += c.path ? "file='" + c.config.file.string() + "'" : "from a dict in '" + c.config.directory.string() + "'";
  if (!c.overrides.empty()) s += ", " + std::to_string(c.overrides.size()) + " overrides";
  return s + ")";
}

RunOptions options(std::optional<std::filesystem::path> out, int threads, bool quiet, bool verbose, bool plots) {
  if (threads < 0 || threads > 1024) throw py::value_error("threads: 0 (all cores) to 1024");
  if (plots && !out) throw py::value_error("plots=True draws into a results folder: give out=...");
  return {std::move(out), threads, quiet, verbose, plots};
}

std::string file_name(const CaseSource& c) { return c.path ? c.path->string() : c.name.string(); }

CaseSource load_any(const py::object& source, const py::object& overrides, const py::object& directory) {
  if (py::isinstance<py::dict>(source)) {
    const std::filesystem::path dir = directory.is_none() ? std::filesystem::current_path()
                                                          : directory.cast<std::filesystem::path>();
    const std::string name = (std::filesystem::absolute(dir).lexically_normal() / "<dict>").string();
    return load_dict_case(source.cast<py::dict>(), override_strings(overrides, name), dir);
  }
  if (!directory.is_none()) throw py::value_error("directory is for a case given as a dict");
  const auto path = source.cast<std::filesystem::path>();
  return load_file_case(path, override_strings(overrides, path.string()));
}

// The keyword arguments every stage takes, with their documentation.
constexpr const char* kStageOptions = R"(
Keyword arguments (as the command line's options):
  out      results folder to write as `--out` does (replaced atomically, run.json included);
           None: a temporary folder, removed after the results are read
  threads  worker threads, 0: all cores (`--threads`)
  quiet    no progress on stderr (`--quiet`)
  verbose  a line per continuation point (`--verbose`)
  plots    draw the command's plots into `out` with tools/plot.py (needs matplotlib)
Every result has status ('ok'), message (None), report (run.json as a dict), tables (every
CSV file written, {file stem: {column: numpy array}}) and out (the folder, or None).
Raises InputError for bad input (out untouched) and NumericalError when the numerics fail
(what was computed is written to out and attached as the exception's result).)";

template <typename F>
void def_stage(py::class_<CaseSource>& cls, const char* name, F run, const std::string& doc) {
  static std::vector<std::string> docs;  // pybind11 keeps the pointer
  docs.push_back(doc + "\n" + kStageOptions);
  cls.def(
      name,
      [run](const CaseSource& c, std::optional<std::filesystem::path> out, int threads, bool quiet, bool verbose,
            bool plots) { return run(c, options(std::move(out), threads, quiet, verbose, plots)); },
      py::kw_only(), "out"_a = py::none(), "threads"_a = 0, "quiet"_a = false, "verbose"_a = false, "plots"_a = false,
      docs.back().c_str());
}

}  // namespace
}  // namespace shroudsim::python

PYBIND11_MODULE(shroudsim, m) {
  using namespace shroudsim::python;  // NOLINT(google-build-using-namespace): the module's own names
  m.doc() =
      "shroudsim: friction damping of shrouded bladed disks (cyclic FE + multiharmonic balance).\n\n"
      "    case = shroudsim.load_case('cases/lumped_jenkins.toml', {'hbm.harmonics': 3})\n"
      "    frf = case.frf(quiet=True)\n"
      "    frf.frequency_hz, frf.amplitude_m, frf.peaks\n\n"
      "See docs/python.md.";
  m.attr("__version__") = SHROUDSIM_VERSION;
  register_errors(m);

  py::class_<Result>(m, "Result", py::dynamic_attr(), "A stage's result: attributes per stage (docs/python.md).")
      .def("__repr__", [](const py::object& self) { return result_repr(self); });
  py::class_<MeshResult, Result>(m, "MeshResult", py::dynamic_attr(),
                                 "The sector mesh: nodes (n, 3) [m], elements (m, 4 | 10), element_order, sectors, "
                                 "node_sets, surface_triangles, cyclic_pairs (k, 2), shroud_pairs (k, 2).");
  py::class_<ModesResult, Result>(m, "ModesResult", py::dynamic_attr(),
                                  "Modes per harmonic index: harmonic_indices, nodal_diameters, frequencies_hz {h: "
                                  "array}, shapes {h: complex (modes, nodes, 3)} or None, nodes, failures.");
  py::class_<CampbellResult, Result>(m, "CampbellResult", py::dynamic_attr(),
                                     "The Campbell diagram: campbell, crossings, modes (tables of the CSV files).");
  py::class_<StaticContactResult, Result>(m, "StaticContactResult", py::dynamic_attr(),
                                          "The static shroud contact: pairs (static_contact.csv as a table: state, "
                                          "gap, loads per matched pair), summary (run.json \"static\").");
  py::class_<FrfResult, Result>(m, "FrfResult", py::dynamic_attr(),
                                "The forced response: frequency_hz, amplitude_m, linear_amplitude_m, "
                                "newton_iterations, piece, harmonic_amplitudes_m (points, H + 1), columns (frf.csv), "
                                "peaks (peaks.csv), peak_frequency_hz, peak_amplitude_m, loops (loops.csv), "
                                "loop_displacement_m and loop_force_n (pairs, samples, 3).");
  py::class_<RunResult, Result>(m, "RunResult", py::dynamic_attr(),
                                "Every stage the case asks for (`shroudsim run`): tables, report.");

  py::class_<CaseSource> cls(m, "Case",
                             "A case: a TOML file (Case(path, overrides)) or a dict (Case.from_dict), with the "
                             "command line's overrides, parsed and checked. Run its stages with mesh(), modes(), "
                             "campbell(), static_contact(), frf(), run().");
  cls.def(py::init([](const std::filesystem::path& path, const py::object& overrides) {
            return load_file_case(path, override_strings(overrides, path.string()));
          }),
          "path"_a, "overrides"_a = py::none(),
          "Reads a case file. overrides: a dict {dotted key: value} or a list of \"KEY=VALUE\" strings "
          "(the command line's --set). Raises InputError naming file, line and key.")
      .def_static(
          "from_dict",
          [](const py::dict& d, const py::object& overrides, const py::object& directory) {
            return load_any(d, overrides, directory);
          },
          "case"_a, "overrides"_a = py::none(), "directory"_a = py::none(),
          "A case given as a dict of sections ({'structure': {'type': 'lumped', ...}, ...}; "
          "[[contact.elements]] as a list of dicts). Relative paths, meshes/ and the .cache/ of "
          "the modal stage are in `directory` (default: the working directory). Messages name "
          "'<directory>/<dict>' and the line of the key in Case.source.")
      .def(
          "with_overrides",
          [](const CaseSource& c, const py::object& more) {
            return with_overrides(c, override_strings(more, file_name(c)));
          },
          "overrides"_a, "The same case with more overrides (applied after its own).")
      .def_property_readonly(
          "name", [](const CaseSource& c) { return c.config.name; }, "The case's name.")
      .def_property_readonly(
          "file", [](const CaseSource& c) { return c.config.file.string(); },
          "The case file (absolute), '<directory>/<dict>' for a dict.")
      .def_property_readonly(
          "directory", [](const CaseSource& c) { return c.config.directory.string(); },
          "Where relative paths and the modal cache are.")
      .def_property_readonly(
          "structure_type", [](const CaseSource& c) { return shroudsim::io::to_string(c.config.structure.type); },
          "'sector' or 'lumped'.")
      .def_property_readonly(
          "overrides", [](const CaseSource& c) { return c.overrides; }, "The overrides as KEY=VALUE strings.")
      .def_property_readonly(
          "toml", [](const CaseSource& c) { return c.config.resolved_toml; },
          "The case as run (every key, defaults inserted, overrides applied) as TOML.")
      .def_property_readonly(
          "source", [](const CaseSource& c) { return c.path ? py::object(py::none()) : py::object(py::str(c.text)); },
          "A dict case: the TOML text it was parsed from (messages' line numbers point here); None for a file.")
      .def(
          "to_dict", [](const CaseSource& c) { return to_python(nlohmann::json::parse(c.config.resolved_json)); },
          "The case as run as a dict (every key).")
      .def("__repr__", &case_repr);

  def_stage(cls, "mesh", &run_mesh, "The sector mesh (`shroudsim mesh`): generated into meshes/<name>.msh or read.");
  static const std::string modes_doc =
      std::string(
          "The modes per harmonic index (`shroudsim modes`). shapes=True adds the complex mode shapes on "
          "every node of the sector, {h: (modes, nodes, 3)} (mass-normalised on the cyclic reduction).\n") +
      kStageOptions;
  cls.def(
      "modes",
      [](const CaseSource& c, bool shapes, std::optional<std::filesystem::path> out, int threads, bool quiet,
         bool verbose,
         bool plots) { return run_modes(c, options(std::move(out), threads, quiet, verbose, plots), shapes); },
      py::kw_only(), "shapes"_a = false, "out"_a = py::none(), "threads"_a = 0, "quiet"_a = false, "verbose"_a = false,
      "plots"_a = false, modes_doc.c_str());
  def_stage(cls, "campbell", &run_campbell, "The Campbell diagram (`shroudsim campbell`).");
  def_stage(cls, "static_contact", &run_static_contact, "The static shroud contact at speed (`shroudsim static`).");
  def_stage(cls, "frf", &run_frf, "The nonlinear forced response (`shroudsim frf`).");
  def_stage(cls, "run", &run_all, "Every stage the case asks for, in order (`shroudsim run`).");

  m.def("load_case", &load_any, "case"_a, "overrides"_a = py::none(), "directory"_a = py::none(),
        "A case from a file path or a dict (Case(path, overrides) or Case.from_dict(case, overrides, directory)).");
  m.def(
      "default_case_text", [] { return shroudsim::io::default_case_text(); },
      "A complete, commented case file with every key at its default (`shroudsim --print-defaults`).");
}
