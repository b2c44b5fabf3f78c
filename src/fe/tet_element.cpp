#include "fe/tet_element.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <vector>

#include "fe/quadrature.hpp"

namespace shroudsim::fe {

bool Material::valid() const {
  return std::isfinite(youngs_modulus) && std::isfinite(poisson_ratio) && std::isfinite(density) &&
         youngs_modulus > 0.0 && poisson_ratio > -1.0 && poisson_ratio < 0.5 && density > 0.0;
}

template <>
Eigen::Matrix<double, 4, 1> TetShape<4>::values(const Eigen::Vector3d& xi) {
  return {1.0 - xi.sum(), xi(0), xi(1), xi(2)};
}

template <>
Eigen::Matrix<double, 4, 3> TetShape<4>::gradients(const Eigen::Vector3d&) {
  Eigen::Matrix<double, 4, 3> g;
  g << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return g;
}

namespace {
// Edge nodes 4..9 of the 10-node tet join these vertex pairs (gmsh order).
constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
}  // namespace

template <>
Eigen::Matrix<double, 10, 1> TetShape<10>::values(const Eigen::Vector3d& xi) {
  const Eigen::Vector4d l(1.0 - xi.sum(), xi(0), xi(1), xi(2));  // barycentric
  Eigen::Matrix<double, 10, 1> n;
  for (int a = 0; a < 4; ++a) n(a) = l(a) * (2.0 * l(a) - 1.0);
  for (int e = 0; e < 6; ++e) n(4 + e) = 4.0 * l(kEdge[e][0]) * l(kEdge[e][1]);
  return n;
}

template <>
Eigen::Matrix<double, 10, 3> TetShape<10>::gradients(const Eigen::Vector3d& xi) {
  const Eigen::Vector4d l(1.0 - xi.sum(), xi(0), xi(1), xi(2));
  const Eigen::Matrix<double, 4, 3> dl = TetShape<4>::gradients(xi);  // d l_a / d xi
  Eigen::Matrix<double, 10, 3> g;
  for (int a = 0; a < 4; ++a) g.row(a) = (4.0 * l(a) - 1.0) * dl.row(a);
  for (int e = 0; e < 6; ++e) {
    const int i = kEdge[e][0], j = kEdge[e][1];
    g.row(4 + e) = 4.0 * (l(i) * dl.row(j) + l(j) * dl.row(i));
  }
  return g;
}

namespace {

// Shape values and reference gradients tabulated at the points of one rule.
template <int NPE>
struct Tabulated {
  std::vector<double> weights;
  std::vector<Eigen::Matrix<double, NPE, 1>> n;
  std::vector<Eigen::Matrix<double, NPE, 3>> dn;
  explicit Tabulated(const TetQuadrature& q) : weights(q.weights) {
    for (const auto& p : q.points) {
      n.push_back(TetShape<NPE>::values(p));
      dn.push_back(TetShape<NPE>::gradients(p));
    }
  }
};

template <int NPE>
constexpr int kStiffnessDegree = 2 * ((NPE == 4 ? 1 : 2) - 1);
template <int NPE>
constexpr int kMassDegree = 2 * (NPE == 4 ? 1 : 2);

}  // namespace

template <int NPE>
bool tet_matrices(const ElementNodes<NPE>& X, const Material& material, ElementMatrix<NPE>& K, ElementMatrix<NPE>& M) {
  static const Tabulated<NPE> kq(tet_quadrature(kStiffnessDegree<NPE>));
  static const Tabulated<NPE> mq(tet_quadrature(kMassDegree<NPE>));
  const double lambda = material.lame_lambda();
  const double mu = material.shear_modulus();
  const double rho = material.density;

  K.setZero();
  for (std::size_t q = 0; q < kq.weights.size(); ++q) {
    const Eigen::Matrix3d J = X.transpose() * kq.dn[q];  // J(i, j) = d x_i / d xi_j
    const double det = J.determinant();
    if (!(det > 0.0)) return false;
    // Physical gradients, one row per node: G = dN/dxi J^{-1}.
    const Eigen::Matrix<double, NPE, 3> G = kq.dn[q] * J.inverse();
    const double w = kq.weights[q] * det;
    const Eigen::Matrix<double, NPE, NPE> dots = G * G.transpose();
    for (int b = 0; b < NPE; ++b) {
      for (int a = b; a < NPE; ++a) {
        auto blk = K.template block<3, 3>(3 * a, 3 * b);
        const Eigen::Vector3d ga = G.row(a).transpose(), gb = G.row(b).transpose();
        blk.noalias() += (w * lambda) * ga * gb.transpose() + (w * mu) * gb * ga.transpose();
        blk.diagonal().array() += w * mu * dots(a, b);
      }
    }
  }
  M.setZero();
  Eigen::Matrix<double, NPE, NPE> m = Eigen::Matrix<double, NPE, NPE>::Zero();
  for (std::size_t q = 0; q < mq.weights.size(); ++q) {
    const Eigen::Matrix3d J = X.transpose() * mq.dn[q];
    const double det = J.determinant();
    if (!(det > 0.0)) return false;
    m.noalias() += (mq.weights[q] * det * rho) * mq.n[q] * mq.n[q].transpose();
  }
  // Mirror the lower block triangle of K; expand the scalar mass to 3 components.
  for (int b = 0; b < NPE; ++b) {
    for (int a = b; a < NPE; ++a) {
      if (a != b) K.template block<3, 3>(3 * b, 3 * a) = K.template block<3, 3>(3 * a, 3 * b).transpose();
      for (int i = 0; i < 3; ++i) {
        M(3 * a + i, 3 * b + i) = m(a, b);
        M(3 * b + i, 3 * a + i) = m(a, b);
      }
    }
  }
  return true;
}

double tet_volume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                  const Eigen::Vector3d& x3) {
  return (x1 - x0).dot((x2 - x0).cross(x3 - x0)) / 6.0;
}

template bool tet_matrices<4>(const ElementNodes<4>&, const Material&, ElementMatrix<4>&, ElementMatrix<4>&);
template bool tet_matrices<10>(const ElementNodes<10>&, const Material&, ElementMatrix<10>&, ElementMatrix<10>&);

}  // namespace shroudsim::fe
