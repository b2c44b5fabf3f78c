#pragma once
// The linear modal stage shared by `modes`, `campbell` and the forced response: the sector
// mesh, its K and M, the cyclic reduction and the modes of the harmonic indices a command
// needs. K, M and the modes of each harmonic index are cached in <case directory>/.cache/
// under fingerprints of what they depend on (mesh, material; plus h, number of modes and
// solver settings for the modes), so a second run with other contact or excitation
// settings reuses them; run.json ("modal" section, stage list) says what was reused.
//
// Harmonic indices h and Nb - h share one solve: the modes of Nb - h are the conjugates of
// those of h (K_{Nb-h} = conj(K_h)).
//
// Usage (forced response, harmonic index h):
//   ModalModel model = run_modal_stage(ctx, {0, 1, 2});
//   const modal::ModalBasis& b = model.bases.at(h);               // omega [rad/s], phi
//   const cyclic::CyclicSector& cs = model.cyclic();              // T_h: cs.expansion(h)
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cyclic/cyclic_sector.hpp"
#include "fe/tet_element.hpp"
#include "frf/static_shroud.hpp"
#include "linalg/sparse.hpp"
#include "modal/eigensolver.hpp"
#include "pipeline/context.hpp"

namespace shroudsim::pipeline {

struct ModalModel {
  mesh::Mesh mesh;
  fe::Material material;
  modal::ModalOptions options;
  double speed_rpm = 0.0;                  ///< > 0: K below is the rotating stiffness at this speed
  linalg::SparsePair<double> km;           ///< sector K [N/m], M [kg] on all 3 * n_nodes DOFs
  std::map<int, modal::ModalBasis> bases;  ///< per harmonic index (reduced DOFs of that h)
  std::vector<std::string> failures;       ///< harmonic indices whose modes failed (message each)
  /// The stuck shroud's springs (empty: open shroud); every reduction of cyclic() has them.
  std::vector<cyclic::InterfaceSpring> interface;

  /// The cyclic reduction of the sector (built on first use).
  const cyclic::CyclicSector& cyclic();

 private:
  std::unique_ptr<cyclic::CyclicSector> cyclic_;
};

/// [modal] harmonic_indices ("all": 0..Nb-1), sorted, unique. Throws InputError for an
/// index outside 0..Nb-1.
std::vector<int> modal_harmonic_indices(const io::Case& c);

/// Mesh (obtain_mesh), K and M, and the modes of `harmonic_indices` (cached where possible).
/// A harmonic index whose solve fails is listed in ModalModel::failures (the caller writes
/// what converged and throws NumericalError). Each K_h factorization is freed when its solve
/// ends (modal::factor_harmonic_stiffness makes one again where it is needed).
/// speed_rpm > 0: the sector spins at that speed (rad/s: Omega = 2 pi rpm / 60) and
/// ModalModel::km.K becomes the rotating stiffness K + Omega^2 (K_sigma1 - M_spin)
/// (centrifugal stiffening and spin softening, modal/rotating.hpp), so the modes, the
/// cyclic reduction and the K_h factors (static and residual flexibility) are all those at
/// that speed; the mode cache key then includes the speed. 0: the sector at rest.
/// shroud: "open", or "stuck" for the case's modal.shroud = "stuck" (`modes`, `campbell`):
/// every matched shroud pair tied by springs (shroud_springs), in the modes, the static solve
/// of the prestress and the K_h factors; the cache keys include the springs.
/// "contact": the pairs the static shroud contact at rest closes (contact.interference) tied.
enum class Shroud { open, stuck, contact };
ModalModel run_modal_stage(Context& ctx, const std::vector<int>& harmonic_indices, double speed_rpm = 0.0,
                           Shroud shroud = Shroud::open);

/// The shroud state `modes` and `campbell` use: the case's modal.shroud.
Shroud case_shroud(const io::Case& c);

/// The stuck shroud's springs: one per matched shroud pair (frf::shroud_face), stiffness
/// (kt, kt, kn) of contact.tangential_stiffness and normal_stiffness times a_i / A (the
/// pair's share of the face area), in the pair's contact frame (frf::contact_frame, turned by
/// contact.frame_angle_deg). Throws InputError when the mesh has no matched shroud pairs.
std::vector<cyclic::InterfaceSpring> shroud_springs(const io::Case& c, const mesh::Mesh& mesh);

/// The static shroud contact settings of the case at `speed_rpm` (contact.*, static.*).
frf::StaticShroudSettings static_shroud_settings(const io::Case& c, double speed_rpm);

/// modes.csv: harmonic_index,nodal_diameter,mode,frequency_hz (mode numbered from 1).
void write_modes_csv(Context& ctx, const ModalModel& model);
/// modes.vtu: the sector mesh with one point-data field per mode ("h<h>_mode<r>_<f>Hz"),
/// the real part of the mode shape on every node (cyclic_high included) after turning its
/// phase so that the largest component is real.
void write_modes_vtu(Context& ctx, ModalModel& model);

}  // namespace shroudsim::pipeline
