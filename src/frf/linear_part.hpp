#pragma once
// The linear structure as the harmonic balance sees it (docs/physics.md sections 2 and 3).
//
// For temporal harmonic n at circular frequency W = n w [rad/s], with the relative
// displacement operator B_n of the contact pairs (c = 3 * pairs rows: x, y, z of each pair
// in its local frame), the excitation f_ext,n and the response DOFs D:
//   G_n       = B_n R(W) B_n^H          (c x c)   [m/N]
//   w_lin,n   = B_n R(W) f_ext,n        (c)       [m]
//   H_n       = D R(W) B_n^H            (d x c)   [m/N]
//   u_lin,n   = D R(W) f_ext,n          (d)       [m]
// so that with contact forces F_n:  W_n = w_lin,n - G_n F_n  and  U_n = u_lin,n - H_n F_n.
// n = 0 is the static part (W = 0, real). Complex amplitudes follow u = Re(U e^{i n w t}).
//
// The energy the linear part dissipates per fundamental period for given complex forces on
// the contact pairs is needed for the energy balance; each model supplies it.
#include <Eigen/Core>
#include <string>
#include <vector>

namespace shroudsim::frf {

/// The linear part of temporal harmonic n as a second-order system in the Laplace variable s,
/// for the Floquet analysis of periodic solutions (forced/stability.hpp):
///   G_n(s) = P (s^2 M + s C + K)^-1 P^H + R,   G_n(n w) = G_n(s = i n w),
/// with M, C, K real (m x m, M invertible), P complex (c x m) and R (c x c) a massless part
/// (residual or static flexibility) taken as quasi-static. Harmonic -n is the complex
/// conjugate structure (conj(P), conj(R)) of a real system.
struct SecondOrderForm {
  Eigen::MatrixXd M, C, K;
  Eigen::MatrixXcd P, R;
};

/// The receptances of the autonomous system of the extended periodic motion concept
/// (forced/nonlinear_modes.hpp, docs/physics.md section 10): the mass-proportional damping
/// -zeta M added to the linear part, so that for harmonic n at W = n w
///   R_n(w, zeta) = (K - W^2 M + i W (C - zeta M))^-1      (lumped, exact)
/// or, in modal form, each mode's denominator w_j^2 - W^2 + i W (2 xi_j w_j - zeta) (the
/// massless residual flexibility is unchanged). With X_n = R_n B_n^H:
///   G_n = B_n X_n (c x c),  H_n = D X_n (d x c, the response DOFs),
/// and for the amplitude normalisation (n = 1 only, when asked) the modal mass of the
/// motion q_1 = -X_1 F_1 the contact forces cause: q_1^H M q_1 = F_1^H N F_1 with
///   N = X_1^H M X_1 (c x c, Hermitian; the massless part contributes nothing), and the
/// excitation's projection on that motion, q_1^H f_ext,1 = -F_1^H e with e = X_1^H f_ext,1.
/// Derivatives with respect to w [rad/s] and zeta [1/s] are exact.
struct DampedReceptance {
  Eigen::MatrixXcd G, dG_dw, dG_dzeta;  ///< c x c [m/N], [m/N/(rad/s)], [m/N s]
  Eigen::MatrixXcd H;                   ///< d x c [m/N]
  Eigen::MatrixXcd N, dN_dw, dN_dzeta;  ///< c x c [kg m^2/N^2 ...], n = 1 with the norm only
  Eigen::VectorXcd e;                   ///< c [m], n = 1 with the norm only
};

struct HarmonicReceptance {
  Eigen::MatrixXcd G;      ///< c x c
  Eigen::VectorXcd w_lin;  ///< c
  Eigen::MatrixXcd H;      ///< d x c
  Eigen::VectorXcd u_lin;  ///< d
};

/// G_n of harmonic n at one frequency in factored form, for products with vectors without
/// forming the c x c matrix:
///   G_n = F + Psi diag(s) Psi^H,   F and Psi independent of the frequency,
/// F (c x c, massless: residual or static flexibility, Hermitian: stored in full, exactly
/// Hermitian, and only its lower triangle is read) the top-left c x c block of *flex
/// (nullptr: no such part), Psi the top c rows of *psi (c x modes; nullptr: no modes), both
/// owned by the linear part and valid for its life; s the modal factors at W = n w. With the
/// derivative, ds = d s / dw (w the fundamental [rad/s]): dG_n/dw = Psi diag(ds) Psi^H.
struct FactoredReceptance {
  const Eigen::MatrixXcd* flex = nullptr;
  const Eigen::MatrixXcd* psi = nullptr;
  Eigen::VectorXcd s, ds;
  Eigen::VectorXcd w_lin, dw_lin;  ///< w_lin,n (c) and d/dw of it (with the derivative)
};

class LinearPart {
 public:
  virtual ~LinearPart() = default;
  /// c: 3 * number of contact pairs.
  virtual int n_contact() const = 0;
  /// d: response DOFs (3 for a sector node, 1 for a lumped DOF).
  virtual int n_response() const = 0;
  /// The receptances of temporal harmonic n (>= 0) at fundamental circular frequency w.
  virtual void harmonic(int n, double w, HarmonicReceptance& out) const = 0;
  /// d/dw of G_n(n w) and of w_lin,n(n w), with respect to the fundamental circular
  /// frequency w [rad/s] (units m/N/(rad/s) and m/(rad/s)). The default is a central
  /// difference of harmonic() (step 1e-6 w, relative); the lumped and the modal (sector)
  /// models override it exactly.
  virtual void harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const;
  /// H_n and u_lin,n only (the response at a solution: U_n = u_lin,n - H_n F_n), without G_n.
  /// The default calls harmonic(); a model where G_n is the costly part overrides it.
  virtual void response_harmonic(int n, double w, Eigen::MatrixXcd& H, Eigen::VectorXcd& u_lin) const;
  /// G_n (and w_lin,n; with `derivative` their d/dw) in factored form (FactoredReceptance):
  /// a model whose G_n is a low-rank modal part plus a frequency-independent one answers true,
  /// and products G_n v then cost O(c modes + c^2) without the O(c^2 modes) of forming G_n.
  /// false (the default): only harmonic() is available.
  virtual bool factored_harmonic(int n, double w, bool derivative, FactoredReceptance& out) const {
    (void)n, (void)w, (void)derivative, (void)out;
    return false;
  }
  /// Work of the excitation per fundamental period [J] and viscous dissipation per period
  /// [J], given the complex contact forces F_n (n = 0..H, each of size c) at frequency w.
  virtual void energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& excitation_work,
                      double& viscous_dissipation) const = 0;
  /// The undamped natural frequencies [Hz] at which the excitation (temporal harmonic 1)
  /// drives this linear part, ascending: where its free response peaks. Used to size the
  /// continuation's displacement unit (forced/frequency_response.hpp); empty if unknown.
  virtual std::vector<double> resonances_hz() const { return {}; }
  /// The second-order form of harmonic n >= 0; false when the model has none (no Floquet
  /// analysis then).
  virtual bool second_order_form(int n, SecondOrderForm& out) const {
    (void)n;
    (void)out;
    return false;
  }
  /// The perturbation families of the Floquet analysis (forced/stability.hpp, docs/physics.md
  /// section 9): a structure whose harmonics share coordinates has one, 0. An FE sector has one
  /// per harmonic index p = 0..Nb/2 whose blocks it holds modes for (family Nb - p is the complex
  /// conjugate of family p).
  virtual std::vector<int> perturbation_families() const { return {0}; }
  /// Block k (-H..H) of family p's Hill problem at fundamental circular frequency w [rad/s].
  /// The default: second_order_form(|k|), conjugated for k < 0. A modal form may leave the
  /// modes above max_omega [rad/s] out of M, C, K and P and add their receptance at s = i k w
  /// to the massless R (so the problem is exact at lambda = 0); max_omega 0 keeps every mode.
  virtual bool perturbation_form(int family, int k, double w, double max_omega, SecondOrderForm& out) const;
  /// The receptances of harmonic n >= 0 of the EPMC's autonomous system (DampedReceptance)
  /// at fundamental circular frequency w and mass-proportional damping -zeta M; with_norm
  /// (n = 1): also N, its derivatives and e. false when the model has no such form.
  virtual bool damped_harmonic(int n, double w, double zeta, bool with_norm, DampedReceptance& out) const {
    (void)n, (void)w, (void)zeta, (void)with_norm, (void)out;
    return false;
  }
  /// Human-readable description (for run.json).
  virtual std::string describe() const = 0;
};

}  // namespace shroudsim::frf
