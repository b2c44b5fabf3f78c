// The mesh stage: a user's mesh read and checked, or the built-in sector generated
// (and reused while its geometry is unchanged).
#include <cmath>
#include <fstream>
#include <mutex>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "fe/fingerprint.hpp"
#include "io/output.hpp"
#include "mesh/checks.hpp"
#include "mesh/msh_reader.hpp"
#include "mesh/sector_generator.hpp"
#include "modal/cache.hpp"
#include "pipeline/context.hpp"

namespace shroudsim::pipeline {
namespace {

namespace fs = std::filesystem;

// Element volume / mesh_size^3 of gmsh's meshes of the generator's sector: 0.04 to 0.08 at
// the sizes in use (thin blade and shroud force smaller elements), about 0.1 for fine
// meshes; 0.04 makes the estimate an upper bound.
constexpr double kElementVolumeRatio = 0.04;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// mesh::read_sector_mesh, through the case's cache: the mesh as read and checked is kept in
// .cache/mesh-<key>.bin under a fingerprint of the file's bytes and the read options, so a
// run whose .msh is unchanged reads it back without gmsh (whose module then is never
// loaded: 0.15 s of every start, mesh/gmsh_module.hpp). A changed or unusable entry is
// read again through gmsh and rewritten.
mesh::Mesh read_mesh_cached(Context& ctx, const fs::path& file, const mesh::ReadOptions& options) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  constexpr std::uintmax_t kMaxHashedBytes = 4ull << 30;  // larger files are read each time
  if (ec || !fs::is_regular_file(file, ec) || size > kMaxHashedBytes) {
    ctx.report.section("mesh")["read_from"] = "gmsh";
    return mesh::read_sector_mesh(file, options);
  }
  std::string bytes(size, '\0');
  {
    std::ifstream in(file, std::ios::binary);
    if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) {
      ctx.report.section("mesh")["read_from"] = "gmsh";
      return mesh::read_sector_mesh(file, options);
    }
  }
  fe::Hasher h;
  h.add(std::string(mesh::kReaderVersion));
  h.add_bytes(bytes.data(), bytes.size());
  h.add(options.sectors);
  h.add(options.match_tolerance);
  const std::string key = h.hex();
  const fs::path entry = ctx.config.directory / ".cache" / ("mesh-" + key + ".bin");
  auto& j = ctx.report.section("mesh");
  j["cache_entry"] = entry.string();
  std::string problem;
  if (auto m = modal::load_mesh(entry, key, &problem)) {
    j["read_from"] = "cache";
    return std::move(*m);
  }
  if (!problem.empty()) ctx.report.warn("cache entry " + entry.string() + " is corrupt (" + problem + "); recomputing");
  mesh::Mesh m = mesh::read_sector_mesh(file, options);
  j["read_from"] = "gmsh";
  try {
    modal::save_mesh(entry, key, m);
  } catch (const std::exception& e) {
    ctx.report.warn(std::string("cannot write the mesh cache entry: ") + e.what());
  }
  return m;
}

void describe_mesh(Context& ctx, const mesh::Mesh& m, const fs::path& file, bool generated, bool reused) {
  const mesh::QualityStats q = mesh::element_quality(m);
  auto& j = ctx.report.section("mesh");
  j["file"] = file.string();
  j["generated"] = generated;
  j["reused"] = reused;
  j["nodes"] = m.n_nodes();
  j["elements"] = m.n_elements();
  j["nodes_per_element"] = m.nodes_per_element();
  j["dofs"] = m.n_dofs();
  j["volume_m3"] = q.volume;
  for (const auto& [name, nodes] : m.node_sets) j["node_sets"][name] = nodes.size();
  j["cyclic_pairs"] = m.cyclic_pairs.size();
  j["shroud_pairs"] = m.shroud_pairs.size();
  j["quality"] = {{"min_mean_ratio", q.min_mean_ratio},
                  {"mean_mean_ratio", q.mean_mean_ratio},
                  {"below_0_1", q.below_0_1},
                  {"min_jacobian_ratio", q.min_jacobian_ratio}};
  std::ostringstream s;
  s << "mesh " << file.string() << ": " << m.n_nodes() << " nodes, " << m.n_elements() << " " << m.nodes_per_element()
    << "-node tetrahedra, " << m.n_dofs() << " DOFs, " << m.cyclic_pairs.size() << " cyclic and "
    << m.shroud_pairs.size() << " shroud node pairs";
  log::info(s.str());
  log::info("mesh " + mesh::describe(q));
  if (q.min_mean_ratio < 0.05)
    ctx.report.warn("poor element quality: min mean ratio " + std::to_string(q.min_mean_ratio));
}

}  // namespace

mesh::Mesh obtain_mesh(Context& ctx) {
  const io::Case& c = ctx.config;
  if (c.structure.type != io::StructureType::sector)
    throw InputError(c.where("structure.type") + ": structure.type = \"" + io::to_string(c.structure.type) +
                     "\" has no mesh (meshes are for structure.type = \"sector\")");
  // gmsh is one global session per process, and study points sharing a case name share its
  // mesh file: one mesh stage at a time (generation, key and read stay consistent).
  static std::mutex mesh_stage_mutex;
  const std::lock_guard<std::mutex> lock(mesh_stage_mutex);
  log::Stopwatch clock;
  if (!c.structure.mesh.empty()) {
    mesh::Mesh m;
    try {
      m = read_mesh_cached(ctx, c.structure.mesh, {c.structure.sectors, 1e-6});
    } catch (const InputError& e) {
      throw InputError(c.locations.at("structure.mesh") + ": structure.mesh: " + e.what());
    }
    ctx.report.stage("mesh", clock.seconds(), /*reused=*/false);
    describe_mesh(ctx, m, c.structure.mesh, false, false);
    return m;
  }
  const mesh::SectorGeometry geometry = io::sector_geometry(c);
  const fs::path file = fs::path("meshes") / (c.name + ".msh");
  const fs::path key_file = file.string() + ".key";
  const std::string key = geometry.fingerprint();
  bool reused = false;
  if (fs::exists(file) && fs::exists(key_file) && read_text(key_file) == key) {
    reused = true;
    // The program's own mesh, unreadable (truncated, changed): regenerated, not blamed on the
    // user.
    try {
      mesh::Mesh m = read_mesh_cached(ctx, file, {c.structure.sectors, 1e-6});
      ctx.report.stage("mesh", clock.seconds(), reused);
      describe_mesh(ctx, m, file, true, reused);
      ctx.report.section("mesh")["analytic_volume_m3"] = geometry.analytic_volume();
      return m;
    } catch (const InputError& e) {
      ctx.report.warn("the generated mesh " + file.string() + " cannot be read (" + e.what() + "); regenerating");
      reused = false;
    }
  }
  {
    // Bounded work: gmsh's element count, estimated from the volume, before meshing.
    const double estimate = geometry.analytic_volume() / (kElementVolumeRatio * std::pow(geometry.mesh_size, 3));
    if (!(estimate <= c.geometry.max_elements))
      throw InputError(c.locations.at("geometry.mesh_size") +
                       ": geometry.mesh_size = " + io::format_number(geometry.mesh_size) + " would give about " +
                       std::to_string(std::llround(estimate)) + " elements (volume " +
                       io::format_number(geometry.analytic_volume()) + " m^3), above geometry.max_elements = " +
                       io::format_number(c.geometry.max_elements) + "; raise geometry.max_elements to mesh it anyway");
    log::info("meshing the sector (gmsh, " + std::to_string(geometry.element_order == 2 ? 10 : 4) +
              "-node tetrahedra, mesh_size " + io::format_number(geometry.mesh_size) + " m)");
    fs::remove(key_file);
    const mesh::GenerateReport r = mesh::generate_sector_mesh(geometry, file, /*verbose=*/false);
    io::write_file_atomic(key_file, key);
    ctx.report.section("mesh")["generation_seconds"] = r.seconds;
  }
  mesh::Mesh m = read_mesh_cached(ctx, file, {c.structure.sectors, 1e-6});
  ctx.report.stage("mesh", clock.seconds(), reused);
  describe_mesh(ctx, m, file, true, reused);
  auto& j = ctx.report.section("mesh");
  j["analytic_volume_m3"] = geometry.analytic_volume();
  return m;
}

}  // namespace shroudsim::pipeline
