#include "forced/excitation_homotopy.hpp"

#include <algorithm>
#include <cmath>

namespace shroudsim::forced {

namespace {

// The homotopy path's extent in x, in units: the path runs from the preload-only state to
// a motion between the stuck and the free one, and its arclength is a 2-norm over every
// unknown, so the unit is a fraction of the larger of those motions' 2-norms.
constexpr double kPathUnits = 2.0;

/// r(W, s) = W - s W_lin + G F(W) at a fixed frequency: lambda is the excitation scale.
class ExcitationHomotopy : public continuation::ParametricResidual {
 public:
  ExcitationHomotopy(ReducedEquations& eq, double frequency_hz) : eq_(eq), frequency_hz_(frequency_hz) {}
  int size() const override { return eq_.size(); }
  bool has_lambda_derivative() const override { return true; }
  bool evaluate(const Eigen::VectorXd& w, double s, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dl) override {
    eq_.set_excitation_scale(s);
    const bool ok = eq_.evaluate(w, frequency_hz_, r, J, nullptr);
    if (dl) *dl = -lin_;
    return ok;
  }
  bool solve_augmented(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) override {
    return eq_.solve_augmented(A, b, d);
  }
  // dR/dW is the equations' own J: their matrix-free solves serve the homotopy too.
  bool matrix_free() const override { return eq_.matrix_free(); }
  bool linearize(const Eigen::VectorXd& w, double s, Eigen::VectorXd& r, Eigen::VectorXd* dl) override {
    eq_.set_excitation_scale(s);
    const bool ok = eq_.linearize(w, frequency_hz_, r, nullptr);
    if (dl) *dl = -lin_;
    return ok;
  }
  bool solve_bordered(const continuation::BorderedMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) override {
    return eq_.solve_bordered(A, b, d);
  }
  Eigen::VectorXd lin_;

 private:
  ReducedEquations& eq_;
  double frequency_hz_;
};

}  // namespace

continuation::Branch solve_by_excitation_homotopy(ReducedEquations& equations, double frequency_hz,
                                                  const continuation::ArclengthOptions& options, Eigen::VectorXd& w,
                                                  const HomotopyStart* from) {
  ExcitationHomotopy homotopy(equations, frequency_hz);
  homotopy.lin_ = equations.linear_motion(frequency_hz);
  // From no excitation to the equations' own excitation scale (1 unless a caller scaled it).
  const double saved = equations.excitation_scale();
  const double target = saved > 0.0 ? saved : 1.0;
  continuation::ArclengthOptions o = options;
  o.lambda_start = 0.0;
  o.lambda_end = target;
  o.lambda_scale = target;
  o.initial_step = 0.05;
  o.max_step = 4.0;
  o.max_points = std::min(o.max_points, 2000);  // a start that needs more is not worth waiting for
  o.start_slack = target;                       // the path may fold back through s < 0 (the excitation reversed)
  // The path's own unit (kPathUnits). The caller's (a twentieth of the free peak over the
  // whole range, per unknown) can be orders of magnitude off it: at 92 Hz, below a lightly
  // damped resonance, on a sector with 89 shroud pairs (2,937 unknowns) the path was hundreds
  // of units long and took 1,785 steps; with its own unit, 83 (docs/continuation.md, "Start").
  equations.set_excitation_scale(target);
  const Eigen::VectorXd stuck_end = equations.stuck_solution(frequency_hz);
  equations.set_excitation_scale(0.0);
  const Eigen::VectorXd start = equations.stuck_solution(frequency_hz);
  const double extent = std::max((target * homotopy.lin_).norm(), (stuck_end - start).norm());
  if (std::isfinite(extent) && extent > 0) o.x_scale = Eigen::VectorXd::Constant(start.size(), extent / kPathUnits);
  const bool resume = from != nullptr && from->scale > 0.0 && from->scale < target;
  if (resume) {
    o.lambda_start = from->scale;
    o.start_slack = o.lambda_start + target;  // still down to s = -target
  }
  continuation::Branch b = continuation::trace(homotopy, resume ? from->x : start, o);
  equations.set_excitation_scale(saved);
  if (b.status == continuation::BranchStatus::kReachedEnd) w = b.points.back().x;
  return b;
}

}  // namespace shroudsim::forced
