// modal.shroud = "stuck" through the command line: the tied shroud couples the blades (the
// ND map is no longer flat), its modes are cached apart from the open ones, and `campbell`
// with rotating effects uses it.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

namespace fs = std::filesystem;

const char* kCoarseCase = R"(name = "coarse"
[geometry]
element_order = 1
mesh_size = 0.025
[modal]
modes = 6
harmonic_indices = [0, 1, 4]
[campbell]
speed_rpm = [0.0, 6000.0]
speed_points = 3
engine_orders = [1, 8]
rotating_effects = true
)";

// (h, mode) -> frequency [Hz] from modes.csv.
std::map<std::pair<int, int>, double> modes_csv(const fs::path& file) {
  std::map<std::pair<int, int>, double> f;
  const auto rows = csv_rows(slurp(file));
  EXPECT_EQ(rows.front(), (std::vector<std::string>{"harmonic_index", "nodal_diameter", "mode", "frequency_hz"}));
  for (std::size_t i = 1; i < rows.size(); ++i)
    f[{std::stoi(rows[i][0]), std::stoi(rows[i][2])}] = std::stod(rows[i][3]);
  return f;
}

nlohmann::json run_json(const fs::path& dir) { return nlohmann::json::parse(slurp(dir / "run.json")); }

TEST(CliShroud, StuckShroudCouplesTheBladesAndIsCachedApartFromTheOpenOne) {
  Scratch s("shroud_modes");
  s.write("coarse.toml", kCoarseCase);
  ASSERT_EQ(s.run("modes coarse.toml --out open --quiet").status, 0);
  const CliResult stuck = s.run("modes coarse.toml --set 'modal.shroud=\"stuck\"' --out stuck");
  ASSERT_EQ(stuck.status, 0) << stuck.err;
  EXPECT_NE(stuck.err.find("shroud stuck: "), std::string::npos) << stuck.err;
  const auto open = modes_csv(s.dir() / "open" / "modes.csv");
  const auto tied = modes_csv(s.dir() / "stuck" / "modes.csv");
  ASSERT_EQ(open.size(), 18u);
  ASSERT_EQ(tied.size(), 18u);
  // Open: the blades couple only through the stiff disk, the first family is flat over ND
  // (within 1 %). Stuck: the springs (1e6 N/m over the face) raise the ND 4 family by far
  // more, and ND 0 (neighbours in phase) least.
  EXPECT_LT(std::abs(open.at({4, 1}) / open.at({0, 1}) - 1.0), 0.01);
  EXPECT_GT(tied.at({4, 1}), 1.5 * open.at({4, 1}));
  EXPECT_LT(tied.at({0, 1}), tied.at({4, 1}));
  for (const auto& [key, f] : open) EXPECT_GE(tied.at(key), f * (1.0 - 1e-9)) << key.first << " " << key.second;
  EXPECT_EQ(run_json(s.dir() / "open")["modal"]["shroud"], "open");
  const auto js = run_json(s.dir() / "stuck")["modal"];
  EXPECT_EQ(js["shroud"], "stuck");
  EXPECT_GT(js["shroud_springs"]["pairs"].get<int>(), 0);
  EXPECT_NEAR(js["shroud_springs"]["normal_stiffness_n_per_m"].get<double>(), 1e6, 1e-6 * 1e6);

  // Each state reuses its own cached modes, never the other's.
  ASSERT_EQ(s.run("modes coarse.toml --out open2 --quiet").status, 0);
  ASSERT_EQ(s.run("modes coarse.toml --set 'modal.shroud=\"stuck\"' --out stuck2 --quiet").status, 0);
  EXPECT_EQ(slurp(s.dir() / "open2" / "modes.csv"), slurp(s.dir() / "open" / "modes.csv"));
  EXPECT_EQ(slurp(s.dir() / "stuck2" / "modes.csv"), slurp(s.dir() / "stuck" / "modes.csv"));
  for (const char* d : {"open2", "stuck2"})
    for (const auto& e : run_json(s.dir() / d)["modal"]["solved"]) EXPECT_TRUE(e["reused"].get<bool>()) << d;
}

TEST(CliShroud, CampbellWithRotatingEffectsUsesTheStuckShroud) {
  Scratch s("shroud_campbell");
  s.write("coarse.toml", kCoarseCase);
  ASSERT_EQ(s.run("modes coarse.toml --set 'modal.shroud=\"stuck\"' --out modes --quiet").status, 0);
  const CliResult r = s.run("campbell coarse.toml --set 'modal.shroud=\"stuck\"' --out campbell --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  // At 0 rpm the Campbell's frequencies are the stuck modes at rest.
  const auto rest = modes_csv(s.dir() / "modes" / "modes.csv");
  const auto campbell = csv_rows(slurp(s.dir() / "campbell" / "campbell.csv"));
  int checked = 0;
  for (std::size_t i = 1; i < campbell.size(); ++i) {
    const auto& v = campbell[i];
    if (std::stod(v[0]) != 0.0) continue;
    EXPECT_NEAR(std::stod(v[4]), rest.at({std::stoi(v[1]), std::stoi(v[3])}), 1e-6 * std::stod(v[4]));
    ++checked;
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(run_json(s.dir() / "campbell")["modal"]["shroud"], "stuck");
}

TEST(CliShroud, BadShroudValueExitsTwoNamingTheKey) {
  Scratch s("shroud_bad");
  s.write("coarse.toml", kCoarseCase);
  const CliResult r = s.run("modes coarse.toml --set 'modal.shroud=\"closed\"' --quiet");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("modal.shroud"), std::string::npos) << r.err;
}

// The 36-blade wheel of cases/shrouded_wheel.toml, coarse: twist -20 degrees (the untwist
// at speed closes the shroud).
const char* kWheelCase = R"(name = "wheel"
[structure]
sectors = 36
[geometry]
element_order = 1
mesh_size = 0.017
blade_twist_deg = -20.0
[modal]
modes = 6
harmonic_indices = [0, 1, 18]
[campbell]
speed_rpm = [0.0, 3000.0]
speed_points = 3
engine_orders = [1]
rotating_effects = true
[static]
speed_rpm = 0.0
increments = 4
)";

struct StaticRow {
  std::string state;
  double gap = 0, normal = 0, tangential = 0;
};

std::vector<StaticRow> static_rows(const fs::path& file) {
  const std::string text = slurp(file);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  const auto cells = csv_rows(text);
  EXPECT_EQ(cells.front(),
            (std::vector<std::string>{"pair", "high_node", "low_node", "x_m", "y_m", "z_m", "area_m2", "state", "gap_m",
                                      "normal_load_n", "tangential_load_n", "pressure_pa"}));
  std::vector<StaticRow> rows;
  for (std::size_t i = 1; i < cells.size(); ++i)
    rows.push_back({cells[i][7], std::stod(cells[i][8]), std::stod(cells[i][9]), std::stod(cells[i][10])});
  return rows;
}

TEST(CliShroud, StaticContactAtRestIsUnloadedWithoutInterferenceAndLinearInIt) {
  Scratch s("static_rest");
  s.write("wheel.toml", kWheelCase);
  ASSERT_EQ(s.run("static wheel.toml --out zero --quiet").status, 0);
  for (const auto& r : static_rows(s.dir() / "zero" / "static_contact.csv")) {
    EXPECT_EQ(r.state, "open");
    EXPECT_EQ(r.normal, 0.0);
    EXPECT_EQ(r.gap, 0.0);
  }
  // At rest the problem is positively homogeneous in the interference: twice the overlap,
  // twice every load (whatever sticks or slips), to the solver's tolerance.
  ASSERT_EQ(s.run("static wheel.toml --set contact.interference=1e-5 --out d1 --quiet").status, 0);
  ASSERT_EQ(s.run("static wheel.toml --set contact.interference=2e-5 --out d2 --quiet").status, 0);
  const auto a = static_rows(s.dir() / "d1" / "static_contact.csv"),
             b = static_rows(s.dir() / "d2" / "static_contact.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  double total = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].state, b[i].state) << i;
    EXPECT_NEAR(b[i].normal, 2 * a[i].normal, 1e-6 * (1e-3 + b[i].normal)) << i;
    EXPECT_NEAR(b[i].tangential, 2 * a[i].tangential, 1e-6 * (1e-3 + b[i].normal)) << i;
    total += a[i].normal;
  }
  EXPECT_GT(total, 0.0);
  // A gap as large: nothing touches, the gap reported is the one given.
  ASSERT_EQ(s.run("static wheel.toml --set contact.interference=-1e-5 --out gap --quiet").status, 0);
  for (const auto& r : static_rows(s.dir() / "gap" / "static_contact.csv")) {
    EXPECT_EQ(r.state, "open");
    EXPECT_NEAR(r.gap, 1e-5, 1e-15);
  }
  const auto j = run_json(s.dir() / "d1")["static"];
  EXPECT_NEAR(j["normal_load_n"].get<double>(), total, 1e-9 * total);
  EXPECT_TRUE(fs::exists(s.dir() / "d1" / "contact_static.vtu"));
}

TEST(CliShroud, TheShroudClosesAtSpeedAndCampbellFollowsTheContact) {
  Scratch s("static_speed");
  s.write("wheel.toml", kWheelCase);
  const CliResult r = s.run("static wheel.toml --set static.speed_rpm=3000 --out speed");
  ASSERT_EQ(r.status, 0) << r.err;
  int closed = 0;
  for (const auto& row : static_rows(s.dir() / "speed" / "static_contact.csv")) closed += row.state != "open";
  EXPECT_GT(closed, 0);
  EXPECT_GT(run_json(s.dir() / "speed")["static"]["normal_load_n"].get<double>(), 0.0);

  // campbell with modal.shroud = "contact": open at rest (no interference), closed at speed;
  // the states are in run.json and the frequencies at rest are the open sector's.
  ASSERT_EQ(s.run("modes wheel.toml --out open --quiet").status, 0);
  const CliResult c = s.run("campbell wheel.toml --set 'modal.shroud=\"contact\"' --out campbell --quiet");
  ASSERT_EQ(c.status, 0) << c.err;
  const auto states = run_json(s.dir() / "campbell")["campbell"]["shroud_contact"]["states"];
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[0]["closed"].get<int>(), 0);
  EXPECT_GT(states[2]["closed"].get<int>(), 0);
  const auto open = modes_csv(s.dir() / "open" / "modes.csv");
  const auto campbell = csv_rows(slurp(s.dir() / "campbell" / "campbell.csv"));
  std::map<std::pair<int, int>, double> top;
  for (std::size_t i = 1; i < campbell.size(); ++i) {
    const auto& v = campbell[i];
    const std::pair<int, int> key{std::stoi(v[1]), std::stoi(v[3])};
    if (std::stod(v[0]) == 0.0) {
      EXPECT_NEAR(std::stod(v[4]), open.at(key), 1e-6 * open.at(key));
    }
    if (std::stod(v[0]) == 3000.0) top[key] = std::stod(v[4]);
  }
  // Closed shrouds couple the blades: ND 18 (neighbours in antiphase) well above ND 0.
  EXPECT_GT(top.at({18, 1}), 1.3 * top.at({0, 1}));
}

TEST(CliShroud, ForcedResponsePreloadsFromTheStaticContact) {
  Scratch s("static_preload");
  s.write("wheel.toml", kWheelCase);
  ASSERT_EQ(s.run("static wheel.toml --set contact.interference=1e-5 --out static --quiet").status, 0);
  const double load = run_json(s.dir() / "static")["static"]["normal_load_n"].get<double>();
  const CliResult r = s.run(
      "frf wheel.toml --set contact.interference=1e-5 --set 'contact.normal_preload=\"static\"' --set contact.pairs=3 "
      "--set hbm.harmonics=1 --set hbm.time_samples=64 --set continuation.frequency_start_hz=60 "
      "--set continuation.frequency_end_hz=70 --out frf --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = run_json(s.dir() / "frf")["frf_model"];
  EXPECT_EQ(m["normal_preload_from"], "static");
  EXPECT_EQ(m["static_open_pairs"].get<int>(), 0);
  // Every pair closed: the patches' preloads add up to the static normal load.
  EXPECT_NEAR(m["normal_preload_total_n"].get<double>(), load, 1e-9 * load);
  EXPECT_NEAR(m["static_normal_load_n"].get<double>(), load, 1e-9 * load);
  // The forced response is written about that static state, which already carries the loads
  // (docs/physics.md section 8): while the contact stays closed, the mean normal load of
  // every patch over the period (N0 + kn W_0,z) is its preload, so the means add up to the
  // static load. Written the other way (the preload acting again on the open structure at
  // zero relative displacement), the structure's static flexibility relaxed them to 86 % of
  // it here (about a third on the default case). Tolerance: the Newton tolerance of W_0
  // times kn, far below that.
  const auto loops = csv_rows(slurp(s.dir() / "frf" / "loops.csv"));
  std::map<std::string, std::pair<double, int>> normal;  // pair -> (sum of N(l), samples)
  for (std::size_t i = 1; i < loops.size(); ++i) {
    const double n = std::stod(loops[i][7]);
    ASSERT_GT(n, 0.0) << "the contact opened: the mean is no longer N0 + kn W_0,z";
    normal[loops[i][0]].first += n;
    ++normal[loops[i][0]].second;
  }
  ASSERT_EQ(normal.size(), 3u);
  double mean_total = 0.0;
  for (const auto& [pair, sum] : normal) mean_total += sum.first / sum.second;
  EXPECT_NEAR(mean_total, load, 1e-6 * load);

  s.write("lumped.toml",
          "[structure]\ntype = \"lumped\"\nmass = [[1.0]]\nstiffness = [[1.0]]\n"
          "[contact]\nnormal_preload = \"static\"\n[[contact.elements]]\nx_dof = 0\n");
  const CliResult bad = s.run("frf lumped.toml --quiet");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("contact.normal_preload"), std::string::npos) << bad.err;
}

TEST(CliShroud, TheDefaultCaseIsAWheelAtSpeedThatRunsEndToEnd) {
  // cases/shrouded_wheel.toml as shipped, on a coarse mesh with fewer modes, speeds and
  // harmonics (the shipped sizes take about a minute: README "The shroud at speed").
  Scratch s("default_case");
  s.write("wheel.toml", slurp(fs::path(SHROUDSIM_SOURCE_DIR) / "cases" / "shrouded_wheel.toml"));
  const CliResult r = s.run(
      "run wheel.toml --out out --quiet --set geometry.element_order=1 --set geometry.mesh_size=0.017 "
      "--set modal.modes=6 --set campbell.speed_points=4 --set hbm.harmonics=3 --set hbm.time_samples=128");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = run_json(s.dir() / "out");
  // The Campbell diagram with rotating effects follows the shroud contact to the top speed.
  const auto& campbell = j["campbell"];
  EXPECT_TRUE(campbell["rotating_effects"].get<bool>());
  EXPECT_EQ(campbell["shroud"], "contact");
  const auto states = campbell["shroud_contact"]["states"];
  ASSERT_EQ(states.size(), 4u);
  EXPECT_EQ(states.back()["speed_rpm"].get<double>(), 3600.0);
  EXPECT_EQ(states.back()["open"].get<int>(), 0);
  // The static contact at the design speed closes every pair; the forced response takes its
  // preloads from it and passes its own checks.
  EXPECT_EQ(j["static"]["speed_rpm"].get<double>(), 3000.0);
  EXPECT_EQ(j["static"]["open"].get<int>(), 0);
  EXPECT_EQ(j["frf_model"]["normal_preload_from"], "static");
  EXPECT_NEAR(j["frf_model"]["normal_preload_total_n"].get<double>(), j["static"]["normal_load_n"].get<double>(),
              1e-9 * j["static"]["normal_load_n"].get<double>());
  EXPECT_TRUE(j["frf"]["energy_check_passed"].get<bool>());
  EXPECT_EQ(j["frf"]["status"], "reached_end");
  for (const char* f : {"modes.csv", "campbell.csv", "crossings.csv", "static_contact.csv", "frf.csv", "peaks.csv"})
    EXPECT_TRUE(fs::exists(s.dir() / "out" / f)) << f;
  // The run solved the modes at speed; the forced response again, now from the cache, gives
  // the same file byte for byte (the K_h factors are computed the same way either way).
  const CliResult again = s.run(
      "frf wheel.toml --out again --quiet --set geometry.element_order=1 --set geometry.mesh_size=0.017 "
      "--set modal.modes=6 --set campbell.speed_points=4 --set hbm.harmonics=3 --set hbm.time_samples=128");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(slurp(s.dir() / "again" / "frf.csv"), slurp(s.dir() / "out" / "frf.csv"));
}

}  // namespace
}  // namespace shroudsim::testing
