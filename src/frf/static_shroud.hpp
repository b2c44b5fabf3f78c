#pragma once
// The static shroud contact of a spinning sector (docs/physics.md section 8): the h = 0
// sector under the centrifugal load, its shroud pairs closed or open with an interference
// and Coulomb friction.
//
// Every matched shroud node pair of the face (shroud_face) is one contact element with
// kn a_i / A, kt a_i / A (the case's totals shared by tributary area), the friction
// coefficient and the interference delta (overlap at rest, uniform over the face). The
// speed is raised in `increments` equal steps of Omega^2 (the centrifugal load and the
// prestress scale with it); at step k the sector's stiffness is K + Omega_k^2 D (the
// rotating stiffness of modal/rotating.hpp, prestress from the open-shroud static solution)
// and the contact problem g = g_ext - C F(g) (contact/static_contact.hpp) is solved with
// the exact static flexibility C = B K_0^-1 B^T of the pairs (B: the springs' relative
// displacement rows at h = 0, CyclicSector::interface_rows) and g_ext = B K_0^-1 T_0^T Omega_k^2 f1. At zero speed one
// step applies the interference alone.
//
// Usage:
//   frf::StaticShroud s = frf::solve_static_shroud(mesh, km, ops_or_null, settings);
//   s.results[i].force, .state, .gap;  s.displacement (all sector DOFs)
#include <Eigen/Core>
#include <vector>

#include "contact/contact_law.hpp"
#include "contact/static_contact.hpp"
#include "frf/contact_patches.hpp"
#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"
#include "modal/rotating.hpp"

namespace shroudsim::frf {

struct StaticShroudSettings {
  double speed_rad_s = 0.0;
  int increments = 10;                ///< steps of Omega^2 from rest (>= 1; 1 at zero speed)
  double interference = 0.0;          ///< delta [m], overlap at rest; < 0: a gap
  double normal_stiffness = 0.0;      ///< kn [N/m] of the whole face
  double tangential_stiffness = 0.0;  ///< kt [N/m] of the whole face
  double friction_coefficient = 0.0;
  double frame_angle = 0.0;  ///< [rad], as contact.frame_angle_deg
};

struct StaticShroud {
  std::vector<ShroudFaceNode> face;  ///< one element per face pair
  /// One per face pair (face_springs): nodes, frame and stiffness; tied, they are the
  /// linear model's springs of the closed pairs (modal.shroud = "contact").
  std::vector<cyclic::InterfaceSpring> springs;
  std::vector<contact::StaticPairParameters> parameters;  ///< the springs' kn, kt, with mu and delta
  std::vector<contact::StaticPairResult> results;         ///< at the final speed
  Eigen::VectorXd displacement;                           ///< all 3 n_nodes sector DOFs [m]
  int increments = 0, newton_iterations = 0;
  double seconds = 0.0;
  /// Totals over the face [N] and counts of the states.
  double normal_load() const;
  int count(contact::StaticState s) const;
};

/// The static contact carried from speed to speed (the friction state is path dependent):
/// a sweep over increasing speeds (a Campbell diagram) steps through them in order.
class StaticShroudSolver {
 public:
  /// ops: the rotating operators of the open sector at unit Omega^2 (null: never spins).
  /// Throws InputError when the mesh has no matched shroud pairs. The state is the
  /// unloaded sector at rest (pairs with a positive interference are closed).
  StaticShroudSolver(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km, const modal::RotatingOperators* ops,
                     const StaticShroudSettings& settings);
  /// Equilibrium at speed [rad/s] from the current state (one load step). Throws
  /// NumericalError when K_0 + Omega^2 D is not positive definite or the contact does not
  /// converge (the message names the speed); the state is then unchanged.
  void step_to(double speed_rad_s);
  const StaticShroud& state() const { return out_; }

 private:
  const mesh::Mesh& mesh_;
  const linalg::SparsePair<double>& km_;
  const modal::RotatingOperators* ops_;
  linalg::SparseMatrixD D_;
  StaticShroud out_;
  contact::StaticContact contact_;
};

/// From rest to settings.speed_rad_s in settings.increments equal steps of Omega^2 (one
/// step at zero speed: the interference alone).
StaticShroud solve_static_shroud(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km,
                                 const modal::RotatingOperators* ops, const StaticShroudSettings& settings);

/// The contact element of each patch of the forced response (docs/physics.md sections 3 and
/// 8): the face's totals `face` (friction coefficient, kt, kn, preload) with kt, kn and the
/// preload times the patch's share A_P / face_area. With `state` (contact.normal_preload =
/// "static"), the preload is instead the sum over the patch's node pairs of their static normal
/// loads, an open pair counting as -kn_i gap_i (a fully open patch then has the area-weighted
/// mean gap); the patches' members index the face, listed in the static solve's order.
std::vector<contact::PairParameters> patch_parameters(const std::vector<ContactPatch>& patches, double face_area,
                                                      const contact::PairParameters& face, const StaticShroud* state);

}  // namespace shroudsim::frf
