#pragma once
// The sector mesh: the value type handed from the mesh stage to FE, cyclic and contact.
//
// Conventions (docs/physics.md section 1):
//  - global z is the rotation axis; sector k+1 = sector k rotated by +alpha = 2*pi/sectors;
//  - node sets (0-based, sorted ascending): "hub" (clamped), "cyclic_low", "cyclic_high",
//    "shroud_low", "shroud_high";
//  - cyclic_pairs / shroud_pairs hold matched (low p, high q) with x_q = R(alpha) x_p;
//  - tets use gmsh's node ordering. 4-node: vertices 0..3 (positive volume).
//    10-node: vertices 0..3, then edge nodes 4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(2,3) 9:(1,3).
//  - surface_triangles hold the faces of the 2D physical groups (3 or 6 nodes per triangle,
//    gmsh ordering: vertices, then 3:(0,1) 4:(1,2) 5:(0,2)), used for areas and normals.
// Units: metres.
#include <Eigen/Core>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace shroudsim::mesh {

using NodeMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using ConnectivityMatrix = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Names of the physical groups every sector mesh must carry.
inline constexpr const char* kHub = "hub";
inline constexpr const char* kCyclicLow = "cyclic_low";
inline constexpr const char* kCyclicHigh = "cyclic_high";
inline constexpr const char* kShroudLow = "shroud_low";
inline constexpr const char* kShroudHigh = "shroud_high";
inline constexpr const char* kSector = "sector";

struct Mesh {
  NodeMatrix nodes;                                             ///< n_nodes x 3, metres
  ConnectivityMatrix tets;                                      ///< n_elements x (4 | 10), 0-based node indices
  int element_order = 2;                                        ///< 1 (4-node) or 2 (10-node)
  int sectors = 0;                                              ///< Nb, the number of sectors of the wheel
  std::map<std::string, std::vector<int>> node_sets;            ///< sorted node indices
  std::map<std::string, ConnectivityMatrix> surface_triangles;  ///< per 2D group
  std::vector<std::pair<int, int>> cyclic_pairs;                ///< (cyclic_low p, cyclic_high q), q = R p
  std::vector<std::pair<int, int>> shroud_pairs;                ///< (shroud_low p, shroud_high q), q = R p

  int n_nodes() const { return static_cast<int>(nodes.rows()); }
  int n_elements() const { return static_cast<int>(tets.rows()); }
  int nodes_per_element() const { return static_cast<int>(tets.cols()); }
  int n_dofs() const { return 3 * n_nodes(); }
  const std::vector<int>& node_set(const std::string& name) const { return node_sets.at(name); }
};

}  // namespace shroudsim::mesh
