#include "mesh/sector_generator.hpp"

#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "mesh/gmsh_session.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/sector_shape.hpp"

namespace shroudsim::mesh {
using namespace detail;

namespace {

using gmsh::vectorpair;

/// 4x4 row-major affine matrix of the rotation by `angle` about z (gmsh setPeriodic).
std::vector<double> rotation_affine(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
}

/// Annular sector solid: r in [r0, r1], z in [z0, z0 + h], theta in [t0, t0 + dt].
int annular_sector(double r0, double r1, double z0, double h, double t0, double dt) {
  const int outer = gmsh::model::occ::addCylinder(0, 0, z0, 0, 0, h, r1, -1, dt);
  const int inner = gmsh::model::occ::addCylinder(0, 0, z0 - h, 0, 0, 3 * h, r0);
  vectorpair out;
  std::vector<vectorpair> map;
  gmsh::model::occ::cut({{3, outer}}, {{3, inner}}, out, map);
  gmsh::model::occ::rotate(out, 0, 0, 0, 0, 0, 1, t0);
  return out.at(0).second;
}

/// A large box covering the half-space n . x >= 0 (side = +1) or <= 0 (side = -1), where
/// the plane contains the z-axis-through radial direction e_r and has normal n.
int half_space(const Eigen::Vector3d& e_r, const Eigen::Vector3d& n, double size, int side) {
  const Eigen::Vector3d t = n.cross(e_r);  // (e_r, t, n) right-handed
  const int box = gmsh::model::occ::addBox(-size, -size, side > 0 ? 0.0 : -size, 2 * size, 2 * size, size);
  // Map local (X, Y, Z) -> X e_r + Y t + Z n.
  std::vector<double> a = {e_r.x(), t.x(), n.x(), 0, e_r.y(), t.y(), n.y(), 0, e_r.z(), t.z(), n.z(), 0};
  gmsh::model::occ::affineTransform({{3, box}}, a);
  return box;
}

/// Twisted blade: loft through rectangular sections in planes y = r, twisted about y.
int blade_solid(const SectorGeometry& g, double r_start, double r_end) {
  const int stations = 6;
  std::vector<int> wires;
  for (int i = 0; i < stations; ++i) {
    const double r = r_start + (r_end - r_start) * i / (stations - 1);
    const double phi = g.blade_twist_deg * kDeg * (r - g.disk_outer_radius) / g.blade_length;
    const double c = std::cos(phi), s = std::sin(phi);
    const double hx = 0.5 * g.blade_thickness, hz = 0.5 * g.blade_chord;
    std::array<int, 4> p{};
    const double corners[4][2] = {{-hx, -hz}, {hx, -hz}, {hx, hz}, {-hx, hz}};
    for (int k = 0; k < 4; ++k) {
      // Rotation about +y by phi: x' = c x + s z, z' = -s x + c z.
      const double x = corners[k][0], z = corners[k][1];
      p[k] = gmsh::model::occ::addPoint(c * x + s * z, r, -s * x + c * z);
    }
    std::vector<int> lines;
    for (int k = 0; k < 4; ++k) lines.push_back(gmsh::model::occ::addLine(p[k], p[(k + 1) % 4]));
    wires.push_back(gmsh::model::occ::addWire(lines));
  }
  vectorpair out;
  gmsh::model::occ::addThruSections(wires, out, -1, true, /*makeRuled=*/false);
  for (const auto& dt : out)
    if (dt.first == 3) return dt.second;
  throw NumericalError("gmsh could not build the blade solid");
}

/// Points sampled on a surface's underlying geometry (parametric grid).
std::vector<Eigen::Vector3d> surface_samples(int tag) {
  std::vector<double> lo, hi;
  gmsh::model::getParametrizationBounds(2, tag, lo, hi);
  std::vector<double> uv;
  for (double fu : {0.2, 0.5, 0.8})
    for (double fv : {0.2, 0.5, 0.8}) {
      uv.push_back(lo[0] + fu * (hi[0] - lo[0]));
      uv.push_back(lo[1] + fv * (hi[1] - lo[1]));
    }
  std::vector<double> xyz;
  gmsh::model::getValue(2, tag, uv, xyz);
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) pts.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  return pts;
}

bool all_on_plane(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& n, double tol) {
  return std::all_of(pts.begin(), pts.end(), [&](const Eigen::Vector3d& p) { return std::abs(n.dot(p)) < tol; });
}

/// gmsh writes the node pairs of each periodic link in hash order, which changes from run
/// to run. Sorting them makes the file a pure function of the case (MSH 4.1 layout).
void sort_periodic_section(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  in.close();
  auto begin = std::find(lines.begin(), lines.end(), "$Periodic");
  if (begin == lines.end()) return;
  std::size_t i = static_cast<std::size_t>(begin - lines.begin()) + 1;
  const long links = std::stol(lines.at(i++));
  for (long l = 0; l < links; ++l) {
    i += 2;  // "dim tag tagMaster", "numAffine affine..."
    const long count = std::stol(lines.at(i++));
    auto first = lines.begin() + static_cast<long>(i);
    std::sort(first, first + count,
              [](const std::string& a, const std::string& b) { return std::stoull(a) < std::stoull(b); });
    i += static_cast<std::size_t>(count);
  }
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  for (const auto& line : lines) out << line << '\n';
}

}  // namespace

GenerateReport generate_sector_mesh(const SectorGeometry& g, const std::filesystem::path& file, bool verbose) {
  const auto violations = g.validate();
  if (!violations.empty()) {
    std::string msg = "inconsistent geometry:";
    for (const auto& [key, what] : violations) msg += " " + key + " violates: " + what + ";";
    throw InputError(msg);
  }
  log::Stopwatch clock;
  const double alpha = alpha_of(g);
  const double theta_low = kThetaCentre - 0.5 * alpha, theta_high = kThetaCentre + 0.5 * alpha;
  const double rd = g.disk_outer_radius, rs = shroud_inner_radius(g), ro = rs + g.shroud_thickness;
  const double a = g.shroud_contact_angle_deg * kDeg;
  const double big = 4.0 * ro;
  const double tol = 1e-7 * ro;
  auto e_r = [](double th) { return Eigen::Vector3d(std::cos(th), std::sin(th), 0.0); };
  auto e_t = [](double th) { return Eigen::Vector3d(-std::sin(th), std::cos(th), 0.0); };
  const Eigen::Vector3d n_low = std::cos(a) * e_t(theta_low) + std::sin(a) * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d n_high = std::cos(a) * e_t(theta_high) + std::sin(a) * Eigen::Vector3d::UnitZ();

  std::filesystem::create_directories(file.parent_path().empty() ? "." : file.parent_path());
  // A name of its own per process: two runs of one case (a study, concurrent users) never
  // write the same temporary file; the rename below makes the mesh appear whole.
  const std::filesystem::path tmp = file.string() + ".tmp" + std::to_string(::getpid()) + ".msh";
  GenerateReport report;
  {
    detail::GmshSession session(verbose);
    gmsh::model::add("sector");
    namespace occ = gmsh::model::occ;
    vectorpair out;
    std::vector<vectorpair> map;

    const int disk = annular_sector(g.hub_radius, rd, -0.5 * g.disk_thickness, g.disk_thickness, theta_low, alpha);
    // Shroud: a slab wider than the pitch, trimmed by the two inclined contact planes.
    const double margin = std::asin(std::min(1.0, (0.5 * g.shroud_width * std::tan(a) + 0.01 * ro) / rs)) + 0.01;
    int shroud = annular_sector(rs, ro, -0.5 * g.shroud_width, g.shroud_width, theta_low - margin, alpha + 2 * margin);
    occ::cut({{3, shroud}},
             {{3, half_space(e_r(theta_high), n_high, big, +1)}, {3, half_space(e_r(theta_low), n_low, big, -1)}}, out,
             map);
    if (out.size() != 1) throw NumericalError("gmsh: trimming the shroud by its contact planes failed");
    shroud = out[0].second;
    // Blade: lofted slightly past both radii, then trimmed to rd <= r <= rs so that it sits
    // exactly on the disk rim and under the shroud.
    const double overlap = 0.5 * std::min(g.disk_outer_radius - g.hub_radius, g.shroud_thickness);
    int blade = blade_solid(g, rd - overlap, rs + overlap);
    const int annulus_outer = occ::addCylinder(0, 0, -big, 0, 0, 2 * big, rs);
    const int annulus_inner = occ::addCylinder(0, 0, -2 * big, 0, 0, 4 * big, rd);
    occ::cut({{3, annulus_outer}}, {{3, annulus_inner}}, out, map);
    const int annulus = out.at(0).second;
    occ::intersect({{3, blade}}, {{3, annulus}}, out, map);
    if (out.size() != 1) throw NumericalError("gmsh: trimming the blade to the disk rim and shroud failed");
    blade = out[0].second;
    occ::fuse({{3, disk}}, {{3, blade}, {3, shroud}}, out, map);
    if (out.size() != 1 || out[0].first != 3)
      throw NumericalError("gmsh: the disk, blade and shroud did not fuse into one solid");
    const int volume = out[0].second;
    occ::synchronize();

    // Classify the boundary surfaces by their underlying geometry.
    vectorpair boundary;
    gmsh::model::getBoundary({{3, volume}}, boundary, /*combined=*/false, /*oriented=*/false);
    std::vector<int> hub, cyc_low, cyc_high, sh_low, sh_high;
    const double r_split = 0.5 * (rd + rs);
    for (const auto& [dim, tag] : boundary) {
      const auto pts = surface_samples(tag);
      double cx = 0, cy = 0, cz = 0;
      occ::getCenterOfMass(2, tag, cx, cy, cz);
      const double rc = std::hypot(cx, cy);
      const bool on_hub = std::all_of(pts.begin(), pts.end(), [&](const Eigen::Vector3d& p) {
        return std::abs(std::hypot(p.x(), p.y()) - g.hub_radius) < tol;
      });
      // Which side: the face lies along the ray at theta_low or theta_high (for Nb = 2 both
      // radial sides are on one plane through the axis, so the plane alone cannot tell).
      const Eigen::Vector3d c(cx, cy, 0.0);
      const bool low_side = c.dot(e_r(theta_low)) > 0, high_side = c.dot(e_r(theta_high)) > 0;
      if (on_hub) hub.push_back(tag);
      else if (rc < r_split && low_side && all_on_plane(pts, e_t(theta_low), tol)) cyc_low.push_back(tag);
      else if (rc < r_split && high_side && all_on_plane(pts, e_t(theta_high), tol)) cyc_high.push_back(tag);
      else if (rc > r_split && low_side && all_on_plane(pts, n_low, tol)) sh_low.push_back(tag);
      else if (rc > r_split && high_side && all_on_plane(pts, n_high, tol)) sh_high.push_back(tag);
    }
    auto need = [](const std::vector<int>& v, const char* what) {
      if (v.empty()) throw NumericalError(std::string("gmsh: no surface found for ") + what);
    };
    need(hub, kHub), need(cyc_low, kCyclicLow), need(cyc_high, kCyclicHigh), need(sh_low, kShroudLow),
        need(sh_high, kShroudHigh);

    // Periodic meshing: each high surface is the rotation of a low one.
    auto make_periodic = [&](const std::vector<int>& low, const std::vector<int>& high, const char* what) {
      if (low.size() != high.size()) throw NumericalError(std::string("gmsh: unpaired ") + what + " surfaces");
      const Eigen::Matrix3d rot = rotation_z(alpha);
      for (int hs : high) {
        double hx, hy, hz;
        occ::getCenterOfMass(2, hs, hx, hy, hz);
        int master = -1;
        for (int ls : low) {
          double lx, ly, lz;
          occ::getCenterOfMass(2, ls, lx, ly, lz);
          if ((rot * Eigen::Vector3d(lx, ly, lz) - Eigen::Vector3d(hx, hy, hz)).norm() < 1e-6 * ro) master = ls;
        }
        if (master < 0) throw NumericalError(std::string("gmsh: no rotated match for a ") + what + " surface");
        gmsh::model::mesh::setPeriodic(2, {hs}, {master}, rotation_affine(alpha));
      }
    };
    make_periodic(cyc_low, cyc_high, "cyclic");
    make_periodic(sh_low, sh_high, "shroud");

    gmsh::model::addPhysicalGroup(3, {volume}, 1);
    gmsh::model::setPhysicalName(3, 1, kSector);
    const std::vector<std::pair<const char*, const std::vector<int>*>> groups = {
        {kHub, &hub}, {kCyclicLow, &cyc_low}, {kCyclicHigh, &cyc_high}, {kShroudLow, &sh_low}, {kShroudHigh, &sh_high}};
    int tag = 11;
    for (const auto& [name, surfaces] : groups) {
      gmsh::model::addPhysicalGroup(2, *surfaces, tag);
      gmsh::model::setPhysicalName(2, tag, name);
      ++tag;
    }

    gmsh::option::setNumber("General.NumThreads", 1);  // determinism
    gmsh::option::setNumber("Mesh.MeshSizeMax", g.mesh_size);
    gmsh::option::setNumber("Mesh.MeshSizeMin", 0.0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 1);
    gmsh::option::setNumber("Mesh.Algorithm", 6);    // Frontal-Delaunay (2D)
    gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay (3D)
    gmsh::option::setNumber("Mesh.Optimize", 1);
    gmsh::option::setNumber("Mesh.ElementOrder", g.element_order);
    gmsh::option::setNumber("Mesh.SecondOrderLinear", 0);
    gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
    gmsh::option::setNumber("Mesh.Binary", 0);
    gmsh::option::setNumber("Mesh.SaveAll", 0);
    try {
      gmsh::model::mesh::generate(3);
    } catch (...) {
      throw NumericalError("gmsh failed to mesh the sector (try another mesh_size)");
    }
    gmsh::write(tmp.string());
  }
  sort_periodic_section(tmp);
  // Read back through the same reader users' meshes go through: groups, matching, validity.
  Mesh mesh;
  try {
    mesh = read_sector_mesh(tmp, ReadOptions{g.sectors, 1e-9});
  } catch (const InputError& e) {
    std::filesystem::remove(tmp);
    // Named as the file it would have become (the temporary name means nothing to a user).
    std::string what = e.what();
    for (std::size_t at; (at = what.find(tmp.string())) != std::string::npos;)
      what.replace(at, tmp.string().size(), file.string());
    throw NumericalError("the generated mesh " + file.string() + " failed its checks: " + what);
  }
  report.quality = element_quality(mesh);
  report.n_nodes = mesh.n_nodes();
  report.n_elements = mesh.n_elements();
  std::filesystem::rename(tmp, file);
  report.seconds = clock.seconds();
  return report;
}

}  // namespace shroudsim::mesh
