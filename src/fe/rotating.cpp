#include "fe/rotating.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.hpp"
#include "fe/quadrature.hpp"

namespace shroudsim::fe {
namespace {

// Rule of the geometric stiffness: degree 3(p - 1), exact for straight-sided elements.
template <int NPE>
constexpr int kGeometricDegree = NPE == 4 ? 1 : 3;

template <int NPE>
struct Tabulated {
  std::vector<double> weights;
  std::vector<Eigen::Matrix<double, NPE, 3>> dn;
  explicit Tabulated(const TetQuadrature& q) : weights(q.weights) {
    for (const auto& p : q.points) dn.push_back(TetShape<NPE>::gradients(p));
  }
};

// Physical gradients G (one row per node) and det J at a point with reference gradients dn.
template <int NPE>
bool physical_gradients(const ElementNodes<NPE>& X, const Eigen::Matrix<double, NPE, 3>& dn,
                        Eigen::Matrix<double, NPE, 3>& G, double& det) {
  const Eigen::Matrix3d J = X.transpose() * dn;  // J(i, j) = d x_i / d xi_j
  det = J.determinant();
  if (!(det > 0.0)) return false;
  G = dn * J.inverse();
  return true;
}

template <int NPE>
Eigen::Matrix3d stress_from_gradients(const Material& material, const Eigen::Matrix<double, NPE, 3>& G,
                                      const ElementVector<NPE>& u) {
  // grad u (i, j) = d u_i / d x_j = sum_a u_ai G(a, j).
  const Eigen::Map<const Eigen::Matrix<double, 3, NPE>> U(u.data());
  const Eigen::Matrix3d grad = U * G;
  const Eigen::Matrix3d eps = 0.5 * (grad + grad.transpose());
  return material.lame_lambda() * eps.trace() * Eigen::Matrix3d::Identity() + 2.0 * material.shear_modulus() * eps;
}

double von_mises(const Eigen::Matrix3d& s) {
  const Eigen::Matrix3d dev = s - s.trace() / 3.0 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * dev.cwiseProduct(dev).sum());
}

template <int NPE, typename StressAt>
bool geometric_kernel(const ElementNodes<NPE>& X, StressAt&& stress_at, ScalarElementMatrix<NPE>& g) {
  static const Tabulated<NPE> q(tet_quadrature(kGeometricDegree<NPE>));
  g.setZero();
  Eigen::Matrix<double, NPE, 3> G;
  for (std::size_t k = 0; k < q.weights.size(); ++k) {
    double det = 0.0;
    if (!physical_gradients<NPE>(X, q.dn[k], G, det)) return false;
    const Eigen::Matrix3d sigma = stress_at(G);
    g.noalias() += (q.weights[k] * det) * G * sigma * G.transpose();
  }
  g = 0.5 * (g + g.transpose()).eval();  // symmetric to the last bit
  return true;
}

template <int NPE>
PeakStress peak_range(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u) {
  static const Tabulated<NPE> q(tet_quadrature(kGeometricDegree<NPE>));
  static const std::vector<Eigen::Matrix<double, NPE, 3>> vertex_dn = [] {
    const Eigen::Vector3d ref[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    std::vector<Eigen::Matrix<double, NPE, 3>> v;
    for (const auto& r : ref) v.push_back(TetShape<NPE>::gradients(r));
    return v;
  }();
  PeakStress peak;
  ElementNodes<NPE> X;
  ElementVector<NPE> ue;
  Eigen::Matrix<double, NPE, 3> G;
  for (int e = 0; e < mesh.n_elements(); ++e) {
    for (int a = 0; a < NPE; ++a) {
      const int n = mesh.tets(e, a);
      X.row(a) = mesh.nodes.row(n);
      ue.template segment<3>(3 * a) = u.segment<3>(3 * n);
    }
    auto visit = [&](const Eigen::Matrix<double, NPE, 3>& dn) {
      double det = 0.0;
      if (!physical_gradients<NPE>(X, dn, G, det)) return;
      const double s = von_mises(stress_from_gradients<NPE>(material, G, ue));
      if (s > peak.von_mises) peak = {s, e};
    };
    for (const auto& dn : q.dn) visit(dn);
    for (const auto& dn : vertex_dn) visit(dn);
  }
  return peak;
}

template <int NPE>
void assemble_geometric_range(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u,
                              linalg::SparseMatrixD& Kg) {
  ElementNodes<NPE> X;
  ElementVector<NPE> ue;
  ScalarElementMatrix<NPE> g;
  const int* outer = Kg.outerIndexPtr();
  const int* inner = Kg.innerIndexPtr();
  double* values = Kg.valuePtr();
  auto slot = [&](int row, int col) {
    const int* begin = inner + outer[col];
    const int* end = inner + outer[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    SHROUDSIM_CHECK(it != end && *it == row, "geometric_stiffness: the pattern lacks an element's node block");
    return static_cast<int>(it - inner);
  };
  for (int e = 0; e < mesh.n_elements(); ++e) {
    for (int a = 0; a < NPE; ++a) {
      const int n = mesh.tets(e, a);
      X.row(a) = mesh.nodes.row(n);
      ue.template segment<3>(3 * a) = u.segment<3>(3 * n);
    }
    if (!tet_geometric_stiffness<NPE>(X, material, ue, g))
      throw InputError("mesh: element " + std::to_string(e) + " is inverted or degenerate (Jacobian determinant <= 0)");
    for (int b = 0; b < NPE; ++b) {
      const int nb = mesh.tets(e, b);
      for (int a = 0; a < NPE; ++a) {
        const int na = mesh.tets(e, a);
        // Rows 3 na + i of column 3 nb + i: the node block's diagonal.
        for (int i = 0; i < 3; ++i) values[slot(3 * na + i, 3 * nb + i)] += g(a, b);
      }
    }
  }
}

}  // namespace

template <int NPE>
bool tet_stress(const ElementNodes<NPE>& X, const Material& material, const ElementVector<NPE>& u,
                const Eigen::Vector3d& xi, Eigen::Matrix3d& sigma) {
  Eigen::Matrix<double, NPE, 3> G;
  double det = 0.0;
  if (!physical_gradients<NPE>(X, TetShape<NPE>::gradients(xi), G, det)) return false;
  sigma = stress_from_gradients<NPE>(material, G, u);
  return true;
}

template <int NPE>
bool tet_geometric_stiffness(const ElementNodes<NPE>& X, const Material& material, const ElementVector<NPE>& u,
                             ScalarElementMatrix<NPE>& g) {
  return geometric_kernel<NPE>(
      X, [&](const Eigen::Matrix<double, NPE, 3>& G) { return stress_from_gradients<NPE>(material, G, u); }, g);
}

template <int NPE>
bool tet_geometric_stiffness(const ElementNodes<NPE>& X, const Eigen::Matrix3d& sigma, ScalarElementMatrix<NPE>& g) {
  const Eigen::Matrix3d s = 0.5 * (sigma + sigma.transpose());
  return geometric_kernel<NPE>(
      X, [&](const Eigen::Matrix<double, NPE, 3>&) { return s; }, g);
}

Eigen::VectorXd centrifugal_load(const mesh::Mesh& mesh, const linalg::SparseMatrixD& M) {
  SHROUDSIM_CHECK(M.rows() == mesh.n_dofs() && M.cols() == mesh.n_dofs(),
                  "centrifugal_load: M does not match the mesh");
  Eigen::VectorXd x = Eigen::VectorXd::Zero(mesh.n_dofs());
  for (int n = 0; n < mesh.n_nodes(); ++n) {
    x(3 * n) = mesh.nodes(n, 0);
    x(3 * n + 1) = mesh.nodes(n, 1);
  }
  return spin_softening(M) * x;
}

linalg::SparseMatrixD spin_softening(const linalg::SparseMatrixD& M) {
  linalg::SparseMatrixD Ms = M;
  Ms.makeCompressed();
  for (Eigen::Index col = 0; col < Ms.outerSize(); ++col)
    for (linalg::SparseMatrixD::InnerIterator it(Ms, col); it; ++it)
      if (it.row() % 3 == 2 || col % 3 == 2) it.valueRef() = 0.0;
  return Ms;
}

linalg::SparseMatrixD geometric_stiffness(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u,
                                          const linalg::SparseMatrixD& pattern) {
  SHROUDSIM_CHECK(u.size() == mesh.n_dofs(), "geometric_stiffness: u does not match the mesh");
  SHROUDSIM_CHECK(pattern.rows() == mesh.n_dofs() && pattern.cols() == mesh.n_dofs(),
                  "geometric_stiffness: the pattern does not match the mesh");
  linalg::SparseMatrixD Kg = pattern;
  Kg.makeCompressed();
  std::fill(Kg.valuePtr(), Kg.valuePtr() + Kg.nonZeros(), 0.0);
  if (mesh.nodes_per_element() == 4) assemble_geometric_range<4>(mesh, material, u, Kg);
  else assemble_geometric_range<10>(mesh, material, u, Kg);
  return Kg;
}

PeakStress peak_von_mises(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u) {
  SHROUDSIM_CHECK(u.size() == mesh.n_dofs(), "peak_von_mises: u does not match the mesh");
  return mesh.nodes_per_element() == 4 ? peak_range<4>(mesh, material, u) : peak_range<10>(mesh, material, u);
}

namespace {
template <int NPE>
Eigen::VectorXd nodal_range(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u) {
  // Reference coordinates of the nodes (gmsh order: vertices, then edge midpoints).
  static const std::vector<Eigen::Matrix<double, NPE, 3>> node_dn = [] {
    const double ref[10][3] = {{0, 0, 0},     {1, 0, 0},   {0, 1, 0},   {0, 0, 1},     {0.5, 0, 0},
                               {0.5, 0.5, 0}, {0, 0.5, 0}, {0, 0, 0.5}, {0, 0.5, 0.5}, {0.5, 0, 0.5}};
    std::vector<Eigen::Matrix<double, NPE, 3>> v;
    for (int a = 0; a < NPE; ++a)
      v.push_back(TetShape<NPE>::gradients(Eigen::Vector3d(ref[a][0], ref[a][1], ref[a][2])));
    return v;
  }();
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(mesh.n_nodes()), count = sum;
  ElementNodes<NPE> X;
  ElementVector<NPE> ue;
  Eigen::Matrix<double, NPE, 3> G;
  for (int e = 0; e < mesh.n_elements(); ++e) {
    for (int a = 0; a < NPE; ++a) {
      const int n = mesh.tets(e, a);
      X.row(a) = mesh.nodes.row(n);
      ue.template segment<3>(3 * a) = u.segment<3>(3 * n);
    }
    for (int a = 0; a < NPE; ++a) {
      double det = 0.0;
      if (!physical_gradients<NPE>(X, node_dn[a], G, det)) continue;
      sum(mesh.tets(e, a)) += von_mises(stress_from_gradients<NPE>(material, G, ue));
      count(mesh.tets(e, a)) += 1.0;
    }
  }
  return sum.cwiseQuotient(count.cwiseMax(1.0));
}
}  // namespace

Eigen::VectorXd nodal_von_mises(const mesh::Mesh& mesh, const Material& material, const Eigen::VectorXd& u) {
  SHROUDSIM_CHECK(u.size() == mesh.n_dofs(), "nodal_von_mises: u does not match the mesh");
  return mesh.nodes_per_element() == 4 ? nodal_range<4>(mesh, material, u) : nodal_range<10>(mesh, material, u);
}

template bool tet_stress<4>(const ElementNodes<4>&, const Material&, const ElementVector<4>&, const Eigen::Vector3d&,
                            Eigen::Matrix3d&);
template bool tet_stress<10>(const ElementNodes<10>&, const Material&, const ElementVector<10>&, const Eigen::Vector3d&,
                             Eigen::Matrix3d&);
template bool tet_geometric_stiffness<4>(const ElementNodes<4>&, const Material&, const ElementVector<4>&,
                                         ScalarElementMatrix<4>&);
template bool tet_geometric_stiffness<10>(const ElementNodes<10>&, const Material&, const ElementVector<10>&,
                                          ScalarElementMatrix<10>&);
template bool tet_geometric_stiffness<4>(const ElementNodes<4>&, const Eigen::Matrix3d&, ScalarElementMatrix<4>&);
template bool tet_geometric_stiffness<10>(const ElementNodes<10>&, const Eigen::Matrix3d&, ScalarElementMatrix<10>&);

}  // namespace shroudsim::fe
