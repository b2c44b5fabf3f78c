#pragma once
// Modes of a structure spinning at Omega [rad/s] about the global z axis: centrifugal
// stiffening and spin softening (fe/rotating.hpp for the element terms), Coriolis neglected.
//
//   (K + Omega^2 D) phi = w^2 M phi,   D = K_sigma1 - M_spin,
// K_sigma1 the geometric stiffness of the prestress of the linear static solution
// K u1 = f1 at unit Omega^2 (stress scales with Omega^2, so K_sigma(Omega) = Omega^2 K_sigma1),
// M_spin the mass on the in-plane components. For a cyclic sector the static solve is the
// h = 0 reduction (the centrifugal load is the same on every sector):
//   K_0 u_r = T_0^T f1,  u1 = T_0 u_r.
// The prestress is then cyclically symmetric, so D reduces like K and M:
//   K_h(Omega) = K_h + Omega^2 D_h,  D_h = T_h^H D T_h,
// with the pattern of K_h + D_h fixed over speeds: RotatingHarmonic analyzes it once and
// refactorizes numerically at every speed (modal::FactorReuse).
//
// Units: K in N/m, M in kg, D in N/m per (rad/s)^2 (i.e. kg), Omega in rad/s, u1 in m per
// (rad/s)^2, stresses in Pa per (rad/s)^2.
//
// Usage (Campbell sweep of harmonic index h):
//   cyclic::CyclicSector sector(mesh, km);
//   modal::RotatingOperators ops = modal::rotating_operators(mesh, material, km, sector);
//   cyclic::CyclicSector rot(mesh, {ops.geometric, ops.spin});    // reduces K_sigma1, M_spin
//   modal::RotatingHarmonic hr(sector, rot, h);
//   for (double omega : speeds) { ModalResult r = hr.solve(omega, options); ... }
#include <vector>

#include "cyclic/cyclic_sector.hpp"
#include "fe/rotating.hpp"
#include "fe/tet_element.hpp"
#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::modal {

/// The rotating-frame operators at unit Omega^2 on all 3 * n_nodes DOFs.
struct RotatingOperators {
  Eigen::VectorXd load;             ///< f1 [N per (rad/s)^2]
  Eigen::VectorXd displacement;     ///< u1 [m per (rad/s)^2], clamped DOFs zero
  linalg::SparseMatrixD geometric;  ///< K_sigma1 [N/m per (rad/s)^2], pattern of K
  linalg::SparseMatrixD spin;       ///< M_spin [kg], pattern of M
  fe::PeakStress peak;              ///< largest von Mises stress of u1 [Pa per (rad/s)^2]
  double seconds = 0.0;             ///< static solve and assembly of K_sigma1
  /// D = K_sigma1 - M_spin, so that K(Omega) = K + Omega^2 D.
  linalg::SparseMatrixD rotating_stiffness() const;
};

/// A clamped structure without cyclic symmetry: the DOFs `fixed_dofs` (ascending) are held
/// at zero in the static solve. Throws NumericalError if K on the free DOFs is singular.
RotatingOperators rotating_operators(const mesh::Mesh& mesh, const fe::Material& material,
                                     const linalg::SparsePair<double>& km, const std::vector<int>& fixed_dofs);
/// A cyclic sector (`sector` built from the same km): the static solve in harmonic index 0.
/// The shroud contact is open (as in the modes): a shroud overhang is loaded by its own
/// centrifugal force only.
RotatingOperators rotating_operators(const mesh::Mesh& mesh, const fe::Material& material,
                                     const linalg::SparsePair<double>& km, const cyclic::CyclicSector& sector);

/// One harmonic index of a spinning cyclic sector: K_h, M_h and D_h formed once, then modes
/// at any speed with the symbolic factorization reused (not thread-safe: one per worker).
class RotatingHarmonic {
 public:
  /// sector: reduction of {K, M}; rotating: reduction of {K_sigma1, M_spin} of the same mesh.
  RotatingHarmonic(const cyclic::CyclicSector& sector, const cyclic::CyclicSector& rotating, int harmonic_index);
  /// Lowest options.modes modes of (K_h + omega^2 D_h) phi = w^2 M_h phi (no StiffnessFactor).
  ModalResult solve(double omega, const ModalOptions& options);
  /// Springs whose state changes with speed (shroud pairs closed or open at each speed):
  /// solve(omega, options, closed) adds Y_h^H diag(k) Y_h over the springs with closed[i]
  /// (Y_h = sector.interface_rows(h, springs) T_h). The pattern keeps every spring, so the
  /// symbolic analysis is still reused.
  void set_variable_springs(const cyclic::CyclicSector& sector, const std::vector<cyclic::InterfaceSpring>& springs);
  ModalResult solve(double omega, const ModalOptions& options, const std::vector<bool>& closed);
  int harmonic_index() const { return h_; }
  const FactorReuse& reuse() const { return reuse_; }

 private:
  int h_ = 0;
  bool real_ = true;
  linalg::SparsePair<double> real_pair_;  // {K_h(omega), M_h}, overwritten per speed
  linalg::SparseMatrixD real_k0_, real_d_;
  linalg::SparsePair<Complex> complex_pair_;
  linalg::SparseMatrixC complex_k0_, complex_d_;
  linalg::SparseMatrixC y_;   // Y_h (3 rows per variable spring), empty without
  Eigen::VectorXd spring_k_;  // stiffness of each row of Y_h
  FactorReuse reuse_;
};

/// Rotor speed: rpm -> rad/s.
inline double rpm_to_rad_s(double rpm) { return rpm * 2.0 * 3.14159265358979323846 / 60.0; }

}  // namespace shroudsim::modal
