// Assembled-matrix checks: patch test, rigid-body null space, total mass.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "fe/assembly.hpp"
#include "fe/structured_mesh.hpp"
#include "linalg/cholmod_factor.hpp"

namespace shroudsim::fe {
namespace {

const Material kSteel{210e9, 0.3, 7850.0};

// A linear displacement field u(x) = c + B x (arbitrary, fixed).
Eigen::VectorXd linear_field(const mesh::Mesh& m) {
  Eigen::Matrix3d B;
  B << 1e-3, 2e-4, -3e-4, -5e-4, 7e-4, 1e-4, 3e-4, -2e-4, -6e-4;
  const Eigen::Vector3d c(1e-4, -2e-4, 3e-4);
  Eigen::VectorXd u(m.n_dofs());
  for (int n = 0; n < m.n_nodes(); ++n) u.segment<3>(3 * n) = c + B * m.nodes.row(n).transpose();
  return u;
}

class PatchTest : public ::testing::TestWithParam<int> {};

TEST_P(PatchTest, LinearFieldIsReproducedExactlyOnADistortedMesh) {
  // Boundary nodes get the linear field; the interior nodes are solved for. A linear field
  // has constant stress, so the FE solution must equal it (to rounding) for both orders.
  const int order = GetParam();
  const mesh::Mesh m = box_mesh(1.0, 0.8, 0.6, 4, 4, 3, order, /*perturbation=*/0.2, /*seed=*/3);
  const auto km = assemble(m, kSteel, 1);
  const Eigen::VectorXd u_exact = linear_field(m);
  std::vector<int> boundary;
  const Eigen::Vector3d hi(1.0, 0.8, 0.6);
  for (int n = 0; n < m.n_nodes(); ++n) {
    const Eigen::Vector3d x = m.nodes.row(n).transpose();
    if ((x.array() < 1e-12).any() || ((hi - x).array() < 1e-12).any()) boundary.push_back(n);
  }
  const std::vector<int> fixed = node_dofs(boundary);
  const std::vector<int> free = free_dofs(m.n_dofs(), fixed);
  ASSERT_GT(free.size(), 30u);  // there are interior nodes to solve for
  // f_free = -K(free, fixed) u_fixed.
  Eigen::VectorXd u_fixed_full = Eigen::VectorXd::Zero(m.n_dofs());
  for (int d : fixed) u_fixed_full(d) = u_exact(d);
  const Eigen::VectorXd f_full = -(km.K * u_fixed_full);
  Eigen::VectorXd f(free.size());
  for (std::size_t k = 0; k < free.size(); ++k) f(k) = f_full(free[k]);
  linalg::CholmodFactor<double> llt;
  ASSERT_EQ(llt.compute(restrict(km.K, free)), linalg::FactorStatus::Success);
  const Eigen::VectorXd u_free = llt.solve(Eigen::MatrixXd(f));
  double err = 0.0, ref = 0.0;
  for (std::size_t k = 0; k < free.size(); ++k) {
    err = std::max(err, std::abs(u_free(k) - u_exact(free[k])));
    ref = std::max(ref, std::abs(u_exact(free[k])));
  }
  constexpr double kPatchTol = 1e-12;  // relative; condition number ~1e4 times machine epsilon
  EXPECT_LT(err, kPatchTol * ref) << "order " << order;
}

INSTANTIATE_TEST_SUITE_P(BothOrders, PatchTest, ::testing::Values(1, 2));

class FreeStiffness : public ::testing::TestWithParam<int> {};

TEST_P(FreeStiffness, HasExactlySixZeroEigenvalues) {
  const int order = GetParam();
  const mesh::Mesh m = box_mesh(1.0, 0.5, 0.4, 3, 2, 2, order, 0.15, 7);
  const auto km = assemble(m, kSteel, 1);
  const Eigen::MatrixXd K(km.K);
  ASSERT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K, Eigen::EigenvaluesOnly).eigenvalues();
  const double top = ev.maxCoeff();
  // Rigid-body eigenvalues are rounding noise (~1e-15 top); the smallest elastic one of this
  // coarse mesh is ~1e-3 top. 1e-10 separates the two by orders of magnitude either way.
  constexpr double kZero = 1e-10;
  int zeros = 0;
  for (Eigen::Index i = 0; i < ev.size(); ++i) zeros += std::abs(ev(i)) < kZero * top;
  EXPECT_EQ(zeros, 6) << "order " << order;
  EXPECT_GT(ev(6), 1e-6 * top);
  EXPECT_GT(ev(0), -kZero * top);  // positive semi-definite
}

INSTANTIATE_TEST_SUITE_P(BothOrders, FreeStiffness, ::testing::Values(1, 2));

class TotalMass : public ::testing::TestWithParam<int> {};

TEST_P(TotalMass, EqualsDensityTimesMeshedVolume) {
  const int order = GetParam();
  constexpr double kTol = 1e-12;  // relative, rounding of the sums
  // Box: meshed volume is the exact volume, even when distorted inside.
  {
    const mesh::Mesh m = box_mesh(1.0, 0.5, 0.4, 3, 2, 2, order, 0.15, 7);
    EXPECT_NEAR(meshed_volume(m), 0.2, kTol * 0.2);
    const auto km = assemble(m, kSteel, 1);
    for (int c = 0; c < 3; ++c) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(m.n_dofs());
      for (int n = 0; n < m.n_nodes(); ++n) e(3 * n + c) = 1.0;
      EXPECT_NEAR(e.dot(km.M * e), kSteel.density * 0.2, kTol * kSteel.density * 0.2);
    }
  }
  // Annular sector: the meshed volume is the polygonal annulus (chords between theta
  // stations): V = (ro^2 - ri^2) / 2 * n_theta * sin(alpha / n_theta) * thickness.
  {
    AnnularSectorSpec s;
    s.n_r = 3, s.n_theta = 4, s.n_z = 2, s.element_order = order;
    const mesh::Mesh m = annular_sector_mesh(s);
    const double v = meshed_volume(m);
    const double alpha = 2.0 * std::numbers::pi / s.sectors;
    const double polygon =
        0.5 * (s.r_outer * s.r_outer - s.r_inner * s.r_inner) * s.n_theta * std::sin(alpha / s.n_theta) * s.thickness;
    EXPECT_NEAR(v, polygon, kTol * polygon);
    const auto km = assemble(m, kSteel, 2);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(m.n_dofs());
    for (int n = 0; n < m.n_nodes(); ++n) e(3 * n + 2) = 1.0;
    EXPECT_NEAR(e.dot(km.M * e), kSteel.density * v, kTol * kSteel.density * v);
  }
}

INSTANTIATE_TEST_SUITE_P(BothOrders, TotalMass, ::testing::Values(1, 2));

// K and M are the same to the last bit whatever the thread count (the element slices are
// summed in a fixed order): a round-off difference in K changes the path of every curve traced
// on the sector (docs/continuation.md, "Determinism").
TEST(Assembler, ThreadedAssemblyEqualsSerialBitForBit) {
  AnnularSectorSpec s;
  s.n_r = 6, s.n_theta = 6, s.n_z = 4, s.element_order = 2, s.blade_length = 0.1, s.n_blade = 6;
  const mesh::Mesh m = annular_sector_mesh(s);
  ASSERT_GE(m.n_elements(), 1000);  // enough for two slices
  const Assembler a(m);
  const auto one = a.assemble(kSteel, 1);
  for (int threads : {2, 3, 0}) {
    const auto other = a.assemble(kSteel, threads);
    ASSERT_EQ(one.K.nonZeros(), other.K.nonZeros());
    for (Eigen::Index k = 0; k < one.K.nonZeros(); ++k) {
      ASSERT_EQ(one.K.valuePtr()[k], other.K.valuePtr()[k]) << "threads " << threads << ", K entry " << k;
      ASSERT_EQ(one.M.valuePtr()[k], other.M.valuePtr()[k]) << "threads " << threads << ", M entry " << k;
    }
  }
}

TEST(Assembler, InvertedElementThrowsInputError) {
  mesh::Mesh m = box_mesh(1.0, 1.0, 1.0, 1, 1, 1, 1);
  std::swap(m.tets(0, 1), m.tets(0, 2));
  EXPECT_THROW(assemble(m, kSteel, 1), InputError);
}

}  // namespace
}  // namespace shroudsim::fe
