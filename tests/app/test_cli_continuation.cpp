// The forced response of an FE sector does not depend on the units of time the case is
// written in, nor on the thread count (docs/continuation.md).
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.hpp"

namespace shroudsim::testing {
namespace {

/// The default sector, coarse (mesh_size 0.03), its third family (~103 Hz) with 5 full3d
/// pairs at N = 512, with time rescaled by s: density * s^2 (every modal frequency / s, the
/// modal damping ratio unchanged) and the frequency range / s.
std::string rescaled_case(double s) {
  std::ostringstream c;
  c.precision(17);
  c << "name = \"rescaled\"\n[geometry]\nmesh_size = 0.03\n[material]\ndensity = " << 7850.0 * s * s
    << "\n[modal]\nmodes = 20\n[hbm]\ntime_samples = 512\n[continuation]\nfrequency_start_hz = " << 96.0 / s
    << "\nfrequency_end_hz = " << 110.0 / s << "\n";
  return c.str();
}

nlohmann::json frf_of(const Scratch& dir, const std::string& out) {
  return nlohmann::json::parse(slurp(dir.dir() / out / "run.json"))["frf"];
}

TEST(CliContinuation, TimeRescaledSectorGivesTheSamePeakAndAnyThreadCountTheSameFile) {
  const Scratch s("rescaled");
  std::vector<nlohmann::json> runs;
  const std::vector<double> scales = {0.1, 1.0, 10.0};
  for (double scale : scales) {
    const std::string name = "case_" + std::to_string(static_cast<int>(std::lround(std::log10(scale)) + 1)) + ".toml";
    s.write(name, rescaled_case(scale));
    const std::string out = "out_" + name;
    const CliResult r = s.run("frf " + name + " --quiet --threads 1 --out " + out);
    ASSERT_EQ(r.status, 0) << "s = " << scale << ": " << r.err;
    runs.push_back(frf_of(s, out));
    if (scale == 1.0) {
      // The same case with 2 threads: the same file, bit for bit.
      const CliResult r2 = s.run("frf " + name + " --quiet --threads 2 --out " + out + "_2");
      ASSERT_EQ(r2.status, 0) << r2.err;
      EXPECT_EQ(slurp(s.dir() / out / "frf.csv"), slurp(s.dir() / (out + "_2") / "frf.csv"));
    }
  }
  // The largest located peak agrees to the solver's tolerance. (The modal frequencies of the
  // rescaled models agree to round-off only, and on a curve with sampled stick-slip corners
  // round-off can change the path, hence the number of points: not compared here.)
  constexpr double kPeakTol = 1e-6;
  const double a1 = runs[1]["peak_amplitude_m"], f1 = runs[1]["peak_frequency_hz"];
  for (std::size_t i = 0; i < runs.size(); ++i) {
    EXPECT_EQ(runs[i]["status"], "reached_end");
    EXPECT_NEAR(runs[i]["peak_amplitude_m"].get<double>(), a1, kPeakTol * a1) << "s = " << scales[i];
    EXPECT_NEAR(runs[i]["peak_frequency_hz"].get<double>() * scales[i], f1, kPeakTol * f1) << "s = " << scales[i];
  }
}

}  // namespace
}  // namespace shroudsim::testing
