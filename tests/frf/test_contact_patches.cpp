// Contact patches on the shroud face (frf/contact_patches.hpp, docs/physics.md section 3):
// the partition and its weights, the patch's interpolation of the relative displacement and
// its force spreading, the limit of one pair per patch, and the stuck patch model against a
// direct FE solve with the patch springs in the stiffness.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cstring>
#include <numbers>
#include <set>

#include "../common/coarse_sector.hpp"
#include "cyclic/cyclic_sector.hpp"
#include "frf/contact_patches.hpp"
#include "frf/sector.hpp"
#include "modal/harmonic.hpp"

namespace shroudsim::frf {
namespace {

using Complex = std::complex<double>;

struct Fixture : testing_support::CoarseSector {
  std::vector<ShroudFaceNode> face;
  Fixture() : CoarseSector("patch", /*element_order=*/2) { face = shroud_face(mesh); }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

// Round-off of sums of a few hundred areas and weights.
constexpr double kRoundOff = 1e-12;

TEST(ContactPatches, PartitionCoversTheFaceAndWeightsSumToOne) {
  const Fixture& f = fixture();
  ASSERT_GE(f.face.size(), 10u);
  // The face area from the shroud_high triangles themselves (planar face: straight edges).
  double face_area = 0.0;
  const auto& tris = f.mesh.surface_triangles.at(mesh::kShroudHigh);
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const Eigen::Vector3d a = f.mesh.nodes.row(tris(t, 0)), b = f.mesh.nodes.row(tris(t, 1)),
                          c = f.mesh.nodes.row(tris(t, 2));
    face_area += 0.5 * (b - a).cross(c - a).norm();
  }
  for (int count : {1, 3, 7, 0}) {
    const auto patches = partition_face(f.mesh, f.face, count);
    EXPECT_EQ(patches.size(), count == 0 ? f.face.size() : static_cast<std::size_t>(count));
    std::multiset<int> seen;
    double total = 0.0;
    for (const auto& p : patches) {
      ASSERT_FALSE(p.members.empty()) << "every patch holds at least its seed";
      EXPECT_NE(std::find(p.members.begin(), p.members.end(), p.seed), p.members.end());
      double w = 0.0;
      for (double x : p.weights) w += x;
      EXPECT_NEAR(w, 1.0, kRoundOff) << "count " << count;
      EXPECT_NEAR(p.normal.norm(), 1.0, kRoundOff);
      total += p.area;
      seen.insert(p.members.begin(), p.members.end());
    }
    EXPECT_NEAR(total, face_area, kRoundOff * face_area) << "count " << count;
    EXPECT_EQ(seen.size(), f.face.size());
    EXPECT_EQ(std::set<int>(seen.begin(), seen.end()).size(), f.face.size()) << "each face pair in one patch";
  }
  EXPECT_THROW(partition_face(f.mesh, f.face, static_cast<int>(f.face.size()) + 1), std::invalid_argument);
}

TEST(ContactPatches, UniformRelativeDisplacementIsThePatchDisplacement) {
  const Fixture& f = fixture();
  const auto patches = partition_face(f.mesh, f.face, 4);
  const auto pairs = contact_pairs(f.mesh, f.face, patches, ContactDiscretization::patches, 0.3);
  const Eigen::Vector3d a(1.0, -2.0, 0.5), b(0.25, 0.75, -1.5);
  const double alpha = 2.0 * std::numbers::pi / f.mesh.sectors;
  for (int h : {0, 1, 3}) {
    // Every shroud_high node moves by a, every shroud_low node by b.
    Eigen::VectorXcd u = Eigen::VectorXcd::Zero(f.sector->n_full());
    for (const auto& n : f.face) {
      u.segment<3>(3 * n.high) = a.cast<Complex>();
      u.segment<3>(3 * n.low) = b.cast<Complex>();
    }
    const Eigen::VectorXcd w = contact_rows(pairs, *f.sector, h, f.sector->n_full()) * u;
    const Eigen::Vector3cd rel =
        a.cast<Complex>() - std::exp(Complex(0.0, h * alpha)) * (cyclic::rotation_z(alpha) * b).cast<Complex>();
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      ASSERT_GT(pairs[i].patch.size(), 1u);
      const Eigen::Vector3cd expected = pairs[i].frame.cast<Complex>() * rel;
      EXPECT_LT((w.segment<3>(3 * static_cast<Eigen::Index>(i)) - expected).norm(), kRoundOff * expected.norm())
          << "patch " << i << ", h " << h;
    }
  }
}

TEST(ContactPatches, RigidTranslationOfOneSideGivesTheTotalSpringForce) {
  const Fixture& f = fixture();
  const auto patches = partition_face(f.mesh, f.face, 5);
  const auto pairs = contact_pairs(f.mesh, f.face, patches, ContactDiscretization::patches, 0.0);
  double total_area = 0.0;
  for (const auto& p : patches) total_area += p.area;
  const double kt = 3e6, kn = 7e6;
  // Stuck springs of every patch, kt A_P / A and kn A_P / A in its frame.
  std::vector<Eigen::Triplet<double>> kt_list;
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const double s = patches[i].area / total_area;
    for (int a = 0; a < 3; ++a) kt_list.emplace_back(3 * i + a, 3 * i + a, (a < 2 ? kt : kn) * s);
  }
  Eigen::SparseMatrix<double> kc(3 * patches.size(), 3 * patches.size());
  kc.setFromTriplets(kt_list.begin(), kt_list.end());
  const Eigen::SparseMatrix<double> b = contact_rows(pairs, *f.sector, 0, f.sector->n_full()).real();
  const Eigen::Vector3d d(2e-6, -1e-6, 3e-6);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(f.sector->n_full());
  for (const auto& n : f.face) u.segment<3>(3 * n.high) = d;
  // Nodal forces of the springs: f = B^T Kc B u, spread back with the transposed weights.
  const Eigen::VectorXd force = b.transpose() * (kc * (b * u));
  Eigen::Vector3d on_high = Eigen::Vector3d::Zero(), on_low = Eigen::Vector3d::Zero();
  for (const auto& n : f.face) on_high += force.segment<3>(3 * n.high), on_low += force.segment<3>(3 * n.low);
  Eigen::Vector3d expected = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const double s = patches[i].area / total_area;
    const Eigen::Matrix3d& l = pairs[i].frame;
    expected += l.transpose() * Eigen::Vector3d(kt * s, kt * s, kn * s).asDiagonal() * l * d;
  }
  EXPECT_LT((on_high - expected).norm(), kRoundOff * expected.norm());
  // The low side feels the reaction, rotated back into the reference sector: R^T (-F).
  const Eigen::Matrix3d rot = cyclic::rotation_z(2.0 * std::numbers::pi / f.mesh.sectors);
  EXPECT_LT((on_low + rot.transpose() * expected).norm(), kRoundOff * expected.norm());
  // Virtual work: u . f = sum_P W_P . K_P W_P.
  const Eigen::VectorXd w = b * u;
  EXPECT_NEAR(u.dot(force), w.dot(kc * w), kRoundOff * w.dot(kc * w));
}

TEST(ContactPatches, OnePairPerPatchIsTheNodeFormBitForBit) {
  const Fixture& f = fixture();
  const auto all = partition_face(f.mesh, f.face, 0);
  const auto patch_pairs = contact_pairs(f.mesh, f.face, all, ContactDiscretization::patches, 0.4);
  const auto node_pairs = contact_pairs(f.mesh, f.face, all, ContactDiscretization::nodes, 0.4);
  ASSERT_EQ(patch_pairs.size(), node_pairs.size());
  for (std::size_t i = 0; i < patch_pairs.size(); ++i) {
    EXPECT_EQ(patch_pairs[i].high_node, node_pairs[i].high_node);
    EXPECT_EQ(patch_pairs[i].low_node, node_pairs[i].low_node);
    EXPECT_TRUE(patch_pairs[i].patch.empty());
    EXPECT_EQ(std::memcmp(patch_pairs[i].frame.data(), node_pairs[i].frame.data(), sizeof(double) * 9), 0);
  }
  for (int h : {0, 2}) {
    const Eigen::SparseMatrix<Complex> a = contact_rows(patch_pairs, *f.sector, h, f.sector->n_full());
    // The node form through an explicit single-member patch of weight 1.
    std::vector<SectorContactPair> weighted = node_pairs;
    for (auto& p : weighted) p.patch = {{p.high_node, p.low_node, 1.0}};
    const Eigen::SparseMatrix<Complex> c = contact_rows(weighted, *f.sector, h, f.sector->n_full());
    ASSERT_EQ(a.nonZeros(), c.nonZeros());
    EXPECT_EQ(std::memcmp(a.valuePtr(), c.valuePtr(), sizeof(Complex) * static_cast<std::size_t>(a.nonZeros())), 0);
    EXPECT_EQ(std::memcmp(a.innerIndexPtr(), c.innerIndexPtr(), sizeof(int) * static_cast<std::size_t>(a.nonZeros())),
              0);
  }
  // In the node form a patch acts at its seed only.
  const auto five = partition_face(f.mesh, f.face, 5);
  for (const auto& p : contact_pairs(f.mesh, f.face, five, ContactDiscretization::nodes, 0.0))
    EXPECT_TRUE(p.patch.empty());
}

TEST(ContactPatches, StuckPatchesThroughTheReceptancesEqualTheFESolveWithPatchSprings) {
  const Fixture& f = fixture();
  const auto patches = partition_face(f.mesh, f.face, 3);
  const auto pairs = contact_pairs(f.mesh, f.face, patches, ContactDiscretization::patches, 0.2);
  SectorForcing forcing;
  forcing.engine_order = 0;  // harmonic index 0: the static system, where the direct solve is exact
  forcing.excitation_node = f.mesh.n_nodes() / 2;
  forcing.response_node = f.mesh.n_nodes() / 3;
  const auto& hub = f.mesh.node_set("hub");
  for (int node : {forcing.excitation_node, forcing.response_node})
    ASSERT_EQ(std::find(hub.begin(), hub.end(), node), hub.end()) << "a node that moves";
  forcing.force = Eigen::Vector3d(1.0, -0.5, 0.25);
  forcing.damping_ratio = 0.0;
  forcing.residual_flexibility = true;
  modal::ModalOptions mo;
  mo.modes = 20;
  auto r = modal::solve_harmonic(*f.sector, 0, mo);
  ASSERT_TRUE(r.report.ok()) << r.report.message;
  std::map<int, modal::ModalBasis> bases{{0, r.basis}};
  const SectorLinearPart part(
      *f.sector, bases, [&](int h) { return modal::factor_harmonic_stiffness(*f.sector, h); }, pairs, forcing, 1);
  // Far below the first mode the receptance is the static flexibility (modes + residual
  // flexibility) up to (w / w_1)^2 of the modal part: 1e-6 here.
  const double w = 1e-3 * r.basis.omega[0];
  HarmonicReceptance rec;
  part.harmonic(1, w, rec);
  const double kt = 4e7, kn = 9e7;
  double total = 0.0;
  for (const auto& p : patches) total += p.area;
  Eigen::VectorXcd kdiag(3 * patches.size());
  for (std::size_t i = 0; i < patches.size(); ++i)
    for (int a = 0; a < 3; ++a) kdiag[3 * i + a] = (a < 2 ? kt : kn) * patches[i].area / total;
  const Eigen::MatrixXcd kc = kdiag.asDiagonal();
  const Eigen::Index c = rec.G.rows();
  const Eigen::VectorXcd wc = (Eigen::MatrixXcd::Identity(c, c) + rec.G * kc).lu().solve(rec.w_lin);
  const Eigen::VectorXcd u_patch = rec.u_lin - rec.H * (kc * wc);

  // Direct: (K_0 + B^H Kc B) u = f in the reduced coordinates of h = 0.
  const auto kmh = f.sector->reduce(0);
  const Eigen::SparseMatrix<Complex> t = f.sector->expansion(0);
  const Eigen::SparseMatrix<Complex> b = contact_rows(pairs, *f.sector, 0, f.sector->n_full()) * t;
  const Eigen::SparseMatrix<Complex> kcs = kc.sparseView();
  Eigen::SparseMatrix<Complex> a = kmh.K - w * w * kmh.M;
  a += Eigen::SparseMatrix<Complex>(b.adjoint() * kcs * b);
  a.makeCompressed();
  Eigen::VectorXcd load = Eigen::VectorXcd::Zero(f.sector->n_full());
  load.segment<3>(3 * forcing.excitation_node) = forcing.force.cast<Complex>();
  Eigen::SparseLU<Eigen::SparseMatrix<Complex>> lu(a);
  ASSERT_EQ(lu.info(), Eigen::Success);
  const Eigen::VectorXcd u = t * lu.solve(Eigen::VectorXcd(t.adjoint() * load));
  const Eigen::Vector3cd u_direct = u.segment<3>(3 * forcing.response_node);
  // The patch springs matter here: the response without them differs by far more.
  EXPECT_GT((rec.u_lin - u_direct).norm(), 1e-2 * u_direct.norm());
  constexpr double kStatic = 1e-6;  // (w / w_1)^2 above
  EXPECT_LT((u_patch - u_direct).norm(), kStatic * u_direct.norm());
  EXPECT_LT((wc - b * lu.solve(Eigen::VectorXcd(t.adjoint() * load))).norm(), kStatic * wc.norm());
}

}  // namespace
}  // namespace shroudsim::frf
