#include "study/trade_design.hpp"

#include <algorithm>
#include <cmath>

#include "io/output.hpp"

namespace shroudsim::study {

std::vector<Knob> convergence_knobs(const io::Case& c) {
  const bool sector = c.structure.type == io::StructureType::sector;
  auto num = [](double v) { return io::format_number(v); };
  auto quoted = [](const std::string& v) { return "\"" + v + "\""; };
  std::vector<Knob> knobs;
  if (sector && c.structure.mesh.empty()) {
    const double m = c.geometry.mesh_size;
    std::vector<std::string> sizes;
    for (int i = 0; i < kMeshLadder; ++i) sizes.push_back(num(m * std::pow(kMeshRatio, -i)));
    knobs.push_back({"mesh size [m]", "geometry.mesh_size", sizes, {}});
  }
  if (sector && c.contact.pairs != 0)
    knobs.push_back({"contact pairs", "contact.pairs", {std::to_string(c.contact.pairs), quoted("all")}, {}});
  if (sector) {
    const int modes = c.modal.modes;
    knobs.push_back({"modes kept",
                     "modal.modes",
                     {std::to_string(std::max(5, modes / 2)), std::to_string(modes), std::to_string(2 * modes)},
                     {}});
    knobs.push_back({"residual flexibility", "modal.residual_flexibility", {"false", "true"}, {}});
  }
  const int h = c.hbm.harmonics_auto ? 5 : c.hbm.harmonics;
  const int n = c.hbm.time_samples_auto ? 512 : c.hbm.time_samples;
  if (c.contact.model != contact::Model::one_d_exact) {
    std::vector<std::string> hs;
    for (int v : {1, 3, h, 2 * h})
      if (v >= 1 && 2 * v + 1 <= 4 * n && (hs.empty() || std::to_string(v) != hs.back()) && v <= 200)
        hs.push_back(std::to_string(v));
    std::sort(hs.begin(), hs.end(),
              [](const std::string& a, const std::string& b) { return std::stoi(a) < std::stoi(b); });
    hs.erase(std::unique(hs.begin(), hs.end()), hs.end());
    knobs.push_back({"harmonics H", "hbm.harmonics", hs, {{"hbm.time_samples", std::to_string(4 * n)}}});
    std::vector<std::string> ns;
    for (int v : {n / 8, n / 4, n / 2, n, 4 * n})
      if (v >= std::max(16, 2 * h + 1) && v <= 65536) ns.push_back(std::to_string(v));
    ns.erase(std::unique(ns.begin(), ns.end()), ns.end());
    knobs.push_back({"time samples N", "hbm.time_samples", ns, {}});
    if (c.contact.model == contact::Model::full3d || c.contact.model == contact::Model::quasi3d) {
      knobs.push_back({"tangential update",
                       "contact.tangential_update",
                       {quoted("radial_return"), quoted("exact_linear")},
                       {{"hbm.time_samples", std::to_string(4 * n)}}});
      knobs.push_back({"contact model", "contact.model", {quoted("quasi3d"), quoted("full3d")}, {}});
    }
    knobs.push_back({"Jacobian", "hbm.jacobian", {quoted("finite_difference"), quoted("analytic")}, {}});
  }
  return knobs;
}

}  // namespace shroudsim::study
