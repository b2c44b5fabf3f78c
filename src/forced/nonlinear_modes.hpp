#pragma once
// Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015; docs/physics.md
// section 10). The autonomous system
//     M q'' + (C - zeta M) q' + K q + B^H f_nl(B q) = 0
// has, at every modal amplitude a, a periodic solution of frequency w whose artificial
// negative damping -zeta M balances all the dissipation (viscous and friction) over a period.
// The mode's frequency is w and its modal damping ratio D = zeta / (2 w).
//
// Unknowns (the reduced form of section 3, no excitation): the contact relative displacements
// W (real harmonic coefficients, the NonlinearForce layout), w [rad/s] and zeta [1/s]:
//   r_W   = W + G(w, zeta) (F(W) - F_s) = 0        (F_s only in harmonic 0),
//   r_a   = sqrt(q_1^H M q_1) / a - 1 = 0,  q_1 = -X_1 F_1 (the fundamental of the physical
//           motion, frf::DampedReceptance: F_1^H N F_1 = q_1^H M q_1),
//   r_phi = s_1 of contact coefficient j = 0 (the sine part of the fundamental of the contact
//           direction that moves most in the linear mode: the phase of the autonomous motion).
// The amplitude is stated on the physical motion, not on W (a motion that does not load the
// contacts has W = 0 and F = 0 and is not a solution this form can carry: such a mode is
// refused at the start). G, its w- and zeta-derivatives and N come from
// frf::LinearPart::damped_harmonic; dF/dW from the force's analytic Jacobian.
//
// Continuation: in lambda = log10(a) from amplitude_start to amplitude_end, secant predictor
// of (W / a, w, zeta) in lambda, Newton corrector on the square (n + 2) system scaled by
// (a c_W, w_0, w_0) (c_W the largest contact motion of the unit linear mode), step in
// lambda grown (x 1.5) after an easy corrector and halved after a failed one. Start: the
// linear mode of the second-order form (frf::SecondOrderForm of harmonic 1: M, C, K, P and
// the massless part R) with the contacts linearized about W = 0: K + P^H K_c (I + R K_c)^-1 P
// (K_c the force's first-harmonic stiffness at W = 0: the contact springs when stuck and
// closed, nothing when open; R, the residual flexibility of an FE sector, condensed in),
// zeta_0 = phi^H C phi. For a lumped model P = B, R = 0; for an FE sector (frf/sector.hpp) the
// coordinates are the modes of the engine order's harmonic index, complex, and the mode is
// the travelling wave of that index.
//
// Usage:
//   forced::NonlinearModeSettings s;  s.amplitude_start = 1e-6;  s.amplitude_end = 1e-2;
//   const forced::NonlinearModeCurve curve = forced::trace_nonlinear_mode(linear, contacts, s);
//   for (const auto& p : curve.points) use(p.amplitude, p.frequency_hz, p.damping_ratio);
#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "frf/linear_part.hpp"
#include "hbm/nonlinear_force.hpp"

namespace shroudsim::forced {

struct NonlinearModeSettings {
  double amplitude_start = 1e-6;  ///< modal amplitude a [m kg^0.5] (q_1^H M q_1 = a^2)
  double amplitude_end = 1e-2;    ///< > amplitude_start
  int mode = 1;                   ///< 1-based index of the linear mode (ascending frequency)
  int max_points = 500;
  double initial_step = 0.02;  ///< decades of a
  double max_step = 0.05;      ///< decades of a: resolution of the curve
  double min_step = 1e-6;      ///< decades of a: stop below
  double tolerance = 1e-10;    ///< scaled residual, infinity norm
  int max_newton_iterations = 30;
  /// One message per violated constraint, keys as in docs/contract.md ([nlmodes]).
  bool validate(std::vector<std::string>* errors) const;
};

/// The linear mode the nonlinear mode starts from.
struct LinearMode {
  double omega = 0.0;    ///< [rad/s]
  double zeta = 0.0;     ///< phi^H C phi [1/s]
  Eigen::VectorXcd phi;  ///< mass-normalised, in the second-order form's coordinates
  /// W of the unit mode: (I + R K_c)^-1 P phi (c), its largest component real and positive
  Eigen::VectorXcd contact_motion;
  Eigen::MatrixXd contact_stiffness;  ///< K_c (c x c) the mode was computed with
};

struct NonlinearModePoint {
  double amplitude = 0.0;  ///< a [m kg^0.5]
  double omega = 0.0;      ///< [rad/s]
  double frequency_hz = 0.0;
  double zeta = 0.0;                 ///< [1/s]
  double damping_ratio = 0.0;        ///< D = zeta / (2 w)
  double contact_dissipation = 0.0;  ///< per period [J]
  /// The contacts' share of D by the first-harmonic energy definition,
  /// D_c = E_contact / (2 pi w^2 a^2) (the whole D for a 1-DOF model at H = 1 without C)
  double contact_damping_ratio = 0.0;
  /// max_t |u_resp(t)| / a: the response DOFs' peak per unit modal amplitude [kg^-0.5]
  double response_per_amplitude = 0.0;
  std::vector<double> harmonic_amplitudes;  ///< |U_n| of the response DOFs / a, n = 0..H
  /// psi^H f_ext,1 with psi = q_1 / a (unit modal mass): the modal force of the case's
  /// excitation [N kg^-0.5]
  std::complex<double> modal_force;
  int newton_iterations = 0;
  int unconverged_pairs = 0;
  Eigen::VectorXd w;  ///< the contact motion W
};

struct NonlinearModeCurve {
  LinearMode linear;
  std::vector<NonlinearModePoint> points;
  bool reached_end = false;
  std::string message;  ///< why it stopped
  int rejected_steps = 0;
  int residual_evaluations = 0;
};

/// The EPMC equations at fixed amplitude: unknowns x = [W, w, zeta] (size n + 2).
class NonlinearModeEquations {
 public:
  /// Not owned. force's pairs are the linear part's contact pairs in order.
  NonlinearModeEquations(const frf::LinearPart& linear, hbm::NonlinearForce& force);

  int n() const { return force_.n_unknowns(); }
  int size() const { return n() + 2; }
  /// Index in W of the sine coefficient the phase condition sets to zero.
  void set_phase_index(int index) { phase_index_ = index; }
  int phase_index() const { return phase_index_; }
  /// r (size n + 2) at amplitude a; J = dr/dx when asked (analytic). false when the linear
  /// part has no damped form or the result is not finite.
  bool evaluate(const Eigen::VectorXd& x, double amplitude, Eigen::VectorXd& r, Eigen::MatrixXd* J);
  /// Everything reported about a solution.
  NonlinearModePoint analyse(const Eigen::VectorXd& x, double amplitude);
  /// Index of coefficient (pair, direction, harmonic, sine?) in W.
  int index(int pair, int direction, int harmonic, bool sine) const;
  /// Complex harmonic n of W-layout vector v as a c-vector (3 per pair).
  Eigen::VectorXcd complex_harmonic(const Eigen::VectorXd& v, int n) const;
  /// out += the W-layout vector whose harmonic n is z.
  void add_harmonic(const Eigen::VectorXcd& z, int n, Eigen::VectorXd& out) const;
  int evaluations() const { return evaluations_; }

 private:
  void receptances(double omega, double zeta);

  const frf::LinearPart& linear_;
  hbm::NonlinearForce& force_;
  int phase_index_ = 1;
  int evaluations_ = 0;
  double cached_omega_ = -1.0, cached_zeta_ = 0.0;
  std::vector<frf::DampedReceptance> rec_;
};

/// The linear mode `mode` (1-based) of the model linearized about `state` (W; empty: W = 0;
/// see above). Throws InputError when the linear part has no second-order form or the mode
/// does not exist.
LinearMode linear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force, int mode,
                       const Eigen::VectorXd& state = Eigen::VectorXd());

/// The contacts' static state without vibration: W with only harmonic 0, solving
/// W_0 + G_0 (F_0(W) - F_s) = 0 (docs/physics.md section 3): W = 0 when every pair carries its
/// preload in the static state, else the preload relaxed through the static flexibility.
/// Throws NumericalError when Newton does not converge.
Eigen::VectorXd static_contact_state(const frf::LinearPart& linear, hbm::NonlinearForce& force);

/// Traces the nonlinear mode (see above). Throws NumericalError when the first point does
/// not converge; a later failure ends the curve (reached_end false, message says why).
NonlinearModeCurve trace_nonlinear_mode(const frf::LinearPart& linear, hbm::NonlinearForce& force,
                                        const NonlinearModeSettings& settings);

}  // namespace shroudsim::forced
