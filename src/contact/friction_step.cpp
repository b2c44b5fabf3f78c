#include "contact/friction_step.hpp"

#include "core/error.hpp"

namespace shroudsim::contact {

// ---------------------------------------------------------------------------------------
// exact_linear step. Written once as a template and evaluated either in double or in a
// forward-mode dual number carrying the 6 partial derivatives (e0x, e0y, dwx, dwy, a0, a1):
// the exact derivative of the step (every branch is decided on values, as in the map).
namespace {

constexpr int kNd = 6;  // partials: e0x, e0y, dwx, dwy, a0, a1

struct Dual {
  double v = 0.0;
  std::array<double, kNd> g{};
  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants promote
};

inline double val(double x) { return x; }
inline double val(const Dual& x) { return x.v; }

// f(x) with f(x.v) = value and f'(x.v) = slope.
inline Dual unary(const Dual& x, double value, double slope) {
  Dual r(value);
  for (int i = 0; i < kNd; ++i) r.g[i] = slope * x.g[i];
  return r;
}

inline Dual operator+(const Dual& a, const Dual& b) {
  Dual r(a.v + b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] + b.g[i];
  return r;
}
inline Dual operator-(const Dual& a, const Dual& b) {
  Dual r(a.v - b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] - b.g[i];
  return r;
}
inline Dual operator-(const Dual& a) { return unary(a, -a.v, -1.0); }
inline Dual operator*(const Dual& a, const Dual& b) {
  Dual r(a.v * b.v);
  for (int i = 0; i < kNd; ++i) r.g[i] = a.g[i] * b.v + a.v * b.g[i];
  return r;
}
inline Dual operator/(const Dual& a, const Dual& b) {
  const double q = a.v / b.v;
  Dual r(q);
  for (int i = 0; i < kNd; ++i) r.g[i] = (a.g[i] - q * b.g[i]) / b.v;
  return r;
}
inline Dual operator+(const Dual& a, double b) { return a + Dual(b); }
inline Dual operator-(double a, const Dual& b) { return Dual(a) - b; }
inline Dual operator*(double a, const Dual& b) { return unary(b, a * b.v, a); }
inline Dual operator/(const Dual& a, double b) { return unary(a, a.v / b, 1.0 / b); }

inline Dual sqrt(const Dual& x) {
  const double s = std::sqrt(x.v);
  return unary(x, s, 0.5 / s);
}
inline Dual exp(const Dual& x) {
  const double e = std::exp(x.v);
  return unary(x, e, e);
}
inline Dual log(const Dual& x) { return unary(x, std::log(x.v), 1.0 / x.v); }
inline Dual operator+(double a, const Dual& b) { return Dual(a) + b; }

using std::exp;
using std::log;
using std::sqrt;

// ln(1 + y)/y, smooth through y = 0 (dual-number friendly).
template <class S>
S log1p_over(const S& y) {
  if (std::abs(val(y)) < 1e-6) return 1.0 - y / 2.0 + y * y / 3.0;
  return log(1.0 + y) / y;
}

// One step with w_t and the slip radius a(s) = a0 + s (a1 - a0) linear in s in [0, 1]:
//  stick while |e0 + s dw| < a(s): first crossing s* from the quadratic
//    g(s) = |e0 + s dw|^2 - a(s)^2 = A s^2 + 2 B s + C,  A = |dw|^2 - da^2,
//    B = e0.dw - a0 da,  C = |e0|^2 - a0^2 <= 0;
//  then slip on the circle: with phi = q - p (q = arg dw, p = arg e),
//    a dp/ds = |dw| sin(phi)  =>  tan(phi1/2) = tan(phi0/2) exp(-K),
//    K = |dw| int_{s*}^1 ds/a(s) = |dw| (1 - s*)/a(s*) * ln(1 + y)/y,  y = (1 - s*) da/a(s*),
//  and slip persists once started (g'(s*) >= 0 means dw.e >= a da, and cos(phi) grows).
template <class S>
void exact_linear_step_t(S e0x, S e0y, const S& dwx, const S& dwy, const S& a0, const S& a1, S& e1x, S& e1y,
                         bool& stuck) {
  stuck = false;
  // Start state inside the start circle (it is, up to round-off, by construction).
  const S n0sq = e0x * e0x + e0y * e0y;
  bool projected = false;
  if (val(n0sq) > val(a0) * val(a0)) {
    const S n0 = sqrt(n0sq);
    e0x = a0 * e0x / n0;
    e0y = a0 * e0y / n0;
    projected = true;
  }
  const S dwsq = dwx * dwx + dwy * dwy;
  if (!(val(dwsq) > 0.0)) {
    // No tangential motion: stick, e1 = e0 + dw (dw is zero in value, not in derivative: the
    // stuck stiffness is de1/ddw = I), unless the radius shrinks below |e0| (then on it).
    e1x = e0x + dwx;
    e1y = e0y + dwy;
    const S n1sq = e1x * e1x + e1y * e1y;
    if (val(n1sq) > val(a1) * val(a1)) {
      const S n1 = sqrt(n1sq);
      e1x = a1 * e1x / n1;
      e1y = a1 * e1y / n1;
      return;
    }
    stuck = !projected;
    return;
  }
  const S da = a1 - a0;
  const S A = dwsq - da * da;
  const S B = e0x * dwx + e0y * dwy - a0 * da;
  const S C = e0x * e0x + e0y * e0y - a0 * a0;
  const S disc = B * B - A * C;
  bool crosses = false;
  S s(0.0);
  if (val(B) > 0.0) {
    if (val(disc) >= 0.0) {
      crosses = true;
      const S root = val(disc) > 0.0 ? sqrt(disc) : S(0.0);
      s = (-C) / (B + root);
    }
  } else if (val(A) > 0.0) {
    crosses = true;
    const S root = val(disc) > 0.0 ? sqrt(disc) : S(0.0);
    s = (root - B) / A;
  }
  if (!crosses || val(s) >= 1.0) {  // stick over the whole step
    e1x = e0x + dwx;
    e1y = e0y + dwy;
    stuck = !projected;
    return;
  }
  // Trigonometry-free: unit vectors q^ = dw/|dw|, u = e(s*)/|e(s*)|, cos/sin of phi0 from
  // dot/cross products, tan(phi/2) by the half-angle identities.
  const S dwn = sqrt(dwsq);
  const S qx = dwx / dwn, qy = dwy / dwn;
  const S as = a0 + s * da;  // radius at the onset of slip
  if (!(val(as) > 0.0)) {    // contact closing at this instant: force along the motion
    e1x = a1 * qx;
    e1y = a1 * qy;
    return;
  }
  const S esx = e0x + s * dwx;
  const S esy = e0y + s * dwy;
  const S esn = sqrt(esx * esx + esy * esy);
  const S ux = esx / esn, uy = esy / esn;
  const S c0 = qx * ux + qy * uy;           // cos(phi0)
  const S s0 = qy * ux - qx * uy;           // sin(phi0), phi0 = q - p0
  if (val(c0) <= -0.5 && val(s0) == 0.0) {  // phi0 = pi: stays opposite to the motion
    e1x = -(a1 * qx);
    e1y = -(a1 * qy);
    return;
  }
  const S t0 = val(c0) > -0.5 ? s0 / (1.0 + c0) : (1.0 - c0) / s0;  // tan(phi0/2)
  const S r = 1.0 - s;
  const S kappa = r * dwn / as * log1p_over(r * da / as);
  const S t1 = t0 * exp(-kappa);  // tan(phi1/2)
  S c1, s1;
  if (std::abs(val(t1)) <= 1.0) {
    const S den = 1.0 + t1 * t1;
    c1 = (1.0 - t1 * t1) / den;
    s1 = 2.0 * t1 / den;
  } else {
    const S v = 1.0 / t1;
    const S den = v * v + 1.0;
    c1 = (v * v - 1.0) / den;
    s1 = 2.0 * v / den;
  }
  // e1 = a1 (cos p1, sin p1), p1 = q - phi1.
  e1x = a1 * (qx * c1 + qy * s1);
  e1y = a1 * (qy * c1 - qx * s1);
}

inline Dual seed(double value, int index) {
  Dual r(value);
  r.g[index] = 1.0;
  return r;
}

}  // namespace

Eigen::Vector2d exact_linear_step(const Eigen::Vector2d& e0, const Eigen::Vector2d& dw, double a, double a_end,
                                  Eigen::Matrix<double, 2, 6>* jac, bool* stuck) {
  bool stuck_local = false;
  bool& st = stuck ? *stuck : stuck_local;
  SHROUDSIM_ASSERT(a >= 0.0 && a_end > 0.0, "exact_linear_step needs a0 >= 0, a1 > 0");
  if (jac == nullptr) {
    double e1x = 0.0, e1y = 0.0;
    exact_linear_step_t<double>(e0.x(), e0.y(), dw.x(), dw.y(), a, a_end, e1x, e1y, st);
    return {e1x, e1y};
  }
  Dual e1x, e1y;
  exact_linear_step_t<Dual>(seed(e0.x(), 0), seed(e0.y(), 1), seed(dw.x(), 2), seed(dw.y(), 3), seed(a, 4),
                            seed(a_end, 5), e1x, e1y, st);
  for (int i = 0; i < kNd; ++i) {
    (*jac)(0, i) = e1x.g[i];
    (*jac)(1, i) = e1y.g[i];
  }
  return {e1x.v, e1y.v};
}

}  // namespace shroudsim::contact
