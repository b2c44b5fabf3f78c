// SectorGeometry's checks, volume and fingerprint (no gmsh: these run in every command).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "mesh/sector_generator.hpp"
#include "mesh/sector_shape.hpp"

namespace shroudsim::mesh {
using namespace detail;

std::vector<std::pair<std::string, std::string>> SectorGeometry::validate() const {
  std::vector<std::pair<std::string, std::string>> v;
  auto add = [&](const char* key, const std::string& what) { v.emplace_back(std::string("geometry.") + key, what); };
  // A 180-degree sector (Nb = 2) has both radial sides on one plane through the axis, which
  // the contact-plane trimming below (half-spaces through the axis) cannot tell apart: Nb = 2
  // needs a mesh of one's own ([structure] mesh), which the cyclic reduction handles.
  if (sectors < 3)
    v.emplace_back("structure.sectors", "sectors >= 3 for a generated sector (Nb = 2: give [structure] mesh)");
  if (v.size()) return v;
  const double alpha = alpha_of(*this);
  if (disk_outer_radius <= hub_radius) add("disk_outer_radius", "disk_outer_radius > hub_radius");
  const double tip_twist = blade_twist_deg * kDeg;
  double half_x = 0.0;
  for (int i = 0; i <= 8; ++i) half_x = std::max(half_x, blade_half_x(*this, tip_twist * i / 8.0));
  if (half_x >= 0.9 * disk_outer_radius * std::sin(0.5 * alpha))
    add("blade_chord",
        "the blade section (chord, thickness, twist) must fit within 90% of the sector pitch at the disk rim");
  const double rs = shroud_inner_radius(*this);
  if (blade_half_z(*this, tip_twist) >= 0.5 * shroud_width)
    add("shroud_width", "shroud_width > axial extent of the twisted blade tip section");
  const double a = shroud_contact_angle_deg * kDeg;
  if (0.5 * shroud_width * std::tan(a) >= 0.8 * rs * std::sin(0.5 * alpha))
    add("shroud_contact_angle_deg",
        "shroud_width/2 * tan(shroud_contact_angle_deg) < 0.8 * half the pitch at the shroud (contact faces must not cross)");
  const double smallest = std::min(
      {blade_length, blade_chord, disk_thickness, disk_outer_radius - hub_radius, shroud_width, hub_radius * alpha});
  if (mesh_size > smallest)
    add("mesh_size",
        "mesh_size <= the smallest of blade_length, blade_chord, disk_thickness, "
        "disk_outer_radius - hub_radius, shroud_width and the hub arc");
  if (mesh_size < 1e-4 * (rs + shroud_thickness))
    add("mesh_size", "mesh_size >= 1e-4 * outer radius (finer meshes exceed any practical size)");
  return v;
}

double SectorGeometry::analytic_volume() const {
  const double alpha = alpha_of(*this);
  const double rd = disk_outer_radius, rs = shroud_inner_radius(*this);
  const double disk = 0.5 * alpha * (rd * rd - hub_radius * hub_radius) * disk_thickness;
  // The shroud's low face is its high face rotated by -alpha, so the shroud is a fundamental
  // domain of the Nb-fold rotation within the annular slab, whatever the contact angle.
  const double ro = rs + shroud_thickness;
  const double shroud = 0.5 * alpha * (ro * ro - rs * rs) * shroud_width;
  // Blade between the cylinders r = rd and r = rs: integrate over the (untwisted) section
  // the radial length sqrt(rs^2 - x^2) - sqrt(rd^2 - x^2) (closed form of the x integral).
  auto primitive = [](double r, double x) { return 0.5 * (x * std::sqrt(r * r - x * x) + r * r * std::asin(x / r)); };
  const double t = 0.5 * blade_thickness;
  const double blade = blade_chord * 2.0 * (primitive(rs, t) - primitive(rd, t));
  return disk + shroud + blade;
}

std::string SectorGeometry::fingerprint() const {
  std::ostringstream s;
  s.precision(17);
  s << "sector-v1 " << sectors << ' ' << hub_radius << ' ' << disk_outer_radius << ' ' << disk_thickness << ' '
    << blade_length << ' ' << blade_chord << ' ' << blade_thickness << ' ' << blade_twist_deg << ' ' << shroud_thickness
    << ' ' << shroud_width << ' ' << shroud_contact_angle_deg << ' ' << element_order << ' ' << mesh_size;
  return s.str();
}

}  // namespace shroudsim::mesh
