#pragma once
// A cubic spring F = k3 w^3 on each of a set of one-directional "pairs", in harmonic balance
// by AFT (hbm/aft.hpp): the smooth nonlinearity of the Duffing oscillator, whose nonlinear
// mode has the closed-form first-harmonic backbone w^2 = w0^2 + (3/4) k3 a^2 / m
// (tests/nlmodes). Layout: one direction (x) per pair, [c0 | c1 s1 | ... | cH sH].
// Jacobian: dF/dW = analysis^T diag(3 k3 w(l)^2) synthesis, exact for the sampled map
// (and for the continuous one when N > 3H, where w^3 does not alias).
//
// Usage:
//   hbm::CubicSpring spring(/*harmonics=*/5, /*samples=*/64, {k3});
//   forced::NonlinearModeEquations eq(linear, spring);
#include <memory>

#include "hbm/aft.hpp"
#include "hbm/nonlinear_force.hpp"

namespace shroudsim::hbm {

class CubicSpring : public NonlinearForce {
 public:
  /// One pair per entry of k3 [N/m^3]; n_time_samples >= 2H+1 (3H+1 for no aliasing).
  CubicSpring(int n_harmonics, int n_time_samples, std::vector<double> k3);
  const HarmonicLayout& pair_layout() const override { return layout_; }
  int n_pairs() const override { return static_cast<int>(k3_.size()); }
  EvaluationStatus evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                            std::vector<Eigen::MatrixXd>* jacobian) override;

 private:
  HarmonicLayout layout_;
  std::vector<double> k3_;
  Aft aft_;
  Aft::Workspace ws_;
  Eigen::VectorXd samples_, weights_;
};

}  // namespace shroudsim::hbm
