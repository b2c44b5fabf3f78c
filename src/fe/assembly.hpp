#pragma once
// Sparse assembly of the sector's stiffness and consistent mass matrices.
//
// DOF numbering: dof = 3 * node + component (x, y, z), over all mesh nodes; nothing is
// clamped here (the free stiffness has the six rigid-body modes in its null space).
// Clamping is a restriction to the free DOFs (restrict(), or the cyclic reduction, which
// drops the `hub` DOFs). K and M share one sparsity pattern, built once per mesh and stored
// in full (both triangles), so that factorizations and reductions can reuse it.
//
// Usage:
//   fe::Assembler assembler(mesh);                      // pattern (mesh not owned, must outlive)
//   linalg::SparsePair<double> km = assembler.assemble(material);
//   auto free = fe::free_dofs(mesh.n_dofs(), fe::node_dofs(mesh.node_set("hub")));
//   linalg::SparseMatrixD Kc = fe::restrict(km.K, free);
#include <vector>

#include "fe/tet_element.hpp"
#include "linalg/sparse.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::fe {

class Assembler {
 public:
  /// Builds the node adjacency and the DOF sparsity pattern of `mesh` (4- or 10-node tets).
  explicit Assembler(const mesh::Mesh& mesh);

  /// K [N/m] and M [kg] on all 3 * n_nodes DOFs. Throws InputError naming the element if an
  /// element is inverted or degenerate. Uses up to `threads` threads (0: hardware).
  linalg::SparsePair<double> assemble(const Material& material, int threads = 0) const;

  Eigen::Index n_dofs() const { return pattern_.rows(); }
  Eigen::Index nonzeros() const { return pattern_.nonZeros(); }

 private:
  template <int NPE>
  void assemble_range(const Material& material, int begin, int end, double* k_values, double* m_values,
                      int* bad_element) const;
  int position(int row_node, int col_node) const;  // offset of node block within column

  const mesh::Mesh* mesh_;              // not owned
  std::vector<int> adjacency_offsets_;  // per node: start in adjacency_ (CSR, sorted)
  std::vector<int> adjacency_;          // neighbour nodes (incl. self), sorted per node
  linalg::SparseMatrixD pattern_;       // values zero
};

/// K and M of `mesh` in one call (see Assembler).
linalg::SparsePair<double> assemble(const mesh::Mesh& mesh, const Material& material, int threads = 0);

/// The three DOFs of every node in `nodes`, ascending.
std::vector<int> node_dofs(const std::vector<int>& nodes);
/// 0..n_dofs-1 without the DOFs in `fixed`, ascending.
std::vector<int> free_dofs(int n_dofs, const std::vector<int>& fixed);
/// A(dofs, dofs) for ascending `dofs` (restriction to free DOFs = clamping the others).
linalg::SparseMatrixD restrict(const linalg::SparseMatrixD& A, const std::vector<int>& dofs);

/// Sum of the element volumes [m^3] from the vertices (exact for straight-sided elements).
double meshed_volume(const mesh::Mesh& mesh);

}  // namespace shroudsim::fe
