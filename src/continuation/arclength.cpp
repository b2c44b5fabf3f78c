#include "continuation/arclength.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace shroudsim::continuation {

bool ParametricResidual::solve_augmented(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  d = lu.solve(b);
  return d.allFinite();
}

bool ParametricResidual::linearize(const Eigen::VectorXd&, double, Eigen::VectorXd&, Eigen::VectorXd*) {
  return false;  // only matrix-free residuals linearize
}

bool ParametricResidual::solve_bordered(const BorderedMatrix&, const Eigen::VectorXd&, Eigen::VectorXd&) {
  return false;
}

const char* to_string(BranchStatus status) {
  switch (status) {
    case BranchStatus::kReachedEnd: return "reached_end";
    case BranchStatus::kLeftRange: return "left_range";
    case BranchStatus::kMaxPoints: return "max_points";
    case BranchStatus::kStepTooSmall: return "step_too_small";
    case BranchStatus::kStartFailed: return "start_failed";
    case BranchStatus::kEvaluationFailed: return "evaluation_failed";
  }
  return "unknown";
}

bool ArclengthOptions::validate(std::vector<std::string>* errors) const {
  std::vector<std::string> e;
  if (!(lambda_end != lambda_start)) e.push_back("lambda_end != lambda_start");
  if (!(initial_step > 0)) e.push_back("initial_step > 0");
  if (!(min_step > 0 && min_step < 1)) e.push_back("0 < min_step < 1");
  if (!(max_step >= 1)) e.push_back("max_step >= 1");
  if (!(max_turn_deg > 0 && max_turn_deg < 180)) e.push_back("0 < max_turn_deg < 180");
  if (!(kink_step > 0 && kink_step <= 1)) e.push_back("0 < kink_step <= 1");
  if (!(max_points >= 1)) e.push_back("max_points >= 1");
  if (!(tolerance > 0)) e.push_back("tolerance > 0");
  if (!(lambda_scale > 0)) e.push_back("lambda_scale > 0");
  if (x_scale.size() && (x_scale.array() <= 0).any()) e.push_back("x_scale > 0");
  if (residual_scale.size() && (residual_scale.array() <= 0).any()) e.push_back("residual_scale > 0");
  if (errors) *errors = e;
  return e.empty();
}

namespace {

/// Scaled view of the residual and its derivatives.
class Scaled {
 public:
  Scaled(ParametricResidual& r, const ArclengthOptions& o, int* evaluations) : r_(r), o_(o), evaluations_(evaluations) {
    const int n = r.size();
    xs_ = o.x_scale.size() ? o.x_scale : Eigen::VectorXd::Ones(n);
    rs_ = o.residual_scale.size() ? o.residual_scale : xs_;
  }
  int n() const { return r_.size(); }
  Eigen::VectorXd to_scaled(const Eigen::VectorXd& x, double lambda) const {
    Eigen::VectorXd y(n() + 1);
    y.head(n()) = x.cwiseQuotient(xs_);
    y[n()] = lambda / o_.lambda_scale;
    return y;
  }
  Eigen::VectorXd x_of(const Eigen::VectorXd& y) const { return y.head(n()).cwiseProduct(xs_); }
  double lambda_of(const Eigen::VectorXd& y) const { return y[n()] * o_.lambda_scale; }

  /// The linearization at a point: the dense scaled Jacobian Js = d(rs)/d(y_s), n x (n+1),
  /// or, for a matrix-free residual, only its last column (the scaled dR/dlambda).
  struct Linearization {
    Eigen::MatrixXd Js;
    Eigen::VectorXd column;
  };

  /// rs = scaled residual; when lin is not null, the linearization there.
  bool evaluate(const Eigen::VectorXd& y, Eigen::VectorXd& rs, Linearization* lin) {
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
      const double h = 1e-6 * (std::abs(lambda) + o_.lambda_scale);
      Eigen::VectorXd rp, rm;
      evaluations_[0] += 2;
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

  /// Solves [Js; row^T] d = b with the linearization of the last evaluate() that gave one.
  bool solve(const Linearization& lin, const Eigen::VectorXd& row, const Eigen::VectorXd& b, Eigen::VectorXd& d) {
    if (r_.matrix_free()) return r_.solve_bordered(BorderedMatrix{rs_, xs_, lin.column, row}, b, d);
    const int m = n();
    A_.resize(m + 1, m + 1);
    A_.topRows(m) = lin.Js;
    A_.row(m) = row.transpose();
    return r_.solve_augmented(A_, b, d);
  }

  ParametricResidual& residual() { return r_; }

 private:
  ParametricResidual& r_;
  const ArclengthOptions& o_;
  int* evaluations_;
  Eigen::VectorXd xs_, rs_;
  Eigen::MatrixXd J_, A_;  // buffers kept across evaluations (n x n, (n+1) x (n+1))
};

/// Unit tangent at y: [Js; row] t = e_{n+1}, oriented along `orient`.
bool tangent_at(Scaled& s, const Eigen::VectorXd& y, const Eigen::VectorXd& row, const Eigen::VectorXd& orient,
                Eigen::VectorXd& t) {
  Eigen::VectorXd rs;
  Scaled::Linearization lin;
  if (!s.evaluate(y, rs, &lin)) return false;
  const int n = s.n();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n + 1);
  b[n] = 1.0;
  if (!s.solve(lin, row, b, t)) return false;
  const double norm = t.norm();
  if (!(norm > 0) || !std::isfinite(norm)) return false;
  t /= norm;
  if (t.dot(orient) < 0) t = -t;
  return true;
}

// Reflection check after a turning point (see TurnWatch in trace): from the
// kReflectionPoints-th to the kReflectionWindow-th point after the turn, a branch closer to
// the stretch before the turn (over twice the arclength travelled since the turn) than
// kReflectionRatio times that arclength is taken for a reflection.
constexpr int kReflectionPoints = 4;
constexpr int kReflectionWindow = 16;  // points after the turn that are checked
constexpr double kReflectionRatio = 0.25;

/// Newton on the augmented system from y (in place). Returns iterations, or -1.
int corrector(Scaled& s, Eigen::VectorXd& y, const Eigen::VectorXd& t, const Eigen::VectorXd& y_pred,
              const ArclengthOptions& o, double& final_norm) {
  const int n = s.n();
  Eigen::VectorXd rs, b(n + 1), d, y_prev, rs_try;
  Scaled::Linearization lin;
  double first = -1.0, prev_norm = 0.0;
  auto norm_at = [&](const Eigen::VectorXd& yy, const Eigen::VectorXd& r) {
    return std::max(r.lpNorm<Eigen::Infinity>(), std::abs(t.dot(yy - y_pred)));
  };
  for (int it = 0; it <= o.max_newton_iterations; ++it) {
    if (!s.evaluate(y, rs, &lin)) return -1;
    double norm = norm_at(y, rs);
    // A full step that did not reduce the residual (Newton cycling between the pieces of a
    // nonsmooth residual, e.g. a sample switching between stick and slip) is cut back along
    // its direction, by halves, to the first point that does; failing that, it is kept.
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

/// At a corner of a piecewise-smooth branch (a nonsmooth residual: the hyperplane normal to the
/// tangent t no longer meets the branch near y), the next piece is sought along the null vector
/// of the Jacobian a little beyond the corner (the residual's other piece), in both
/// orientations, at a few step sizes from `kink`, and then along t itself with larger steps
/// (over the corner). A solution that heads back (tangent within ~25 degrees of -t: the branch
/// already traced, or its twin through a sample that switches state, which a time-discretized
/// friction law produces near incipient slip) does not count. On success y_new is the new point
/// and t_new its tangent, oriented away from y.
bool cross_kink(Scaled& s, const Eigen::VectorXd& y, const Eigen::VectorXd& t, double kink, const ArclengthOptions& o,
                Eigen::VectorXd& y_new, Eigen::VectorXd& t_new, int& iterations, double& rnorm) {
  std::vector<Eigen::VectorXd> directions;
  for (double beyond : {0.1, 1.0, 10.0}) {
    Eigen::VectorXd tb;
    if (!tangent_at(s, y + beyond * kink * t, t, t, tb)) continue;
    directions.push_back(tb);
    directions.push_back(-tb);
  }
  std::vector<std::pair<Eigen::VectorXd, double>> trials;
  for (const Eigen::VectorXd& v : directions)
    for (double size : {1.0, 10.0, 100.0}) trials.emplace_back(v, size);
  for (double size : {10.0, 100.0, 1000.0}) trials.emplace_back(t, size);
  for (const auto& [v, size] : trials) {
    const Eigen::VectorXd y_pred = y + size * kink * v;
    Eigen::VectorXd yc = y_pred;
    const int it = corrector(s, yc, v, y_pred, o, rnorm);
    if (it < 0) continue;
    Eigen::VectorXd d = yc - y;
    const double moved = d.norm();
    if (moved < 0.1 * size * kink) continue;
    d /= moved;
    if (d.dot(-t) > 0.9) continue;  // back along the branch already traced
    if (!tangent_at(s, yc, d, d, t_new) || t_new.dot(-t) > 0.9) continue;
    y_new = yc;
    iterations = it;
    return true;
  }
  return false;
}

}  // namespace

int newton_fixed(ParametricResidual& residual, Eigen::VectorXd& x, double lambda, const ArclengthOptions& o,
                 double* residual_norm) {
  int evaluations = 0;
  Scaled s(residual, o, &evaluations);
  const int n = s.n();
  Eigen::VectorXd y = s.to_scaled(x, lambda);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n + 1);
  e[n] = 1.0;
  // Fixing lambda is the augmented system with the constraint row e_lambda.
  double norm = 0.0;
  const int it = corrector(s, y, e, y, o, norm);
  if (residual_norm) *residual_norm = norm;
  if (it >= 0) x = s.x_of(y);
  return it;
}

Branch trace(ParametricResidual& residual, const Eigen::VectorXd& x_guess, const ArclengthOptions& o,
             const std::function<void(const BranchPoint&)>& on_point) {
  Branch branch;
  Scaled s(residual, o, &branch.residual_evaluations);
  const int n = s.n();
  const double direction = o.lambda_end > o.lambda_start ? 1.0 : -1.0;
  const double lambda_lo = std::min(o.lambda_start, o.lambda_end), lambda_hi = std::max(o.lambda_start, o.lambda_end);
  const double lambda_slack = 1e-9 * (lambda_hi - lambda_lo);
  Eigen::VectorXd e_lambda = Eigen::VectorXd::Zero(n + 1);
  e_lambda[n] = 1.0;

  // Start: Newton at lambda_start.
  Eigen::VectorXd y = s.to_scaled(x_guess, o.lambda_start);
  double norm = 0.0;
  int it = corrector(s, y, e_lambda, y, o, norm);
  if (it < 0) {
    branch.status = BranchStatus::kStartFailed;
    std::ostringstream m;
    m << "no solution found at the start of the range (lambda = " << o.lambda_start << ", residual " << norm << ")";
    branch.message = m.str();
    return branch;
  }
  branch.newton_iterations += it;
  Eigen::VectorXd t;
  if (!tangent_at(s, y, e_lambda, direction * e_lambda, t)) {
    branch.status = BranchStatus::kEvaluationFailed;
    branch.message = "the tangent at the start point could not be computed (singular Jacobian)";
    return branch;
  }
  auto accept = [&](const Eigen::VectorXd& yk, const Eigen::VectorXd& tk, int iters, double step, double rnorm) {
    BranchPoint p;
    p.x = s.x_of(yk);
    p.lambda = s.lambda_of(yk);
    p.tangent = tk;
    p.newton_iterations = iters;
    p.step = step;
    p.residual_norm = rnorm;
    branch.points.push_back(p);
    if (on_point) on_point(branch.points.back());
  };
  accept(y, t, it, 0.0, norm);

  double step = o.initial_step;
  const double min_step = o.min_step * o.initial_step, max_step = o.max_step * o.initial_step;
  const double kink_step = o.kink_step * o.initial_step;
  const double cos_max_turn = std::cos(o.max_turn_deg * std::numbers::pi / 180.0);
  bool retracing = false, kink_tried = false;
  int retraced_points = 0;
  // After each turning point: does the branch come back along the stretch it traced before
  // the turn (a twin of it, a sample away)? A sampled friction law can reflect the branch at
  // a corner onto such a twin, which then leads all the way back through the start. A true
  // fold leaves at a distance of the order of the arclength travelled since the turn.
  struct TurnWatch {
    bool active = false;
    std::size_t first = 0;  // index of the first point after the turn
    double arc = 0.0;       // arclength travelled since the turn
    int points = 0;
  } watch;
  std::vector<Eigen::VectorXd> tangents = {t};  // tangent of each accepted point, for backtracking

  while (static_cast<int>(branch.points.size()) < o.max_points) {
    const Eigen::VectorXd y_pred = y + step * t;
    Eigen::VectorXd y_new = y_pred;
    double rnorm = 0.0;
    it = corrector(s, y_new, t, y_pred, o, rnorm);
    Eigen::VectorXd t_new;
    if (it >= 0 && !tangent_at(s, y_new, t, t, t_new)) it = -1;
    // Branch jump: the tangent turned too far over one step. Rejected unless the step is
    // already at kink size.
    if (it >= 0 && step > kink_step && t_new.dot(t) < cos_max_turn) {
      ++branch.rejected_turns;
      it = -1;
    }
    if (it < 0 && step < kink_step && !kink_tried) {
      // The step has shrunk to kink size without a solution: a corner of a nonsmooth branch.
      kink_tried = true;
      if (cross_kink(s, y, t, kink_step, o, y_new, t_new, it, rnorm)) {
        ++branch.kinks_crossed;
        step = (y_new - y).norm();
      } else {
        it = -1;
      }
    }
    if (it < 0) {
      ++branch.rejected_steps;
      step *= 0.5;
      if (step < min_step) {
        branch.status = BranchStatus::kStepTooSmall;
        std::ostringstream m;
        m << "the corrector did not converge even with the arclength step reduced to " << step
          << " (scaled units) at lambda = " << s.lambda_of(y);
        branch.message = m.str();
        return branch;
      }
      continue;
    }
    branch.newton_iterations += it;
    kink_tried = false;

    // Turning point: the lambda component of the tangent changes sign.
    if (t_new[n] * t[n] < 0.0) {
      const bool resolved = std::abs(y_new[n] - y[n]) < 0.1 * o.initial_step;
      if (!retracing && !resolved && static_cast<int>(branch.points.size()) > 1) {
        const int drop = std::min<int>(o.turning_backtrack, static_cast<int>(branch.points.size()) - 1);
        for (int k = 0; k < drop; ++k) {
          branch.points.pop_back();
          tangents.pop_back();
        }
        y = s.to_scaled(branch.points.back().x, branch.points.back().lambda);
        t = tangents.back();
        step = std::max(step / 10.0, min_step);
        retracing = true;
        retraced_points = 0;
        continue;
      }
      ++branch.turning_points;
      retracing = false;
      watch = {true, branch.points.size(), 0.0, 0};
    }
    // Steep branch: the x part of the tangent jumps.
    const double tx_old = t.head(n).norm(), tx_new = t_new.head(n).norm();
    if (tx_old > 0 && tx_new > o.steep_ratio * tx_old) step = std::min(step, o.initial_step);

    const double used_step = step;
    y = y_new;
    t = t_new;
    tangents.push_back(t);
    const double lambda = s.lambda_of(y);

    // Leaving the range: the last point is put on the boundary by Newton at fixed lambda.
    const bool past_end = direction * (lambda - o.lambda_end) > lambda_slack;
    const bool before_start = direction * (lambda - o.lambda_start) < -lambda_slack - o.start_slack;
    if (past_end || before_start) {
      const double bound = past_end ? o.lambda_end : o.lambda_start - direction * o.start_slack;
      const BranchPoint& prev = branch.points.back();
      const double w = (bound - prev.lambda) / (lambda - prev.lambda);
      Eigen::VectorXd yb = s.to_scaled(prev.x + w * (s.x_of(y) - prev.x), bound);
      int itb = corrector(s, yb, e_lambda, yb, o, rnorm);
      if (itb < 0) {  // keep the point outside rather than nothing
        yb = y;
        itb = it;
      } else {
        branch.newton_iterations += itb;
      }
      accept(yb, t, itb, used_step, rnorm);
      branch.status = past_end ? BranchStatus::kReachedEnd : BranchStatus::kLeftRange;
      if (before_start) branch.message = "the branch turned back and left the range through its start";
      return branch;
    }
    accept(y, t, it, used_step, rnorm);
    if (watch.active) {
      watch.arc += used_step;
      if (++watch.points >= kReflectionPoints) {
        if (watch.points >= kReflectionWindow) watch.active = false;
        // Nearest point of the stretch before the turn that a reflection would retrace: back
        // from the turn over twice the arclength travelled since.
        double nearest = std::numeric_limits<double>::infinity(), back = 0.0;
        for (std::size_t j = watch.first; j-- > 0;) {
          nearest = std::min(nearest, (s.to_scaled(branch.points[j].x, branch.points[j].lambda) - y).norm());
          back += branch.points[j].step;  // arclength from point j - 1 to the turn
          if (back > 2.0 * watch.arc) break;
        }
        if (nearest < kReflectionRatio * watch.arc && watch.first >= 1) {
          // Back to the last point before the turn, and over the corner from there (once).
          watch.active = false;
          const std::size_t k = watch.first - 1;
          const Eigen::VectorXd y0 = s.to_scaled(branch.points[k].x, branch.points[k].lambda), t0 = tangents[k];
          Eigen::VectorXd yk, tk;
          int itk = 0;
          double rk = 0.0;
          // Only a crossing that goes on past the turn in lambda counts (the other side of a
          // narrow true fold is a solution too, but not one beyond it).
          const double ahead = t0[n] > 0 ? 1.0 : -1.0;
          const double turn_lambda = ahead * std::max(ahead * branch.points[k].lambda, ahead * branch.points[k + 1].lambda);
          if (cross_kink(s, y0, t0, kink_step, o, yk, tk, itk, rk) && ahead * (s.lambda_of(yk) - turn_lambda) > 0 &&
              ahead * tk[n] > 0) {
            branch.points.resize(k + 1);
            tangents.resize(k + 1);
            --branch.turning_points;
            ++branch.reflections_crossed;
            branch.newton_iterations += itk;
            step = std::max((yk - y0).norm(), min_step);
            y = yk;
            t = tk;
            tangents.push_back(t);
            accept(y, t, itk, step, rk);
            continue;
          }
        }
      }
    }
    // A retrace walks at the small step until it passes the turn (or has walked ten times the
    // dropped stretch, should the turn have been spurious).
    if (retracing && ++retraced_points > 10 * (o.turning_backtrack + 1)) retracing = false;

    // Step control from the Newton effort.
    if (retracing) {
      if (it > o.target_newton_iterations) step = std::max(step * 0.7, min_step);
    } else if (it <= o.target_newton_iterations / 2) step = std::min(step * 1.5, max_step);
    else if (it > o.target_newton_iterations) step = std::max(step * 0.7, min_step);
  }
  branch.status = BranchStatus::kMaxPoints;
  std::ostringstream m;
  m << "stopped after max_points = " << o.max_points << " points at lambda = " << s.lambda_of(y);
  branch.message = m.str();
  return branch;
}

}  // namespace shroudsim::continuation
