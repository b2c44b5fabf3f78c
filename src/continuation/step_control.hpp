#pragma once
// Step-length control of the pseudo-arclength continuation, in scaled arclength units
// (docs/continuation.md). The step grows after an easy corrector (few Newton iterations and a
// small turn of the tangent), shrinks after a hard one, and is halved after a failure; it
// stays within [min_step, max_step] * initial_step.
#include "continuation/arclength.hpp"

namespace shroudsim::continuation {

class StepControl {
 public:
  explicit StepControl(const ArclengthOptions& o);

  double step() const { return step_; }
  /// Steps below this are "kink size": a corner of a nonsmooth branch, not a curve to resolve.
  double kink() const { return kink_; }
  /// After an accepted step: Newton iterations it took and the angle (radians) between the
  /// tangents at its ends. Grows by 1.5 when the corrector took at most half the target
  /// iterations, shrinks by 0.7 above the target, and aims at a turn of the tangent of
  /// target_turn_deg per step (the factor target_turn / turn, within [0.5, 1.5], caps it).
  void accepted(int iterations, double turn);
  /// After a failed or rejected step: halves. False when the step fell below min_step.
  bool rejected();
  /// Sets the step (clamped to [min, max]).
  void set(double step);

 private:
  double step_, min_, max_, kink_, target_turn_;
  int target_iterations_;
};

}  // namespace shroudsim::continuation
