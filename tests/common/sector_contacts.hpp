#pragma once
// The shroud contact pairs and forcing the FE-sector tests put on a coarse sector
// (coarse_sector.hpp): any orthonormal frame serves the algebra, the normal roughly
// circumferential; excitation and response at fixed nodes of the blade.
#include <Eigen/Geometry>

#include "frf/sector.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::testing_support {

/// The pair of matched shroud nodes (low, high) with its normal along the circumference.
inline frf::SectorContactPair circumferential_pair(const mesh::Mesh& mesh, int low, int high) {
  frf::SectorContactPair p;
  p.low_node = low;
  p.high_node = high;
  const Eigen::Vector3d x = mesh.nodes.row(high);
  Eigen::Vector3d n(-x.y(), x.x(), 0.0);
  n.normalize();
  p.frame.row(2) = n;
  p.frame.row(0) = Eigen::Vector3d::UnitZ();
  p.frame.row(1) = n.cross(Eigen::Vector3d::UnitZ());
  return p;
}

/// Engine order 1, unit force on every axis at node n/2, response at node n/3.
inline frf::SectorForcing test_forcing(const mesh::Mesh& mesh, bool residual_flexibility) {
  frf::SectorForcing forcing;
  forcing.engine_order = 1;
  forcing.excitation_node = mesh.n_nodes() / 2;
  forcing.response_node = mesh.n_nodes() / 3;
  forcing.force = Eigen::Vector3d(1.0, 1.0, 1.0);
  forcing.residual_flexibility = residual_flexibility;
  return forcing;
}

}  // namespace shroudsim::testing_support
