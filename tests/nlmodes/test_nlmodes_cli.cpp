// `shroudsim nlmodes` through the real command line: files, run.json, input errors.
#include <gtest/gtest.h>

#include <cmath>
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
  r = s.run("nlmodes " + std::string(SHROUDSIM_SOURCE_DIR) + "/cases/shrouded_blade.toml --quiet --out out");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("lumped"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace shroudsim::testing
