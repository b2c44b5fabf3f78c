#pragma once
// Structured tetrahedral meshes for verification tests and benchmarks (not for users):
// hexahedral cells split into six tetrahedra along their main diagonal (Kuhn split, which
// is conforming between neighbouring cells), optionally 10-node (straight-sided: edge
// nodes at edge midpoints). Node sets follow mesh/mesh.hpp.
#include <cstdint>

#include "mesh/mesh.hpp"

namespace shroudsim::fe {

/// Box [0, lx] x [0, ly] x [0, lz] with nx x ny x nz cells. Node set "hub" = face x = 0
/// (the clamped end of a cantilever along x). Units: m.
/// perturbation > 0 moves every interior vertex by up to perturbation * cell size in each
/// direction (seeded, reproducible), for patch tests on distorted meshes.
mesh::Mesh box_mesh(double lx, double ly, double lz, int nx, int ny, int nz, int element_order,
                    double perturbation = 0.0, std::uint32_t seed = 1);

/// One sector of an annular plate: r in [r_inner, r_outer], theta in [0, 2 pi / sectors],
/// z in [0, thickness], n_r x n_theta x n_z cells mapped from (r, theta, z). Node sets:
/// "hub" (r = r_inner, clamped), "cyclic_low" (theta = 0), "cyclic_high" (theta = alpha),
/// with cyclic_pairs matched exactly (x_q = R(alpha) x_p). Shroud sets are empty.
/// blade_length > 0 adds a radial blade (a block of the plate's width in theta at the
/// sector's middle is extended outwards to r_outer + blade_length with n_blade cells), so
/// that the sector has blade-like modes; the blade cells need n_theta >= 3.
struct AnnularSectorSpec {
  double r_inner = 0.1, r_outer = 0.2, thickness = 0.02;
  int sectors = 6;
  int n_r = 2, n_theta = 2, n_z = 1;
  int element_order = 2;
  double blade_length = 0.0;
  int n_blade = 0;
};
mesh::Mesh annular_sector_mesh(const AnnularSectorSpec& spec);

/// The full 360-degree wheel from `sector.sectors` rotated copies of a sector mesh, the
/// cyclic_high nodes of copy k merged with the cyclic_low nodes of copy k+1. Node set "hub"
/// is the union over copies. Needs matched cyclic_pairs.
mesh::Mesh replicate_wheel(const mesh::Mesh& sector);

}  // namespace shroudsim::fe
