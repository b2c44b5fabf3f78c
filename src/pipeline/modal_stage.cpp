// The modal stage shared by `modes`, `campbell`, `static` and the forced response
// (pipeline/modal_stage.hpp): FE assembly, cyclic reduction and modes per harmonic index,
// cached; modes.csv and modes.vtu; the static shroud settings of a case.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <mutex>
#include <numbers>
#include <sstream>
#include <thread>

#include "core/error.hpp"
#include "core/format.hpp"
#include "core/log.hpp"
#include "frf/contact_patches.hpp"
#include "frf/static_shroud.hpp"
#include "io/output.hpp"
#include "io/vtu.hpp"
#include "linalg/parallel.hpp"
#include "modal/harmonic.hpp"
#include "modal/modal_stage.hpp"
#include "modal/rotating.hpp"
#include "pipeline/context.hpp"
#include "pipeline/modal_stage.hpp"

namespace shroudsim::pipeline {
namespace {

namespace fs = std::filesystem;

}  // namespace

const cyclic::CyclicSector& ModalModel::cyclic() {
  if (!cyclic_) {
    cyclic_ = std::make_unique<cyclic::CyclicSector>(mesh, km);
    cyclic_->set_interface(interface);
  }
  return *cyclic_;
}

Shroud case_shroud(const io::Case& c) {
  return c.modal.shroud == io::ModalShroud::stuck     ? Shroud::stuck
         : c.modal.shroud == io::ModalShroud::contact ? Shroud::contact
                                                      : Shroud::open;
}

std::vector<cyclic::InterfaceSpring> shroud_springs(const io::Case& c, const mesh::Mesh& mesh) {
  try {
    return frf::face_springs(mesh, frf::shroud_face(mesh), c.contact.normal_stiffness, c.contact.tangential_stiffness,
                             c.contact.frame_angle_deg * std::numbers::pi / 180.0);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.where("modal.shroud") + ": modal.shroud = \"" + io::to_string(c.modal.shroud) +
                     "\": " + e.what());
  }
}

std::vector<int> modal_harmonic_indices(const io::Case& c) {
  const int nb = c.structure.sectors;
  std::vector<int> hs;
  if (c.modal.all_harmonic_indices) {
    for (int h = 0; h < nb; ++h) hs.push_back(h);
    return hs;
  }
  for (int h : c.modal.harmonic_indices) {
    if (h < 0 || h >= nb)
      throw InputError(c.where("modal.harmonic_indices") + ": modal.harmonic_indices contains " + std::to_string(h) +
                       ", which violates: 0 <= h < structure.sectors = " + std::to_string(nb));
    hs.push_back(h);
  }
  std::sort(hs.begin(), hs.end());
  hs.erase(std::unique(hs.begin(), hs.end()), hs.end());
  return hs;
}

ModalModel run_modal_stage(Context& ctx, const std::vector<int>& harmonic_indices, double speed_rpm, Shroud shroud) {
  const io::Case& c = ctx.config;
  ModalModel model;
  model.mesh = obtain_mesh(ctx);
  const int nb = model.mesh.sectors > 0 ? model.mesh.sectors : c.structure.sectors;
  model.mesh.sectors = nb;
  model.material = {c.material.youngs_modulus, c.material.poisson_ratio, c.material.density};
  model.options.modes = c.modal.modes;
  model.options.method = c.modal.eigensolver;
  std::vector<std::string> errors;
  if (!model.options.validate(&errors)) throw InputError(c.where("modal.modes") + ": modal." + errors.front());

  const fs::path cache_dir = c.directory / ".cache";
  auto& report = ctx.report.section("modal");
  report["cache_dir"] = cache_dir.string();
  report["sectors"] = nb;
  report["modes_per_harmonic_index"] = model.options.modes;
  report["shroud"] = shroud == Shroud::stuck ? "stuck" : shroud == Shroud::contact ? "contact" : "open";
  if (shroud == Shroud::stuck) model.interface = shroud_springs(c, model.mesh);

  // K and M.
  const modal::StageCache cache{cache_dir, [&ctx](const std::string& m) { ctx.report.warn(m); }};
  modal::SectorMatrices matrices = modal::assemble_matrices(model.mesh, model.material, ctx.threads);
  model.km = std::move(matrices.km);
  const std::string& km_key = matrices.key;
  const double km_seconds = matrices.seconds;
  log::Stopwatch clock;
  ctx.report.stage("assembly", km_seconds, false);  // assembled every time (modal/modal_stage.hpp)
  report["matrices"] = {{"key", km_key},
                        {"reused", false},
                        {"seconds", km_seconds},
                        {"dofs", model.mesh.n_dofs()},
                        {"stored_entries_K", model.km.K.nonZeros()}};
  log::info("assembled K and M: " + std::to_string(model.mesh.n_dofs()) + " DOFs, " +
            std::to_string(model.km.K.nonZeros()) + " stored entries (" + fixed(km_seconds, 2) + " s)");

  if (shroud == Shroud::contact) {
    // The pairs the interference closes at rest (campbell follows the state with speed).
    frf::StaticShroud st;
    try {
      st = frf::solve_static_shroud(model.mesh, model.km, nullptr, static_shroud_settings(c, 0.0));
    } catch (const InputError& e) {
      throw InputError(c.where("modal.shroud") + ": modal.shroud = \"contact\": " + e.what());
    }
    std::vector<cyclic::InterfaceSpring> closed;
    for (std::size_t i = 0; i < st.results.size(); ++i)
      if (st.results[i].state != contact::StaticState::open) closed.push_back(st.springs[i]);
    report["shroud_contact_at_rest"] = {
        {"closed", closed.size()}, {"open", st.results.size() - closed.size()}, {"normal_load_n", st.normal_load()}};
    model.interface = std::move(closed);
  }
  if (shroud != Shroud::open) {
    double kn = 0.0, kt = 0.0;
    for (const auto& sp : model.interface) kt += sp.stiffness[0], kn += sp.stiffness[2];
    report["shroud_springs"] = {
        {"pairs", model.interface.size()}, {"normal_stiffness_n_per_m", kn}, {"tangential_stiffness_n_per_m", kt}};
    std::ostringstream line;
    line << "shroud " << report["shroud"].get<std::string>() << ": " << model.interface.size()
         << " matched shroud pairs tied (kn " << std::setprecision(6) << kn << " N/m, kt " << kt << " N/m)";
    log::info(line.str());
  }

  // Spinning sector: K -> K + Omega^2 (K_sigma1 - M_spin), prestress from the h = 0 static solve.
  model.speed_rpm = speed_rpm;
  if (speed_rpm > 0.0) {
    clock.restart();
    const double omega = modal::rpm_to_rad_s(speed_rpm);
    cyclic::CyclicSector rest(model.mesh, model.km);
    rest.set_interface(model.interface);  // a stuck shroud carries centrifugal load across
    const modal::RotatingOperators ops = modal::rotating_operators(model.mesh, model.material, model.km, rest);
    model.km.K = model.km.K + (omega * omega) * ops.rotating_stiffness();
    model.km.K.makeCompressed();
    const double seconds = clock.seconds();
    ctx.report.stage("prestress", seconds, false);
    report["rotating"] = {{"speed_rpm", speed_rpm},
                          {"omega_rad_s", omega},
                          {"peak_von_mises_pa", ops.peak.von_mises * omega * omega},
                          {"max_static_displacement_m", ops.displacement.cwiseAbs().maxCoeff() * omega * omega},
                          {"seconds", seconds}};
    log::info("rotating at " + io::format_number(speed_rpm) + " rpm: centrifugal prestress (peak von Mises " +
              fixed(ops.peak.von_mises * omega * omega / 1e6, 1) + " MPa), K + K_sigma - Omega^2 M_spin (" +
              fixed(seconds, 2) + " s)");
  }

  // Canonical harmonic indices: h and Nb - h share the solve of min(h, Nb - h).
  std::vector<int> canonical;
  for (int h : harmonic_indices) canonical.push_back(cyclic::canonical_index(h, nb));
  std::sort(canonical.begin(), canonical.end());
  canonical.erase(std::unique(canonical.begin(), canonical.end()), canonical.end());

  clock.restart();
  std::map<int, modal::CachedModes> outcome =
      modal::cached_modes([&model]() -> const cyclic::CyclicSector& { return model.cyclic(); }, km_key, canonical,
                          model.options, speed_rpm, model.interface, cache, ctx.threads);
  if (std::any_of(outcome.begin(), outcome.end(), [](const auto& o) { return !o.second.reused; }))
    report["reduced_dofs"] = model.cyclic().n_reduced();  // built for the solves

  bool all_reused = true;
  nlohmann::json per_h = nlohmann::json::array();
  for (int h : canonical) {
    modal::CachedModes& o = outcome.at(h);
    const auto& r = o.result.report;
    all_reused = all_reused && o.reused;
    nlohmann::json entry = {{"harmonic_index", h},
                            {"nodal_diameter", cyclic::nodal_diameter(h, nb)},
                            {"reused", o.reused},
                            {"status", modal::to_string(r.status)},
                            {"modes", o.result.basis.size()}};
    if (!o.reused) {
      entry.update({{"message", r.message},
                    {"method", r.method},
                    {"spectra_info", r.spectra_info},
                    {"requested_eigenvalues", r.requested_eigenvalues},
                    {"converged_eigenvalues", r.converged_eigenvalues},
                    {"restarts", r.iterations},
                    {"solves", r.operations},
                    {"mass_products", r.mass_products},
                    {"max_relative_residual", r.max_residual},
                    {"factor_nonzeros", r.factor_nonzeros},
                    {"factor_seconds", r.factor_seconds},
                    {"lanczos_seconds", r.solve_seconds},
                    {"seconds", o.seconds}});
    }
    per_h.push_back(entry);
    if (!r.ok()) {
      std::string why = "harmonic index " + std::to_string(h) + ": " + modal::to_string(r.status) + ": " + r.message;
      if (speed_rpm > 0.0 && r.status == modal::ModalStatus::FactorizationFailed)
        why += " (at " + io::format_number(speed_rpm) +
               " rpm K + K_sigma - Omega^2 M_spin is not positive definite: a mode diverges; see `campbell` with "
               "rotating_effects = true)";
      model.failures.push_back(why);
      continue;
    }
    if (!r.message.empty()) ctx.report.warn("harmonic index " + std::to_string(h) + ": " + r.message);
  }
  report["harmonic_indices"] = harmonic_indices;
  report["solved"] = per_h;
  for (int h : harmonic_indices) {
    const int hc = cyclic::canonical_index(h, nb);
    const modal::CachedModes& o = outcome.at(hc);
    if (!o.result.report.ok()) continue;
    model.bases[h] = h == hc ? o.result.basis : o.result.basis.conjugate(h);
  }
  ctx.report.stage("modes", clock.seconds(), all_reused);
  return model;
}

void write_modes_csv(Context& ctx, const ModalModel& model) {
  std::ostringstream s;
  s << "harmonic_index,nodal_diameter,mode,frequency_hz\n";
  for (const auto& [h, b] : model.bases) {
    const Eigen::VectorXd f = b.frequency_hz();
    for (int r = 0; r < b.size(); ++r)
      s << h << ',' << cyclic::nodal_diameter(h, model.mesh.sectors) << ',' << r + 1 << ',' << io::format_number(f(r))
        << '\n';
  }
  io::write_file_atomic(ctx.out_dir / "modes.csv", s.str());
}

void write_modes_vtu(Context& ctx, ModalModel& model) {
  const mesh::Mesh& m = model.mesh;
  // Field budget: at most 256 MiB of float32 point data.
  const double per_field = 12.0 * m.n_nodes();
  const int max_fields = std::max(1, static_cast<int>(256.0 * 1024 * 1024 / per_field));
  int total = 0;
  for (const auto& [h, b] : model.bases) total += b.size();
  const int per_h_cap = total <= max_fields ? 1 << 30 : std::max(1, max_fields / static_cast<int>(model.bases.size()));
  if (total > max_fields)
    ctx.report.warn("modes.vtu holds the first " + std::to_string(per_h_cap) +
                    " modes of each harmonic index (file size limit of 256 MiB)");

  io::VtuBuilder vtu(m);
  const cyclic::CyclicSector& sector = model.cyclic();
  for (const auto& [h, b] : model.bases) {
    const Eigen::VectorXd f = b.frequency_hz();
    const int n = std::min(b.size(), per_h_cap);
    const Eigen::MatrixXcd full = sector.expand(h, b.phi.leftCols(n));
    for (int r = 0; r < n; ++r) {
      Eigen::Index imax = 0;
      full.col(r).cwiseAbs().maxCoeff(&imax);
      const std::complex<double> turn = std::abs(full(imax, r)) > 0 ? std::conj(full(imax, r)) / std::abs(full(imax, r))
                                                                    : 1.0;
      const Eigen::VectorXd re = (full.col(r) * turn).real();
      const double scale = re.cwiseAbs().maxCoeff() > 0 ? 1.0 / re.cwiseAbs().maxCoeff() : 1.0;
      std::vector<float> v(re.size());
      for (Eigen::Index i = 0; i < re.size(); ++i) v[i] = static_cast<float>(re(i) * scale);
      std::ostringstream name;
      name << 'h' << h << "_mode" << r + 1 << '_' << fixed(f(r), 1) << "Hz";
      vtu.add(name.str(), v, 3);
    }
  }
  io::write_file_atomic(ctx.out_dir / "modes.vtu", vtu.finish());
}

frf::StaticShroudSettings static_shroud_settings(const io::Case& c, double speed_rpm) {
  frf::StaticShroudSettings s;
  s.speed_rad_s = modal::rpm_to_rad_s(speed_rpm);
  s.increments = c.static_contact.increments;
  s.interference = c.contact.interference;
  s.normal_stiffness = c.contact.normal_stiffness;
  s.tangential_stiffness = c.contact.tangential_stiffness;
  s.friction_coefficient = c.contact.friction_coefficient;
  s.frame_angle = c.contact.frame_angle_deg * std::numbers::pi / 180.0;
  return s;
}

}  // namespace shroudsim::pipeline
