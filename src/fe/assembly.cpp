#include "fe/assembly.hpp"

#include <algorithm>
#include <atomic>
#include <thread>

#include "core/error.hpp"

namespace shroudsim::fe {

Assembler::Assembler(const mesh::Mesh& mesh) : mesh_(&mesh) {
  const int npe = mesh.nodes_per_element();
  SHROUDSIM_CHECK(npe == 4 || npe == 10, "Assembler: tets must have 4 or 10 nodes");
  const int n_nodes = mesh.n_nodes();
  // Node adjacency through elements (each node is its own neighbour), as sorted CSR lists.
  std::vector<std::vector<int>> adj(n_nodes);
  for (int e = 0; e < mesh.n_elements(); ++e) {
    for (int a = 0; a < npe; ++a) {
      const int na = mesh.tets(e, a);
      SHROUDSIM_CHECK(na >= 0 && na < n_nodes, "Assembler: element node index out of range");
      for (int b = 0; b < npe; ++b) adj[na].push_back(mesh.tets(e, b));
    }
  }
  adjacency_offsets_.assign(n_nodes + 1, 0);
  for (int n = 0; n < n_nodes; ++n) {
    auto& v = adj[n];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    adjacency_offsets_[n + 1] = adjacency_offsets_[n] + static_cast<int>(v.size());
  }
  adjacency_.reserve(adjacency_offsets_.back());
  for (auto& v : adj) {
    adjacency_.insert(adjacency_.end(), v.begin(), v.end());
    std::vector<int>().swap(v);
  }
  // Column 3b+c holds rows 3a+i for every neighbour a of b (sorted), i = 0..2.
  const Eigen::Index n_dofs = 3 * static_cast<Eigen::Index>(n_nodes);
  const Eigen::Index nnz = 9 * static_cast<Eigen::Index>(adjacency_.size());
  SHROUDSIM_CHECK(nnz < (Eigen::Index{1} << 31), "Assembler: more than 2^31 stored entries");
  pattern_.resize(n_dofs, n_dofs);
  pattern_.resizeNonZeros(nnz);
  int* outer = pattern_.outerIndexPtr();
  int* inner = pattern_.innerIndexPtr();
  int pos = 0;
  for (int b = 0; b < n_nodes; ++b) {
    for (int c = 0; c < 3; ++c) {
      outer[3 * b + c] = pos;
      for (int k = adjacency_offsets_[b]; k < adjacency_offsets_[b + 1]; ++k)
        for (int i = 0; i < 3; ++i) inner[pos++] = 3 * adjacency_[k] + i;
    }
  }
  outer[n_dofs] = pos;
  std::fill(pattern_.valuePtr(), pattern_.valuePtr() + nnz, 0.0);
}

int Assembler::position(int row_node, int col_node) const {
  const int* begin = adjacency_.data() + adjacency_offsets_[col_node];
  const int* end = adjacency_.data() + adjacency_offsets_[col_node + 1];
  return static_cast<int>(std::lower_bound(begin, end, row_node) - begin);
}

template <int NPE>
void Assembler::assemble_range(const Material& material, int begin, int end, double* kv, double* mv,
                               int* bad_element) const {
  const mesh::Mesh& mesh = *mesh_;
  const int* outer = pattern_.outerIndexPtr();
  ElementNodes<NPE> X;
  ElementMatrix<NPE> Ke, Me;
  for (int e = begin; e < end; ++e) {
    for (int a = 0; a < NPE; ++a) X.row(a) = mesh.nodes.row(mesh.tets(e, a));
    if (!tet_matrices<NPE>(X, material, Ke, Me)) {
      *bad_element = e;
      return;
    }
    for (int b = 0; b < NPE; ++b) {
      const int nb = mesh.tets(e, b);
      for (int a = 0; a < NPE; ++a) {
        const int na = mesh.tets(e, a);
        const int offset = 3 * position(na, nb);
        for (int j = 0; j < 3; ++j) {
          const int base = outer[3 * nb + j] + offset;
          for (int i = 0; i < 3; ++i) {
            kv[base + i] += Ke(3 * a + i, 3 * b + j);
            mv[base + i] += Me(3 * a + i, 3 * b + j);
          }
        }
      }
    }
  }
}

namespace {
// Slices of the parallel assembly: at least this many elements each, and at most kMaxSlices
// (each slice past the first holds a copy of the K and M values: 2 nnz doubles).
constexpr int kElementsPerSlice = 500;
constexpr int kMaxSlices = 2;
}  // namespace

linalg::SparsePair<double> Assembler::assemble(const Material& material, int threads) const {
  SHROUDSIM_CHECK(material.valid(), "Assembler::assemble: invalid material");
  const mesh::Mesh& mesh = *mesh_;
  linalg::SparsePair<double> km{pattern_, pattern_};
  const int n_el = mesh.n_elements();
  // The elements are split into a number of slices that depends on the mesh only, each
  // scattered into its own value arrays (no locks; slice 0 into km itself) and the slices summed
  // in order, so K and M are the same to the last bit whatever the thread count (the threads
  // only share out the slices). Summing per thread instead made K differ in round-off between
  // --threads 1 and 2 from 1,000 elements on, and with it the path of every curve traced on the
  // sector (docs/continuation.md, "Determinism").
  const int n_slices = std::clamp(n_el / kElementsPerSlice, 1, kMaxSlices);
  int n_threads = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  n_threads = std::clamp(n_threads, 1, n_slices);
  std::vector<std::vector<double>> k_extra(n_slices - 1), m_extra(n_slices - 1);
  std::vector<int> bad(n_slices, -1);
  auto slice = [&](int t) {
    const int begin = static_cast<int>(static_cast<long>(n_el) * t / n_slices);
    const int end = static_cast<int>(static_cast<long>(n_el) * (t + 1) / n_slices);
    double* kv = km.K.valuePtr();
    double* mv = km.M.valuePtr();
    if (t > 0) {
      k_extra[t - 1].assign(pattern_.nonZeros(), 0.0);
      m_extra[t - 1].assign(pattern_.nonZeros(), 0.0);
      kv = k_extra[t - 1].data();
      mv = m_extra[t - 1].data();
    }
    if (mesh.nodes_per_element() == 4) assemble_range<4>(material, begin, end, kv, mv, &bad[t]);
    else assemble_range<10>(material, begin, end, kv, mv, &bad[t]);
  };
  // Thread t takes slices t, t + n_threads, ...
  auto run = [&](int t) {
    for (int k = t; k < n_slices; k += n_threads) slice(k);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n_threads; ++t) pool.emplace_back(run, t);
  run(0);
  for (auto& th : pool) th.join();
  for (int t = 0; t < n_slices; ++t) {
    if (bad[t] >= 0)
      throw InputError("mesh: element " + std::to_string(bad[t]) +
                       " is inverted or degenerate (Jacobian determinant <= 0)");
  }
  for (int t = 1; t < n_slices; ++t) {
    Eigen::Map<Eigen::VectorXd>(km.K.valuePtr(), pattern_.nonZeros()) +=
        Eigen::Map<const Eigen::VectorXd>(k_extra[t - 1].data(), pattern_.nonZeros());
    Eigen::Map<Eigen::VectorXd>(km.M.valuePtr(), pattern_.nonZeros()) +=
        Eigen::Map<const Eigen::VectorXd>(m_extra[t - 1].data(), pattern_.nonZeros());
  }
  return km;
}

linalg::SparsePair<double> assemble(const mesh::Mesh& mesh, const Material& material, int threads) {
  return Assembler(mesh).assemble(material, threads);
}

std::vector<int> node_dofs(const std::vector<int>& nodes) {
  std::vector<int> dofs;
  dofs.reserve(3 * nodes.size());
  for (int n : nodes)
    for (int c = 0; c < 3; ++c) dofs.push_back(3 * n + c);
  std::sort(dofs.begin(), dofs.end());
  dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
  return dofs;
}

std::vector<int> free_dofs(int n_dofs, const std::vector<int>& fixed) {
  std::vector<char> is_fixed(n_dofs, 0);
  for (int d : fixed) {
    SHROUDSIM_CHECK(d >= 0 && d < n_dofs, "free_dofs: DOF out of range");
    is_fixed[d] = 1;
  }
  std::vector<int> free;
  for (int d = 0; d < n_dofs; ++d)
    if (!is_fixed[d]) free.push_back(d);
  return free;
}

linalg::SparseMatrixD restrict(const linalg::SparseMatrixD& A, const std::vector<int>& dofs) {
  SHROUDSIM_CHECK(std::is_sorted(dofs.begin(), dofs.end()), "restrict: DOFs must be ascending");
  std::vector<int> new_index(A.rows(), -1);
  for (std::size_t k = 0; k < dofs.size(); ++k) new_index[dofs[k]] = static_cast<int>(k);
  // Kept rows stay in ascending order, so each kept column is copied in place.
  const auto n = static_cast<Eigen::Index>(dofs.size());
  linalg::SparseMatrixD R(n, n);
  Eigen::Index nnz = 0;
  for (int d : dofs)
    for (linalg::SparseMatrixD::InnerIterator it(A, d); it; ++it) nnz += new_index[it.row()] >= 0;
  R.resizeNonZeros(nnz);
  int pos = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    R.outerIndexPtr()[k] = pos;
    for (linalg::SparseMatrixD::InnerIterator it(A, dofs[k]); it; ++it) {
      const int r = new_index[it.row()];
      if (r < 0) continue;
      R.innerIndexPtr()[pos] = r;
      R.valuePtr()[pos++] = it.value();
    }
  }
  R.outerIndexPtr()[n] = pos;
  return R;
}

double meshed_volume(const mesh::Mesh& mesh) {
  double v = 0.0;
  for (int e = 0; e < mesh.n_elements(); ++e) {
    v += tet_volume(mesh.nodes.row(mesh.tets(e, 0)).transpose(), mesh.nodes.row(mesh.tets(e, 1)).transpose(),
                    mesh.nodes.row(mesh.tets(e, 2)).transpose(), mesh.nodes.row(mesh.tets(e, 3)).transpose());
  }
  return v;
}

}  // namespace shroudsim::fe
