#include "continuation/arclength.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "continuation/events.hpp"
#include "continuation/scaled_system.hpp"
#include "continuation/step_control.hpp"

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
    case BranchStatus::kClosedLoop: return "closed_loop";
    case BranchStatus::kMaxPoints: return "max_points";
    case BranchStatus::kStepTooSmall: return "step_too_small";
    case BranchStatus::kStartFailed: return "start_failed";
    case BranchStatus::kEvaluationFailed: return "evaluation_failed";
  }
  return "unknown";
}

bool ArclengthOptions::validate(int n, std::vector<std::string>* errors) const {
  std::vector<std::string> e;
  if (!(std::isfinite(lambda_start) && std::isfinite(lambda_end) && lambda_end != lambda_start))
    e.push_back("lambda_start, lambda_end finite and different");
  if (!(initial_step > 0 && std::isfinite(initial_step))) e.push_back("initial_step > 0");
  if (!(min_step > 0 && min_step < 1)) e.push_back("0 < min_step < 1");
  if (!(max_step >= 1 && std::isfinite(max_step))) e.push_back("max_step >= 1");
  if (!(max_lambda_step >= 0 && std::isfinite(max_lambda_step))) e.push_back("max_lambda_step >= 0 (0: none)");
  if (!(max_turn_deg > 0 && max_turn_deg < 180)) e.push_back("0 < max_turn_deg < 180");
  if (!(target_turn_deg > 0 && target_turn_deg <= max_turn_deg)) e.push_back("0 < target_turn_deg <= max_turn_deg");
  if (!(kink_step > 0 && kink_step <= 1)) e.push_back("0 < kink_step <= 1");
  if (!(max_points >= 1)) e.push_back("max_points >= 1");
  if (!(tolerance > 0)) e.push_back("tolerance > 0");
  if (!(max_newton_iterations >= 1)) e.push_back("max_newton_iterations >= 1");
  if (!(target_newton_iterations >= 1)) e.push_back("target_newton_iterations >= 1");
  if (!(lambda_scale > 0 && std::isfinite(lambda_scale))) e.push_back("lambda_scale > 0");
  if (!(start_slack >= 0)) e.push_back("start_slack >= 0");
  if (x_scale.size() && x_scale.size() != n) e.push_back("x_scale of size n = " + std::to_string(n) + " (or empty)");
  if (x_scale.size() && !((x_scale.array() > 0).all() && x_scale.allFinite())) e.push_back("x_scale > 0 and finite");
  if (residual_scale.size() && residual_scale.size() != n)
    e.push_back("residual_scale of size n = " + std::to_string(n) + " (or empty)");
  if (residual_scale.size() && !((residual_scale.array() > 0).all() && residual_scale.allFinite()))
    e.push_back("residual_scale > 0 and finite");
  if (errors) *errors = e;
  return e.empty();
}

namespace {
void check_options(const ParametricResidual& residual, const Eigen::VectorXd& x, const ArclengthOptions& o) {
  std::vector<std::string> errors;
  if (!o.validate(residual.size(), &errors))
    throw std::invalid_argument("continuation: invalid ArclengthOptions: " + errors.front());
  if (x.size() != residual.size())
    throw std::invalid_argument("continuation: the initial guess has size " + std::to_string(x.size()) +
                                ", the residual " + std::to_string(residual.size()));
}

// Is the newest point (the last of ys and points, reached by a step h) a point passed before, more than
// kLoopGap points back, travelling the same way? A candidate lies within a twentieth of the
// chord of an earlier step (a smooth branch is that close to its chords) with both tangents
// along t; it is confirmed by the corrector from that step's first point onto the hyperplane
// through y: the branch's own point there must be y to within kLoopTolerance times the
// corrector's tolerance. A twin a sample away (the far side of a Z at a corner of a sampled
// law, running alongside at the slab's width) stays at its own distance.
bool closes_loop(ParametricResidual& residual, const ArclengthOptions& o, const std::vector<Eigen::VectorXd>& ys,
                 const std::vector<BranchPoint>& points, double h) {
  constexpr std::size_t kLoopGap = 8;
  constexpr double kChordFraction = 0.05;
  constexpr double kSameWay = 0.99;  // cosine between the tangents
  constexpr double kLoopTolerance = 100.0;
  const std::size_t m = ys.size();
  if (m < kLoopGap + 2) return false;
  const Eigen::VectorXd& y = ys.back();
  const Eigen::VectorXd& t = points.back().tangent;
  const int n = static_cast<int>(y.size()) - 1;
  for (std::size_t j = 0; j + kLoopGap + 1 < m; ++j) {
    const Eigen::VectorXd& a = ys[j];
    const Eigen::VectorXd& b = ys[j + 1];
    const double lo = std::min(a[n], b[n]), hi = std::max(a[n], b[n]);
    if (y[n] < lo - h || y[n] > hi + h) continue;  // cheap filter on lambda
    const Eigen::VectorXd ab = b - a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0)) continue;
    const double u = std::clamp((y - a).dot(ab) / len2, 0.0, 1.0);
    const double dist = (a + u * ab - y).norm();
    const double len = std::sqrt(len2);
    if (dist <= kChordFraction * std::min(len, h) && t.dot(points[j].tangent) > kSameWay &&
        t.dot(points[j + 1].tangent) > kSameWay &&
        distance_to_branch(residual, o, {points[j]}, points.back()) <= kLoopTolerance * o.tolerance)
      return true;
  }
  return false;
}

double angle_between(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0));
}
}  // namespace

int newton_fixed(ParametricResidual& residual, Eigen::VectorXd& x, double lambda, const ArclengthOptions& o,
                 double* residual_norm) {
  check_options(residual, x, o);
  int evaluations = 0;
  ScaledSystem s(residual, o, &evaluations);
  const int n = s.n();
  Eigen::VectorXd y = s.to_scaled(x, lambda);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n + 1);
  e[n] = 1.0;
  // Fixing lambda is the augmented system with the constraint row e_lambda.
  double norm = 0.0;
  const int it = correct(s, y, e, y, norm);
  if (residual_norm) *residual_norm = norm;
  if (it >= 0) x = s.x_of(y);
  return it;
}

Branch trace(ParametricResidual& residual, const Eigen::VectorXd& x_guess, const ArclengthOptions& o,
             const std::function<void(const BranchPoint&)>& on_point) {
  check_options(residual, x_guess, o);
  Branch branch;
  ScaledSystem s(residual, o, &branch.residual_evaluations);
  const int n = s.n();
  const double direction = o.lambda_end > o.lambda_start ? 1.0 : -1.0;
  const double lambda_slack = 1e-9 * std::abs(o.lambda_end - o.lambda_start);
  Eigen::VectorXd e_lambda = Eigen::VectorXd::Zero(n + 1);
  e_lambda[n] = 1.0;

  std::vector<Eigen::VectorXd> ys;  // the scaled coordinates of every point
  std::size_t emitted = 0;
  ReflectionWatch watch;
  // Points are reported once no reflection check can remove them any more.
  auto emit = [&](bool all) {
    const std::size_t upto = all || !watch.active() ? branch.points.size() : watch.first();
    for (; emitted < upto; ++emitted)
      if (on_point) on_point(branch.points[emitted]);
  };
  auto push = [&](const Eigen::VectorXd& yk, const Eigen::VectorXd& tk, int iters, double step, double rnorm,
                  PointKind kind) {
    BranchPoint p;
    p.x = s.x_of(yk);
    p.lambda = s.lambda_of(yk);
    p.tangent = tk;
    p.newton_iterations = iters;
    p.step = step;
    p.residual_norm = rnorm;
    p.kind = kind;
    branch.points.push_back(std::move(p));
    ys.push_back(yk);
  };
  auto finish = [&](BranchStatus status, const std::string& message) {
    branch.status = status;
    branch.message = message;
    emit(true);
    return branch;
  };

  // Start: Newton at lambda_start.
  Eigen::VectorXd y = s.to_scaled(x_guess, o.lambda_start);
  double norm = 0.0;
  int it = correct(s, y, e_lambda, y, norm);
  if (it < 0) {
    std::ostringstream m;
    m << "no solution found at the start of the range (lambda = " << o.lambda_start << ", residual " << norm << ")";
    return finish(BranchStatus::kStartFailed, m.str());
  }
  branch.newton_iterations += it;
  Eigen::VectorXd t;
  if (!s.tangent(y, e_lambda, direction * e_lambda, t))
    return finish(BranchStatus::kEvaluationFailed,
                  "the tangent at the start point could not be computed (singular Jacobian)");
  push(y, t, it, 0.0, norm, PointKind::kRegular);
  emit(false);

  StepControl steps(o);
  const double cos_max_turn = std::cos(o.max_turn_deg * std::numbers::pi / 180.0);
  bool corner_tried = false;
  // Consecutive accepted steps below kink size before the corner crossing is tried anyway.
  constexpr int kStallSteps = 25;
  int tiny_steps = 0;

  while (static_cast<int>(branch.points.size()) < o.max_points) {
    // Predictor and corrector.
    double h = steps.step();
    if (o.max_lambda_step > 0 && std::abs(t[n]) * h > o.max_lambda_step) {
      steps.set(o.max_lambda_step / std::abs(t[n]));  // a rejection halves from here
      h = steps.step();
    }
    const Eigen::VectorXd y_pred = y + h * t;
    Eigen::VectorXd y_new = y_pred, t_new;
    double rnorm = 0.0;
    it = correct(s, y_new, t, y_pred, rnorm);
    if (it >= 0 && !s.tangent(y_new, t, t, t_new)) it = -1;
    // A step whose tangent turned too far has most likely jumped to a nearby branch.
    if (it >= 0 && h > steps.kink() && t_new.dot(t) < cos_max_turn) {
      ++branch.rejected_turns;
      it = -1;
    }
    // A step over which the solution itself turned (the direction of x, e.g. the response's
    // phase flipping across a resonance far narrower than the step, where the amplitude stays
    // small in the problem's units and the tangent barely turns) has stepped over a peak.
    if (it >= 0 && h > steps.kink()) {
      const double a = y.head(n).norm(), b = y_new.head(n).norm();
      if (a > 0 && b > 0 && y.head(n).dot(y_new.head(n)) < cos_max_turn * a * b) {
        ++branch.rejected_turns;
        it = -1;
      }
    }
    bool crossed_corner = false;
    if (it < 0 && h < steps.kink() && !corner_tried) {
      // No solution even at kink size: a corner of a nonsmooth branch.
      corner_tried = true;
      if (cross_corner(s, y, t, steps.kink(), y_new, t_new, it, rnorm) ||
          turn_at_corner(s, y, t, steps.kink(), y_new, t_new, it, rnorm)) {
        ++branch.kinks_crossed;
        crossed_corner = true;
        h = (y_new - y).norm();
      } else {
        it = -1;
      }
    }
    if (it < 0) {
      ++branch.rejected_steps;
      if (!steps.rejected()) {
        std::ostringstream m;
        m << "the corrector did not converge even with the arclength step reduced to " << steps.step()
          << " (scaled units) at lambda = " << s.lambda_of(y);
        return finish(BranchStatus::kStepTooSmall, m.str());
      }
      continue;
    }
    branch.newton_iterations += it;
    corner_tried = false;
    const double turn = angle_between(t, t_new);

    // Fold event: t_lambda changes sign between y and y_new; located and inserted.
    if (t_new[n] * t[n] < 0.0) {
      ++branch.turning_points;
      FoldLocation fold;
      if (!crossed_corner && locate_fold(s, y, t, h, t_new, fold)) {
        branch.newton_iterations += fold.newton_iterations;
        branch.smooth_folds += fold.smooth ? 1 : 0;
        const double lf = s.lambda_of(fold.y);
        const bool inside = direction * (lf - o.lambda_end) <= lambda_slack &&
                            direction * (lf - o.lambda_start) >= -lambda_slack - o.start_slack;
        if (inside) {
          push(fold.y, fold.t, fold.newton_iterations, fold.s, 0.0,
               fold.smooth ? PointKind::kFold : PointKind::kCorner);
          h = std::max(h - fold.s, 0.0);
          if (static_cast<int>(branch.points.size()) >= o.max_points) break;  // the fold took the last place
        }
      }
      watch.arm(branch.points.size() - (branch.points.back().kind == PointKind::kRegular ? 0 : 1));
    }

    // Leaving the range: the last point is put on the boundary by Newton at fixed lambda.
    const double lambda = s.lambda_of(y_new);
    const bool past_end = direction * (lambda - o.lambda_end) > lambda_slack;
    const bool before_start = direction * (lambda - o.lambda_start) < -lambda_slack - o.start_slack;
    if (past_end || before_start) {
      const double bound = past_end ? o.lambda_end : o.lambda_start - direction * o.start_slack;
      const Eigen::VectorXd& yp = ys.back();
      const double w = (bound / o.lambda_scale - yp[n]) / (y_new[n] - yp[n]);
      Eigen::VectorXd yb = yp + w * (y_new - yp);
      yb[n] = bound / o.lambda_scale;
      int itb = correct(s, yb, e_lambda, yb, rnorm);
      PointKind kind = PointKind::kBoundary;
      if (itb < 0) {  // keep the point outside rather than nothing
        yb = y_new;
        itb = it;
        kind = PointKind::kRegular;
      } else {
        branch.newton_iterations += itb;
      }
      push(yb, t_new, itb, h, rnorm, kind);
      if (past_end) return finish(BranchStatus::kReachedEnd, "");
      return finish(BranchStatus::kLeftRange, "the branch turned back and left the range through its start");
    }
    y = y_new;
    t = t_new;
    push(y, t, it, h, rnorm, PointKind::kRegular);
    if (closes_loop(residual, o, ys, branch.points, h))
      return finish(BranchStatus::kClosedLoop,
                    "the branch closed on itself at lambda = " + std::to_string(s.lambda_of(y)) +
                        " (it came back to a point passed before, travelling the same way)");

    // Reflection at a corner: back to the last point before the turn and over the corner.
    if (watch.observe(
            y, h, [&](std::size_t j) -> Eigen::VectorXd { return ys[j]; },
            [&](std::size_t j) { return branch.points[j].step; })) {
      const std::size_t k = watch.first() - 1;
      const Eigen::VectorXd y0 = ys[k], t0 = branch.points[k].tangent;
      Eigen::VectorXd yk, tk;
      int itk = 0;
      double rk = 0.0;
      // Only a crossing that goes on past the turn in lambda counts (the other side of a
      // narrow true fold is a solution too, but not one beyond it).
      const double ahead = t0[n] > 0 ? 1.0 : -1.0;
      const double turn_lambda = ahead * std::max(ahead * ys[k][n], ahead * ys[k + 1][n]) * o.lambda_scale;
      if (cross_corner(s, y0, t0, steps.kink(), yk, tk, itk, rk) && ahead * (s.lambda_of(yk) - turn_lambda) > 0 &&
          ahead * tk[n] > 0) {
        if (branch.points[k + 1].kind == PointKind::kFold) --branch.smooth_folds;
        branch.points.resize(k + 1);
        ys.resize(k + 1);
        --branch.turning_points;
        ++branch.reflections_crossed;
        branch.newton_iterations += itk;
        y = yk;
        t = tk;
        push(y, t, itk, (yk - y0).norm(), rk, PointKind::kRegular);
        steps.set((yk - y0).norm());
        emit(false);
        continue;
      }
    }
    emit(false);
    steps.accepted(it, turn);

    // Stall: accepted steps far below kink size that zig-zag between the pieces of a corner
    // (each turns the tangent, so the step never grows back) are a corner too.
    if (h < steps.kink() && ++tiny_steps >= kStallSteps) {
      tiny_steps = 0;
      Eigen::VectorXd yk, tk;
      int itk = 0;
      double rk = 0.0;
      if (cross_corner(s, y, t, steps.kink(), yk, tk, itk, rk)) {
        ++branch.kinks_crossed;
        branch.newton_iterations += itk;
        const double jump = (yk - y).norm();
        y = yk;
        t = tk;
        push(y, t, itk, jump, rk, PointKind::kRegular);
        steps.set(std::max(jump, steps.kink()));
        emit(false);
      }
    } else if (h >= steps.kink()) {
      tiny_steps = 0;
    }
  }
  std::ostringstream m;
  m << "stopped after max_points = " << o.max_points << " points at lambda = " << s.lambda_of(y);
  return finish(BranchStatus::kMaxPoints, m.str());
}

}  // namespace shroudsim::continuation
