#include "linalg/cholmod_factor.hpp"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace shroudsim::linalg {

std::string to_string(FactorStatus status) {
  switch (status) {
    case FactorStatus::Success: return "success";
    case FactorStatus::NotPositiveDefinite: return "not positive definite";
    case FactorStatus::Failed: return "CHOLMOD failure";
  }
  return "unknown";
}

namespace {
// Eigen's wrapper plus access to the CHOLMOD factor for the half solves.
template <typename Scalar>
struct Decomposition : Eigen::CholmodDecomposition<SparseMatrix<Scalar>, Eigen::Lower> {
  cholmod_factor* factor() const { return this->m_cholmodFactor; }
  // analyzePattern() without the analysis: a copy of another's symbolic factor (CHOLMOD's
  // pattern-only cholmod_factor carries no scalar type), in this object's workspace.
  void adopt_symbolic(const cholmod_factor* symbolic) {
    if (this->m_cholmodFactor) cholmod_free_factor(&this->m_cholmodFactor, &this->cholmod());
    this->m_cholmodFactor = cholmod_copy_factor(const_cast<cholmod_factor*>(symbolic), &this->cholmod());
    const bool ok = this->m_cholmodFactor != nullptr;
    this->m_isInitialized = ok;
    this->m_info = ok ? Eigen::Success : Eigen::InvalidInput;
    this->m_analysisIsOk = ok;
    this->m_factorizationIsOk = false;
  }
};
}  // namespace

template <typename Scalar>
struct CholmodFactor<Scalar>::Impl {
  Decomposition<Scalar> llt;
  // x = sys2(sys1(b)) with CHOLMOD's partial solves (int API, as Eigen uses for int indices).
  // b and x hold ncol columns of length n, stored contiguously (leading dimension n).
  void two_step(int sys1, int sys2, const Scalar* b, Scalar* x, Eigen::Index n, Eigen::Index ncol = 1) {
    cholmod_common& c = llt.cholmod();
    cholmod_dense B;
    B.nrow = B.d = static_cast<std::size_t>(n);
    B.ncol = static_cast<std::size_t>(ncol);
    B.nzmax = B.nrow * B.ncol;
    B.x = const_cast<Scalar*>(b);
    B.z = nullptr;
    B.xtype = std::is_same_v<Scalar, double> ? CHOLMOD_REAL : CHOLMOD_COMPLEX;
    B.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* t = cholmod_solve(sys1, llt.factor(), &B, &c);
    cholmod_dense* u = t ? cholmod_solve(sys2, llt.factor(), t, &c) : nullptr;
    if (!u) {
      if (t) cholmod_free_dense(&t, &c);
      throw std::runtime_error("CHOLMOD partial solve failed");
    }
    std::copy_n(static_cast<const Scalar*>(u->x), n * ncol, x);
    cholmod_free_dense(&t, &c);
    cholmod_free_dense(&u, &c);
  }
};

namespace {
// CHOLMOD's nested-dissection ordering (METIS, tried when AMD's fill is poor: the larger
// sectors) draws from a random generator that is global to the process and reseeded at each
// call. Two analyses at once on different threads (the parallel stages) interleave their
// draws, so the ordering, and the factor's round-off, depended on the timing: the 77k-DOF
// sector gave a linear amplitude that differed by 2e-9 between two identical runs on two
// threads. One analysis at a time.
std::mutex& analysis_lock() {
  static std::mutex lock;
  return lock;
}
}  // namespace

template <typename Scalar>
CholmodFactor<Scalar>::CholmodFactor(FactorMethod method) : impl_(std::make_unique<Impl>()) {
  impl_->llt.setMode(method == FactorMethod::Supernodal ? Eigen::CholmodSupernodalLLt : Eigen::CholmodSimplicialLLt);
  cholmod_common& c = impl_->llt.cholmod();
  c.print = 0;  // failures are reported through status(), not stderr
  c.quick_return_if_not_posdef = 1;
}

template <typename Scalar>
CholmodFactor<Scalar>::~CholmodFactor() = default;
template <typename Scalar>
CholmodFactor<Scalar>::CholmodFactor(CholmodFactor&&) noexcept = default;
template <typename Scalar>
CholmodFactor<Scalar>& CholmodFactor<Scalar>::operator=(CholmodFactor&&) noexcept = default;

template <typename Scalar>
void CholmodFactor<Scalar>::analyze(const SparseMatrix<Scalar>& A) {
  SHROUDSIM_CHECK(A.rows() == A.cols(), "CholmodFactor: matrix must be square");
  SHROUDSIM_CHECK(A.isCompressed(), "CholmodFactor: matrix must be compressed");
  rows_ = A.rows();
  const std::lock_guard<std::mutex> one_at_a_time(analysis_lock());
  impl_->llt.analyzePattern(A);
  status_ = impl_->llt.info() == Eigen::Success ? FactorStatus::Success : FactorStatus::Failed;
}

template <typename Scalar>
FactorStatus CholmodFactor<Scalar>::factorize(const SparseMatrix<Scalar>& A) {
  SHROUDSIM_CHECK(A.rows() == rows_ && A.cols() == rows_, "CholmodFactor: size changed after analyze");
  impl_->llt.factorize(A);
  switch (impl_->llt.info()) {
    case Eigen::Success: status_ = FactorStatus::Success; break;
    case Eigen::NumericalIssue: status_ = FactorStatus::NotPositiveDefinite; break;
    default: status_ = FactorStatus::Failed; break;
  }
  // CHOLMOD reports "not positive definite" through Common.status as well.
  if (status_ == FactorStatus::Success && impl_->llt.cholmod().status == CHOLMOD_NOT_POSDEF)
    status_ = FactorStatus::NotPositiveDefinite;
  return status_;
}

template <typename Scalar>
FactorStatus CholmodFactor<Scalar>::compute(const SparseMatrix<Scalar>& A) {
  analyze(A);
  if (status_ != FactorStatus::Success) return status_;
  return factorize(A);
}

template <typename Scalar>
bool CholmodFactor<Scalar>::symbolic_only() const {
  const cholmod_factor* f = impl_->llt.factor();
  return f && f->xtype == CHOLMOD_PATTERN;
}

template <typename Scalar>
template <typename Other>
void CholmodFactor<Scalar>::analyze_like(const CholmodFactor<Other>& analysed) {
  SHROUDSIM_CHECK(analysed.symbolic_only(), "CholmodFactor::analyze_like: the source must be analysed, not factorized");
  impl_->llt.adopt_symbolic(analysed.impl_->llt.factor());
  // The analysis statistics (factor_nonzeros() reads them) come with the analysis.
  impl_->llt.cholmod().lnz = analysed.impl_->llt.cholmod().lnz;
  impl_->llt.cholmod().fl = analysed.impl_->llt.cholmod().fl;
  rows_ = analysed.rows_;
  status_ = impl_->llt.info() == Eigen::Success ? FactorStatus::Success : FactorStatus::Failed;
}

template <typename Scalar>
typename CholmodFactor<Scalar>::Matrix CholmodFactor<Scalar>::solve(const Matrix& b) const {
  SHROUDSIM_CHECK(status_ == FactorStatus::Success, "CholmodFactor::solve without a valid factor");
  SHROUDSIM_CHECK(b.rows() == rows_, "CholmodFactor::solve: right-hand side has the wrong size");
  return impl_->llt.solve(b);
}

template <typename Scalar>
void CholmodFactor<Scalar>::solve(const Scalar* b, Scalar* x) const {
  SHROUDSIM_CHECK(status_ == FactorStatus::Success, "CholmodFactor::solve without a valid factor");
  Eigen::Map<const Vector> bm(b, rows_);
  Eigen::Map<Vector> xm(x, rows_);
  xm = impl_->llt.solve(Vector(bm));
}

template <typename Scalar>
void CholmodFactor<Scalar>::half_solve(int first, int second, const Scalar* b, Scalar* x, Eigen::Index ncol,
                                       const char* name) const {
  SHROUDSIM_CHECK(status_ == FactorStatus::Success, std::string("CholmodFactor::") + name + " without a valid factor");
  SHROUDSIM_CHECK(impl_->llt.factor()->is_ll, "CholmodFactor: half solves need an LL^H factor");
  if (ncol > 0) impl_->two_step(first, second, b, x, rows_, ncol);
}

template <typename Scalar>
void CholmodFactor<Scalar>::solve_forward(const Scalar* b, Scalar* x) const {
  half_solve(CHOLMOD_P, CHOLMOD_L, b, x, 1, "solve_forward");
}

template <typename Scalar>
void CholmodFactor<Scalar>::solve_backward(const Scalar* b, Scalar* x) const {
  half_solve(CHOLMOD_Lt, CHOLMOD_Pt, b, x, 1, "solve_backward");
}

template <typename Scalar>
typename CholmodFactor<Scalar>::Matrix CholmodFactor<Scalar>::solve_forward(const Matrix& b) const {
  SHROUDSIM_CHECK(b.rows() == rows_, "CholmodFactor::solve_forward: right-hand side has the wrong size");
  Matrix x(rows_, b.cols());
  half_solve(CHOLMOD_P, CHOLMOD_L, b.data(), x.data(), b.cols(), "solve_forward");
  return x;
}

template <typename Scalar>
typename CholmodFactor<Scalar>::Matrix CholmodFactor<Scalar>::solve_backward(const Matrix& b) const {
  SHROUDSIM_CHECK(b.rows() == rows_, "CholmodFactor::solve_backward: right-hand side has the wrong size");
  Matrix x(rows_, b.cols());
  half_solve(CHOLMOD_Lt, CHOLMOD_Pt, b.data(), x.data(), b.cols(), "solve_backward");
  return x;
}

template <typename Scalar>
double CholmodFactor<Scalar>::factor_nonzeros() const {
  return impl_->llt.cholmod().lnz;
}

template class CholmodFactor<double>;
template class CholmodFactor<Complex>;
template void CholmodFactor<double>::analyze_like(const CholmodFactor<double>&);
template void CholmodFactor<double>::analyze_like(const CholmodFactor<Complex>&);
template void CholmodFactor<Complex>::analyze_like(const CholmodFactor<double>&);
template void CholmodFactor<Complex>::analyze_like(const CholmodFactor<Complex>&);

}  // namespace shroudsim::linalg
