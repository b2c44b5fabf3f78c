// A results folder is one run (io/results_folder.hpp): killed runs leave the old folder,
// concurrent runs into one folder are refused, bad input and bad --out touch nothing.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

namespace fs = std::filesystem;

const char* kQuickCase = R"(name = "coarse"
[geometry]
element_order = 1
mesh_size = 0.025
[modal]
modes = 6
harmonic_indices = [0, 1]
[campbell]
speed_points = 3
engine_orders = [1]
[hbm]
harmonics = 1
time_samples = 64
[contact]
pairs = 3
[continuation]
frequency_start_hz = 96.0
frequency_end_hz = 110.0
)";

// Every file of a folder (relative name -> content).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return files;
}

TEST(CliResults, AKilledRunLeavesTheOldFolderWhole) {
  Scratch s("results_kill");
  s.write("c.toml", kQuickCase);
  ASSERT_EQ(s.run("run c.toml --out r --quiet").status, 0);
  const auto old = snapshot(s.dir() / "r");
  ASSERT_GT(old.size(), 8u);
  // The second run differs (another frequency range): killed at several instants of the
  // pipeline (mesh and modes cached: modes, campbell, forced response, plots), the folder is
  // the old run, file for file; a run that got to the end is the new run, whole.
  int old_seen = 0, new_seen = 0;
  for (const char* at : {"0.3", "1.0", "2.0", "30"}) {
    // Scratch::run prefixes the executable: a harmless --version, then the timed run.
    const CliResult r = s.run(std::string("--version >/dev/null; timeout -s KILL ") + at +
                              " '" SHROUDSIM_EXE
                              "' run c.toml --set continuation.frequency_end_hz=109.0 --out r --quiet; true");
    (void)r;
    const auto now = snapshot(s.dir() / "r");
    if (now == old) {
      ++old_seen;
    } else {
      ++new_seen;
      EXPECT_NE(now.at("run.json").find("\"status\": \"ok\""), std::string::npos) << at;
      EXPECT_NE(now.at("run.json").find("109"), std::string::npos) << at;
      EXPECT_EQ(now.count("frf.csv"), 1u) << at;
      EXPECT_EQ(now.count("modes.csv"), 1u) << at;
      EXPECT_NE(now.at("frf.csv"), old.at("frf.csv")) << at;
      break;  // later kills would compare against the new run
    }
  }
  EXPECT_GT(old_seen, 0);
  EXPECT_EQ(new_seen, 1);  // the 30 s run finishes
  // Killed runs' staging folders are removed by the next run into the folder.
  ASSERT_EQ(s.run("run c.toml --out r --quiet").status, 0);
  for (const auto& e : fs::directory_iterator(s.dir()))
    EXPECT_EQ(e.path().filename().string().find(".staging-"), std::string::npos) << e.path();
}

TEST(CliResults, ASecondRunIntoTheSameFolderIsRefusedWhileTheFirstWrites) {
  Scratch s("results_lock");
  s.write("c.toml", kQuickCase);
  ASSERT_EQ(s.run("mesh c.toml --out m --quiet").status, 0);
  std::thread first([&] { EXPECT_EQ(s.run("run c.toml --out r --quiet").status, 0); });
  // Wait until the first run holds the folder (its staging folder exists).
  bool started = false;
  for (int i = 0; i < 200 && !started; ++i) {
    for (const auto& e : fs::directory_iterator(s.dir()))
      if (e.path().filename().string().rfind(".r.staging-", 0) == 0) started = true;
    if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(started);
  const CliResult second = s.run("frf c.toml --out r --quiet");
  first.join();
  EXPECT_EQ(second.status, 2);
  EXPECT_NE(second.err.find("another shroudsim run is writing this results folder"), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("--out"), std::string::npos) << second.err;
  const std::string run_json = slurp(s.dir() / "r" / "run.json");
  EXPECT_NE(run_json.find("\"command\": \"run\""), std::string::npos);
}

TEST(CliResults, BadOutAndBadInputTouchNothing) {
  Scratch s("results_bad");
  s.write("c.toml", kQuickCase);
  s.write("a_file", "user data\n");
  s.write("mine/notes.txt", "user data\n");
  for (const char* out : {"a_file", "mine", "/proc/self/fakedir", "/dev/null"}) {
    const CliResult r = s.run(std::string("modes c.toml --out ") + out);
    EXPECT_EQ(r.status, 2) << out;
    EXPECT_NE(r.err.find("--out"), std::string::npos) << out << ": " << r.err;
    EXPECT_FALSE(fs::exists(s.dir() / "meshes")) << out << ": work started before --out was checked";
  }
  EXPECT_EQ(slurp(s.dir() / "a_file"), "user data\n");
  EXPECT_EQ(slurp(s.dir() / "mine" / "notes.txt"), "user data\n");
  // A case name too long for a folder name: refused before any work, naming the folder.
  s.write("long.toml", "name = \"" + std::string(240, 'x') + "\"\n");
  const CliResult lng = s.run("modes long.toml");
  EXPECT_EQ(lng.status, 2);
  EXPECT_NE(lng.err.find("characters"), std::string::npos) << lng.err;
  // A bad key that is only checked after the modal stage (the excitation point on the hub)
  // leaves the earlier run's folder as it was.
  ASSERT_EQ(s.run("run c.toml --out r --quiet").status, 0);
  const auto old = snapshot(s.dir() / "r");
  const CliResult bad = s.run("run c.toml --set 'excitation.point=[0.0, 0.1, 0.0]' --out r --quiet");
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_EQ(snapshot(s.dir() / "r"), old);
  // ... and is checked before the modal stage (no modes line in the progress output), as is
  // a contact.pairs above the face's node pairs.
  for (const char* set : {"'excitation.point=[0.0, 0.1, 0.0]'", "contact.pairs=100000"}) {
    const CliResult early = s.run(std::string("run c.toml --set ") + set + " --set modal.modes=5 --out r");
    EXPECT_EQ(early.status, 2) << early.err;
    EXPECT_EQ(early.err.find("modes h ="), std::string::npos) << set << ": " << early.err;
    EXPECT_EQ(snapshot(s.dir() / "r"), old);
  }
}

// A cache entry with a changed byte (K and M, and the modes of a harmonic index; at the
// start, the middle and the end of the file) is reported and recomputed: the results are
// those of a clean run. Not byte for byte: a mode solved alone or beside another harmonic
// index's solve (threads) differs at round-off, ~1e-15; a corrupted entry used would
// differ at O(1) (or by the changed byte's weight).
std::vector<double> frequencies(const std::string& modes_csv) {
  std::vector<double> f;
  std::istringstream in(modes_csv);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) f.push_back(std::stod(line.substr(line.rfind(',') + 1)));
  return f;
}

TEST(CliResults, CorruptedCacheEntriesAreRecomputedNotUsed) {
  constexpr double kRoundOff = 1e-12;
  Scratch s("results_cache");
  s.write("c.toml", kQuickCase);
  ASSERT_EQ(s.run("modes c.toml --out clean --quiet").status, 0);
  const std::string clean = slurp(s.dir() / "clean" / "modes.csv");
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(s.dir() / ".cache")) entries.push_back(e.path());
  ASSERT_GE(entries.size(), 2u);  // modes of h = 0 and 1 (K and M are not cached)
  int runs = 0;
  for (const auto& file : entries)
    for (double where : {0.1, 0.5, 0.999}) {
      std::string bytes = slurp(file);
      const std::size_t at = static_cast<std::size_t>(where * static_cast<double>(bytes.size() - 1));
      bytes[at] = static_cast<char>(bytes[at] ^ 0x01);
      std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
      const CliResult r = s.run("modes c.toml --out again");
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_NE(r.err.find("is corrupt"), std::string::npos) << file << " byte " << at << ": " << r.err;
      EXPECT_NE(r.err.find("recomputing"), std::string::npos);
      const auto a = frequencies(clean), b = frequencies(slurp(s.dir() / "again" / "modes.csv"));
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < a.size(); ++i)
        EXPECT_NEAR(b[i], a[i], kRoundOff * a[i]) << file << " byte " << at << " mode row " << i;
      ++runs;
    }
  EXPECT_EQ(runs, 3 * static_cast<int>(entries.size()));
}

// The mesh as read and checked is cached under the .msh file's bytes: a run whose mesh is
// unchanged reads it back without loading gmsh (mesh/gmsh_module.hpp), and any change to
// the file reads it through gmsh again. The modes are those of the first reading.
TEST(CliResults, AnUnchangedMeshIsReadBackWithoutGmsh) {
  Scratch s("results_mesh_cache");
  s.write("c.toml", kQuickCase);
  ASSERT_EQ(s.run("mesh c.toml --out m --quiet").status, 0);
  const std::string made = slurp(s.dir() / "m" / "run.json");
  EXPECT_NE(made.find("\"read_from\": \"gmsh\""), std::string::npos) << made;
  EXPECT_NE(made.find("\"gmsh_module\": \"/"), std::string::npos) << made;  // generated: gmsh loaded

  ASSERT_EQ(s.run("modes c.toml --out a --quiet").status, 0);
  const std::string cached = slurp(s.dir() / "a" / "run.json");
  EXPECT_NE(cached.find("\"read_from\": \"cache\""), std::string::npos) << cached;
  EXPECT_NE(cached.find("\"gmsh_module\": null"), std::string::npos) << cached;

  // One byte more (a blank line at the end: the same mesh to gmsh): read through gmsh again.
  const fs::path msh = s.dir() / "meshes" / "coarse.msh";
  ASSERT_TRUE(fs::exists(msh));
  std::ofstream(msh, std::ios::app) << "\n";
  ASSERT_EQ(s.run("modes c.toml --out b --quiet").status, 0);
  const std::string reread = slurp(s.dir() / "b" / "run.json");
  EXPECT_NE(reread.find("\"read_from\": \"gmsh\""), std::string::npos) << reread;
  EXPECT_NE(reread.find("\"gmsh_module\": \"/"), std::string::npos) << reread;
  EXPECT_EQ(slurp(s.dir() / "b" / "modes.csv"), slurp(s.dir() / "a" / "modes.csv"));
}

// --no-plots: the same result files, no PNG, no plotting process, and run.json says why.
TEST(CliResults, NoPlotsWritesTheSameResultsWithoutPictures) {
  Scratch s("results_no_plots");
  s.write("c.toml", kQuickCase);
  ASSERT_EQ(s.run("modes c.toml --out a --quiet").status, 0);
  ASSERT_EQ(s.run("modes c.toml --out b --quiet --no-plots").status, 0);
  EXPECT_EQ(slurp(s.dir() / "b" / "modes.csv"), slurp(s.dir() / "a" / "modes.csv"));
  EXPECT_TRUE(fs::exists(s.dir() / "b" / "modes.vtu"));
  for (const auto& e : fs::directory_iterator(s.dir() / "b")) EXPECT_NE(e.path().extension(), ".png") << e.path();
  const std::string run = slurp(s.dir() / "b" / "run.json");
  EXPECT_NE(run.find("\"reason\": \"--no-plots\""), std::string::npos) << run;
  EXPECT_NE(run.find("\"drawn\": false"), std::string::npos) << run;
  // With plots, the run that drew them says so (or that matplotlib is missing: then no reason).
  const std::string drew = slurp(s.dir() / "a" / "run.json");
  EXPECT_EQ(drew.find("--no-plots"), std::string::npos) << drew;
}

const char* kLumped = R"(name = "lumped"
[structure]
type = "lumped"
mass = [[1.0]]
stiffness = [[3947.8417604357433]]
damping = [[1.2566370614359172]]
[excitation]
force = 1.0
[contact]
model = "1d"
normal_preload = 1.0
friction_coefficient = 0.5
tangential_stiffness = 3947.8417604357433
[[contact.elements]]
x_dof = 0
[hbm]
harmonics = 3
time_samples = 64
[continuation]
frequency_start_hz = 5.0
frequency_end_hz = 25.0
)";

// Hostile inputs found by trying: each is exit 2 with a message naming what is wrong, and
// no work is done (no mesh generated, no results folder).
TEST(CliResults, HostileInputsExitTwoBeforeAnyWork) {
  Scratch s("results_hostile");
  s.write("c.toml", kQuickCase);
  s.write("l.toml", kLumped);
  struct Hostile {
    std::string args, expect;
  };
  const std::vector<Hostile> cases = {
      {"frf l.toml --set 'hbm.harmonics=3\ncontinuation.max_points=1'", "line break"},  // a real newline
      {"frf /dev/zero", "not a regular file"},
      {"mesh c.toml --set geometry.mesh_size=1e-3", "geometry.max_elements"},
      {"frf l.toml --set 'structure.damping=[[-0.1]]'", "positive semidefinite"},
      {"frf l.toml --set 'structure.stiffness=[[-1.0]]'", "positive semidefinite"},
      {"frf l.toml --set excitation.force=0.0", "excitation.force is zero"},
  };
  for (const auto& h : cases) {
    const CliResult r = s.run(h.args + " --out r");
    EXPECT_EQ(r.status, 2) << h.args << ": " << r.err;
    EXPECT_NE(r.err.find(h.expect), std::string::npos) << h.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(s.dir() / "r")) << h.args;
    EXPECT_FALSE(fs::exists(s.dir() / "meshes")) << h.args;
  }
  // A mesh with a non-finite node coordinate: named, with the node and the file.
  ASSERT_EQ(s.run("mesh c.toml --out m --quiet").status, 0);
  std::string msh = slurp(s.dir() / "meshes" / "coarse.msh");
  const std::size_t nodes = msh.find("$Nodes");
  ASSERT_NE(nodes, std::string::npos);
  // The first coordinate line of the section: the first line after it holding a '.'.
  std::size_t line = msh.find('\n', nodes) + 1;
  while (msh.substr(line, msh.find('\n', line) - line).find('.') == std::string::npos) line = msh.find('\n', line) + 1;
  msh.replace(line, msh.find(' ', line) - line, "nan");
  s.write("nan.msh", msh);
  s.write("nan.toml", "name = \"nanmesh\"\n[structure]\nmesh = \"nan.msh\"\n");
  const CliResult r = s.run("mesh nan.toml --out n");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("non-finite coordinate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nan.msh"), std::string::npos) << r.err;
  // The program's own mesh, truncated on disk: regenerated with a warning, not blamed on
  // the user.
  const std::string whole = slurp(s.dir() / "meshes" / "coarse.msh");
  std::ofstream(s.dir() / "meshes" / "coarse.msh", std::ios::binary | std::ios::trunc)
      << whole.substr(0, whole.size() / 3);
  const CliResult again = s.run("mesh c.toml --out m");
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find("regenerating"), std::string::npos) << again.err;
  EXPECT_EQ(slurp(s.dir() / "meshes" / "coarse.msh"), whole);
}

}  // namespace
}  // namespace shroudsim::testing
