#include "contact/jenkins.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace shroudsim::contact {

JenkinsHarmonics jenkins_single_harmonic(double kt, double slip_force, double c0, double c1, double s1) {
  constexpr double kPi = std::numbers::pi;
  JenkinsHarmonics h;
  const double a = std::hypot(c1, s1);
  const double fs = slip_force;
  if (!(fs > 0.0)) {  // no friction: no force
    h.stick = false;
    return h;
  }
  if (kt * a <= fs) {
    h.stick = true;
    h.f0 = kt * c0;
    h.fc = kt * c1;
    h.fs = kt * s1;
    h.jacobian = kt * Eigen::Matrix3d::Identity();
    return h;
  }
  h.stick = false;
  const double r = fs / (kt * a);
  const double beta = std::acos(std::clamp(1.0 - 2.0 * r, -1.0, 1.0));
  // (fc, fs) = g (c1, s1) + q (-s1, c1), g = a1/a, q = b1/a.
  const double g = (kt / kPi) * (beta - 0.5 * std::sin(2.0 * beta));
  const double q = -(4.0 * fs / kPi) * (1.0 / a - fs / (kt * a * a));
  const double dg = -(4.0 * fs * std::sin(beta)) / (kPi * a * a);  // dg/da
  const double dq = -(4.0 * fs / kPi) * (-1.0 / (a * a) + 2.0 * fs / (kt * a * a * a));
  h.fc = g * c1 - q * s1;
  h.fs = g * s1 + q * c1;
  const double ua = c1 / a, va = s1 / a;  // da/dc1, da/ds1
  const double rc = dg * c1 - dq * s1;    // d fc / da
  const double rs = dg * s1 + dq * c1;    // d fs / da
  h.jacobian(1, 1) = g + rc * ua;
  h.jacobian(1, 2) = -q + rc * va;
  h.jacobian(2, 1) = q + rs * ua;
  h.jacobian(2, 2) = g + rs * va;
  return h;
}

double jenkins_force(double kt, double slip_force, double c0, double c1, double s1, double theta) {
  constexpr double kPi = std::numbers::pi;
  const double a = std::hypot(c1, s1);
  const double fs = slip_force;
  if (!(fs > 0.0)) return 0.0;
  if (kt * a <= fs) return kt * (c0 + c1 * std::cos(theta) + s1 * std::sin(theta));
  const double beta = std::acos(std::clamp(1.0 - 2.0 * fs / (kt * a), -1.0, 1.0));
  double psi = std::fmod(theta - std::atan2(s1, c1), 2.0 * kPi);
  if (psi < 0.0) psi += 2.0 * kPi;
  // From the upper turning point (x = a, F = Fs): stick down to -Fs, slip, and back.
  if (psi < beta) return fs - kt * a * (1.0 - std::cos(psi));
  if (psi < kPi) return -fs;
  if (psi < kPi + beta) return -fs + kt * a * (1.0 + std::cos(psi));
  return fs;
}

double jenkins_dissipation(double kt, double slip_force, double amplitude) {
  if (!(slip_force > 0.0) || kt * amplitude <= slip_force) return 0.0;
  return 4.0 * slip_force * (amplitude - slip_force / kt);
}

}  // namespace shroudsim::contact
