// Sampled studies through the command line ([study] sample, study.samples, study.method,
// study.seed, study.threshold_m): the drawn values follow their distributions (a Latin hypercube
// puts one value in each stratum), the statistics in run.json are those of study.csv
// (recomputed here independently), the same seed gives the same table, a drawn value the case
// refuses is recorded with its reason while the other samples run, and bad sample tables exit 2
// naming the key. `study --resume`: the finished points of a killed or earlier study are reused
// when their case is the same, and only the others run.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

std::string sampled_case(const std::string& study) {
  return std::string(R"(name = "sampled"
[structure]
type = "lumped"
sectors = 1
mass = [[1.0]]
stiffness = [[3947.8417604357433]]
damping = [[0.6283185307179586]]
[excitation]
force = 10.0
[contact]
model = "1d"
tangential_stiffness = 3947.8417604357433
normal_preload = 10.0
[[contact.elements]]
x_dof = 0
[hbm]
harmonics = 3
time_samples = 64
[continuation]
frequency_start_hz = 5.0
frequency_end_hz = 20.0
[study]
)") + study;
}

/// study.csv as columns by header name (a row's missing last cells are empty).
std::map<std::string, std::vector<std::string>> columns(const std::string& text) {
  const auto rows = csv_rows(text);
  std::map<std::string, std::vector<std::string>> out;
  for (std::size_t i = 1; i < rows.size(); ++i)
    for (std::size_t c = 0; c < rows[0].size(); ++c) out[rows[0][c]].push_back(c < rows[i].size() ? rows[i][c] : "");
  return out;
}

std::vector<double> numbers(const std::vector<std::string>& v) {
  std::vector<double> out;
  for (const auto& s : v) out.push_back(std::stod(s));
  return out;
}

/// Spearman's rho without ties, the plain way: 1 - 6 sum d^2 / (n (n^2 - 1)).
double spearman_no_ties(const std::vector<double>& x, const std::vector<double>& y) {
  auto rank = [](const std::vector<double>& v) {
    std::vector<double> r(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
      r[i] = 1.0 + static_cast<double>(std::count_if(v.begin(), v.end(), [&](double w) { return w < v[i]; }));
    return r;
  };
  const auto rx = rank(x), ry = rank(y);
  double d2 = 0.0;
  for (std::size_t i = 0; i < rx.size(); ++i) d2 += (rx[i] - ry[i]) * (rx[i] - ry[i]);
  const double n = static_cast<double>(x.size());
  return 1.0 - 6.0 * d2 / (n * (n * n - 1.0));
}

TEST(CliSampled, DrawsFollowTheirDistributionsAndTheStatisticsAreThoseOfTheTable) {
  const Scratch s("sampled");
  s.write("case.toml", sampled_case(R"(samples = 10
threshold_m = 0.2
sample = { "contact.friction_coefficient" = { distribution = "uniform", min = 0.05, max = 0.35 }, "contact.normal_preload" = { distribution = "lognormal", median = 10.0, log_std = 0.2 } }
)"));
  const CliResult r = s.run("study case.toml --quiet --threads 2");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto table = columns(slurp(s.dir() / "results" / "sampled" / "study.csv"));
  ASSERT_EQ(table.at("sample").size(), 10u);
  for (const auto& st : table.at("status")) EXPECT_EQ(st, "ok");
  // Latin hypercube: one friction coefficient in each tenth of [0.05, 0.35].
  const auto mu = numbers(table.at("contact.friction_coefficient"));
  std::vector<int> strata(10, 0);
  for (double m : mu) {
    ASSERT_GT(m, 0.05);
    ASSERT_LT(m, 0.35);
    ++strata[static_cast<std::size_t>((m - 0.05) / 0.03)];
  }
  for (int c : strata) EXPECT_EQ(c, 1);
  const auto n0 = numbers(table.at("contact.normal_preload"));
  for (double v : n0) EXPECT_GT(v, 0.0);
  // run.json's statistics recomputed from study.csv.
  const auto peaks = numbers(table.at("peak_amplitude_m"));
  const auto run = nlohmann::json::parse(slurp(s.dir() / "results" / "sampled" / "run.json"));
  const auto& st = run["study"];
  EXPECT_TRUE(st["sampled"].get<bool>());
  EXPECT_EQ(st["method"], "latin_hypercube");
  double mean = 0.0;
  for (double p : peaks) mean += p / static_cast<double>(peaks.size());
  std::vector<double> sorted = peaks;
  std::sort(sorted.begin(), sorted.end());
  // Written with 17 significant digits: the same numbers to round-off.
  constexpr double kRoundOff = 1e-13;
  EXPECT_NEAR(st["statistics"]["peak_amplitude_m"]["mean"].get<double>(), mean, kRoundOff * mean);
  EXPECT_NEAR(st["statistics"]["peak_amplitude_m"]["p50"].get<double>(), 0.5 * (sorted[4] + sorted[5]),
              kRoundOff * mean);
  EXPECT_EQ(st["statistics"]["peak_amplitude_m"]["max"].get<double>(), sorted.back());
  const int above = static_cast<int>(std::count_if(peaks.begin(), peaks.end(), [](double p) { return p > 0.2; }));
  EXPECT_EQ(st["exceedance"]["above"].get<int>(), above);
  EXPECT_LE(st["exceedance"]["low_95"].get<double>(), above / 10.0);
  EXPECT_GE(st["exceedance"]["high_95"].get<double>(), above / 10.0);
  ASSERT_EQ(st["sensitivity"].size(), 2u);
  EXPECT_EQ(st["sensitivity"][0]["key"], "contact.friction_coefficient");
  EXPECT_NEAR(st["sensitivity"][0]["spearman_peak_amplitude"].get<double>(), spearman_no_ties(mu, peaks), 1e-12);
  EXPECT_NEAR(st["sensitivity"][1]["spearman_peak_amplitude"].get<double>(), spearman_no_ties(n0, peaks), 1e-12);
  EXPECT_TRUE(std::filesystem::exists(s.dir() / "results" / "sampled" / "study_statistics.json"));

  // The same seed draws the same table (every column but the times); another seed others.
  const CliResult again = s.run("study case.toml --quiet --out results/again");
  ASSERT_EQ(again.status, 0) << again.err;
  auto second = columns(slurp(s.dir() / "results" / "again" / "study.csv"));
  auto first = table;
  first.erase("seconds"), second.erase("seconds");
  EXPECT_EQ(first, second);
  const CliResult other = s.run("study case.toml --quiet --out results/other --set study.seed=2");
  ASSERT_EQ(other.status, 0) << other.err;
  EXPECT_NE(columns(slurp(s.dir() / "results" / "other" / "study.csv")).at("contact.friction_coefficient"),
            table.at("contact.friction_coefficient"));
}

TEST(CliSampled, ADrawTheCaseRefusesIsRecordedWithItsReasonAndTheOthersRun) {
  // A normal friction coefficient of mean 0.05 and std 0.1 draws negative values (refused by
  // contact.friction_coefficient >= 0) in about 30 % of the samples.
  const Scratch s("sampled_refused");
  s.write("case.toml", sampled_case(R"(samples = 12
method = "random"
sample = { "contact.friction_coefficient" = { distribution = "normal", mean = 0.05, std = 0.1 } }
)"));
  const CliResult r = s.run("study case.toml --quiet");
  EXPECT_EQ(r.status, 3) << r.err;
  const auto table = columns(slurp(s.dir() / "results" / "sampled" / "study.csv"));
  const auto mu = numbers(table.at("contact.friction_coefficient"));
  int refused = 0;
  for (std::size_t i = 0; i < mu.size(); ++i) {
    if (mu[i] < 0) {
      ++refused;
      EXPECT_EQ(table.at("status")[i], "failed");
      EXPECT_NE(table.at("message")[i].find("contact.friction_coefficient"), std::string::npos)
          << table.at("message")[i];
    } else {
      EXPECT_EQ(table.at("status")[i], "ok") << table.at("message")[i];
      EXPECT_GT(std::stod(table.at("peak_amplitude_m")[i]), 0.0);
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_LT(refused, 12);
  const auto run = nlohmann::json::parse(slurp(s.dir() / "results" / "sampled" / "run.json"));
  EXPECT_EQ(run["study"]["failed"].get<int>(), refused);
  EXPECT_EQ(run["study"]["statistics"]["peak_amplitude_m"]["count"].get<int>(), 12 - refused);
  EXPECT_NE(r.err.find("samples failed"), std::string::npos) << r.err;
}

TEST(CliSampled, BadSampleTablesExitTwoNamingTheKey) {
  const Scratch s("sampled_bad");
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"(sample = { "contact.friction_coefficient" = { distribution = "weibull", min = 0.1, max = 0.2 } })",
       "distribution must be one of"},
      {R"(sample = { "contact.friction_coefficient" = { distribution = "uniform", min = 0.3, max = 0.2 } })",
       "min < max"},
      {R"(sample = { "contact.friction_coefficient" = { distribution = "normal", mean = 0.3 } })", "needs std"},
      {R"(sample = { "contact.friction_coefficient" = { distribution = "normal", mean = 0.3, std = 0.1, min = 0 } })",
       "unknown field 'min'"},
      {R"(sample = { "hbm.harmonics" = { distribution = "uniform", min = 1, max = 5 } })", "only number keys"},
      {R"(sample = { "contact.friction_coeficient" = { distribution = "uniform", min = 0.1, max = 0.2 } })",
       "did you mean"},
      {R"(vary = { "contact.normal_preload" = [1.0] }
sample = { "contact.friction_coefficient" = { distribution = "uniform", min = 0.1, max = 0.2 } })",
       "not both study.vary and study.sample"},
  };
  for (const auto& [table, what] : bad) {
    s.write("case.toml", sampled_case(table + "\n"));
    const CliResult r = s.run("study case.toml --quiet");
    EXPECT_EQ(r.status, 2) << table << "\n" << r.err;
    EXPECT_NE(r.err.find("case.toml:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("study.sample"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(s.dir() / "results" / "sampled" / "study.csv"));
  }
}

std::map<std::string, std::vector<std::string>> without_seconds(std::map<std::string, std::vector<std::string>> t) {
  t.erase("seconds");
  return t;
}

TEST(CliSampled, ResumeReusesTheFinishedPointsOfTheSameCaseOnly) {
  const Scratch s("resume_done");
  s.write("case.toml", sampled_case(R"(vary = { "contact.friction_coefficient" = [0.1, 0.2, 0.3, 0.4] }
)"));
  ASSERT_EQ(s.run("study case.toml --quiet").status, 0);
  const std::string before = slurp(s.dir() / "results" / "sampled" / "study.csv");
  const CliResult again = s.run("study case.toml --quiet --resume");
  ASSERT_EQ(again.status, 0) << again.err;
  auto run = nlohmann::json::parse(slurp(s.dir() / "results" / "sampled" / "run.json"));
  EXPECT_EQ(run["study"]["reused_points"].get<int>(), 4);
  // Reused points keep their numbers and their recorded times: the same table.
  EXPECT_EQ(slurp(s.dir() / "results" / "sampled" / "study.csv"), before);
  // Another case (a tighter tolerance): no point is the same, every one runs again.
  const CliResult other = s.run("study case.toml --quiet --resume --set hbm.tolerance=1e-9");
  ASSERT_EQ(other.status, 0) << other.err;
  run = nlohmann::json::parse(slurp(s.dir() / "results" / "sampled" / "run.json"));
  EXPECT_EQ(run["study"]["reused_points"].get<int>(), 0);
}

TEST(CliSampled, AKilledStudyResumesWithOnlyItsMissingPoints) {
  const Scratch s("resume_killed");
  s.write("case.toml", sampled_case(R"(samples = 24
sample = { "contact.friction_coefficient" = { distribution = "uniform", min = 0.05, max = 0.35 } }
)"));
  // The reference: the whole study in one go.
  ASSERT_EQ(s.run("study case.toml --quiet --out full").status, 0);
  // The same study killed once a few points are done (its staging folder names its pid).
  std::thread run([&] { s.run("study case.toml --quiet --threads 1 --out r"); });
  int pid = -1, done = 0;
  for (int i = 0; i < 4000 && done < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(s.dir(), ec)) {
      const std::string n = e.path().filename().string();
      if (n.rfind(".r.staging-", 0) != 0) continue;
      pid = std::stoi(n.substr(11));
      done = 0;
      for (const auto& p : std::filesystem::directory_iterator(e.path(), ec))
        done += std::filesystem::exists(p.path() / "run.json") ? 1 : 0;
    }
  }
  ASSERT_GT(pid, 0);
  ::kill(pid, SIGKILL);
  run.join();
  ASSERT_FALSE(std::filesystem::exists(s.dir() / "r" / "study.csv")) << "killed before the end";
  int finished = 0;
  for (const auto& e : std::filesystem::directory_iterator(s.dir())) {
    if (e.path().filename().string().rfind(".r.staging-", 0) != 0) continue;
    for (const auto& p : std::filesystem::directory_iterator(e.path()))
      finished += std::filesystem::exists(p.path() / "run.json") ? 1 : 0;
  }
  ASSERT_GE(finished, 3);
  ASSERT_LT(finished, 24) << "the study was not killed mid-way";
  const CliResult resumed = s.run("study case.toml --quiet --resume --out r");
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  const auto run_json = nlohmann::json::parse(slurp(s.dir() / "r" / "run.json"));
  EXPECT_EQ(run_json["study"]["reused_points"].get<int>(), finished);
  // The resumed study is the whole study: every sample, the same numbers.
  EXPECT_EQ(without_seconds(columns(slurp(s.dir() / "r" / "study.csv"))),
            without_seconds(columns(slurp(s.dir() / "full" / "study.csv"))));
  for (const auto& e : std::filesystem::directory_iterator(s.dir()))
    EXPECT_EQ(e.path().filename().string().find(".staging-"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace shroudsim::testing
