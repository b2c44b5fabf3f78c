#pragma once
// A solution of the reduced equations (forced/reduced_equations.hpp) at one frequency f by
// continuation in the excitation scale s (docs/continuation.md, the start of a frequency
// response):
//
//     r(W, s) = W - s W_lin(f) + G(f) F(W) = 0,      dr/ds = -W_lin(f),      s: 0 -> 1,
//
// traced by the pseudo-arclength continuation (continuation/arclength.hpp) from the stuck
// solution at s = 0 (preload only, exact when the preload alone does not slip) to s = 1, the
// case itself. Robust where Newton from a guess cycles between contact states. The path may
// fold back through s < 0 (the excitation reversed); at most 2000 points are traced. The
// equations' dR/dW and linear solvers (dense or matrix-free) serve the homotopy unchanged.
#include <Eigen/Core>

#include "continuation/arclength.hpp"
#include "forced/reduced_equations.hpp"

namespace shroudsim::forced {

/// A solution of the equations at excitation scale `scale` (between 0 and the equations' own
/// scale) that the homotopy may start from instead of the preload-only state: the part of the
/// path below it is not traced again.
struct HomotopyStart {
  double scale = 0.0;
  Eigen::VectorXd x;
};

/// The continuation in s at `frequency_hz` [Hz] with `options`' tolerance and corrector
/// settings (the lambda range, the x unit, the steps and the point cap are set here; the x unit
/// from the path's own extent, the larger of the free and the stuck motion at this frequency).
/// Returns the branch; on BranchStatus::kReachedEnd, w (output only) holds the solution at
/// s = 1. equations' excitation scale is restored before returning. With `from`, the path
/// starts at from->scale from from->x.
continuation::Branch solve_by_excitation_homotopy(ReducedEquations& equations, double frequency_hz,
                                                  const continuation::ArclengthOptions& options, Eigen::VectorXd& w,
                                                  const HomotopyStart* from = nullptr);

}  // namespace shroudsim::forced
