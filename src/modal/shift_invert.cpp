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

// K - sigma M, compressed (K itself, uncopied, when sigma == 0 and K is compressed).
template <typename S>
struct Shifted {
  linalg::SparseMatrix<S> owned;
  const linalg::SparseMatrix<S>* matrix = nullptr;
  Shifted(const linalg::SparsePair<S>& km, double sigma) {
    if (sigma == 0.0 && km.K.isCompressed()) {
      matrix = &km.K;
      return;
    }
    owned = sigma == 0.0 ? linalg::SparseMatrix<S>(km.K) : linalg::SparseMatrix<S>(km.K - S(sigma) * km.M);
    owned.makeCompressed();
    matrix = &owned;
  }
};

// M Y, the block at once: M's entries are read once per block instead of once per column
// (Eigen's sparse-times-dense product streams the whole matrix for every column, and at 40k
// DOFs that product was the largest part of a Lanczos step after the half solves). Each
// result entry sums its terms in the order Eigen's product does (by column of M), and a
// complex term is m y written out in real arithmetic (libgcc's NaN-checking complex multiply
// is not called). Compiled with -O3 it does not give the bits of Eigen's product (at -O0
// the two agree to the last bit): the modes change in their last digits (BENCHMARKS.md,
// "The reduction in one pass, the mass product by blocks, ...").
template <typename S>
Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> mass_product(
    const linalg::SparseMatrix<S>& M, const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>& Y) {
  using Block = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Index n = M.rows(), b = Y.cols();
  const Block Yt = Y.transpose();  // column k: row k of Y, contiguous
  Block Rt = Block::Zero(b, n);
  const int* outer = M.outerIndexPtr();
  const int* inner = M.innerIndexPtr();
  const S* value = M.valuePtr();
  for (Eigen::Index k = 0; k < M.outerSize(); ++k) {
    const S* y = Yt.col(k).data();
    const int end = M.isCompressed() ? outer[k + 1] : outer[k] + M.innerNonZeroPtr()[k];
    for (int p = outer[k]; p < end; ++p) {
      S* r = Rt.col(inner[p]).data();
      if constexpr (kIsComplex<S>) {
        const double mr = value[p].real(), mi = value[p].imag();
        for (Eigen::Index c = 0; c < b; ++c)
          r[c] += S(mr * y[c].real() - mi * y[c].imag(), mr * y[c].imag() + mi * y[c].real());
      } else {
        const double m = value[p];
        for (Eigen::Index c = 0; c < b; ++c) r[c] += m * y[c];
      }
    }
  }
  return Rt.transpose();
}

}  // namespace

template <typename S>
std::shared_ptr<const SharedAnalysis> analyse_pattern(const linalg::SparsePair<S>& km, double sigma,
                                                      linalg::FactorMethod method) {
  const Shifted<S> shifted(km, sigma);
  const linalg::SparseMatrix<S>& A = *shifted.matrix;
  auto factor = std::make_shared<linalg::CholmodFactor<double>>(method);
  if constexpr (kIsComplex<S>) {
    linalg::SparseMatrix<double> pattern(A.real());  // every stored entry kept: the same pattern
    pattern.makeCompressed();
    factor->analyze(pattern);
  } else {
    factor->analyze(A);
  }
  auto out = std::make_shared<SharedAnalysis>();
  out->rows = A.rows();
  out->nonzeros = A.nonZeros();
  if (factor->status() == linalg::FactorStatus::Success) out->symbolic = std::move(factor);
  return out;
}

template std::shared_ptr<const SharedAnalysis> analyse_pattern<double>(const linalg::SparsePair<double>&, double,
                                                                       linalg::FactorMethod);
template std::shared_ptr<const SharedAnalysis> analyse_pattern<Complex>(const linalg::SparsePair<Complex>&, double,
                                                                        linalg::FactorMethod);

template <typename S>
std::shared_ptr<linalg::CholmodFactor<S>> factor_shifted(const linalg::SparsePair<S>& km, double sigma,
                                                         linalg::FactorMethod method, FactorReuse* reuse,
                                                         const SharedAnalysis* shared) {
  std::shared_ptr<linalg::CholmodFactor<S>> factor;
  const Shifted<S> shifted(km, sigma);
  const linalg::SparseMatrix<S>& A = *shifted.matrix;
  if (reuse && reuse_slot<S>(*reuse) && reuse_slot<S>(*reuse)->rows() == A.rows() &&
      reuse_nonzeros<S>(*reuse) == A.nonZeros()) {
    factor = reuse_slot<S>(*reuse);
    factor->factorize(A);  // symbolic analysis of an earlier solve, same pattern
  } else if (!reuse && shared && shared->symbolic && shared->rows == A.rows() && shared->nonzeros == A.nonZeros()) {
    factor = std::make_shared<linalg::CholmodFactor<S>>(method);
    factor->analyze_like(*shared->symbolic);
    if (factor->status() == linalg::FactorStatus::Success) factor->factorize(A);
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
                                                                               FactorReuse*, const SharedAnalysis*);
template std::shared_ptr<linalg::CholmodFactor<Complex>> factor_shifted<Complex>(const linalg::SparsePair<Complex>&,
                                                                                 double, linalg::FactorMethod,
                                                                                 FactorReuse*, const SharedAnalysis*);

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
  const Block MY = mass_product<S>(M_, Y);
  return factor_.solve_forward(MY);
}

template class ShiftInvertOperator<double>;
template class ShiftInvertOperator<Complex>;

}  // namespace shroudsim::modal
