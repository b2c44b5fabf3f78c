#pragma once
// Geometric checks on a sector mesh: rotational node matching, element orientation and
// quality, volume. Pure functions on Mesh; no gmsh.
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh.hpp"

namespace shroudsim::mesh {

/// 3x3 rotation by `angle` (rad) about the global z axis.
Eigen::Matrix3d rotation_z(double angle);

/// Result of matching `low` nodes to `high` nodes under x_high = R x_low.
struct NodeMatch {
  std::vector<std::pair<int, int>> pairs;  ///< (low, high), in the order of `low`
  double worst_distance = 0.0;             ///< max over low nodes of |R x_low - x_high| (m)
  int worst_low = -1, worst_high = -1;     ///< the pair attaining it
  bool complete = false;                   ///< one-to-one and every distance <= tolerance
};

/// Matches each low node to its nearest high node after rotating it by `angle` about z.
/// Complete when |low| == |high|, the map is one-to-one and every distance <= tolerance.
NodeMatch match_rotated_nodes(const NodeMatrix& nodes, const std::vector<int>& low, const std::vector<int>& high,
                              double angle, double tolerance);

/// Diagonal of the bounding box of all nodes (m): the model size used for tolerances.
double model_size(const NodeMatrix& nodes);

/// Quality statistics of the tetrahedra.
struct QualityStats {
  double min_mean_ratio = 1.0;  ///< mean-ratio quality in (0, 1], 1 = regular; of the corners
  double mean_mean_ratio = 1.0;
  int below_0_1 = 0;                ///< elements with mean ratio < 0.1
  double min_jacobian_ratio = 1.0;  ///< min over elements of min/max det J at sample points
  int inverted = 0;                 ///< elements with det J <= 0 at some sample point
  int degenerate = 0;               ///< elements with a volume below 1e-12 of the mean volume
  double volume = 0.0;              ///< total volume (m^3)
};

/// Corner mean ratio, Jacobian sign at the vertices, edge midpoints and centroid
/// (quadratic elements), and volume (exact for straight-sided elements; for curved
/// 10-node elements by a degree-2 rule on the quadratic map).
QualityStats element_quality(const Mesh& mesh);

/// Human-readable one-liner of the statistics.
std::string describe(const QualityStats& q);

}  // namespace shroudsim::mesh
