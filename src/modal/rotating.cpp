#include "modal/rotating.hpp"

#include "core/error.hpp"
#include "core/log.hpp"
#include "fe/assembly.hpp"
#include "linalg/cholmod_factor.hpp"

namespace shroudsim::modal {

using linalg::SparseMatrixC;
using linalg::SparseMatrixD;

linalg::SparseMatrixD RotatingOperators::rotating_stiffness() const {
  SparseMatrixD d = geometric - spin;
  d.makeCompressed();
  return d;
}

namespace {

// K_sigma1 and M_spin from the static solution u1 (shared by both variants).
void finish_operators(const mesh::Mesh& mesh, const fe::Material& material, const linalg::SparsePair<double>& km,
                      RotatingOperators& ops) {
  ops.geometric = fe::geometric_stiffness(mesh, material, ops.displacement, km.K);
  ops.spin = fe::spin_softening(km.M);
  ops.peak = fe::peak_von_mises(mesh, material, ops.displacement);
}

}  // namespace

RotatingOperators rotating_operators(const mesh::Mesh& mesh, const fe::Material& material,
                                     const linalg::SparsePair<double>& km, const std::vector<int>& fixed_dofs) {
  SHROUDSIM_CHECK(km.K.rows() == mesh.n_dofs(), "rotating_operators: K does not match the mesh");
  log::Stopwatch clock;
  RotatingOperators ops;
  ops.load = fe::centrifugal_load(mesh, km.M);
  const std::vector<int> free = fe::free_dofs(mesh.n_dofs(), fixed_dofs);
  const SparseMatrixD Kf = fe::restrict(km.K, free);
  linalg::CholmodFactor<double> factor(linalg::FactorMethod::Supernodal);
  if (factor.compute(Kf) != linalg::FactorStatus::Success)
    throw NumericalError("centrifugal static solve: factorization of K failed (" + linalg::to_string(factor.status()) +
                         "); is the structure clamped?");
  Eigen::VectorXd f(static_cast<Eigen::Index>(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k) f(static_cast<Eigen::Index>(k)) = ops.load(free[k]);
  const Eigen::VectorXd u = factor.solve(f);
  ops.displacement = Eigen::VectorXd::Zero(mesh.n_dofs());
  for (std::size_t k = 0; k < free.size(); ++k) ops.displacement(free[k]) = u(static_cast<Eigen::Index>(k));
  finish_operators(mesh, material, km, ops);
  ops.seconds = clock.seconds();
  return ops;
}

RotatingOperators rotating_operators(const mesh::Mesh& mesh, const fe::Material& material,
                                     const linalg::SparsePair<double>& km, const cyclic::CyclicSector& sector) {
  SHROUDSIM_CHECK(km.K.rows() == mesh.n_dofs() && sector.n_full() == mesh.n_dofs(),
                  "rotating_operators: K or the cyclic sector does not match the mesh");
  log::Stopwatch clock;
  RotatingOperators ops;
  ops.load = fe::centrifugal_load(mesh, km.M);
  // h = 0: T_0 is real; K_0 u_r = T_0^T f1.
  const SparseMatrixD T0 = sector.expansion(0).real();
  const SparseMatrixD K0 = sector.reduce_real(0).K;
  linalg::CholmodFactor<double> factor(linalg::FactorMethod::Supernodal);
  if (factor.compute(K0) != linalg::FactorStatus::Success)
    throw NumericalError("centrifugal static solve (h = 0): factorization of K_0 failed (" +
                         linalg::to_string(factor.status()) + ")");
  const Eigen::VectorXd fr = T0.transpose() * ops.load;
  const Eigen::VectorXd ur = factor.solve(fr);
  ops.displacement = T0 * ur;
  finish_operators(mesh, material, km, ops);
  ops.seconds = clock.seconds();
  return ops;
}

RotatingHarmonic::RotatingHarmonic(const cyclic::CyclicSector& sector, const cyclic::CyclicSector& rotating, int h)
    : h_(h), real_(sector.is_real(h)) {
  SHROUDSIM_CHECK(sector.n_reduced() == rotating.n_reduced(), "RotatingHarmonic: sectors of different meshes");
  if (real_) {
    real_pair_ = sector.reduce_real(h);
    real_k0_ = real_pair_.K;
    const linalg::SparsePair<double> r = rotating.reduce_real(h);
    real_d_ = r.K - r.M;
    real_d_.makeCompressed();
  } else {
    complex_pair_ = sector.reduce(h);
    complex_k0_ = complex_pair_.K;
    const linalg::SparsePair<Complex> r = rotating.reduce(h);
    complex_d_ = r.K - r.M;
    complex_d_.makeCompressed();
  }
}

ModalResult RotatingHarmonic::solve(double omega, const ModalOptions& options) {
  const double w2 = omega * omega;
  // The sum keeps every stored entry of both terms (explicit zeros included), so the pattern
  // of K_h(omega) is the same at every speed and the symbolic analysis is reused.
  if (real_) {
    real_pair_.K = real_k0_ + w2 * real_d_;
    real_pair_.K.makeCompressed();
    return solve_modes(real_pair_, h_, options, reuse_);
  }
  complex_pair_.K = complex_k0_ + Complex(w2) * complex_d_;
  complex_pair_.K.makeCompressed();
  return solve_modes(complex_pair_, h_, options, reuse_);
}

void RotatingHarmonic::set_variable_springs(const cyclic::CyclicSector& sector,
                                            const std::vector<cyclic::InterfaceSpring>& springs) {
  y_ = sector.interface_rows(h_, springs) * sector.expansion(h_);
  spring_k_.resize(y_.rows());
  for (std::size_t i = 0; i < springs.size(); ++i)
    spring_k_.segment<3>(static_cast<Eigen::Index>(3 * i)) = springs[i].stiffness;
}

ModalResult RotatingHarmonic::solve(double omega, const ModalOptions& options, const std::vector<bool>& closed) {
  SHROUDSIM_CHECK(static_cast<Eigen::Index>(3 * closed.size()) == y_.rows(),
                  "RotatingHarmonic::solve: one closed flag per variable spring");
  Eigen::VectorXcd k(y_.rows());
  for (Eigen::Index r = 0; r < y_.rows(); ++r) k[r] = closed[static_cast<std::size_t>(r / 3)] ? spring_k_[r] : 0.0;
  // diag(k) Y keeps Y's pattern (explicit zeros for open springs): a fixed pattern.
  SparseMatrixC kY = y_;
  for (Eigen::Index col = 0; col < kY.outerSize(); ++col)
    for (SparseMatrixC::InnerIterator it(kY, col); it; ++it) it.valueRef() *= k[it.row()];
  SparseMatrixC S = SparseMatrixC(y_.adjoint()) * kY;
  const SparseMatrixC SH = S.adjoint();
  S = 0.5 * (S + SH);
  const double w2 = omega * omega;
  if (real_) {
    real_pair_.K = real_k0_ + w2 * real_d_ + SparseMatrixD(S.real());
    real_pair_.K.makeCompressed();
    return solve_modes(real_pair_, h_, options, reuse_);
  }
  complex_pair_.K = complex_k0_ + Complex(w2) * complex_d_ + S;
  complex_pair_.K.makeCompressed();
  return solve_modes(complex_pair_, h_, options, reuse_);
}

}  // namespace shroudsim::modal
