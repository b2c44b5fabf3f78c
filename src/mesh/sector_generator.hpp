#pragma once
// The built-in parametric shrouded blade sector (gmsh, OpenCASCADE kernel).
//
// Geometry (metres, degrees), global z = rotation axis, the sector centred on the +y axis:
//  - disk: annular sector hub_radius <= r <= disk_outer_radius, |z| <= disk_thickness/2,
//    |theta - 90deg| <= alpha/2 (alpha = 360deg/sectors). The bore r = hub_radius is "hub";
//    its two radial faces are "cyclic_low" (theta = 90 - alpha/2) and "cyclic_high".
//  - blade: a plate of chord blade_chord (along z at the root) and thickness blade_thickness
//    (along x), standing on +y from r = disk_outer_radius to r = shroud inner radius
//    R_s = disk_outer_radius + blade_length, twisted linearly about its radial axis from 0 at
//    the root to blade_twist_deg at the tip.
//  - shroud: R_s <= r <= R_s + shroud_thickness, |z| <= shroud_width/2, spanning the pitch;
//    its side faces are planes through the radial line at theta = 90 -/+ alpha/2 with normal
//    n = cos(a) e_theta + sin(a) e_z, a = shroud_contact_angle_deg ("shroud_low",
//    "shroud_high"; the high face is the low one rotated by +alpha, and the high face's
//    outward normal is n).
// Both face pairs are meshed periodically, so their nodes match under the rotation.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "mesh/checks.hpp"

namespace shroudsim::mesh {

struct SectorGeometry {
  int sectors = 8;
  double hub_radius = 0.10;
  double disk_outer_radius = 0.16;
  double disk_thickness = 0.03;
  double blade_length = 0.25;
  double blade_chord = 0.05;
  double blade_thickness = 0.006;
  double blade_twist_deg = 20.0;
  double shroud_thickness = 0.006;
  double shroud_width = 0.05;
  double shroud_contact_angle_deg = 45.0;
  int element_order = 2;
  double mesh_size = 0.01;

  /// Consistency of the whole geometry: (key, violated constraint) for every violation.
  /// Single-key ranges are checked by the case reader; this checks how the keys fit together.
  std::vector<std::pair<std::string, std::string>> validate() const;

  /// Exact volume of the sector solid (m^3), exact for blade_twist_deg = 0 and to second
  /// order in the twist otherwise.
  double analytic_volume() const;

  /// Stable text of every parameter (the mesh cache key).
  std::string fingerprint() const;
};

struct GenerateReport {
  int n_nodes = 0, n_elements = 0;
  QualityStats quality;
  double seconds = 0.0;
};

/// Meshes the sector and writes a gmsh 4.1 ASCII .msh to `file` (via a temporary file that
/// is renamed only when the mesh passed every check: no inverted or degenerate element,
/// matched cyclic and shroud nodes). Throws InputError for an inconsistent geometry and
/// NumericalError when gmsh fails or the mesh fails its checks.
GenerateReport generate_sector_mesh(const SectorGeometry& geometry, const std::filesystem::path& file, bool verbose);

}  // namespace shroudsim::mesh
