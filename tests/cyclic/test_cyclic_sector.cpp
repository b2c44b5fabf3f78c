// Cyclic reduction against the full 360-degree wheel assembled from Nb copies.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
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
  // Each conjugate pair {h, Nb - h} has one canonical index, its smaller member.
  for (int n : {1, 2, 7, 8}) {
    for (int h = 0; h < n; ++h) {
      const int c = canonical_index(h, n);
      EXPECT_EQ(c, canonical_index((n - h) % n, n)) << "n = " << n << ", h = " << h;
      EXPECT_EQ(c, std::min(h, (n - h) % n)) << "n = " << n << ", h = " << h;
    }
  }
}

TEST(CyclicSector, MismatchedPairsAreRejected) {
  mesh::Mesh m = fe::annular_sector_mesh(small_sector(6, 1));
  m.nodes(m.cyclic_pairs.front().second, 2) += 1e-3;
  EXPECT_THROW(CyclicSector(m, fe::assemble(m, kSteel, 1)), InputError);
}

// ---- Interface springs (the stuck shroud) against the full wheel ----

// Node of the sector at (r, theta / alpha, z) nearest to the given point (an exact grid node).
int node_at(const mesh::Mesh& m, double r, double theta_fraction, double z) {
  const double a = 2.0 * std::numbers::pi / m.sectors * theta_fraction;
  const Eigen::Vector3d x(r * std::cos(a), r * std::sin(a), z);
  int best = -1;
  double d_best = 1e300;
  for (int v = 0; v < m.n_nodes(); ++v) {
    const double d = (m.nodes.row(v).transpose() - x).norm();
    if (d < d_best) best = v, d_best = d;
  }
  return best;
}

// Two springs from nodes near theta = alpha of a sector to nodes near theta = 0 of the next,
// one of them from a cyclic_high node, with turned frames and unequal stiffnesses.
std::vector<InterfaceSpring> test_springs(const mesh::Mesh& m, double k) {
  std::vector<InterfaceSpring> springs(2);
  springs[0].high_node = node_at(m, 0.2, 0.75, 0.03);
  springs[0].low_node = node_at(m, 0.2, 0.25, 0.03);
  springs[1].high_node = node_at(m, 0.2, 1.0, 0.0);  // on cyclic_high
  springs[1].low_node = node_at(m, 0.15, 0.25, 0.0);
  springs[0].frame = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  springs[1].frame = Eigen::AngleAxisd(-1.1, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  springs[0].stiffness = Eigen::Vector3d(0.5, 0.7, 2.0) * k;
  springs[1].stiffness = Eigen::Vector3d(1.0, 0.3, 1.5) * k;
  return springs;
}

// Wheel node of node v of sector copy k (replicate_wheel's numbering).
int wheel_node(const mesh::Mesh& sector, int k, int v) {
  const int nb = sector.sectors, n = sector.n_nodes();
  std::vector<int> partner_low(n, -1), kept(n, -1);
  for (const auto& [p, q] : sector.cyclic_pairs) partner_low[q] = p;
  int n_kept = 0;
  for (int u = 0; u < n; ++u)
    if (partner_low[u] < 0) kept[u] = n_kept++;
  if (partner_low[v] >= 0) return ((k + 1) % nb) * n_kept + kept[partner_low[v]];
  return k * n_kept + kept[v];
}

// Eigenvalues of the full wheel (hub clamped) with the springs of every sector added to K
// directly (stiffness matrix assembled in global coordinates).
Eigen::VectorXd wheel_with_springs(const mesh::Mesh& sector_mesh, const std::vector<InterfaceSpring>& springs) {
  const int nb = sector_mesh.sectors;
  const mesh::Mesh wheel = fe::replicate_wheel(sector_mesh);
  const auto kmw = fe::assemble(wheel, kSteel, 1);
  Eigen::MatrixXd K(kmw.K);
  for (int k = 0; k < nb; ++k) {
    const Eigen::Matrix3d Rk = rotation_z(2.0 * std::numbers::pi * k / nb);
    for (const auto& s : springs) {
      const int a = wheel_node(sector_mesh, k, s.high_node), b = wheel_node(sector_mesh, (k + 1) % nb, s.low_node);
      const Eigen::Matrix3d L = s.frame * Rk.transpose();  // the frame turned with copy k
      const Eigen::Matrix3d Ks = L.transpose() * s.stiffness.asDiagonal() * L;
      K.block<3, 3>(3 * a, 3 * a) += Ks;
      K.block<3, 3>(3 * b, 3 * b) += Ks;
      K.block<3, 3>(3 * a, 3 * b) -= Ks;
      K.block<3, 3>(3 * b, 3 * a) -= Ks;
    }
  }
  const auto free = fe::free_dofs(wheel.n_dofs(), fe::node_dofs(wheel.node_set(mesh::kHub)));
  std::vector<int> f(free.begin(), free.end());
  Eigen::MatrixXd Kf(f.size(), f.size()), Mf(f.size(), f.size());
  const Eigen::MatrixXd M(kmw.M);
  for (std::size_t i = 0; i < f.size(); ++i)
    for (std::size_t j = 0; j < f.size(); ++j) Kf(i, j) = K(f[i], f[j]), Mf(i, j) = M(f[i], f[j]);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kf, Mf, Eigen::EigenvaluesOnly);
  return es.eigenvalues();
}

std::vector<double> cyclic_union(const CyclicSector& sector) {
  std::vector<double> ev;
  for (int h = 0; h < sector.sectors(); ++h) {
    const auto km = sector.reduce(h);
    const auto e = dense_eigenvalues(Eigen::MatrixXcd(km.K), Eigen::MatrixXcd(km.M));
    ev.insert(ev.end(), e.begin(), e.end());
  }
  std::sort(ev.begin(), ev.end());
  return ev;
}

double max_relative_frequency_difference(const Eigen::VectorXd& wheel_ev, const std::vector<double>& cyclic_ev,
                                         int count) {
  double worst = 0.0;
  for (int i = 0; i < count; ++i)
    worst = std::max(worst, std::abs(std::sqrt(wheel_ev(i)) - std::sqrt(cyclic_ev[i])) / std::sqrt(wheel_ev(i)));
  return worst;
}

class WheelWithSprings : public ::testing::TestWithParam<int> {};

TEST_P(WheelWithSprings, CyclicSpringsEqualTheWheelWithSprings) {
  const int nb = GetParam();
  const mesh::Mesh m = fe::annular_sector_mesh(small_sector(nb, 2));
  CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  const std::vector<double> open = cyclic_union(sector);
  // Springs as stiff as the plate's own diagonal: they change the spectrum at order one.
  const double k = Eigen::VectorXd(Eigen::MatrixXd(fe::assemble(m, kSteel, 1).K).diagonal()).maxCoeff();
  sector.set_interface(test_springs(m, k));
  const std::vector<double> stuck = cyclic_union(sector);
  const Eigen::VectorXd wheel = wheel_with_springs(m, sector.interface());
  ASSERT_EQ(static_cast<Eigen::Index>(stuck.size()), wheel.size());
  // Same bound as the open wheel above (dense eigenvalues carry ~1e-12 relative rounding).
  constexpr double kRelTol = 1e-8;
  const double worst = max_relative_frequency_difference(wheel, stuck, static_cast<int>(stuck.size()));
  EXPECT_LT(worst, kRelTol);
  // The springs matter: the lowest frequencies move by far more than the tolerance.
  EXPECT_GT(std::sqrt(stuck[0] / open[0]) - 1.0, 1e-3);
  std::printf("  Nb %d: springs move the first frequency by %.2f %%; wheel vs cyclic %.2e\n", nb,
              100 * (std::sqrt(stuck[0] / open[0]) - 1.0), worst);
  // Hermitian, K_{Nb-h} = conj(K_h), real for h = 0.
  for (int h = 0; h < nb; ++h) {
    const Eigen::MatrixXcd K(sector.reduce(h).K), Kc(sector.reduce((nb - h) % nb).K);
    EXPECT_LT((K - K.adjoint()).norm(), 1e-14 * K.norm()) << h;
    EXPECT_LT((Kc - K.conjugate()).norm(), 1e-14 * K.norm()) << h;
  }
  EXPECT_EQ((Eigen::MatrixXd(sector.reduce_real(0).K) - Eigen::MatrixXcd(sector.reduce(0).K).real()).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Wheels, WheelWithSprings, ::testing::Values(5, 6));

// Very stiff springs tie the node pairs: the spectrum tends to that of the wheel with the
// tied nodes merged (constraints applied directly), with an error that falls like 1 / k.
TEST(CyclicSector, StiffSpringsTendToTheTiedWheel) {
  const int nb = 5;
  const mesh::Mesh m = fe::annular_sector_mesh(small_sector(nb, 2));
  CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  const double kd = Eigen::VectorXd(Eigen::MatrixXd(fe::assemble(m, kSteel, 1).K).diagonal()).maxCoeff();
  std::vector<InterfaceSpring> springs = test_springs(m, 1.0);
  // The tied wheel: node b = (k+1, low) replaced by a = (k, high) in every element.
  const mesh::Mesh wheel = fe::replicate_wheel(m);
  std::vector<int> target(wheel.n_nodes());
  for (int v = 0; v < wheel.n_nodes(); ++v) target[v] = v;
  for (int k = 0; k < nb; ++k)
    for (const auto& s : springs) target[wheel_node(m, (k + 1) % nb, s.low_node)] = wheel_node(m, k, s.high_node);
  const auto kmw = fe::assemble(wheel, kSteel, 1);
  std::vector<bool> hub(wheel.n_nodes(), false);
  for (int v : wheel.node_set(mesh::kHub)) hub[v] = true;
  // Z: wheel DOFs -> independent DOFs (tied nodes share their target's columns).
  std::vector<int> column(wheel.n_dofs(), -1);
  int n_ind = 0;
  for (int v = 0; v < wheel.n_nodes(); ++v)
    if (target[v] == v && !hub[v])
      for (int c = 0; c < 3; ++c) column[3 * v + c] = n_ind++;
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(wheel.n_dofs(), n_ind);
  for (int v = 0; v < wheel.n_nodes(); ++v)
    for (int c = 0; c < 3; ++c)
      if (column[3 * target[v] + c] >= 0) Z(3 * v + c, column[3 * target[v] + c]) = 1.0;
  const Eigen::MatrixXd Kt = Z.transpose() * Eigen::MatrixXd(kmw.K) * Z,
                        Mt = Z.transpose() * Eigen::MatrixXd(kmw.M) * Z;
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kt, Mt, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd tied = es.eigenvalues();
  // Penalty error of the lowest 20 modes at k = 1e3 and 1e4 times the largest diagonal entry.
  constexpr int kModes = 20;
  double errors[2];
  for (int i = 0; i < 2; ++i) {
    for (auto& s : springs) s.stiffness = Eigen::Vector3d::Constant(kd * (i == 0 ? 1e3 : 1e4));
    sector.set_interface(springs);
    errors[i] = max_relative_frequency_difference(tied, cyclic_union(sector), kModes);
  }
  std::printf("  tied wheel vs stiff springs: %.2e (1e3 kd), %.2e (1e4 kd)\n", errors[0], errors[1]);
  EXPECT_LT(errors[1], 1e-4);
  // First order in 1 / k: ten times stiffer, about ten times closer (at least 5x).
  EXPECT_LT(errors[1], errors[0] / 5.0);
}

TEST(CyclicSector, InterfaceSpringsAreChecked) {
  const mesh::Mesh m = fe::annular_sector_mesh(small_sector(6, 1));
  CyclicSector sector(m, fe::assemble(m, kSteel, 1));
  std::vector<InterfaceSpring> bad(1);
  bad[0].high_node = 0, bad[0].low_node = m.n_nodes();
  EXPECT_THROW(sector.set_interface(bad), InputError);
  bad[0].low_node = 1, bad[0].stiffness = Eigen::Vector3d(1.0, -1.0, 1.0);
  EXPECT_THROW(sector.set_interface(bad), InputError);
  bad[0].stiffness = Eigen::Vector3d(1.0, std::nan(""), 1.0);
  EXPECT_THROW(sector.set_interface(bad), InputError);
}

}  // namespace
}  // namespace shroudsim::cyclic
