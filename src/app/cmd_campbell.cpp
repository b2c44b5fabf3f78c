// `shroudsim campbell`: natural frequencies against speed with engine-order lines ->
// campbell.csv, crossings.csv (and modes.csv, campbell.png, nd_map.png).
//
// Frequencies do not depend on speed yet (no centrifugal stiffening or spin softening).
// Engine order e excites harmonic index h = e mod Nb, so it meets the modes of nodal
// diameter min(h, Nb - h) (aliasing included: with Nb = 8, EO 9 excites ND 1, EO 6 ND 2).
// A crossing is where the line f = e * rpm / 60 meets a mode's frequency f_r:
// rpm = 60 f_r / e, listed when inside [speed_rpm[0], speed_rpm[1]].
#include <algorithm>
#include <sstream>
#include <tuple>

#include "app/context.hpp"
#include "app/modal_stage.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/output.hpp"

namespace shroudsim::app {

int cmd_campbell(Context& ctx) {
  const io::Case& c = ctx.config;
  auto where = [&](const std::string& key) {
    auto it = c.locations.find(key);
    return it != c.locations.end() ? it->second : c.file.string();
  };
  if (c.structure.type != "sector")
    throw InputError(where("structure.type") + ": structure.type = \"" + c.structure.type +
                     "\": `campbell` needs an FE sector (structure.type = \"sector\")");
  if (c.campbell.rotating_effects)
    throw InputError(where("campbell.rotating_effects") +
                     ": campbell.rotating_effects = true is not supported yet (frequencies are "
                     "speed-independent); set it to false");
  if (c.campbell.speed_rpm.size() != 2 || !(c.campbell.speed_rpm[0] >= 0.0) ||
      !(c.campbell.speed_rpm[1] > c.campbell.speed_rpm[0]))
    throw InputError(where("campbell.speed_rpm") + ": campbell.speed_rpm violates: [min, max] with 0 <= min < max");
  if (c.campbell.speed_points < 2)
    throw InputError(where("campbell.speed_points") + ": campbell.speed_points = " +
                     std::to_string(c.campbell.speed_points) + " violates: speed_points >= 2");
  const int nb = c.structure.sectors;
  for (int e : c.campbell.engine_orders)
    if (e < 1)
      throw InputError(where("campbell.engine_orders") + ": campbell.engine_orders contains " + std::to_string(e) +
                       ", which violates: engine orders >= 1");

  // The [modal] harmonic indices plus those the engine orders excite.
  std::vector<int> hs = modal_harmonic_indices(c);
  for (int e : c.campbell.engine_orders) hs.push_back(e % nb);
  std::sort(hs.begin(), hs.end());
  hs.erase(std::unique(hs.begin(), hs.end()), hs.end());

  ModalModel model = run_modal_stage(ctx, hs, /*keep_factors=*/false);
  log::Stopwatch clock;
  write_modes_csv(ctx, model);

  const double s0 = c.campbell.speed_rpm[0], s1 = c.campbell.speed_rpm[1];
  const int np = c.campbell.speed_points;
  std::ostringstream camp;
  camp << "speed_rpm,harmonic_index,nodal_diameter,mode,frequency_hz\n";
  for (int i = 0; i < np; ++i) {
    const double rpm = s0 + (s1 - s0) * i / (np - 1);
    for (const auto& [h, b] : model.bases) {
      const Eigen::VectorXd f = b.frequency_hz();
      for (int r = 0; r < b.size(); ++r)
        camp << io::format_number(rpm) << ',' << h << ',' << cyclic::nodal_diameter(h, nb) << ',' << r + 1 << ','
             << io::format_number(f(r)) << '\n';
    }
  }
  io::write_file_atomic(ctx.out_dir / "campbell.csv", camp.str());

  std::vector<std::tuple<int, double, int, int, double>> rows;  // eo, rpm, nd, mode, f
  for (int e : c.campbell.engine_orders) {
    const int h = e % nb;
    auto it = model.bases.find(h);
    if (it == model.bases.end()) continue;  // its solve failed: reported below
    const Eigen::VectorXd f = it->second.frequency_hz();
    for (int r = 0; r < f.size(); ++r) {
      const double rpm = 60.0 * f(r) / e;
      if (rpm >= s0 && rpm <= s1) rows.emplace_back(e, rpm, cyclic::nodal_diameter(h, nb), r + 1, f(r));
    }
  }
  std::sort(rows.begin(), rows.end());
  std::ostringstream cross;
  cross << "engine_order,nodal_diameter,mode,speed_rpm,frequency_hz\n";
  for (const auto& [e, rpm, nd, r, f] : rows)
    cross << e << ',' << nd << ',' << r << ',' << io::format_number(rpm) << ',' << io::format_number(f) << '\n';
  io::write_file_atomic(ctx.out_dir / "crossings.csv", cross.str());
  ctx.report.stage("campbell", clock.seconds(), false);
  ctx.report.section("campbell")["crossings"] = rows.size();
  log::info("campbell: " + std::to_string(rows.size()) + " crossings of engine orders with modes in [" +
            io::format_number(s0) + ", " + io::format_number(s1) + "] rpm");

  if (!model.failures.empty()) {
    std::string msg = "modal analysis failed for";
    for (const auto& f : model.failures) msg += "\n  " + f;
    throw NumericalError(msg + "\n(campbell.csv and crossings.csv hold the harmonic indices that converged)");
  }
  draw_plots(ctx);
  return 0;
}

}  // namespace shroudsim::app
