#include "fe/structured_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "core/error.hpp"
#include "fe/tet_element.hpp"

namespace shroudsim::fe {
namespace {

using Ijk = std::array<int, 3>;

// A structured grid of (ni x nj x nk) hexahedral cells; cells where `keep` is true become six
// tetrahedra each; `coord` maps grid vertex (i, j, k) to space.
struct Grid {
  int ni = 0, nj = 0, nk = 0;
  std::function<Eigen::Vector3d(int, int, int)> coord;
  std::function<bool(int, int, int)> keep;
  int vertex_id(int i, int j, int k) const { return (i * (nj + 1) + j) * (nk + 1) + k; }
};

struct Tet4Mesh {
  mesh::Mesh mesh;              // 4-node
  std::vector<Ijk> grid_index;  // per node: its grid vertex
};

Tet4Mesh build_tet4(const Grid& g) {
  // Kuhn split: one tet per axis permutation, walking 000 -> ... -> 111.
  static constexpr int kPerm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::vector<int> node_of((g.ni + 1) * (g.nj + 1) * (g.nk + 1), -1);
  Tet4Mesh out;
  std::vector<std::array<int, 4>> tets;
  std::vector<Eigen::Vector3d> xyz;
  auto node = [&](int i, int j, int k) {
    int& id = node_of[g.vertex_id(i, j, k)];
    if (id < 0) {
      id = static_cast<int>(xyz.size());
      xyz.push_back(g.coord(i, j, k));
      out.grid_index.push_back({i, j, k});
    }
    return id;
  };
  for (int i = 0; i < g.ni; ++i)
    for (int j = 0; j < g.nj; ++j)
      for (int k = 0; k < g.nk; ++k) {
        if (!g.keep(i, j, k)) continue;
        for (const auto& p : kPerm) {
          Ijk c{i, j, k};
          std::array<int, 4> t{};
          t[0] = node(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            c[p[s]] += 1;
            t[s + 1] = node(c[0], c[1], c[2]);
          }
          tets.push_back(t);
        }
      }
  mesh::Mesh& m = out.mesh;
  m.element_order = 1;
  m.nodes.resize(static_cast<Eigen::Index>(xyz.size()), 3);
  for (std::size_t n = 0; n < xyz.size(); ++n) m.nodes.row(n) = xyz[n].transpose();
  m.tets.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (std::size_t e = 0; e < tets.size(); ++e) {
    auto t = tets[e];
    const double v = tet_volume(m.nodes.row(t[0]).transpose(), m.nodes.row(t[1]).transpose(),
                                m.nodes.row(t[2]).transpose(), m.nodes.row(t[3]).transpose());
    if (v < 0.0) std::swap(t[1], t[2]);
    for (int a = 0; a < 4; ++a) m.tets(e, a) = t[a];
  }
  return out;
}

// Node set of the vertices whose grid index satisfies `pred` (sorted).
std::vector<int> vertex_set(const Tet4Mesh& t4, const std::function<bool(const Ijk&)>& pred) {
  std::vector<int> s;
  for (std::size_t n = 0; n < t4.grid_index.size(); ++n)
    if (pred(t4.grid_index[n])) s.push_back(static_cast<int>(n));
  return s;
}

// Adds straight-sided edge nodes (gmsh order) to a 4-node mesh; node sets grow by the edge
// nodes whose two vertices are both in the set; cyclic pairs grow by matched edges.
void make_quadratic(mesh::Mesh& m) {
  static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
  std::map<std::pair<int, int>, int> edge_node;
  std::vector<Eigen::Vector3d> extra;
  const int n_vertices = m.n_nodes();
  mesh::ConnectivityMatrix tets10(m.n_elements(), 10);
  for (int e = 0; e < m.n_elements(); ++e) {
    for (int a = 0; a < 4; ++a) tets10(e, a) = m.tets(e, a);
    for (int s = 0; s < 6; ++s) {
      int p = m.tets(e, kEdge[s][0]), q = m.tets(e, kEdge[s][1]);
      const auto key = std::minmax(p, q);
      auto [it, inserted] = edge_node.try_emplace({key.first, key.second}, n_vertices + static_cast<int>(extra.size()));
      if (inserted) extra.push_back(0.5 * (m.nodes.row(p) + m.nodes.row(q)).transpose());
      tets10(e, 4 + s) = it->second;
    }
  }
  mesh::NodeMatrix nodes(n_vertices + static_cast<Eigen::Index>(extra.size()), 3);
  nodes.topRows(n_vertices) = m.nodes;
  for (std::size_t k = 0; k < extra.size(); ++k) nodes.row(n_vertices + k) = extra[k].transpose();
  for (auto& [name, set] : m.node_sets) {
    std::vector<char> in(n_vertices, 0);
    for (int n : set) in[n] = 1;
    for (const auto& [edge, id] : edge_node)
      if (in[edge.first] && in[edge.second]) set.push_back(id);
    std::sort(set.begin(), set.end());
  }
  std::map<int, int> partner;
  for (const auto& [p, q] : m.cyclic_pairs) partner[p] = q;
  std::vector<std::pair<int, int>> pairs = m.cyclic_pairs;
  for (const auto& [edge, id] : edge_node) {
    auto a = partner.find(edge.first), b = partner.find(edge.second);
    if (a == partner.end() || b == partner.end()) continue;
    const auto key = std::minmax(a->second, b->second);
    auto it = edge_node.find({key.first, key.second});
    if (it != edge_node.end()) pairs.emplace_back(id, it->second);
  }
  std::sort(pairs.begin(), pairs.end());
  m.cyclic_pairs = pairs;
  m.nodes = nodes;
  m.tets = tets10;
  m.element_order = 2;
}

}  // namespace

mesh::Mesh box_mesh(double lx, double ly, double lz, int nx, int ny, int nz, int element_order, double perturbation,
                    std::uint32_t seed) {
  SHROUDSIM_CHECK(nx > 0 && ny > 0 && nz > 0, "box_mesh: cell counts must be positive");
  SHROUDSIM_CHECK(element_order == 1 || element_order == 2, "box_mesh: order 1 or 2");
  const double hx = lx / nx, hy = ly / ny, hz = lz / nz;
  Grid g;
  g.ni = nx;
  g.nj = ny;
  g.nk = nz;
  g.keep = [](int, int, int) { return true; };
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-perturbation, perturbation);
  std::vector<Eigen::Vector3d> shift((nx + 1) * (ny + 1) * (nz + 1), Eigen::Vector3d::Zero());
  for (int i = 1; i < nx; ++i)
    for (int j = 1; j < ny; ++j)
      for (int k = 1; k < nz; ++k) shift[g.vertex_id(i, j, k)] = Eigen::Vector3d(u(rng) * hx, u(rng) * hy, u(rng) * hz);
  g.coord = [&](int i, int j, int k) -> Eigen::Vector3d {
    return Eigen::Vector3d(i * hx, j * hy, k * hz) + shift[g.vertex_id(i, j, k)];
  };
  Tet4Mesh t4 = build_tet4(g);
  mesh::Mesh m = std::move(t4.mesh);
  m.sectors = 1;
  m.node_sets[mesh::kHub] = vertex_set(t4, [](const Ijk& c) { return c[0] == 0; });
  if (element_order == 2) make_quadratic(m);
  return m;
}

mesh::Mesh annular_sector_mesh(const AnnularSectorSpec& s) {
  SHROUDSIM_CHECK(s.sectors >= 2 && s.n_r > 0 && s.n_theta > 0 && s.n_z > 0, "annular_sector_mesh: bad spec");
  SHROUDSIM_CHECK(s.blade_length <= 0.0 || (s.n_blade > 0 && s.n_theta >= 3),
                  "annular_sector_mesh: a blade needs n_blade > 0 and n_theta >= 3");
  const double alpha = 2.0 * std::numbers::pi / s.sectors;
  const bool blade = s.blade_length > 0.0;
  Grid g;
  g.ni = s.n_r + (blade ? s.n_blade : 0);
  g.nj = s.n_theta;
  g.nk = s.n_z;
  const int band_lo = s.n_theta / 3, band_hi = s.n_theta - s.n_theta / 3;
  g.keep = [&](int i, int j, int) { return i < s.n_r || (j >= band_lo && j < band_hi); };
  g.coord = [&](int i, int j, int k) {
    const double r = i <= s.n_r ? s.r_inner + i * (s.r_outer - s.r_inner) / s.n_r
                                : s.r_outer + (i - s.n_r) * s.blade_length / s.n_blade;
    // theta = alpha exactly on the high face, so that x_q = R(alpha) x_p up to rounding.
    const double theta = j == s.n_theta ? alpha : j * alpha / s.n_theta;
    return Eigen::Vector3d(r * std::cos(theta), r * std::sin(theta), k * s.thickness / s.n_z);
  };
  Tet4Mesh t4 = build_tet4(g);
  mesh::Mesh m = std::move(t4.mesh);
  m.sectors = s.sectors;
  m.node_sets[mesh::kHub] = vertex_set(t4, [](const Ijk& c) { return c[0] == 0; });
  m.node_sets[mesh::kCyclicLow] = vertex_set(t4, [](const Ijk& c) { return c[1] == 0; });
  m.node_sets[mesh::kCyclicHigh] = vertex_set(t4, [&](const Ijk& c) { return c[1] == s.n_theta; });
  m.node_sets[mesh::kShroudLow] = {};
  m.node_sets[mesh::kShroudHigh] = {};
  std::map<Ijk, int> high;
  for (int q : m.node_sets[mesh::kCyclicHigh]) high[t4.grid_index[q]] = q;
  for (int p : m.node_sets[mesh::kCyclicLow]) {
    Ijk c = t4.grid_index[p];
    c[1] = s.n_theta;
    m.cyclic_pairs.emplace_back(p, high.at(c));
  }
  std::sort(m.cyclic_pairs.begin(), m.cyclic_pairs.end());
  if (s.element_order == 2) make_quadratic(m);
  return m;
}

mesh::Mesh replicate_wheel(const mesh::Mesh& sector) {
  const int nb = sector.sectors;
  SHROUDSIM_CHECK(nb >= 1, "replicate_wheel: sectors must be >= 1");
  const int n = sector.n_nodes();
  std::vector<int> partner_low(n, -1);  // high node -> its low partner
  for (const auto& [p, q] : sector.cyclic_pairs) partner_low[q] = p;
  std::vector<int> kept_index(n, -1);
  int n_kept = 0;
  for (int v = 0; v < n; ++v)
    if (partner_low[v] < 0) kept_index[v] = n_kept++;
  auto wheel_node = [&](int k, int v) {
    if (partner_low[v] >= 0) return ((k + 1) % nb) * n_kept + kept_index[partner_low[v]];
    return k * n_kept + kept_index[v];
  };
  mesh::Mesh w;
  w.element_order = sector.element_order;
  w.sectors = 1;
  w.nodes.resize(static_cast<Eigen::Index>(nb) * n_kept, 3);
  w.tets.resize(static_cast<Eigen::Index>(nb) * sector.n_elements(), sector.nodes_per_element());
  std::vector<int> hub;
  for (int k = 0; k < nb; ++k) {
    const double a = 2.0 * std::numbers::pi * k / nb;
    Eigen::Matrix3d R;
    R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    for (int v = 0; v < n; ++v)
      if (kept_index[v] >= 0)
        w.nodes.row(k * n_kept + kept_index[v]) = (R * sector.nodes.row(v).transpose()).transpose();
    for (int e = 0; e < sector.n_elements(); ++e)
      for (int a2 = 0; a2 < sector.nodes_per_element(); ++a2)
        w.tets(k * sector.n_elements() + e, a2) = wheel_node(k, sector.tets(e, a2));
    if (sector.node_sets.count(mesh::kHub))
      for (int v : sector.node_set(mesh::kHub)) hub.push_back(wheel_node(k, v));
  }
  std::sort(hub.begin(), hub.end());
  hub.erase(std::unique(hub.begin(), hub.end()), hub.end());
  w.node_sets[mesh::kHub] = hub;
  return w;
}

}  // namespace shroudsim::fe
