#include "cyclic/cyclic_sector.hpp"
#include "mesh/checks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

namespace {

// The entries of A, B and B^T (compressed, column-major) in column j, merged by row: calls
// f(row, a, b, bt) once per row stored in any of them, in ascending row order, with a null
// pointer for an operand that has no entry there.
template <typename F>
void merge_column(const SparseMatrixD& A, const SparseMatrixD& B, const SparseMatrixD& Bt, Eigen::Index j, F&& f) {
  const int* ai = A.innerIndexPtr();
  const int* bi = B.innerIndexPtr();
  const int* ti = Bt.innerIndexPtr();
  const double* av = A.valuePtr();
  const double* bv = B.valuePtr();
  const double* tv = Bt.valuePtr();
  int pa = A.outerIndexPtr()[j], pb = B.outerIndexPtr()[j], pt = Bt.outerIndexPtr()[j];
  const int ea = A.outerIndexPtr()[j + 1], eb = B.outerIndexPtr()[j + 1], et = Bt.outerIndexPtr()[j + 1];
  constexpr int kEnd = std::numeric_limits<int>::max();
  while (pa < ea || pb < eb || pt < et) {
    const int ra = pa < ea ? ai[pa] : kEnd, rb = pb < eb ? bi[pb] : kEnd, rt = pt < et ? ti[pt] : kEnd;
    const int r = std::min({ra, rb, rt});
    f(r, ra == r ? &av[pa++] : nullptr, rb == r ? &bv[pb++] : nullptr, rt == r ? &tv[pt++] : nullptr);
  }
}

// A matrix with the pattern of A + B + B^T (outer: its column starts, from union_pattern)
// and the value value(a, b, bt) at each entry. One pass and one allocation: the sum as an
// Eigen expression grew its storage as it went, and that regrowth (reallocation, copying and
// fresh pages) was a fifth of the cyclic reduction's time at 40k DOFs.
template <typename T, typename Value>
Eigen::SparseMatrix<T> combine(const SparseMatrixD& A, const SparseMatrixD& B, const SparseMatrixD& Bt,
                               const std::vector<int>& outer, Value&& value) {
  const Eigen::Index n = A.rows();
  Eigen::SparseMatrix<T> out(n, A.cols());
  out.resizeNonZeros(outer.back());
  std::copy(outer.begin(), outer.end(), out.outerIndexPtr());
  int* inner = out.innerIndexPtr();
  T* values = out.valuePtr();
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    int k = outer[static_cast<std::size_t>(j)];
    merge_column(A, B, Bt, j, [&](int r, const double* a, const double* b, const double* bt) {
      inner[k] = r;
      values[k++] = value(a, b, bt);
    });
  }
  return out;
}

// The column starts of A + B + B^T.
std::vector<int> union_pattern(const SparseMatrixD& A, const SparseMatrixD& B, const SparseMatrixD& Bt) {
  std::vector<int> outer(static_cast<std::size_t>(A.cols()) + 1, 0);
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    int count = 0;
    merge_column(A, B, Bt, j, [&](int, const double*, const double*, const double*) { ++count; });
    outer[static_cast<std::size_t>(j) + 1] = outer[static_cast<std::size_t>(j)] + count;
  }
  return outer;
}

// A + e B + conj(e) B^T, entry by entry as the Eigen expression
// A.cast<Complex>() + B.cast<Complex>() * e + Bt.cast<Complex>() * conj(e) evaluates it (the
// reduction before this one-pass form; the same bits): an operand without an entry counts
// as Complex(0), and the sums run left to right.
SparseMatrixC combine_complex(const SparseMatrixD& A, const SparseMatrixD& B, const SparseMatrixD& Bt,
                              const std::vector<int>& outer, Complex e) {
  const Complex ec = std::conj(e), zero(0.0, 0.0);
  return combine<Complex>(A, B, Bt, outer, [&](const double* a, const double* b, const double* bt) {
    const Complex ca = a ? Complex(*a) : zero, cb = b ? Complex(*b) * e : zero, ct = bt ? Complex(*bt) * ec : zero;
    return (ca + cb) + ct;
  });
}

// A + s (B + B^T), s = +-1, as the Eigen expression A + s * (B + Bt) evaluates it.
SparseMatrixD combine_real(const SparseMatrixD& A, const SparseMatrixD& B, const SparseMatrixD& Bt,
                           const std::vector<int>& outer, double s) {
  return combine<double>(A, B, Bt, outer, [&](const double* a, const double* b, const double* bt) {
    const double sym = b || bt ? s * ((b ? *b : 0.0) + (bt ? *bt : 0.0)) : 0.0;
    return (a ? *a : 0.0) + sym;
  });
}

}  // namespace

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
  for (SparseMatrixD* m : {&KA_, &KB_, &MA_, &MB_}) m->makeCompressed();
  KBt_ = KB_.transpose();
  MBt_ = MB_.transpose();
  K_outer_ = union_pattern(KA_, KB_, KBt_);
  M_outer_ = union_pattern(MA_, MB_, MBt_);
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
  linalg::SparsePair<Complex> out{combine_complex(KA_, KB_, KBt_, K_outer_, e),
                                  combine_complex(MA_, MB_, MBt_, M_outer_, e)};
  if (!springs_.empty()) {
    out.K = out.K + interface_stiffness(h);
    out.K.makeCompressed();
  }
  return out;
}

linalg::SparsePair<double> CyclicSector::reduce_real(int h) const {
  SHROUDSIM_CHECK(is_real(h), "CyclicSector::reduce_real: h must be 0 or Nb/2");
  const double s = phase(h).real();
  linalg::SparsePair<double> out{combine_real(KA_, KB_, KBt_, K_outer_, s), combine_real(MA_, MB_, MBt_, M_outer_, s)};
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
