#include "frf/contact_patches.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace shroudsim::frf {

std::vector<ShroudFaceNode> shroud_face(const mesh::Mesh& m) {
  std::map<int, ShroudFaceNode> by_high;
  for (const auto& [p, q] : m.shroud_pairs) by_high[q] = ShroudFaceNode{q, p, 0.0, Eigen::Vector3d::Zero()};
  const auto it_tris = m.surface_triangles.find(mesh::kShroudHigh);
  if (it_tris != m.surface_triangles.end()) {
    const auto& tris = it_tris->second;
    for (Eigen::Index t = 0; t < tris.rows(); ++t) {
      const Eigen::Vector3d a = m.nodes.row(tris(t, 0)), b = m.nodes.row(tris(t, 1)), c = m.nodes.row(tris(t, 2));
      const Eigen::Vector3d cross = (b - a).cross(c - a);
      const double area = 0.5 * cross.norm();
      // Tributary areas: linear triangles A/3 per corner; quadratic ones split into four
      // linear triangles: corners A/12, midside nodes A/4.
      for (int k = 0; k < tris.cols(); ++k) {
        auto it = by_high.find(tris(t, k));
        if (it == by_high.end()) continue;
        it->second.area += tris.cols() == 3 ? area / 3.0 : (k < 3 ? area / 12.0 : area / 4.0);
        it->second.normal += cross;  // area-weighted, sign fixed below
      }
    }
  }
  std::vector<ShroudFaceNode> out;
  for (auto& [q, f] : by_high) {
    // Outward of shroud_high = towards the next sector (+theta).
    const Eigen::Vector3d x = m.nodes.row(q);
    const Eigen::Vector3d e_theta(-x.y(), x.x(), 0.0);
    if (f.normal.dot(e_theta) < 0) f.normal = -f.normal;
    if (f.normal.norm() > 0) f.normal.normalize();
    out.push_back(f);
  }
  return out;
}

namespace {

/// `count` face indices spread evenly over the face (farthest-point sampling from the node
/// nearest the area centroid).
std::vector<int> spread(const mesh::Mesh& m, const std::vector<ShroudFaceNode>& face, int count) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (const auto& f : face) centroid += f.area * m.nodes.row(f.high).transpose(), total += f.area;
  centroid /= total;
  std::vector<double> dist(face.size(), std::numeric_limits<double>::infinity());
  std::vector<int> chosen;
  int next = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < face.size(); ++i) {
    const double d = (m.nodes.row(face[i].high).transpose() - centroid).norm();
    if (d < best) best = d, next = static_cast<int>(i);
  }
  while (static_cast<int>(chosen.size()) < count) {
    chosen.push_back(next);
    const int current = next;
    double far = -1.0;
    for (std::size_t i = 0; i < face.size(); ++i) {
      dist[i] = std::min(
          dist[i], (m.nodes.row(face[i].high) - m.nodes.row(face[static_cast<std::size_t>(current)].high)).norm());
      if (dist[i] > far) far = dist[i], next = static_cast<int>(i);
    }
  }
  return chosen;
}

}  // namespace

std::vector<ContactPatch> partition_face(const mesh::Mesh& m, const std::vector<ShroudFaceNode>& face, int count) {
  const int n = static_cast<int>(face.size());
  if (n == 0) throw std::invalid_argument("the mesh has no matched shroud node pairs");
  if (count < 0 || count > n)
    throw std::invalid_argument("pairs = " + std::to_string(count) +
                                " violates: pairs <= matched shroud node pairs of the mesh (" + std::to_string(n) +
                                ")");
  std::vector<int> seeds(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) seeds[static_cast<std::size_t>(i)] = i;
  if (count != 0 && count < n) seeds = spread(m, face, count);
  std::vector<ContactPatch> patches(seeds.size());
  for (std::size_t k = 0; k < seeds.size(); ++k) patches[k].seed = seeds[k];
  // Each face node goes to its nearest seed (ties: the first seed chosen).
  for (int i = 0; i < n; ++i) {
    std::size_t best = 0;
    double d_best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < seeds.size(); ++k) {
      const double d = (m.nodes.row(face[static_cast<std::size_t>(i)].high) -
                        m.nodes.row(face[static_cast<std::size_t>(seeds[k])].high))
                           .norm();
      if (d < d_best) d_best = d, best = k;
    }
    patches[best].members.push_back(i);
  }
  for (ContactPatch& p : patches) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int i : p.members) {
      p.area += face[static_cast<std::size_t>(i)].area;
      normal += face[static_cast<std::size_t>(i)].area * face[static_cast<std::size_t>(i)].normal;
    }
    for (int i : p.members)
      p.weights.push_back(p.area > 0 ? face[static_cast<std::size_t>(i)].area / p.area
                                     : 1.0 / static_cast<double>(p.members.size()));
    // A single pair keeps its own (already unit) normal: the node form, bit for bit.
    if (p.members.size() == 1 || !(normal.norm() > 0)) normal = face[static_cast<std::size_t>(p.seed)].normal;
    else normal.normalize();
    p.normal = normal;
  }
  return patches;
}

std::string to_string(ContactDiscretization d) { return d == ContactDiscretization::nodes ? "nodes" : "patches"; }

Eigen::Matrix3d contact_frame(const Eigen::Vector3d& n, const Eigen::Vector3d& x, double angle) {
  Eigen::Vector3d t1 = Eigen::Vector3d::UnitZ() - n.z() * n;  // axial direction in the plane
  if (t1.norm() < 0.1) t1 = Eigen::Vector3d(x.x(), x.y(), 0.0) - n.dot(Eigen::Vector3d(x.x(), x.y(), 0.0)) * n;
  t1.normalize();
  const Eigen::Vector3d t2 = n.cross(t1);
  Eigen::Matrix3d l;
  l.row(0) = std::cos(angle) * t1 + std::sin(angle) * t2;
  l.row(1) = -std::sin(angle) * t1 + std::cos(angle) * t2;
  l.row(2) = n;
  return l;
}

std::vector<cyclic::InterfaceSpring> face_springs(const mesh::Mesh& m, const std::vector<ShroudFaceNode>& face,
                                                  double normal_stiffness, double tangential_stiffness,
                                                  double frame_angle) {
  double area = 0.0;
  for (const auto& f : face) area += f.area;
  if (face.empty() || !(area > 0))
    throw std::invalid_argument("the mesh has no matched shroud_high/shroud_low node pairs");
  std::vector<cyclic::InterfaceSpring> springs;
  springs.reserve(face.size());
  for (const auto& f : face) {
    cyclic::InterfaceSpring sp;
    sp.high_node = f.high;
    sp.low_node = f.low;
    sp.frame = contact_frame(f.normal, m.nodes.row(f.high).transpose(), frame_angle);
    sp.stiffness = Eigen::Vector3d(tangential_stiffness, tangential_stiffness, normal_stiffness) * (f.area / area);
    springs.push_back(sp);
  }
  return springs;
}

std::vector<SectorContactPair> contact_pairs(const mesh::Mesh& m, const std::vector<ShroudFaceNode>& face,
                                             const std::vector<ContactPatch>& patches,
                                             ContactDiscretization discretization, double frame_angle) {
  std::vector<SectorContactPair> pairs;
  for (const ContactPatch& p : patches) {
    const ShroudFaceNode& seed = face[static_cast<std::size_t>(p.seed)];
    SectorContactPair c;
    c.high_node = seed.high;
    c.low_node = seed.low;
    // A single-member patch's normal is its seed's (partition_face): the node form exactly.
    const bool spread = discretization == ContactDiscretization::patches && p.members.size() > 1;
    c.frame = contact_frame(spread ? p.normal : seed.normal, m.nodes.row(seed.high).transpose(), frame_angle);
    if (spread) {
      for (std::size_t k = 0; k < p.members.size(); ++k) {
        const ShroudFaceNode& f = face[static_cast<std::size_t>(p.members[k])];
        c.patch.push_back({f.high, f.low, p.weights[k]});
      }
    }
    pairs.push_back(std::move(c));
  }
  return pairs;
}

}  // namespace shroudsim::frf
