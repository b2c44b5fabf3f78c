#pragma once
// Keller pseudo-arclength continuation of R(x, lambda) = 0 (docs/continuation.md).
//
// Unknowns y = (x, lambda), scaled as y_s = (x ./ x_scale, lambda / lambda_scale): every step
// and tolerance below is in these scaled units, so the caller chooses the units (the
// frequency response takes them from the problem: forced/frequency_response.hpp). The
// algorithm is built of separate pieces:
//  - predictor: y_p = y_k + s t_k along the unit tangent;
//  - corrector: Newton on R(y) = 0, t_k . (y - y_p) = 0 (scaled_system.hpp);
//  - step control: from the Newton effort and the turn of the tangent (step_control.hpp);
//    a step whose tangent turns by more than max_turn_deg is rejected (it has most likely
//    jumped to a nearby branch) unless it is already at kink size (a true corner of a
//    nonsmooth residual);
//  - events (events.hpp): a fold (t_lambda changes sign) is located between the two points
//    and inserted into the branch; a reflection at a corner (the branch comes straight back
//    along itself after a fold) is undone and the corner crossed; a step that finds no
//    solution even at kink size crosses the corner along the residual's other piece.
// Options are validated on entry (std::invalid_argument). Only points that stay on the
// branch reach on_point: points after a fold are reported once the reflection check has
// passed them.
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
  Eigen::VectorXd x_scale;         ///< typical magnitude of each unknown (> 0); empty: 1
  Eigen::VectorXd residual_scale;  ///< typical magnitude of each residual; empty: x_scale
  double lambda_scale = 1.0;       ///< unit of lambda in the arclength
  double initial_step = 0.5;       ///< arclength, scaled units
  double min_step = 1e-6;          ///< relative to initial_step: stop when the step falls below
  double max_step = 20.0;          ///< relative to initial_step
  /// Largest change of lambda per step, scaled units (0: none). The arclength step is cut so
  /// that |t_lambda| h stays below it: the frequency resolution is bounded where the branch
  /// moves along lambda, while where it moves in x (a resonance's phase turning) the step is
  /// bounded by max_step and the turn of the tangent only.
  double max_lambda_step = 0.0;
  int max_points = 5000;
  double tolerance = 1e-8;  ///< on the scaled residual, infinity norm
  int max_newton_iterations = 15;
  int target_newton_iterations = 4;  ///< grow the step below, shrink above
  double max_turn_deg = 30.0;        ///< largest angle between successive tangents (scaled)
  double target_turn_deg = 20.0;     ///< step control aims at this turn per step (< max_turn_deg)
  double kink_step = 1e-3;           ///< relative to initial_step: below, large turns are accepted
  /// How far beyond lambda_start (against the direction of travel, in lambda units) the
  /// branch may go before it counts as having left the range (0: not at all).
  double start_slack = 0.0;
  /// n: the residual's size (x_scale and residual_scale must be empty or of size n).
  bool validate(int n, std::vector<std::string>* errors) const;
};

/// What a point of a branch is.
enum class PointKind {
  kRegular,   ///< reached by a continuation step
  kFold,      ///< a located fold (t_lambda = 0 to the corrector's tolerance)
  kCorner,    ///< a located reversal of lambda at a corner of a nonsmooth branch
  kBoundary,  ///< put on the end (or start) of the range by Newton at fixed lambda
};

struct BranchPoint {
  Eigen::VectorXd x;
  double lambda = 0.0;
  Eigen::VectorXd tangent;  ///< unit tangent (scaled variables), size n+1, lambda last
  int newton_iterations = 0;
  double step = 0.0;           ///< arclength step that led here
  double residual_norm = 0.0;  ///< scaled, infinity norm
  PointKind kind = PointKind::kRegular;
};

enum class BranchStatus {
  kReachedEnd,
  kLeftRange,
  kClosedLoop,  ///< the branch came back onto itself, travelling the same way (an isola)
  kMaxPoints,
  kStepTooSmall,
  kStartFailed,
  kEvaluationFailed
};

/// "reached_end", "left_range", ...
const char* to_string(BranchStatus status);

struct Branch {
  std::vector<BranchPoint> points;  ///< in continuation order
  BranchStatus status = BranchStatus::kReachedEnd;
  std::string message;          ///< why it stopped, for users
  int turning_points = 0;       ///< folds and corner reversals passed (located, in points)
  int smooth_folds = 0;         ///< of those, true folds (t_lambda -> 0)
  int newton_iterations = 0;    ///< total
  int rejected_steps = 0;       ///< corrector failures that shrank the step
  int rejected_turns = 0;       ///< of those, steps whose tangent turned too far (branch jumps)
  int kinks_crossed = 0;        ///< corners of a nonsmooth branch passed along the other piece
  int reflections_crossed = 0;  ///< "turning points" that were reflections at a corner, crossed
  int residual_evaluations = 0;
};

/// Newton at fixed lambda from x (updated in place). Returns iterations used, or -1.
int newton_fixed(ParametricResidual& residual, Eigen::VectorXd& x, double lambda, const ArclengthOptions& options,
                 double* residual_norm = nullptr);

/// Traces the branch from the solution near x_guess at lambda_start until lambda_end.
/// on_point is called for every point that stays on the branch, in order (may be empty).
/// Throws std::invalid_argument when the options are invalid for this residual.
Branch trace(ParametricResidual& residual, const Eigen::VectorXd& x_guess, const ArclengthOptions& options,
             const std::function<void(const BranchPoint&)>& on_point = {});

}  // namespace shroudsim::continuation
