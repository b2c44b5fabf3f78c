#pragma once
// Static contact of the shroud pairs at speed (docs/physics.md section 8): unilateral
// normal contact with an interference and Coulomb friction, solved on the contact unknowns.
//
// Per pair i the relative displacement g_i = (g_t1, g_t2, g_n) in its frame (section 3,
// g_n > 0 presses) gives the forces
//   N = kn max(0, delta + g_n)                       (delta: overlap at rest, < 0 a gap),
//   T = kt (g_t - s),  |T| <= mu N                   (s: the slider, carried between steps),
// and the sector answers to them through its exact static flexibility C (3P x 3P, h = 0):
//   g = g_ext - C F(g),
// g_ext the contact motion of the unloaded sector under the external (centrifugal) load.
// The load is applied in increments (the friction state depends on the path); each
// increment is a nonsmooth Newton solve of r(g) = g - g_ext + C F(g) with the exact
// generalized Jacobian I + C dF/dg and a backtracking line search on |r|.
//
// Usage:
//   contact::StaticContact sc(pairs);                          // kn, kt, mu, delta per pair
//   for (k = 1..n) sc.solve(C_k, g_ext_k);                     // increments, state kept
//   sc.result().pairs[i].state / .force / .gap
#include <Eigen/Core>
#include <string>
#include <vector>

namespace shroudsim::contact {

struct StaticPairParameters {
  double normal_stiffness = 0.0;      ///< kn [N/m] > 0
  double tangential_stiffness = 0.0;  ///< kt [N/m] > 0
  double friction_coefficient = 0.0;  ///< mu >= 0
  double interference = 0.0;          ///< delta [m]: overlap at rest (negative: gap)
};

enum class StaticState { open, stick, slip };
std::string to_string(StaticState s);

struct StaticPairResult {
  Eigen::Vector3d g = Eigen::Vector3d::Zero();       ///< relative displacement (t1, t2, n) [m]
  Eigen::Vector3d force = Eigen::Vector3d::Zero();   ///< (T1, T2, N) [N]
  Eigen::Vector2d slider = Eigen::Vector2d::Zero();  ///< s [m]
  StaticState state = StaticState::open;
  double gap = 0.0;  ///< -(delta + g_n) when open, 0 when closed [m]
};

struct StaticStep {
  bool converged = false;
  int newton_iterations = 0;
  double residual = 0.0;  ///< |r|_inf / scale at the end
  std::string message;
};

class StaticContact {
 public:
  /// Throws std::invalid_argument for a non-positive stiffness, a negative friction
  /// coefficient or a non-finite value.
  explicit StaticContact(std::vector<StaticPairParameters> pairs);

  int n_pairs() const { return static_cast<int>(pairs_.size()); }
  /// One load increment: solves g = g_ext - C F(g) from the current state (the previous
  /// increment's g as the first guess) and, when it converges, makes the result the new
  /// state (sliders moved). C: 3P x 3P symmetric positive semidefinite, g_ext: 3P.
  StaticStep solve(const Eigen::MatrixXd& C, const Eigen::VectorXd& g_ext, int max_iterations = 100);
  const std::vector<StaticPairResult>& pairs() const { return state_; }
  /// The contact forces F (3P), as stored in pairs().
  Eigen::VectorXd forces() const;

  /// Forces of pair i at g with the slider s (the law above) and, if dF is not null,
  /// dF/dg (3 x 3, the derivative of the branch the state is on).
  static Eigen::Vector3d law(const StaticPairParameters& p, const Eigen::Vector3d& g, const Eigen::Vector2d& s,
                             StaticState* state, Eigen::Matrix3d* dF);

 private:
  std::vector<StaticPairParameters> pairs_;
  std::vector<StaticPairResult> state_;
};

}  // namespace shroudsim::contact
