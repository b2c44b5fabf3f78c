#pragma once
// The update of one time sample of the friction laws (docs/physics.md section 4): from the
// damper position d at sample l-1 and the relative displacement at l to the tangential force
// T(l) and d(l), for a pressed contact with slip limit lim = mu N(l) > 0 (a separated one has
// T = 0 and d = w_t, no update needed). T = kt (w_t - d) always; the functions below differ
// in how d follows when |T| would exceed the limit. Units: m, N, N/m.
//
// Coupled (full3d), 2D tangential:
//   radial_return      T* = kt (w_t(l) - d(l-1)); stick |T*| <= lim: T = T*; slip:
//                      T = lim T*/|T*|, d(l) = w_t(l) - T/kt (first order on 2D orbits).
//   exact_linear_step  w_t and the slip radius a = mu N/kt linear within the step, the
//                      stick/slip evolution integrated exactly (second order), in the
//                      elastic displacement e = w_t - d; with its exact derivative.
// Uncoupled (quasi3d per axis, 1d), one axis, the exact clamp of e = w - d to |e| <= a:
//   axis_radial_return  e = w(l) - d(l-1) clamped to lim/kt.
//   axis_exact_linear   e(l-1) clamped to the start radius a0 = mu N(l-1)/kt (a no-op up to
//                       round-off), the increment added, clamped to the end radius a1.
//   axis_closing        exact_linear where the contact closes within the step: the slider at
//                       the closing instant, the rest of the step clamped to the radius.
// The coupled closing step is exact_linear_step(0, r dw, 0, a1) (periodic_law.cpp).
// All but exact_linear_step are inline: the periodic law calls them once per sample.
#include <Eigen/Core>
#include <array>
#include <cmath>

namespace shroudsim::contact {

/// One coupled radial-return sample. d: the damper position, advanced in place.
struct RadialReturn {
  double tx = 0.0, ty = 0.0;  ///< T [N]
  bool stick = true;          ///< |T*| <= lim: T = T*, d unchanged
  double ex = 0.0, ey = 0.0;  ///< slip: the direction T* / |T*|
  double rho = 0.0;           ///< slip: lim / |T*|
};
inline RadialReturn radial_return(double wx, double wy, std::array<double, 2>& d, double kt, double lim) {
  RadialReturn r;
  const double tsx = kt * (wx - d[0]);
  const double tsy = kt * (wy - d[1]);
  const double nt = std::sqrt(tsx * tsx + tsy * tsy);
  if (nt <= lim) {
    r.tx = tsx;
    r.ty = tsy;
    return r;
  }
  r.stick = false;
  r.ex = tsx / nt;
  r.ey = tsy / nt;
  r.tx = lim * r.ex;
  r.ty = lim * r.ey;
  d = {wx - r.tx / kt, wy - r.ty / kt};
  r.rho = lim / nt;
  return r;
}

/// One exact_linear step of the coupled law in elastic-displacement form (exposed for tests).
/// e0 = w_t(l-1) - d(l-1) [m], dw = w_t(l) - w_t(l-1) [m], slip radii a0 = mu N(l-1)/kt >= 0
/// and a1 = mu N(l)/kt > 0 [m]. w_t and the radius are taken linear within the step and the
/// stick/slip evolution integrated exactly: the stick fraction s* from a quadratic, then the
/// slip angle from tan((q - p1)/2) = tan((q - p0)/2) exp(-|dw| int ds/a(s)) (q = arg dw).
/// Returns e1 = w_t(l) - d(l), |e1| <= a1; if jac != nullptr, also
/// de1/d(e0x, e0y, dwx, dwy, a0, a1) (2 x 6).
/// stuck (optional): set when the whole step sticks from an admissible start (e1 = e0 + dw).
Eigen::Vector2d exact_linear_step(const Eigen::Vector2d& e0, const Eigen::Vector2d& dw, double a0, double a1,
                                  Eigen::Matrix<double, 2, 6>* jac = nullptr, bool* stuck = nullptr);

/// One sample of a 1D law. d: the damper position of the axis, advanced in place.
struct AxisStep {
  double t = 0.0;      ///< T [N]
  double slip = 0.0;   ///< sign (+-1) of the slip at the sample; 0 when it sticks
  double start = 0.0;  ///< axis_exact_linear: sign (+-1) of the clamped start e(l-1); 0 unclamped
};
/// lim = mu N(l) > 0.
inline AxisStep axis_radial_return(double w, double& d, double kt, double lim) {
  AxisStep r;
  const double ts = kt * (w - d);
  if (std::abs(ts) <= lim) {
    r.t = ts;
    return r;
  }
  const double sg = ts > 0.0 ? 1.0 : -1.0;
  r.t = lim * sg;
  d = w - r.t / kt;
  r.slip = sg;
  return r;
}
/// The clamp shared by the exact 1D updates: e1 = v clamped to |e1| <= a1, T = kt e1,
/// d = w - e1; slip: the sign when clamped.
inline AxisStep axis_clamp(double v, double w, double& d, double kt, double a1) {
  AxisStep r;
  double e1 = v;
  if (std::abs(v) > a1) {
    const double sg = v > 0.0 ? 1.0 : -1.0;
    e1 = a1 * sg;
    r.slip = sg;
  }
  r.t = kt * e1;
  d = w - e1;
  return r;
}
/// w, w_prev = w(l), w(l-1); slip radii a0 = mu N(l-1)/kt >= 0, a1 = mu N(l)/kt > 0.
inline AxisStep axis_exact_linear(double w, double w_prev, double& d, double kt, double a0, double a1) {
  double e0 = w_prev - d;
  double start = 0.0;
  if (std::abs(e0) > a0) {
    start = e0 > 0.0 ? 1.0 : -1.0;
    e0 = a0 * start;
  }
  AxisStep r = axis_clamp(e0 + (w - w_prev), w, d, kt, a1);
  r.start = start;
  return r;
}
/// axis_exact_linear for a step in which the contact closes (open at l-1, pressed at l): the
/// slider starts at the closing instant (e = 0 there) and the remaining fraction r in (0, 1]
/// of the step is integrated with the slip radius growing from 0 to a1 = mu N(l)/kt > 0:
/// e(l) = r (w(l) - w(l-1)) clamped to a1.
inline AxisStep axis_closing(double w, double w_prev, double r, double& d, double kt, double a1) {
  return axis_clamp(r * (w - w_prev), w, d, kt, a1);
}

}  // namespace shroudsim::contact
