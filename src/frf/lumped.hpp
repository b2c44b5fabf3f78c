#pragma once
// A lumped structure: M u'' + C u' + K u = f, with contact elements joining one DOF per
// direction to ground or to other DOFs. The receptance is the exact inverse
// (K - W^2 M + i W C)^-1 (no modes). Excitation: a harmonic force of amplitude `force` on
// DOF `excited_dof` in temporal harmonic 1 (f = force cos(w t)).
#include <Eigen/Core>
#include <array>

#include "frf/linear_part.hpp"

namespace shroudsim::frf {

/// A contact element of a lumped model: DOF per direction (x, y, z; -1 absent) and the
/// DOF it acts against (-1: ground). w_d = u[dof_d] - u[other_d].
struct LumpedContact {
  std::array<int, 3> dof{-1, -1, -1};
  std::array<int, 3> other{-1, -1, -1};
  double frame_angle = 0.0;  ///< turns the tangential axes (x, y) about z [rad]
};

class LumpedLinearPart : public LinearPart {
 public:
  /// Throws std::invalid_argument on inconsistent sizes, non-symmetric matrices or DOFs out
  /// of range.
  LumpedLinearPart(Eigen::MatrixXd mass, Eigen::MatrixXd stiffness, Eigen::MatrixXd damping,
                   std::vector<LumpedContact> contacts, int excited_dof, double force, int response_dof);

  int n_contact() const override { return 3 * static_cast<int>(contacts_.size()); }
  int n_response() const override { return 1; }
  void harmonic(int n, double w, HarmonicReceptance& out) const override;
  /// Exact: dX/dw = -D^-1 (-2 n^2 w M + i n C) X with D = K - (n w)^2 M + i n w C.
  void harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const override;
  void energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& excitation_work,
              double& viscous_dissipation) const override;
  std::string describe() const override;
  /// M, C, K of the model, P = B (no massless part): the same for every harmonic.
  bool second_order_form(int n, SecondOrderForm& out) const override;
  /// The exact (K - W^2 M + i W (C - zeta M))^-1 projected, with its exact derivatives.
  bool damped_harmonic(int n, double w, double zeta, bool with_norm, DampedReceptance& out) const override;
  /// sqrt(eig(K, M)) / 2 pi.
  std::vector<double> resonances_hz() const override;

  /// B (c x ndof): relative displacement operator of the contacts.
  const Eigen::MatrixXd& contact_operator() const { return b_; }
  const Eigen::MatrixXd& mass() const { return m_; }
  const Eigen::MatrixXd& stiffness() const { return k_; }
  const Eigen::MatrixXd& damping() const { return c_; }
  /// Complex displacements of every DOF for harmonic n (circular frequency w) under contact
  /// forces F_n (the excitation included for n = 1): (K - (n w)^2 M + i n w C)^-1 (f_n - B^T F_n).
  Eigen::VectorXcd displacement(int n, double w, const Eigen::VectorXcd& contact_force) const;
  /// The excitation's force amplitude on every DOF (f(t) = force_vector() cos(w t)).
  Eigen::VectorXd force_vector() const {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(m_.rows());
    f[excited_dof_] = force_;
    return f;
  }

 private:
  /// D = K - W^2 M + i W C at circular frequency W = n w.
  Eigen::MatrixXcd dynamic_matrix(double big_w) const;

  Eigen::MatrixXd m_, k_, c_;
  std::vector<LumpedContact> contacts_;
  Eigen::MatrixXd b_;
  int excited_dof_, response_dof_;
  double force_;
};

}  // namespace shroudsim::frf
