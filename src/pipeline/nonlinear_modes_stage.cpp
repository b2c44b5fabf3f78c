#include "pipeline/nonlinear_modes_stage.hpp"

#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "forced/frequency_response.hpp"
#include "forced/mode_synthesis.hpp"
#include "forced/nonlinear_modes.hpp"
#include "forced/reduced_equations.hpp"
#include "frf/sector.hpp"
#include "hbm/contact_evaluator.hpp"
#include "io/output.hpp"
#include "io/vtu.hpp"
#include "pipeline/forced_model.hpp"
#include "pipeline/forced_shapes.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::pipeline {
namespace {

/// nlmodes.csv: one row per amplitude.
void write_nlmodes_csv(const std::filesystem::path& file, const forced::NonlinearModeCurve& curve, int harmonics) {
  std::ostringstream csv;
  csv << "amplitude,frequency_hz,damping_ratio,zeta,contact_damping_ratio,contact_dissipation_j,"
         "response_per_amplitude,modal_force_re,modal_force_im,newton_iterations";
  for (int n = 0; n <= harmonics; ++n) csv << ",h" << n;
  csv << "\n";
  for (const auto& p : curve.points) {
    csv << io::format_number(p.amplitude) << "," << io::format_number(p.frequency_hz) << ","
        << io::format_number(p.damping_ratio) << "," << io::format_number(p.zeta) << ","
        << io::format_number(p.contact_damping_ratio) << "," << io::format_number(p.contact_dissipation) << ","
        << io::format_number(p.response_per_amplitude) << "," << io::format_number(p.modal_force.real()) << ","
        << io::format_number(p.modal_force.imag()) << "," << p.newton_iterations;
    for (double h : p.harmonic_amplitudes) csv << "," << io::format_number(h);
    csv << "\n";
  }
  io::write_file_atomic(file, csv.str());
}

/// nlmodes.vtu (FE sector): the mode's displacement harmonics U_n of every sector node at the
/// stuck start, the point of largest damping and the last point (`start_u_h<n>_re_m` ...,
/// `<name>_amplitude_m` = max over the period of |u|), and each one's motion over a period
/// (nlmodes_<name>.pvd, frames in nlmodes_frames/), from the same modal receptance as the
/// equations: U_n = -X_n(w, zeta) F_n, no excitation (frf::sector_displacements).
void write_nlmodes_vtu(Context& ctx, const forced::ForcedModel& model, hbm::ContactEvaluator& contacts,
                       const forced::NonlinearModeCurve& curve, nlohmann::json& j) {
  if (!model.sector_forcing || curve.points.empty()) return;
  const io::Case& c = ctx.config;
  std::size_t largest = 0;
  for (std::size_t i = 0; i < curve.points.size(); ++i)
    if (curve.points[i].damping_ratio > curve.points[largest].damping_ratio) largest = i;
  const std::vector<std::pair<std::string, std::size_t>> shapes = {
      {"start", 0}, {"max_damping", largest}, {"end", curve.points.size() - 1}};
  forced::NonlinearModeEquations eq(*model.linear, contacts);
  const Eigen::VectorXcd f_static = contacts.static_load();
  std::vector<frf::ShapeLoad> loads;
  for (const auto& [name, i] : shapes) {
    const forced::NonlinearModePoint& p = curve.points[i];
    Eigen::VectorXd f;
    contacts.evaluate(p.w, f, nullptr);
    frf::ShapeLoad load;
    load.w = p.omega;
    load.zeta = p.zeta;
    load.excitation = false;
    for (int n = 0; n <= c.hbm.harmonics; ++n) {
      Eigen::VectorXcd fn = eq.complex_harmonic(f, n);
      if (n == 0) fn -= f_static;
      load.forces.push_back(fn);
    }
    loads.push_back(std::move(load));
  }
  const SectorShapes shaped = sector_shapes(ctx, model, loads, "nlmodes shapes");
  std::vector<io::PointField> fields;
  auto& shapes_json = j["shapes"];
  shapes_json = nlohmann::json::array();
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    const std::string& name = shapes[s].first;
    const ShapeFiles written =
        write_shape(ctx.out_dir, shaped.mesh, shaped.u[s], name, "nlmodes_frames", "nlmodes_" + name + ".pvd", fields);
    const forced::NonlinearModePoint& p = curve.points[shapes[s].second];
    shapes_json.push_back({{"name", name},
                           {"amplitude", p.amplitude},
                           {"frequency_hz", p.frequency_hz},
                           {"damping_ratio", p.damping_ratio},
                           {"largest_displacement_m", written.largest_m},
                           {"frames", "nlmodes_" + name + ".pvd"}});
  }
  const mesh::Mesh& mesh = shaped.mesh;
  io::write_point_fields_vtu(ctx.out_dir / "nlmodes.vtu", mesh, fields);
}

}  // namespace

NonlinearModesOutcome run_nonlinear_modes(Context& ctx) {
  const io::Case& c = ctx.config;
  const log::Stopwatch clock;
  if (c.hbm.harmonics_auto)
    throw InputError(c.where("hbm.harmonics") +
                     ": hbm.harmonics = \"auto\" violates: a number for `nlmodes` (the search is the forced "
                     "response's)");
  if (c.hbm.time_samples_auto)
    throw InputError(c.where("hbm.time_samples") + ": hbm.time_samples = \"auto\" violates: a number for `nlmodes`");
  ForcedModel model = c.structure.type == io::StructureType::lumped ? make_lumped_model(c) : make_sector_model(ctx);
  hbm::ContactEvaluator contacts(evaluator_options(c, ctx.threads), model.pairs);
  forced::NonlinearModeSettings settings;
  settings.amplitude_start = c.nlmodes.amplitude_start;
  settings.amplitude_end = c.nlmodes.amplitude_end;
  settings.mode = c.nlmodes.mode;
  settings.max_points = c.nlmodes.max_points;
  settings.tolerance = c.hbm.tolerance;
  forced::NonlinearModeCurve curve;
  try {
    curve = forced::trace_nonlinear_mode(*model.linear, contacts, settings);
  } catch (const InputError& e) {
    // The key the message is about (it starts with it), else the mode's.
    const std::string what = e.what();
    const std::string key = what.rfind("nlmodes.amplitude_start", 0) == 0 ? "nlmodes.amplitude_start" : "nlmodes.mode";
    throw InputError(c.where(key) + ": " + what);
  }
  const double trace_seconds = clock.seconds();
  write_nlmodes_csv(ctx.out_dir / "nlmodes.csv", curve, c.hbm.harmonics);

  // The synthesized forced responses.
  auto& j = ctx.report.section("nlmodes");
  j["mode"] = c.nlmodes.mode;
  j["linear_frequency_hz"] = curve.linear.omega / (2.0 * 3.141592653589793);
  j["linear_damping_ratio"] = curve.linear.zeta / (2.0 * curve.linear.omega);
  j["points"] = curve.points.size();
  j["reached_end"] = curve.reached_end;
  j["message"] = curve.message;
  j["rejected_steps"] = curve.rejected_steps;
  j["residual_evaluations"] = curve.residual_evaluations;
  j["trace_seconds"] = trace_seconds;
  if (!curve.points.empty()) {
    const auto& last = curve.points.back();
    j["end_frequency_hz"] = last.frequency_hz;
    double d_max = 0.0, a_max = 0.0;
    for (const auto& p : curve.points)
      if (p.damping_ratio > d_max) d_max = p.damping_ratio, a_max = p.amplitude;
    j["max_damping_ratio"] = d_max;
    j["max_damping_amplitude"] = a_max;
  }
  std::ostringstream syn;
  syn << "scale,frequency_hz,amplitude_m,modal_amplitude,upper\n";
  auto& peaks = j["synthesis"];
  peaks = nlohmann::json::array();
  for (double s : c.nlmodes.synthesis_scales) {
    const log::Stopwatch sc;
    const std::vector<forced::SynthesisPoint> pts = forced::synthesize(curve.points, s);
    const forced::SynthesisPeak peak = forced::synthesis_peak(curve.points, s);
    const double seconds = sc.seconds();
    for (const auto& p : pts)
      syn << io::format_number(s) << "," << io::format_number(p.frequency_hz) << "," << io::format_number(p.amplitude)
          << "," << io::format_number(p.modal_amplitude) << "," << (p.above_backbone ? 1 : 0) << "\n";
    nlohmann::json e = {{"scale", s}, {"points", pts.size()}, {"seconds", seconds}, {"peak_found", peak.found}};
    if (peak.found) {
      e["peak_frequency_hz"] = peak.frequency_hz;
      e["peak_amplitude_m"] = peak.amplitude;
    } else {
      e["note"] = "the mode's amplitude range ends below this level's peak (raise nlmodes.amplitude_end)";
    }
    peaks.push_back(e);
  }
  io::write_file_atomic(ctx.out_dir / "nlmodes_synthesis.csv", syn.str());
  write_nlmodes_vtu(ctx, model, contacts, curve, j);

  // The full harmonic balance at each scale over the case's range: its largest peak against
  // the synthesized one (docs/physics.md section 10).
  if (c.nlmodes.compare_hb) {
    std::ostringstream cmp;
    cmp << "scale,hb_frequency_hz,hb_amplitude_m,synthesis_frequency_hz,synthesis_amplitude_m,frequency_error,"
           "amplitude_error,within_5_percent,hb_seconds,synthesis_seconds,hb_status\n";
    auto& comparison = j["comparison"];
    comparison = nlohmann::json::array();
    const forced::FrequencyResponseSettings fs = frequency_response_settings(c);
    const hbm::ContactEvaluatorOptions eo = evaluator_options(c, ctx.threads);
    for (double s : c.nlmodes.synthesis_scales) {
      const log::Stopwatch sc;
      const forced::SynthesisPeak peak = forced::synthesis_peak(curve.points, s);
      const double synthesis_seconds = sc.seconds();
      hbm::ContactEvaluator hb_contacts(eo, model.pairs);
      forced::ReducedEquations equations(*model.linear, hb_contacts);
      equations.set_excitation_scale(s);
      const log::Stopwatch hc;
      nlohmann::json e = {{"scale", s}};
      try {
        const forced::FrequencyResponse response = forced::trace_frequency_response(fs, model, eo, equations);
        e["hb_seconds"] = hc.seconds();
        e["hb_status"] = continuation::to_string(response.summary.status);
        const forced::ResponsePeak* top = nullptr;
        for (const auto& p : response.peaks)
          if (!top || p.amplitude_m > top->amplitude_m) top = &p;
        if (top && peak.found) {
          const double ef = peak.frequency_hz / top->frequency_hz - 1, ea = peak.amplitude / top->amplitude_m - 1;
          const bool within = std::abs(ea) <= 0.05;
          e["hb_peak_frequency_hz"] = top->frequency_hz;
          e["hb_peak_amplitude_m"] = top->amplitude_m;
          e["synthesis_peak_frequency_hz"] = peak.frequency_hz;
          e["synthesis_peak_amplitude_m"] = peak.amplitude;
          e["frequency_error"] = ef;
          e["amplitude_error"] = ea;
          e["within_5_percent"] = within;
          cmp << io::format_number(s) << "," << io::format_number(top->frequency_hz) << ","
              << io::format_number(top->amplitude_m) << "," << io::format_number(peak.frequency_hz) << ","
              << io::format_number(peak.amplitude) << "," << io::format_number(ef) << "," << io::format_number(ea)
              << "," << (within ? 1 : 0) << "," << io::format_number(hc.seconds()) << ","
              << io::format_number(synthesis_seconds) << "," << e["hb_status"].get<std::string>() << "\n";
          log::info("nlmodes: scale " + io::format_number(s) + ": HB peak " + io::format_number(top->amplitude_m) +
                    " m at " + io::format_number(top->frequency_hz) + " Hz, synthesis " +
                    io::format_number(peak.amplitude) + " m at " + io::format_number(peak.frequency_hz) + " Hz (" +
                    io::format_number(100 * ea) + " %)");
        } else {
          e["note"] = top ? "the mode's amplitude range ends below this level's peak" : "the HB curve has no peak";
        }
      } catch (const NumericalError& err) {
        e["hb_seconds"] = hc.seconds();
        e["hb_status"] = "start_failed";
        e["note"] = err.what();
      }
      comparison.push_back(e);
    }
    io::write_file_atomic(ctx.out_dir / "nlmodes_compare.csv", cmp.str());
  }
  ctx.report.stage("nlmodes", clock.seconds());
  std::ostringstream msg;
  msg << "nlmodes: " << curve.points.size() << " points, " << j["linear_frequency_hz"].get<double>() << " Hz -> "
      << (curve.points.empty() ? 0.0 : curve.points.back().frequency_hz) << " Hz, largest damping ratio "
      << j.value("max_damping_ratio", 0.0);
  log::info(msg.str());
  NonlinearModesOutcome out;
  if (!curve.reached_end) out.failure = "nlmodes: the curve stopped before nlmodes.amplitude_end: " + curve.message;
  return out;
}

}  // namespace shroudsim::pipeline
