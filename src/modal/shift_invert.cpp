#include "modal/shift_invert.hpp"

#include <type_traits>

namespace shroudsim::modal {

namespace {

template <typename S>
constexpr bool kIsComplex = !std::is_same_v<S, double>;

template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>>& reuse_slot(FactorReuse& reuse) {
  if constexpr (kIsComplex<S>) return reuse.complex;
  else return reuse.real;
}
template <typename S>
Eigen::Index& reuse_nonzeros(FactorReuse& reuse) {
  if constexpr (kIsComplex<S>) return reuse.complex_nonzeros;
  else return reuse.real_nonzeros;
}

}  // namespace

template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>> factor_shifted(const linalg::SparsePair<S>& km, double sigma,
                                                         linalg::FactorMethod method, FactorReuse* reuse) {
  std::shared_ptr<linalg::CholmodFactor<S>> factor;
  linalg::SparseMatrix<S> A = sigma == 0.0 ? linalg::SparseMatrix<S>(km.K)
                                           : linalg::SparseMatrix<S>(km.K - S(sigma) * km.M);
  A.makeCompressed();
  if (reuse && reuse_slot<S>(*reuse) && reuse_slot<S>(*reuse)->rows() == A.rows() &&
      reuse_nonzeros<S>(*reuse) == A.nonZeros()) {
    factor = reuse_slot<S>(*reuse);
    factor->factorize(A);  // symbolic analysis of an earlier solve, same pattern
  } else {
    factor = std::make_shared<linalg::CholmodFactor<S>>(method);
    factor->compute(A);
    if (reuse) {
      reuse_slot<S>(*reuse) = factor;
      reuse_nonzeros<S>(*reuse) = A.nonZeros();
      ++reuse->analyses;
    }
  }
  if (reuse) ++reuse->factorizations;
  return factor;
}

template std::shared_ptr<linalg::CholmodFactor<double>> factor_shifted<double>(const linalg::SparsePair<double>&,
                                                                               double, linalg::FactorMethod,
                                                                               FactorReuse*);
template std::shared_ptr<linalg::CholmodFactor<Complex>> factor_shifted<Complex>(const linalg::SparsePair<Complex>&,
                                                                                 double, linalg::FactorMethod,
                                                                                 FactorReuse*);

template <typename S>
ShiftInvertOperator<S>::ShiftInvertOperator(const linalg::CholmodFactor<S>& factor, const linalg::SparseMatrix<S>& M)
    : factor_(factor), M_(M), n_(M.rows()), a_(n_), b_(n_) {}

template <typename S>
Eigen::Index ShiftInvertOperator<S>::rows() const {
  return kIsComplex<S> ? 2 * n_ : n_;
}

template <typename S>
void ShiftInvertOperator<S>::perform_op(const double* x, double* y) const {
  ++products_;
  if constexpr (kIsComplex<S>) {
    for (Eigen::Index i = 0; i < n_; ++i) a_[i] = S(x[i], x[n_ + i]);
    factor_.solve_backward(a_.data(), b_.data());
    a_.noalias() = M_ * b_;
    factor_.solve_forward(a_.data(), b_.data());
    for (Eigen::Index i = 0; i < n_; ++i) {
      y[i] = b_[i].real();
      y[n_ + i] = b_[i].imag();
    }
  } else {
    factor_.solve_backward(x, b_.data());
    a_.noalias() = M_ * b_;
    factor_.solve_forward(a_.data(), y);
  }
}

template <typename S>
typename ShiftInvertOperator<S>::Block ShiftInvertOperator<S>::apply(const Block& X) const {
  products_ += X.cols();
  const Block Y = factor_.solve_backward(X);
  const Block MY = M_ * Y;
  return factor_.solve_forward(MY);
}

template class ShiftInvertOperator<double>;
template class ShiftInvertOperator<Complex>;

}  // namespace shroudsim::modal
