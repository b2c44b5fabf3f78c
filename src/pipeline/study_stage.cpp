// The study stages: see study_stage.hpp.
#include "pipeline/study_stage.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "distributed/task_pool.hpp"
#include "io/output.hpp"
#include "linalg/parallel.hpp"
#include "study/curves.hpp"
#include "study/sampling.hpp"
#include "study/trade_design.hpp"

namespace shroudsim::pipeline {
namespace {

struct StudyPoint {
  std::vector<std::pair<std::string, std::string>> values;  ///< key, TOML value text
  std::string folder;
  int status = -1;
  std::string message;
  double peak = 0.0, peak_frequency = 0.0, seconds = 0.0;
  double cpu_seconds = 0.0;  ///< CPU time of the point's own thread (points run with threads = 1)
  std::size_t points = 0;
  int harmonics = 0, time_samples = 0;  ///< of the curve reported (a raised N or a search may differ from the case's)
};

std::string folder_name(const std::vector<std::pair<std::string, std::string>>& values) {
  std::string s;
  for (const auto& [k, v] : values) {
    std::string key = k.substr(k.rfind('.') + 1), val = v;
    val.erase(std::remove(val.begin(), val.end(), '"'), val.end());
    for (char& ch : val)
      if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '-' && ch != '_') ch = '_';
    s += (s.empty() ? "" : "__") + key + "=" + val;
  }
  return s;
}

/// CPU time of the calling thread [s]: the cost of a study point whatever else the machine
/// (or the other workers) is doing.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// The command's two case runners: `run` (every stage of the case: sweep and convergence
/// points) and `frf` (the forced response only: sampled points).
struct Runners {
  const CaseRunner& run_case;
  const CaseRunner& run_forced;
};

/// A point's task for the work pool (distributed/task_pool.hpp): what any rank needs to run
/// it. Paths are absolute: a serving rank may start elsewhere (same file system).
distributed::Json point_task(const Context& ctx, const StudyPoint& p, bool forced) {
  std::vector<std::string> sets = ctx.overrides;
  for (const auto& [k, v] : p.values) sets.push_back(k + "=" + v);
  return {{"case_file", std::filesystem::absolute(ctx.config.file).string()},
          {"sets", sets},
          {"dir", std::filesystem::absolute(ctx.out_dir / p.folder).string()},
          {"forced", forced}};
}

/// Runs one point's task on this rank (quietly, one thread) into its folder, writes the
/// folder's run.json (the point's report, status, case and cost) and returns the result that
/// run_points reads back. Never throws: a failure is a status and a message.
distributed::Json run_point(const distributed::Json& task, const Runners& runners) {
  Context pc;
  pc.out_dir = task.at("dir").get<std::string>();
  pc.threads = 1;
  pc.plots = false;
  log::Stopwatch clock;
  const double cpu0 = thread_cpu_seconds();
  int status = 1;
  std::string message;
  bool loaded = false;
  try {
    pc.config = io::load_case(task.at("case_file").get<std::string>(), task.at("sets").get<std::vector<std::string>>());
    loaded = true;
    status = (task.at("forced").get<bool>() ? runners.run_forced : runners.run_case)(pc);
  } catch (const InputError& e) {
    status = 2, message = e.what();
  } catch (const NumericalError& e) {
    status = 3, message = e.what();
  } catch (const std::exception& e) {
    status = 1, message = e.what();
  }
  distributed::Json r = {{"status", status},
                         {"message", message},
                         {"seconds", clock.seconds()},
                         {"cpu_seconds", thread_cpu_seconds() - cpu0},
                         {"rank", distributed::world().rank()},
                         {"peak", 0.0},
                         {"peak_frequency", 0.0},
                         {"points", 0},
                         {"harmonics", 0},
                         {"time_samples", 0}};
  const auto& j = pc.report.json();
  if (j.contains("frf")) {
    r["peak"] = j["frf"].value("peak_amplitude_m", 0.0);
    r["peak_frequency"] = j["frf"].value("peak_frequency_hz", 0.0);
    r["points"] = j["frf"].value("points", std::size_t{0});
    r["harmonics"] = j["frf"].value("harmonics", 0);
    r["time_samples"] = j["frf"].value("time_samples", 0);
  }
  nlohmann::json rj = j;
  rj["status"] = status == 0 ? "ok" : "failed";
  if (!message.empty()) rj["message"] = message;
  if (loaded) rj["case"] = nlohmann::json::parse(pc.config.resolved_json);
  rj["point_seconds"] = r["seconds"];
  rj["point_cpu_seconds"] = r["cpu_seconds"];
  try {
    io::write_file_atomic(pc.out_dir / "run.json", rj.dump(2) + "\n");
  } catch (const std::exception&) {
  }
  return r;
}

/// Runs every point (the case `cases[i]` into <out>/<points[i].folder>) on --threads workers
/// here and, under `mpirun -n K`, on the workers of every rank (distributed/task_pool.hpp),
/// quietly, one line each; fills status, message, peak, points and seconds. The first point
/// runs alone: it fills the mesh and mode caches the others read. Returns the number of
/// workers used; reused_points: how many finished points --resume reused.
int run_points(Context& ctx, const std::vector<io::Case>& cases, std::vector<StudyPoint>& points,
               const Runners& runners, bool forced, int* reused_points = nullptr) {
  // --resume: a point whose folder holds a run.json of status ok for the same case (its
  // fingerprint: the resolved case, every key) is reused as it is; any other folder of a point
  // (a failed point, a point killed half-written, a point of another case) is cleared and run.
  std::vector<int> to_run;
  int reused = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::filesystem::path dir = ctx.out_dir / points[i].folder;
    std::error_code ec;
    if (ctx.resume && std::filesystem::exists(dir / "run.json", ec)) {
      try {
        std::ifstream in(dir / "run.json");
        const auto j = nlohmann::json::parse(in);
        if (j.value("status", "") == "ok" && j.contains("case") &&
            j["case"] == nlohmann::json::parse(cases[i].resolved_json)) {
          StudyPoint& p = points[i];
          p.status = 0;
          if (j.contains("frf")) {
            p.peak = j["frf"].value("peak_amplitude_m", 0.0);
            p.peak_frequency = j["frf"].value("peak_frequency_hz", 0.0);
            p.points = j["frf"].value("points", std::size_t{0});
            p.harmonics = j["frf"].value("harmonics", 0);
            p.time_samples = j["frf"].value("time_samples", 0);
          }
          p.seconds = j.value("point_seconds", 0.0);
          p.cpu_seconds = j.value("point_cpu_seconds", 0.0);
          ++reused;
          continue;
        }
      } catch (const std::exception&) {
        // unreadable: run the point again
      }
    }
    std::filesystem::remove_all(dir, ec);
    to_run.push_back(static_cast<int>(i));
  }
  if (ctx.resume)
    log::info("study --resume: " + std::to_string(reused) + " of " + std::to_string(points.size()) +
              " points reused (same case, status ok), " + std::to_string(to_run.size()) + " to run");
  if (reused_points) *reused_points = reused;
  const distributed::World& world = distributed::world();
  const int threads = linalg::worker_count(ctx.threads, std::max<int>(1, static_cast<int>(to_run.size())));
  const int others = world.size() - 1;
  log::info("study: " + std::to_string(to_run.size()) + " points on " + std::to_string(threads) +
            (threads == 1 ? " worker" : " workers") +
            (others > 0
                 ? " here and the workers of " + std::to_string(others) + (others == 1 ? " other rank" : " other ranks")
                 : std::string()));
  std::vector<distributed::Json> tasks;
  for (const int i : to_run) tasks.push_back(point_task(ctx, points[static_cast<std::size_t>(i)], forced));
  const bool verbose = log::verbose();
  log::set_verbose(false);  // points run quietly; one line each below
  const int workers = distributed::run_tasks(
      tasks, {threads, /*first_alone=*/true}, [&](const distributed::Json& t) { return run_point(t, runners); },
      [&](std::size_t k, const distributed::Json& r) {
        StudyPoint& p = points[static_cast<std::size_t>(to_run[k])];
        p.status = r.at("status").get<int>();
        p.message = r.at("message").get<std::string>();
        p.seconds = r.at("seconds").get<double>();
        p.cpu_seconds = r.at("cpu_seconds").get<double>();
        p.peak = r.at("peak").get<double>();
        p.peak_frequency = r.at("peak_frequency").get<double>();
        p.points = r.at("points").get<std::size_t>();
        p.harmonics = r.value("harmonics", 0);
        p.time_samples = r.value("time_samples", 0);
        if (!verbose) return;
        std::ostringstream s;
        s << "shroudsim: study: " << p.folder << ": " << (p.status == 0 ? "ok" : "failed (" + p.message + ")")
          << ", peak " << std::scientific << std::setprecision(4) << p.peak << " m at " << std::defaultfloat
          << std::setprecision(6) << p.peak_frequency << " Hz, " << std::setprecision(3) << p.seconds << " s";
        if (world.distributed()) s << " (rank " << r.at("rank").get<int>() << ")";
        std::cerr << s.str() << "\n";
      });
  log::set_verbose(verbose);
  return workers;
}

/// `study --convergence`: every knob of the accuracy/speed trade varied one at a time around
/// the case's own setting, each against its finest value (the reference), with every other
/// knob at the case's setting. The error of a point is peaks_change (study/curves.hpp) between
/// its curve and the reference's (the largest relative change at any resonance peak of the
/// range) and peaks_shift_hz (the largest shift of such a peak); its cost is its wall time (a run
/// that has to build a new mesh and its modes pays for them). -> trade.csv, trade.png.
StudyOutcome run_convergence(Context& ctx, const Runners& runners) {
  const io::Case& c = ctx.config;
  auto num = [](double v) { return io::format_number(v); };
  const std::vector<study::Knob> knobs = study::convergence_knobs(c);
  if (knobs.empty()) throw InputError(c.file.string() + ": study --convergence: this case has no knob to vary");

  // Points: one per distinct set of overrides (the case itself appears under several knobs).
  std::vector<StudyPoint> points;
  std::map<std::string, std::size_t> index;
  auto point_of = [&](std::vector<std::pair<std::string, std::string>> values) {
    std::sort(values.begin(), values.end());
    // Overrides equal to the case's own setting are dropped, so equal points merge.
    std::vector<std::pair<std::string, std::string>> kept;
    for (const auto& [k, v] : values) {
      const io::Case probe = io::load_case(c.file, [&] {
        std::vector<std::string> sets = ctx.overrides;
        sets.push_back(k + "=" + v);
        return sets;
      }());
      if (probe.resolved_json != c.resolved_json) kept.emplace_back(k, v);
    }
    const std::string name = kept.empty() ? "case" : folder_name(kept);
    auto [it, fresh] = index.emplace(name, points.size());
    if (fresh) {
      StudyPoint p;
      p.values = kept;
      p.folder = name;
      points.push_back(p);
    }
    return it->second;
  };
  struct Row {
    std::size_t knob, point, reference;
    std::string value;
  };
  std::vector<Row> rows;
  std::vector<std::string> reference_label(knobs.size());
  try {
    for (std::size_t k = 0; k < knobs.size(); ++k) {
      // Every value at the case's other settings; the reference is the finest value, with
      // the knob's extra overrides (e.g. more samples for more harmonics) when it has some,
      // listed as a row of its own.
      auto ref = knobs[k].reference;
      ref.emplace_back(knobs[k].key, knobs[k].values.back());
      const std::size_t r = point_of(ref);
      reference_label[k] = knobs[k].values.back();
      for (const auto& [key, value] : knobs[k].reference) reference_label[k] += " " + key + "=" + value;
      for (const auto& v : knobs[k].values) rows.push_back({k, point_of({{knobs[k].key, v}}), r, v});
      if (!knobs[k].reference.empty()) rows.push_back({k, r, r, reference_label[k]});
    }
  } catch (const InputError& e) {
    throw InputError(c.file.string() + ": study --convergence: a varied value is not valid for this case: " + e.what());
  }
  std::vector<io::Case> cases;
  for (const auto& p : points) {
    std::vector<std::string> sets = ctx.overrides;
    for (const auto& [k, v] : p.values) sets.push_back(k + "=" + v);
    cases.push_back(io::load_case(c.file, sets));
  }
  log::info("study --convergence: " + std::to_string(knobs.size()) + " knobs, " + std::to_string(points.size()) +
            " runs");
  log::Stopwatch clock;
  int reused = 0;
  const int workers = run_points(ctx, cases, points, runners, /*forced=*/false, &reused);
  ctx.report.stage("study", clock.seconds());

  std::ostringstream csv;
  csv << "knob,key,value,reference_value,status,seconds,points,peak_amplitude_m,peak_frequency_hz,peaks_error,"
         "peak_frequency_error_hz,folder,cpu_seconds,harmonics,time_samples\n";
  int failed = 0;
  for (const auto& row : rows) {
    const StudyPoint& p = points[row.point];
    const StudyPoint& r = points[row.reference];
    const bool ok = p.status == 0 && r.status == 0;
    double err = 0.0, ferr = 0.0;
    if (ok) {
      const auto cp = study::read_curve(ctx.out_dir / p.folder / "frf.csv"),
                 cr = study::read_curve(ctx.out_dir / r.folder / "frf.csv");
      err = study::peaks_change(cp, cr);
      ferr = study::peaks_shift_hz(cp, cr);
    }
    std::string value = row.value, ref = reference_label[row.knob];
    for (std::string* t : {&value, &ref}) t->erase(std::remove(t->begin(), t->end(), '"'), t->end());
    csv << knobs[row.knob].name << "," << knobs[row.knob].key << "," << value << "," << ref << ","
        << (p.status == 0 ? "ok" : "failed") << "," << num(p.seconds) << "," << p.points << "," << num(p.peak) << ","
        << num(p.peak_frequency) << "," << (ok ? num(err) : "") << "," << (ok ? num(ferr) : "") << "," << p.folder
        << "," << num(p.cpu_seconds) << "," << p.harmonics << "," << p.time_samples << "\n";
    failed += p.status != 0;
  }
  io::write_file_atomic(ctx.out_dir / "trade.csv", csv.str());
  ctx.report.section("study") = {{"convergence", true},
                                 {"runs", points.size()},
                                 {"knobs", knobs.size()},
                                 {"failed_rows", failed},
                                 {"workers", workers},
                                 {"reused_points", reused},
                                 {"ranks", distributed::world().size()}};
  // The mesh ladder: observed order and extrapolated peak (docs/contact_patches.md).
  for (std::size_t k = 0; k < knobs.size(); ++k) {
    if (knobs[k].key != "geometry.mesh_size") continue;
    std::vector<double> sizes, peaks;
    bool all_ok = true;
    for (const auto& row : rows)
      if (row.knob == k) {
        sizes.push_back(std::stod(row.value));
        peaks.push_back(points[row.point].peak);
        all_ok = all_ok && points[row.point].status == 0;
      }
    if (!all_ok || peaks.size() < 3) continue;
    const study::MeshConvergence mc = study::mesh_convergence(peaks, study::kMeshRatio);
    nlohmann::json j = {{"mesh_sizes_m", sizes},
                        {"peaks_m", peaks},
                        {"case_peak_m", peaks.front()},
                        {"finest_peak_m", peaks.back()},
                        {"monotone", mc.monotone}};
    j["observed_order"] = mc.monotone ? nlohmann::json(mc.order) : nlohmann::json(nullptr);
    j["extrapolated_peak_m"] = mc.monotone ? nlohmann::json(mc.extrapolated) : nlohmann::json(nullptr);
    j["case_error_estimate"] = mc.case_error;
    ctx.report.section("mesh_convergence") = j;
    std::ostringstream s;
    s << "study --convergence: mesh: peak " << io::format_number(peaks.front()) << " m at the case's size, "
      << io::format_number(peaks.back()) << " m at the finest";
    if (mc.monotone)
      s << "; observed order " << std::setprecision(3) << mc.order << ", extrapolated "
        << io::format_number(mc.extrapolated) << " m";
    else s << "; not monotone over the three finest sizes (no extrapolation)";
    s << "; estimated mesh error of the case: " << std::setprecision(3) << 100.0 * mc.case_error << " %";
    log::info(s.str());
  }
  StudyOutcome outcome;
  if (failed) outcome.warning = std::to_string(failed) + " rows of trade.csv failed (see their folders' run.json)";
  return outcome;
}

/// A message as one CSV field: no commas, quotes or line breaks.
std::string csv_field(std::string s) {
  for (char& ch : s)
    if (ch == ',' || ch == '\n' || ch == '\r') ch = ';';
    else if (ch == '"') ch = '\'';
  return s;
}

study::Distribution distribution_of(const io::SampleInput& in) {
  study::Distribution d;
  d.kind = in.distribution == "uniform"  ? study::Distribution::Kind::uniform
           : in.distribution == "normal" ? study::Distribution::Kind::normal
                                         : study::Distribution::Kind::lognormal;
  d.a = in.a, d.b = in.b;
  return d;
}

nlohmann::json statistics_json(const study::SampleStatistics& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"std", s.std_dev}, {"min", s.min}, {"p05", s.p05},
          {"p25", s.p25},     {"p50", s.p50},   {"p75", s.p75},     {"p95", s.p95}, {"max", s.max}};
}

/// A sampled study ([study] sample): study.samples points of the unit cube (study.method,
/// study.seed) mapped through each input's distribution; a point whose drawn values the case
/// refuses (e.g. a normal friction coefficient below 0) is recorded as failed with the reason
/// and the others run. -> study.csv (one row per sample), run.json study.statistics (peak
/// amplitude and frequency: mean, std, percentiles; the exceedance of study.threshold_m with its
/// 95 % Wilson interval; Spearman's rank correlation of each input with both).
StudyOutcome run_sampled(Context& ctx, const Runners& runners) {
  const io::Case& base = ctx.config;
  const io::StudySection& st = base.study;
  const int n = st.samples, dims = static_cast<int>(st.sample.size());
  const auto unit = study::unit_samples(st.method, n, dims, static_cast<std::uint64_t>(st.seed));
  std::vector<study::Distribution> dist;
  for (const auto& in : st.sample) dist.push_back(distribution_of(in));
  std::vector<std::vector<double>> drawn(static_cast<std::size_t>(n));
  std::vector<StudyPoint> points(static_cast<std::size_t>(n));
  std::vector<io::Case> cases;
  std::vector<StudyPoint> runnable;
  std::vector<std::size_t> runnable_index;
  const int width = static_cast<int>(std::to_string(n).size());
  for (int i = 0; i < n; ++i) {
    StudyPoint& p = points[static_cast<std::size_t>(i)];
    std::vector<std::string> sets = ctx.overrides;
    for (int d = 0; d < dims; ++d) {
      const double v =
          dist[static_cast<std::size_t>(d)].quantile(unit[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)]);
      drawn[static_cast<std::size_t>(i)].push_back(v);
      p.values.emplace_back(st.sample[static_cast<std::size_t>(d)].key, io::format_number(v));
      sets.push_back(st.sample[static_cast<std::size_t>(d)].key + "=" + io::format_number(v));
    }
    std::ostringstream folder;
    folder << "sample_" << std::setw(width) << std::setfill('0') << i + 1;
    p.folder = folder.str();
    try {
      cases.push_back(io::load_case(base.file, sets));
      runnable.push_back(p);
      runnable_index.push_back(static_cast<std::size_t>(i));
    } catch (const InputError& e) {
      p.status = 2;
      p.message = std::string("the drawn values are not a valid case: ") + e.what();
    }
  }
  log::info("study: sampled, " + std::to_string(n) + " points (" + io::to_string(st.method) + ", seed " +
            std::to_string(st.seed) + "), " + std::to_string(n - static_cast<int>(runnable.size())) +
            " refused by the case's rules");
  int workers = 0, reused = 0;
  if (!runnable.empty()) {
    workers = run_points(ctx, cases, runnable, runners, /*forced=*/true, &reused);
    for (std::size_t k = 0; k < runnable.size(); ++k) points[runnable_index[k]] = runnable[k];
  }

  std::ostringstream csv;
  csv << "sample";
  for (const auto& in : st.sample) csv << "," << in.key;
  csv << ",status,peak_amplitude_m,peak_frequency_hz,points,seconds,folder,message,harmonics,time_samples\n";
  int failed = 0;
  std::vector<double> peaks, freqs;
  std::vector<std::vector<double>> inputs(static_cast<std::size_t>(dims));
  for (int i = 0; i < n; ++i) {
    const StudyPoint& p = points[static_cast<std::size_t>(i)];
    csv << i + 1;
    for (const auto& [k, v] : p.values) csv << "," << v;
    const bool ok = p.status == 0;
    csv << "," << (ok ? "ok" : "failed") << "," << io::format_number(p.peak) << ","
        << io::format_number(p.peak_frequency) << "," << p.points << "," << io::format_number(p.seconds) << ","
        << p.folder << "," << csv_field(p.message) << "," << p.harmonics << "," << p.time_samples << "\n";
    failed += !ok;
    if (!ok) continue;
    peaks.push_back(p.peak);
    freqs.push_back(p.peak_frequency);
    for (int d = 0; d < dims; ++d)
      inputs[static_cast<std::size_t>(d)].push_back(drawn[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)]);
  }
  io::write_file_atomic(ctx.out_dir / "study.csv", csv.str());

  nlohmann::json j = {{"sampled", true},
                      {"points", n},
                      {"failed", failed},
                      {"workers", workers},
                      {"samples", n},
                      {"method", io::to_string(st.method)},
                      {"seed", st.seed},
                      {"inputs", nlohmann::json::array()},
                      {"reused_points", reused},
                      {"ranks", distributed::world().size()}};
  for (std::size_t d = 0; d < st.sample.size(); ++d)
    j["inputs"].push_back({{"key", st.sample[d].key}, {"distribution", dist[d].describe()}});
  if (!peaks.empty()) {
    const study::SampleStatistics a = study::summarize(peaks), f = study::summarize(freqs);
    j["statistics"] = {{"peak_amplitude_m", statistics_json(a)}, {"peak_frequency_hz", statistics_json(f)}};
    if (st.threshold_m > 0) {
      const study::Exceedance e = study::exceedance(peaks, st.threshold_m);
      j["exceedance"] = {{"threshold_m", st.threshold_m},
                         {"probability", e.probability},
                         {"low_95", e.low},
                         {"high_95", e.high},
                         {"above", e.above},
                         {"count", e.count}};
    }
    j["sensitivity"] = nlohmann::json::array();
    for (std::size_t d = 0; d < st.sample.size(); ++d) {
      const auto ra = study::spearman(inputs[d], peaks), rf = study::spearman(inputs[d], freqs);
      j["sensitivity"].push_back({{"key", st.sample[d].key},
                                  {"spearman_peak_amplitude", ra ? nlohmann::json(*ra) : nlohmann::json(nullptr)},
                                  {"spearman_peak_frequency", rf ? nlohmann::json(*rf) : nlohmann::json(nullptr)}});
    }
    std::ostringstream s;
    s << "study: peak amplitude over " << a.count << " samples: mean " << io::format_number(a.mean) << " m, std "
      << io::format_number(a.std_dev) << " m, 5 % / 50 % / 95 % " << io::format_number(a.p05) << " / "
      << io::format_number(a.p50) << " / " << io::format_number(a.p95) << " m";
    if (j.contains("exceedance"))
      s << "; P(peak > " << io::format_number(st.threshold_m) << " m) = " << std::setprecision(3)
        << j["exceedance"]["probability"].get<double>() << " [" << j["exceedance"]["low_95"].get<double>() << ", "
        << j["exceedance"]["high_95"].get<double>() << "]";
    log::info(s.str());
  }
  // Also on its own for the plot (drawn before run.json is written).
  io::write_file_atomic(ctx.out_dir / "study_statistics.json", j.dump(2) + "\n");
  ctx.report.section("study") = j;
  StudyOutcome outcome;
  if (failed)
    outcome.warning =
        std::to_string(failed) + " of " + std::to_string(n) + " samples failed (see study.csv, column message)";
  return outcome;
}

}  // namespace

StudyOutcome run_study(Context& ctx, const CaseRunner& run_case, const CaseRunner& run_forced) {
  const Runners runners{run_case, run_forced};
  if (ctx.convergence) return run_convergence(ctx, runners);
  if (!ctx.config.study.sample.empty()) return run_sampled(ctx, runners);
  const io::Case& base = ctx.config;
  if (base.study.vary.empty())
    throw InputError(base.locations.at("study.vary") +
                     ": study.vary and study.sample are empty: name at least one key and its values (a sweep) or "
                     "its distribution (a sampled study)");
  // Bounded work: the product's size before any point is built.
  constexpr double kMaxStudyPoints = 10000;
  double count = 1;
  for (const auto& [key, values] : base.study.vary) count *= static_cast<double>(values.size());
  if (count > kMaxStudyPoints)
    throw InputError(base.locations.at("study.vary") + ": study.vary spans " + io::format_number(count) +
                     " points (the product of its value lists), more than " + io::format_number(kMaxStudyPoints) +
                     " a study runs; split it into several studies");
  // Cartesian product, first key slowest.
  std::vector<StudyPoint> points(1);
  for (const auto& [key, values] : base.study.vary) {
    std::vector<StudyPoint> next;
    for (const auto& p : points)
      for (const auto& v : values) {
        StudyPoint q = p;
        q.values.emplace_back(key, v);
        next.push_back(q);
      }
    points = next;
  }
  // Every point is validated before any runs: a bad value is an input error up front.
  std::vector<io::Case> cases;
  for (auto& p : points) {
    std::vector<std::string> sets = ctx.overrides;
    for (const auto& [k, v] : p.values) sets.push_back(k + "=" + v);
    try {
      cases.push_back(io::load_case(base.file, sets));
    } catch (const InputError& e) {
      throw InputError(base.locations.at("study.vary") + ": study point " + folder_name(p.values) + ": " + e.what());
    }
    p.folder = folder_name(p.values);
  }
  // Values that sanitize to one folder name ("a/b.msh" and "a_b.msh") get a suffix of
  // their own (the point's index), so that no point overwrites another.
  {
    std::map<std::string, int> uses;
    for (const auto& p : points) ++uses[p.folder];
    for (std::size_t i = 0; i < points.size(); ++i)
      if (uses[points[i].folder] > 1) points[i].folder += "__point" + std::to_string(i + 1);
  }
  int reused = 0;
  const int workers = run_points(ctx, cases, points, runners, /*forced=*/false, &reused);

  std::ostringstream csv;
  for (const auto& [k, v] : points.front().values) csv << k << ",";
  csv << "status,peak_amplitude_m,peak_frequency_hz,points,seconds,folder,harmonics,time_samples\n";
  int failed = 0;
  for (const auto& p : points) {
    for (const auto& [k, v] : p.values) {
      std::string val = v;
      val.erase(std::remove(val.begin(), val.end(), '"'), val.end());
      csv << val << ",";
    }
    csv << (p.status == 0 ? "ok" : "failed") << "," << io::format_number(p.peak) << ","
        << io::format_number(p.peak_frequency) << "," << p.points << "," << io::format_number(p.seconds) << ","
        << p.folder << "," << p.harmonics << "," << p.time_samples << "\n";
    failed += p.status != 0;
  }
  io::write_file_atomic(ctx.out_dir / "study.csv", csv.str());
  ctx.report.section("study") = {{"points", points.size()},
                                 {"failed", failed},
                                 {"workers", workers},
                                 {"reused_points", reused},
                                 {"ranks", distributed::world().size()}};
  StudyOutcome outcome;
  if (failed)
    outcome.warning =
        std::to_string(failed) + " of " + std::to_string(points.size()) + " study points failed (see study.csv)";
  return outcome;
}

int serve_study(int threads, const CaseRunner& run_case, const CaseRunner& run_forced) {
  const Runners runners{run_case, run_forced};
  return distributed::serve(threads, [&](const distributed::Json& t) { return run_point(t, runners); });
}

}  // namespace shroudsim::pipeline
