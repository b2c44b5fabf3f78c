#pragma once
// A small lumped model with several contact pairs, shared by the forced-response tests:
// three point masses (x, y, z each: 9 DOFs) on springs to ground and to each other, modes
// near 8 to 30 Hz, 1 % stiffness-proportional damping, each mass with a full3d contact to
// ground (frames turned by 0, 0.2, 0.4 rad); 1 N on DOF 0, response at DOF 3.
#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <vector>

#include "contact/contact_law.hpp"
#include "frf/lumped.hpp"

namespace shroudsim::forced::testing {

inline frf::LumpedLinearPart three_contacts_linear() {
  const int n = 9;
  Eigen::MatrixXd m = Eigen::MatrixXd::Identity(n, n), k = Eigen::MatrixXd::Zero(n, n);
  const double k0 = std::pow(2 * std::numbers::pi * 8.0, 2);
  for (int node = 0; node < 3; ++node)
    for (int d = 0; d < 3; ++d) {
      const int i = 3 * node + d;
      k(i, i) += k0 * (1.0 + 0.3 * d);
      if (node < 2) {  // spring to the next mass, same direction
        const int j = i + 3;
        k(i, i) += 2 * k0, k(j, j) += 2 * k0, k(i, j) -= 2 * k0, k(j, i) -= 2 * k0;
      }
    }
  std::vector<frf::LumpedContact> contacts;
  for (int node = 0; node < 3; ++node) {
    frf::LumpedContact c;
    c.dof = {3 * node, 3 * node + 1, 3 * node + 2};
    c.frame_angle = 0.2 * node;
    contacts.push_back(c);
  }
  return frf::LumpedLinearPart(m, k, 1e-3 * k, contacts, 0, 1.0, 3);
}

inline std::vector<contact::PairParameters> three_contacts_pairs() {
  std::vector<contact::PairParameters> pairs;
  for (int i = 0; i < 3; ++i) {
    contact::PairParameters p;
    p.tangential_stiffness = 2000.0 * (1 + i);
    p.normal_stiffness = 3000.0;
    p.friction_coefficient = 0.3;
    p.normal_preload = 0.5;
    pairs.push_back(p);
  }
  return pairs;
}

}  // namespace shroudsim::forced::testing
