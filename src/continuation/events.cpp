#include "continuation/events.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace shroudsim::continuation {

bool locate_fold(ScaledSystem& s, const Eigen::VectorXd& y0, const Eigen::VectorXd& t0, double step,
                 const Eigen::VectorXd& t1, FoldLocation& fold) {
  const int n = s.n();
  // g(s) = t_lambda(s), the tangent at the corrector's solution on t0 . (y - y0) = s,
  // oriented along t0 (the branch turns by less than 90 degrees over an accepted step).
  double a = 0.0, b = step, ga = t0[n], gb = t1[n];
  Eigen::VectorXd ya = y0, ta = t0;
  Eigen::VectorXd yb, tb = t1;
  int side = 0;  // Illinois: which end was kept last time
  // A smooth fold: t_lambda is linear in s there and false position converges in a few
  // iterations; a corner reversal: t_lambda jumps, and after kCornerIterations bisection-like
  // steps the sign change is taken as located (the corner's position is a sampling artefact).
  constexpr int kMaxIterations = 40;
  constexpr int kCornerIterations = 12;
  constexpr double kSmoothTangent = 1e-6;      // |t_lambda| below: the fold itself
  constexpr double kLambdaResolution = 1e-12;  // scaled lambda (a range spans ~100 units)
  fold.newton_iterations = 0;
  for (int it = 0; it < kMaxIterations; ++it) {
    double c = (a * gb - b * ga) / (gb - ga);
    if (!(c > a && c < b)) c = 0.5 * (a + b);
    Eigen::VectorXd y_pred = y0 + c * t0, yc = y_pred, tc;
    double rnorm = 0.0;
    const int itc = correct(s, yc, t0, y_pred, rnorm);
    if (itc < 0 || !s.tangent(yc, t0, t0, tc)) return false;
    fold.newton_iterations += itc;
    const double gc = tc[n];
    if ((gc < 0) == (ga < 0)) {
      a = c, ga = gc, ya = yc, ta = tc;
      if (side == -1) gb *= 0.5;
      side = -1;
    } else {
      b = c, gb = gc, yb = yc, tb = tc;
      if (side == 1) ga *= 0.5;
      side = 1;
    }
    const bool converged = std::abs(gc) < kSmoothTangent || (b - a) < 1e-10 * step ||
                           (yb.size() && std::abs(yb[n] - ya[n]) < kLambdaResolution);
    const bool corner = it + 1 >= kCornerIterations && std::min(std::abs(ta[n]), std::abs(tb[n])) > 1e-2;
    if (converged || corner) {
      fold.y = yc;
      fold.t = tc;
      fold.s = c;
      fold.smooth = !corner && std::abs(gc) < 1e-3;
      return true;
    }
  }
  fold.y = ya;
  fold.t = ta;
  fold.s = a;
  fold.smooth = false;
  return true;
}

bool cross_corner(ScaledSystem& s, const Eigen::VectorXd& y, const Eigen::VectorXd& t, double kink,
                  Eigen::VectorXd& y_new, Eigen::VectorXd& t_new, int& iterations, double& rnorm) {
  std::vector<Eigen::VectorXd> directions;
  for (double beyond : {0.1, 1.0, 10.0}) {
    Eigen::VectorXd tb;
    if (!s.tangent(y + beyond * kink * t, t, t, tb)) continue;
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
    const int it = correct(s, yc, v, y_pred, rnorm);
    if (it < 0) continue;
    Eigen::VectorXd d = yc - y;
    const double moved = d.norm();
    if (moved < 0.1 * size * kink) continue;
    d /= moved;
    if (d.dot(-t) > 0.9) continue;  // back along the branch already traced
    if (!s.tangent(yc, d, d, t_new) || t_new.dot(-t) > 0.9) continue;
    y_new = yc;
    iterations = it;
    return true;
  }
  return false;
}

bool turn_at_corner(ScaledSystem& s, const Eigen::VectorXd& y, const Eigen::VectorXd& t, double reach,
                    Eigen::VectorXd& y_new, Eigen::VectorXd& t_new, int& iterations, double& rnorm) {
  const double tol = s.options().tolerance;
  Eigen::VectorXd r;
  if (!s.evaluate(y, r, nullptr)) return false;
  // The branch's own piece keeps R(y + h t) at its value at y up to second order; past the
  // corner it grows linearly. "Left" = grown above a margin over the tolerance.
  const double base = std::max(r.lpNorm<Eigen::Infinity>(), tol);
  auto left = [&](double h) {
    Eigen::VectorXd rh;
    return !s.evaluate(y + h * t, rh, nullptr) || rh.lpNorm<Eigen::Infinity>() > 4.0 * base;
  };
  if (!left(reach)) return false;
  double lo = 0.0, hi = reach;
  constexpr int kBisections = 60;
  for (int i = 0; i < kBisections && hi - lo > 1e-6 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (left(mid) ? hi : lo) = mid;
  }
  // Just past the corner: the other piece's Jacobian and its null vector.
  const Eigen::VectorXd yk = y + hi * t;
  Eigen::VectorXd tb;
  if (!s.tangent(yk, t, t, tb)) return false;
  // The orientation along which the residual stays flat, tried at growing distances.
  for (double size : {1e-3, 1e-2, 1e-1, 1.0}) {
    const double h = std::max(size * reach, 4.0 * (hi - lo));
    double flat[2];
    for (int k = 0; k < 2; ++k) {
      Eigen::VectorXd rh;
      flat[k] = s.evaluate(yk + (k ? -h : h) * tb, rh, nullptr) ? rh.lpNorm<Eigen::Infinity>()
                                                                : std::numeric_limits<double>::infinity();
    }
    const double sign = flat[0] <= flat[1] ? 1.0 : -1.0;
    const Eigen::VectorXd v = sign * tb;
    const Eigen::VectorXd y_pred = yk + h * v;
    Eigen::VectorXd yc = y_pred;
    const int it = correct(s, yc, v, y_pred, rnorm);
    if (it < 0) continue;
    const Eigen::VectorXd d = yc - y;
    const double moved = d.norm();
    if (moved < 0.5 * h) continue;
    // Not the piece the branch came along, traced backwards.
    if ((d - d.dot(t) * t).norm() < 1e-3 * moved) continue;
    if (!s.tangent(yc, v, v, t_new)) continue;
    y_new = yc;
    iterations = it;
    return true;
  }
  return false;
}

bool ReflectionWatch::observe(const Eigen::VectorXd& y, double step,
                              const std::function<Eigen::VectorXd(std::size_t)>& scaled,
                              const std::function<double(std::size_t)>& step_to) {
  if (!active_) return false;
  arc_ += step;
  if (++points_ < kPoints) return false;
  if (points_ >= kWindow) active_ = false;
  double nearest = std::numeric_limits<double>::infinity(), back = 0.0;
  for (std::size_t j = first_; j-- > 0;) {
    nearest = std::min(nearest, (scaled(j) - y).norm());
    back += step_to(j);
    if (back > 2.0 * arc_) break;
  }
  if (nearest < kRatio * arc_ && first_ >= 1) {
    active_ = false;
    return true;
  }
  return false;
}

Extremum locate_maximum(ParametricResidual& residual, const ArclengthOptions& options, const BranchPoint& from,
                        double step, const std::function<double(const Eigen::VectorXd&, double)>& g,
                        double s_tolerance) {
  return locate_maximum(residual, options, from, 0.0, step, g, s_tolerance);
}

std::vector<Extremum> sample_along(ParametricResidual& residual, const ArclengthOptions& options,
                                   const BranchPoint& from, const std::vector<double>& s,
                                   const std::function<double(const Eigen::VectorXd&, double)>& g) {
  int evaluations = 0;
  ScaledSystem sys(residual, options, &evaluations);
  const Eigen::VectorXd y0 = sys.to_scaled(from.x, from.lambda);
  const Eigen::VectorXd& t0 = from.tangent;
  std::vector<Extremum> out;
  out.reserve(s.size());
  Eigen::VectorXd y_last;
  double s_last = 0.0;
  for (double sj : s) {
    const Eigen::VectorXd y_pred = y0 + sj * t0;
    // The previous solution moved onto this hyperplane (t0 is a unit vector).
    Eigen::VectorXd y = y_last.size() ? Eigen::VectorXd(y_last + (sj - s_last) * t0) : y_pred;
    double rnorm = 0.0;
    const int before = evaluations;
    Extremum e;
    e.s = sj;
    if (correct(sys, y, t0, y_pred, rnorm) >= 0) {
      e.found = true;
      e.x = sys.x_of(y);
      e.lambda = sys.lambda_of(y);
      e.value = g(e.x, e.lambda);
      y_last = y;
      s_last = sj;
    } else {
      y_last.resize(0);
    }
    e.evaluations = evaluations - before;
    out.push_back(std::move(e));
  }
  return out;
}

Extremum locate_maximum(ParametricResidual& residual, const ArclengthOptions& options, const BranchPoint& from,
                        double s_lo, double s_hi, const std::function<double(const Eigen::VectorXd&, double)>& g,
                        double s_tolerance, const Extremum* near) {
  Extremum best;
  int evaluations = 0;
  ScaledSystem sys(residual, options, &evaluations);
  const Eigen::VectorXd y0 = sys.to_scaled(from.x, from.lambda);
  const Eigen::VectorXd& t0 = from.tangent;
  // -g at arclength s (infinity where the corrector fails).
  // Each trial starts from the best trial so far (Brent's trials close in on it; before the
  // first, from `near` or the tangent line), moved along the tangent: far fewer corrector
  // iterations than from the tangent line.
  Eigen::VectorXd y_near;
  double s_near = 0.0;
  if (near && near->found) y_near = sys.to_scaled(near->x, near->lambda), s_near = near->s;
  auto f = [&](double s) {
    const Eigen::VectorXd y_pred = y0 + s * t0;
    Eigen::VectorXd y = y_near.size() ? Eigen::VectorXd(y_near + (s - s_near) * t0) : y_pred;
    double rnorm = 0.0;
    if (correct(sys, y, t0, y_pred, rnorm) < 0) return std::numeric_limits<double>::infinity();
    const Eigen::VectorXd x = sys.x_of(y);
    const double lambda = sys.lambda_of(y), v = g(x, lambda);
    if (!best.found || v > best.value) {
      best = Extremum{true, s, x, lambda, v, 0};
      y_near = y, s_near = s;
    }
    return -v;
  };
  // Brent's minimization of f on [s_lo, s_hi] (golden section with parabolic steps).
  const double golden = 0.5 * (3.0 - std::sqrt(5.0)), tol = s_tolerance * (s_hi - s_lo);
  double a = s_lo, b = s_hi, x = a + golden * (b - a), w = x, v = x, fx = f(x), fw = fx, fv = fx;
  double d = 0.0, e = 0.0;
  for (int it = 0; it < 100; ++it) {
    const double m = 0.5 * (a + b), tol1 = tol, tol2 = 2 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool parabolic = false;
    if (std::abs(e) > tol1) {
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw), p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      if (std::abs(p) < std::abs(0.5 * q * e) && p > q * (a - x) && p < q * (b - x) && std::isfinite(fx)) {
        e = d;
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = x < m ? tol1 : -tol1;
        parabolic = true;
      }
    }
    if (!parabolic) {
      e = (x < m ? b : a) - x;
      d = golden * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0 ? tol1 : -tol1);
    const double fu = f(u);
    if (fu <= fx) {
      if (u < x) b = x;
      else a = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      if (u < x) a = u;
      else b = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  best.evaluations = evaluations;
  return best;
}

double distance_to_branch(ParametricResidual& residual, const ArclengthOptions& options,
                          const std::vector<BranchPoint>& branch, const BranchPoint& p) {
  if (branch.empty()) return std::numeric_limits<double>::infinity();
  int evaluations = 0;
  ScaledSystem sys(residual, options, &evaluations);
  const Eigen::VectorXd yp = sys.to_scaled(p.x, p.lambda);
  std::size_t nearest = 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < branch.size(); ++j) {
    const double d = (sys.to_scaled(branch[j].x, branch[j].lambda) - yp).norm();
    if (d < best) best = d, nearest = j;
  }
  const BranchPoint& q = branch[nearest];
  const Eigen::VectorXd yq = sys.to_scaled(q.x, q.lambda);
  const Eigen::VectorXd y_pred = yq + q.tangent.dot(yp - yq) * q.tangent;
  Eigen::VectorXd y = y_pred;
  double rnorm = 0.0;
  if (correct(sys, y, q.tangent, y_pred, rnorm) < 0) return std::numeric_limits<double>::infinity();
  return (y - yp).norm();
}

}  // namespace shroudsim::continuation
