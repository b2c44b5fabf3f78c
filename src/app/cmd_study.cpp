// `shroudsim study CASE`: the case over the Cartesian product of the [study] vary lists.
// Each point is the case with the point's values as --set overrides (after the command
// line's own), run in its own folder <out>/<key=value__key=value...>/ with its own run.json; points
// run in parallel on --threads workers. study.csv lists every point with its status, peak
// amplitude and frequency; study.png plots the peak against the first varied key.
#include <algorithm>
#include <atomic>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "app/context.hpp"
#include "app/modal_stage.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/output.hpp"

namespace shroudsim::app {
namespace {

struct StudyPoint {
  std::vector<std::pair<std::string, std::string>> values;  ///< key, TOML value text
  std::string folder;
  int status = -1;
  std::string message;
  double peak = 0.0, peak_frequency = 0.0, seconds = 0.0;
  std::size_t points = 0;
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

}  // namespace

int cmd_study(Context& ctx) {
  const io::Case& base = ctx.config;
  if (base.study.vary.empty())
    throw InputError(base.locations.at("study.vary") + ": study.vary is empty: name at least one key and its values");
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
  const int workers = std::max(1, std::min<int>(ctx.threads > 0 ? ctx.threads : static_cast<int>(std::thread::hardware_concurrency()),
                                                 static_cast<int>(points.size())));
  log::info("study: " + std::to_string(points.size()) + " points on " + std::to_string(workers) + " workers");
  const bool verbose = log::verbose();
  log::set_verbose(false);  // points run quietly; one line each below
  std::atomic<std::size_t> next{0};
  std::mutex out;
  auto work = [&] {
    for (std::size_t i; (i = next++) < points.size();) {
      Context pc;
      pc.config = cases[i];
      pc.out_dir = ctx.out_dir / points[i].folder;
      pc.threads = 1;
      pc.plots = false;
      log::Stopwatch clock;
      StudyPoint& p = points[i];
      try {
        p.status = cmd_run(pc);
      } catch (const InputError& e) {
        p.status = 2, p.message = e.what();
      } catch (const NumericalError& e) {
        p.status = 3, p.message = e.what();
      } catch (const std::exception& e) {
        p.status = 1, p.message = e.what();
      }
      p.seconds = clock.seconds();
      const auto& j = pc.report.json();
      if (j.contains("frf")) {
        p.peak = j["frf"].value("peak_amplitude_m", 0.0);
        p.peak_frequency = j["frf"].value("peak_frequency_hz", 0.0);
        p.points = j["frf"].value("points", std::size_t{0});
      }
      nlohmann::json rj = j;
      rj["status"] = p.status == 0 ? "ok" : "failed";
      if (!p.message.empty()) rj["message"] = p.message;
      rj["case"] = nlohmann::json::parse(pc.config.resolved_json);
      try {
        io::write_file_atomic(pc.out_dir / "run.json", rj.dump(2) + "\n");
      } catch (const std::exception&) {
      }
      std::lock_guard<std::mutex> lock(out);
      if (verbose) {
        std::ostringstream s;
        s << "shroudsim: study: " << p.folder << ": " << (p.status == 0 ? "ok" : "failed (" + p.message + ")")
          << ", peak " << std::scientific << std::setprecision(4) << p.peak << " m at " << std::defaultfloat
          << std::setprecision(6) << p.peak_frequency << " Hz, " << std::setprecision(3) << p.seconds << " s\n";
        std::cerr << s.str();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < workers; ++t) pool.emplace_back(work);
  for (auto& t : pool) t.join();
  log::set_verbose(verbose);

  std::ostringstream csv;
  for (const auto& [k, v] : points.front().values) csv << k << ",";
  csv << "status,peak_amplitude_m,peak_frequency_hz,points,seconds,folder\n";
  int failed = 0;
  for (const auto& p : points) {
    for (const auto& [k, v] : p.values) {
      std::string val = v;
      val.erase(std::remove(val.begin(), val.end(), '"'), val.end());
      csv << val << ",";
    }
    csv << (p.status == 0 ? "ok" : "failed") << "," << io::format_number(p.peak) << ","
        << io::format_number(p.peak_frequency) << "," << p.points << "," << io::format_number(p.seconds) << ","
        << p.folder << "\n";
    failed += p.status != 0;
  }
  io::write_file_atomic(ctx.out_dir / "study.csv", csv.str());
  ctx.report.section("study") = {{"points", points.size()}, {"failed", failed}, {"workers", workers}};
  draw_plots(ctx);
  if (failed) {
    ctx.report.warn(std::to_string(failed) + " of " + std::to_string(points.size()) + " study points failed (see study.csv)");
    return 3;
  }
  return 0;
}

}  // namespace shroudsim::app
