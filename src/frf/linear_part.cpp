#include "frf/linear_part.hpp"

#include <algorithm>
#include <cmath>

namespace shroudsim::frf {

void LinearPart::response_harmonic(int n, double w, Eigen::MatrixXcd& H, Eigen::VectorXcd& u_lin) const {
  HarmonicReceptance rec;
  harmonic(n, w, rec);
  H = std::move(rec.H);
  u_lin = std::move(rec.u_lin);
}

void LinearPart::harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const {
  // Relative to w, whatever its unit (a floor in rad/s would be a coarse step at 0.01 Hz).
  const double h = w != 0.0 ? 1e-6 * std::abs(w) : 1e-6;
  HarmonicReceptance plus, minus;
  harmonic(n, w + h, plus);
  harmonic(n, w - h, minus);
  dG = (plus.G - minus.G) / (2.0 * h);
  dw_lin = (plus.w_lin - minus.w_lin) / (2.0 * h);
}

bool LinearPart::perturbation_form(int family, int k, double /*w*/, double /*max_omega*/, SecondOrderForm& out) const {
  if (family != 0 || !second_order_form(std::abs(k), out)) return false;
  if (k < 0) {
    out.P = out.P.conjugate().eval();
    out.R = out.R.conjugate().eval();
  }
  return true;
}

}  // namespace shroudsim::frf
