// The gmsh sector generator and the .msh reader: groups, matching, volume, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "mesh/checks.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/sector_generator.hpp"

namespace shroudsim::mesh {
namespace {

namespace fs = std::filesystem;

/// A coarse sector that meshes in well under a second.
SectorGeometry coarse(int order) {
  SectorGeometry g;
  g.element_order = order;
  g.mesh_size = 0.02;
  return g;
}

// A file in this process's scratch folder, which is removed when the process exits.
fs::path temp_file(const std::string& name) {
  struct Scratch {
    fs::path dir = fs::temp_directory_path() / ("shroudsim_test_mesh_" + std::to_string(::getpid()));
    ~Scratch() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  };
  static const Scratch scratch;
  fs::create_directories(scratch.dir);
  return scratch.dir / name;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Mesh generate_and_read(const SectorGeometry& g, const std::string& name) {
  const fs::path file = temp_file(name);
  generate_sector_mesh(g, file, false);
  return read_sector_mesh(file, {g.sectors, 1e-9});
}

class SectorOrders : public ::testing::TestWithParam<int> {};

TEST_P(SectorOrders, HasEveryGroupAndMatchedFaces) {
  const SectorGeometry g = coarse(GetParam());
  const Mesh m = generate_and_read(g, "groups" + std::to_string(GetParam()) + ".msh");
  EXPECT_EQ(m.nodes_per_element(), GetParam() == 1 ? 4 : 10);
  for (const char* name : {kHub, kCyclicLow, kCyclicHigh, kShroudLow, kShroudHigh}) {
    ASSERT_TRUE(m.node_sets.count(name)) << name;
    EXPECT_GT(m.node_sets.at(name).size(), 3u) << name;
    EXPECT_GT(m.surface_triangles.at(name).rows(), 0) << name;
  }
  // Matching to round-off: the periodic mesh copies master nodes by the rotation itself.
  constexpr double kRoundOff = 1e-12;
  const double size = model_size(m.nodes);
  const double alpha = 2.0 * std::numbers::pi / g.sectors;
  for (const auto& [pairs, low, high] :
       {std::tuple{&m.cyclic_pairs, kCyclicLow, kCyclicHigh}, std::tuple{&m.shroud_pairs, kShroudLow, kShroudHigh}}) {
    ASSERT_EQ(pairs->size(), m.node_sets.at(low).size());
    const NodeMatch match =
        match_rotated_nodes(m.nodes, m.node_sets.at(low), m.node_sets.at(high), alpha, kRoundOff * size);
    EXPECT_TRUE(match.complete) << low << " worst " << match.worst_distance;
    EXPECT_LT(match.worst_distance, kRoundOff * size);
  }
  // Hub nodes lie on the bore; cyclic-low nodes on the radial plane at 90 - alpha/2.
  for (int n : m.node_sets.at(kHub)) EXPECT_NEAR(std::hypot(m.nodes(n, 0), m.nodes(n, 1)), g.hub_radius, 1e-9);
  const double tl = 0.5 * std::numbers::pi - 0.5 * alpha;
  for (int n : m.node_sets.at(kCyclicLow))
    EXPECT_NEAR(-std::sin(tl) * m.nodes(n, 0) + std::cos(tl) * m.nodes(n, 1), 0.0, 1e-9);
  const QualityStats q = element_quality(m);
  EXPECT_EQ(q.inverted, 0);
  EXPECT_EQ(q.degenerate, 0);
  EXPECT_GT(q.min_mean_ratio, 0.02);
}

TEST_P(SectorOrders, VolumeMatchesTheAnalyticVolume) {
  SectorGeometry g = coarse(GetParam());
  g.blade_twist_deg = 0.0;  // analytic_volume() is exact without twist
  g.shroud_width = 0.06;    // an untwisted tip needs room within the shroud
  const Mesh m = generate_and_read(g, "volume" + std::to_string(GetParam()) + ".msh");
  const double exact = g.analytic_volume();
  const double meshed = element_quality(m).volume;
  // Meshing tolerance: facets of a circle of radius R with edge length h lose a relative area
  // of about h^2 / (12 R^2) (linear); quadratic edges follow the arc to O(h^4 / R^4).
  // The smallest curved radius is the hub, R = 0.1, so h/R = 0.2.
  const double h_over_r = g.mesh_size / g.hub_radius;
  const double tolerance = GetParam() == 1 ? h_over_r * h_over_r / 12.0 : std::pow(h_over_r, 4);
  EXPECT_NEAR(meshed / exact, 1.0, tolerance) << "meshed " << meshed << " exact " << exact;
}

INSTANTIATE_TEST_SUITE_P(Mesh, SectorOrders, ::testing::Values(1, 2));

TEST(SectorMesh, SameCaseGivesTheSameMeshFile) {
  const SectorGeometry g = coarse(2);
  const fs::path a = temp_file("det_a.msh"), b = temp_file("det_b.msh");
  generate_sector_mesh(g, a, false);
  generate_sector_mesh(g, b, false);
  EXPECT_EQ(read_text(a), read_text(b));
}

TEST(SectorMesh, ContactAngleTurnsTheShroudFaceNormal) {
  // With a 30 degree contact angle, every shroud_high node lies on the plane through the
  // radial line at 90 + alpha/2 with normal cos(a) e_theta + sin(a) e_z.
  SectorGeometry g = coarse(2);
  g.shroud_contact_angle_deg = 30.0;
  const Mesh m = generate_and_read(g, "angle.msh");
  const double th = 0.5 * std::numbers::pi + std::numbers::pi / g.sectors, a = 30.0 * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(-std::sin(th) * std::cos(a), std::cos(th) * std::cos(a), std::sin(a));
  for (int i : m.node_sets.at(kShroudHigh)) EXPECT_NEAR(n.dot(m.nodes.row(i).transpose()), 0.0, 1e-9);
}

TEST(SectorMesh, InconsistentGeometryIsRefused) {
  SectorGeometry g = coarse(2);
  g.blade_chord = 0.2;  // does not fit the pitch of 8 sectors at the rim
  EXPECT_THROW(generate_sector_mesh(g, temp_file("bad.msh"), false), InputError);
  EXPECT_FALSE(fs::exists(temp_file("bad.msh")));
}

TEST(MshReader, WrongSectorCountIsAnUnmatchedNodeError) {
  const SectorGeometry g = coarse(1);
  const fs::path file = temp_file("nine.msh");
  generate_sector_mesh(g, file, false);
  try {
    read_sector_mesh(file, {9, 1e-6});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("unmatched nodes between 'cyclic_low' and 'cyclic_high'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("worst pair"), std::string::npos) << msg;
  }
}

TEST(MshReader, MissingGroupIsNamed) {
  const SectorGeometry g = coarse(1);
  const fs::path file = temp_file("nohub.msh");
  generate_sector_mesh(g, file, false);
  std::string text = read_text(file);
  const auto at = text.find("\"hub\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 5, "\"bore\"");
  std::ofstream(file, std::ios::binary) << text;
  try {
    read_sector_mesh(file, {8, 1e-6});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing 2D physical group(s): hub"), std::string::npos) << e.what();
  }
}

TEST(MshReader, MissingFileAndGarbageAreInputErrors) {
  EXPECT_THROW(read_sector_mesh(temp_file("absent.msh"), {8, 1e-6}), InputError);
  const fs::path junk = temp_file("junk.msh");
  std::ofstream(junk) << "this is not a mesh\n";
  EXPECT_THROW(read_sector_mesh(junk, {8, 1e-6}), InputError);
}

}  // namespace
}  // namespace shroudsim::mesh
