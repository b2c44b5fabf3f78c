#include "python/stages.hpp"

#include <pybind11/numpy.h>
#include <stdlib.h>

#include <Eigen/Core>
#include <complex>
#include <exception>
#include <functional>
#include <memory>
#include <sstream>

#include "app/context.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "io/output.hpp"
#include "io/results_folder.hpp"
#include "pipeline/context.hpp"
#include "pipeline/modal_stage.hpp"
#include "python/convert.hpp"
#include "python/errors.hpp"

namespace shroudsim::python {
namespace {

namespace fs = std::filesystem;
using pipeline::Context;

/// The message of the exception being handled, with its location, as the current Python
/// error (InputError located against the case), then py::error_already_set. Other exceptions
/// are rethrown for the module's translator.
[[noreturn]] void raise_current(const std::vector<std::string>& names, const std::map<std::string, std::string>* at) {
  try {
    throw;
  } catch (const InputError& e) {
    set_input_error(e.what(), names, at);
    throw py::error_already_set();
  }
}

/// A temporary results folder (when the caller gave no `out`), removed with everything in it.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::string pattern = (fs::temp_directory_path() / "shroudsim-python-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary folder in " + pattern);
    path_ = pattern;
  }
  ~TemporaryFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// --quiet / --verbose for the duration of one stage (the log's settings are process-wide).
class LogLevel {
 public:
  LogLevel(bool quiet, bool verbose) : verbose_(log::verbose()), detailed_(log::detailed()) {
    log::set_verbose(!quiet);
    log::set_detailed(verbose && !quiet);
  }
  ~LogLevel() {
    log::set_verbose(verbose_);
    log::set_detailed(detailed_);
  }
  LogLevel(const LogLevel&) = delete;
  LogLevel& operator=(const LogLevel&) = delete;

 private:
  bool verbose_, detailed_;
};

/// run.json as the command line writes it (app/cli.cpp), plus "driver".
nlohmann::json run_json(const Context& ctx, const std::string& command, const std::string& status,
                        const std::string& message) {
  nlohmann::json j = app::run_report(ctx, command, status, message);
  j["driver"] = "python";
  return j;
}

/// One stage as its command runs it: the context, the results folder (`out`, or a temporary
/// one), `body` without the GIL, run.json, then `collect` reads the result into `result`
/// (GIL held, the files still in the folder), the folder is committed. A NumericalError of
/// the body is raised after that, with the result attached (the command line's exit 3: what
/// was computed is written); an InputError leaves `out` untouched (exit 2).
py::object run_stage(const CaseSource& c, const RunOptions& o, const std::string& command, py::object result,
                     const std::function<void(Context&)>& body,
                     const std::function<void(const Context&, py::object&, const py::dict&)>& collect) {
  const std::vector<std::string> names = c.message_names();
  Context ctx;
  ctx.config = c.config;
  ctx.threads = o.threads;
  ctx.overrides = c.overrides;
  ctx.plots = o.plots;
  std::unique_ptr<io::ResultsFolder> folder;
  std::unique_ptr<TemporaryFolder> temporary;
  try {
    if (o.out) {
      folder = std::make_unique<io::ResultsFolder>(*o.out, "out");
      ctx.out_dir = folder->staging();
    } else {
      temporary = std::make_unique<TemporaryFolder>();
      ctx.out_dir = temporary->path();
    }
  } catch (const InputError& e) {
    set_input_error(e.what(), {}, nullptr, /*locate=*/false);  // about `out`, not the case
    throw py::error_already_set();
  }

  std::string numerical;
  std::exception_ptr failure;
  {
    const LogLevel level(o.quiet, o.verbose);
    const py::gil_scoped_release nogil;
    try {
      body(ctx);
    } catch (const NumericalError& e) {
      numerical = e.what();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (...) {
      raise_current(names, &c.config.locations);
    }
  }

  const std::string status = numerical.empty() ? "ok" : "numerics_failed";
  const nlohmann::json run = run_json(ctx, command, status, numerical);
  io::write_file_atomic(ctx.out_dir / "run.json", run.dump(2) + "\n");
  const py::dict tables = read_csv_tables(ctx.out_dir);
  result.attr("status") = status;
  result.attr("message") = numerical.empty() ? py::object(py::none()) : py::object(py::str(numerical));
  result.attr("report") = to_python(run);
  result.attr("tables") = tables;
  collect(ctx, result, tables);
  if (folder) {
    folder->commit();
    result.attr("out") = py::str(folder->target().string());
  } else {
    result.attr("out") = py::none();
  }
  if (!numerical.empty()) {
    set_numerical_error(numerical, result);
    throw py::error_already_set();
  }
  return result;
}

/// A table's column, or None when the file or column is missing.
py::object column(const py::dict& tables, const char* table, const char* name) {
  if (!tables.contains(table)) return py::none();
  const py::dict t = tables[table];
  return t.contains(name) ? py::object(t[name]) : py::object(py::none());
}

/// A row-major Eigen matrix as a numpy array of type T (a copy).
template <typename T, typename Matrix>
py::array_t<T> to_array(const Matrix& m) {
  py::array_t<T> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto v = a.template mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) v(i, j) = static_cast<T>(m(i, j));
  return a;
}

py::array_t<std::int64_t> pairs_array(const std::vector<std::pair<int, int>>& pairs) {
  py::array_t<std::int64_t> a({static_cast<py::ssize_t>(pairs.size()), py::ssize_t{2}});
  auto v = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    v(static_cast<py::ssize_t>(i), 0) = pairs[i].first;
    v(static_cast<py::ssize_t>(i), 1) = pairs[i].second;
  }
  return a;
}

py::array_t<double> vector_array(const Eigen::VectorXd& x) {
  py::array_t<double> a(static_cast<py::ssize_t>(x.size()));
  std::copy(x.data(), x.data() + x.size(), a.mutable_data());
  return a;
}

}  // namespace

std::vector<std::string> CaseSource::message_names() const {
  // io::load_case names the file as given in its own checks and TOML syntax errors, the
  // schema names it as an absolute path (io::Case::file).
  std::vector<std::string> names{config.file.string()};
  if (path) names.push_back(path->string());
  if (!name.empty()) names.push_back(name.string());
  return names;
}

CaseSource load_file_case(const fs::path& path, const std::vector<std::string>& overrides) {
  CaseSource c;
  c.path = path;
  c.overrides = overrides;
  try {
    c.config = io::load_case(path, overrides);
  } catch (const InputError& e) {
    set_input_error(e.what(), {path.string(), fs::absolute(path).lexically_normal().string()});
    throw py::error_already_set();
  } catch (const std::exception& e) {
    // As the command line reports it: "<case>: <what>".
    throw std::runtime_error(path.string() + ": " + e.what());
  }
  return c;
}

CaseSource load_dict_case(const py::dict& case_dict, const std::vector<std::string>& overrides,
                          const fs::path& directory) {
  CaseSource c;
  c.name = fs::absolute(directory).lexically_normal() / "<dict>";
  c.overrides = overrides;
  try {
    c.text = dict_to_toml(case_dict, c.name.string());
    c.config = io::parse_case(c.text, c.name, overrides);
  } catch (const InputError& e) {
    set_input_error(e.what(), {c.name.string()});
    throw py::error_already_set();
  }
  return c;
}

CaseSource with_overrides(const CaseSource& source, const std::vector<std::string>& more) {
  std::vector<std::string> all = source.overrides;
  all.insert(all.end(), more.begin(), more.end());
  if (source.path) return load_file_case(*source.path, all);
  CaseSource c = source;
  c.overrides = all;
  try {
    c.config = io::parse_case(c.text, c.name, all);
  } catch (const InputError& e) {
    set_input_error(e.what(), {c.name.string()});
    throw py::error_already_set();
  }
  return c;
}

py::object run_mesh(const CaseSource& c, const RunOptions& o) {
  std::optional<mesh::Mesh> m;
  return run_stage(
      c, o, "mesh", py::cast(MeshResult{}), [&](Context& ctx) { m = pipeline::obtain_mesh(ctx); },
      [&](const Context&, py::object& r, const py::dict&) {
        r.attr("nodes") = to_array<double>(m->nodes);
        r.attr("elements") = to_array<std::int64_t>(m->tets);
        r.attr("element_order") = m->element_order;
        r.attr("sectors") = m->sectors;
        py::dict sets, faces;
        for (const auto& [name, nodes] : m->node_sets) {
          py::array_t<std::int64_t> a(static_cast<py::ssize_t>(nodes.size()));
          std::copy(nodes.begin(), nodes.end(), a.mutable_data());
          sets[py::str(name)] = a;
        }
        for (const auto& [name, tri] : m->surface_triangles) faces[py::str(name)] = to_array<std::int64_t>(tri);
        r.attr("node_sets") = sets;
        r.attr("surface_triangles") = faces;
        r.attr("cyclic_pairs") = pairs_array(m->cyclic_pairs);
        r.attr("shroud_pairs") = pairs_array(m->shroud_pairs);
      });
}

py::object run_modes(const CaseSource& c, const RunOptions& o, bool shapes) {
  // What the stage computed, kept for the result (filled without the GIL).
  struct Modes {
    std::map<int, Eigen::VectorXd> frequency_hz;
    std::map<int, Eigen::MatrixXcd> shapes;  ///< 3 * n_nodes x modes, per harmonic index
    std::map<int, int> nodal_diameter;
    mesh::NodeMatrix nodes;
    std::vector<std::string> failures;
  } modes;
  const bool write_vtu = o.out.has_value();  // modes.vtu only for a folder someone reads
  return run_stage(
      c, o, "modes", py::cast(ModesResult{}),
      [&](Context& ctx) {
        // As `shroudsim modes` (app/cmd_modes.cpp), keeping the model for the result.
        const io::Case& cc = ctx.config;
        if (cc.structure.type != io::StructureType::sector)
          throw InputError(cc.where("structure.type") + ": structure.type = \"" + io::to_string(cc.structure.type) +
                           "\": `modes` needs an FE sector (structure.type = \"sector\")");
        pipeline::ModalModel model =
            pipeline::run_modal_stage(ctx, pipeline::modal_harmonic_indices(cc), 0.0, pipeline::case_shroud(cc));
        pipeline::write_modes_csv(ctx, model);
        if (write_vtu && !model.bases.empty()) pipeline::write_modes_vtu(ctx, model);
        for (const auto& [h, b] : model.bases) {
          modes.frequency_hz[h] = b.frequency_hz();
          modes.nodal_diameter[h] = cyclic::nodal_diameter(h, model.mesh.sectors);
          if (shapes) modes.shapes[h] = model.cyclic().expand(h, b.phi);
        }
        modes.nodes = model.mesh.nodes;
        modes.failures = model.failures;
        if (!model.failures.empty()) {
          std::string msg = "modal analysis failed for";
          for (const auto& f : model.failures) msg += "\n  " + f;
          throw NumericalError(msg + "\n(modes.csv holds the harmonic indices that converged)");
        }
        app::draw_plots(ctx);
      },
      [&](const Context&, py::object& r, const py::dict&) {
        py::array_t<std::int64_t> hs(static_cast<py::ssize_t>(modes.frequency_hz.size())),
            nds(static_cast<py::ssize_t>(modes.frequency_hz.size()));
        py::dict frequencies, shape_arrays;
        py::ssize_t i = 0;
        for (const auto& [h, f] : modes.frequency_hz) {
          hs.mutable_at(i) = h;
          nds.mutable_at(i) = modes.nodal_diameter.at(h);
          ++i;
          frequencies[py::int_(h)] = vector_array(f);
          if (!shapes) continue;
          // (mode, node, direction): DOF 3 * node + direction of the expanded mode.
          const Eigen::MatrixXcd& u = modes.shapes.at(h);
          const auto n_nodes = static_cast<py::ssize_t>(u.rows() / 3);
          py::array_t<std::complex<double>> a({static_cast<py::ssize_t>(u.cols()), n_nodes, py::ssize_t{3}});
          auto v = a.mutable_unchecked<3>();
          for (py::ssize_t r_ = 0; r_ < u.cols(); ++r_)
            for (py::ssize_t n = 0; n < n_nodes; ++n)
              for (py::ssize_t k = 0; k < 3; ++k) v(r_, n, k) = u(3 * n + k, r_);
          shape_arrays[py::int_(h)] = a;
        }
        r.attr("harmonic_indices") = hs;
        r.attr("nodal_diameters") = nds;
        r.attr("frequencies_hz") = frequencies;
        r.attr("shapes") = shapes ? py::object(shape_arrays) : py::object(py::none());
        r.attr("nodes") = to_array<double>(modes.nodes);
        py::list failures;
        for (const auto& f : modes.failures) failures.append(py::str(f));
        r.attr("failures") = failures;
      });
}

py::object run_campbell(const CaseSource& c, const RunOptions& o) {
  return run_stage(
      c, o, "campbell", py::cast(CampbellResult{}), [](Context& ctx) { app::cmd_campbell(ctx); },
      [](const Context&, py::object& r, const py::dict& tables) {
        for (const char* t : {"campbell", "crossings", "modes"})
          r.attr(t) = tables.contains(t) ? py::object(tables[t]) : py::object(py::none());
      });
}

py::object run_static_contact(const CaseSource& c, const RunOptions& o) {
  return run_stage(
      c, o, "static", py::cast(StaticContactResult{}), [](Context& ctx) { app::cmd_static(ctx); },
      [](const Context&, py::object& r, const py::dict& tables) {
        r.attr("pairs") = tables.contains("static_contact") ? py::object(tables["static_contact"]) : py::none();
        const py::dict report = r.attr("report");
        r.attr("summary") = report.contains("static") ? py::object(report["static"]) : py::none();
      });
}

py::object run_frf(const CaseSource& c, const RunOptions& o) {
  return run_stage(
      c, o, "frf", py::cast(FrfResult{}), [](Context& ctx) { app::cmd_frf(ctx); },
      [](const Context&, py::object& r, const py::dict& tables) {
        const py::module_ np = py::module_::import("numpy");
        for (const char* name : {"frequency_hz", "amplitude_m", "linear_amplitude_m", "newton_iterations", "piece"})
          r.attr(name) = column(tables, "frf", name);
        // h0_m .. hH_m side by side: (points, H + 1).
        py::list harmonics;
        for (int n = 0;; ++n) {
          // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on "h" + s + "_m".
          std::string name = std::to_string(n);
          name.insert(0, 1, 'h');
          name.append("_m");
          const py::object h = column(tables, "frf", name.c_str());
          if (h.is_none()) break;
          harmonics.append(h);
        }
        r.attr("harmonic_amplitudes_m") = harmonics.empty() ? py::object(py::none())
                                                            : np.attr("column_stack")(harmonics);
        r.attr("columns") = tables.contains("frf") ? py::object(tables["frf"]) : py::none();
        r.attr("peaks") = tables.contains("peaks") ? py::object(tables["peaks"]) : py::none();
        const py::dict report = r.attr("report");
        const py::dict frf = report.contains("frf") ? py::dict(report["frf"]) : py::dict();
        for (const char* name : {"peak_frequency_hz", "peak_amplitude_m"})
          r.attr(name) = frf.contains(name) ? py::object(frf[name]) : py::none();
        // loops.csv: rows by pair, then time sample -> (pair, sample, direction).
        r.attr("loops") = tables.contains("loops") ? py::object(tables["loops"]) : py::none();
        r.attr("loop_displacement_m") = py::none();
        r.attr("loop_force_n") = py::none();
        const py::object pair = column(tables, "loops", "pair");
        if (!pair.is_none() && py::len(pair) > 0) {
          const py::ssize_t pairs = np.attr("unique")(pair).attr("size").cast<py::ssize_t>();
          const py::ssize_t samples = static_cast<py::ssize_t>(py::len(pair)) / pairs;
          auto stack = [&](const char* a, const char* b, const char* cc) {
            py::list cols;
            for (const char* name : {a, b, cc}) cols.append(column(tables, "loops", name));
            return np.attr("column_stack")(cols).attr("reshape")(pairs, samples, 3);
          };
          r.attr("loop_displacement_m") = stack("x_m", "y_m", "z_m");
          r.attr("loop_force_n") = stack("tx_n", "ty_n", "n_n");
        }
      });
}

py::object run_all(const CaseSource& c, const RunOptions& o) {
  return run_stage(
      c, o, "run", py::cast(RunResult{}),
      [](Context& ctx) {
        const int status = app::cmd_run(ctx);
        if (status != 0) throw NumericalError("run: exit status " + std::to_string(status));
      },
      [](const Context&, py::object&, const py::dict&) {});
}

}  // namespace shroudsim::python
