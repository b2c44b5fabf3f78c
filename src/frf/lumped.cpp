#include "frf/lumped.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace shroudsim::frf {

LumpedLinearPart::LumpedLinearPart(Eigen::MatrixXd mass, Eigen::MatrixXd stiffness, Eigen::MatrixXd damping,
                                   std::vector<LumpedContact> contacts, int excited_dof, double force, int response_dof)
    : m_(std::move(mass)),
      k_(std::move(stiffness)),
      c_(std::move(damping)),
      contacts_(std::move(contacts)),
      excited_dof_(excited_dof),
      response_dof_(response_dof),
      force_(force) {
  const Eigen::Index n = m_.rows();
  if (n == 0 || m_.cols() != n || k_.rows() != n || k_.cols() != n)
    throw std::invalid_argument("lumped model: mass and stiffness must be square and of one size");
  if (c_.size() == 0) c_ = Eigen::MatrixXd::Zero(n, n);
  if (c_.rows() != n || c_.cols() != n) throw std::invalid_argument("lumped model: damping must match the mass size");
  if (excited_dof < 0 || excited_dof >= n || response_dof < 0 || response_dof >= n)
    throw std::invalid_argument("lumped model: excitation or response DOF out of range");
  b_ = Eigen::MatrixXd::Zero(n_contact(), n);
  for (std::size_t e = 0; e < contacts_.size(); ++e)
    for (int d = 0; d < 3; ++d) {
      const int a = contacts_[e].dof[d], o = contacts_[e].other[d];
      if (a >= n || o >= n) throw std::invalid_argument("lumped model: contact DOF out of range");
      if (a < 0) continue;
      b_(3 * static_cast<Eigen::Index>(e) + d, a) += 1.0;
      if (o >= 0) b_(3 * static_cast<Eigen::Index>(e) + d, o) -= 1.0;
    }
  // Local tangential axes turned by the frame angle: t1 = cos x + sin y, t2 = -sin x + cos y.
  for (std::size_t e = 0; e < contacts_.size(); ++e) {
    const double c = std::cos(contacts_[e].frame_angle), s = std::sin(contacts_[e].frame_angle);
    const Eigen::Index r = 3 * static_cast<Eigen::Index>(e);
    const Eigen::RowVectorXd x = b_.row(r), y = b_.row(r + 1);
    b_.row(r) = c * x + s * y;
    b_.row(r + 1) = -s * x + c * y;
  }
}

Eigen::MatrixXcd LumpedLinearPart::dynamic_matrix(double big_w) const {
  return k_.cast<std::complex<double>>() - big_w * big_w * m_.cast<std::complex<double>>() +
         std::complex<double>(0.0, big_w) * c_.cast<std::complex<double>>();
}

void LumpedLinearPart::harmonic(int n, double w, HarmonicReceptance& out) const {
  const double big_w = n * w;
  const Eigen::MatrixXcd dyn = dynamic_matrix(big_w);
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(dyn);
  // R B^H: one solve per contact direction; R f: one solve.
  const Eigen::MatrixXcd rbh = lu.solve(b_.transpose().cast<std::complex<double>>());
  Eigen::VectorXcd f = Eigen::VectorXcd::Zero(m_.rows());
  if (n == 1) f[excited_dof_] = force_;
  const Eigen::VectorXcd rf = lu.solve(f);
  out.G = b_.cast<std::complex<double>>() * rbh;
  out.w_lin = b_.cast<std::complex<double>>() * rf;
  out.H = rbh.row(response_dof_);
  out.u_lin = rf.segment(response_dof_, 1);
}

void LumpedLinearPart::harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const {
  using Complex = std::complex<double>;
  const double big_w = n * w;
  const Eigen::MatrixXcd dyn = dynamic_matrix(big_w);
  // X = D^-1 [B^T f],  dX/dw = -D^-1 (dD/dw) X,  dD/dw = -2 n^2 w M + i n C.
  const Eigen::MatrixXcd d_dw = -2.0 * n * big_w * m_.cast<Complex>() + Complex(0.0, n) * c_.cast<Complex>();
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(dyn);
  Eigen::MatrixXcd rhs(m_.rows(), b_.rows() + 1);
  rhs.leftCols(b_.rows()) = b_.transpose().cast<Complex>();
  rhs.col(b_.rows()).setZero();
  if (n == 1) rhs(excited_dof_, b_.rows()) = force_;
  const Eigen::MatrixXcd x = lu.solve(rhs);
  const Eigen::MatrixXcd dx = -lu.solve(d_dw * x);
  const Eigen::MatrixXcd bdx = b_.cast<Complex>() * dx;
  dG = bdx.leftCols(b_.rows());
  dw_lin = bdx.col(b_.rows());
}

bool LumpedLinearPart::damped_harmonic(int n, double w, double zeta, bool with_norm, DampedReceptance& out) const {
  using Complex = std::complex<double>;
  const double big_w = n * w;
  const Eigen::MatrixXcd mc = m_.cast<Complex>(), cz = (c_ - zeta * m_).cast<Complex>();
  const Eigen::MatrixXcd dyn = k_.cast<Complex>() - big_w * big_w * mc + Complex(0.0, big_w) * cz;
  // dD/dw = -2 n^2 w M + i n (C - zeta M),  dD/dzeta = -i n w M,  dX = -R dD X.
  const Eigen::MatrixXcd d_dw = -2.0 * n * big_w * mc + Complex(0.0, n) * cz;
  const Eigen::MatrixXcd d_dzeta = Complex(0.0, -big_w) * mc;
  const Eigen::PartialPivLU<Eigen::MatrixXcd> lu(dyn);
  const Eigen::MatrixXcd bc = b_.cast<Complex>();
  const Eigen::MatrixXcd x = lu.solve(bc.transpose());
  const Eigen::MatrixXcd dx_dw = -lu.solve(d_dw * x), dx_dzeta = -lu.solve(d_dzeta * x);
  out.G = bc * x;
  out.dG_dw = bc * dx_dw;
  out.dG_dzeta = bc * dx_dzeta;
  out.H = x.row(response_dof_);
  if (with_norm && n == 1) {
    const Eigen::MatrixXcd mx = mc * x;
    out.N = x.adjoint() * mx;
    out.dN_dw = dx_dw.adjoint() * mx;
    out.dN_dw += out.dN_dw.adjoint().eval();
    out.dN_dzeta = dx_dzeta.adjoint() * mx;
    out.dN_dzeta += out.dN_dzeta.adjoint().eval();
    out.e = x.adjoint() * force_vector().cast<Complex>();
  }
  return lu.rcond() > 0 && out.G.allFinite();
}

bool LumpedLinearPart::second_order_form(int /*n*/, SecondOrderForm& out) const {
  out.M = m_;
  out.C = c_;
  out.K = k_;
  out.P = b_.cast<std::complex<double>>();
  out.R = Eigen::MatrixXcd::Zero(b_.rows(), b_.rows());
  return true;
}

Eigen::VectorXcd LumpedLinearPart::displacement(int n, double w, const Eigen::VectorXcd& contact_force) const {
  const double big_w = n * w;
  const Eigen::MatrixXcd dyn = dynamic_matrix(big_w);
  Eigen::VectorXcd f = -b_.transpose().cast<std::complex<double>>() * contact_force;
  if (n == 1) f[excited_dof_] += force_;
  return Eigen::PartialPivLU<Eigen::MatrixXcd>(dyn).solve(f);
}

void LumpedLinearPart::energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& excitation_work,
                              double& viscous_dissipation) const {
  constexpr double kPi = std::numbers::pi;
  excitation_work = 0.0;
  viscous_dissipation = 0.0;
  for (std::size_t n = 1; n < forces.size(); ++n) {
    const Eigen::VectorXcd u = displacement(static_cast<int>(n), w, forces[n]);
    // Per fundamental period: harmonic n makes n cycles; int u'^T C u' dt = pi n^2 w U^H C U.
    viscous_dissipation += kPi * n * n * w * (u.adjoint() * c_.cast<std::complex<double>>() * u)(0, 0).real();
    // Work of f = Re(F e^{i w t}) on u: pi Im(F conj(U)).
    if (n == 1) excitation_work += kPi * (force_ * std::conj(u[excited_dof_])).imag();
  }
}

std::vector<double> LumpedLinearPart::resonances_hz() const {
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k_, m_, Eigen::EigenvaluesOnly);
  std::vector<double> f;
  if (eig.info() != Eigen::Success) return f;
  for (Eigen::Index i = 0; i < eig.eigenvalues().size(); ++i)
    if (eig.eigenvalues()[i] > 0) f.push_back(std::sqrt(eig.eigenvalues()[i]) / (2.0 * std::numbers::pi));
  std::sort(f.begin(), f.end());
  return f;
}

std::string LumpedLinearPart::describe() const {
  std::ostringstream s;
  s << "lumped model, " << m_.rows() << " DOFs, " << contacts_.size() << " contact elements";
  return s.str();
}

}  // namespace shroudsim::frf
