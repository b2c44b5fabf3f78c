// `shroudsim campbell`: natural frequencies against speed with engine-order lines ->
// campbell.csv, crossings.csv (and modes.csv, campbell.png, nd_map.png; with rotating effects
// also prestress.vtu: the centrifugal displacement and von Mises stress at the top speed).
//
// Speeds: campbell.speed_points values evenly spaced over campbell.speed_rpm = [s0, s1].
// - rotating_effects = false: the frequencies at rest at every speed (flat lines).
// - rotating_effects = true: at each speed Omega [rad/s] = 2 pi rpm / 60, the modes of
//     (K_h + Omega^2 D_h) phi = w^2 M_h phi,  D_h = T_h^H (K_sigma1 - M_spin) T_h,
//   K_sigma1 the geometric stiffness of the centrifugal prestress at unit Omega^2 (linear
//   static solve of the clamped sector in harmonic index 0: body force rho Omega^2 (x, y, 0),
//   axis = global z), M_spin the mass on the in-plane components (spin softening); Coriolis
//   is neglected (modal/rotating.hpp, fe/rotating.hpp). The prestress is computed once
//   (stress scales with Omega^2); per harmonic index the pattern of K_h + D_h is analyzed
//   once and each speed refactorizes numerically. Harmonic indices run in parallel
//   (--threads); h and Nb - h share one sweep. Speed 0 reuses the modes at rest.
// Modes are numbered by frequency at each speed (mode r = the r-th lowest), so where two
// families cross in frequency the numbering swaps.
//
// Engine order e excites harmonic index h = e mod Nb, so it meets the modes of nodal
// diameter min(h, Nb - h) (aliasing included: with Nb = 8, EO 9 excites ND 1, EO 6 ND 2).
// A crossing is where g_r(s) = f_r(s) - e s / 60 changes sign between two speed points
// (or is zero at one): s by linear interpolation of g between them, f = e s / 60 (on the
// line). For flat lines this is exactly rpm = 60 f_r / e.
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <tuple>

#include "app/context.hpp"
#include "app/modal_stage.hpp"
#include "app/workers.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/output.hpp"
#include "frf/static_shroud.hpp"
#include "modal/rotating.hpp"

namespace shroudsim::app {
namespace {

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// Frequencies [Hz] of one canonical harmonic index at every speed point (empty: not solved).
struct Sweep {
  std::vector<Eigen::VectorXd> f;
  std::string failure;      // first failure of the sweep (the later speeds are skipped)
  double seconds = 0.0;     // solves only
  double factor_seconds = 0.0, lanczos_seconds = 0.0;
  int solves = 0;
  int analyses = 0;
};

}  // namespace

int cmd_campbell(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\": `campbell` needs an FE sector (structure.type = \"sector\")");
  if (c.campbell.speed_rpm.size() != 2 || !(c.campbell.speed_rpm[0] >= 0.0) ||
      !(c.campbell.speed_rpm[1] > c.campbell.speed_rpm[0]))
    throw InputError(c.where("campbell.speed_rpm") + ": campbell.speed_rpm violates: [min, max] with 0 <= min < max");
  if (c.campbell.speed_points < 2)
    throw InputError(c.where("campbell.speed_points") + ": campbell.speed_points = " +
                     std::to_string(c.campbell.speed_points) + " violates: speed_points >= 2");
  const int nb = c.structure.sectors;
  for (int e : c.campbell.engine_orders)
    if (e < 1)
      throw InputError(c.where("campbell.engine_orders") + ": campbell.engine_orders contains " + std::to_string(e) +
                       ", which violates: engine orders >= 1");

  // The [modal] harmonic indices plus those the engine orders excite.
  std::vector<int> hs = modal_harmonic_indices(c);
  for (int e : c.campbell.engine_orders) hs.push_back(e % nb);
  std::sort(hs.begin(), hs.end());
  hs.erase(std::unique(hs.begin(), hs.end()), hs.end());

  ModalModel model = run_modal_stage(ctx, hs, /*keep_factors=*/false, 0.0, case_shroud(c));
  log::Stopwatch clock;
  write_modes_csv(ctx, model);

  const double s0 = c.campbell.speed_rpm[0], s1 = c.campbell.speed_rpm[1];
  const int np = c.campbell.speed_points;
  std::vector<double> rpm(np);
  for (int i = 0; i < np; ++i) rpm[i] = s0 + (s1 - s0) * i / (np - 1);
  const bool rotating = c.campbell.rotating_effects;
  auto& report = ctx.report.section("campbell");
  report["rotating_effects"] = rotating;
  report["speed_points"] = np;

  // Canonical harmonic indices (h and Nb - h share frequencies) that have modes at rest.
  std::vector<int> canonical;
  for (const auto& [h, b] : model.bases) canonical.push_back(std::min(h, (nb - h) % nb));
  std::sort(canonical.begin(), canonical.end());
  canonical.erase(std::unique(canonical.begin(), canonical.end()), canonical.end());
  std::map<int, Sweep> sweeps;
  for (int h : canonical) sweeps[h].f.assign(np, Eigen::VectorXd());
  // Frequencies at rest of canonical h (from h or from Nb - h: equal spectra).
  auto at_rest = [&](int h) {
    auto it = model.bases.find(h);
    if (it == model.bases.end()) it = model.bases.find((nb - h) % nb);
    return it->second.frequency_hz();
  };

  if (!rotating) {
    for (int h : canonical)
      for (int i = 0; i < np; ++i) sweeps[h].f[i] = at_rest(h);
  } else {
    // Centrifugal prestress (h = 0 static solve) and the reduction of K_sigma1, M_spin.
    log::Stopwatch watch;
    const cyclic::CyclicSector& sector = model.cyclic();
    // modal.shroud = "contact": the sweep's sector is open and each speed ties the pairs the
    // static shroud contact closes there (docs/physics.md section 8); the prestress is that of
    // the open sector.
    const bool follow_contact = case_shroud(c) == Shroud::contact;
    std::unique_ptr<cyclic::CyclicSector> open_sector;
    if (follow_contact) open_sector = std::make_unique<cyclic::CyclicSector>(model.mesh, model.km);
    const cyclic::CyclicSector& sweep_sector = follow_contact ? *open_sector : sector;
    const modal::RotatingOperators ops = modal::rotating_operators(model.mesh, model.material, model.km, sweep_sector);
    const cyclic::CyclicSector rot(model.mesh, {ops.geometric, ops.spin});
    const double prestress_seconds = watch.seconds();
    const double omega_top = modal::rpm_to_rad_s(s1);
    const double peak_top = ops.peak.von_mises * omega_top * omega_top;
    const double tip_top = ops.displacement.cwiseAbs().maxCoeff() * omega_top * omega_top;
    report["prestress_seconds"] = prestress_seconds;
    report["peak_von_mises_pa_at_top_speed"] = peak_top;
    report["peak_von_mises_element"] = ops.peak.element;
    report["max_static_displacement_m_at_top_speed"] = tip_top;
    // The static shroud contact at every speed, in increasing order (friction state carried),
    // from rest (static.increments steps up to the first speed when it is not 0).
    std::vector<std::vector<bool>> closed_at(np);
    std::vector<cyclic::InterfaceSpring> all_springs;
    int static_points = np;
    if (follow_contact) {
      log::Stopwatch static_clock;
      frf::StaticShroudSolver solver(model.mesh, model.km, &ops, static_shroud_settings(c, 0.0));
      all_springs = solver.state().springs;  // the static contact's elements, in its order
      nlohmann::json states = nlohmann::json::array();
      try {
        const int pre = rpm[0] > 0.0 ? std::max(1, c.static_contact.increments) : 0;
        for (int k = 1; k <= pre; ++k)
          solver.step_to(modal::rpm_to_rad_s(rpm[0]) * std::sqrt(static_cast<double>(k) / (pre + 1)));
        for (int i = 0; i < np; ++i) {
          solver.step_to(modal::rpm_to_rad_s(rpm[i]));
          const frf::StaticShroud& st = solver.state();
          closed_at[i].resize(st.results.size());
          int closed = 0;
          for (std::size_t p = 0; p < st.results.size(); ++p) {
            closed_at[i][p] = st.results[p].state != contact::StaticState::open;
            closed += closed_at[i][p] ? 1 : 0;
          }
          states.push_back({{"speed_rpm", rpm[i]}, {"closed", closed}, {"open", static_cast<int>(st.results.size()) - closed},
                            {"slip", st.count(contact::StaticState::slip)}, {"normal_load_n", st.normal_load()}});
        }
      } catch (const NumericalError& e) {
        static_points = static_cast<int>(states.size());
        model.failures.push_back(std::string("static shroud contact: ") + e.what());
      }
      report["shroud_contact"] = {{"states", states}, {"seconds", static_clock.seconds()},
                                  {"interference_m", c.contact.interference}};
      const int closed_top = static_points > 0 ? states.back()["closed"].get<int>() : 0;
      log::info("campbell: static shroud contact at " + std::to_string(static_points) + " speeds: " +
                std::to_string(closed_top) + " of " + std::to_string(all_springs.size()) + " pairs closed at " +
                io::format_number(static_points > 0 ? rpm[static_points - 1] : 0.0) + " rpm (" +
                fixed(static_clock.seconds(), 2) + " s)");
    }
    {
      // The prestress at the top speed for ParaView: displacement and nodal von Mises stress.
      const double w2 = omega_top * omega_top;
      Eigen::MatrixXd disp(model.mesh.n_nodes(), 3);
      for (int n = 0; n < model.mesh.n_nodes(); ++n) disp.row(n) = w2 * ops.displacement.segment<3>(3 * n).transpose();
      const Eigen::VectorXd vm = w2 * fe::nodal_von_mises(model.mesh, model.material, ops.displacement);
      write_point_fields_vtu(ctx, model.mesh, "prestress.vtu",
                             {{"centrifugal_displacement_m", disp}, {"von_mises_pa", Eigen::MatrixXd(vm)}});
    }
    log::info("campbell: centrifugal prestress at " + io::format_number(s1) + " rpm: peak von Mises " +
              fixed(peak_top / 1e6, 1) + " MPa (element " + std::to_string(ops.peak.element) +
              "), largest displacement " + fixed(tip_top * 1e3, 3) + " mm (" + fixed(prestress_seconds, 2) + " s)");

    const int workers = worker_count(ctx.threads, static_cast<int>(canonical.size()));
    std::mutex lock;
    parallel_for(static_cast<int>(canonical.size()), workers, [&](int k) {
      {
        const int h = canonical[k];
        Sweep s;
        s.f.assign(np, Eigen::VectorXd());
        try {
          modal::RotatingHarmonic hr(sweep_sector, rot, h);
          if (follow_contact) hr.set_variable_springs(sweep_sector, all_springs);
          for (int i = 0; i < np; ++i) {
            if (rpm[i] == 0.0 && !follow_contact) {  // K(0) = K: the modes at rest
              s.f[i] = at_rest(h);
              continue;
            }
            if (follow_contact && i >= static_points) {
              s.failure = "harmonic index " + std::to_string(h) + ": no static shroud contact state at " +
                          io::format_number(rpm[i]) + " rpm";
              break;
            }
            log::Stopwatch solve_clock;
            const modal::ModalResult r = follow_contact
                                             ? hr.solve(modal::rpm_to_rad_s(rpm[i]), model.options, closed_at[i])
                                             : hr.solve(modal::rpm_to_rad_s(rpm[i]), model.options);
            s.seconds += solve_clock.seconds();
            s.factor_seconds += r.report.factor_seconds;
            s.lanczos_seconds += r.report.solve_seconds;
            ++s.solves;
            if (!r.report.ok()) {
              s.failure = "harmonic index " + std::to_string(h) + " at " + io::format_number(rpm[i]) +
                          " rpm: " + modal::to_string(r.report.status) + ": " + r.report.message +
                          (r.report.status == modal::ModalStatus::FactorizationFailed
                               ? " (K + K_sigma - Omega^2 M_spin is not positive definite: a mode diverges)"
                               : "");
              // Where: between the last converged speed and this one; the lowest f^2 extrapolated
              // linearly in Omega^2 from the last two speeds, when that lands in between.
              if (i >= 1 && s.f[i - 1].size() > 0) {
                const double fb = s.f[i - 1](0);
                s.failure += "; the lowest mode is " + fixed(fb, 1) + " Hz at " + io::format_number(rpm[i - 1]) +
                             " rpm and diverges below " + io::format_number(rpm[i]) + " rpm";
                if (i >= 2 && s.f[i - 2].size() > 0 && fb < s.f[i - 2](0)) {
                  const double fa = s.f[i - 2](0);
                  const double wa = rpm[i - 2] * rpm[i - 2], wb = rpm[i - 1] * rpm[i - 1];
                  const double at = std::sqrt(wb + (0.0 - fb * fb) * (wb - wa) / (fb * fb - fa * fa));
                  if (at > rpm[i - 1] && at < rpm[i])
                    s.failure += " (f^2 extrapolated to 0 near " + fixed(at, 0) + " rpm)";
                }
              }
              break;
            }
            s.f[i] = r.basis.frequency_hz();
          }
          s.analyses = hr.reuse().analyses;
        } catch (const std::exception& e) {
          s.failure = "harmonic index " + std::to_string(h) + ": " + e.what();
        }
        std::string line = "campbell h = " + std::to_string(h) + " (ND " + std::to_string(cyclic::nodal_diameter(h, nb)) + "): ";
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

    nlohmann::json per_h = nlohmann::json::array();
    double total = 0.0;
    int solves = 0;
    for (int h : canonical) {
      const Sweep& s = sweeps.at(h);
      total += s.seconds;
      solves += s.solves;
      nlohmann::json entry = {{"harmonic_index", h}, {"solves", s.solves}, {"seconds", s.seconds},
                              {"factor_seconds", s.factor_seconds}, {"lanczos_seconds", s.lanczos_seconds},
                              {"symbolic_analyses", s.analyses}};
      if (!s.failure.empty()) entry["failure"] = s.failure;
      if (s.f.front().size() > 0 && s.f.back().size() > 0)
        entry["mode1_hz"] = {s.f.front()(0), s.f.back()(0)};
      per_h.push_back(entry);
      if (!s.failure.empty()) model.failures.push_back(s.failure);
    }
    report["sweeps"] = per_h;
    report["solves"] = solves;
    report["solve_seconds"] = total;
    report["seconds_per_speed_point"] = total / std::max(1, np - (rpm[0] == 0.0 ? 1 : 0));
  }

  // campbell.csv: every speed, every harmonic index asked for (Nb - h from h).
  std::ostringstream camp;
  camp << "speed_rpm,harmonic_index,nodal_diameter,mode,frequency_hz\n";
  for (int i = 0; i < np; ++i) {
    for (const auto& [h, b] : model.bases) {
      const Eigen::VectorXd& f = sweeps.at(std::min(h, (nb - h) % nb)).f[i];
      for (Eigen::Index r = 0; r < f.size(); ++r)
        camp << io::format_number(rpm[i]) << ',' << h << ',' << cyclic::nodal_diameter(h, nb) << ',' << r + 1 << ','
             << io::format_number(f(r)) << '\n';
    }
  }
  io::write_file_atomic(ctx.out_dir / "campbell.csv", camp.str());

  // Crossings: sign changes of g = f_r(s) - e s / 60 between speed points.
  std::vector<std::tuple<int, double, int, int, double>> rows;  // eo, rpm, nd, mode, f
  for (int e : c.campbell.engine_orders) {
    const int h = e % nb;
    if (!model.bases.count(h)) continue;  // its solve failed: reported below
    const Sweep& s = sweeps.at(std::min(h, (nb - h) % nb));
    int last = np - 1;  // a failed sweep: speeds up to the first missing one
    for (int i = 0; i < np; ++i)
      if (s.f[i].size() == 0) {
        last = i - 1;
        break;
      }
    if (last < 0) continue;
    const Eigen::Index n_modes = s.f[0].size();
    for (Eigen::Index r = 0; r < n_modes; ++r) {
      auto g = [&](int i) { return s.f[i](r) - e * rpm[i] / 60.0; };
      for (int i = 0; i <= last; ++i) {
        if (s.f[i].size() <= r) break;
        const double gi = g(i);
        if (gi == 0.0) {
          rows.emplace_back(e, rpm[i], cyclic::nodal_diameter(h, nb), static_cast<int>(r) + 1, s.f[i](r));
          continue;
        }
        if (i == last || s.f[i + 1].size() <= r) break;
        const double gj = g(i + 1);
        if (gj == 0.0 || (gi > 0.0) == (gj > 0.0)) continue;
        const double t = gi / (gi - gj);
        const double at = rpm[i] + t * (rpm[i + 1] - rpm[i]);
        rows.emplace_back(e, at, cyclic::nodal_diameter(h, nb), static_cast<int>(r) + 1, e * at / 60.0);
      }
    }
  }
  std::sort(rows.begin(), rows.end());
  std::ostringstream cross;
  cross << "engine_order,nodal_diameter,mode,speed_rpm,frequency_hz\n";
  for (const auto& [e, at, nd, r, f] : rows)
    cross << e << ',' << nd << ',' << r << ',' << io::format_number(at) << ',' << io::format_number(f) << '\n';
  io::write_file_atomic(ctx.out_dir / "crossings.csv", cross.str());
  ctx.report.stage("campbell", clock.seconds(), false);
  report["crossings"] = rows.size();
  log::info("campbell: " + std::to_string(rows.size()) + " crossings of engine orders with modes in [" +
            io::format_number(s0) + ", " + io::format_number(s1) + "] rpm" +
            (rotating ? " (rotating effects)" : " (frequencies at rest)"));

  // What converged is drawn even when a sweep failed. run.json (where tools/plot.py reads why
  // a sweep stopped) is written after the command returns, so the plot of this run gets the
  // reason from the environment of the plotting process.
  // (Only when this command plots: study points run in threads and never plot.)
  if (ctx.plots && !model.failures.empty())
    ::setenv("SHROUDSIM_CAMPBELL_STOPPED", model.failures.front().c_str(), 1);
  draw_plots(ctx);
  if (!model.failures.empty()) {
    std::string msg = "modal analysis failed for";
    for (const auto& f : model.failures) msg += "\n  " + f;
    throw NumericalError(msg + "\n(campbell.csv and crossings.csv hold the harmonic indices and speeds that converged)");
  }
  return 0;
}

}  // namespace shroudsim::app
