#pragma once
// The linear stages of a sector (docs/contract.md "Caches"): K and M of the mesh, and the
// modes of a set of harmonic indices, read from a cache folder when an entry with the same
// fingerprint exists (modal/cache.hpp: checksummed files; a corrupt entry is reported
// through `warn` and recomputed) and written there after they are computed. K and M are
// assembled every time: that is faster than reading them back (40k DOFs: 0.38 s on one
// thread against 0.76 s for the checksummed read; at 240k DOFs the file is 0.5 GB).
//
// Fingerprints: K and M from the mesh and the material; the modes of harmonic index h from
// that, h, the solver options, the rotating speed (the modes of K + Omega^2 (K_sigma1 -
// M_spin)) and the interface springs of a stuck shroud. Harmonic indices h and Nb - h share
// one solve, that of min(h, Nb - h) (K_{Nb-h} = conj(K_h)): callers pass canonical indices.
//
//   modal::StageCache cache{case_dir / ".cache", warn};
//   modal::SectorMatrices km = modal::assemble_matrices(mesh, material, threads);
//   auto modes = modal::cached_modes(sector, km.key, {0, 1, 2}, options, speed_rpm, springs, cache, threads);
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "cyclic/cyclic_sector.hpp"
#include "fe/tet_element.hpp"
#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::modal {

struct StageCache {
  std::filesystem::path dir;                     ///< created when an entry is written
  std::function<void(const std::string&)> warn;  ///< corrupt entries, failed writes (may be empty)
};

/// Fingerprint of K and M: mesh (nodes, elements, groups) and material.
std::string matrices_key(const mesh::Mesh& mesh, const fe::Material& material);
/// Fingerprint of the modes of harmonic index h (speed_rpm 0: at rest; springs empty: open shroud).
std::string modes_key(const std::string& matrices_key, int h, const ModalOptions& options, double speed_rpm,
                      const std::vector<cyclic::InterfaceSpring>& springs);

struct SectorMatrices {
  linalg::SparsePair<double> km;  ///< sector K [N/m], M [kg] on all 3 n_nodes DOFs
  std::string key;                ///< matrices_key(mesh, material)
  double seconds = 0.0;
};
/// K and M of the mesh (fe::assemble with `threads`) and their fingerprint.
SectorMatrices assemble_matrices(const mesh::Mesh& mesh, const fe::Material& material, int threads);

/// The modes of one canonical harmonic index.
struct CachedModes {
  ModalResult result;  ///< result.report.method = "cache" when reused; result.stiffness empty
  bool reused = false;
  double seconds = 0.0;
};
/// Modes of the canonical harmonic indices `canonical`: each from the cache, or solved
/// (modal::solve_harmonic on sector(), harmonic indices in parallel on `threads` workers) and
/// cached when it converged. A failed solve is returned with its status and message (never
/// thrown). sector() is called only when something must be solved. Each solve's K_h factor is
/// freed as the solve ends (at most one per worker is held). One log line per solve.
std::map<int, CachedModes> cached_modes(const std::function<const cyclic::CyclicSector&()>& sector,
                                        const std::string& matrices_key, const std::vector<int>& canonical,
                                        const ModalOptions& options, double speed_rpm,
                                        const std::vector<cyclic::InterfaceSpring>& springs, const StageCache& cache,
                                        int threads);

}  // namespace shroudsim::modal
