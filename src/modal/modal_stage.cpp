#include "modal/modal_stage.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <mutex>
#include <sstream>

#include "core/log.hpp"
#include "fe/assembly.hpp"
#include "fe/fingerprint.hpp"
#include "linalg/parallel.hpp"
#include "modal/cache.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::modal {
namespace {

// Version tags: bump when the meaning of a cached entry changes.
constexpr const char* kMatricesVersion = "fe-km/1";
constexpr const char* kModesVersion = "modes/1";
// Speed 0 keeps the key of the modes at rest; a speed adds the rotating-effects tag and Omega.
constexpr const char* kRotatingVersion = "rotating/1";
constexpr const char* kInterfaceVersion = "interface/1";

void warn(const StageCache& cache, const std::string& message) {
  if (cache.warn) cache.warn(message);
}

}  // namespace

std::string matrices_key(const mesh::Mesh& m, const fe::Material& mat) {
  fe::Hasher h;
  h.add(std::string(kMatricesVersion));
  fe::hash_into(h, m);
  fe::hash_into(h, mat);
  return h.hex();
}

std::string modes_key(const std::string& km_key, int h, const ModalOptions& o, double speed_rpm,
                      const std::vector<cyclic::InterfaceSpring>& springs) {
  fe::Hasher hs;
  hs.add(std::string(kModesVersion));
  hs.add(km_key);
  // The open shroud keeps the key it always had; springs add their nodes, frames, stiffnesses.
  if (!springs.empty()) {
    hs.add(std::string(kInterfaceVersion));
    for (const auto& sp : springs) {
      hs.add(sp.high_node);
      hs.add(sp.low_node);
      for (int i = 0; i < 9; ++i) hs.add(sp.frame(i));
      for (int i = 0; i < 3; ++i) hs.add(sp.stiffness[i]);
    }
  }
  if (speed_rpm > 0.0) {
    hs.add(std::string(kRotatingVersion));
    hs.add(speed_rpm);
  }
  hs.add(h);
  hs.add(o.modes);
  hs.add(o.shift);
  hs.add(o.tolerance);
  hs.add(o.residual_tolerance);
  hs.add(to_string(o.method));
  return hs.hex();
}

SectorMatrices assemble_matrices(const mesh::Mesh& mesh, const fe::Material& material, int threads) {
  log::Stopwatch clock;
  SectorMatrices out;
  out.key = matrices_key(mesh, material);
  out.km = fe::assemble(mesh, material, threads);
  out.seconds = clock.seconds();
  return out;
}

std::map<int, CachedModes> cached_modes(const std::function<const cyclic::CyclicSector&()>& sector,
                                        const std::string& km_key, const std::vector<int>& canonical,
                                        const ModalOptions& options, double speed_rpm,
                                        const std::vector<cyclic::InterfaceSpring>& springs, const StageCache& cache,
                                        int threads) {
  std::map<int, CachedModes> outcome;
  std::vector<int> to_solve;
  for (int h : canonical) {
    const std::string key = modes_key(km_key, h, options, speed_rpm, springs);
    const std::filesystem::path f = cache.dir / ("modes-" + key + ".bin");
    std::string problem;
    auto cached = load_basis(f, key, &problem);
    if (cached && (cached->harmonic_index != h || cached->size() != options.modes)) {
      problem = "its modes do not match the harmonic index or the mode count";
      cached.reset();
    }
    if (!problem.empty()) warn(cache, "cache entry " + f.string() + " is corrupt (" + problem + "); recomputing");
    if (cached) {
      CachedModes& o = outcome[h];
      o.reused = true;
      o.result.basis = std::move(*cached);
      o.result.report.method = "cache";
    } else {
      to_solve.push_back(h);
    }
  }
  if (to_solve.empty()) return outcome;

  const cyclic::CyclicSector& s = sector();
  const int nb = s.sectors();
  // Harmonic indices are independent: solved in parallel (each worker holds one
  // factorization; CHOLMOD, Spectra and Eigen objects are not shared).
  const int workers = linalg::worker_count(threads, static_cast<int>(to_solve.size()));
  // Every K_h has one pattern: one symbolic analysis serves all the solves (0.2 s each at
  // 40k DOFs, modal/shift_invert.hpp).
  ModalOptions solve_options = options;
  if (to_solve.size() > 1) {
    const int h0 = to_solve.front();
    solve_options.analysis = s.is_real(h0) ? analyse_pattern(s.reduce_real(h0), options.shift, options.factor_method)
                                           : analyse_pattern(s.reduce(h0), options.shift, options.factor_method);
  }
  std::mutex lock;
  linalg::parallel_for(static_cast<int>(to_solve.size()), workers, [&](int i) {
    const int h = to_solve[i];
    log::Stopwatch watch;
    CachedModes o;
    try {
      o.result = solve_harmonic(s, h, solve_options);
    } catch (const std::exception& e) {
      o.result.report.status = ModalStatus::NotConverged;
      o.result.report.message = e.what();
    }
    o.seconds = watch.seconds();
    o.result.stiffness = StiffnessFactor();  // free the factor now
    const auto& r = o.result.report;
    std::string line =
        "modes h = " + std::to_string(h) + " (ND " + std::to_string(cyclic::nodal_diameter(h, nb)) + "): ";
    if (r.ok()) {
      const Eigen::VectorXd f = o.result.basis.frequency_hz();
      line += std::to_string(f.size()) + " modes, " + fixed(f(0), 2) + " .. " + fixed(f(f.size() - 1), 2) + " Hz (" +
              r.method + ", factor " + fixed(r.factor_seconds, 2) + " s, Lanczos " + fixed(r.solve_seconds, 2) +
              " s, " + std::to_string(r.operations) + " solves)";
    } else {
      line += "FAILED: " + to_string(r.status) + ": " + r.message;
    }
    log::info(line);
    std::lock_guard<std::mutex> g(lock);
    outcome[h] = std::move(o);
  });
  // Cached after the parallel part (in order of h), only what converged.
  for (int h : to_solve) {
    const CachedModes& o = outcome.at(h);
    if (!o.result.report.ok()) continue;
    try {
      const std::string key = modes_key(km_key, h, options, speed_rpm, springs);
      save_basis(cache.dir / ("modes-" + key + ".bin"), key, o.result.basis);
    } catch (const std::exception& e) {
      warn(cache, std::string("could not cache modes: ") + e.what());
    }
  }
  return outcome;
}

}  // namespace shroudsim::modal
