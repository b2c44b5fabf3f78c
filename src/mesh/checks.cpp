#include "mesh/checks.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

namespace shroudsim::mesh {

Eigen::Matrix3d rotation_z(double angle) {
  Eigen::Matrix3d r;
  const double c = std::cos(angle), s = std::sin(angle);
  r << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return r;
}

double model_size(const NodeMatrix& nodes) {
  if (nodes.rows() == 0) return 0.0;
  return (nodes.colwise().maxCoeff() - nodes.colwise().minCoeff()).norm();
}

namespace {

/// Uniform hash grid over a point cloud for nearest-neighbour queries.
class PointGrid {
 public:
  PointGrid(const NodeMatrix& nodes, const std::vector<int>& ids) : nodes_(nodes), ids_(ids) {
    if (ids.empty()) return;
    Eigen::RowVector3d lo = nodes.row(ids[0]), hi = lo;
    for (int id : ids) {
      lo = lo.cwiseMin(nodes.row(id));
      hi = hi.cwiseMax(nodes.row(id));
    }
    origin_ = lo;
    // About two points per cell on a surface point set.
    extent_ = std::max((hi - lo).norm(), 1e-300);
    cell_ = extent_ / std::max(1.0, std::sqrt(static_cast<double>(ids.size()) / 2.0));
    for (int id : ids) cells_[key(cell_of(nodes.row(id)))].push_back(id);
  }

  /// Nearest point of the set to x (searching outward ring by ring), and its distance.
  std::pair<int, double> nearest(const Eigen::RowVector3d& x) const {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    if (ids_.empty()) return {best, best_d};
    const Eigen::Vector3i c = cell_of(x);
    const int max_ring = static_cast<int>(std::ceil(((x - origin_).norm() + extent_) / cell_)) + 2;
    for (int ring = 0;; ++ring) {
      for (int i = -ring; i <= ring; ++i)
        for (int j = -ring; j <= ring; ++j)
          for (int k = -ring; k <= ring; ++k) {
            if (std::max({std::abs(i), std::abs(j), std::abs(k)}) != ring) continue;
            auto it = cells_.find(key(c + Eigen::Vector3i(i, j, k)));
            if (it == cells_.end()) continue;
            for (int id : it->second) {
              const double d = (nodes_.row(id) - x).norm();
              if (d < best_d) best_d = d, best = id;
            }
          }
      // Every point outside the searched rings is farther than ring * cell_.
      if ((best >= 0 && best_d <= ring * cell_) || ring >= max_ring) break;
    }
    return {best, best_d};
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::RowVector3d& x) const {
    return ((x - origin_) / cell_).array().floor().cast<int>().transpose();
  }
  static long long key(const Eigen::Vector3i& c) {
    return (static_cast<long long>(c.x() & 0x1FFFFF) << 42) | (static_cast<long long>(c.y() & 0x1FFFFF) << 21) |
           static_cast<long long>(c.z() & 0x1FFFFF);
  }
  const NodeMatrix& nodes_;
  const std::vector<int>& ids_;
  Eigen::RowVector3d origin_ = Eigen::RowVector3d::Zero();
  double cell_ = 1.0;
  double extent_ = 1.0;
  std::unordered_map<long long, std::vector<int>> cells_;
};

}  // namespace

NodeMatch match_rotated_nodes(const NodeMatrix& nodes, const std::vector<int>& low, const std::vector<int>& high,
                              double angle, double tolerance) {
  NodeMatch m;
  const Eigen::Matrix3d r = rotation_z(angle);
  const PointGrid grid(nodes, high);
  std::vector<int> used(nodes.rows(), 0);
  bool one_to_one = true;
  for (int p : low) {
    const Eigen::RowVector3d x = (r * nodes.row(p).transpose()).transpose();
    const auto [q, d] = grid.nearest(x);
    if (q < 0) {
      one_to_one = false;
      m.worst_distance = std::numeric_limits<double>::infinity();
      m.worst_low = p;
      continue;
    }
    if (used[q]++) one_to_one = false;
    m.pairs.emplace_back(p, q);
    if (d > m.worst_distance || m.worst_low < 0) {
      m.worst_distance = d;
      m.worst_low = p;
      m.worst_high = q;
    }
  }
  m.complete = one_to_one && low.size() == high.size() && !low.empty() && m.worst_distance <= tolerance;
  return m;
}

namespace {

// Gradients of the 10-node shape functions at barycentric point (l0, l1, l2, l3) with
// respect to (l1, l2, l3) as independent coordinates (l0 = 1 - l1 - l2 - l3).
// Returns the 3x3 Jacobian dx/d(l1,l2,l3) of the element map at that point.
Eigen::Matrix3d jacobian_at(const NodeMatrix& nodes, const int* conn, int npe, const double l[4]) {
  // dN_a/dl_i for the complete barycentric set, then chain rule with dl0 = -(dl1+dl2+dl3).
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  auto add = [&](int node, const Eigen::Vector4d& dn_dl) {
    // derivative wrt independent (l1,l2,l3): dN/dlk - dN/dl0
    const Eigen::Vector3d g(dn_dl[1] - dn_dl[0], dn_dl[2] - dn_dl[0], dn_dl[3] - dn_dl[0]);
    j += nodes.row(node).transpose() * g.transpose();
  };
  if (npe == 4) {
    for (int a = 0; a < 4; ++a) add(conn[a], Eigen::Vector4d::Unit(a));
    return j;
  }
  static const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
  for (int a = 0; a < 4; ++a) add(conn[a], (4.0 * l[a] - 1.0) * Eigen::Vector4d::Unit(a));
  for (int e = 0; e < 6; ++e) {
    const int a = edge[e][0], b = edge[e][1];
    add(conn[4 + e], 4.0 * (l[b] * Eigen::Vector4d::Unit(a) + l[a] * Eigen::Vector4d::Unit(b)));
  }
  return j;
}

}  // namespace

QualityStats element_quality(const Mesh& mesh) {
  QualityStats q;
  const int ne = mesh.n_elements(), npe = mesh.nodes_per_element();
  if (ne == 0) return q;
  // Sample points: vertices, edge midpoints, centroid (sign of det J for quadratic maps).
  std::vector<std::array<double, 4>> samples;
  for (int a = 0; a < 4; ++a) {
    std::array<double, 4> l{0, 0, 0, 0};
    l[a] = 1.0;
    samples.push_back(l);
  }
  if (npe == 10) {
    static const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {2, 3}, {1, 3}};
    for (const auto& e : edge) {
      std::array<double, 4> l{0, 0, 0, 0};
      l[e[0]] = l[e[1]] = 0.5;
      samples.push_back(l);
    }
  }
  samples.push_back({0.25, 0.25, 0.25, 0.25});
  // Degree-2 rule (4 points) for the volume of curved quadratic elements.
  const double qa = 0.5854101966249685, qb = 0.1381966011250105;
  const double rule[4][4] = {{qa, qb, qb, qb}, {qb, qa, qb, qb}, {qb, qb, qa, qb}, {qb, qb, qb, qa}};

  std::vector<double> volumes(ne);
  double sum_ratio = 0.0;
  for (int e = 0; e < ne; ++e) {
    const int* c = mesh.tets.row(e).data();
    double dmin = std::numeric_limits<double>::infinity(), dmax = -dmin;
    for (const auto& l : samples) {
      const double d = jacobian_at(mesh.nodes, c, npe, l.data()).determinant();
      dmin = std::min(dmin, d), dmax = std::max(dmax, d);
    }
    if (dmin <= 0.0) ++q.inverted;
    q.min_jacobian_ratio = std::min(q.min_jacobian_ratio, dmax > 0 ? dmin / dmax : -1.0);
    double vol = 0.0;
    if (npe == 4) {
      vol = jacobian_at(mesh.nodes, c, npe, samples[4].data()).determinant() / 6.0;
    } else {
      for (const auto& l : rule) vol += jacobian_at(mesh.nodes, c, npe, l).determinant() / 24.0;
    }
    volumes[e] = vol;
    q.volume += vol;
    // Mean ratio of the corner tetrahedron: 12 (3|V|)^(2/3) / sum of squared edge lengths.
    double l2 = 0.0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) l2 += (mesh.nodes.row(c[a]) - mesh.nodes.row(c[b])).squaredNorm();
    const Eigen::Matrix3d jc = jacobian_at(mesh.nodes, c, 4, samples[4].data());
    const double vc = jc.determinant() / 6.0;
    const double ratio = l2 > 0 ? 12.0 * std::cbrt(9.0 * vc * vc) / l2 * (vc > 0 ? 1.0 : -1.0) : 0.0;
    q.min_mean_ratio = std::min(q.min_mean_ratio, ratio);
    sum_ratio += ratio;
    if (ratio < 0.1) ++q.below_0_1;
  }
  q.mean_mean_ratio = sum_ratio / ne;
  const double mean_volume = q.volume / ne;
  for (double v : volumes)
    if (std::abs(v) < 1e-12 * std::abs(mean_volume)) ++q.degenerate;
  return q;
}

std::string describe(const QualityStats& q) {
  std::ostringstream s;
  s.precision(3);
  s << "quality (mean ratio) min " << q.min_mean_ratio << " mean " << q.mean_mean_ratio << ", " << q.below_0_1
    << " below 0.1; min detJ ratio " << q.min_jacobian_ratio << "; inverted " << q.inverted << ", degenerate "
    << q.degenerate;
  return s.str();
}

}  // namespace shroudsim::mesh
