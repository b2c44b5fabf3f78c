#include "mesh/msh_reader.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "core/error.hpp"
#include "mesh/checks.hpp"
#include "mesh/gmsh_session.hpp"

namespace shroudsim::mesh {
namespace {

constexpr int kGmshTet4 = 4, kGmshTet10 = 11, kGmshTri3 = 2, kGmshTri6 = 9;

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw InputError(file.string() + ": " + what);
}

// gmsh 4.8 can crash (segmentation fault) or loop on a malformed mesh file, e.g. an element
// that names a negative node tag. The file is read once in a child process first: a child
// that dies by a signal or does not finish within kProbeSeconds is the file's fault, and
// is reported as bad input instead of taking the whole run down.
constexpr int kProbeSeconds = 600;

void probe_in_child(const std::filesystem::path& file) {
  const pid_t pid = ::fork();
  if (pid < 0) return;  // cannot fork: read it directly
  if (pid == 0) {
    int code = 0;
    try {
      gmsh::initialize(0, nullptr, false);
      gmsh::option::setNumber("General.Terminal", 0);
      gmsh::open(file.string());
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> tags, nodes;
      gmsh::model::mesh::getElements(types, tags, nodes, -1, -1);
      std::vector<std::size_t> node_tags;
      std::vector<double> coords, params;
      gmsh::model::mesh::getNodes(node_tags, coords, params, -1, -1, true, false);
    } catch (...) {
      code = 3;  // gmsh refused it: the reader below says so in its own words
    }
    ::_exit(code);
  }
  int status = 0;
  for (int waited = 0; waited < 100 * kProbeSeconds; ++waited) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) {
      if (WIFSIGNALED(status))
        fail(file, "gmsh crashed reading this file (signal " + std::to_string(WTERMSIG(status)) +
                       "): it is not a well-formed mesh");
      return;
    }
    if (r < 0) return;
    ::usleep(10000);
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  fail(file, "gmsh did not finish reading this file within " + std::to_string(kProbeSeconds) +
                 " s: it is not a well-formed mesh");
}

std::string point_text(const NodeMatrix& nodes, int i) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << nodes(i, 0) << ", " << nodes(i, 1) << ", " << nodes(i, 2) << ")";
  return s.str();
}

}  // namespace

Mesh read_sector_mesh(const std::filesystem::path& file, const ReadOptions& options) {
  if (!std::filesystem::exists(file)) fail(file, "mesh file does not exist");
  // Only regular files, of a size a sector mesh can have (a device or a pipe would be read
  // forever).
  constexpr std::uintmax_t kMaxMeshBytes = 16ull << 30;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) fail(file, "not a regular file");
  if (std::filesystem::file_size(file, ec) > kMaxMeshBytes || ec)
    fail(file, "larger than 16 GiB (or unreadable): not a sector mesh");
  SHROUDSIM_CHECK(options.sectors >= 1, "sectors >= 1");
  Mesh mesh;
  mesh.sectors = options.sectors;

  {
    detail::GmshSession session(false);
    probe_in_child(file);  // under the session's lock: one gmsh user at a time
    try {
      gmsh::open(file.string());
    } catch (...) {
      fail(file, "gmsh cannot read this file as a mesh");
    }
    gmsh::vectorpair groups;
    gmsh::model::getPhysicalGroups(groups);
    std::map<std::string, std::pair<int, int>> by_name;  // name -> (dim, tag)
    for (const auto& [dim, tag] : groups) {
      std::string name;
      gmsh::model::getPhysicalName(dim, tag, name);
      by_name[name] = {dim, tag};
    }

    // Nodes: compact 0-based numbering of the nodes the 3D elements use.
    std::unordered_map<std::size_t, int> index;
    std::vector<std::size_t> node_tags;
    std::vector<double> coords, params;
    gmsh::model::mesh::getNodes(node_tags, coords, params, -1, -1, /*includeBoundary=*/true,
                                /*returnParametricCoordinates=*/false);
    std::unordered_map<std::size_t, std::size_t> tag_to_row;
    for (std::size_t i = 0; i < node_tags.size(); ++i) tag_to_row[node_tags[i]] = i;

    // Volume elements.
    std::vector<std::pair<int, int>> volumes;
    if (by_name.count(kSector) && by_name[kSector].first == 3) {
      std::vector<int> ents;
      gmsh::model::getEntitiesForPhysicalGroup(3, by_name[kSector].second, ents);
      for (int e : ents) volumes.emplace_back(3, e);
    } else {
      gmsh::model::getEntities(volumes, 3);
    }
    int element_type = 0;
    std::vector<std::size_t> conn;
    for (const auto& [dim, tag] : volumes) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> elem_tags, elem_nodes;
      gmsh::model::mesh::getElements(types, elem_tags, elem_nodes, dim, tag);
      for (std::size_t t = 0; t < types.size(); ++t) {
        if (types[t] != kGmshTet4 && types[t] != kGmshTet10) {
          std::string name;
          int d = 0, order = 0, nn = 0, npn = 0;
          std::vector<double> lc;
          gmsh::model::mesh::getElementProperties(types[t], name, d, order, nn, lc, npn);
          fail(file, "3D elements must be 4- or 10-node tetrahedra; found " + name);
        }
        if (element_type && element_type != types[t])
          fail(file, "mixed 4-node and 10-node tetrahedra; use one element order");
        element_type = types[t];
        conn.insert(conn.end(), elem_nodes[t].begin(), elem_nodes[t].end());
      }
    }
    if (!element_type) fail(file, "no tetrahedra (3D elements) in the mesh");
    const int npe = element_type == kGmshTet4 ? 4 : 10;
    mesh.element_order = npe == 4 ? 1 : 2;
    for (std::size_t t : conn)
      if (!index.count(t)) index.emplace(t, static_cast<int>(index.size()));
    // Order compact indices by gmsh tag for determinism.
    std::vector<std::size_t> used;
    used.reserve(index.size());
    for (const auto& kv : index) used.push_back(kv.first);
    std::sort(used.begin(), used.end());
    for (std::size_t i = 0; i < used.size(); ++i) index[used[i]] = static_cast<int>(i);
    mesh.nodes.resize(static_cast<Eigen::Index>(used.size()), 3);
    for (std::size_t i = 0; i < used.size(); ++i) {
      const std::size_t row = tag_to_row.at(used[i]);
      for (int c = 0; c < 3; ++c) {
        const double x = coords[3 * row + c];
        if (!std::isfinite(x))
          fail(file, "node " + std::to_string(used[i]) + " has a non-finite coordinate (" + std::to_string(x) + ")");
        mesh.nodes(static_cast<Eigen::Index>(i), c) = x;
      }
    }
    const Eigen::Index ne = static_cast<Eigen::Index>(conn.size() / npe);
    mesh.tets.resize(ne, npe);
    for (Eigen::Index e = 0; e < ne; ++e)
      for (int a = 0; a < npe; ++a) mesh.tets(e, a) = index.at(conn[e * npe + a]);

    // Surface groups.
    std::vector<std::string> missing;
    for (const char* name : {kHub, kCyclicLow, kCyclicHigh, kShroudLow, kShroudHigh}) {
      auto it = by_name.find(name);
      if (it == by_name.end() || it->second.first != 2) {
        missing.push_back(name);
        continue;
      }
      std::vector<int> ents;
      gmsh::model::getEntitiesForPhysicalGroup(2, it->second.second, ents);
      std::set<int> nodes;
      std::vector<int> tri;
      int tri_npe = 0;
      for (int ent : ents) {
        std::vector<int> types;
        std::vector<std::vector<std::size_t>> elem_tags, elem_nodes;
        gmsh::model::mesh::getElements(types, elem_tags, elem_nodes, 2, ent);
        for (std::size_t t = 0; t < types.size(); ++t) {
          if (types[t] != kGmshTri3 && types[t] != kGmshTri6)
            fail(file, std::string("surface group '") + name + "' must hold triangles");
          tri_npe = types[t] == kGmshTri3 ? 3 : 6;
          for (std::size_t tag : elem_nodes[t]) {
            auto n = index.find(tag);
            if (n == index.end())
              fail(file, std::string("surface group '") + name + "' has a node that no tetrahedron uses (node tag " +
                             std::to_string(tag) + ")");
            tri.push_back(n->second);
            nodes.insert(n->second);
          }
        }
      }
      if (nodes.empty()) fail(file, std::string("physical group '") + name + "' is empty");
      mesh.node_sets[name] = std::vector<int>(nodes.begin(), nodes.end());
      ConnectivityMatrix t(static_cast<Eigen::Index>(tri.size() / tri_npe), tri_npe);
      for (Eigen::Index i = 0; i < t.rows(); ++i)
        for (int a = 0; a < tri_npe; ++a) t(i, a) = tri[i * tri_npe + a];
      mesh.surface_triangles[name] = std::move(t);
    }
    if (!missing.empty()) {
      std::string list;
      for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
      fail(file, "missing 2D physical group(s): " + list +
                     " (a sector mesh needs hub, cyclic_low, cyclic_high, shroud_low, shroud_high)");
    }
  }

  // Rotational matching of the cyclic and shroud faces.
  const double alpha = 2.0 * std::numbers::pi / options.sectors;
  const double tol = options.match_tolerance * model_size(mesh.nodes);
  auto match = [&](const char* low, const char* high, std::vector<std::pair<int, int>>& out) {
    const auto& lo = mesh.node_sets.at(low);
    const auto& hi = mesh.node_sets.at(high);
    if (lo.size() != hi.size())
      fail(file, std::string("unmatched nodes: '") + low + "' has " + std::to_string(lo.size()) + " nodes and '" +
                     high + "' has " + std::to_string(hi.size()) +
                     " (they must match one to one under the rotation by 360/" + std::to_string(options.sectors) +
                     " deg)");
    const NodeMatch m = match_rotated_nodes(mesh.nodes, lo, hi, alpha, tol);
    if (!m.complete) {
      std::ostringstream s;
      s << "unmatched nodes between '" << low << "' and '" << high << "' under the rotation by 360/" << options.sectors
        << " deg: ";
      if (m.worst_high >= 0)
        s << "worst pair low node at " << point_text(mesh.nodes, m.worst_low) << " -> nearest high node at "
          << point_text(mesh.nodes, m.worst_high) << ", distance " << m.worst_distance << " m > tolerance " << tol
          << " m";
      else s << "the rotated low nodes do not map one to one onto the high nodes";
      fail(file, s.str());
    }
    out = m.pairs;
  };
  match(kCyclicLow, kCyclicHigh, mesh.cyclic_pairs);
  match(kShroudLow, kShroudHigh, mesh.shroud_pairs);
  if (mesh.node_sets.at(kHub).empty()) fail(file, "physical group 'hub' is empty");

  const QualityStats q = element_quality(mesh);
  if (q.inverted > 0) fail(file, std::to_string(q.inverted) + " inverted element(s) (non-positive Jacobian)");
  if (q.degenerate > 0) fail(file, std::to_string(q.degenerate) + " degenerate element(s)");
  return mesh;
}

}  // namespace shroudsim::mesh
