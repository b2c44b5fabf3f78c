// The Campbell stage: see campbell_stage.hpp.
#include "pipeline/campbell_stage.hpp"

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>

#include "campbell/campbell.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/log.hpp"
#include "frf/static_shroud.hpp"
#include "io/output.hpp"
#include "io/vtu.hpp"
#include "linalg/parallel.hpp"
#include "modal/rotating.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::pipeline {
namespace {

using Sweeps = std::map<int, campbell::HarmonicSweep>;  ///< by canonical harmonic index
using AtRest = std::function<Eigen::VectorXd(int)>;     ///< frequencies at rest of a harmonic index

/// modal.shroud = "contact": the static shroud contact at every speed, in increasing order
/// (friction state carried), from rest (static.increments steps up to the first speed when
/// it is not 0); run.json "campbell"/"shroud_contact".
campbell::ShroudStates shroud_states_over_speed(Context& ctx, ModalModel& model, const modal::RotatingOperators& ops,
                                                const std::vector<double>& rpm, nlohmann::json& report) {
  const io::Case& c = ctx.config;
  log::Stopwatch static_clock;
  frf::StaticShroudSolver solver(model.mesh, model.km, &ops, static_shroud_settings(c, 0.0));
  campbell::ShroudStates states = campbell::shroud_states(solver, rpm, c.static_contact.increments);
  if (!states.failure.empty()) model.failures.push_back(states.failure);
  nlohmann::json per_speed = nlohmann::json::array();
  const int pairs = static_cast<int>(states.springs.size());
  for (int i = 0; i < states.solved(); ++i) {
    const int closed = static_cast<int>(std::count(states.closed[i].begin(), states.closed[i].end(), true));
    per_speed.push_back({{"speed_rpm", rpm[i]},
                         {"closed", closed},
                         {"open", pairs - closed},
                         {"slip", states.slipping[i]},
                         {"normal_load_n", states.normal_load_n[i]}});
  }
  report["shroud_contact"] = {
      {"states", per_speed}, {"seconds", static_clock.seconds()}, {"interference_m", c.contact.interference}};
  const int closed_top = states.solved() > 0 ? per_speed.back()["closed"].get<int>() : 0;
  log::info("campbell: static shroud contact at " + std::to_string(states.solved()) +
            " speeds: " + std::to_string(closed_top) + " of " + std::to_string(pairs) + " pairs closed at " +
            io::format_number(states.solved() > 0 ? rpm[states.solved() - 1] : 0.0) + " rpm (" +
            fixed(static_clock.seconds(), 2) + " s)");
  return states;
}

/// prestress.vtu: the centrifugal displacement and nodal von Mises stress at omega [rad/s].
void write_prestress_vtu(const Context& ctx, const ModalModel& model, const modal::RotatingOperators& ops,
                         double omega) {
  const double w2 = omega * omega;
  Eigen::MatrixXd disp(model.mesh.n_nodes(), 3);
  for (int n = 0; n < model.mesh.n_nodes(); ++n) disp.row(n) = w2 * ops.displacement.segment<3>(3 * n).transpose();
  const Eigen::VectorXd vm = w2 * fe::nodal_von_mises(model.mesh, model.material, ops.displacement);
  io::write_point_fields_vtu(ctx.out_dir / "prestress.vtu", model.mesh,
                             {{"centrifugal_displacement_m", disp}, {"von_mises_pa", Eigen::MatrixXd(vm)}});
}

/// The sweep's cost and failures per harmonic index in run.json "campbell".
void report_sweeps(const Sweeps& sweeps, const std::vector<double>& rpm, ModalModel& model, nlohmann::json& report) {
  nlohmann::json per_h = nlohmann::json::array();
  double total = 0.0;
  int solves = 0;
  for (const auto& [h, s] : sweeps) {
    total += s.seconds;
    solves += s.solves;
    nlohmann::json entry = {{"harmonic_index", h},
                            {"solves", s.solves},
                            {"seconds", s.seconds},
                            {"factor_seconds", s.factor_seconds},
                            {"lanczos_seconds", s.lanczos_seconds},
                            {"symbolic_analyses", s.analyses}};
    if (!s.failure.empty()) entry["failure"] = s.failure;
    if (s.f.front().size() > 0 && s.f.back().size() > 0) entry["mode1_hz"] = {s.f.front()(0), s.f.back()(0)};
    per_h.push_back(entry);
    if (!s.failure.empty()) model.failures.push_back(s.failure);
  }
  const int np = static_cast<int>(rpm.size());
  report["sweeps"] = per_h;
  report["solves"] = solves;
  report["solve_seconds"] = total;
  report["seconds_per_speed_point"] = total / std::max(1, np - (rpm[0] == 0.0 ? 1 : 0));
}

/// Rotating effects: the centrifugal prestress (h = 0 static solve), the reduction of
/// K_sigma1 and M_spin, and the sweep of every canonical harmonic index over the speeds, in
/// parallel. modal.shroud = "contact": the sweep's sector is open and each speed ties the
/// pairs the static shroud contact closes there (docs/physics.md section 8); the prestress is
/// that of the open sector.
void rotating_sweeps(Context& ctx, ModalModel& model, const std::vector<double>& rpm, const AtRest& at_rest,
                     Sweeps& sweeps, nlohmann::json& report) {
  const io::Case& c = ctx.config;
  const int nb = c.structure.sectors;
  log::Stopwatch watch;
  const cyclic::CyclicSector& sector = model.cyclic();
  const bool follow_contact = case_shroud(c) == Shroud::contact;
  std::unique_ptr<cyclic::CyclicSector> open_sector;
  if (follow_contact) open_sector = std::make_unique<cyclic::CyclicSector>(model.mesh, model.km);
  const cyclic::CyclicSector& sweep_sector = follow_contact ? *open_sector : sector;
  const modal::RotatingOperators ops = modal::rotating_operators(model.mesh, model.material, model.km, sweep_sector);
  const cyclic::CyclicSector rot(model.mesh, {ops.geometric, ops.spin});
  const double prestress_seconds = watch.seconds();
  const double s0 = c.campbell.speed_rpm[0], s1 = c.campbell.speed_rpm[1];
  const double omega_top = modal::rpm_to_rad_s(s1);
  const double peak_top = ops.peak.von_mises * omega_top * omega_top;
  const double tip_top = ops.displacement.cwiseAbs().maxCoeff() * omega_top * omega_top;
  report["prestress_seconds"] = prestress_seconds;
  report["peak_von_mises_pa_at_top_speed"] = peak_top;
  report["peak_von_mises_element"] = ops.peak.element;
  report["max_static_displacement_m_at_top_speed"] = tip_top;
  campbell::ShroudStates states;
  if (follow_contact) states = shroud_states_over_speed(ctx, model, ops, rpm, report);
  write_prestress_vtu(ctx, model, ops, omega_top);
  log::info("campbell: centrifugal prestress at " + io::format_number(s1) + " rpm: peak von Mises " +
            fixed(peak_top / 1e6, 1) + " MPa (element " + std::to_string(ops.peak.element) +
            "), largest displacement " + fixed(tip_top * 1e3, 3) + " mm (" + fixed(prestress_seconds, 2) + " s)");

  std::vector<int> canonical;
  for (const auto& [h, s] : sweeps) canonical.push_back(h);
  const int workers = linalg::worker_count(ctx.threads, static_cast<int>(canonical.size()));
  std::mutex lock;
  linalg::parallel_for(static_cast<int>(canonical.size()), workers, [&](int k) {
    {
      const int h = canonical[k];
      campbell::HarmonicSweep s = campbell::sweep_harmonic(sweep_sector, rot, h, rpm, model.options, at_rest(h),
                                                           follow_contact ? &states : nullptr);
      std::string line =
          "campbell h = " + std::to_string(h) + " (ND " + std::to_string(cyclic::nodal_diameter(h, nb)) + "): ";
      if (s.f.front().size() > 0 && s.f.back().size() > 0)
        line += "mode 1 " + fixed(s.f.front()(0), 2) + " Hz at " + io::format_number(s0) + " rpm -> " +
                fixed(s.f.back()(0), 2) + " Hz at " + io::format_number(s1) + " rpm, ";
      line += std::to_string(s.solves) + " speeds in " + fixed(s.seconds, 2) + " s (" +
              fixed(s.solves ? s.seconds / s.solves : 0.0, 3) + " s each, " + std::to_string(s.analyses) +
              " symbolic analysis)";
      if (!s.failure.empty()) line += "; FAILED: " + s.failure;
      log::info(line);
      std::lock_guard<std::mutex> g(lock);
      sweeps[h] = std::move(s);
    }
  });
  report_sweeps(sweeps, rpm, model, report);
}

/// campbell.csv: every speed, every harmonic index asked for (Nb - h from h).
void write_campbell_csv(const Context& ctx, const ModalModel& model, const std::vector<double>& rpm,
                        const Sweeps& sweeps) {
  const int nb = ctx.config.structure.sectors;
  std::ostringstream camp;
  camp << "speed_rpm,harmonic_index,nodal_diameter,mode,frequency_hz\n";
  for (std::size_t i = 0; i < rpm.size(); ++i) {
    for (const auto& [h, b] : model.bases) {
      const Eigen::VectorXd& f = sweeps.at(cyclic::canonical_index(h, nb)).f[i];
      for (Eigen::Index r = 0; r < f.size(); ++r)
        camp << io::format_number(rpm[i]) << ',' << h << ',' << cyclic::nodal_diameter(h, nb) << ',' << r + 1 << ','
             << io::format_number(f(r)) << '\n';
    }
  }
  io::write_file_atomic(ctx.out_dir / "campbell.csv", camp.str());
}

/// crossings.csv: the crossings of the engine-order lines (an engine order whose harmonic
/// index failed is left out). Returns their number.
std::size_t write_crossings_csv(const Context& ctx, const ModalModel& model, const std::vector<double>& rpm,
                                const Sweeps& sweeps) {
  const int nb = ctx.config.structure.sectors;
  Sweeps solved;
  for (const auto& [h, s] : sweeps)
    if (model.bases.count(h) || model.bases.count((nb - h) % nb)) solved.emplace(h, s);
  const std::vector<campbell::Crossing> rows = campbell::crossings(rpm, solved, ctx.config.campbell.engine_orders, nb);
  std::ostringstream cross;
  cross << "engine_order,nodal_diameter,mode,speed_rpm,frequency_hz\n";
  for (const campbell::Crossing& x : rows)
    cross << x.engine_order << ',' << x.nodal_diameter << ',' << x.mode << ',' << io::format_number(x.speed_rpm) << ','
          << io::format_number(x.frequency_hz) << '\n';
  io::write_file_atomic(ctx.out_dir / "crossings.csv", cross.str());
  return rows.size();
}

}  // namespace

CampbellOutcome run_campbell(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\": `campbell` needs an FE sector (structure.type = \"sector\")");
  const int nb = c.structure.sectors;

  // The [modal] harmonic indices plus those the engine orders excite.
  std::vector<int> hs = modal_harmonic_indices(c);
  for (int e : c.campbell.engine_orders) hs.push_back(e % nb);
  std::sort(hs.begin(), hs.end());
  hs.erase(std::unique(hs.begin(), hs.end()), hs.end());

  ModalModel model = run_modal_stage(ctx, hs, 0.0, case_shroud(c));
  log::Stopwatch clock;
  write_modes_csv(ctx, model);

  const double s0 = c.campbell.speed_rpm[0], s1 = c.campbell.speed_rpm[1];
  const int np = c.campbell.speed_points;
  const std::vector<double> rpm = campbell::speed_points(s0, s1, np);
  const bool rotating = c.campbell.rotating_effects;
  auto& report = ctx.report.section("campbell");
  report["rotating_effects"] = rotating;
  report["speed_points"] = np;
  // The shroud state of the diagram (a later stage of `run`, the forced response, records
  // its own open modal model under "modal").
  report["shroud"] = ctx.report.json()["modal"]["shroud"];

  // Canonical harmonic indices (h and Nb - h share frequencies) that have modes at rest.
  Sweeps sweeps;
  for (const auto& [h, b] : model.bases) sweeps[cyclic::canonical_index(h, nb)].f.assign(np, Eigen::VectorXd());
  // Frequencies at rest of canonical h (from h or from Nb - h: equal spectra).
  const AtRest at_rest = [&](int h) {
    auto it = model.bases.find(h);
    if (it == model.bases.end()) it = model.bases.find((nb - h) % nb);
    return it->second.frequency_hz();
  };
  if (rotating) {
    rotating_sweeps(ctx, model, rpm, at_rest, sweeps, report);
  } else {
    for (auto& [h, s] : sweeps)
      for (int i = 0; i < np; ++i) s.f[i] = at_rest(h);
  }

  write_campbell_csv(ctx, model, rpm, sweeps);
  const std::size_t crossings = write_crossings_csv(ctx, model, rpm, sweeps);
  ctx.report.stage("campbell", clock.seconds(), false);
  report["crossings"] = crossings;
  log::info("campbell: " + std::to_string(crossings) + " crossings of engine orders with modes in [" +
            io::format_number(s0) + ", " + io::format_number(s1) + "] rpm" +
            (rotating ? " (rotating effects)" : " (frequencies at rest)"));
  CampbellOutcome outcome;
  outcome.failures = model.failures;
  return outcome;
}

}  // namespace shroudsim::pipeline
