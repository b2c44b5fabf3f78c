#pragma once
// Cyclic-symmetry reduction of a sector (docs/physics.md section 1).
//
// Nb sectors, alpha = 2 pi / Nb, R = rotation by +alpha about z. For harmonic index h
// (0 <= h < Nb) every matched pair (low p, high q = R p) obeys u_q = exp(i h alpha) R u_p.
// The reduced DOFs u_r are the sector DOFs that are neither cyclic_high nor clamped; the
// clamped DOFs are those of the `hub` nodes and of their cyclic partners. With
//   u = T_h u_r,   T_h = P + exp(i h alpha) G
// (P copies kept DOFs, G maps low DOFs onto their high partners through R), the reduced
// matrices are
//   K_h = T_h^H K T_h = A + exp(i h alpha) B + exp(-i h alpha) B^T,
//   A = P^T K P + G^T K G,   B = P^T K G      (the same for M),
// Hermitian, and real for h = 0 and h = Nb/2. A and B are formed once, so every harmonic
// index costs one pass over the entries. K_{Nb-h} = conj(K_h), T_{Nb-h} = conj(T_h).
//
// Usage:
//   fe::Assembler assembler(mesh);
//   cyclic::CyclicSector sector(mesh, assembler.assemble(material));
//   linalg::SparsePair<linalg::Complex> kmh = sector.reduce(h);
//   Eigen::MatrixXcd u_full = sector.expand(h, phi);      // 3 * n_nodes rows, all nodes
//
// Interface springs (the stuck shroud, docs/physics.md section 1): a spring joins node q of
// a sector to node p of the next sector (x_q = R x_p). Its relative displacement in the
// spring's frame L (rows t1, t2, n) is, for harmonic index h,
//   g = L (u_q - exp(i h alpha) R u_p) = Y_h u_r,   Y_h = S_h T_h,
// (the operator of the relative displacement of the forced response's contact pairs), and
// its energy g^H diag(k) g / 2 adds  Y_h^H diag(k) Y_h  to K_h (Hermitian, positive
// semidefinite; real for h = 0 and h = Nb/2). set_interface() makes every reduction include
// it, so modes, static solves and speed sweeps of the sector all see the springs.
#include <vector>

#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::cyclic {

/// Rotation by `angle` [rad] about the global z axis.
Eigen::Matrix3d rotation_z(double angle);

/// Nodal diameter of harmonic index h: min(h mod Nb, Nb - h mod Nb).
int nodal_diameter(int h, int sectors);
/// The canonical index of the conjugate pair {h, Nb - h}: min(h, (Nb - h) mod Nb). The modes
/// and K_h factor of Nb - h are those of h conjugated, so only canonical indices are solved.
int canonical_index(int h, int sectors);

/// A spring across the sector boundary: node `high_node` of a sector to node `low_node` of
/// the next one (x_high = R x_low), with stiffness along the rows t1, t2, n of `frame`.
struct InterfaceSpring {
  int high_node = -1, low_node = -1;
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();  ///< rows t1, t2, n
  Eigen::Vector3d stiffness = Eigen::Vector3d::Zero();  ///< k_t1, k_t2, k_n [N/m], >= 0
};

class CyclicSector {
 public:
  /// km: the sector's K and M on all 3 * n_nodes DOFs (fe::Assembler). Throws InputError if
  /// the cyclic pairs do not match under R (relative tolerance 1e-6 of the mesh size) or a
  /// node is paired twice.
  CyclicSector(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km);

  int sectors() const { return sectors_; }
  Eigen::Index n_full() const { return n_full_; }
  Eigen::Index n_reduced() const { return static_cast<Eigen::Index>(reduced_to_full_.size()); }
  /// Full sector DOF (3 * node + component) of each reduced DOF, ascending.
  const std::vector<int>& reduced_to_full() const { return reduced_to_full_; }
  /// Full DOFs that are clamped (hub nodes and their cyclic partners), ascending.
  const std::vector<int>& clamped_dofs() const { return clamped_dofs_; }

  /// h = 0, or h = Nb/2 for even Nb: K_h, M_h and T_h are real.
  bool is_real(int h) const;
  /// exp(i h alpha).
  linalg::Complex phase(int h) const;

  /// K_h, M_h (Hermitian, n_reduced x n_reduced, full storage). 0 <= h < Nb.
  linalg::SparsePair<linalg::Complex> reduce(int h) const;
  /// Real K_h, M_h for is_real(h).
  linalg::SparsePair<double> reduce_real(int h) const;
  /// Interface springs added to every reduced K_h from now on (replaces any set before).
  /// Throws InputError for a node out of range or a negative or non-finite stiffness.
  void set_interface(std::vector<InterfaceSpring> springs);
  const std::vector<InterfaceSpring>& interface() const { return springs_; }
  /// S_h: the relative displacements of the springs (3 rows per spring, row 3i + a is
  /// L_i(a, :) (u_q - exp(i h alpha) R u_p)) from all n_full sector DOFs.
  linalg::SparseMatrixC interface_rows(int h) const { return interface_rows(h, springs_); }
  /// Adds weight * L (u_q - exp(i h alpha) R u_p), the relative displacement of node q of a
  /// sector and node p of the next in the frame L (rows; docs/physics.md section 3), to rows
  /// row .. row + 2 of t (columns: all n_full sector DOFs). The one definition of that
  /// operator: the springs here and the forced response's contact rows both use it.
  void add_relative_rows(std::vector<Eigen::Triplet<linalg::Complex>>& t, int row, const Eigen::Matrix3d& frame,
                         int high_node, int low_node, double weight, int h) const;
  /// The same for any springs (their stiffness is not used).
  linalg::SparseMatrixC interface_rows(int h, const std::vector<InterfaceSpring>& springs) const;

  /// T_h: n_full x n_reduced (complex; real-valued for is_real(h)).
  linalg::SparseMatrixC expansion(int h) const;
  /// T_h u: reduced DOF vectors (columns) to all sector DOFs, cyclic_high nodes included.
  Eigen::MatrixXcd expand(int h, const Eigen::MatrixXcd& u_reduced) const;

 private:
  void check_h(int h) const;
  int sectors_ = 1;
  Eigen::Index n_full_ = 0;
  std::vector<int> reduced_to_full_, clamped_dofs_;
  linalg::SparseMatrixD P_, G_;                          // n_full x n_reduced
  linalg::SparseMatrixD KA_, KB_, MA_, MB_, KBt_, MBt_;  // compressed; KBt_ = KB_^T, MBt_ = MB_^T
  std::vector<int> K_outer_, M_outer_;                   // column starts of KA_ + KB_ + KBt_, MA_ + ...
  std::vector<InterfaceSpring> springs_;
  /// Y_h^H diag(k) Y_h on the reduced DOFs (empty matrix without springs).
  linalg::SparseMatrixC interface_stiffness(int h) const;
};

}  // namespace shroudsim::cyclic
