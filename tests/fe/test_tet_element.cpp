// Element-level checks: quadrature exactness, shape functions, closed-form mass matrices.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "fe/quadrature.hpp"
#include "fe/tet_element.hpp"

namespace shroudsim::fe {
namespace {

double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

TEST(TetQuadrature, IntegratesMonomialsExactlyUpToItsDegree) {
  // int_ref xi^a eta^b zeta^c = a! b! c! / (a + b + c + 3)!
  constexpr double kTol = 1e-14;  // rounding of ~14 products and sums
  for (int degree : {1, 2, 5}) {
    const TetQuadrature& q = tet_quadrature(degree);
    ASSERT_EQ(q.degree, degree);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b)
        for (int c = 0; a + b + c <= degree; ++c) {
          double sum = 0.0;
          for (int k = 0; k < q.size(); ++k)
            sum +=
                q.weights[k] * std::pow(q.points[k](0), a) * std::pow(q.points[k](1), b) * std::pow(q.points[k](2), c);
          const double exact = factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 3);
          EXPECT_NEAR(sum, exact, kTol) << "degree " << degree << " monomial " << a << b << c;
        }
    for (double w : q.weights) EXPECT_GT(w, 0.0);
  }
}

TEST(TetQuadrature, DegreeTwoRuleIsNotExactForDegreeThree) {
  // Guards the test above against a rule that is trivially exact: xi^3 must fail at degree 2.
  const TetQuadrature& q = tet_quadrature(2);
  double sum = 0.0;
  for (int k = 0; k < q.size(); ++k) sum += q.weights[k] * std::pow(q.points[k](0), 3);
  EXPECT_GT(std::abs(sum - factorial(3) / factorial(6)), 1e-6);
}

template <int NPE>
void check_partition_of_unity_and_nodality() {
  // Node positions on the reference tet (gmsh order).
  Eigen::Matrix<double, 10, 3> ref;
  ref << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, 0, 0, 0.5, 0.5, 0, 0, 0.5, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 0, 0.5;
  for (int a = 0; a < NPE; ++a) {
    const auto n = TetShape<NPE>::values(ref.row(a).transpose());
    for (int b = 0; b < NPE; ++b) EXPECT_NEAR(n(b), a == b ? 1.0 : 0.0, 1e-15);
  }
  const Eigen::Vector3d xi(0.2, 0.3, 0.1);
  EXPECT_NEAR(TetShape<NPE>::values(xi).sum(), 1.0, 1e-15);
  EXPECT_LT(TetShape<NPE>::gradients(xi).colwise().sum().norm(), 1e-14);
  // Gradients against central differences of the values (quadratic: exact up to rounding).
  constexpr double kStep = 1e-6;
  for (int d = 0; d < 3; ++d) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e(d) = kStep;
    const auto fd = ((TetShape<NPE>::values(xi + e) - TetShape<NPE>::values(xi - e)) / (2 * kStep)).eval();
    EXPECT_LT((fd - TetShape<NPE>::gradients(xi).col(d)).norm(), 1e-8);
  }
}

TEST(TetShape, Tet4NodalPartitionOfUnityAndGradients) { check_partition_of_unity_and_nodality<4>(); }
TEST(TetShape, Tet10NodalPartitionOfUnityAndGradients) { check_partition_of_unity_and_nodality<10>(); }

// A distorted straight-sided element: vertices below, edge nodes at midpoints.
ElementNodes<10> distorted_tet10() {
  Eigen::Matrix<double, 4, 3> v;
  v << 0.1, 0.0, 0.05, 1.3, 0.2, -0.1, 0.3, 0.9, 0.2, 0.2, 0.4, 1.1;
  constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
  ElementNodes<10> X;
  X.topRows<4>() = v;
  for (int e = 0; e < 6; ++e) X.row(4 + e) = 0.5 * (v.row(kEdge[e][0]) + v.row(kEdge[e][1]));
  return X;
}

TEST(TetElement, Tet10MassMatchesClosedForm) {
  // Consistent mass of the straight-sided 10-node tet: rho V / 420 times
  // vertex-vertex 6 (diag) / 1, vertex-edge -4 (edge touches the vertex) / -6,
  // edge-edge 32 (diag) / 16 (edges share a vertex) / 8 (opposite edges).
  // The integrand has degree 4: a rule below degree 4 fails this test.
  const ElementNodes<10> X = distorted_tet10();
  const Material mat{200e9, 0.3, 7800.0};
  ElementMatrix<10> K, M;
  ASSERT_TRUE(tet_matrices<10>(X, mat, K, M));
  const double V = tet_volume(X.row(0).transpose(), X.row(1).transpose(), X.row(2).transpose(), X.row(3).transpose());
  constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
  auto touches = [&](int e, int v) { return kEdge[e][0] == v || kEdge[e][1] == v; };
  auto shares = [&](int e, int f) { return touches(f, kEdge[e][0]) || touches(f, kEdge[e][1]); };
  Eigen::Matrix<double, 10, 10> ref;
  for (int a = 0; a < 10; ++a)
    for (int b = 0; b < 10; ++b) {
      if (a < 4 && b < 4) ref(a, b) = a == b ? 6 : 1;
      else if (a < 4) ref(a, b) = touches(b - 4, a) ? -4 : -6;
      else if (b < 4) ref(a, b) = touches(a - 4, b) ? -4 : -6;
      else ref(a, b) = a == b ? 32 : shares(a - 4, b - 4) ? 16 : 8;
    }
  ref *= mat.density * V / 420.0;
  constexpr double kTol = 1e-13;  // relative, rounding only
  for (int a = 0; a < 10; ++a)
    for (int b = 0; b < 10; ++b)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          EXPECT_NEAR(M(3 * a + i, 3 * b + j), i == j ? ref(a, b) : 0.0, kTol * mat.density * V);
}

TEST(TetElement, Tet4MassMatchesClosedForm) {
  // rho V / 20 (1 + delta_ab) per direction.
  const ElementNodes<10> X10 = distorted_tet10();
  const ElementNodes<4> X = X10.topRows<4>();
  const Material mat{200e9, 0.3, 7800.0};
  ElementMatrix<4> K, M;
  ASSERT_TRUE(tet_matrices<4>(X, mat, K, M));
  const double V = tet_volume(X.row(0).transpose(), X.row(1).transpose(), X.row(2).transpose(), X.row(3).transpose());
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      EXPECT_NEAR(M(3 * a, 3 * b), mat.density * V / 20.0 * (a == b ? 2.0 : 1.0), 1e-13 * mat.density * V);
}

TEST(TetElement, StiffnessIsSymmetricWithRigidBodyNullSpace) {
  const ElementNodes<10> X = distorted_tet10();
  const Material mat{200e9, 0.3, 7800.0};
  ElementMatrix<10> K, M;
  ASSERT_TRUE(tet_matrices<10>(X, mat, K, M));
  EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
  // Translations and infinitesimal rotations produce no force.
  for (int r = 0; r < 6; ++r) {
    Eigen::Matrix<double, 30, 1> u;
    for (int a = 0; a < 10; ++a) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      if (r < 3) d(r) = 1.0;
      else d = Eigen::Vector3d::Unit(r - 3).cross(X.row(a).transpose());
      u.segment<3>(3 * a) = d;
    }
    EXPECT_LT((K * u).norm(), 1e-12 * K.norm() * u.norm()) << "rigid mode " << r;
  }
}

TEST(TetElement, InvertedElementIsReported) {
  ElementNodes<10> X = distorted_tet10();
  X.row(1).swap(X.row(2));  // swaps two vertices (edge nodes now wrong too): negative Jacobian
  ElementMatrix<10> K, M;
  EXPECT_FALSE(tet_matrices<10>(X, Material{}, K, M));
}

}  // namespace
}  // namespace shroudsim::fe
