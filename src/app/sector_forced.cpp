// The FE sector as the forced response sees it: modes of the harmonic indices the engine
// order reaches, shroud contact pairs with frames and tributary areas, excitation and
// response nodes (docs/physics.md sections 2 and 3).
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <tuple>
#include <sstream>

#include "app/forced_stage.hpp"
#include "app/modal_stage.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "io/output.hpp"
#include "frf/sector.hpp"

namespace shroudsim::app {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

int nearest_node(const mesh::Mesh& m, const std::array<double, 3>& p) {
  const Eigen::RowVector3d x(p[0], p[1], p[2]);
  Eigen::Index best = 0;
  (m.nodes.rowwise() - x).rowwise().squaredNorm().minCoeff(&best);
  return static_cast<int>(best);
}

struct FaceNode {
  int high = -1, low = -1;
  double area = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

/// Every matched shroud pair with its tributary area on shroud_high and its outward normal.
std::vector<FaceNode> shroud_face(const mesh::Mesh& m) {
  std::map<int, FaceNode> by_high;
  for (const auto& [p, q] : m.shroud_pairs) by_high[q] = FaceNode{q, p, 0.0, Eigen::Vector3d::Zero()};
  const auto& tris = m.surface_triangles.at(mesh::kShroudHigh);
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
  std::vector<FaceNode> out;
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

/// `count` nodes spread evenly over the face (farthest-point sampling from the centroid).
std::vector<int> spread(const mesh::Mesh& m, const std::vector<FaceNode>& face, int count) {
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
      dist[i] = std::min(dist[i], (m.nodes.row(face[i].high) - m.nodes.row(face[static_cast<std::size_t>(current)].high)).norm());
      if (dist[i] > far) far = dist[i], next = static_cast<int>(i);
    }
  }
  return chosen;
}

Eigen::Matrix3d frame_of(const Eigen::Vector3d& n, const Eigen::Vector3d& x, double angle) {
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

}  // namespace

ForcedModel make_sector_model(Context& ctx) {
  const io::Case& c = ctx.config;
  const int nb = c.structure.sectors, m = c.excitation.engine_order;
  std::set<int> needed;
  for (int n = 1; n <= c.hbm.harmonics; ++n) needed.insert(((n * m) % nb + nb) % nb);
  ModalModel modal = run_modal_stage(ctx, std::vector<int>(needed.begin(), needed.end()), /*keep_factors=*/true,
                                     c.excitation.speed_rpm);  // > 0: the modes at that speed
  if (!modal.failures.empty()) throw NumericalError("modal stage failed: " + modal.failures.front());
  const mesh::Mesh& mesh = modal.mesh;

  const std::vector<FaceNode> face = shroud_face(mesh);
  if (face.empty()) throw InputError(c.file.string() + ": the mesh has no matched shroud node pairs");
  const int count = c.contact.pairs == 0 ? static_cast<int>(face.size()) : c.contact.pairs;
  if (count > static_cast<int>(face.size()))
    throw InputError(c.locations.at("contact.pairs") + ": contact.pairs = " + std::to_string(count) +
                     " violates: pairs <= matched shroud node pairs of the mesh (" + std::to_string(face.size()) + ")");
  std::vector<int> chosen(face.size());
  for (std::size_t i = 0; i < face.size(); ++i) chosen[i] = static_cast<int>(i);
  if (count < static_cast<int>(face.size())) chosen = spread(mesh, face, count);
  // Each face node's area goes to the nearest chosen pair (its tributary share).
  std::vector<double> share(chosen.size(), 0.0);
  double total = 0.0;
  for (const auto& f : face) {
    std::size_t best = 0;
    double d_best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      const double d = (mesh.nodes.row(f.high) - mesh.nodes.row(face[static_cast<std::size_t>(chosen[k])].high)).norm();
      if (d < d_best) d_best = d, best = k;
    }
    share[best] += f.area;
    total += f.area;
  }

  ForcedModel model;
  std::vector<frf::SectorContactPair> pairs;
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const FaceNode& f = face[static_cast<std::size_t>(chosen[k])];
    frf::SectorContactPair p;
    p.high_node = f.high;
    p.low_node = f.low;
    p.frame = frame_of(f.normal, mesh.nodes.row(f.high).transpose(), c.contact.frame_angle_deg * kDeg);
    pairs.push_back(p);
    const double s = share[k] / total;
    contact::PairParameters pp;
    pp.friction_coefficient = c.contact.friction_coefficient;
    pp.tangential_stiffness = c.contact.tangential_stiffness * s;
    pp.normal_stiffness = c.contact.normal_stiffness * s;
    pp.normal_preload = c.contact.normal_preload * s;
    model.pairs.push_back(pp);
  }
  frf::SectorForcing forcing;
  forcing.engine_order = m;
  forcing.excitation_node = nearest_node(mesh, c.excitation.point);
  forcing.force = Eigen::Vector3d(c.excitation.force[0], c.excitation.force[1], c.excitation.force[2]);
  forcing.response_node = nearest_node(mesh, c.response.point);
  // A point whose nearest node is clamped, or that lies off the sector, would give a silent
  // zero (or meaningless) response: an input error naming the key.
  {
    const auto& hub = mesh.node_set("hub");
    const double size = (mesh.nodes.colwise().maxCoeff() - mesh.nodes.colwise().minCoeff()).norm();
    for (const auto& [key, point, node] : {std::tuple{std::string("excitation.point"), c.excitation.point, forcing.excitation_node},
                                           std::tuple{std::string("response.point"), c.response.point, forcing.response_node}}) {
      const Eigen::RowVector3d x(point[0], point[1], point[2]);
      const double distance = (mesh.nodes.row(node) - x).norm();
      const auto it = c.locations.find(key);
      const std::string where = it != c.locations.end() ? it->second : c.file.string();
      if (std::find(hub.begin(), hub.end(), node) != hub.end())
        throw InputError(where + ": " + key + ": the nearest node (" + std::to_string(node) +
                         ") is on the clamped hub: it does not move; give a point on the blade or shroud");
      if (distance > 0.1 * size)
        throw InputError(where + ": " + key + " is " + io::format_number(distance) + " m from the nearest node of the sector (" +
                         "model size " + io::format_number(size) + " m): give a point on the sector");
    }
  }
  forcing.damping_ratio = c.modal.damping_ratio;
  forcing.residual_flexibility = c.modal.residual_flexibility;
  log::Stopwatch clock;
  const cyclic::CyclicSector& sector = modal.cyclic();
  model.linear = std::make_unique<frf::SectorLinearPart>(
      sector, modal.bases, [&](int h) { return modal.stiffness_factor(h); }, pairs, forcing, c.hbm.harmonics);
  ctx.report.stage("receptances", clock.seconds());
  auto& j = ctx.report.section("frf_model");
  j["contact_pairs"] = pairs.size();
  j["shroud_pairs_available"] = face.size();
  j["contact_area_m2"] = total;
  j["excitation_node"] = forcing.excitation_node;
  j["response_node"] = forcing.response_node;
  j["harmonic_indices"] = std::vector<int>(needed.begin(), needed.end());
  std::ostringstream s;
  s << "frf: " << pairs.size() << " of " << face.size() << " shroud pairs, contact area " << total * 1e6
    << " mm^2; excitation node " << forcing.excitation_node << ", response node " << forcing.response_node;
  log::info(s.str());
  return model;
}

}  // namespace shroudsim::app
