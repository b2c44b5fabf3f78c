#pragma once
// Internal: the shape formulas the sector geometry's checks and the gmsh generator share
// (the [geometry] keys, docs/case_keys.md). Header-only: the generator lives in the gmsh
// module (mesh/gmsh_module.hpp).
#include <cmath>
#include <numbers>

#include "mesh/sector_generator.hpp"

namespace shroudsim::mesh::detail {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kDeg = kPi / 180.0;
inline constexpr double kThetaCentre = 0.5 * kPi;  // the sector is centred on +y

inline double alpha_of(const SectorGeometry& g) { return 2.0 * kPi / g.sectors; }
inline double shroud_inner_radius(const SectorGeometry& g) { return g.disk_outer_radius + g.blade_length; }

/// Half extent of the twisted blade section along x (circumferential) at twist phi.
inline double blade_half_x(const SectorGeometry& g, double phi) {
  return 0.5 * g.blade_chord * std::abs(std::sin(phi)) + 0.5 * g.blade_thickness * std::abs(std::cos(phi));
}
inline double blade_half_z(const SectorGeometry& g, double phi) {
  return 0.5 * g.blade_chord * std::abs(std::cos(phi)) + 0.5 * g.blade_thickness * std::abs(std::sin(phi));
}

}  // namespace shroudsim::mesh::detail
