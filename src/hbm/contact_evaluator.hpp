#pragma once
// Harmonic balance contact forces of many independent pairs at once, with their
// block-diagonal Jacobian (docs/physics.md sections 4-5). The forced-response solver calls
// evaluate() thousands of times per frequency curve: all scratch (time samples, derivative
// rows, FFTW buffers) and the FFTW plans are made once here and reused; pairs are evaluated
// in parallel (OpenMP when available), each thread with its own workspace.
//
// Unknowns: the relative displacement W of every pair in real harmonic coefficients [m],
// pairs one after the other, each in pair_layout() order [x block | y block | z block]
// (1 block, x only, for the 1d models), each block [c0 | c1 s1 | ... | cH sH].
// Output F [N] in the same layout; Jacobian: one block dF_p/dW_p [N/m] per pair,
// pair_layout().size() squared (3(2H+1) or 2H+1), the rest of dF/dW is zero.
//
// Not re-entrant: one evaluate()/evaluate_pair() call at a time per evaluator (the calls
// share its workspaces; the parallelism is inside, over pairs).
//
// Usage:
//   hbm::ContactEvaluator ev({.n_harmonics = 5, .n_time_samples = 512}, pairs);
//   Eigen::VectorXd f;  std::vector<Eigen::MatrixXd> J;
//   const auto status = ev.evaluate(w, f, &J);   // status.unconverged_pairs == 0 normally
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "contact/periodic_law.hpp"
#include "hbm/aft.hpp"
#include "hbm/harmonic_layout.hpp"
#include "hbm/nonlinear_force.hpp"

namespace shroudsim::hbm {

enum class JacobianMethod {
  analytic,           ///< differentiated time recursion, Fourier-projected (the default)
  finite_difference,  ///< central differences of the same discrete map (2 P residuals per pair)
  /// Central differences of the whole contact-force vector: every unknown perturbed in turn
  /// and all pairs evaluated each time (2 n evaluations of every pair per Jacobian), the
  /// block-diagonal structure not used. The finite-difference Jacobian as commonly written
  /// (the paper's Example 4 compares against it); for comparison only, it is slow.
  finite_difference_full
};
/// "analytic", "finite_difference", "finite_difference_full" (hbm.jacobian)
std::string to_string(JacobianMethod method);

struct ContactEvaluatorOptions {
  int n_harmonics = 5;       ///< H >= 0 (1d_exact: H = 1)
  int n_time_samples = 512;  ///< N >= 2H+1 (not used by 1d_exact)
  contact::LawOptions law;   ///< model, tangential update, steady-state iteration
  JacobianMethod jacobian = JacobianMethod::analytic;
  double fd_relative_step = 1e-6;  ///< central-difference step / max|W_pair| (see fd_step)
  int threads = 0;                 ///< 0: OpenMP default, 1: serial
  bool measure_plans = true;       ///< FFTW_MEASURE planning

  /// One message per violated constraint, keys named as in docs/contract.md where they map.
  bool validate(std::vector<std::string>* errors) const;
};

/// Everything about one pair's evaluation (for `shroudsim contact` and the plots).
struct PairDetail {
  Eigen::MatrixX3d w;        ///< N x 3 relative displacement samples [m] (x, y, z)
  Eigen::MatrixX3d f;        ///< N x 3 force samples (Tx, Ty, N) [N]
  Eigen::VectorXd force;     ///< force harmonics, pair_layout() order [N]
  Eigen::MatrixXd jacobian;  ///< dF/dW [N/m] (empty unless asked for)
  contact::PeriodicStatus status;
};

class ContactEvaluator : public NonlinearForce {
 public:
  /// Throws std::invalid_argument with the violated constraint on bad options or pairs.
  ContactEvaluator(const ContactEvaluatorOptions& options, std::vector<contact::PairParameters> pairs);
  ~ContactEvaluator() override;
  ContactEvaluator(const ContactEvaluator&) = delete;
  ContactEvaluator& operator=(const ContactEvaluator&) = delete;

  const HarmonicLayout& pair_layout() const override { return layout_; }
  int n_pairs() const override { return static_cast<int>(pairs_.size()); }
  int size() const { return n_pairs() * layout_.size(); }  ///< length of W and F
  const ContactEvaluatorOptions& options() const { return options_; }
  const std::vector<contact::PairParameters>& pairs() const { return pairs_; }

  /// f = F(w); when jacobian != nullptr also the per-pair blocks dF_p/dW_p (method of the
  /// options). Sizes are checked (std::logic_error). Non-finite w -> std::invalid_argument.
  EvaluationStatus evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                            std::vector<Eigen::MatrixXd>* jacobian) override;
  /// The normal max(0, N0) of every pair with PairParameters::preload_in_equilibrium (3D
  /// models), else 0 (as forced::ReducedEquations).
  Eigen::VectorXcd static_load() const override;
  /// The largest of mu |N0| / kt and |N0| / kn over the pairs.
  double rest_displacement() const override;
  /// The same with an explicit Jacobian method (comparisons and benchmarks).
  EvaluationStatus evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f, std::vector<Eigen::MatrixXd>* jacobian,
                            JacobianMethod method);

  /// Each pair's steady period at W as a recursion of its samples
  /// (contact::PeriodicLaw::sample_steps): the law's memory, for Hill's method with the slider
  /// as a state (forced/stability.hpp). Serial. 1d_exact (not a time recursion) refuses
  /// (std::logic_error).
  std::vector<std::vector<contact::SampleStep>> sample_steps(const Eigen::VectorXd& w);
  /// One pair (coefficients w_pair of pair_layout().size()) with its time histories.
  void evaluate_pair(int pair, const Eigen::VectorXd& w_pair, PairDetail& detail, bool with_jacobian);

  /// The central-difference step for one coefficient of a pair [m]: fd_relative_step times
  /// the largest coefficient of the same direction (directions may differ by many orders of
  /// magnitude when kt and kn do), else the contact's own scale (mu |N0|/kt tangential,
  /// |N0|/kn normal), else 1 m.
  double fd_step(int pair, const double* w_pair, int coefficient) const;

 private:
  struct Workspace;
  contact::PeriodicStatus residual(int pair, const double* w, double* f, Workspace& ws);
  contact::PeriodicStatus analytic(int pair, const double* w, double* f, Eigen::MatrixXd& jac, Workspace& ws);
  contact::PeriodicStatus finite_difference(int pair, const double* w, double* f, Eigen::MatrixXd& jac, Workspace& ws);
  void to_time(const double* w, Workspace& ws);

  ContactEvaluatorOptions options_;
  std::vector<contact::PairParameters> pairs_;
  HarmonicLayout layout_;
  std::unique_ptr<Aft> aft_;                            // null for 1d_exact
  std::vector<std::unique_ptr<Workspace>> workspaces_;  // one per thread
};

/// Energy dissipated per cycle by the force F on the motion W [J]: the loop integral
/// sum over directions of  integral F dw = sum_n pi n (Fc_n s_n - Fs_n c_n).
double dissipated_energy(const HarmonicLayout& layout, const Eigen::VectorXd& w, const Eigen::VectorXd& f);

}  // namespace shroudsim::hbm
