// `shroudsim nlmodes` through the real command line: files, run.json, input errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {
namespace fs = std::filesystem;
const std::string kJenkins = std::string(SHROUDSIM_SOURCE_DIR) + "/cases/lumped_jenkins.toml";

TEST(NlmodesCli, JenkinsCaseRunsEndToEnd) {
  Scratch s("nlmodes_jenkins");
  const CliResult r = s.run("nlmodes " + kJenkins + " --quiet --out out");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = csv_rows(slurp(s.dir() / "out" / "nlmodes.csv"));
  ASSERT_GT(rows.size(), 50u);
  ASSERT_GE(rows[0].size(), 4u);
  EXPECT_EQ(rows[0][0], "amplitude");
  EXPECT_EQ(rows[0][1], "frequency_hz");
  EXPECT_EQ(rows[0][2], "damping_ratio");
  EXPECT_EQ(rows[0][3], "zeta");
  // Stuck: sqrt(2) x 10 Hz (kt = k), 1 % / sqrt(2) viscous damping; gross slip: 10 Hz.
  EXPECT_NEAR(std::stod(rows[1][1]), 10.0 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(std::stod(rows[1][2]), 0.01 / std::sqrt(2.0), 1e-8);
  EXPECT_NEAR(std::stod(rows.back()[1]), 10.0, 0.01);
  const auto syn = csv_rows(slurp(s.dir() / "out" / "nlmodes_synthesis.csv"));
  ASSERT_GT(syn.size(), 10u);
  EXPECT_EQ(syn[0][0], "scale");
  const nlohmann::json j = nlohmann::json::parse(slurp(s.dir() / "out" / "run.json"));
  EXPECT_EQ(j["command"], "nlmodes");
  EXPECT_EQ(j["status"], "ok");
  EXPECT_TRUE(j["nlmodes"]["reached_end"].get<bool>());
  ASSERT_EQ(j["nlmodes"]["synthesis"].size(), 3u);
  for (const auto& e : j["nlmodes"]["synthesis"]) EXPECT_TRUE(e["peak_found"].get<bool>()) << e.dump();
  // No temporary files left behind.
  for (const auto& f : fs::directory_iterator(s.dir() / "out"))
    EXPECT_EQ(f.path().filename().string().find(".tmp"), std::string::npos) << f.path();
}

TEST(NlmodesCli, BadKeysAreInputErrorsNamingTheKey) {
  Scratch s("nlmodes_bad");
  CliResult r = s.run("nlmodes " + kJenkins + " --quiet --out out --set nlmodes.amplitude_end=1e-7");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nlmodes.amplitude_end"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("violates"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(s.dir() / "out" / "nlmodes.csv"));
  const auto file = s.write("c.toml", slurp(kJenkins) + "\n");
  std::string text = slurp(file);
  text.replace(text.find("amplitude_start = 1e-6"), 22, "amplitude_start = -1.0");
  s.write("c.toml", text);
  r = s.run("nlmodes c.toml --quiet --out out");
  EXPECT_EQ(r.status, 2);
  // file:line:column of the key.
  EXPECT_NE(r.err.find("c.toml:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nlmodes.amplitude_start"), std::string::npos) << r.err;
  r = s.run("nlmodes " + kJenkins + " --quiet --out out --set nlmodes.mode=2");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("nlmodes.mode"), std::string::npos) << r.err;
  r = s.run("nlmodes " + kJenkins + " --quiet --out out --set nlmodes.compare_hb=3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nlmodes.compare_hb"), std::string::npos) << r.err;
}

TEST(NlmodesCli, TheDefaultWheelsModeRunsEndToEndAndMeetsItsHarmonicBalance) {
  // cases/shrouded_wheel.toml on a coarse mesh with fewer modes and harmonics: the FE sector's
  // nonlinear mode from stick into slip, and the synthesized peak at the case's excitation
  // against the full harmonic balance (nlmodes.compare_hb).
  Scratch s("nlmodes_wheel");
  s.write("wheel.toml", slurp(fs::path(SHROUDSIM_SOURCE_DIR) / "cases" / "shrouded_wheel.toml"));
  const CliResult r = s.run(
      "nlmodes wheel.toml --out out --quiet --set geometry.element_order=1 --set geometry.mesh_size=0.0144 "
      "--set modal.modes=10 --set hbm.harmonics=3 --set hbm.time_samples=128 --set nlmodes.synthesis_scales=[1.0] "
      "--set nlmodes.compare_hb=true");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(s.dir() / "out" / "run.json"));
  const auto& n = j["nlmodes"];
  EXPECT_TRUE(n["reached_end"].get<bool>());
  const auto rows = csv_rows(slurp(s.dir() / "out" / "nlmodes.csv"));
  ASSERT_GT(rows.size(), 20u);
  // Stuck at small amplitude: the linear mode with the contact springs, its modal damping.
  EXPECT_NEAR(std::stod(rows[1][1]) / n["linear_frequency_hz"].get<double>(), 1.0, 1e-6);
  // Friction damps it: the largest damping ratio well above the stuck one, the frequency lower.
  EXPECT_GT(n["max_damping_ratio"].get<double>(), 5 * n["linear_damping_ratio"].get<double>());
  EXPECT_LT(n["end_frequency_hz"].get<double>(), n["linear_frequency_hz"].get<double>());
  ASSERT_EQ(n["comparison"].size(), 1u);
  const auto& c = n["comparison"][0];
  ASSERT_TRUE(c.contains("amplitude_error")) << c.dump();
  EXPECT_TRUE(fs::exists(s.dir() / "out" / "nlmodes_compare.csv"));
  // The shapes for ParaView: stuck start, largest damping, end; the mode moves the sector.
  EXPECT_TRUE(fs::exists(s.dir() / "out" / "nlmodes.vtu"));
  ASSERT_EQ(n["shapes"].size(), 3u);
  for (const auto& shape : n["shapes"]) EXPECT_GT(shape["largest_displacement_m"].get<double>(), 0.0) << shape.dump();
  EXPECT_EQ(n["shapes"][1]["damping_ratio"].get<double>(), n["max_damping_ratio"].get<double>());
  // Each shape's motion over one period for ParaView: a collection of 24 frames that exist.
  for (const auto& shape : n["shapes"]) {
    const std::string pvd = slurp(s.dir() / "out" / shape["frames"].get<std::string>());
    int frames = 0;
    for (std::size_t at = pvd.find("file=\""); at != std::string::npos; at = pvd.find("file=\"", at + 1)) {
      const std::size_t begin = at + 6, end = pvd.find('"', begin);
      EXPECT_TRUE(fs::exists(s.dir() / "out" / pvd.substr(begin, end - begin))) << pvd.substr(begin, end - begin);
      ++frames;
    }
    EXPECT_EQ(frames, 24) << shape.dump();
  }
  std::printf(
      "coarse wheel: %zu points, %.3f -> %.3f Hz, D max %.4f; peak HB %.4e m at %.3f Hz, synthesis %+.2e, %+.2e\n",
      rows.size() - 1, n["linear_frequency_hz"].get<double>(), n["end_frequency_hz"].get<double>(),
      n["max_damping_ratio"].get<double>(), c["hb_peak_amplitude_m"].get<double>(),
      c["hb_peak_frequency_hz"].get<double>(), c["amplitude_error"].get<double>(), c["frequency_error"].get<double>());
  // The single-mode synthesis is an approximation on the sector (measured here -4.8 % in
  // amplitude and -4.9 % in frequency; on the shipped mesh -11 to -14 %, README): it must land
  // on this resonance, not on another one.
  constexpr double kSameResonance = 0.25;
  EXPECT_LT(std::abs(c["amplitude_error"].get<double>()), kSameResonance) << c.dump();
  EXPECT_LT(std::abs(c["frequency_error"].get<double>()), kSameResonance) << c.dump();
  EXPECT_EQ(c["within_5_percent"].get<bool>(), std::abs(c["amplitude_error"].get<double>()) <= 0.05);
}

}  // namespace
}  // namespace shroudsim::testing
