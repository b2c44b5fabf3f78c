#pragma once
// Events along a branch (docs/continuation.md): each is detected by a sign change between
// two accepted points and located between them by the corrector, never by re-tracing.
//  - fold: the lambda component of the tangent changes sign (a turning point of a smooth
//    branch, or a reversal at a corner of a nonsmooth one, e.g. a friction law sampled in
//    time); located by false position (Illinois) on t_lambda(s).
//  - extremum of a functional along the branch (a resonance peak of the response amplitude):
//    located by Brent's method on the arclength.
// And the two ways through a corner of a piecewise-smooth branch: crossing it along the
// residual's other piece (cross_corner), and recognising a "turning point" whose branch comes
// straight back along the stretch before it (a reflection at a corner; ReflectionWatch).
#include <Eigen/Core>
#include <functional>
#include <vector>

#include "continuation/scaled_system.hpp"

namespace shroudsim::continuation {

struct FoldLocation {
  Eigen::VectorXd y, t;  ///< the located point and its tangent (scaled)
  double s = 0.0;        ///< arclength from the start of the step
  bool smooth = false;   ///< |t_lambda| -> 0 there (a true fold); false: a corner reversal
  int newton_iterations = 0;
};

/// Locates the fold on the step from y0 (tangent t0) to the point at arclength `step` along
/// t0, whose tangent t1 has t1_lambda of the other sign. False if the corrector fails inside.
bool locate_fold(ScaledSystem& s, const Eigen::VectorXd& y0, const Eigen::VectorXd& t0, double step,
                 const Eigen::VectorXd& t1, FoldLocation& fold);

/// At a corner of a piecewise-smooth branch (the hyperplane normal to t no longer meets the
/// branch near y), the next piece is sought along the null vector of the Jacobian a little
/// beyond the corner, both orientations, at a few step sizes from `kink`, then along t itself
/// with larger steps. A solution that heads back (within ~25 degrees of -t) does not count.
/// On success y_new, t_new (oriented away from y), the Newton iterations and residual norm.
bool cross_corner(ScaledSystem& s, const Eigen::VectorXd& y, const Eigen::VectorXd& t, double kink,
                  Eigen::VectorXd& y_new, Eigen::VectorXd& t_new, int& iterations, double& rnorm);

/// Where no solution lies on the hyperplanes normal to t ahead of y, however small the step (the
/// branch ends on the piece it came along: past a corner of the residual the only
/// continuation turns back, possibly by nearly 180 degrees, e.g. across the steep slab of a
/// very stiff sampled contact): the corner is located on the ray y + h t (h <= `reach`) as the
/// first h where the residual leaves its value at y, the null vector of the Jacobian just past
/// it is taken, and of its two orientations the one along which the residual stays flat (the
/// residual's own piece, not the one the branch came along) is followed by the corrector. On
/// success y_new, t_new (t_new along that orientation), the Newton iterations and residual
/// norm; t_new may point back in lambda (the caller records a turning point).
bool turn_at_corner(ScaledSystem& s, const Eigen::VectorXd& y, const Eigen::VectorXd& t, double reach,
                    Eigen::VectorXd& y_new, Eigen::VectorXd& t_new, int& iterations, double& rnorm);

/// After a fold: does the branch come back along the stretch traced before it? A sampled
/// friction law can reflect the branch at a corner onto a twin of itself (a sample away),
/// which then leads back through the start; a true fold leaves at a distance of the order of
/// the arclength travelled since the turn. From the kPoints-th to the kWindow-th point after
/// the fold, a branch closer to the stretch before the fold (looked at back over twice the
/// arclength travelled since) than kRatio times that arclength is a reflection.
class ReflectionWatch {
 public:
  static constexpr int kPoints = 4;
  static constexpr int kWindow = 16;
  static constexpr double kRatio = 0.25;

  /// A fold was passed; `first` is the index of the first point after it.
  void arm(std::size_t first) {
    active_ = true;
    first_ = first;
    arc_ = 0.0;
    points_ = 0;
  }
  bool active() const { return active_; }
  std::size_t first() const { return first_; }
  /// A point y (scaled) was accepted after a step `step`; scaled(j) gives accepted point j
  /// and step_to(j) the step that led to it. True when the watch recognises a reflection.
  bool observe(const Eigen::VectorXd& y, double step, const std::function<Eigen::VectorXd(std::size_t)>& scaled,
               const std::function<double(std::size_t)>& step_to);

 private:
  bool active_ = false;
  std::size_t first_ = 0;
  double arc_ = 0.0;
  int points_ = 0;
};

/// The maximum of g(x, lambda) along the branch between point `from` and the point at
/// arclength `step` along its tangent (`options` as the branch was traced with): Brent's
/// method on the arclength s in [0, step], each g evaluated at the corrector's solution on the
/// hyperplane t . (y - y_from) = s, started from the best trial so far moved along the
/// tangent (the first from the tangent line). Stops when s is known to `s_tolerance` * step.
struct Extremum {
  bool found = false;
  double s = 0.0;
  Eigen::VectorXd x;
  double lambda = 0.0;
  double value = 0.0;
  int evaluations = 0;  ///< residual evaluations it took
};
Extremum locate_maximum(ParametricResidual& residual, const ArclengthOptions& options, const BranchPoint& from,
                        double step, const std::function<double(const Eigen::VectorXd&, double)>& g,
                        double s_tolerance = 1e-7);
/// The same on [s_lo, s_hi] (0 <= s_lo < s_hi), s known to `s_tolerance` * (s_hi - s_lo);
/// with `near` (a solution on the branch at arclength near.s, e.g. from sample_along) the
/// first trial starts from it moved along the tangent rather than from the tangent line.
Extremum locate_maximum(ParametricResidual& residual, const ArclengthOptions& options, const BranchPoint& from,
                        double s_lo, double s_hi, const std::function<double(const Eigen::VectorXd&, double)>& g,
                        double s_tolerance = 1e-7, const Extremum* near = nullptr);

/// g along the branch at the arclengths `s` (increasing) from point `from` along its tangent:
/// the corrector's solution on each hyperplane t . (y - y_from) = s_j, started from the
/// previous one moved by (s_j - s_{j-1}) t (cheap where the s_j are close). One entry per
/// s_j; found = false where the corrector failed (and the next starts from the prediction).
std::vector<Extremum> sample_along(ParametricResidual& residual, const ArclengthOptions& options,
                                   const BranchPoint& from, const std::vector<double>& s,
                                   const std::function<double(const Eigen::VectorXd&, double)>& g);

/// Does point p lie on `branch` (traced with `options`)? The corrector from the branch point
/// nearest to p (scaled distance), on the hyperplane through p normal to that point's tangent,
/// finds the branch's own point there; returned is its scaled distance from p (infinity when
/// the corrector fails). Two solutions of one branch agree to about the tolerance; a twin
/// branch a sample away, or a separate branch, stays at its own distance.
double distance_to_branch(ParametricResidual& residual, const ArclengthOptions& options,
                          const std::vector<BranchPoint>& branch, const BranchPoint& p);

}  // namespace shroudsim::continuation
