// `campbell` with rotating effects and the forced response at a speed, through the command
// line: speed-dependent campbell.csv, crossings on the engine-order lines, bad input exit 2.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

namespace fs = std::filesystem;

// A coarse 4-node sector, two harmonic indices, four speeds up to 6000 rpm (below the
// divergence of the generator's free shroud overhangs, ~11000 rpm for the default sector).
const char* kRotatingCase = R"(name = "coarse"
[geometry]
element_order = 1
mesh_size = 0.025
[modal]
modes = 8
harmonic_indices = [0, 1]
[campbell]
speed_rpm = [0.0, 6000.0]
speed_points = 4
engine_orders = [1, 8, 9]
rotating_effects = true
)";

// (speed, h, mode) -> frequency from campbell.csv.
std::map<std::tuple<double, int, int>, double> campbell(const fs::path& file) {
  const auto rows = csv_rows(slurp(file));
  EXPECT_EQ(rows.front(),
            (std::vector<std::string>{"speed_rpm", "harmonic_index", "nodal_diameter", "mode", "frequency_hz"}));
  std::map<std::tuple<double, int, int>, double> f;
  for (std::size_t i = 1; i < rows.size(); ++i)
    f[{std::stod(rows[i][0]), std::stoi(rows[i][1]), std::stoi(rows[i][3])}] = std::stod(rows[i][4]);
  return f;
}

TEST(CliRotating, CampbellFrequenciesDependOnSpeedAndCrossingsLieOnTheEngineOrderLines) {
  const Scratch s("campbell_rotating");
  s.write("case.toml", kRotatingCase);
  const CliResult r = s.run("campbell case.toml --quiet --threads 1");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto f = campbell(s.dir() / "results" / "coarse" / "campbell.csv");
  EXPECT_EQ(f.size(), 4u * 2u * 8u);  // speeds x harmonic indices x modes
  // The first family stiffens (centrifugal stiffening beats spin softening).
  EXPECT_GT(f.at({6000.0, 0, 1}), 1.05 * f.at({0.0, 0, 1}));
  EXPECT_GT(f.at({6000.0, 1, 1}), 1.05 * f.at({0.0, 1, 1}));
  // Each crossing is on its line f = EO rpm / 60, between two speed points where
  // f_r - EO rpm / 60 changes sign.
  const auto cross = csv_rows(slurp(s.dir() / "results" / "coarse" / "crossings.csv"));
  ASSERT_EQ(cross.front(),
            (std::vector<std::string>{"engine_order", "nodal_diameter", "mode", "speed_rpm", "frequency_hz"}));
  ASSERT_GT(cross.size(), 1u);
  for (std::size_t i = 1; i < cross.size(); ++i) {
    const int e = std::stoi(cross[i][0]), mode = std::stoi(cross[i][2]);
    const double rpm = std::stod(cross[i][3]), fc = std::stod(cross[i][4]);
    EXPECT_NEAR(fc, e * rpm / 60.0, 1e-9 * fc);
    const int h = e % 8;
    const double s0 = 2000.0 * std::floor(rpm / 2000.0), s1 = std::min(s0 + 2000.0, 6000.0);
    const double g0 = f.at({s0, h, mode}) - e * s0 / 60.0, g1 = f.at({s1, h, mode}) - e * s1 / 60.0;
    EXPECT_LE(g0 * g1, 0.0) << "EO " << e << " mode " << mode << " at " << rpm << " rpm";
  }
  const std::string run = slurp(s.dir() / "results" / "coarse" / "run.json");
  EXPECT_NE(run.find("\"rotating_effects\": true"), std::string::npos);
  const std::string vtu = slurp(s.dir() / "results" / "coarse" / "prestress.vtu");
  EXPECT_NE(vtu.find("Name=\"von_mises_pa\""), std::string::npos);
  EXPECT_NE(vtu.find("Name=\"centrifugal_displacement_m\""), std::string::npos);
  EXPECT_NE(run.find("\"symbolic_analyses\": 1"), std::string::npos);  // one analysis per harmonic index
}

TEST(CliRotating, WithoutRotatingEffectsTheFrequenciesAreThoseAtRest) {
  const Scratch s("campbell_at_rest");
  s.write("case.toml", kRotatingCase);
  const CliResult r = s.run("campbell case.toml --quiet --set campbell.rotating_effects=false");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto f = campbell(s.dir() / "results" / "coarse" / "campbell.csv");
  for (const auto& [key, v] : f) EXPECT_EQ(v, f.at({0.0, std::get<1>(key), std::get<2>(key)}));
}

TEST(CliRotating, BadSpeedAndFlagValuesExitTwoNamingTheKey) {
  const Scratch s("campbell_bad");
  s.write("case.toml", kRotatingCase);
  CliResult r = s.run("campbell case.toml --set campbell.rotating_effects=1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("campbell.rotating_effects"), std::string::npos) << r.err;
  r = s.run("frf case.toml --set excitation.speed_rpm=-100");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("excitation.speed_rpm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(s.dir() / "results" / "coarse" / "run.json"));
}

TEST(CliRotating, ForcedResponseAtASpeedUsesTheModesAtThatSpeed) {
  // The same coarse sector and contact at rest and at 6000 rpm: the spinning blade is
  // stiffer (this stiff 4-node sector's first family: 94 Hz at rest, 125 Hz at 6000 rpm for
  // ND 1), so the response peak of 70 to 160 Hz, that family's, moves up with it, and the run
  // says it used the rotating stiffness.
  const Scratch s("frf_speed");
  s.write("case.toml", R"(name = "coarse"
[geometry]
element_order = 1
mesh_size = 0.025
[modal]
modes = 8
[contact]
pairs = 3
[hbm]
harmonics = 3
time_samples = 128
[continuation]
frequency_start_hz = 70.0
frequency_end_hz = 160.0
initial_step = 0.5
)");
  const CliResult rest = s.run("frf case.toml --quiet --out rest");
  ASSERT_EQ(rest.status, 0) << rest.err;
  const CliResult spin = s.run("frf case.toml --quiet --out spin --set excitation.speed_rpm=6000");
  ASSERT_EQ(spin.status, 0) << spin.err;
  auto peak_of = [&](const char* dir) {
    double best = 0.0, at = 0.0;
    std::istringstream in(slurp(s.dir() / dir / "frf.csv"));
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      const double f = std::stod(line.substr(0, line.find(','))), a = std::stod(line.substr(line.find(',') + 1));
      if (a > best) best = a, at = f;
    }
    return at;
  };
  const double f_rest = peak_of("rest"), f_spin = peak_of("spin");
  // The modes move by 125 / 94 = 1.33; the contact shifts both peaks a little.
  EXPECT_GT(f_spin, 1.2 * f_rest) << "at rest " << f_rest << " Hz, at 6000 rpm " << f_spin << " Hz";
  EXPECT_NE(slurp(s.dir() / "spin" / "run.json").find("\"rotating\""), std::string::npos);
  EXPECT_EQ(slurp(s.dir() / "rest" / "run.json").find("\"rotating\""), std::string::npos);
}

}  // namespace
}  // namespace shroudsim::testing
