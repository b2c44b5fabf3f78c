// Cyclic reduction against the full 360-degree wheel assembled from Nb copies.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <numbers>

#include "core/error.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "fe/assembly.hpp"
#include "fe/structured_mesh.hpp"

namespace shroudsim::cyclic {
namespace {

const fe::Material kSteel{210e9, 0.3, 7850.0};

fe::AnnularSectorSpec small_sector(int sectors, int order) {
  fe::AnnularSectorSpec s;
  s.sectors = sectors;
  s.n_r = 2, s.n_theta = 2, s.n_z = 1, s.element_order = order;
  s.r_inner = 0.1, s.r_outer = 0.2, s.thickness = 0.03;
  return s;
}

std::vector<double> dense_eigenvalues(const Eigen::MatrixXcd& K, const Eigen::MatrixXcd& M) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXcd> es(K, M, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd ev = es.eigenvalues();
  return {ev.data(), ev.data() + ev.size()};
}

struct WheelCase {
  int sectors;
  int order;
};

class FullWheel : public ::testing::TestWithParam<WheelCase> {};

TEST_P(FullWheel, UnionOfCyclicSpectraEqualsWheelSpectrum) {
  const auto [nb, order] = GetParam();
  const mesh::Mesh sector_mesh = fe::annular_sector_mesh(small_sector(nb, order));
  const CyclicSector sector(sector_mesh, fe::assemble(sector_mesh, kSteel, 1));

  // Full wheel, hub clamped: every eigenvalue.
  const mesh::Mesh wheel = fe::replicate_wheel(sector_mesh);
  const auto kmw = fe::assemble(wheel, kSteel, 1);
  const auto free = fe::free_dofs(wheel.n_dofs(), fe::node_dofs(wheel.node_set(mesh::kHub)));
  ASSERT_EQ(static_cast<Eigen::Index>(free.size()), nb * sector.n_reduced());  // DOF count identity
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(
      Eigen::MatrixXd(fe::restrict(kmw.K, free)), Eigen::MatrixXd(fe::restrict(kmw.M, free)), Eigen::EigenvaluesOnly);
  const Eigen::VectorXd wheel_ev = es.eigenvalues();

  std::vector<double> cyclic_ev;
  std::vector<std::vector<double>> per_h(nb);
  for (int h = 0; h < nb; ++h) {
    const auto km = sector.reduce(h);
    per_h[h] = dense_eigenvalues(Eigen::MatrixXcd(km.K), Eigen::MatrixXcd(km.M));
    cyclic_ev.insert(cyclic_ev.end(), per_h[h].begin(), per_h[h].end());
  }
  std::sort(cyclic_ev.begin(), cyclic_ev.end());
  ASSERT_EQ(static_cast<Eigen::Index>(cyclic_ev.size()), wheel_ev.size());
  // Frequencies (sqrt of eigenvalues) agree to 1e-8 relative, as issue 3 asks; dense
  // eigenvalues of these ~1e3-DOF problems carry ~1e-12 relative rounding.
  constexpr double kRelTol = 1e-8;
  double worst = 0.0;
  for (std::size_t i = 0; i < cyclic_ev.size(); ++i) {
    const double fw = std::sqrt(wheel_ev(i)), fc = std::sqrt(cyclic_ev[i]);
    worst = std::max(worst, std::abs(fw - fc) / fw);
  }
  EXPECT_LT(worst, kRelTol) << "Nb " << nb << " order " << order;
  RecordProperty("max_relative_frequency_difference", std::to_string(worst));
  std::printf("  Nb %d order %d: %zu wheel modes, max relative frequency difference %.2e\n", nb, order,
              cyclic_ev.size(), worst);

  // h and Nb - h: equal spectra.
  for (int h = 1; h < nb; ++h)
    for (std::size_t i = 0; i < per_h[h].size(); ++i)
      EXPECT_NEAR(per_h[h][i], per_h[nb - h][i], kRelTol * per_h[h][i]) << "h " << h;
}

INSTANTIATE_TEST_SUITE_P(Wheels, FullWheel,
                         ::testing::Values(WheelCase{6, 2}, WheelCase{5, 2}, WheelCase{6, 1}, WheelCase{3, 2}));

TEST(CyclicSector, ReducedMatricesAreHermitianAndRealForNd0AndNbOver2) {
  const int nb = 6;
  const mesh::Mesh m = fe::annular_sector_mesh(small_sector(nb, 2));
  const CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  for (int h = 0; h < nb; ++h) {
    const auto km = sector.reduce(h);
    const Eigen::MatrixXcd K(km.K), M(km.M);
    EXPECT_LT((K - K.adjoint()).norm(), 1e-14 * K.norm()) << h;
    EXPECT_LT((M - M.adjoint()).norm(), 1e-14 * M.norm()) << h;
    if (h == 0 || 2 * h == nb) {
      EXPECT_EQ(K.imag().norm(), 0.0) << h;
      EXPECT_EQ(M.imag().norm(), 0.0) << h;
      const auto kr = sector.reduce_real(h);
      EXPECT_EQ((Eigen::MatrixXd(kr.K) - K.real()).norm(), 0.0);
    } else {
      EXPECT_GT(K.imag().norm(), 1e-6 * K.norm()) << h;
    }
    // K_{Nb-h} = conj(K_h)
    const int hc = (nb - h) % nb;
    const Eigen::MatrixXcd Kc(sector.reduce(hc).K);
    EXPECT_LT((Kc - K.conjugate()).norm(), 1e-14 * K.norm());
  }
}

TEST(CyclicSector, ExpansionSatisfiesTheCyclicConstraint) {
  const int nb = 7;
  const mesh::Mesh m = fe::annular_sector_mesh(small_sector(nb, 2));
  const CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  const Eigen::Matrix3d R = rotation_z(2.0 * std::numbers::pi / nb);
  std::srand(11);
  const Eigen::MatrixXcd ur = Eigen::MatrixXcd::Random(sector.n_reduced(), 2);
  for (int h : {0, 2, 5}) {
    const Eigen::MatrixXcd u = sector.expand(h, ur);
    ASSERT_EQ(u.rows(), m.n_dofs());
    const std::complex<double> e = std::polar(1.0, 2.0 * std::numbers::pi * h / nb);
    for (const auto& [p, q] : m.cyclic_pairs)
      for (int c = 0; c < 2; ++c) {
        const Eigen::Vector3cd up = u.col(c).segment<3>(3 * p), uq = u.col(c).segment<3>(3 * q);
        EXPECT_LT((uq - e * R.cast<std::complex<double>>() * up).norm(), 1e-14 * (1.0 + up.norm()));
      }
    for (int d : sector.clamped_dofs()) EXPECT_EQ(std::abs(u(d, 0)), 0.0);
  }
  EXPECT_EQ(nodal_diameter(5, nb), 2);
  EXPECT_EQ(nodal_diameter(3, nb), 3);
  EXPECT_EQ(nodal_diameter(9, nb), 2);  // engine order 9 aliases to h = 2
}

TEST(CyclicSector, MismatchedPairsAreRejected) {
  mesh::Mesh m = fe::annular_sector_mesh(small_sector(6, 1));
  m.nodes(m.cyclic_pairs.front().second, 2) += 1e-3;
  EXPECT_THROW(CyclicSector(m, fe::assemble(m, kSteel, 1)), InputError);
}

}  // namespace
}  // namespace shroudsim::cyclic
