// `shroudsim modes`: the modal stage (pipeline/modal_stage.hpp) for the case's harmonic
// indices -> modes.csv (the nodal diameter map), modes.vtu, nd_map.png; and the plots of
// every command (draw_plots).
#include <cstdlib>
#include <filesystem>
#include <string>

#include "app/context.hpp"
#include "core/error.hpp"
#include "core/log.hpp"

#ifndef SHROUDSIM_SOURCE_DIR
#define SHROUDSIM_SOURCE_DIR "."
#endif

namespace shroudsim::app {

namespace fs = std::filesystem;

void draw_plots(Context& ctx) {
  if (!ctx.plots) return;  // study points: the study plots once at the end
  const fs::path script = fs::path(SHROUDSIM_SOURCE_DIR) / "tools" / "plot.py";
  const char* python = "/usr/bin/python3";
  if (!fs::exists(python) || !fs::exists(script) ||
      std::system((std::string(python) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) != 0) {
    log::info("plots skipped (needs /usr/bin/python3 with matplotlib and " + script.string() + ")");
    ctx.report.section("plots")["drawn"] = false;
    return;
  }
  std::string cmd = std::string(python) + " '" + script.string() + "' '" + ctx.out_dir.string() + "'";
  // The shroud state in the titles of nd_map.png and campbell.png: the Campbell stage's when
  // there is one (in `run`, the forced response's open modal model comes after it).
  const nlohmann::json& j = ctx.report.json();
  for (const char* section : {"campbell", "modal"})
    if (j.contains(section) && j[section].contains("shroud")) {
      cmd += " --shroud " + j[section]["shroud"].get<std::string>();
      break;
    }
  const int rc = std::system(cmd.c_str());
  ctx.report.section("plots")["drawn"] = rc == 0;
  if (rc != 0) ctx.report.warn("plotting failed (" + cmd + ")");
}

int cmd_modes(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\": `modes` needs an FE sector (structure.type = \"sector\")");
  ModalModel model = run_modal_stage(ctx, modal_harmonic_indices(c), /*keep_factors=*/false, 0.0, case_shroud(c));
  write_modes_csv(ctx, model);
  if (!model.bases.empty()) write_modes_vtu(ctx, model);
  if (!model.failures.empty()) {
    std::string msg = "modal analysis failed for";
    for (const auto& f : model.failures) msg += "\n  " + f;
    throw NumericalError(msg + "\n(modes.csv holds the harmonic indices that converged)");
  }
  draw_plots(ctx);
  return 0;
}

}  // namespace shroudsim::app
