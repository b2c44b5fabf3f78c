#pragma once
// The nonlinear forces of the harmonic balance as the nonlinear-mode solver
// (forced/nonlinear_modes.hpp) sees them: independent "pairs", each with the relative
// displacement W_p in real harmonic coefficients (pair_layout() order, [x | y | z] blocks
// of [c0 | c1 s1 | ... | cH sH]) and its force F_p(W_p) with the block dF_p/dW_p.
// hbm::ContactEvaluator (the friction contacts) implements it; hbm::CubicSpring (a cubic
// spring by AFT, hbm/cubic_spring.hpp) is the smooth reference of the tests.
#include <Eigen/Core>
#include <vector>

#include "hbm/harmonic_layout.hpp"

namespace shroudsim::hbm {

struct EvaluationStatus {
  int unconverged_pairs = 0;  ///< pairs whose damper state did not repeat within max_periods
  int max_periods = 0;        ///< largest number of periods any pair used
};

class NonlinearForce {
 public:
  virtual ~NonlinearForce() = default;
  virtual const HarmonicLayout& pair_layout() const = 0;
  virtual int n_pairs() const = 0;
  /// Length of W and F: n_pairs() * pair_layout().size().
  int n_unknowns() const { return n_pairs() * pair_layout().size(); }
  /// f = F(w); with jacobian != nullptr also the per-pair blocks dF_p/dW_p.
  virtual EvaluationStatus evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                                    std::vector<Eigen::MatrixXd>* jacobian) = 0;
  /// F_s (3 per pair, complex as the linear part's contact vectors): the static forces the
  /// structure already carries about the state W = 0 is measured from (docs/physics.md
  /// section 3); the static harmonic balances F_0 - F_s. Default: none.
  virtual Eigen::VectorXcd static_load() const { return Eigen::VectorXcd::Zero(3 * n_pairs()); }
  /// A displacement on which the force's behaviour at rest changes (a contact's slip or
  /// lift-off displacement; the largest over the pairs) [m], for probing the force near rest;
  /// 0: none (a smooth force).
  virtual double rest_displacement() const { return 0.0; }
};

}  // namespace shroudsim::hbm
