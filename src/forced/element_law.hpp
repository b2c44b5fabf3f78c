#pragma once
// The contact law of one element in continuous time, shared by the time integration
// (forced/time_march.hpp) and the shooting (forced/shooting.hpp): docs/physics.md section 4
// without the sampling of the period.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "contact/contact_law.hpp"

namespace shroudsim::forced::detail {

// The step is far below the stick and slip time scales, so the slider update of the
// sampled law ("radial_return") is exact to O(dt).
struct ElementLaw {
  contact::PairParameters p;
  bool one_d = false, coupled = true;

  // w: x, y, z of the element; d: slider (x, y), updated; f: force (Tx, Ty, N).
  // at_limit (bit k: tangential direction k; the coupled law: any bit): the slider is put on
  // the friction limit along the trial force even where that force lies inside it (the
  // shooting's differences at a sliding contact, forced/shooting.cpp).
  void force(const double* w, double* d, double* f, unsigned at_limit = 0) const {
    const double kt = p.tangential_stiffness, mu = p.friction_coefficient;
    const double n = one_d ? std::max(0.0, p.normal_preload)
                           : std::max(0.0, p.normal_preload + p.normal_stiffness * w[2]);
    f[2] = one_d ? 0.0 : n;
    if (!(n > 0.0)) {  // separated: no force, the slider follows
      d[0] = w[0];
      d[1] = one_d ? 0.0 : w[1];
      f[0] = f[1] = 0.0;
      return;
    }
    const double limit = mu * n;
    if (one_d || !coupled) {
      for (int k = 0; k < (one_d ? 1 : 2); ++k) {
        const double t = kt * (w[k] - d[k]);
        if ((std::abs(t) <= limit && ((at_limit >> k) & 1U) == 0) || t == 0.0) {
          f[k] = t;
        } else {
          f[k] = std::copysign(limit, t);
          d[k] = w[k] - f[k] / kt;
        }
      }
      if (one_d) f[1] = 0.0;
      return;
    }
    const double tx = kt * (w[0] - d[0]), ty = kt * (w[1] - d[1]);
    const double t = std::hypot(tx, ty);
    if (t <= limit && (at_limit == 0 || t == 0.0)) {
      f[0] = tx;
      f[1] = ty;
    } else {
      f[0] = limit * tx / t;
      f[1] = limit * ty / t;
      d[0] = w[0] - f[0] / kt;
      d[1] = w[1] - f[1] / kt;
    }
  }
};

/// The forces the structure already carries (contact.normal_preload = "static"), per contact
/// row (x, y, z of each element): max(0, N0) normal, for the 3D laws.
inline Eigen::VectorXd static_load(const std::vector<contact::PairParameters>& pairs, bool one_d) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t e = 0; e < pairs.size(); ++e)
    if (pairs[e].preload_in_equilibrium && !one_d)
      f[3 * static_cast<Eigen::Index>(e) + 2] = std::max(0.0, pairs[e].normal_preload);
  return f;
}

/// The steps one excitation period needs: at least min_steps_per_period, and
/// steps_per_stiff_period per period of the stuck system's highest mode w_max [rad/s].
inline double steps_needed(int min_steps_per_period, double steps_per_stiff_period, double w_max, double w) {
  return std::max(static_cast<double>(min_steps_per_period), steps_per_stiff_period * w_max / w);
}

/// The explicit scheme's step options, as the time integration and the shooting both take them:
/// appends one message per violated constraint; true when valid.
inline bool valid_steps(int min_steps_per_period, double steps_per_stiff_period, std::vector<std::string>* errors) {
  bool ok = true;
  if (min_steps_per_period < 16) {
    ok = false;
    if (errors) errors->push_back("min_steps_per_period >= 16");
  }
  if (!(steps_per_stiff_period >= 8.0) || !std::isfinite(steps_per_stiff_period)) {
    ok = false;
    if (errors) errors->push_back("steps_per_stiff_period >= 8 (the scheme is unstable from pi steps on)");
  }
  return ok;
}

}  // namespace shroudsim::forced::detail
