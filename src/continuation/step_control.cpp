#include "continuation/step_control.hpp"

#include <algorithm>
#include <numbers>

namespace shroudsim::continuation {

StepControl::StepControl(const ArclengthOptions& o)
    : step_(o.initial_step),
      min_(o.min_step * o.initial_step),
      max_(o.max_step * o.initial_step),
      kink_(o.kink_step * o.initial_step),
      target_turn_(o.target_turn_deg * std::numbers::pi / 180.0),
      target_iterations_(o.target_newton_iterations) {}

void StepControl::accepted(int iterations, double turn) {
  double factor = 1.0;
  if (iterations <= target_iterations_ / 2) factor = 1.5;
  else if (iterations > target_iterations_) factor = 0.7;
  if (turn > 0) factor = std::min(factor, std::clamp(target_turn_ / turn, 0.5, 1.5));
  set(step_ * factor);
}

bool StepControl::rejected() {
  step_ *= 0.5;
  return step_ >= min_;
}

void StepControl::set(double step) { step_ = std::clamp(step, min_, max_); }

}  // namespace shroudsim::continuation
