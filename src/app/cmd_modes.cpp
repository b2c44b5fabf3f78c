// `shroudsim modes`: the modal stage (pipeline/modal_stage.hpp) for the case's harmonic
// indices -> modes.csv (the nodal diameter map), modes.vtu, nd_map.png; and the plots of
// every command (draw_plots).
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>

#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include "app/context.hpp"
#include "core/error.hpp"
#include "core/log.hpp"

#ifndef SHROUDSIM_SOURCE_DIR
#define SHROUDSIM_SOURCE_DIR "."
#endif

extern char** environ;

namespace shroudsim::app {

namespace fs = std::filesystem;

namespace {

/// The plotting script: beside an installed program (<prefix>/bin/shroudsim ->
/// <prefix>/share/shroudsim/plot.py), else in the source tree the program was built from.
fs::path plot_script() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "shroudsim" / "plot.py";
    if (fs::exists(installed, ec)) return installed;
  }
  return fs::path(SHROUDSIM_SOURCE_DIR) / "tools" / "plot.py";
}

/// Starts argv[0] with these arguments (no shell: paths with quotes or spaces pass
/// unchanged) and the given file actions (may be null); its pid, or -1 when it could not start.
pid_t spawn(const std::vector<std::string>& args, const posix_spawn_file_actions_t* actions) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  return posix_spawn(&pid, argv[0], actions, nullptr, argv.data(), environ) == 0 ? pid : -1;
}

/// Waits for the child `pid`: its exit status, or -1 (killed by a signal, or not waitable).
int wait_exit_status(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// Runs the program to its end: its exit status, or -1 when it could not start.
int run_program(const std::vector<std::string>& args) {
  const pid_t pid = spawn(args, nullptr);
  return pid < 0 ? -1 : wait_exit_status(pid);
}

const std::string kPython = "/usr/bin/python3";

/// The plotting process an EarlyPlotter started: `plot.py --wait`, its stdin a pipe.
struct WaitingPlotter {
  pid_t pid = -1;
  int pipe = -1;  ///< write end
  /// Ends it without plots: its stdin closed (it then exits at once, or after its imports).
  void cancel() {
    if (pid <= 0) return;
    ::close(pipe);
    ::kill(pid, SIGTERM);
    wait_exit_status(pid);
    pid = -1;
  }
  /// Sends the arguments (one per line) and closes its stdin: it draws from then on. False
  /// when it could not be told.
  bool send(const std::vector<std::string>& args) {
    std::string text;
    for (const auto& a : args) text += a + "\n";
    // A plotter that died early must not take this process with it (SIGPIPE).
    struct sigaction ignore {
    }, before{};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGPIPE, &ignore, &before);
    bool sent = true;
    for (std::size_t done = 0; done < text.size();) {
      const ssize_t n = ::write(pipe, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        sent = false;
        break;
      }
      done += static_cast<std::size_t>(n);
    }
    ::close(pipe);
    ::sigaction(SIGPIPE, &before, nullptr);
    return sent;
  }
  /// Waits for it after send(): its exit status, -1 when it was not told (`sent` false).
  int wait(bool sent) {
    const int status = wait_exit_status(pid);
    pid = -1;
    return sent ? status : -1;
  }
};

WaitingPlotter g_plotter;  // one command per process: at most one

}  // namespace

EarlyPlotter::EarlyPlotter() {
  const fs::path script = plot_script();
  if (!fs::exists(kPython) || !fs::exists(script) || g_plotter.pid > 0) return;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return;  // later children (gmsh, ...) must not hold it open
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  const pid_t pid = spawn({kPython, script.string(), "--wait"}, &actions);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (pid < 0) {
    ::close(fds[1]);
    return;
  }
  g_plotter.pid = pid;
  g_plotter.pipe = fds[1];
}

EarlyPlotter::~EarlyPlotter() { g_plotter.cancel(); }

void draw_plots(Context& ctx, const std::function<void()>& meanwhile) {
  auto run_meanwhile = [&]() {
    if (meanwhile) meanwhile();
  };
  if (!ctx.plots) {  // study points: the study plots once at the end
    run_meanwhile();
    return;
  }
  if (ctx.no_plots) {
    auto& section = ctx.report.section("plots");
    section["drawn"] = false;
    section["reason"] = "--no-plots";
    run_meanwhile();
    return;
  }
  const fs::path script = plot_script();
  const std::string& python = kPython;
  auto skipped = [&]() {
    log::info("plots skipped (needs /usr/bin/python3 with matplotlib and " + script.string() + ")");
    ctx.report.section("plots")["drawn"] = false;
  };
  if (!fs::exists(python) || !fs::exists(script)) {
    run_meanwhile();
    skipped();
    return;
  }
  std::vector<std::string> args{python, script.string(), ctx.out_dir.string()};
  // The shroud state in the titles of nd_map.png and campbell.png: the Campbell stage's when
  // there is one (in `run`, the forced response's open modal model comes after it).
  const nlohmann::json& j = ctx.report.json();
  for (const char* section : {"campbell", "modal"})
    if (j.contains(section) && j[section].contains("shroud")) {
      args.push_back("--shroud");
      args.push_back(j[section]["shroud"].get<std::string>());
      break;
    }
  // One interpreter start: the script itself says when matplotlib is missing. Started early
  // (EarlyPlotter), it has imported matplotlib by now, is given the arguments only and draws
  // while `meanwhile` runs here.
  constexpr int kNoMatplotlib = 3;  // tools/plot.py NO_MATPLOTLIB
  int rc = -1;
  if (g_plotter.pid > 0) {
    const bool sent = g_plotter.send(std::vector<std::string>(args.begin() + 2, args.end()));
    try {
      run_meanwhile();
    } catch (...) {
      g_plotter.wait(sent);  // no plotter left behind; the error is what the command reports
      throw;
    }
    rc = g_plotter.wait(sent);
  } else {
    run_meanwhile();
    rc = run_program(args);
  }
  if (rc == kNoMatplotlib) {
    skipped();
    return;
  }
  ctx.report.section("plots")["drawn"] = rc == 0;
  if (rc != 0) {
    std::string cmd;
    for (const auto& a : args) cmd += (cmd.empty() ? "" : " ") + a;
    ctx.report.warn("plotting failed (exit " + std::to_string(rc) + ": " + cmd + ")");
  }
}

int cmd_modes(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\": `modes` needs an FE sector (structure.type = \"sector\")");
  ModalModel model = run_modal_stage(ctx, modal_harmonic_indices(c), 0.0, case_shroud(c));
  write_modes_csv(ctx, model);
  auto write_vtu = [&]() {
    if (!model.bases.empty()) write_modes_vtu(ctx, model);
  };
  if (!model.failures.empty()) {
    write_vtu();
    std::string msg = "modal analysis failed for";
    for (const auto& f : model.failures) msg += "\n  " + f;
    throw NumericalError(msg + "\n(modes.csv holds the harmonic indices that converged)");
  }
  // nd_map.png needs modes.csv only: it is drawn while modes.vtu is written.
  draw_plots(ctx, write_vtu);
  return 0;
}

}  // namespace shroudsim::app
