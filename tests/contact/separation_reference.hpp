#pragma once
// An independent reference for the friction law through separation: the time-continuous 1D
// law (docs/physics.md section 4, no sampling) under a prescribed trigonometric motion, solved
// event by event (closing, stick -> slip, slip -> stick, opening located by bisection to
// round-off) and its force harmonics integrated by composite Gauss-Legendre quadrature on each
// smooth piece. Along a straight tangential line the coupled law (full3d) is this 1D law; the
// uncoupled one (quasi3d) is it per axis. Used by tests/contact and bench/contact.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "contact/contact_law.hpp"

namespace shroudsim::testing {

/// w_j(t) = c[j](0) + sum_k c[j](2k-1) cos(k t) + c[j](2k) sin(k t), j = x, y, z; t in radians
/// of the period [0, 2 pi).
struct TrigMotion {
  std::array<Eigen::VectorXd, 3> c;
  double value(int j, double t) const {
    double v = c[j](0);
    for (int k = 1; 2 * k < c[j].size(); ++k) v += c[j](2 * k - 1) * std::cos(k * t) + c[j](2 * k) * std::sin(k * t);
    return v;
  }
  double rate(int j, double t) const {
    double v = 0.0;
    for (int k = 1; 2 * k < c[j].size(); ++k)
      v += k * (-c[j](2 * k - 1) * std::sin(k * t) + c[j](2 * k) * std::cos(k * t));
    return v;
  }
  /// Samples at t_l = 2 pi (l + shift) / n, l = 0..n-1 (N x 3, the law's input).
  Eigen::MatrixX3d sample(int n, double shift) const {
    Eigen::MatrixX3d w(n, 3);
    for (int l = 0; l < n; ++l)
      for (int j = 0; j < 3; ++j) w(l, j) = value(j, 2.0 * std::numbers::pi * (l + shift) / n);
    return w;
  }
};

/// Fourier coefficients (a0, a1, b1, ..., ah, bh) of samples f(t_l), t_l = 2 pi (l + shift)/n:
/// the trapezoidal rule of the Fourier integrals, as the harmonic balance projects.
inline Eigen::VectorXd sampled_harmonics(const Eigen::VectorXd& f, double shift, int h) {
  const int n = static_cast<int>(f.size());
  Eigen::VectorXd c = Eigen::VectorXd::Zero(2 * h + 1);
  for (int l = 0; l < n; ++l) {
    const double t = 2.0 * std::numbers::pi * (l + shift) / n;
    c(0) += f(l) / n;
    for (int k = 1; k <= h; ++k) {
      c(2 * k - 1) += 2.0 * f(l) * std::cos(k * t) / n;
      c(2 * k) += 2.0 * f(l) * std::sin(k * t) / n;
    }
  }
  return c;
}

/// The time-continuous law along the unit tangential direction (cos theta, sin theta):
/// harmonics of the tangential force T_u and of the normal load, and the fractions of the
/// period spent open, stuck and slipping. stick_after_closing: every closing sticks.
struct ContinuousLaw {
  Eigen::VectorXd tangential, normal;  // (a0, a1, b1, ...) [N]
  double open = 0.0, stick = 0.0, slip = 0.0;
  bool stick_after_closing = true;
  int closings = 0;
};

inline ContinuousLaw continuous_1d_law(const TrigMotion& m, double theta, const contact::PairParameters& p, int h) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const double ct = std::cos(theta), st = std::sin(theta);
  const double kt = p.tangential_stiffness, kn = p.normal_stiffness, mu = p.friction_coefficient;
  auto u = [&](double t) { return ct * m.value(0, t) + st * m.value(1, t); };
  auto up = [&](double t) { return ct * m.rate(0, t) + st * m.rate(1, t); };
  auto nr = [&](double t) { return p.normal_preload + kn * m.value(2, t); };
  auto radius = [&](double t) { return mu * std::max(0.0, nr(t)) / kt; };
  auto radius_rate = [&](double t) { return mu * kn * m.rate(2, t) / kt; };

  // The first sign change of f from > 0 to <= 0 after t0 (scanned at kScan steps, then
  // bisected to round-off); end when there is none before end.
  constexpr int kScan = 1 << 15;
  const double dt = kTwoPi / kScan;
  auto next_root = [&](auto&& f, double t0, double end) {
    double a = t0;
    for (double b = t0 + dt;; b += dt) {
      if (b >= end) b = end;
      if (f(b) <= 0.0) {
        for (int i = 0; i < 200 && b - a > 1e-15 * kTwoPi; ++i) {
          const double c = 0.5 * (a + b);
          (f(c) > 0.0 ? a : b) = c;
        }
        return b;
      }
      if (b >= end) return end;
      a = b;
    }
  };
  // An opening: the normal load falls through zero.
  double t_open = -1.0;
  for (int i = 0; i < kScan && t_open < 0.0; ++i) {
    const double a = i * dt;
    if (nr(a) > 0.0 && nr(a + dt) <= 0.0) t_open = next_root(nr, a, a + dt);
  }
  if (t_open < 0.0) throw std::invalid_argument("continuous_1d_law: the motion does not separate");

  struct Piece {
    double t0, t1;
    int kind;  // 0 open, 1 stick (e = es + u - u(ts)), 2 slip (e = sg a)
    double es, ts, sg;
  };
  std::vector<Piece> pieces;
  ContinuousLaw out;
  const double end = t_open + kTwoPi;
  double t = t_open;
  int kind = 0;
  double es = 0.0, ts = 0.0, sg = 1.0;
  while (t < end) {
    // The current piece runs from t to t1; (nkind, nes, nts, nsg) are those of the next one.
    double t1 = end, nes = 0.0, nts = 0.0, nsg = 1.0;
    int nkind = kind;
    if (kind == 0) {
      t1 = next_root([&](double s) { return -nr(s); }, t, end);
      const bool stick = radius_rate(t1) > std::abs(up(t1));
      if (t1 < end) {
        ++out.closings;
        out.stick_after_closing = out.stick_after_closing && stick;
      }
      nkind = stick ? 1 : 2;
      nes = 0.0;
      nts = t1;
      nsg = up(t1) >= 0.0 ? 1.0 : -1.0;
    } else if (kind == 1) {
      t1 = next_root([&](double s) { return radius(s) - std::abs(es + u(s) - u(ts)); }, t, end);
      nkind = 2;
      nsg = es + u(t1) - u(ts) >= 0.0 ? 1.0 : -1.0;
    } else {
      const double t_opening = next_root(nr, t, end);
      const double t_stick = next_root([&](double s) { return sg * up(s) - radius_rate(s); }, t, end);
      t1 = std::min(t_opening, t_stick);
      nkind = t_opening <= t_stick ? 0 : 1;
      nes = sg * radius(t1);
      nts = t1;
    }
    pieces.push_back({t, t1, kind, es, ts, sg});
    t = t1;
    kind = nkind;
    es = nes;
    ts = nts;
    sg = nsg;
  }
  // Gauss-Legendre, 8 points on [-1, 1].
  static constexpr std::array<double, 8> kX{-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                            -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                            0.7966664774136267,  0.9602898564975363};
  static constexpr std::array<double, 8> kW{0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                            0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                            0.2223810344533745, 0.1012285362903763};
  out.tangential = Eigen::VectorXd::Zero(2 * h + 1);
  out.normal = Eigen::VectorXd::Zero(2 * h + 1);
  constexpr double kWidth = kTwoPi / 4096;  // sub-interval width of the quadrature
  for (const Piece& pc : pieces) {
    const double len = pc.t1 - pc.t0;
    (pc.kind == 0 ? out.open : pc.kind == 1 ? out.stick : out.slip) += len / kTwoPi;
    if (!(len > 0.0)) continue;
    const int parts = std::max(1, static_cast<int>(std::ceil(len / kWidth)));
    const double w = len / parts;
    for (int q = 0; q < parts; ++q) {
      const double mid = pc.t0 + (q + 0.5) * w;
      for (int g = 0; g < 8; ++g) {
        const double s = mid + 0.5 * w * kX[g];
        const double ws = 0.5 * w * kW[g];
        const double tu = pc.kind == 0 ? 0.0 : kt * (pc.kind == 1 ? pc.es + u(s) - u(pc.ts) : pc.sg * radius(s));
        const double nn = pc.kind == 0 ? 0.0 : std::max(0.0, nr(s));
        out.tangential(0) += ws * tu / kTwoPi;
        out.normal(0) += ws * nn / kTwoPi;
        for (int k = 1; k <= h; ++k) {
          const double c = std::cos(k * s) / std::numbers::pi, sn = std::sin(k * s) / std::numbers::pi;
          out.tangential(2 * k - 1) += ws * tu * c;
          out.tangential(2 * k) += ws * tu * sn;
          out.normal(2 * k - 1) += ws * nn * c;
          out.normal(2 * k) += ws * nn * sn;
        }
      }
    }
  }
  return out;
}

// Normal motion: N = N0 (1 - 1.5 cos t + 0.3 sin 2t), open over about a third of the period;
// the contact closes near t = 0.9 with the slip radius growing faster than the tangential
// motion (stick right after closing), slips in the middle and again as the load falls.
// Tangential: the line u(t) = a_s (1.5 cos(t - 0.84) + 0.3 sin 2t) at angle theta, or an
// ellipse (x, y) = a_s (1.5 cos(t - 0.84), 0.8 sin(t - 0.34)) when theta < 0.
inline TrigMotion separating_motion(const contact::PairParameters& p, double theta) {
  const double as = p.friction_coefficient * p.normal_preload / p.tangential_stiffness;
  const double zs = p.normal_preload / p.normal_stiffness;
  TrigMotion m;
  for (auto& c : m.c) c = Eigen::VectorXd::Zero(5);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(5);
  u(1) = 1.5 * as * std::cos(0.84);
  u(2) = 1.5 * as * std::sin(0.84);
  if (theta >= 0.0) {
    u(4) = 0.3 * as;
    m.c[0] = std::cos(theta) * u;
    m.c[1] = std::sin(theta) * u;
  } else {
    m.c[0] = u;
    m.c[1](1) = 0.8 * as * std::sin(-0.34);  // sin(t + p) = sin t cos p + cos t sin p
    m.c[1](2) = 0.8 * as * std::cos(-0.34);
  }
  m.c[2](1) = -1.5 * zs;
  m.c[2](4) = 0.3 * zs;
  return m;
}

}  // namespace shroudsim::testing
