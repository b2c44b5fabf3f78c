#pragma once
// Isotropic linear-elastic tetrahedra: 4-node (linear) and 10-node (quadratic), node order as
// gmsh (mesh/mesh.hpp): vertices 0..3, edge nodes 4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(2,3) 9:(1,3).
// Reference tet: vertices (0,0,0), (1,0,0), (0,1,0), (0,0,1).
//
// Element DOFs are interleaved per node: [u0x u0y u0z u1x ...]. Units: coordinates in m,
// E in Pa, density in kg/m^3 -> stiffness in N/m, mass in kg.
// Stiffness: K_ab(i,j) = int lambda dNa/dx_i dNb/dx_j + mu dNa/dx_j dNb/dx_i
//                          + mu delta_ij grad Na . grad Nb  dV,
// consistent mass: M_ab(i,j) = int rho Na Nb delta_ij dV.
// Quadrature (fe/quadrature.hpp) is exact for straight-sided elements of order p: the
// stiffness integrand has degree 2(p-1), the mass integrand degree 2p. 4-node: 1-point
// stiffness, 4-point mass; 10-node: 4-point stiffness, 14-point (degree 5) mass. Curved
// 10-node elements are integrated isoparametrically with the same rules.
#include <Eigen/Core>

namespace shroudsim::fe {

/// Isotropic linear-elastic material. Units: Pa, -, kg/m^3.
struct Material {
  double youngs_modulus = 210e9;
  double poisson_ratio = 0.3;
  double density = 7850.0;

  double lame_lambda() const {
    return youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
  double shear_modulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }
  /// true when E > 0, -1 < nu < 0.5, rho > 0 (finite).
  bool valid() const;
};

/// Shape functions N (NPE) and reference gradients dN/dxi (NPE x 3) at reference point xi.
template <int NPE>
struct TetShape {
  static_assert(NPE == 4 || NPE == 10, "4- or 10-node tetrahedra only");
  static Eigen::Matrix<double, NPE, 1> values(const Eigen::Vector3d& xi);
  static Eigen::Matrix<double, NPE, 3> gradients(const Eigen::Vector3d& xi);
};

template <int NPE>
using ElementMatrix = Eigen::Matrix<double, 3 * NPE, 3 * NPE>;
template <int NPE>
using ElementNodes = Eigen::Matrix<double, NPE, 3>;

/// Element stiffness and consistent mass of one tetrahedron with node coordinates X (rows).
/// Returns false (and leaves K, M undefined) if the Jacobian determinant is not positive at
/// some quadrature point (inverted or degenerate element).
template <int NPE>
bool tet_matrices(const ElementNodes<NPE>& X, const Material& material, ElementMatrix<NPE>& K, ElementMatrix<NPE>& M);

/// Volume of a tetrahedron from its four vertices (positive for gmsh orientation).
double tet_volume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                  const Eigen::Vector3d& x3);

template <>
Eigen::Matrix<double, 4, 1> TetShape<4>::values(const Eigen::Vector3d& xi);
template <>
Eigen::Matrix<double, 4, 3> TetShape<4>::gradients(const Eigen::Vector3d& xi);
template <>
Eigen::Matrix<double, 10, 1> TetShape<10>::values(const Eigen::Vector3d& xi);
template <>
Eigen::Matrix<double, 10, 3> TetShape<10>::gradients(const Eigen::Vector3d& xi);
extern template bool tet_matrices<4>(const ElementNodes<4>&, const Material&, ElementMatrix<4>&, ElementMatrix<4>&);
extern template bool tet_matrices<10>(const ElementNodes<10>&, const Material&, ElementMatrix<10>&, ElementMatrix<10>&);

}  // namespace shroudsim::fe
