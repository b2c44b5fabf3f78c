#include "continuation/scaled_system.hpp"

#include <algorithm>
#include <cmath>

namespace shroudsim::continuation {

ScaledSystem::ScaledSystem(ParametricResidual& r, const ArclengthOptions& o, int* evaluations)
    : r_(r), o_(o), evaluations_(evaluations) {
  const int n = r.size();
  xs_ = o.x_scale.size() ? o.x_scale : Eigen::VectorXd::Ones(n);
  rs_ = o.residual_scale.size() ? o.residual_scale : xs_;
}

Eigen::VectorXd ScaledSystem::to_scaled(const Eigen::VectorXd& x, double lambda) const {
  Eigen::VectorXd y(n() + 1);
  y.head(n()) = x.cwiseQuotient(xs_);
  y[n()] = lambda / o_.lambda_scale;
  return y;
}

bool ScaledSystem::evaluate(const Eigen::VectorXd& y, Eigen::VectorXd& rs, Linearization* lin) {
  const Eigen::VectorXd x = x_of(y);
  const double lambda = lambda_of(y);
  Eigen::VectorXd r;
  Eigen::VectorXd dl;
  const bool analytic_lambda = r_.has_lambda_derivative();
  const bool matrix_free = lin && r_.matrix_free();
  ++*evaluations_;
  if (matrix_free) {
    if (!r_.linearize(x, lambda, r, analytic_lambda ? &dl : nullptr)) return false;
  } else if (!r_.evaluate(x, lambda, r, lin ? &J_ : nullptr, lin && analytic_lambda ? &dl : nullptr)) {
    return false;
  }
  if (!r.allFinite()) return false;
  rs = r.cwiseQuotient(rs_);
  if (!lin) return true;
  if (!analytic_lambda) {
    // Central difference in lambda with a step relative to lambda and its unit.
    const double h = 1e-6 * (std::abs(lambda) + o_.lambda_scale);
    Eigen::VectorXd rp, rm;
    *evaluations_ += 2;
    if (!r_.evaluate(x, lambda + h, rp, nullptr, nullptr) || !r_.evaluate(x, lambda - h, rm, nullptr, nullptr))
      return false;
    dl = (rp - rm) / (2 * h);
  }
  lin->column = dl.cwiseQuotient(rs_) * o_.lambda_scale;
  if (matrix_free) return lin->column.allFinite();
  lin->Js.resize(n(), n() + 1);
  lin->Js.leftCols(n()) = rs_.cwiseInverse().asDiagonal() * J_ * xs_.asDiagonal();
  lin->Js.col(n()) = lin->column;
  return lin->Js.allFinite();
}

bool ScaledSystem::solve(const Linearization& lin, const Eigen::VectorXd& row, const Eigen::VectorXd& b,
                         Eigen::VectorXd& d) {
  if (r_.matrix_free()) return r_.solve_bordered(BorderedMatrix{rs_, xs_, lin.column, row}, b, d);
  const int m = n();
  A_.resize(m + 1, m + 1);
  A_.topRows(m) = lin.Js;
  A_.row(m) = row.transpose();
  return r_.solve_augmented(A_, b, d);
}

bool ScaledSystem::tangent(const Eigen::VectorXd& y, const Eigen::VectorXd& row, const Eigen::VectorXd& orient,
                           Eigen::VectorXd& t) {
  Eigen::VectorXd rs;
  Linearization lin;
  if (!evaluate(y, rs, &lin)) return false;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n() + 1);
  b[n()] = 1.0;
  if (!solve(lin, row, b, t)) return false;
  const double norm = t.norm();
  if (!(norm > 0) || !std::isfinite(norm)) return false;
  t /= norm;
  if (t.dot(orient) < 0) t = -t;
  return true;
}

int correct(ScaledSystem& s, Eigen::VectorXd& y, const Eigen::VectorXd& t, const Eigen::VectorXd& y_pred,
            double& final_norm) {
  const ArclengthOptions& o = s.options();
  const int n = s.n();
  Eigen::VectorXd rs, b(n + 1), d, y_prev, rs_try;
  ScaledSystem::Linearization lin;
  double first = -1.0, prev_norm = 0.0;
  auto norm_at = [&](const Eigen::VectorXd& yy, const Eigen::VectorXd& r) {
    return std::max(r.lpNorm<Eigen::Infinity>(), std::abs(t.dot(yy - y_pred)));
  };
  for (int it = 0; it <= o.max_newton_iterations; ++it) {
    if (!s.evaluate(y, rs, &lin)) return -1;
    double norm = norm_at(y, rs);
    if (it > 0 && norm >= prev_norm) {
      for (double a = 0.5; a >= 1.0 / 16.0; a *= 0.5) {
        const Eigen::VectorXd y_try = y_prev + a * d;
        if (!s.evaluate(y_try, rs_try, nullptr)) break;
        if (norm_at(y_try, rs_try) < prev_norm) {
          y = y_try;
          if (!s.evaluate(y, rs, &lin)) return -1;
          norm = norm_at(y, rs);
          break;
        }
      }
    }
    const double constraint = t.dot(y - y_pred);
    if (first < 0) first = norm;
    final_norm = norm;
    if (norm <= o.tolerance) return it;
    if (it == o.max_newton_iterations || norm > 1e6 * std::max(first, o.tolerance)) return -1;
    b.head(n) = -rs;
    b[n] = -constraint;
    if (!s.solve(lin, t, b, d)) return -1;
    y_prev = y;
    prev_norm = norm;
    y += d;
  }
  return -1;
}

}  // namespace shroudsim::continuation
