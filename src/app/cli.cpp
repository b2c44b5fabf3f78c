#include "app/cli.hpp"

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <ctime>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string_view>

#include "app/context.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "distributed/task_pool.hpp"
#include "io/case.hpp"
#include "io/output.hpp"
#include "io/results_folder.hpp"
#include "io/schema.hpp"
#include "mesh/gmsh_module.hpp"
#include "modal/cache.hpp"
#include "pipeline/study_stage.hpp"

namespace shroudsim::app {
namespace {

struct CommonOptions {
  std::string case_file;
  std::vector<std::string> sets;
  std::string out;
  bool quiet = false;
  bool verbose = false;
  int threads = 0;
  bool no_plots = false;
  double cache_limit_gib = static_cast<double>(modal::kDefaultCacheLimitBytes) / (1ull << 30);
  bool convergence = false;  ///< study only
  bool resume = false;       ///< study only
};

void add_common(CLI::App* sub, CommonOptions& o) {
  sub->add_option("case", o.case_file, "case file (TOML)")->required();
  sub->add_option("--set", o.sets, "override a case key: KEY=VALUE (dotted key, TOML value); repeatable")
      ->type_name("KEY=VALUE")
      ->take_all();
  sub->add_option("--out", o.out, "result folder (default results/<name>)");
  sub->add_flag("--quiet,-q", o.quiet, "no progress output");
  sub->add_flag("--verbose,-v", o.verbose, "a line per continuation point instead of one progress line");
  sub->add_option("--threads", o.threads, "worker threads (default: all cores)")->check(CLI::Range(0, 1024));
  sub->add_option("--cache-limit", o.cache_limit_gib,
                  "GiB kept in the case folder's .cache: after a stage writes an entry, the least recently used "
                  "ones are deleted down to this (default 10)")
      ->check(CLI::Range(0.0, 1e6));
  sub->add_flag("--no-plots", o.no_plots,
                "write the result files only: no plotting process is started and no PNG is drawn (the plot's "
                "Python and matplotlib cost about 0.5 s of a core per command)");
}

std::string now_utc() {
  const auto t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::ostringstream s;
  s << std::put_time(std::gmtime(&t), "%Y-%m-%dT%H:%M:%SZ");
  return s.str();
}

/// Writes run.json: the case as run, versions, stages, statistics, status.
void write_run_json(const Context& ctx, const std::string& command, const std::string& status,
                    const std::string& message) {
  const nlohmann::json j = run_report(ctx, command, status, message);
  io::write_file_atomic(ctx.out_dir / "run.json", j.dump(2) + "\n");
}

void print_summary(const Context& ctx, const std::string& command, double seconds) {
  if (!log::verbose()) return;
  std::ostringstream s;
  s << std::fixed << std::setprecision(2) << command << " finished in " << seconds << " s";
  if (ctx.report.json().contains("stages")) {
    // Once per stage, in the order they first ran: a stage that ran several times (the
    // modal stage at each speed of a Campbell sweep) shows its total time and count.
    struct Total {
      std::string name;
      double seconds = 0.0;
      int runs = 0, reused = 0;
    };
    std::vector<Total> totals;
    for (const auto& st : ctx.report.json()["stages"]) {
      const std::string name = st["name"].get<std::string>();
      auto it = std::find_if(totals.begin(), totals.end(), [&](const Total& t) { return t.name == name; });
      if (it == totals.end()) it = totals.insert(totals.end(), Total{name});
      it->seconds += st["seconds"].get<double>();
      ++it->runs;
      it->reused += st["reused"].get<bool>() ? 1 : 0;
    }
    s << " (";
    for (std::size_t i = 0; i < totals.size(); ++i) {
      const Total& t = totals[i];
      s << (i ? ", " : "") << t.name << " " << t.seconds << " s";
      if (t.runs > 1) s << " x" << t.runs;
      if (t.reused == t.runs) s << " reused";
      else if (t.reused > 0) s << " (" << t.reused << " reused)";
    }
    s << ")";
  }
  s << "; results in " << ctx.out_dir.string();
  log::info(s.str());
}

}  // namespace

nlohmann::json run_report(const Context& ctx, const std::string& command, const std::string& status,
                          const std::string& message) {
  nlohmann::json j = ctx.report.json();
  j["command"] = command;
  j["status"] = status;
  if (!message.empty()) j["message"] = message;
  j["case_file"] = ctx.config.file.string();
  j["case"] = nlohmann::json::parse(ctx.config.resolved_json);
  j["finished_utc"] = now_utc();
  j["total_seconds"] = ctx.report.total_seconds();
  j["peak_memory_mib"] = log::peak_memory_mib();
  // null: no mesh was read or made with gmsh (the mesh cache served it, or no mesh)
  const std::filesystem::path gmsh = mesh::detail::gmsh_module_path();
  j["gmsh_module"] = gmsh.empty() ? nlohmann::json() : nlohmann::json(gmsh.string());
  j["versions"] = {{"shroudsim", SHROUDSIM_VERSION},
                   {"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) + "." +
                                 std::to_string(EIGEN_MINOR_VERSION)},
                   {"compiler", __VERSION__}};
  return j;
}

int run_cli(int argc, char** argv) {
  CLI::App app{"shroudsim: friction damping of shrouded bladed disks (cyclic FE + multiharmonic balance)"};
  app.require_subcommand(0, 1);
  bool print_defaults = false, print_reference = false, version = false;
  app.add_flag("--print-defaults", print_defaults, "print a complete commented case file with every default");
  app.add_flag("--print-case-reference", print_reference,
               "print the reference of every case key (Markdown: docs/case_keys.md)");
  app.add_flag("--version", version, "print the version");

  struct Sub {
    const char* name;
    const char* help;
    std::function<int(Context&)> run;
  };
  const std::vector<Sub> subs = {
      {"run", "every stage the case asks for, in order, reusing cached stages", cmd_run},
      {"mesh", "build the sector mesh with gmsh -> meshes/<name>.msh (or check a given mesh)", cmd_mesh},
      {"modes", "FE assembly, cyclic reduction, modes per harmonic index -> modes.csv", cmd_modes},
      {"campbell", "frequencies against speed with engine-order lines -> campbell.csv, crossings.csv", cmd_campbell},
      {"frf", "nonlinear forced response with continuation -> frf.csv", cmd_frf},
      {"nlmodes",
       "nonlinear mode (frequency and damping against amplitude, EPMC) of a lumped case and the forced responses "
       "synthesized from it -> nlmodes.csv, nlmodes_synthesis.csv",
       cmd_nlmodes},
      {"contact", "one contact pair under the prescribed motion of [motion] -> contact.json", cmd_contact},
      {"static",
       "shroud contact of the spinning sector (interference, friction) -> static_contact.csv, contact_static.vtu",
       cmd_static},
      {"study", "the case over the [study] sweep -> one folder per point and study.csv", cmd_study},
  };
  std::vector<CommonOptions> options(subs.size());
  std::vector<CLI::App*> commands;
  for (std::size_t i = 0; i < subs.size(); ++i) {
    CLI::App* sub = app.add_subcommand(subs[i].name, subs[i].help);
    add_common(sub, options[i]);
    if (std::string_view(subs[i].name) == "study")
      sub->add_flag("--convergence", options[i].convergence,
                    "vary every accuracy knob (mesh, modes, residual flexibility, H, N, update, model, Jacobian) "
                    "around the case against its finest value -> trade.csv, trade.png");
    if (std::string_view(subs[i].name) == "study")
      sub->add_flag("--resume", options[i].resume,
                    "start from what an interrupted (killed) or earlier study wrote into the results folder: its "
                    "finished points whose run.json holds the same case are reused, the others run");
    commands.push_back(sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "shroudsim: error: " << e.what() << " (shroudsim --help lists the commands and options)\n";
    return 2;
  }
  if (print_defaults) {
    std::cout << io::default_case_text();
    return 0;
  }
  if (print_reference) {
    std::cout << io::case_reference_markdown();
    return 0;
  }
  if (version) {
    std::cout << "shroudsim " << SHROUDSIM_VERSION << "\n";
    return 0;
  }
  std::size_t chosen = subs.size();
  for (std::size_t i = 0; i < subs.size(); ++i)
    if (commands[i]->parsed()) chosen = i;
  if (chosen == subs.size()) {
    std::cerr << app.help();
    return 2;
  }
  const CommonOptions& o = options[chosen];
  const std::string command = subs[chosen].name;
  // Under an MPI launcher (`mpirun -n K`): only `study` shares its work; rank 0 reads the
  // case, owns the results folder and prints, the other ranks serve its points
  // (pipeline::serve_study) in its staging folder.
  distributed::World& world = distributed::world();
  const bool root = world.rank() == 0;
  if (world.distributed() && command != "study") {
    if (root)
      std::cerr << "shroudsim: error: " << command << " runs as one process; only `study` shares its points over "
                << world.size() << " MPI ranks (run it without mpirun)\n";
    return 2;
  }
  log::set_verbose(!o.quiet && root);
  log::set_detailed(o.verbose && !o.quiet && root);
  modal::set_cache_limit(static_cast<std::uintmax_t>(o.cache_limit_gib * static_cast<double>(1ull << 30)));
  log::Stopwatch clock;

  Context ctx;
  std::string error;
  try {
    ctx.config = io::load_case(o.case_file, o.sets);
  } catch (const InputError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = o.case_file + ": " + e.what();
  }
  if (!world.all_ok(error.empty())) {
    // Rank 0 says why; another rank only when rank 0 could read the case (a file system
    // that differs between nodes).
    const bool root_ok = world.broadcast(error.empty() ? "ok" : "") == "ok";
    if (!error.empty() && (root || root_ok))
      std::cerr << "shroudsim: error: " << (root ? "" : "rank " + std::to_string(world.rank()) + ": ") << error << "\n";
    return 2;
  }
  const int threads = o.threads > 0 ? o.threads : world.distributed() ? world.default_threads() : 0;
  if (!root) {
    // A serving rank: the points go into rank 0's staging folder ("" when rank 0 refused it).
    const std::string staging = world.broadcast("");
    if (staging.empty()) return 2;
    return pipeline::serve_study(threads, cmd_run, cmd_frf);
  }
  // Rank 0 releases the serving ranks whatever happens below, with its exit status.
  int status = 1;
  struct Release {
    distributed::World& world;
    const int& status;
    ~Release() { world.release(status); }
  } release{world, status};
  // The results folder: checked and locked before any work, written through a staging
  // folder and replaced in one exchange at the end (io/results_folder.hpp).
  std::unique_ptr<io::ResultsFolder> folder;
  try {
    folder = std::make_unique<io::ResultsFolder>(
        o.out.empty() ? std::filesystem::path("results") / ctx.config.name : std::filesystem::path(o.out),
        o.out.empty() ? "results folder (results/<name>)" : "--out", o.resume);
  } catch (const InputError& e) {
    world.broadcast("");
    std::cerr << "shroudsim: error: " << e.what() << "\n";
    return status = 2;
  }
  world.broadcast(std::filesystem::absolute(folder->staging()).string());
  if (world.distributed())
    log::info("study: " + std::to_string(world.size()) + " MPI ranks; " + std::to_string(threads) +
              (threads == 1 ? " worker" : " workers") + " on rank 0 (--threads sets the workers of each rank)");
  ctx.out_dir = folder->staging();
  ctx.threads = threads;
  ctx.overrides = o.sets;
  ctx.convergence = o.convergence;
  ctx.resume = o.resume;
  ctx.no_plots = o.no_plots;
  if (o.resume)
    log::info("study --resume: " + (folder->resumed_from().empty() ? std::string("nothing to resume from")
                                                                   : "from " + folder->resumed_from()));

  // Python and matplotlib load while the command computes (every command but `mesh` plots,
  // unless --no-plots).
  std::optional<EarlyPlotter> plotter;
  if (command != "mesh" && !o.no_plots) plotter.emplace();
  std::string state = "failed", message;
  try {
    status = subs[chosen].run(ctx);
    state = status == 0 ? "ok" : status == 3 ? "numerics_failed" : "failed";
  } catch (const InputError& e) {
    std::cerr << "shroudsim: error: " << e.what() << "\n";
    status = 2, state = "bad_input", message = e.what();
  } catch (const NumericalError& e) {
    std::cerr << "shroudsim: numerics failed: " << e.what() << "\n";
    status = 3, state = "numerics_failed", message = e.what();
  } catch (const std::exception& e) {
    std::cerr << "shroudsim: error: " << e.what() << "\n";
    status = 1, state = "failed", message = e.what();
  }
  // Bad input (and any other failure) leaves the results folder as it was; a run that
  // finished (0) or whose numerics failed with what it computed (3) replaces it.
  if (status == 0 || status == 3) {
    try {
      write_run_json(ctx, command, state, message);
      folder->commit();
    } catch (const std::exception& e) {
      std::cerr << "shroudsim: error: writing the results folder " << folder->target().string() << ": " << e.what()
                << "\n";
      status = 1;
    }
  }
  ctx.out_dir = folder->target();
  if (status == 0) print_summary(ctx, command, clock.seconds());
  return status;
}

}  // namespace shroudsim::app
