#pragma once
// Quadrature rules on the reference tetrahedron {xi, eta, zeta >= 0, xi + eta + zeta <= 1}
// (volume 1/6; the weights sum to 1/6).
#include <Eigen/Core>
#include <vector>

namespace shroudsim::fe {

struct TetQuadrature {
  int degree = 0;                       ///< exact for polynomials up to this total degree
  std::vector<Eigen::Vector3d> points;  ///< reference coordinates (xi, eta, zeta)
  std::vector<double> weights;          ///< all positive, sum 1/6
  int size() const { return static_cast<int>(points.size()); }
};

/// The cheapest stored rule exact for total degree `degree` (1..5), all weights positive:
/// degree 1: centroid (1 point); degree 2: 4 points; degree 3..5: 14 points (Walkington's
/// degree-5 rule). Stiffness of a straight-sided 10-node tetrahedron is degree 2, its
/// consistent mass degree 4.
const TetQuadrature& tet_quadrature(int degree);

}  // namespace shroudsim::fe
