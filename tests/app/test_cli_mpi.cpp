// `mpirun -n K shroudsim study` through the real launcher (built when the build found MPI):
// the points shared over 2 and 3 ranks give the threaded run's study.csv (same points, same
// numbers: every column but the wall time), for a sweep and a sampled study; a point that
// fails is recorded with its reason while the others finish; a rank killed mid-study ends the
// job (no hang) without touching the results folder, and `--resume` reruns only the points
// that had not finished; other commands refuse to run on several ranks.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

namespace fs = std::filesystem;

std::string lumped_case(const std::string& extra) {
  return std::string(R"(name = "ranks"
[structure]
type = "lumped"
sectors = 1
mass = [[1.0]]
stiffness = [[3947.8417604357433]]
damping = [[1.2566370614359172]]
[excitation]
force = 0.5
[contact]
model = "1d"
friction_coefficient = 0.3
tangential_stiffness = 3947.8417604357433
normal_preload = 1.0
[[contact.elements]]
x_dof = 0
[hbm]
harmonics = 5
time_samples = 256
[continuation]
frequency_start_hz = 5.0
frequency_end_hz = 25.0
[study]
)") + extra;
}

const std::string kSweep =
    R"(vary = { "contact.friction_coefficient" = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6], "excitation.force" = [0.5, 1.0] })"
    "\n";

/// The launcher's environment: CI containers run as root (OpenMPI refuses root unless told),
/// and shared-memory transfers between processes without ptrace rights (CMA) are off.
void launcher_environment() {
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  ::setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
}

/// `mpirun -n RANKS shroudsim ARGS` in the scratch folder (oversubscribed: this machine may
/// have fewer cores than ranks).
CliResult mpirun(const Scratch& s, int ranks, const std::string& args) {
  launcher_environment();
  return s.run_command("'" SHROUDSIM_MPIEXEC "' --oversubscribe -n " + std::to_string(ranks) + " '" SHROUDSIM_EXE "' " +
                       args);
}

/// study.csv without its wall-time column (`seconds`), which differs from run to run.
std::string table_without_times(const fs::path& csv) {
  const auto rows = csv_rows(slurp(csv));
  std::size_t seconds = rows.at(0).size();
  for (std::size_t c = 0; c < rows[0].size(); ++c)
    if (rows[0][c] == "seconds") seconds = c;
  std::string out;
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c)
      if (c != seconds) out += row[c] + ",";
    out += "\n";
  }
  return out;
}

nlohmann::json run_json(const fs::path& folder) { return nlohmann::json::parse(slurp(folder / "run.json")); }

TEST(CliMpi, TwoAndThreeRanksGiveTheThreadedTable) {
  Scratch s("mpi_table");
  s.write("sweep.toml", lumped_case(kSweep));
  s.write("sampled.toml", lumped_case(R"(samples = 6
sample = { "contact.friction_coefficient" = { distribution = "uniform", min = 0.1, max = 0.6 } }
)"));
  for (const std::string name : {"sweep", "sampled"}) {
    SCOPED_TRACE(name);
    const CliResult threaded = s.run("study " + name + ".toml --threads 2 --out " + name + "_threads -q");
    ASSERT_EQ(threaded.status, 0) << threaded.err;
    const std::string reference = table_without_times(s.dir() / (name + "_threads") / "study.csv");
    for (const int ranks : {2, 3}) {
      SCOPED_TRACE(ranks);
      const std::string out = name + "_ranks" + std::to_string(ranks);
      const CliResult r = mpirun(s, ranks, "study " + name + ".toml --threads 1 --out " + out);
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_EQ(table_without_times(s.dir() / out / "study.csv"), reference);
      const auto j = run_json(s.dir() / out);
      EXPECT_EQ(j["study"]["ranks"], ranks);
      EXPECT_EQ(j["study"]["workers"], ranks);  // one thread per rank, every rank served
      // Every point was run by some rank into the shared folder, with its own run.json.
      const auto rows = csv_rows(slurp(s.dir() / out / "study.csv"));
      const std::size_t folder = std::find(rows[0].begin(), rows[0].end(), "folder") - rows[0].begin();
      ASSERT_LT(folder, rows[0].size());
      for (std::size_t i = 1; i < rows.size(); ++i)
        EXPECT_EQ(run_json(s.dir() / out / rows[i].at(folder))["status"], "ok") << rows[i].at(folder);
      EXPECT_NE(r.err.find("(rank "), std::string::npos) << "the point lines name their rank";
    }
  }
}

TEST(CliMpi, AFailedPointIsRecordedAndTheOthersFinish) {
  Scratch s("mpi_failed");
  // 10 points is too few for the curve: that point's continuation stops (exit 3 of its own).
  s.write("case.toml", lumped_case(R"(vary = { "continuation.max_points" = [10, 5000, 6000] })"
                                   "\n"));
  const CliResult r = mpirun(s, 2, "study case.toml --threads 1 --out out -q");
  EXPECT_EQ(r.status, 3) << r.err;
  const auto rows = csv_rows(slurp(s.dir() / "out" / "study.csv"));
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[1][1], "failed");
  EXPECT_EQ(rows[2][1], "ok");
  EXPECT_EQ(rows[3][1], "ok");
  const auto folder = std::find(rows[0].begin(), rows[0].end(), "folder") - rows[0].begin();
  ASSERT_LT(folder, static_cast<std::ptrdiff_t>(rows[0].size()));
  const auto failed = run_json(s.dir() / "out" / rows[1][static_cast<std::size_t>(folder)]);
  EXPECT_NE(failed.value("message", "").find("max_points"), std::string::npos) << failed.dump();
  EXPECT_EQ(run_json(s.dir() / "out")["study"]["failed"], 1);
}

TEST(CliMpi, OtherCommandsRefuseSeveralRanks) {
  Scratch s("mpi_refuse");
  s.write("case.toml", lumped_case(kSweep));
  const CliResult r = mpirun(s, 2, "frf case.toml --out out");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("only `study` shares its points"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(s.dir() / "out"));
  // A bad case: one message (rank 0's), exit 2, nothing written.
  const CliResult bad = mpirun(s, 2, "study missing.toml --out out");
  EXPECT_NE(bad.status, 0);
  EXPECT_NE(bad.err.find("missing.toml"), std::string::npos) << bad.err;
  EXPECT_EQ(bad.err.find("rank 1:"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(s.dir() / "out"));
}

/// The process of `rank` among those running in `dir` with `marker` on their command line.
int pid_of_rank(const std::string& marker, int rank) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string cmdline = slurp(e.path() / "cmdline"), environ = slurp(e.path() / "environ");
    if (cmdline.find(marker) == std::string::npos || cmdline.find("shroudsim") == std::string::npos) continue;
    if (environ.find("OMPI_COMM_WORLD_RANK=" + std::to_string(rank) + std::string(1, '\0')) != std::string::npos)
      return std::stoi(name);
  }
  return -1;
}

/// Point folders of the staging folders beside `target` with a finished (status ok) run.json.
int finished_points(const fs::path& parent) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(parent)) {
    if (e.path().filename().string().rfind(".killed.staging-", 0) != 0) continue;
    for (const auto& p : fs::directory_iterator(e.path())) {
      std::error_code ec;
      if (!fs::exists(p.path() / "run.json", ec)) continue;
      try {
        n += run_json(p.path())["status"] == "ok";
      } catch (const std::exception&) {
      }
    }
  }
  return n;
}

TEST(CliMpi, AKilledRankEndsTheJobAndResumeRerunsOnlyTheMissingPoints) {
  Scratch s("mpi_killed");
  // Points of about a second each (H = 15, N = 2048), 12 of them over 3 ranks.
  s.write("case.toml", lumped_case(kSweep));
  const std::string sets = " --set hbm.harmonics=15 --set hbm.time_samples=2048";
  ASSERT_EQ(s.run("study case.toml --threads 2 -q --out reference" + sets).status, 0);
  const std::string reference = table_without_times(s.dir() / "reference" / "study.csv");

  const std::string marker = (s.dir() / "killed").string();
  const std::string cmd = "cd '" + s.dir().string() +
                          "' && ('" SHROUDSIM_MPIEXEC "' --oversubscribe -n 3 '" SHROUDSIM_EXE
                          "' study case.toml --threads 1 --out '" +
                          marker + "'" + sets + " >killed.out 2>killed.err </dev/null; echo $? >killed.rc) &";
  launcher_environment();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  // Kill rank 2 once two points have finished (and before all have).
  const auto start = std::chrono::steady_clock::now();
  auto waited = [&] { return std::chrono::steady_clock::now() - start; };
  while (finished_points(s.dir()) < 2 && waited() < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const int victim = pid_of_rank(marker, 2);
  ASSERT_GT(victim, 0) << "rank 2 not found; the study may have finished already";
  ASSERT_EQ(::kill(victim, SIGKILL), 0);
  // The job ends, it does not hang: the launcher sees the dead rank and stops the others.
  while (!fs::exists(s.dir() / "killed.rc") && waited() < std::chrono::seconds(180))
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(fs::exists(s.dir() / "killed.rc")) << "the job hangs after a rank died";
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_NE(std::stoi(slurp(s.dir() / "killed.rc")), 0);
  EXPECT_NE(slurp(s.dir() / "killed.err").find("rank 2"), std::string::npos) << "the dead rank is reported";
  EXPECT_FALSE(fs::exists(s.dir() / "killed")) << "a killed study must not replace the results folder";
  const int finished = finished_points(s.dir());
  ASSERT_GE(finished, 2);
  ASSERT_LT(finished, 12);

  // Resumed on 2 ranks: the finished points are reused, only the others run, and the table
  // is the one run in one go.
  const CliResult resumed = mpirun(s, 2, "study case.toml --threads 1 --resume --out killed" + sets);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find(std::to_string(finished) + " of 12 points reused"), std::string::npos) << resumed.err;
  EXPECT_EQ(run_json(s.dir() / "killed")["study"]["reused_points"], finished);
  EXPECT_EQ(table_without_times(s.dir() / "killed" / "study.csv"), reference);
}

}  // namespace
}  // namespace shroudsim::testing
