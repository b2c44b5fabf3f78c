#pragma once
// The continuation's view of a ParametricResidual in scaled variables (docs/continuation.md):
//     y = (x ./ x_scale, lambda / lambda_scale),   rs = R ./ residual_scale.
// Every piece of the algorithm (corrector, tangent, events) works on y only, so that no
// tolerance or step of the continuation depends on the units of x or lambda.
#include <Eigen/Core>

#include "continuation/arclength.hpp"

namespace shroudsim::continuation {

class ScaledSystem {
 public:
  /// options must have passed ArclengthOptions::validate for residual.size().
  ScaledSystem(ParametricResidual& residual, const ArclengthOptions& options, int* evaluations);

  int n() const { return r_.size(); }
  const ArclengthOptions& options() const { return o_; }
  Eigen::VectorXd to_scaled(const Eigen::VectorXd& x, double lambda) const;
  Eigen::VectorXd x_of(const Eigen::VectorXd& y) const { return y.head(n()).cwiseProduct(xs_); }
  double lambda_of(const Eigen::VectorXd& y) const { return y[n()] * o_.lambda_scale; }

  /// The linearization at a point: the dense scaled Jacobian Js = d(rs)/d(y), n x (n+1), or,
  /// for a matrix-free residual, only its last column (the scaled dR/dlambda).
  struct Linearization {
    Eigen::MatrixXd Js;
    Eigen::VectorXd column;
  };

  /// rs = scaled residual at y; when lin is not null, the linearization there. False when
  /// the residual cannot be evaluated or is not finite.
  bool evaluate(const Eigen::VectorXd& y, Eigen::VectorXd& rs, Linearization* lin);
  /// Solves [Js; row^T] d = b with the linearization of the last evaluate() that gave one.
  bool solve(const Linearization& lin, const Eigen::VectorXd& row, const Eigen::VectorXd& b, Eigen::VectorXd& d);
  /// Unit tangent at y: [Js; row^T] t = e_{n+1}, oriented so that t . orient >= 0.
  bool tangent(const Eigen::VectorXd& y, const Eigen::VectorXd& row, const Eigen::VectorXd& orient, Eigen::VectorXd& t);

 private:
  ParametricResidual& r_;
  const ArclengthOptions& o_;
  int* evaluations_;
  Eigen::VectorXd xs_, rs_;
  Eigen::MatrixXd J_, A_;  // buffers kept across evaluations (n x n, (n+1) x (n+1))
};

/// Newton on the augmented system R(y) = 0, t . (y - y_pred) = 0 from y (updated in place).
/// A full Newton step that does not reduce the residual is cut back by halves (down to 1/16)
/// to the first that does (Newton cycling between the pieces of a nonsmooth residual).
/// Converged when max(|rs|_inf, |t . (y - y_pred)|) <= options.tolerance. Returns the
/// iterations used, or -1; final_norm is the last norm seen.
int correct(ScaledSystem& s, Eigen::VectorXd& y, const Eigen::VectorXd& t, const Eigen::VectorXd& y_pred,
            double& final_norm);

}  // namespace shroudsim::continuation
