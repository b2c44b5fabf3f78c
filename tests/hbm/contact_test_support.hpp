#pragma once
// Helpers shared by the hbm contact tests, the Jacobian-accuracy tool and the benchmarks:
// seeded random pair states on the scale of the contact, and the relative Jacobian error.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "contact/contact_law.hpp"
#include "hbm/harmonic_layout.hpp"

namespace shroudsim::testing {

/// A random relative motion on the contact's own scale: tangential harmonics of amplitude
/// U(0.2, 4) * mu N0/kt / n (from stick to gross slip), random phases and means; normal
/// motion of amplitude U(0, 2) N0/kn / n (partial separation included). Seeded.
inline Eigen::VectorXd random_contact_state(const hbm::HarmonicLayout& layout, const contact::PairParameters& p,
                                            std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double slip = p.friction_coefficient * std::abs(p.normal_preload) / p.tangential_stiffness;
  const double normal = std::abs(p.normal_preload) / p.normal_stiffness;
  const int m = layout.per_direction();
  Eigen::VectorXd w = Eigen::VectorXd::Zero(layout.size());
  for (int j = 0; j < layout.n_directions(); ++j) {
    const bool z = (j == 2);
    const double scale = z ? normal : slip;
    w[j * m] = (u01(rng) - 0.5) * scale;
    for (int n = 1; n <= layout.n_harmonics(); ++n) {
      const double amp = (z ? 2.0 * u01(rng) : 0.2 + 3.8 * u01(rng)) * scale / n;
      const double ph = 2.0 * std::numbers::pi * u01(rng);
      w[j * m + 2 * n - 1] = amp * std::cos(ph);
      w[j * m + 2 * n] = amp * std::sin(ph);
    }
  }
  return w;
}

/// ||J - J_ref||_F / ||J_ref||_F (absolute when J_ref = 0).
inline double relative_error(const Eigen::MatrixXd& j, const Eigen::MatrixXd& j_ref) {
  const double ref = j_ref.norm();
  return ref > 0.0 ? (j - j_ref).norm() / ref : (j - j_ref).norm();
}

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace shroudsim::testing
