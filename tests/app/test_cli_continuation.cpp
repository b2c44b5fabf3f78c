// The forced response of an FE sector does not depend on the units of time the case is
// written in, nor on the thread count (docs/continuation.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
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
      // The same case with 2 threads: the same file, bit for bit. Its receptances are computed
      // again (the receptance stage runs the K_h factorizations in parallel), not read from
      // the first run's cache entry.
      for (const auto& e : std::filesystem::directory_iterator(s.dir() / ".cache"))
        if (e.path().filename().string().rfind("receptances-", 0) == 0) std::filesystem::remove(e.path());
      const CliResult r2 = s.run("frf " + name + " --quiet --threads 2 --out " + out + "_2");
      ASSERT_EQ(r2.status, 0) << r2.err;
      EXPECT_FALSE(
          nlohmann::json::parse(slurp(s.dir() / (out + "_2") / "run.json"))["frf_model"]["receptances"]["reused"]
              .get<bool>());
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

TEST(CliContinuation, PeaksLocatedInParallelAreTheSameAtAnyThreadCount) {
  // Every prominent maximum is located with equations of its own, on up to --threads workers:
  // on a sector whose Newton systems go through the lagged preconditioner (>= 250 unknowns:
  // 10 node pairs, H = 5), with several peaks, 1 and 2 threads write the same curve and the
  // same located peaks, bit for bit.
  const Scratch s("parallel_peaks");
  s.write("case.toml", coarse_sector_case(80.0, 130.0));
  for (const char* t : {"1", "2"}) {
    const CliResult r =
        s.run(std::string("frf case.toml --quiet --no-plots --set 'contact.pairs=\"all\"' ") +
              "--set 'contact.discretization=\"nodes\"' --set hbm.harmonics=5 --threads " + t + " --out out" + t);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const auto frf = frf_of(s, "out1");
  EXPECT_GE(frf["unknowns"].get<int>(), 250);
  int located = 0;
  for (const auto& p : frf["peaks"]) located += p["located"].get<bool>() ? 1 : 0;
  EXPECT_GE(located, 2);
  EXPECT_EQ(slurp(s.dir() / "out1" / "frf.csv"), slurp(s.dir() / "out2" / "frf.csv"));
  EXPECT_EQ(slurp(s.dir() / "out1" / "peaks.csv"), slurp(s.dir() / "out2" / "peaks.csv"));
  EXPECT_EQ(frf["peaks"].dump(), frf_of(s, "out2")["peaks"].dump());
}

TEST(CliContinuation, PointsAreJudgedByTheirEnergyBalanceAtTheirOwnScale) {
  // A stress-corpus model (tools/stress_continuation.py, seed 1, model 74: 3 DOFs, a 1d
  // contact 150 times stiffer than the structure, stuck, at the excited DOF, N = 64). Solved
  // to the corrector's tolerance, relative to the free motion (orders of magnitude above the
  // clamped motion), its energy balance missed by 0.14 of the excitation work per cycle
  // though its amplitudes equal the stuck linear response to 7 digits; polished at each
  // point's own scale it balances to ~1e-6.
  const Scratch s("energy");
  s.write("case.toml", R"(name = "stress_0074"

[structure]
type = "lumped"
sectors = 1
mass = [[0.03840514117196052, 0.0, 0.0], [0.0, 0.03154466528782106, 0.0], [0.0, 0.0, 0.1029848885039463]]
stiffness = [[85796730.74564694, -45960403.407765195, 0.0], [-45960403.407765195, 63584727.87830496, -17624324.470539767], [0.0, -17624324.470539767, 45594290.19558298]]
damping = [[0.6201114417970204, -0.22569507098599897, 0.0], [-0.22569507098599897, 0.4755247474285935, -0.08654674170650771], [0.0, -0.08654674170650771, 0.7569722956509034]]

[excitation]
force = 0.6563521410889713
dof = 0

[response]
dof = 2

[contact]
model = "1d"
friction_coefficient = 0.7030690948118106
tangential_stiffness = 12694115164.065872
normal_stiffness = 20402611548.839394
normal_preload = 2.7319310870975975

[[contact.elements]]
x_dof = 0

[hbm]
harmonics = 4
time_samples = 64

[continuation]
frequency_start_hz = 2011.6141859588283
frequency_end_hz = 3913.0516074698676
)");
  const CliResult ok = s.run("frf case.toml --quiet");
  ASSERT_EQ(ok.status, 0) << ok.err;
  const auto frf = frf_of(s, "results/stress_0074");
  EXPECT_TRUE(frf["energy_check_passed"].get<bool>());
  EXPECT_GT(frf["polished_points"].get<int>(), 0);
  EXPECT_LT(frf["max_energy_balance_error"].get<double>(), 1e-5);
}

TEST(CliContinuation, ACurveThatFailsItsEnergyCheckIsNotReportedAsSuccess) {
  // The Jenkins oscillator balances its energy to ~1e-8 per cycle; asked for 1e-13 it fails
  // the check: exit 3, the curve written, the key named.
  const Scratch s("energy_check");
  const CliResult bad = s.run("frf " + std::string(SHROUDSIM_SOURCE_DIR) +
                              "/cases/lumped_jenkins.toml --quiet --out out --set hbm.energy_tolerance=1e-13");
  EXPECT_EQ(bad.status, 3) << bad.err;
  EXPECT_NE(bad.err.find("hbm.energy_tolerance"), std::string::npos) << bad.err;
  // Traced again with 4 N and 16 N, the error stays at ~1e-7 (the balance of a harmonic-balance
  // solution does not depend on N): the message says that a finer N will not help.
  EXPECT_NE(bad.err.find("the energy error does not fall with N"), std::string::npos) << bad.err;
  const auto frf = frf_of(s, "out");
  EXPECT_FALSE(frf["energy_check_passed"].get<bool>());
  const std::string csv = slurp(s.dir() / "out" / "frf.csv");
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 100);
  const CliResult good =
      s.run("frf " + std::string(SHROUDSIM_SOURCE_DIR) + "/cases/lumped_jenkins.toml --quiet --out out2");
  EXPECT_EQ(good.status, 0) << good.err;
}

TEST(CliContinuation, ACurveThatStopsAtCornersOfTheSampledLawIsTracedAgainWithAFinerSampling) {
  // Stress corpus model 14 (quasi3d, H = 2, N = 64): at N = 64 the branch closes on itself at
  // a corner of the sampled law, from either end and from the middle of the gap (exit 3). With
  // hbm.raise_time_samples (the default) it is traced again with 4 N = 256, which reaches the
  // end: the result is that curve, exactly the one a case with N = 256 gives, and run.json and
  // the warning say so. With the option off, the case's N stands and the stop is reported.
  const Scratch s("raise_n");
  s.write("case.toml", R"(name = "stress_0014"

[structure]
type = "lumped"
sectors = 1
mass = [[60.03472219001946, 0.0, 0.0, 0.0, 0.0], [0.0, 31.189723176261673, 0.0, 0.0, 0.0], [0.0, 0.0, 49.29516142930039, 0.0, 0.0], [0.0, 0.0, 0.0, 76.20675453473119, 0.0], [0.0, 0.0, 0.0, 0.0, 29.071178341147046]]
stiffness = [[9368.054461067362, 2730.13310342276, 2196.5868893828997, 4677.736728095047, 3034.6263212322365], [2730.13310342276, 11636.947235488784, 2440.477623090116, 6158.901119219361, -2576.274558823115], [2196.5868893828997, 2440.477623090116, 8554.744069306267, -1087.0994399904132, -192.86160993255024], [4677.736728095047, 6158.901119219361, -1087.0994399904132, 14976.25210078617, 849.0895873679985], [3034.6263212322365, -2576.274558823115, -192.86160993255024, 849.0895873679985, 8892.469835005626]]
damping = [[29.90879857627771, 3.982528367251045, 3.204228243352614, 6.823557133831758, 4.426701904446536], [3.982528367251045, 25.414036488147232, 3.559999089939157, 8.984176774251276, -3.758090218926391], [3.204228243352614, 3.559999089939157, 25.816641971258775, -1.5857850858468343, -0.2813331084653534], [6.823557133831758, 8.984176774251276, -1.5857850858468343, 42.46524340774627, 1.2385928597368139], [4.426701904446536, -3.758090218926391, -0.2813331084653534, 1.2385928597368139, 20.837378254336958]]

[excitation]
force = 16999.121192627077
dof = 3

[response]
# The continuation is this test's subject; the stability stage, which would
# cost more than the curve here, is tested on its own (stability tests below).
stability = false
dof = 0

[contact]
model = "quasi3d"
friction_coefficient = 0.3344267324403067
tangential_stiffness = 656.0573797507546
normal_stiffness = 6619457.879076438
normal_preload = 14.308612615242884
frame_angle_deg = 0.0

[[contact.elements]]
x_dof = 1
y_dof = 0
z_dof = 3

[hbm]
harmonics = 2
time_samples = 64

[continuation]
frequency_start_hz = 0.9967331688984198
frequency_end_hz = 2.1641631349525445)");
  const CliResult raised = s.run("frf case.toml --quiet --out raised");
  ASSERT_EQ(raised.status, 0) << raised.err;
  const auto frf = frf_of(s, "raised");
  EXPECT_EQ(frf["time_samples"].get<int>(), 256);
  EXPECT_EQ(frf["status"], "reached_end");
  ASSERT_TRUE(frf.contains("time_samples_raised"));
  EXPECT_EQ(frf["time_samples_raised"]["from"].get<int>(), 64);
  const auto& attempts = frf["time_samples_raised"]["attempts"];
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_FALSE(attempts[0]["passed"].get<bool>());
  EXPECT_NE(attempts[0]["message"].get<std::string>().find("closed on itself"), std::string::npos);
  EXPECT_TRUE(attempts[1]["passed"].get<bool>());
  EXPECT_NE(raised.err.find("traced again with N = 256"), std::string::npos) << raised.err;
  EXPECT_FALSE(std::filesystem::exists(s.dir() / "raised" / "raised")) << "the attempt's folder is removed";

  const CliResult direct = s.run("frf case.toml --quiet --out direct --set hbm.time_samples=256");
  ASSERT_EQ(direct.status, 0) << direct.err;
  EXPECT_FALSE(frf_of(s, "direct").contains("time_samples_raised"));
  EXPECT_EQ(slurp(s.dir() / "raised" / "frf.csv"), slurp(s.dir() / "direct" / "frf.csv"));
  EXPECT_EQ(slurp(s.dir() / "raised" / "peaks.csv"), slurp(s.dir() / "direct" / "peaks.csv"));

  const CliResult kept = s.run("frf case.toml --quiet --out kept --set hbm.raise_time_samples=false");
  EXPECT_EQ(kept.status, 3) << kept.err;
  EXPECT_NE(kept.err.find("closed on itself"), std::string::npos) << kept.err;
  const auto k = frf_of(s, "kept");
  EXPECT_EQ(k["time_samples"].get<int>(), 64);
  EXPECT_FALSE(k.contains("time_samples_raised"));
}

TEST(CliContinuation, WhereNoMotionOfTheExcitationsPeriodExistsTheStopSaysSo) {
  // A stress-corpus model (tools/stress_continuation.py, seed 1, model 131: 3 DOFs, a full3d
  // contact without preload, so it impacts; first mode 8.41 Hz) started at 4.27 Hz, about half
  // of it. No harmonic-balance start is found there, and a time integration from rest
  // (forced/time_march.hpp) settles on a motion that repeats every two excitation periods: a
  // subharmonic, which a harmonic balance of the excitation's period cannot represent. The range
  // is traced from its other end, 12.3 Hz, until the branch turns back; then the run stops
  // (exit 3) and says why there is no start at 4.27 Hz. (With hbm.raise_time_samples on, the
  // default, the range is then traced again with N = 512: from 12.3 Hz that branch reaches
  // 4.27 Hz, 441 points, exit 0, in about a minute; this test keeps N = 128.)
  const Scratch s("subharmonic");
  s.write("case.toml", R"(name = "stress_0131"

[structure]
type = "lumped"
sectors = 1
mass = [[18.15501439951414, 0.0, 0.0], [0.0, 42.8550096420159, 0.0], [0.0, 0.0, 10.490537497208551]]
stiffness = [[370681.8733347799, -186888.25051647378, 0.0], [-186888.25051647378, 319495.4706231562, -132607.2201066824], [0.0, -132607.2201066824, 223491.84451767677]]
damping = [[266.1261834145856, -94.91376025229103, 0.0], [-94.91376025229103, 346.07344752183434, -67.34639476877648], [0.0, -67.34639476877648, 158.49930917894164]]

[excitation]
force = 3.498485488581492
dof = 2

[response]
# The continuation is this test's subject; the stability stage, which would
# cost more than the curve here, is tested on its own (stability tests below).
stability = false
dof = 0

[contact]
model = "full3d"
friction_coefficient = 0.49809335994186493
tangential_stiffness = 4453169.612587134
normal_stiffness = 13937757.214890867
normal_preload = 0.0
frame_angle_deg = 15.335515728693025

[[contact.elements]]
x_dof = 2
y_dof = 0
z_dof = 1

[hbm]
harmonics = 12
time_samples = 128

[continuation]
frequency_start_hz = 4.269022959253111
frequency_end_hz = 12.316202486923972
)");
  const CliResult r = s.run("frf case.toml --quiet --out out --set hbm.raise_time_samples=false");
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("no solution at the start frequency"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("subharmonic (repeats every 2 excitation periods"), std::string::npos) << r.err;
  const auto run = nlohmann::json::parse(slurp(s.dir() / "out" / "run.json"));
  EXPECT_NE(run.dump().find("subharmonic"), std::string::npos);
  // Without a start at the start of the range, the range was traced from its other end: the
  // curve down to where the branch turns back is written (970 points).
  EXPECT_NE(run["frf"]["start"].get<std::string>().find("from the end of the range"), std::string::npos)
      << run["frf"]["start"];
  EXPECT_GT(run["frf"]["points"].get<int>(), 100);
}

TEST(CliContinuation, WithoutAResonanceInTheRangeThePeakIsTheLargestPoint) {
  // The Jenkins oscillator above its 10 Hz resonance, 12 to 20 Hz: the amplitude falls all
  // the way, so there is no interior peak to locate; the reported one is the largest point
  // (the first, listed as an end-of-range maximum that was not located).
  const Scratch s("falling");
  const CliResult r = s.run("frf " + std::string(SHROUDSIM_SOURCE_DIR) +
                            "/cases/lumped_jenkins.toml --quiet --out out --set continuation.frequency_start_hz=12"
                            " --set continuation.frequency_end_hz=20");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto frf = frf_of(s, "out");
  ASSERT_EQ(frf["peaks"].size(), 1u);
  EXPECT_FALSE(frf["peaks"][0]["located"].get<bool>());
  EXPECT_EQ(frf["peak_frequency_hz"].get<double>(), 12.0);
  std::istringstream csv(slurp(s.dir() / "out" / "frf.csv"));
  std::string line;
  std::getline(csv, line);  // header
  double largest = 0.0;
  while (std::getline(csv, line)) largest = std::max(largest, std::stod(line.substr(line.find(',') + 1)));
  EXPECT_EQ(frf["peak_amplitude_m"].get<double>(), largest);
}

TEST(CliContinuation, AVeryStiffSampledContactIsFollowedRoundTheCornersWhereItsBranchTurnsBack) {
  // Stress corpus model 168: a 1d Jenkins contact 8,880 times stiffer than the structure,
  // sampled on N = 64. The stick phase after each reversal is ~1e-5 of the sample spacing, so
  // the sampled force is a staircase of steep slabs; at one of them (0.7366 Hz) the branch
  // ends on its piece and turns back by ~166 degrees, where no hyperplane ahead meets it. The
  // corrector used to stall there at every step size (exit 3); the turn at the corner follows
  // the other piece (continuation::turn_at_corner) and the curve reaches the end.
  const Scratch s("stiff_corner");
  s.write("case.toml", R"(name = "stress_0168"

[structure]
type = "lumped"
sectors = 1
mass = [[8.28659034910023, 0.0, 0.0, 0.0], [0.0, 11.69038242952306, 0.0, 0.0], [0.0, 0.0, 6.186343951528171, 0.0], [0.0, 0.0, 0.0, 14.14799018959927]]
stiffness = [[1215.0554328008352, 690.9986243479839, -171.73988641783225, -266.3964456487466], [690.9986243479839, 1252.832500977837, -673.2923994823614, 41.046485028175354], [-171.73988641783225, -673.2923994823614, 899.9359842918869, -382.2961917424062], [-266.3964456487466, 41.046485028175354, -382.2961917424062, 784.2393531359447]]
damping = [[0.24903086649611597, 0.09310812308374238, -0.02314097006787495, -0.035895401490761814], [0.09310812308374238, 0.2891625877242719, -0.09072231028173805, 0.005530779722990761], [-0.02314097006787495, -0.09072231028173805, 0.18494862882751598, -0.051512231169468306], [-0.035895401490761814, 0.005530779722990761, -0.051512231169468306, 0.2513229995849307]]

[excitation]
force = 0.0005573659550485557
dof = 1

[response]
dof = 1

[contact]
model = "1d"
friction_coefficient = 0.4130197069319451
tangential_stiffness = 9216894.689610455
normal_stiffness = 2027.7335811873024
normal_preload = 0.0017353467731309477

[[contact.elements]]
x_dof = 0

[hbm]
harmonics = 5
time_samples = 64

[continuation]
frequency_start_hz = 0.5035226317992781
frequency_end_hz = 1.006079560439476)");
  const CliResult r = s.run("frf case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto frf = frf_of(s, "results/stress_0168");
  EXPECT_TRUE(frf["energy_check_passed"].get<bool>());
  EXPECT_GT(frf["kinks_crossed"].get<int>(), 0);
}

TEST(CliContinuation, AGapBothPiecesLeaveIsCoveredFromItsMiddleAndReportedHonestly) {
  // Stress corpus model 105 (quasi3d, N = 64): the branch from 545 Hz closes on itself near
  // 778 Hz, the one traced back from 1392 Hz near 1004 Hz; between them no piece got through
  // and the run used to stop (exit 3). A start in the middle of the gap, traced both ways,
  // covers it: exit 0 and four pieces in frf.csv. Whether the middle pieces end on the pieces
  // they run into depends on round-off: the first piece loops near 772 Hz, and in a build with
  // FMA (-march=native) the backward middle piece ends 4.6 scaled units from it, on another
  // sheet, while a portable build's ends on it (join distance 3e-8). Either way the report must
  // say what was found: the flag, the distance and the warning's words agree.
  const Scratch s("gap_middle");
  s.write("case.toml", R"(name = "stress_0105"

[structure]
type = "lumped"
sectors = 1
mass = [[20.527841424563977, 0.0, 0.0, 0.0], [0.0, 104.54819099206871, 0.0, 0.0], [0.0, 0.0, 87.97837496433017, 0.0], [0.0, 0.0, 0.0, 119.01449762240684]]
stiffness = [[4268575626.744325, 196050792.3089846, -1600439918.6397486, -996650982.536285], [196050792.3089846, 5899021123.720413, -1636841536.2168021, -3729562681.3690977], [-1600439918.6397486, -1636841536.2168021, 3402412039.4073896, 1061079982.3023541], [-996650982.536285, -3729562681.3690977, 1061079982.3023541, 8950267825.224955]]
damping = [[116.30663967447224, 4.038083160984023, -32.964465022106594, -20.528147336507942], [4.038083160984023, 266.07388172002027, -33.71423377967842, -76.81827797836853], [-32.964465022106594, -33.71423377967842, 191.7378866934617, 21.855199657849077], [-20.528147336507942, -76.81827797836853, 21.855199657849077, 348.9250503828979]]

[excitation]
force = 0.008188408188264853
dof = 1

[response]
dof = 2

[contact]
model = "quasi3d"
friction_coefficient = 0.19079267070287287
tangential_stiffness = 150483167.26757142
normal_stiffness = 7150255545.2713
normal_preload = 9.762483354157716
frame_angle_deg = 0.0

[[contact.elements]]
x_dof = 3
y_dof = 1
z_dof = 0

[hbm]
harmonics = 4
time_samples = 64

[continuation]
frequency_start_hz = 545.0431703885854
frequency_end_hz = 1391.629964680137)");
  const CliResult r = s.run("frf case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto frf = frf_of(s, "results/stress_0105");
  EXPECT_EQ(frf["pieces"].get<int>(), 4);
  ASSERT_TRUE(frf.contains("pieces_join"));
  ASSERT_TRUE(frf.contains("join_distance"));
  // The join test of frequency_response.cpp: two solutions of one branch agree far within a
  // step (kJoinTolerance, scaled units); an infinite distance (the corrector found no point)
  // is written as null.
  constexpr double kJoinTolerance = 1e-5;
  const bool join = frf["pieces_join"].get<bool>();
  const bool measured = frf["join_distance"].is_number();
  if (join) {
    ASSERT_TRUE(measured);
    EXPECT_LE(frf["join_distance"].get<double>(), kJoinTolerance);
    EXPECT_NE(r.err.find("four pieces that join"), std::string::npos) << r.err;
  } else {
    if (measured) {
      EXPECT_GT(frf["join_distance"].get<double>(), kJoinTolerance);
    }
    EXPECT_NE(r.err.find("four pieces, not all shown to be one branch"), std::string::npos) << r.err;
  }
  EXPECT_TRUE(frf["energy_check_passed"].get<bool>());
  // Every piece's points lie inside the range, and between them they cover it.
  const auto rows = csv_rows(slurp(s.dir() / "results" / "stress_0105" / "frf.csv"));
  const double f0 = 545.0431703885854, f1 = 1391.629964680137;
  std::vector<double> f;
  for (std::size_t i = 1; i < rows.size(); ++i) f.push_back(std::stod(rows[i][0]));
  std::sort(f.begin(), f.end());
  ASSERT_FALSE(f.empty());
  EXPECT_NEAR(f.front(), f0, 1e-9 * f0);
  EXPECT_NEAR(f.back(), f1, 1e-9 * f1);
  double widest = 0.0;
  for (std::size_t i = 1; i < f.size(); ++i) widest = std::max(widest, f[i] - f[i - 1]);
  EXPECT_LT(widest, 0.01 * (f1 - f0));  // no stretch of the range left without points
}

// The frequency extents of frf.csv's pieces (column `piece`), merged: whether every frequency
// of [f0, f1] lies between the lowest and the highest frequency of some piece.
bool pieces_cover(const std::vector<std::vector<std::string>>& rows, double f0, double f1) {
  std::size_t piece_col = rows[0].size();
  for (std::size_t c = 0; c < rows[0].size(); ++c)
    if (rows[0][c] == "piece") piece_col = c;
  if (piece_col == rows[0].size()) return false;
  std::map<int, std::pair<double, double>> span;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const int k = std::stoi(rows[i][piece_col]);
    const double f = std::stod(rows[i][0]);
    auto it = span.find(k);
    if (it == span.end()) span[k] = {f, f};
    else it->second = {std::min(it->second.first, f), std::max(it->second.second, f)};
  }
  std::vector<std::pair<double, double>> spans;
  for (const auto& [k, s] : span) spans.push_back(s);
  std::sort(spans.begin(), spans.end());
  const double slack = 1e-9 * (f1 - f0);  // a piece that reached an end is put on it to this
  double covered = f0;
  for (const auto& [a, b] : spans) {
    if (a > covered + slack) return false;
    covered = std::max(covered, b);
  }
  return covered >= f1 - slack;
}

TEST(CliContinuation, PastAPieceThatClosedOnItselfTheCurveGoesOnFromANewStart) {
  // Stress corpus model 154 (full3d, kt 4,160 times the structure's stiffness, zeta 4e-4) at
  // N = 256: the branch from 12.66 Hz closes on itself on a loop of the sampled law near
  // 13.08 Hz, the one traced back from 28.35 Hz near 21.76 Hz, and of the two pieces from the
  // middle of that gap one closes on itself too, near 13.18 Hz. Before the hops the run
  // stopped there (exit 3). A start just past where a piece stopped (Newton from that piece's
  // last point, else the whole start search in the stretch left uncovered), traced both ways,
  // covers the rest: exit 0, more than the four pieces of the middle search, and the report
  // says they were not all shown to be one branch unless they passed the join test.
  const Scratch s("hops");
  s.write("case.toml", R"(name = "stress_0154"

[structure]
type = "lumped"
sectors = 1
mass = [[13.814332609063378, 0.0, 0.0, 0.0], [0.0, 61.907424596993366, 0.0, 0.0], [0.0, 0.0, 65.05893911886453, 0.0], [0.0, 0.0, 0.0, 50.206374742552015]]
stiffness = [[448906.7750189198, -19381.637961102744, 17273.40478248263, 10484.781392774581], [-19381.637961102744, 599360.7723250751, -118829.7816038158, -193403.48023575134], [17273.40478248263, -118829.7816038158, 504661.5989044049, 152300.852037347], [10484.781392774581, -193403.48023575134, 152300.852037347, 702335.8346729153]]
damping = [[4.75342249408158, -0.20522994747087148, 0.18290610748516486, 0.11102215090392023], [-0.20522994747087148, 6.346562662414807, -1.2582749654838095, -2.047927330451932], [0.18290610748516486, -1.2582749654838095, 5.343803946889129, 1.612696301835952], [0.11102215090392023, -2.047927330451932, 1.612696301835952, 7.436953819182371]]

[excitation]
force = 401.5283804791073
dof = 2

[response]
# The continuation is this test's subject; the stability stage, which would
# cost more than the curve here, is tested on its own (stability tests below).
stability = false
dof = 1

[contact]
model = "full3d"
friction_coefficient = 0.7154487416904293
tangential_stiffness = 2348195090.069985
normal_stiffness = 1263063.0126657402
normal_preload = 252.4071610291438
frame_angle_deg = 0.0

[[contact.elements]]
x_dof = 2
y_dof = 0
z_dof = 1

[hbm]
harmonics = 3
time_samples = 256

[continuation]
frequency_start_hz = 12.658354212715707
frequency_end_hz = 28.35090486285054)");
  const CliResult r = s.run("frf case.toml --quiet --set hbm.raise_time_samples=false");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("starts past where they stopped gave the rest"), std::string::npos) << r.err;
  const auto frf = frf_of(s, "results/stress_0154");
  EXPECT_GT(frf["pieces"].get<int>(), 4);
  EXPECT_TRUE(frf["energy_check_passed"].get<bool>());
  // The join test of frequency_response.cpp (kJoinTolerance, scaled units); a piece that
  // stopped short of its neighbour has no join distance (null).
  constexpr double kJoinTolerance = 1e-5;
  if (frf["pieces_join"].get<bool>()) {
    EXPECT_LE(frf["join_distance"].get<double>(), kJoinTolerance);
  } else {
    EXPECT_NE(r.err.find("not all shown to be one branch"), std::string::npos) << r.err;
    if (frf["join_distance"].is_number()) {
      EXPECT_GT(frf["join_distance"].get<double>(), kJoinTolerance);
    }
  }
  // Checked from frf.csv alone: the pieces' frequency extents cover the range, and every point
  // lies in it (to the tracing's slack).
  const auto rows = csv_rows(slurp(s.dir() / "results" / "stress_0154" / "frf.csv"));
  const double f0 = 12.658354212715707, f1 = 28.35090486285054;
  ASSERT_GT(rows.size(), 100u);
  EXPECT_TRUE(pieces_cover(rows, f0, f1));
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const double f = std::stod(rows[i][0]);
    EXPECT_GE(f, f0 - 1e-9 * f0);
    EXPECT_LE(f, f1 + 1e-9 * f1);
  }
}

TEST(CliContinuation, ACurveJoinedOnlyByHopsGivesWayToAFinerSamplingThatNeedsNone) {
  // Stress corpus model 58 at its N = 64: the pieces from the ends stop, and the hops cover the
  // rest in pieces not shown to be one branch, with a larger peak than the curve at N = 256,
  // which needs no hop. With hbm.raise_time_samples (the default) the finer N is tried and is
  // the result; the N = 64 curve is kept only where no finer N does better. Without it, the
  // curve in pieces is the result (exit 0, its hops counted).
  const Scratch s("hops_or_finer");
  s.write("case.toml", R"(name = "stress_0058"

[structure]
type = "lumped"
sectors = 1
mass = [[6.303228595967036, 0.0, 0.0, 0.0], [0.0, 1.0926034600016292, 0.0, 0.0], [0.0, 0.0, 1.378425480327431, 0.0], [0.0, 0.0, 0.0, 1.8669798261590043]]
stiffness = [[465.2332706330768, 92.727249849641, 6.993668200307193, -8.570739205957745], [92.727249849641, 607.2453741380245, 142.25664526528422, -160.15505936649743], [6.993668200307193, 142.25664526528422, 962.958472498098, 105.70374681883405], [-8.570739205957745, -160.15505936649743, 105.70374681883405, 470.2728439294243]]
damping = [[0.579382259021919, 0.027811430509912367, 0.0020975917810311336, -0.002570598375683393], [0.027811430509912367, 0.25837249716730765, 0.04266664665224107, -0.048034869055263774], [0.0020975917810311336, 0.04266664665224107, 0.38500552420820955, 0.031703435765174426], [-0.002570598375683393, -0.048034869055263774, 0.031703435765174426, 0.2713275219785402]]

[excitation]
force = 77.86869524095493
dof = 3

[response]
# The continuation is this test's subject; the stability stage, which would
# cost more than the curve here, is tested on its own (stability tests below).
stability = false
dof = 0

[contact]
model = "full3d"
friction_coefficient = 0.4633797382543974
tangential_stiffness = 604404.8317925647
normal_stiffness = 2199743.3342519156
normal_preload = 0.005022327237656415
frame_angle_deg = 88.29268957931117

[[contact.elements]]
x_dof = 0
y_dof = 2
z_dof = 3

[hbm]
harmonics = 2
time_samples = 64

[continuation]
frequency_start_hz = 0.8932721449688094
frequency_end_hz = 2.0593885510196044)");
  const CliResult fixed = s.run("frf case.toml --quiet --out fixed --set hbm.raise_time_samples=false");
  ASSERT_EQ(fixed.status, 0) << fixed.err;
  const auto at64 = frf_of(s, "fixed");
  EXPECT_EQ(at64["time_samples"].get<int>(), 64);
  EXPECT_GT(at64["hops"].get<int>(), 0);
  EXPECT_FALSE(at64["pieces_join"].get<bool>());
  const CliResult raised = s.run("frf case.toml --quiet --out raised");
  ASSERT_EQ(raised.status, 0) << raised.err;
  const auto finer = frf_of(s, "raised");
  EXPECT_GT(finer["time_samples"].get<int>(), 64);
  EXPECT_EQ(finer["hops"].get<int>(), 0);
  const auto& attempts = finer["time_samples_raised"]["attempts"];
  ASSERT_GE(attempts.size(), 2u);
  EXPECT_FALSE(attempts[0]["passed"].get<bool>());
  EXPECT_NE(attempts[0]["message"].get<std::string>().find("only by hops"), std::string::npos) << attempts[0];
  EXPECT_NE(raised.err.find("reached the end only by hops"), std::string::npos) << raised.err;
}

TEST(CliContinuation, WithNoStartAtEitherEndTheCurveIsSoughtInsideTheRangeAndWhatItFindsIsKept) {
  // Stress corpus model 25 (quasi3d, 6 DOFs, the excitation 6e4 times the friction limit, so
  // the contact separates): no start at 0.125 Hz nor at 0.223 Hz (no harmonic-balance start,
  // and time integration finds no periodic motion at either). A start in the middle of the
  // range (0.174 Hz) is traced both ways; neither piece gets through and the stretch below
  // has no start either, so the run stops (exit 3), but the pieces found are written (before,
  // the run stopped with nothing written) and run.json says where the start came from.
  const Scratch s("inside");
  s.write("case.toml", R"(name = "stress_0025"

[structure]
type = "lumped"
sectors = 1
mass = [[0.12060880851326367, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.1831494931516441, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.05957955445498279, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.05125342047198694, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.1224024616494912, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0, 0.03186353318906183]]
stiffness = [[1.1265803777204322, -0.2543432213575282, -0.34419249173496497, 0.0859006940465509, -0.4534136146380125, 0.008335899984497476], [-0.2543432213575282, 0.9430806326547926, 0.32343965699740473, -0.043944594179658854, -0.25952015587423743, 0.27568602339313086], [-0.34419249173496497, 0.32343965699740473, 1.1472946768493382, 0.46607307934819836, 0.2797645422749079, 0.22598087332369354], [0.0859006940465509, -0.043944594179658854, 0.46607307934819836, 0.5053544832660387, 0.12990194385296247, 0.11222121394049711], [-0.4534136146380125, -0.25952015587423743, 0.2797645422749079, 0.12990194385296247, 0.6859928028612103, 0.005884016232945085], [0.008335899984497476, 0.27568602339313086, 0.22598087332369354, 0.11222121394049711, 0.005884016232945085, 0.4998011259278221]]
damping = [[0.0002600400652518066, -3.6306725507343866e-05, -4.913243707621311e-05, 1.2262064241352112e-05, -6.472342199682398e-05, 1.1899245082234384e-06], [-3.6306725507343866e-05, 0.0002852978678105285, 4.6170032690932765e-05, -6.272957894835089e-06, -3.70457172503298e-05, 3.935334593987725e-05], [-4.913243707621311e-05, 4.6170032690932765e-05, 0.00021278857731219035, 6.653052229165172e-05, 3.9935542173481786e-05, 3.225808611639786e-05], [1.2262064241352112e-05, -6.272957894835089e-06, 6.653052229165172e-05, 0.00011430369727533475, 1.8543109555533304e-05, 1.6019238841483453e-05], [-6.472342199682398e-05, -3.70457172503298e-05, 3.9935542173481786e-05, 1.8543109555533304e-05, 0.0001986231490264923, 8.399255191865154e-07], [1.1899245082234384e-06, 3.935334593987725e-05, 3.225808611639786e-05, 1.6019238841483453e-05, 8.399255191865154e-07, 9.755903145235235e-05]]

[excitation]
force = 6104.132864748908
dof = 1

[response]
dof = 4

[contact]
model = "quasi3d"
friction_coefficient = 0.8282915073020134
tangential_stiffness = 1.7587972085208725
normal_stiffness = 1179.0159200198561
normal_preload = 0.09845147424177142
frame_angle_deg = 0.0

[[contact.elements]]
x_dof = 4
y_dof = 3
z_dof = 1

[hbm]
harmonics = 9
time_samples = 128

[continuation]
frequency_start_hz = 0.12518401127621737
frequency_end_hz = 0.22304599246229262)");
  const CliResult r = s.run("frf case.toml --quiet --out out --set hbm.raise_time_samples=false");
  ASSERT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("inside the range:"), std::string::npos) << r.err;
  const auto frf = frf_of(s, "out");
  EXPECT_EQ(frf["start"].get<std::string>(), "inside the range (none at either end)");
  EXPECT_FALSE(frf["pieces_join"].get<bool>());
  const auto rows = csv_rows(slurp(s.dir() / "out" / "frf.csv"));
  EXPECT_GT(rows.size(), 100u);
  for (std::size_t i = 1; i < rows.size(); ++i)
    for (const auto& v : rows[i]) EXPECT_EQ(v.find("nan"), std::string::npos) << "row " << i;
}

TEST(CliContinuation, TheMiddleBranchBetweenTwoFoldsIsReportedUnstable) {
  // cases/gap_oscillator.toml: a hardening gap oscillator whose curve leans over a fold pair.
  // frf.csv's `stable` column is 0 exactly on a stretch traced backwards in frequency (up to the
  // points next to each fold, where the curve is nearly vertical) and run.json lists two folds.
  const Scratch s("stability_gap");
  s.write("case.toml", slurp(std::filesystem::path(SHROUDSIM_SOURCE_DIR) / "cases" / "gap_oscillator.toml"));
  const CliResult r = s.run("frf case.toml --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto frf = frf_of(s, "results/gap_oscillator");
  ASSERT_TRUE(frf.contains("stability"));
  const auto& st = frf["stability"];
  EXPECT_TRUE(st["available"].get<bool>());
  EXPECT_EQ(st["method"].get<std::string>(), "hill");  // no friction: a memoryless law
  EXPECT_EQ(st["failed_points"].get<int>(), 0);
  ASSERT_EQ(st["changes"].size(), 2u);
  for (const auto& c : st["changes"]) EXPECT_EQ(c["kind"].get<std::string>(), "fold");
  const auto rows = csv_rows(slurp(s.dir() / "results" / "gap_oscillator" / "frf.csv"));
  ASSERT_GT(rows.size(), 10u);
  ASSERT_EQ(rows[0].back(), "stable");
  int unstable = 0, backwards_unstable = 0;
  for (std::size_t i = 1; i + 1 < rows.size(); ++i) {
    if (rows[i].back() != "0") continue;
    ++unstable;
    if (std::stod(rows[i + 1][0]) < std::stod(rows[i][0])) ++backwards_unstable;
  }
  EXPECT_EQ(unstable, st["unstable_points"].get<int>());
  EXPECT_GT(unstable, 10);
  // All but the points next to the folds (at most two at each) step backwards.
  EXPECT_GE(backwards_unstable, unstable - 4);
}

TEST(CliContinuation, ShootingAndHillAgreeOnAFrictionlessGapOscillator) {
  // Without friction the contact law has no memory, and Hill's method on the harmonic balance's
  // linearization (the default here) and the shooting on the time integration
  // (response.stability_method = "shooting") are two independent judgements of the same
  // solutions: the same two folds, and the same verdict at every point but those next to a fold
  // (within kNearFold points of where Hill's verdict changes), where a multiplier is within the
  // integration's error of 1 and Newton on the period map converges slowly. The folds' frequencies
  // agree to kFoldAgreement, relative: both are interpolated between the two points either side,
  // which lie closer than that together near a fold (measured: 8e-6 and 5e-6).
  constexpr int kNearFold = 2;
  constexpr double kFoldAgreement = 1e-4;
  const Scratch s("stability_both");
  s.write("case.toml", slurp(std::filesystem::path(SHROUDSIM_SOURCE_DIR) / "cases" / "gap_oscillator.toml"));
  ASSERT_EQ(s.run("frf case.toml --quiet --threads 2 --out hill").status, 0);
  const CliResult r =
      s.run("frf case.toml --quiet --threads 2 --out shooting --set response.stability_method=\"shooting\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto hill = frf_of(s, "hill")["stability"];
  const auto st = frf_of(s, "shooting")["stability"];
  EXPECT_EQ(hill["method"].get<std::string>(), "hill");
  EXPECT_EQ(st["requested"].get<std::string>(), "shooting");
  EXPECT_EQ(st["method"].get<std::string>(), "shooting");
  EXPECT_EQ(st["stride"].get<int>(), 1);
  ASSERT_EQ(st["changes"].size(), 2u);
  ASSERT_EQ(hill["changes"].size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(st["changes"][c]["kind"].get<std::string>(), "fold");
    const double f = hill["changes"][c]["frequency_hz"].get<double>();
    EXPECT_NEAR(st["changes"][c]["frequency_hz"].get<double>(), f, kFoldAgreement * f);
  }
  const auto a = csv_rows(slurp(s.dir() / "hill" / "frf.csv"));
  const auto b = csv_rows(slurp(s.dir() / "shooting" / "frf.csv"));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 10u);
  std::vector<std::size_t> folds;  // rows where Hill's verdict changes
  for (std::size_t i = 2; i < a.size(); ++i)
    if (a[i].back() != a[i - 1].back()) folds.push_back(i);
  ASSERT_EQ(folds.size(), 2u);
  int differ = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    EXPECT_EQ(a[i][0], b[i][0]) << "row " << i;  // the same curve
    if (a[i].back() == b[i].back()) continue;
    ++differ;
    const bool near = std::any_of(folds.begin(), folds.end(), [&](std::size_t f) {
      return std::abs(static_cast<long>(i) - static_cast<long>(f)) <= kNearFold;
    });
    EXPECT_TRUE(near) << "row " << i << " at " << a[i][0] << " Hz: Hill " << a[i].back() << ", shooting "
                      << b[i].back();
  }
  EXPECT_LE(differ, 2 * (2 * kNearFold + 1));
  EXPECT_GT(st["unstable_points"].get<int>(), 10);
}

/// Stress corpus model 8 (3 DOFs, quasi3d friction, H = 15, N = 128) with time rescaled by s:
/// mass s^2, damping s, frequencies / s.
std::string model_8(double s) {
  std::ostringstream c;
  c.precision(17);
  const double m[3] = {1.6066451485192936, 3.1022110663309252, 2.111869185489189};
  const double k[3][3] = {{7.043627933089065, 2.534038191691849, -1.3796205878592054},
                          {2.534038191691849, 3.712810230293924, 1.5670428633530467},
                          {-1.3796205878592054, 1.5670428633530467, 3.0050000077515504}};
  const double d[3][3] = {{0.44199958292165586, 0.15901518854703842, -0.08657352861573811},
                          {0.15901518854703842, 0.23298513051035977, 0.098334593848804},
                          {-0.08657352861573811, 0.098334593848804, 0.18856884019472284}};
  const auto matrix = [&](const double(*a)[3], double f) {
    std::ostringstream o;
    o.precision(17);
    o << "[";
    for (int i = 0; i < 3; ++i) {
      o << (i ? ", [" : "[");
      for (int j = 0; j < 3; ++j) o << (j ? ", " : "") << a[i][j] * f;
      o << "]";
    }
    o << "]";
    return o.str();
  };
  const double mass[3][3] = {{m[0], 0, 0}, {0, m[1], 0}, {0, 0, m[2]}};
  c << "name = \"stress_0008\"\n[structure]\ntype = \"lumped\"\nsectors = 1\nmass = " << matrix(mass, s * s)
    << "\nstiffness = " << matrix(k, 1.0) << "\ndamping = " << matrix(d, s)
    << "\n[excitation]\nforce = 1.1286367840819407\ndof = 1\n[response]\ndof = 2\n"
       "[contact]\nmodel = \"quasi3d\"\nfriction_coefficient = 0.28024622979545577\n"
       "tangential_stiffness = 17.127970366335703\nnormal_stiffness = 4.789290774238505\n"
       "normal_preload = 8.532175357752111\n[[contact.elements]]\nx_dof = 0\ny_dof = 1\nz_dof = 2\n"
       "[hbm]\nharmonics = 15\ntime_samples = 128\n[continuation]\nfrequency_start_hz = "
    << 0.053803261612576106 / s << "\nfrequency_end_hz = " << 0.1156911635999745 / s << "\n";
  return c.str();
}

TEST(CliContinuation, ALumpedFrictionModelIsJudgedByShootingTheSameAtAnyTimeScaleAndThreadCount) {
  // The harmonic balance's linearization (without the slider as a state) calls stretches of this
  // curve unstable where the time integration from rest settles on it (forced.Shooting tests);
  // the shooting on the time integration calls every point stable. The verdicts are a property of
  // the motion: the same with time rescaled by 1e-3, and with 1 or 2 threads.
  const Scratch s("shooting");
  std::vector<std::vector<std::vector<std::string>>> tables;
  for (double scale : {1.0, 1e-3}) {
    const std::string name = scale == 1.0 ? "case_1" : "case_2";
    s.write(name + ".toml", model_8(scale));
    const CliResult r = s.run("frf " + name + ".toml --quiet --threads 2 --out " + name);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto frf = frf_of(s, name);
    const auto& st = frf["stability"];
    EXPECT_EQ(st["method"].get<std::string>(), "shooting");
    EXPECT_EQ(st["failed_points"].get<int>(), 0);
    EXPECT_EQ(st["unstable_points"].get<int>(), 0);
    const auto rows = csv_rows(slurp(s.dir() / name / "frf.csv"));
    ASSERT_GT(rows.size(), 100u);
    ASSERT_EQ(rows[0].back(), "stable");
    for (std::size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i].back(), "1") << "row " << i;
    // Hill's verdicts (the slider as a state) are counted against the shooting's at up to 64 of
    // its points, every ceil(n / 64)-th (202 points: every 4th, 51): none differs.
    const std::size_t n = rows.size() - 1, stride = (n + 63) / 64;
    EXPECT_EQ(st["hill"]["judged_points"].get<std::size_t>(), (n + stride - 1) / stride);
    EXPECT_EQ(st["hill"]["disagreements"].get<int>(), 0);
    EXPECT_EQ(st["hill"]["unstable_points"].get<int>(), 0);
    tables.push_back(rows);
    if (scale == 1.0) {
      const CliResult r1 = s.run("frf " + name + ".toml --quiet --threads 1 --out " + name + "_t1");
      ASSERT_EQ(r1.status, 0) << r1.err;
      EXPECT_EQ(slurp(s.dir() / name / "frf.csv"), slurp(s.dir() / (name + "_t1") / "frf.csv"));
    }
  }
  EXPECT_EQ(tables[0].size(), tables[1].size());
}

TEST(CliContinuation, HillsMethodTakesTheSliderAsAStateAndAgreesWithTheShootingOnAFrictionModel) {
  // response.stability_method = "hill" on a lumped friction model (stress model 8): Hill's method
  // with the slider as a state (docs/physics.md section 9). The harmonic balance's dF/dW called
  // 8 of every 5th point unstable here where the integration from rest settles on the solution;
  // with the slider as a state no point is unstable, as the shooting ("auto") finds, and the
  // shooting run counts no disagreement with it.
  const Scratch s("stability_hill");
  s.write("case.toml", model_8(1.0));
  const CliResult r = s.run("frf case.toml --threads 2 --out hill --set response.stability_method=\"hill\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto frf = frf_of(s, "hill");
  const auto& st = frf["stability"];
  EXPECT_EQ(st["requested"].get<std::string>(), "hill");
  EXPECT_EQ(st["method"].get<std::string>(), "hill");
  EXPECT_EQ(st["linearization"].get<std::string>(), "slider_state");
  EXPECT_FALSE(st.contains("hill"));
  EXPECT_EQ(st["memory_samples"].get<int>(), 128);  // N: 2 x 128 damper positions fit
  EXPECT_EQ(st["unstable_points"].get<int>(), 0);
  const auto rows = csv_rows(slurp(s.dir() / "hill" / "frf.csv"));
  int ones = 0;
  for (std::size_t i = 1; i < rows.size(); ++i) ones += rows[i].back() == "1" ? 1 : 0;
  EXPECT_EQ(ones, static_cast<int>(rows.size()) - 1);

  const CliResult a = s.run("frf case.toml --threads 2 --out auto");
  ASSERT_EQ(a.status, 0) << a.err;
  const auto frf_auto = frf_of(s, "auto");
  const auto& sa = frf_auto["stability"];
  EXPECT_EQ(sa["method"].get<std::string>(), "shooting");
  EXPECT_GE(sa["hill"]["judged_points"].get<int>(), 50);  // up to 64 of the shooting's points
  EXPECT_EQ(sa["hill"]["disagreements"].get<int>(), 0);
  EXPECT_FALSE(sa["hill"].contains("reason"));

  // At N = 1024 with the slider state at every sample the pencil (186 + 2 x 1024 wide) is above
  // the size limit: Hill judges none of the shooting's points, and run.json says why.
  const CliResult big =
      s.run("frf case.toml --threads 2 --out big --set hbm.time_samples=1024 --set response.stability_samples=1024");
  ASSERT_EQ(big.status, 0) << big.err;
  const auto frf_big = frf_of(s, "big");
  const auto& sb = frf_big["stability"];
  EXPECT_EQ(sb["hill"]["judged_points"].get<int>(), 0);
  EXPECT_NE(sb["hill"]["reason"].get<std::string>().find("kMaxSliderStateSize"), std::string::npos) << sb["hill"];
}

}  // namespace
}  // namespace shroudsim::testing
