// The command line as users drive it: exit statuses, one clear message per bad input
// (file, line, key), result files written atomically and never clobbered by bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

namespace fs = std::filesystem;

constexpr int kBadInput = 2;

/// A fast case: a coarse linear-tet sector.
const char* kCoarseCase = R"(name = "coarse"
[geometry]
element_order = 1
mesh_size = 0.025
)";

struct BadRun {
  const char* what;
  std::string case_text;
  std::string args;                   ///< extra arguments after the case file
  std::vector<std::string> expected;  ///< substrings of stderr
};

class BadInput : public ::testing::TestWithParam<BadRun> {};

TEST_P(BadInput, ExitsTwoWithOneMessageNamingLineAndKey) {
  const Scratch s(GetParam().what);
  s.write("case.toml", GetParam().case_text);
  const CliResult r = s.run("mesh case.toml " + GetParam().args);
  EXPECT_EQ(r.status, kBadInput) << r.err;
  for (const auto& part : GetParam().expected)
    EXPECT_NE(r.err.find(part), std::string::npos) << "'" << part << "' not in: " << r.err;
  // One message: a single line on stderr, no partial results.
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(s.dir() / "results" / "coarse" / "run.json"));
}

INSTANTIATE_TEST_SUITE_P(
    Cli, BadInput,
    ::testing::Values(
        BadRun{"syntax", "name = \"coarse\"\n[geometry\n", "", {"case.toml:2:", "TOML syntax error"}},
        BadRun{"unknown_key",
               "[geometry]\nmesh_sise = 0.02\n",
               "",
               {"case.toml:2:1", "unknown key 'geometry.mesh_sise'", "geometry.mesh_size"}},
        BadRun{"wrong_type",
               "[structure]\nsectors = \"eight\"\n",
               "",
               {"case.toml:2:11", "structure.sectors: expected an integer"}},
        BadRun{"negative_modulus",
               "[material]\nyoungs_modulus = -2e11\n",
               "",
               {"case.toml:2:18", "material.youngs_modulus", "violates: > 0"}},
        BadRun{"poisson",
               "[material]\npoisson_ratio = 0.5\n",
               "",
               {"case.toml:2:17", "material.poisson_ratio = 0.5", "< 0.5"}},
        BadRun{"zero_sectors", "[structure]\nsectors = 0\n", "", {"case.toml:2:11", "structure.sectors = 0"}},
        BadRun{"mesh_size_above_blade",
               "[geometry]\nmesh_size = 0.1\n",
               "",
               {"case.toml:2:13", "geometry.mesh_size = 0.1", "mesh_size <="}},
        BadRun{"missing_mesh",
               "[structure]\nmesh = \"meshes/none.msh\"\n",
               "",
               {"case.toml:2:8", "structure.mesh", "an existing mesh file"}},
        BadRun{
            "bad_set_value", "", "--set hbm.harmonics=0", {"--set hbm.harmonics=0", "hbm.harmonics = 0", "violates"}},
        BadRun{"bad_set_key", "", "--set contact.mu=0.2", {"--set contact.mu=0.2", "unknown key 'contact.mu'"}},
        BadRun{"samples",
               "[hbm]\nharmonics = 10\ntime_samples = 16\n",
               "",
               {"case.toml:3:16", "hbm.time_samples = 16", "(= 21)"}},
        BadRun{"blade_too_wide",
               "[geometry]\nblade_chord = 0.3\nblade_thickness = 0.01\n",
               "",
               {"case.toml:2:15", "geometry.blade_chord", "pitch"}}),
    [](const ::testing::TestParamInfo<BadRun>& info) { return std::string(info.param.what); });

TEST(Cli, UsageErrorsExitTwo) {
  const Scratch s("usage");
  EXPECT_EQ(s.run("").status, kBadInput);
  EXPECT_EQ(s.run("frobnicate case.toml").status, kBadInput);
  EXPECT_EQ(s.run("mesh").status, kBadInput);  // no case file
  const CliResult missing = s.run("mesh nowhere.toml");
  EXPECT_EQ(missing.status, kBadInput);
  EXPECT_NE(missing.err.find("nowhere.toml: case file does not exist"), std::string::npos) << missing.err;
}

TEST(Cli, PrintDefaultsIsAValidCaseFile) {
  const Scratch s("defaults");
  const CliResult r = s.run("--print-defaults");
  ASSERT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("[contact]"), std::string::npos);
  EXPECT_NE(r.out.find("tangential_update = \"exact_linear\""), std::string::npos);
  s.write("defaults.toml", r.out);
  // The printed file is accepted as it is (a mesh-free check: a bad key would exit 2).
  const CliResult check =
      s.run("mesh defaults.toml --quiet --set geometry.mesh_size=0.03 --set geometry.element_order=1");
  EXPECT_EQ(check.status, 0) << check.err;
}

TEST(Cli, MeshCommandWritesTheMeshAndRunJsonAndReusesIt) {
  const Scratch s("mesh");
  s.write("cases/coarse.toml", kCoarseCase);
  const CliResult first = s.run("mesh cases/coarse.toml");
  ASSERT_EQ(first.status, 0) << first.err;
  EXPECT_TRUE(fs::exists(s.dir() / "meshes" / "coarse.msh"));
  EXPECT_NE(first.err.find("DOFs"), std::string::npos) << first.err;  // progress on stderr
  const std::string run_json = slurp(s.dir() / "results" / "coarse" / "run.json");
  EXPECT_NE(run_json.find("\"status\": \"ok\""), std::string::npos) << run_json;
  EXPECT_NE(run_json.find("\"mesh_size\": 0.025"), std::string::npos) << "case as run is recorded";
  const CliResult second = s.run("mesh cases/coarse.toml --quiet");
  ASSERT_EQ(second.status, 0);
  EXPECT_TRUE(second.err.empty()) << "--quiet silences progress: " << second.err;
  EXPECT_NE(slurp(s.dir() / "results" / "coarse" / "run.json").find("\"reused\": true"), std::string::npos);
}

TEST(Cli, BadInputLeavesEarlierResultsUntouched) {
  const Scratch s("keep");
  s.write("case.toml", kCoarseCase);
  ASSERT_EQ(s.run("mesh case.toml --quiet").status, 0);
  const std::string before = slurp(s.dir() / "results" / "coarse" / "run.json");
  EXPECT_EQ(s.run("mesh case.toml --set material.density=-1").status, kBadInput);
  EXPECT_EQ(slurp(s.dir() / "results" / "coarse" / "run.json"), before);
}

TEST(Cli, GivenMeshIsCheckedAndItsProblemsNamed) {
  const Scratch s("given");
  s.write("gen.toml", kCoarseCase);
  ASSERT_EQ(s.run("mesh gen.toml --quiet").status, 0);
  // The same mesh read as an 8-sector mesh passes; as a 9-sector mesh its cyclic faces do not match.
  s.write("user.toml", "name = \"user\"\n[structure]\nmesh = \"meshes/coarse.msh\"\n");
  const CliResult ok = s.run("mesh user.toml");
  EXPECT_EQ(ok.status, 0) << ok.err;
  s.write("nine.toml", "name = \"user\"\n[structure]\nsectors = 9\nmesh = \"meshes/coarse.msh\"\n");
  const CliResult bad = s.run("mesh nine.toml");
  EXPECT_EQ(bad.status, kBadInput);
  EXPECT_NE(bad.err.find("nine.toml:4:8: structure.mesh"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("unmatched nodes between 'cyclic_low' and 'cyclic_high'"), std::string::npos) << bad.err;
  // Without the hub group.
  std::string text = slurp(s.dir() / "meshes" / "coarse.msh");
  text.replace(text.find("\"hub\""), 5, "\"bore\"");
  s.write("meshes/nohub.msh", text);
  s.write("nohub.toml", "name = \"user\"\n[structure]\nmesh = \"meshes/nohub.msh\"\n");
  const CliResult nohub = s.run("mesh nohub.toml");
  EXPECT_EQ(nohub.status, kBadInput);
  EXPECT_NE(nohub.err.find("nohub.toml:3:8: structure.mesh"), std::string::npos) << nohub.err;
  EXPECT_NE(nohub.err.find("missing 2D physical group(s): hub"), std::string::npos) << nohub.err;
}

}  // namespace
}  // namespace shroudsim::testing

namespace shroudsim::testing {
namespace {

/// 1-DOF oscillator with a Jenkins element (the lumped forced-response case).
const char* kLumpedCase = R"(name = "jenkins"
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
tangential_stiffness = 3947.8417604357433
normal_preload = 1.0
[[contact.elements]]
x_dof = 0
[hbm]
harmonics = 3
time_samples = 64
[continuation]
frequency_start_hz = 5.0
frequency_end_hz = 25.0
initial_step = 0.2
[study]
vary = { "contact.normal_preload" = [0.5, 2.0], "contact.friction_coefficient" = [0.3] }
)";

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

TEST(Cli, FrfWritesTheContractColumnsAndNoNaN) {
  const Scratch s("frf");
  s.write("case.toml", kLumpedCase);
  const CliResult r = s.run("frf case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = lines_of(slurp(s.dir() / "results" / "jenkins" / "frf.csv"));
  ASSERT_GT(lines.size(), 20u);
  EXPECT_EQ(lines[0], "frequency_hz,amplitude_m,linear_amplitude_m,newton_iterations,h0_m,h1_m,h2_m,h3_m,piece,stable");
  for (const auto& l : lines) {
    EXPECT_EQ(l.find("nan"), std::string::npos) << l;
    EXPECT_EQ(l.find("inf"), std::string::npos) << l;
  }
  const std::string run = slurp(s.dir() / "results" / "jenkins" / "run.json");
  EXPECT_NE(run.find("\"max_energy_balance_error\""), std::string::npos);
  EXPECT_NE(run.find("\"jacobian_evaluations\""), std::string::npos) << "solver statistics in run.json";
  EXPECT_TRUE(fs::exists(s.dir() / "results" / "jenkins" / "loops.csv"));
}

TEST(Cli, AutoHarmonicsAndSamplesStopWhereThePeaksSettle) {
  const Scratch s("auto");
  s.write("case.toml", kLumpedCase);
  constexpr double kAutoTol = 1e-3;
  const CliResult r = s.run(
      "frf case.toml --quiet --set hbm.harmonics=\"auto\" --set hbm.time_samples=\"auto\" "
      "--set hbm.auto_tolerance=" +
      std::to_string(kAutoTol));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto run = nlohmann::json::parse(slurp(s.dir() / "results" / "jenkins" / "run.json"));
  const auto& a = run.at("auto");
  const int h = a.at("harmonics"), n = a.at("time_samples");
  EXPECT_TRUE(a.at("harmonics_converged").get<bool>());
  EXPECT_TRUE(a.at("time_samples_converged").get<bool>());
  EXPECT_GE(n, 2 * h + 1);
  // The H search stops at the first H whose curve is within the tolerance of the one before,
  // and the N search likewise: the accepted trials met it, the ones before them did not.
  std::vector<nlohmann::json> h_trials, n_trials;
  for (const auto& t : a.at("trials"))
    (t.at("time_samples") == n && t.at("harmonics") == h ? n_trials : h_trials).push_back(t);
  ASSERT_FALSE(n_trials.empty());
  const auto& accepted = n_trials.back();
  ASSERT_FALSE(accepted.at("relative_change").is_null());
  EXPECT_LT(accepted.at("relative_change").get<double>(), kAutoTol);
  int h_search_below = 0;
  for (const auto& t : a.at("trials"))
    if (t.at("harmonics") != h && !t.at("relative_change").is_null() &&
        t.at("relative_change").get<double>() < kAutoTol)
      ++h_search_below;
  EXPECT_EQ(h_search_below, 0) << "the H search went past an H that already met the tolerance";
  EXPECT_GE(a.at("trials").size(), 3u);
  // The result is the accepted trial's curve, with its harmonics as columns.
  const auto lines = lines_of(slurp(s.dir() / "results" / "jenkins" / "frf.csv"));
  ASSERT_GT(lines.size(), 20u);
  EXPECT_NE(lines[0].find(",h" + std::to_string(h) + "_m,piece"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[0].find(",h" + std::to_string(h + 1) + "_m"), std::string::npos) << lines[0];
  // A Jenkins element is judged by shooting, which costs more than a curve: only the accepted
  // trial is judged (its frf.csv has the `stable` column, the other trials' do not).
  EXPECT_EQ(run.at("frf").at("stability").at("method").get<std::string>(), "shooting");
  EXPECT_EQ(run.at("frf").at("stability").at("failed_points").get<int>(), 0);
  EXPECT_NE(lines[0].find(",piece,stable"), std::string::npos) << lines[0];
  for (const auto& t : a.at("trials")) {
    const fs::path dir = s.dir() / "results" / "jenkins" / "auto" /
                         ("H=" + std::to_string(t.at("harmonics").get<int>()) +
                          "__N=" + std::to_string(t.at("time_samples").get<int>()));
    const auto trial = lines_of(slurp(dir / "frf.csv"));
    ASSERT_FALSE(trial.empty()) << dir;
    const bool is_accepted = t.at("harmonics") == h && t.at("time_samples") == n;
    EXPECT_EQ(trial[0].find(",stable") != std::string::npos, is_accepted) << dir;
    if (is_accepted) {
      EXPECT_EQ(trial, lines) << "the accepted trial traced again is the same curve";
    }
  }
}

TEST(Cli, ConvergenceStudyTabulatesEveryKnobAgainstItsFinestValue) {
  const Scratch s("convergence");
  s.write("case.toml", kLumpedCase);
  const CliResult r = s.run("study --convergence case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = lines_of(slurp(s.dir() / "results" / "jenkins" / "trade.csv"));
  ASSERT_GT(lines.size(), 1u);
  EXPECT_EQ(lines[0],
            "knob,key,value,reference_value,status,seconds,points,peak_amplitude_m,peak_frequency_hz,"
            "peaks_error,peak_frequency_error_hz,folder,cpu_seconds,harmonics,time_samples");
  // Rows per knob, in the order coarse to fine: (value, error).
  std::map<std::string, std::vector<std::pair<std::string, double>>> knobs;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<std::string> f;
    std::istringstream row(lines[i]);
    for (std::string x; std::getline(row, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 15u) << lines[i];
    EXPECT_EQ(f[4], "ok") << lines[i];
    // The discretization each row's curve was traced with: the knob's value (a curve may be
    // traced again with a finer N when its energy check fails, never with a coarser one).
    if (f[1] == "hbm.harmonics") {
      EXPECT_EQ(std::stoi(f[13]), std::stoi(f[2])) << lines[i];  // the value: "H" or "H hbm.time_samples=N"
    }
    if (f[1] == "hbm.time_samples") {
      EXPECT_GE(std::stoi(f[14]), std::stoi(f[2])) << lines[i];
    }
    knobs[f[1]].emplace_back(f[2], std::stod(f[9]));
    if (f[2] == f[3]) {
      EXPECT_EQ(std::stod(f[9]), 0.0) << "a reference has no error against itself: " << lines[i];
    }
  }
  // A 1d lumped case: no mesh, modes, update or contact-model knobs.
  EXPECT_EQ(knobs.size(), 3u);
  ASSERT_TRUE(knobs.count("hbm.harmonics") && knobs.count("hbm.time_samples") && knobs.count("hbm.jacobian"));
  // More harmonics and more samples converge: the error against the finest falls along the list.
  for (const char* key : {"hbm.harmonics", "hbm.time_samples"}) {
    const auto& v = knobs[key];
    ASSERT_GE(v.size(), 3u) << key;
    for (std::size_t i = 1; i < v.size(); ++i) EXPECT_LE(v[i].second, v[i - 1].second) << key << " = " << v[i].first;
  }
  // The finite-difference Jacobian traces the same curve (to its step, 1e-6 relative).
  constexpr double kSameCurve = 1e-6;
  EXPECT_LT(knobs["hbm.jacobian"].front().second, kSameCurve);
  EXPECT_TRUE(fs::exists(s.dir() / "results" / "jenkins" / "case" / "frf.csv"));
}

TEST(Cli, SectorCountExtremes) {
  // Nb = 100: a thin 3.6-degree sector on a 1 m hub runs end to end (mesh, modes of the
  // harmonic indices EO 1 reaches, forced response) with every value finite.
  const Scratch s("nb100");
  s.write("case.toml", R"(name = "nb100"
[structure]
sectors = 100
[geometry]
hub_radius = 1.0
disk_outer_radius = 1.04
blade_chord = 0.04
blade_twist_deg = 10.0
shroud_width = 0.05
element_order = 1
mesh_size = 0.02
[modal]
modes = 10
[excitation]
point = [0.0, 1.28, 0.0]
[response]
point = [0.0, 1.27, 0.0]
[contact]
pairs = 3
[hbm]
harmonics = 3
time_samples = 128
[continuation]
frequency_start_hz = 100.0
frequency_end_hz = 200.0
initial_step = 0.5
)");
  const CliResult r = s.run("run case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto run = nlohmann::json::parse(slurp(s.dir() / "results" / "nb100" / "run.json"));
  EXPECT_EQ(run.at("frf").at("status"), "reached_end");
  EXPECT_GT(run.at("frf").at("peak_amplitude_m").get<double>(), 0.0);
  for (const auto& l : lines_of(slurp(s.dir() / "results" / "nb100" / "frf.csv"))) {
    EXPECT_EQ(l.find("nan"), std::string::npos) << l;
    EXPECT_EQ(l.find("inf"), std::string::npos) << l;
  }
  // A point whose nearest node is clamped would answer zero: refused, naming the key.
  const CliResult hub = s.run("frf case.toml --quiet --set excitation.point=[0.0,1.0,0.0]");
  EXPECT_EQ(hub.status, kBadInput) << hub.err;
  EXPECT_NE(hub.err.find("excitation.point"), std::string::npos) << hub.err;
  EXPECT_NE(hub.err.find("clamped"), std::string::npos) << hub.err;
  // Nb = 2 is refused by the generator with the reason (a user mesh serves it).
  const CliResult two = s.run("mesh case.toml --quiet --set structure.sectors=2");
  EXPECT_EQ(two.status, kBadInput) << two.err;
  EXPECT_NE(two.err.find("structure.sectors"), std::string::npos) << two.err;
}

TEST(Cli, ContinuationThatCannotFinishExitsThreeWithWhatItHas) {
  const Scratch s("frf3");
  s.write("case.toml", kLumpedCase);
  const CliResult r = s.run("frf case.toml --quiet --set continuation.max_points=5");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("max_points"), std::string::npos) << r.err;
  const auto lines = lines_of(slurp(s.dir() / "results" / "jenkins" / "frf.csv"));
  EXPECT_EQ(lines.size(), 6u);  // header + the 5 points computed
  EXPECT_NE(slurp(s.dir() / "results" / "jenkins" / "run.json").find("\"status\": \"numerics_failed\""),
            std::string::npos);
}

TEST(Cli, StudyRunsEveryPointInItsOwnFolder) {
  const Scratch s("study");
  s.write("case.toml", kLumpedCase);
  const CliResult r = s.run("study case.toml --quiet --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lines = lines_of(slurp(s.dir() / "results" / "jenkins" / "study.csv"));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0].rfind("contact.friction_coefficient,contact.normal_preload,status,peak_amplitude_m", 0), 0u)
      << lines[0];
  // Each row ends with the H and N its curve was traced with (the case's 3 and 64 here).
  EXPECT_EQ(lines[0].substr(lines[0].size() - 30), ",folder,harmonics,time_samples") << lines[0];
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(lines[i].substr(lines[i].size() - 5), ",3,64") << lines[i];
  EXPECT_TRUE(fs::exists(s.dir() / "results" / "jenkins" / "friction_coefficient=0.3__normal_preload=0.5" / "frf.csv"));
  // A higher preload sticks more: the 2 N point's peak is lower than the 0.5 N one.
  auto peak = [&](const std::string& line) { return std::stod(line.substr(line.find(",ok,") + 4)); };
  EXPECT_LT(peak(lines[2]), peak(lines[1]));
}

}  // namespace
}  // namespace shroudsim::testing

namespace shroudsim::testing {
namespace {

TEST(Cli, ContactCommandWritesTheCircularOrbitSolution) {
  // A circular tangential orbit of radius 1e-6 m beyond the slip radius mu N / kt, at a
  // constant normal load N = N0 + kn z0 = 1.1 N: |T| = mu N throughout (docs/physics.md section 6),
  // so the first harmonic of Tx has amplitude 0.33 N and the others vanish.
  const Scratch s("contact");
  s.write("c.toml",
          "name = \"c\"\n[contact]\nmodel = \"full3d\"\nfriction_coefficient = 0.3\nnormal_preload = 1.0\n"
          "[hbm]\nharmonics = 3\ntime_samples = 256\n[motion]\nx = [[1, 1e-6, 0.0]]\ny = [[1, 0.0, 1e-6]]\n"
          "z = [[0, 1e-7, 0.0]]\n");
  const CliResult r = s.run("contact c.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string j = slurp(s.dir() / "results" / "c" / "contact.json");
  for (const char* key : {"\"force_harmonics\"", "\"time\"", "\"jacobian\"", "\"seconds\"", "\"tx\""})
    EXPECT_NE(j.find(key), std::string::npos) << key;
  // Parse the x force harmonics: [[0, c, s], [1, c, s], ...].
  const auto at = j.find("\"x\"", j.find("\"force_harmonics\""));
  ASSERT_NE(at, std::string::npos);
  std::vector<double> v;
  std::string num;
  for (std::size_t i = j.find('[', at) + 1; v.size() < 12 && i < j.size(); ++i) {
    const char ch = j[i];
    if (std::isdigit(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.' || ch == 'e' || ch == '+') {
      num += ch;
    } else if (!num.empty()) {
      v.push_back(std::stod(num));
      num.clear();
    }
  }
  ASSERT_EQ(v.size(), 12u);
  EXPECT_NEAR(std::hypot(v[4], v[5]), 0.33, 1e-9);                      // harmonic 1 (exact_linear, constant N)
  EXPECT_LT(std::hypot(v[7], v[8]) + std::hypot(v[10], v[11]), 1e-12);  // harmonics 2 and 3
  const CliResult bad = s.run("contact c.toml --set 'motion.x=[[1, 1e-6]]'");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("motion.x"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace shroudsim::testing

namespace shroudsim::testing {
namespace {

TEST(Cli, SectorForcedResponseRunsEndToEndWithFullThreeDimensionalContact) {
  // A coarse sector (4-node tets), 3 shroud pairs, full3d contact, H = 3: mesh -> modes ->
  // receptances -> harmonic balance -> continuation, through the command line.
  const Scratch s("sector_frf");
  s.write("case.toml", coarse_sector_case(80.0, 130.0));
  const CliResult r = s.run("frf case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string run = slurp(s.dir() / "results" / "sector" / "run.json");
  const auto at = run.find("\"max_energy_balance_error\": ");
  ASSERT_NE(at, std::string::npos);
  // Excitation work = modal viscous + contact dissipation at every point, to the Newton tolerance.
  EXPECT_LT(std::stod(run.substr(at + 28)), 1e-5) << run.substr(at, 60);
  EXPECT_GT(lines_of(slurp(s.dir() / "results" / "sector" / "frf.csv")).size(), 50u);
  // With stability_method "auto" the sector's stability is not analysed (it needs the modes of
  // every harmonic index and, with friction, pencils N x 2 x pairs wider: docs/physics.md section
  // 9): run.json says so and how to ask for it, and frf.csv has no `stable` column rather than
  // claiming anything; the forced stage computed the harmonic balance's indices only.
  const auto j = nlohmann::json::parse(run);
  const auto stability = j["frf"]["stability"];
  EXPECT_FALSE(stability["available"].get<bool>());
  EXPECT_NE(stability["reason"].get<std::string>().find("FE sector"), std::string::npos);
  EXPECT_NE(stability["reason"].get<std::string>().find("stability_method = \"hill\""), std::string::npos);
  EXPECT_EQ(j["frf_model"]["harmonic_indices"], nlohmann::json({1, 2, 3}));
  const auto lines = lines_of(slurp(s.dir() / "results" / "sector" / "frf.csv"));
  EXPECT_EQ(lines[0].find("stable"), std::string::npos) << lines[0];
}

TEST(Cli, HillOnASectorJudgesEveryPointOverTheModesOfEveryHarmonicIndex) {
  // stability_method = "hill" on the coarse sector (Nb = 8, full3d friction, H = 3, N = 64): the
  // forced stage computes the modes of indices 0..4 (the perturbation families), every point is
  // judged with the slider as a state, and frf.csv's `stable` column is run.json's count. Its
  // verdicts against an independent reference, the whole wheel's time integration:
  // tests/forced/test_modal_wheel.cpp.
  const Scratch s("sector_hill");
  s.write("case.toml", coarse_sector_case(110.0, 110.2) + "[response]\nstability_method = \"hill\"\n");
  const CliResult r = s.run("frf case.toml --quiet --no-plots");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(s.dir() / "results" / "sector" / "run.json"));
  EXPECT_EQ(j["frf_model"]["harmonic_indices"], nlohmann::json({0, 1, 2, 3, 4}));
  const auto stability = j["frf"]["stability"];
  ASSERT_TRUE(stability["available"].get<bool>()) << stability.dump();
  EXPECT_EQ(stability["linearization"], "slider_state");
  EXPECT_EQ(stability["failed_points"].get<int>(), 0);
  const auto lines = lines_of(slurp(s.dir() / "results" / "sector" / "frf.csv"));
  ASSERT_NE(lines[0].find(",stable"), std::string::npos) << lines[0];
  int unstable = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const char last = lines[i].back();
    ASSERT_TRUE(last == '0' || last == '1') << lines[i];
    unstable += last == '0' ? 1 : 0;
  }
  EXPECT_EQ(unstable, stability["unstable_points"].get<int>());
  EXPECT_GT(lines.size(), 5u);
  // The slider state at the harmonic balance's N = 64 (3 x 2 x 64 damper positions fit), or at
  // the samples asked for (response.stability_samples), every point judged either way.
  EXPECT_EQ(stability["memory_samples"].get<int>(), 64);
  const CliResult coarse = s.run("frf case.toml --quiet --no-plots --out m32 --set response.stability_samples=32");
  ASSERT_EQ(coarse.status, 0) << coarse.err;
  const auto m32 = nlohmann::json::parse(slurp(s.dir() / "m32" / "run.json"))["frf"]["stability"];
  ASSERT_TRUE(m32["available"].get<bool>()) << m32.dump();
  EXPECT_EQ(m32["memory_samples"].get<int>(), 32);
  EXPECT_EQ(m32["failed_points"].get<int>(), 0);
  // At N = 512 with the slider state at every sample the damper positions alone would make each
  // pencil 512 x 2 x 3 = 3072 wide, above the limit: refused before any further mode is computed,
  // and run.json says so ("auto" would take 133 samples).
  const CliResult big = s.run(
      "frf case.toml --quiet --no-plots --out n512 --set hbm.time_samples=512 --set response.stability_samples=512");
  ASSERT_EQ(big.status, 0) << big.err;
  const auto k = nlohmann::json::parse(slurp(s.dir() / "n512" / "run.json"));
  EXPECT_EQ(k["frf_model"]["harmonic_indices"], nlohmann::json({1, 2, 3}));
  EXPECT_FALSE(k["frf"]["stability"]["available"].get<bool>());
  EXPECT_NE(k["frf"]["stability"]["reason"].get<std::string>().find("at least 3072 unknowns"), std::string::npos)
      << k["frf"]["stability"]["reason"];
}

TEST(Cli, ReceptancesAreReusedWhereOnlyTheContactLawChangesAndRecomputedWhereTheirInputsDo) {
  // The receptance stage's data (factorizations of every K_h, static and residual
  // flexibility) is cached under the fingerprint of what it depends on: the same case again,
  // or another friction coefficient, reuses it and factorizes nothing; another set of contact
  // pairs does not; a damaged entry is recomputed with a warning. The curve from a reused
  // entry is the same file, byte for byte.
  const Scratch s("receptance_cache");
  s.write("case.toml", coarse_sector_case(95.0, 100.0));
  auto run = [&](const std::string& out, const std::string& extra) {
    const CliResult r = s.run("frf case.toml --quiet --no-plots --out " + out + extra);
    EXPECT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(s.dir() / out / "run.json"));
    return std::make_pair(j["frf_model"]["receptances"], r.err);
  };
  const auto [first, first_err] = run("a", "");
  EXPECT_FALSE(first["reused"].get<bool>());
  const fs::path entry = first["cache_entry"].get<std::string>();
  ASSERT_TRUE(fs::exists(entry));
  const auto [again, again_err] = run("b", "");
  EXPECT_TRUE(again["reused"].get<bool>());
  EXPECT_EQ(slurp(s.dir() / "b" / "frf.csv"), slurp(s.dir() / "a" / "frf.csv"));
  const auto [friction, friction_err] = run("c", " --set contact.friction_coefficient=0.6");
  EXPECT_TRUE(friction["reused"].get<bool>());
  EXPECT_NE(slurp(s.dir() / "c" / "frf.csv"), slurp(s.dir() / "a" / "frf.csv"));  // another curve
  const auto [pairs, pairs_err] = run("d", " --set contact.pairs=2");
  EXPECT_FALSE(pairs["reused"].get<bool>());
  EXPECT_NE(pairs["cache_entry"].get<std::string>(), entry.string());
  // One byte changed in the middle of the entry: not used, said, recomputed and rewritten.
  {
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(fs::file_size(entry) / 2));
    char c = 0;
    f.read(&c, 1);
    f.seekp(static_cast<std::streamoff>(fs::file_size(entry) / 2));
    c = static_cast<char>(c ^ 0x5a);
    f.write(&c, 1);
  }
  const auto [damaged, damaged_err] = run("e", "");
  EXPECT_FALSE(damaged["reused"].get<bool>());
  EXPECT_NE(damaged_err.find("checksum"), std::string::npos) << damaged_err;
  EXPECT_EQ(slurp(s.dir() / "e" / "frf.csv"), slurp(s.dir() / "a" / "frf.csv"));
  const auto [rewritten, rewritten_err] = run("f", "");
  EXPECT_TRUE(rewritten["reused"].get<bool>());
  // Another excitation level: the data is linear in the force (its excitation row), so the entry
  // serves it; a force of another direction does not. The data is always computed for the
  // force's direction and then scaled, so the curve is the same file whether the run reads the
  // entry or computes it: it does not depend on which level wrote the entry.
  const auto [level, level_err] = run("g", " --set 'excitation.force=[-2.5, -2.5, -2.5]'");
  EXPECT_TRUE(level["reused"].get<bool>());
  EXPECT_EQ(level["force_scale"].get<double>(), -2.5);
  EXPECT_EQ(level["cache_entry"].get<std::string>(), entry.string());
  const auto [direction, direction_err] = run("h", " --set 'excitation.force=[1.0, 0.0, 0.0]'");
  EXPECT_FALSE(direction["reused"].get<bool>());
  EXPECT_NE(direction["cache_entry"].get<std::string>(), entry.string());
  for (const auto& e : fs::directory_iterator(entry.parent_path()))
    if (e.path().filename().string().rfind("receptances-", 0) == 0) fs::remove(e.path());
  const auto [computed, computed_err] = run("i", " --set 'excitation.force=[-2.5, -2.5, -2.5]'");
  EXPECT_FALSE(computed["reused"].get<bool>());
  EXPECT_EQ(slurp(s.dir() / "g" / "frf.csv"), slurp(s.dir() / "i" / "frf.csv"));
  // The entry that run wrote serves the case's own force: the first run's file again.
  const auto [back, back_err] = run("j", "");
  EXPECT_TRUE(back["reused"].get<bool>());
  EXPECT_EQ(slurp(s.dir() / "j" / "frf.csv"), slurp(s.dir() / "a" / "frf.csv"));
  // and -2.5 is a curve of its own: with friction the response is not proportional to the force.
  const double a_peak = nlohmann::json::parse(slurp(s.dir() / "a" / "run.json"))["frf"]["peak_amplitude_m"];
  const double i_peak = nlohmann::json::parse(slurp(s.dir() / "i" / "run.json"))["frf"]["peak_amplitude_m"];
  EXPECT_GT(std::abs(i_peak / a_peak - 2.5), 1e-3);
}

TEST(Cli, CacheLimitBoundsTheCaseFolderCache) {
  // --cache-limit 0 keeps only the entry written last (the receptances, after the mesh and
  // the modes of three harmonic indices); a negative bound is refused before any work.
  const Scratch s("cache_limit");
  s.write("case.toml", coarse_sector_case(95.0, 96.0));
  const CliResult r = s.run("frf case.toml --quiet --no-plots --cache-limit 0 --out a");
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> entries;
  for (const auto& e : fs::directory_iterator(s.dir() / ".cache")) entries.push_back(e.path().filename().string());
  ASSERT_EQ(entries.size(), 1u);
  EXPECT_EQ(entries[0].rfind("receptances-", 0), 0u) << entries[0];
  const CliResult bad = s.run("frf case.toml --quiet --cache-limit -1 --out b");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--cache-limit"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(s.dir() / "b"));
}

}  // namespace
}  // namespace shroudsim::testing
