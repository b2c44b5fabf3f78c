#include "contact/static_contact.hpp"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace shroudsim::contact {

std::string to_string(StaticState s) {
  switch (s) {
    case StaticState::open: return "open";
    case StaticState::stick: return "stick";
    case StaticState::slip: return "slip";
  }
  return "?";
}

StaticContact::StaticContact(std::vector<StaticPairParameters> pairs) : pairs_(std::move(pairs)) {
  for (const auto& p : pairs_) {
    if (!(p.normal_stiffness > 0) || !(p.tangential_stiffness > 0) || !std::isfinite(p.normal_stiffness) ||
        !std::isfinite(p.tangential_stiffness))
      throw std::invalid_argument("static contact: stiffnesses must be finite and > 0");
    if (!(p.friction_coefficient >= 0) || !std::isfinite(p.friction_coefficient))
      throw std::invalid_argument("static contact: friction coefficient must be finite and >= 0");
    if (!std::isfinite(p.interference)) throw std::invalid_argument("static contact: interference must be finite");
  }
  state_.resize(pairs_.size());
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    // At rest and unloaded: g = 0; closed where the faces overlap.
    Eigen::Matrix3d dF;
    state_[i].force = law(pairs_[i], state_[i].g, state_[i].slider, &state_[i].state, &dF);
    state_[i].gap = state_[i].state == StaticState::open ? -pairs_[i].interference : 0.0;
  }
}

Eigen::Vector3d StaticContact::law(const StaticPairParameters& p, const Eigen::Vector3d& g, const Eigen::Vector2d& s,
                                   StaticState* state, Eigen::Matrix3d* dF) {
  Eigen::Vector3d F = Eigen::Vector3d::Zero();
  if (dF) dF->setZero();
  const double pen = p.interference + g[2];
  if (!(pen > 0)) {
    if (state) *state = StaticState::open;
    return F;
  }
  const double N = p.normal_stiffness * pen;
  F[2] = N;
  if (dF) (*dF)(2, 2) = p.normal_stiffness;
  const Eigen::Vector2d trial = p.tangential_stiffness * (g.head<2>() - s);
  const double limit = p.friction_coefficient * N, norm = trial.norm();
  if (norm <= limit) {
    F.head<2>() = trial;
    if (dF) (*dF)(0, 0) = (*dF)(1, 1) = p.tangential_stiffness;
    if (state) *state = StaticState::stick;
    return F;
  }
  const Eigen::Vector2d e = trial / norm;
  F.head<2>() = limit * e;
  if (dF) {
    dF->topLeftCorner<2, 2>() =
        limit / norm * p.tangential_stiffness * (Eigen::Matrix2d::Identity() - e * e.transpose());
    dF->block<2, 1>(0, 2) = p.friction_coefficient * p.normal_stiffness * e;
  }
  if (state) *state = StaticState::slip;
  return F;
}

Eigen::VectorXd StaticContact::forces() const {
  Eigen::VectorXd F(3 * n_pairs());
  for (int i = 0; i < n_pairs(); ++i) F.segment<3>(3 * i) = state_[i].force;
  return F;
}

StaticStep StaticContact::solve(const Eigen::MatrixXd& C, const Eigen::VectorXd& g_ext, int max_iterations) {
  const int n = 3 * n_pairs();
  if (C.rows() != n || C.cols() != n || g_ext.size() != n) throw std::invalid_argument("static contact: wrong sizes");
  StaticStep step;
  if (n == 0) {
    step.converged = true;
    return step;
  }
  Eigen::VectorXd g(n);
  for (int i = 0; i < n_pairs(); ++i) g.segment<3>(3 * i) = state_[i].g;
  // Length scale of the residual: the larger of the external motion and the overlaps.
  double scale = g_ext.lpNorm<Eigen::Infinity>();
  for (const auto& p : pairs_) scale = std::max(scale, std::abs(p.interference));
  if (!(scale > 0)) scale = 1.0;
  constexpr double kTolerance = 1e-10;  // relative to scale: a few hundred round-offs of g

  Eigen::VectorXd F(n), r(n), F_try(n), r_try(n);
  Eigen::MatrixXd J(n, n), dFall = Eigen::MatrixXd::Zero(n, n);
  auto evaluate = [&](const Eigen::VectorXd& gg, Eigen::VectorXd& FF, Eigen::VectorXd& rr, bool jac) {
    for (int i = 0; i < n_pairs(); ++i) {
      Eigen::Matrix3d d;
      FF.segment<3>(3 * i) = law(pairs_[i], gg.segment<3>(3 * i), state_[i].slider, nullptr, jac ? &d : nullptr);
      if (jac) dFall.block<3, 3>(3 * i, 3 * i) = d;
    }
    rr = gg - g_ext + C * FF;
  };
  evaluate(g, F, r, true);
  double norm = r.lpNorm<Eigen::Infinity>() / scale;
  int it = 0;
  for (; it < max_iterations && !(norm <= kTolerance); ++it) {
    J = Eigen::MatrixXd::Identity(n, n) + C * dFall;
    const Eigen::VectorXd d = J.partialPivLu().solve(-r);
    if (!d.allFinite()) break;
    // Backtracking on |r|: a full step that does not reduce it is halved (down to 1/1024).
    double a = 1.0;
    bool reduced = false;
    for (; a >= 1.0 / 1024; a *= 0.5) {
      evaluate(g + a * d, F_try, r_try, false);
      if (r_try.lpNorm<Eigen::Infinity>() / scale < norm) {
        reduced = true;
        break;
      }
    }
    if (!reduced) break;
    g += a * d;
    evaluate(g, F, r, true);
    norm = r.lpNorm<Eigen::Infinity>() / scale;
  }
  step.newton_iterations = it;
  step.residual = norm;
  step.converged = norm <= kTolerance;
  if (!step.converged) {
    step.message = "the static contact did not converge (relative residual " + std::to_string(norm) + " after " +
                   std::to_string(it) + " Newton iterations)";
    return step;
  }
  for (int i = 0; i < n_pairs(); ++i) {
    StaticPairResult& s = state_[i];
    s.g = g.segment<3>(3 * i);
    s.force = law(pairs_[i], s.g, s.slider, &s.state, nullptr);
    if (s.state == StaticState::slip) s.slider = s.g.head<2>() - s.force.head<2>() / pairs_[i].tangential_stiffness;
    if (s.state == StaticState::open) s.slider = s.g.head<2>();  // an open pair re-closes unloaded
    s.gap = s.state == StaticState::open ? -(pairs_[i].interference + s.g[2]) : 0.0;
  }
  return step;
}

}  // namespace shroudsim::contact
