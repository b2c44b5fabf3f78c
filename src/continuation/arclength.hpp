#pragma once
// Keller pseudo-arclength continuation of R(x, lambda) = 0 (PHYSICS.md section 7).
//
// Unknowns y = (x, lambda), scaled as y_s = (x ./ x_scale, lambda / lambda_scale). From a
// converged point y_k with unit tangent t_k (in scaled variables), the predictor is
// y_p = y_k + s t_k and the corrector is Newton on the augmented system
//     R(x, lambda) = 0,   t_k . (y_s - y_p,s) = 0.
// Step control: grow after few Newton iterations, shrink after many or on failure. When the
// lambda component of the tangent changes sign (a turning point), the last `turning_backtrack`
// points are dropped and the turn is retraced at a tenth of the step, unless the step already
// moved lambda by less than a tenth of the initial step (a fold on a near-vertical stretch,
// where a piecewise-smooth residual such as a friction law sampled in time zigzags by round-off
// amounts: retracing there would only shrink the step without locating anything better). When
// the x part of the tangent grows by more than `steep_ratio` between two points (a steep
// branch), the step is capped at the initial step. A step whose tangent turns by more than
// `max_turn_deg` is rejected and halved (it has most likely jumped to a nearby branch, or
// cut a corner too sharp to follow); below
// `kink_step` (relative to initial_step) it is accepted all the same, so that a true kink
// of a nonsmooth residual does not stop the branch. When even a kink-size step finds no
// solution (a corner sharper than a right angle: the branch goes on along the residual's other
// piece), the null vector of the Jacobian just beyond the corner is tried, both ways.
//
// Usage:
//   MyResidual r;                        // implements ParametricResidual
//   ArclengthOptions o; o.lambda_start = 100; o.lambda_end = 220; o.x_scale = ...;
//   const Branch b = trace(r, x_guess, o, [](const BranchPoint& p) { ... });
//   if (b.status != BranchStatus::kReachedEnd) report(b.message);   // b.points is usable
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace shroudsim::continuation {

/// The (n+1) x (n+1) bordered Newton matrix of the continuation, in its scaled variables,
/// given without forming it:
///     A = [ diag(1 / r_scale) J diag(x_scale)   column ]
///         [ row^T                                      ]
/// J = dR/dx at the last linearize() point, column = the scaled dR/dlambda (n), row (n + 1).
struct BorderedMatrix {
  const Eigen::VectorXd& r_scale;
  const Eigen::VectorXd& x_scale;
  const Eigen::VectorXd& column;
  const Eigen::VectorXd& row;
};

/// R(x, lambda): R^n x R -> R^n.
class ParametricResidual {
 public:
  virtual ~ParametricResidual() = default;
  virtual int size() const = 0;
  /// r = R(x, lambda); when J is not null, J = dR/dx (n x n); when dr_dlambda is not null,
  /// dR/dlambda (n) (a residual that cannot give it leaves it untouched and returns
  /// has_lambda_derivative() = false: the solver then takes a central difference).
  /// Returns false when R cannot be evaluated there (e.g. non-finite values).
  virtual bool evaluate(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                        Eigen::VectorXd* dr_dlambda) = 0;
  virtual bool has_lambda_derivative() const { return false; }
  /// Solves the (n+1) augmented Newton system A d = b. The default is a dense LU;
  /// a residual with structure (e.g. a low-rank update) may do better.
  virtual bool solve_augmented(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& d);

  /// Matrix-free residuals (matrix_free() true) never give the continuation a dense J:
  /// linearize() evaluates r (and dR/dlambda when has_lambda_derivative()) and keeps what
  /// products with J need; solve_bordered() solves A d = b with the bordered matrix at the
  /// last linearize() point (evaluations without linearizing in between do not move it).
  /// The continuation then calls these instead of evaluate() with J and solve_augmented():
  /// for large n the dense n x n J, its scaled copies and their O(n^2) traffic per Newton
  /// iteration are what cost.
  virtual bool matrix_free() const { return false; }
  virtual bool linearize(const Eigen::VectorXd& x, double lambda, Eigen::VectorXd& r, Eigen::VectorXd* dr_dlambda);
  virtual bool solve_bordered(const BorderedMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& d);
};

struct ArclengthOptions {
  double lambda_start = 0.0;
  double lambda_end = 1.0;
  Eigen::VectorXd x_scale;        ///< typical magnitude of each unknown (> 0); empty: 1
  Eigen::VectorXd residual_scale; ///< typical magnitude of each residual; empty: x_scale
  double lambda_scale = 1.0;      ///< unit of lambda in the arclength
  double initial_step = 0.5;      ///< arclength, scaled units
  double min_step = 1e-6;         ///< relative to initial_step: stop when the step falls below
  double max_step = 20.0;         ///< relative to initial_step
  int max_points = 5000;
  double tolerance = 1e-8;        ///< on the scaled residual, infinity norm
  int max_newton_iterations = 15;
  int target_newton_iterations = 4;  ///< grow the step below, shrink above
  double steep_ratio = 30.0;      ///< "a" of the steep-branch rule (20 to 40)
  int turning_backtrack = 2;      ///< points dropped before retracing a turning point
  double max_turn_deg = 30.0;     ///< largest angle between successive tangents (scaled)
  double kink_step = 1e-3;        ///< relative to initial_step: below, large turns are accepted
  /// How far beyond lambda_start (against the direction of travel, in lambda units) the
  /// branch may go before it counts as having left the range (0: not at all).
  double start_slack = 0.0;
  bool validate(std::vector<std::string>* errors) const;
};

struct BranchPoint {
  Eigen::VectorXd x;
  double lambda = 0.0;
  Eigen::VectorXd tangent;        ///< unit tangent (scaled variables), size n+1, lambda last
  int newton_iterations = 0;
  double step = 0.0;              ///< arclength step that led here
  double residual_norm = 0.0;     ///< scaled, infinity norm
};

enum class BranchStatus { kReachedEnd, kLeftRange, kMaxPoints, kStepTooSmall, kStartFailed, kEvaluationFailed };

/// "reached_end", "left_range", ...
const char* to_string(BranchStatus status);

struct Branch {
  std::vector<BranchPoint> points;  ///< in continuation order
  BranchStatus status = BranchStatus::kReachedEnd;
  std::string message;              ///< why it stopped, for users
  int turning_points = 0;           ///< folds passed (after retracing)
  int newton_iterations = 0;        ///< total
  int rejected_steps = 0;           ///< corrector failures that shrank the step
  int rejected_turns = 0;           ///< of those, steps whose tangent turned too far (branch jumps)
  int kinks_crossed = 0;            ///< corners of a nonsmooth branch passed along the other piece
  int reflections_crossed = 0;      ///< "turning points" that were reflections at a corner, crossed
  int residual_evaluations = 0;
};

/// Newton at fixed lambda from x (updated in place). Returns iterations used, or -1.
int newton_fixed(ParametricResidual& residual, Eigen::VectorXd& x, double lambda, const ArclengthOptions& options,
                 double* residual_norm = nullptr);

/// Traces the branch from the solution near x_guess at lambda_start until lambda_end.
/// on_point is called for every accepted point (may be empty).
Branch trace(ParametricResidual& residual, const Eigen::VectorXd& x_guess, const ArclengthOptions& options,
             const std::function<void(const BranchPoint&)>& on_point = {});

}  // namespace shroudsim::continuation
