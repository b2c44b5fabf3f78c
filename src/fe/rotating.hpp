#pragma once
// Rotating-frame terms of a structure spinning at Omega [rad/s] about the global z axis:
// centrifugal load, stress (geometric) stiffness and spin softening, for the 4- and 10-node
// tetrahedra of fe/tet_element.hpp (same DOF numbering: dof = 3 * node + component).
//
// Small vibrations u about the centrifugally loaded state, in the rotating frame (Coriolis
// terms neglected, as in a Campbell diagram without gyroscopic coupling):
//   M u'' + (K + K_sigma(Omega) - Omega^2 M_spin) u = 0,
// - centrifugal body force b = rho Omega^2 (x, y, 0). Its consistent nodal load is
//   f_ai = int rho N_a x_i dV = sum_b m_ab x_bi (i = x, y; isoparametric x = sum N_b x_b),
//   i.e. f = Omega^2 M_spin X with X the nodal coordinates: centrifugal_load() returns the
//   load at unit Omega^2, f1 [N / (rad/s)^2];
// - the prestress sigma of the linear static solution K u1 = f1 (at unit Omega^2; a linear
//   solve scales with Omega^2, so sigma(Omega) = Omega^2 sigma1), sigma = lambda tr(eps) I +
//   2 mu eps, eps = sym(grad u);
// - geometric stiffness K_sigma(3a+i, 3b+j) = delta_ij g_ab, g_ab = int grad N_a . sigma .
//   grad N_b dV [N/m], symmetric because sigma is; linear in sigma, so K_sigma(Omega) =
//   Omega^2 K_sigma1;
// - spin softening M_spin = M restricted to the in-plane components (x, y): the change of
//   the centrifugal force when the body moves by u is Omega^2 M_spin u, i.e. the projection
//   of M perpendicular to the axis [kg].
// Rotating stiffness: K(Omega) = K + Omega^2 (K_sigma1 - M_spin).
//
// Quadrature: for straight-sided elements the integrand of g has degree 2(p-1) + (p-1)
// (gradients of degree p-1, stress of degree p-1): 4-node 1 point, 10-node degree 3
// (14 points), so both are integrated exactly; curved 10-node elements isoparametrically.
//
// Usage (clamped structure; for a cyclic sector see modal/rotating.hpp):
//   const Eigen::VectorXd f1 = fe::centrifugal_load(mesh, km.M);     // unit Omega^2
//   ... solve K u1 = f1 on the free DOFs ...
//   linalg::SparseMatrixD Kg1 = fe::geometric_stiffness(mesh, material, u1, km.K);  // K's pattern
//   linalg::SparseMatrixD Ms = fe::spin_softening(km.M);
//   linalg::SparseMatrixD K_omega = km.K + omega * omega * (Kg1 - Ms);
#include <Eigen/Core>

#include "fe/tet_element.hpp"
#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::fe {

template <int NPE>
using ElementVector = Eigen::Matrix<double, 3 * NPE, 1>;
template <int NPE>
using ScalarElementMatrix = Eigen::Matrix<double, NPE, NPE>;

/// Cauchy stress [Pa] of element displacements u (interleaved [u0x u0y u0z u1x ...], m) at
/// reference point xi. Returns false for a non-positive Jacobian determinant there.
template <int NPE>
bool tet_stress(const ElementNodes<NPE>& X, const Material& material, const ElementVector<NPE>& u,
                const Eigen::Vector3d& xi, Eigen::Matrix3d& sigma);

/// g_ab = int grad N_a . sigma(u) . grad N_b dV [N/m] with the stress of displacements u.
/// Returns false for an inverted or degenerate element.
template <int NPE>
bool tet_geometric_stiffness(const ElementNodes<NPE>& X, const Material& material, const ElementVector<NPE>& u,
                             ScalarElementMatrix<NPE>& g);
/// The same for a stress field that is constant over the element [Pa].
template <int NPE>
bool tet_geometric_stiffness(const ElementNodes<NPE>& X, const Eigen::Matrix3d& sigma, ScalarElementMatrix<NPE>& g);

/// Consistent centrifugal load at unit Omega^2 [N / (rad/s)^2] on all 3 * n_nodes DOFs:
/// f1 = M_spin X (M: the consistent mass of `mesh`, fe::assemble).
Eigen::VectorXd centrifugal_load(const mesh::Mesh& mesh, const linalg::SparseMatrixD& M);

/// M_spin: M with the z rows and columns set to zero (pattern of M kept, explicit zeros).
linalg::SparseMatrixD spin_softening(const linalg::SparseMatrixD& M);

/// K_sigma [N/m] of the stress of the displacement field u (all 3 * n_nodes DOFs, m),
/// assembled on the sparsity pattern of `pattern` (e.g. K from fe::assemble, whose pattern
/// holds every 3 x 3 node block; entries outside it are an error). Throws InputError naming
/// an inverted element.
linalg::SparseMatrixD geometric_stiffness(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u,
                                          const linalg::SparseMatrixD& pattern);

/// Largest von Mises stress [Pa] of the displacement field u over the quadrature points of
/// the geometric stiffness (and the vertices), with the element where it occurs.
struct PeakStress {
  double von_mises = 0.0;
  int element = -1;
};
PeakStress peak_von_mises(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u);

/// Von Mises stress [Pa] of u at every node: the average over the elements sharing the node of
/// each element's stress at that node (for plots; the stress is discontinuous between elements).
Eigen::VectorXd nodal_von_mises(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u);

extern template bool tet_stress<4>(const ElementNodes<4>&, const Material&, const ElementVector<4>&,
                                   const Eigen::Vector3d&, Eigen::Matrix3d&);
extern template bool tet_stress<10>(const ElementNodes<10>&, const Material&, const ElementVector<10>&,
                                    const Eigen::Vector3d&, Eigen::Matrix3d&);
extern template bool tet_geometric_stiffness<4>(const ElementNodes<4>&, const Material&, const ElementVector<4>&,
                                                ScalarElementMatrix<4>&);
extern template bool tet_geometric_stiffness<10>(const ElementNodes<10>&, const Material&, const ElementVector<10>&,
                                                 ScalarElementMatrix<10>&);
extern template bool tet_geometric_stiffness<4>(const ElementNodes<4>&, const Eigen::Matrix3d&,
                                                ScalarElementMatrix<4>&);
extern template bool tet_geometric_stiffness<10>(const ElementNodes<10>&, const Eigen::Matrix3d&,
                                                 ScalarElementMatrix<10>&);

}  // namespace shroudsim::fe
