#include "modal/stiffness_factor.hpp"

#include "core/error.hpp"

namespace shroudsim::modal {

StiffnessFactor::StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<double>> real) : real_(std::move(real)) {}
StiffnessFactor::StiffnessFactor(std::shared_ptr<const linalg::CholmodFactor<Complex>> complex, bool conjugated)
    : complex_(std::move(complex)), conjugated_(conjugated) {}

Eigen::Index StiffnessFactor::rows() const { return real_ ? real_->rows() : complex_ ? complex_->rows() : 0; }

Eigen::MatrixXcd StiffnessFactor::solve(const Eigen::MatrixXcd& b) const {
  SHROUDSIM_CHECK(valid(), "StiffnessFactor::solve without a factor");
  if (real_) {
    // A real right-hand side (the contact rows of a real harmonic index, 0 or Nb/2) needs no
    // solve of its zero imaginary part: half the work.
    if (b.imag().isZero(0.0)) {
      const Eigen::MatrixXd x = real_->solve(Eigen::MatrixXd(b.real()));
      return x.cast<Complex>();
    }
    Eigen::MatrixXd parts(b.rows(), 2 * b.cols());
    parts << b.real(), b.imag();
    const Eigen::MatrixXd x = real_->solve(parts);
    Eigen::MatrixXcd out(b.rows(), b.cols());
    out.real() = x.leftCols(b.cols());
    out.imag() = x.rightCols(b.cols());
    return out;
  }
  if (conjugated_) return complex_->solve(b.conjugate()).conjugate();
  return complex_->solve(b);
}

StiffnessFactor StiffnessFactor::conjugate() const {
  if (real_) return *this;
  return StiffnessFactor(complex_, !conjugated_);
}

template <typename Scalar>
static StiffnessFactor factor_stiffness_impl(const linalg::SparseMatrix<Scalar>& K, linalg::FactorMethod method) {
  auto f = std::make_shared<linalg::CholmodFactor<Scalar>>(method);
  const auto status = f->compute(K);
  if (status != linalg::FactorStatus::Success)
    throw NumericalError("factorization of the stiffness matrix failed: " + linalg::to_string(status));
  return make_stiffness_factor<Scalar>(f);
}

StiffnessFactor factor_stiffness(const linalg::SparseMatrixD& K, linalg::FactorMethod method) {
  return factor_stiffness_impl(K, method);
}
StiffnessFactor factor_stiffness(const linalg::SparseMatrixC& K, linalg::FactorMethod method) {
  return factor_stiffness_impl(K, method);
}

}  // namespace shroudsim::modal
