#include "cyclic/cyclic_sector.hpp"
#include "mesh/checks.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "fe/assembly.hpp"

namespace shroudsim::cyclic {

using linalg::Complex;
using linalg::SparseMatrixC;
using linalg::SparseMatrixD;

Eigen::Matrix3d rotation_z(double angle) { return mesh::rotation_z(angle); }

int nodal_diameter(int h, int sectors) {
  const int m = ((h % sectors) + sectors) % sectors;
  return std::min(m, sectors - m);
}

int canonical_index(int h, int sectors) { return nodal_diameter(h, sectors); }  // the same number

CyclicSector::CyclicSector(const mesh::Mesh& mesh, const linalg::SparsePair<double>& km)
    : sectors_(mesh.sectors), n_full_(mesh.n_dofs()) {
  SHROUDSIM_CHECK(sectors_ >= 1, "CyclicSector: mesh.sectors must be >= 1");
  SHROUDSIM_CHECK(km.K.rows() == n_full_ && km.M.rows() == n_full_, "CyclicSector: matrices do not match the mesh");
  const int n_nodes = mesh.n_nodes();
  const double alpha = 2.0 * std::numbers::pi / sectors_;
  const Eigen::Matrix3d R = rotation_z(alpha);

  // Pairing, with the geometric check x_q = R x_p.
  const double size = (mesh.nodes.colwise().maxCoeff() - mesh.nodes.colwise().minCoeff()).norm();
  constexpr double kMatchTol = 1e-6;  // relative to the mesh size; gmsh writes ~16 digits
  std::vector<int> high_partner(n_nodes, -1), low_partner(n_nodes, -1);
  for (const auto& [p, q] : mesh.cyclic_pairs) {
    if (p < 0 || q < 0 || p >= n_nodes || q >= n_nodes || p == q || high_partner[p] >= 0 || low_partner[q] >= 0 ||
        low_partner[p] >= 0 || high_partner[q] >= 0)
      throw InputError("mesh: cyclic pair (" + std::to_string(p) + ", " + std::to_string(q) +
                       ") is invalid or uses a node twice");
    const Eigen::Vector3d xp = mesh.nodes.row(p).transpose(), xq = mesh.nodes.row(q).transpose();
    if ((xq - R * xp).norm() > kMatchTol * size)
      throw InputError("mesh: cyclic_high node " + std::to_string(q) + " is not cyclic_low node " + std::to_string(p) +
                       " rotated by 360/" + std::to_string(sectors_) + " degrees about z");
    high_partner[p] = q;
    low_partner[q] = p;
  }
  // Clamped nodes: hub, and the cyclic partners of hub nodes.
  std::vector<char> clamped(n_nodes, 0);
  if (auto it = mesh.node_sets.find(mesh::kHub); it != mesh.node_sets.end())
    for (int v : it->second) clamped[v] = 1;
  for (int v = 0; v < n_nodes; ++v) {
    if (!clamped[v]) continue;
    if (high_partner[v] >= 0) clamped[high_partner[v]] = 1;
    if (low_partner[v] >= 0) clamped[low_partner[v]] = 1;
  }
  std::vector<int> reduced_of(n_full_, -1);
  for (int v = 0; v < n_nodes; ++v) {
    for (int c = 0; c < 3; ++c) {
      if (clamped[v]) {
        clamped_dofs_.push_back(3 * v + c);
      } else if (low_partner[v] < 0) {
        reduced_of[3 * v + c] = static_cast<int>(reduced_to_full_.size());
        reduced_to_full_.push_back(3 * v + c);
      }
    }
  }
  const auto n_r = static_cast<Eigen::Index>(reduced_to_full_.size());
  std::vector<Eigen::Triplet<double>> tp, tg;
  for (Eigen::Index j = 0; j < n_r; ++j) tp.emplace_back(reduced_to_full_[j], static_cast<int>(j), 1.0);
  for (int q = 0; q < n_nodes; ++q) {
    const int p = low_partner[q];
    if (p < 0 || clamped[q]) continue;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (R(i, j) != 0.0) tg.emplace_back(3 * q + i, reduced_of[3 * p + j], R(i, j));
  }
  P_.resize(n_full_, n_r);
  P_.setFromTriplets(tp.begin(), tp.end());
  G_.resize(n_full_, n_r);
  G_.setFromTriplets(tg.begin(), tg.end());

  auto split = [&](const SparseMatrixD& K, SparseMatrixD& A, SparseMatrixD& B) {
    const SparseMatrixD KG = K * G_;
    const SparseMatrixD GtKG = SparseMatrixD(G_.transpose()) * KG;
    A = fe::restrict(K, reduced_to_full_) + GtKG;
    B = SparseMatrixD(P_.transpose()) * KG;
  };
  split(km.K, KA_, KB_);
  split(km.M, MA_, MB_);
}

void CyclicSector::check_h(int h) const {
  SHROUDSIM_CHECK(h >= 0 && h < sectors_, "CyclicSector: harmonic index out of range 0..Nb-1");
}

bool CyclicSector::is_real(int h) const {
  check_h(h);
  return h == 0 || 2 * h == sectors_;
}

Complex CyclicSector::phase(int h) const {
  check_h(h);
  if (h == 0) return 1.0;
  if (2 * h == sectors_) return -1.0;
  return std::polar(1.0, 2.0 * std::numbers::pi * h / sectors_);
}

namespace {
SparseMatrixC combine(const SparseMatrixD& A, const SparseMatrixD& B, Complex e) {
  const SparseMatrixD Bt = B.transpose();
  SparseMatrixC out = A.cast<Complex>() + B.cast<Complex>() * e + Bt.cast<Complex>() * std::conj(e);
  out.makeCompressed();
  return out;
}
}  // namespace

void CyclicSector::set_interface(std::vector<InterfaceSpring> springs) {
  const Eigen::Index n_nodes = n_full_ / 3;
  for (const auto& s : springs) {
    if (s.high_node < 0 || s.high_node >= n_nodes || s.low_node < 0 || s.low_node >= n_nodes)
      throw InputError("interface spring: node out of range");
    if (!s.stiffness.allFinite() || (s.stiffness.array() < 0).any() || !s.frame.allFinite())
      throw InputError("interface spring: stiffness must be finite and >= 0, frame finite");
  }
  springs_ = std::move(springs);
}

void CyclicSector::add_relative_rows(std::vector<Eigen::Triplet<Complex>>& t, int row, const Eigen::Matrix3d& frame,
                                     int high_node, int low_node, double weight, int h) const {
  const Complex e = phase(h);
  const Eigen::Matrix3d LR = frame * rotation_z(2.0 * std::numbers::pi / sectors_);
  for (int a = 0; a < 3; ++a)
    for (int j = 0; j < 3; ++j) {
      t.emplace_back(row + a, 3 * high_node + j, weight * frame(a, j));  // 1.0 * x == x: a node pair exactly
      t.emplace_back(row + a, 3 * low_node + j, -e * (weight * LR(a, j)));
    }
}

SparseMatrixC CyclicSector::interface_rows(int h, const std::vector<InterfaceSpring>& springs) const {
  std::vector<Eigen::Triplet<Complex>> t;
  t.reserve(springs.size() * 18);
  for (std::size_t i = 0; i < springs.size(); ++i)
    add_relative_rows(t, static_cast<int>(3 * i), springs[i].frame, springs[i].high_node, springs[i].low_node, 1.0, h);
  SparseMatrixC S(static_cast<Eigen::Index>(3 * springs.size()), n_full_);
  S.setFromTriplets(t.begin(), t.end());  // a spring from a node to itself sums its entries
  return S;
}

SparseMatrixC CyclicSector::interface_stiffness(int h) const {
  if (springs_.empty()) return {};
  const SparseMatrixC Y = interface_rows(h) * expansion(h);
  Eigen::VectorXcd k(Y.rows());
  for (std::size_t i = 0; i < springs_.size(); ++i)
    for (int a = 0; a < 3; ++a) k[static_cast<Eigen::Index>(3 * i) + a] = springs_[i].stiffness[a];
  const SparseMatrixC kY = k.asDiagonal() * Y;
  SparseMatrixC out = SparseMatrixC(Y.adjoint()) * kY;
  // Exactly Hermitian (the product's two triangles are summed in different orders).
  const SparseMatrixC outH = out.adjoint();
  out = 0.5 * (out + outH);
  out.makeCompressed();
  return out;
}

linalg::SparsePair<Complex> CyclicSector::reduce(int h) const {
  const Complex e = phase(h);
  linalg::SparsePair<Complex> out{combine(KA_, KB_, e), combine(MA_, MB_, e)};
  if (!springs_.empty()) {
    out.K = out.K + interface_stiffness(h);
    out.K.makeCompressed();
  }
  return out;
}

linalg::SparsePair<double> CyclicSector::reduce_real(int h) const {
  SHROUDSIM_CHECK(is_real(h), "CyclicSector::reduce_real: h must be 0 or Nb/2");
  const double s = phase(h).real();
  auto combine_real = [s](const SparseMatrixD& A, const SparseMatrixD& B) {
    const SparseMatrixD Bt = B.transpose();
    SparseMatrixD out = A + s * (B + Bt);
    out.makeCompressed();
    return out;
  };
  linalg::SparsePair<double> out{combine_real(KA_, KB_), combine_real(MA_, MB_)};
  if (!springs_.empty()) {
    out.K = out.K + SparseMatrixD(interface_stiffness(h).real());
    out.K.makeCompressed();
  }
  return out;
}

SparseMatrixC CyclicSector::expansion(int h) const {
  SparseMatrixC T = P_.cast<Complex>() + G_.cast<Complex>() * phase(h);
  T.makeCompressed();
  return T;
}

Eigen::MatrixXcd CyclicSector::expand(int h, const Eigen::MatrixXcd& u_reduced) const {
  SHROUDSIM_CHECK(u_reduced.rows() == n_reduced(), "CyclicSector::expand: wrong number of rows");
  return expansion(h) * u_reduced;
}

}  // namespace shroudsim::cyclic
