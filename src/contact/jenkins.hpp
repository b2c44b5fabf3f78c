#pragma once
// Time-continuous Jenkins element (spring kt in series with a Coulomb slider of slip force
// Fs = mu N0) in periodic steady state under one harmonic, x(theta) = c0 + c1 cos(theta) +
// s1 sin(theta) = c0 + a cos(theta - phi). Reference of the "1d_exact" model and of the tests
// (docs/physics.md section 4). Units: m in, N out.
//
// With r = Fs/(kt a):
//   kt a <= Fs (stick):  F = kt x (mean included, as the discrete map started from d = 0);
//   else beta = acos(1 - 2r), in the frame of the motion (x = a cos psi, psi = theta - phi)
//     F ~ a1 cos(psi) + b1 sin(psi),  a1 = (kt a/pi)(beta - sin(2 beta)/2),
//     b1 = -(4 Fs/pi)(1 - r),  mean 0, energy dissipated per cycle 4 Fs (a - Fs/kt).
#include <Eigen/Core>

namespace shroudsim::contact {

struct JenkinsHarmonics {
  double f0 = 0.0;                                     ///< mean force [N]
  double fc = 0.0;                                     ///< cos(theta) coefficient [N]
  double fs = 0.0;                                     ///< sin(theta) coefficient [N]
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();  ///< d(f0, fc, fs)/d(c0, c1, s1) [N/m]
  bool stick = true;
};

/// First-harmonic (and mean) coefficients of the steady Jenkins force, with their exact
/// derivatives. kt > 0, slip_force >= 0.
JenkinsHarmonics jenkins_single_harmonic(double kt, double slip_force, double c0, double c1, double s1);

/// The steady time-continuous Jenkins force at phase theta [rad].
double jenkins_force(double kt, double slip_force, double c0, double c1, double s1, double theta);

/// Energy dissipated per cycle [J] at amplitude a [m]: 4 Fs (a - Fs/kt) in slip, else 0.
double jenkins_dissipation(double kt, double slip_force, double amplitude);

}  // namespace shroudsim::contact
