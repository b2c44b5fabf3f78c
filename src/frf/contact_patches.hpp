#pragma once
// The shroud contact face as the forced response discretizes it (docs/physics.md section 3,
// "Contact patches").
//
// The matched node pairs of the face (shroud_high node q, shroud_low node p, x_q = R x_p)
// carry tributary areas a_i (quadratic triangles: corners A/12, midside nodes A/4) and
// area-weighted outward normals. `contact.pairs = K` splits the face into K patches: K seed
// pairs spread evenly by farthest-point sampling from the area centroid, every face node
// going to its nearest seed (a Voronoi partition of the face nodes). Then either
//  - patches (the default): one contact element per patch, acting on the area-weighted mean
//    relative displacement of its node pairs, W_P = L_P sum_i (a_i / A_P) w_i, with the
//    patch frame L_P from the area-weighted mean normal; its force F_P is spread back over
//    the same node pairs with the transposed weights, so the virtual work F_P . dW_P is that
//    of the nodal forces (an RBE3-like interpolation). A point load on a continuum has a
//    displacement that grows without bound as the elements shrink; a patch's mean does not,
//    so the response converges under mesh refinement;
//  - nodes (the paper's model): the element acts at the seed pair alone, with the patch's
//    share of stiffness and preload.
// Either way a patch of area A_P gets kt A_P / A, kn A_P / A and N0 A_P / A of the face's
// totals. K = "all" gives one pair per patch, and both forms coincide bit for bit.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "frf/sector.hpp"
#include "mesh/mesh.hpp"

namespace shroudsim::frf {

/// One matched node pair of the shroud face.
struct ShroudFaceNode {
  int high = -1, low = -1;                           ///< q on shroud_high, p on shroud_low
  double area = 0.0;                                 ///< tributary area on shroud_high [m^2]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, outward of shroud_high (+theta)
};

/// Every matched shroud pair (ordered by its high node) with area and normal.
std::vector<ShroudFaceNode> shroud_face(const mesh::Mesh& mesh);

struct ContactPatch {
  int seed = -1;                                     ///< index into the face of the patch's seed pair
  std::vector<int> members;                          ///< indices into the face, ascending
  std::vector<double> weights;                       ///< a_i / A_P of each member (sum 1)
  double area = 0.0;                                 ///< A_P [m^2]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit area-weighted mean normal
};

/// The face split into `count` patches (count = face size, or 0: one patch per pair).
/// Throws std::invalid_argument when count is out of 0..face size or the face is empty.
std::vector<ContactPatch> partition_face(const mesh::Mesh& mesh, const std::vector<ShroudFaceNode>& face, int count);

enum class ContactDiscretization { patches, nodes };
std::string to_string(ContactDiscretization d);  ///< "patches", "nodes" (contact.discretization)

/// The frame [t1; t2; n] (rows) at a point x of the face with unit normal n: t1 the axial
/// direction projected on the contact plane (the radial one where the normal is nearly
/// axial), t2 = n x t1, both turned about n by `angle` [rad].
Eigen::Matrix3d contact_frame(const Eigen::Vector3d& normal, const Eigen::Vector3d& x, double angle);

/// One spring per face pair across the sector boundary (the stuck shroud, docs/physics.md
/// sections 1 and 8): stiffness (kt, kt, kn) a_i / A of the face's totals (A the face area),
/// in the pair's contact frame turned by frame_angle [rad]. Same order as the face. Throws
/// std::invalid_argument when the face is empty or has no area.
std::vector<cyclic::InterfaceSpring> face_springs(const mesh::Mesh& mesh, const std::vector<ShroudFaceNode>& face,
                                                  double normal_stiffness, double tangential_stiffness,
                                                  double frame_angle);

/// One SectorContactPair per patch, in the given discretization; frames turned by
/// frame_angle [rad]. A single-member patch is exactly the node pair of the node form.
std::vector<SectorContactPair> contact_pairs(const mesh::Mesh& mesh, const std::vector<ShroudFaceNode>& face,
                                             const std::vector<ContactPatch>& patches,
                                             ContactDiscretization discretization, double frame_angle);

}  // namespace shroudsim::frf
