// The BLAS and LAPACK routines CHOLMOD's supernodal factorization and solves call
// (dgemm dsyrk dtrsm dgemv dtrsv dpotrf and their complex z counterparts, zherk for dsyrk),
// implemented with Eigen's blocked, vectorised kernels.
//
// Why: Debian's default libblas is the unoptimised reference BLAS, on which the supernodal
// factorization of a 1e5-DOF complex K_h takes minutes. These definitions are linked into
// every executable that uses shroudsim_linalg and exported (see CMakeLists.txt), so the
// dynamic linker binds CHOLMOD's (and LAPACK's) calls to them instead of libblas.
// Semantics are those of the reference BLAS/LAPACK for column-major storage with positive
// increments; 32-bit integers (Debian's libblas ABI). Thread-safe (no shared state).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <complex>

namespace {

using Eigen::Dynamic;
using Eigen::Index;
using Eigen::InnerStride;
using Eigen::OuterStride;

template <typename S>
using Mat = Eigen::Matrix<S, Dynamic, Dynamic>;
template <typename S>
using MapM = Eigen::Map<Mat<S>, 0, OuterStride<>>;
template <typename S>
using MapCM = Eigen::Map<const Mat<S>, 0, OuterStride<>>;
template <typename S>
using Vec = Eigen::Matrix<S, Dynamic, 1>;
template <typename S>
using MapV = Eigen::Map<Vec<S>, 0, InnerStride<>>;
template <typename S>
using MapCV = Eigen::Map<const Vec<S>, 0, InnerStride<>>;

char up(const char* c) { return static_cast<char>(*c & ~0x20); }  // ASCII upper case

// Calls f(op(A)) with op = identity, transpose or adjoint.
template <typename M, typename F>
void with_op(char t, const M& A, F&& f) {
  if (t == 'N') f(A);
  else if (t == 'T') f(A.transpose());
  else f(A.adjoint());
}

template <typename S>
void gemm(const char* ta, const char* tb, int m, int n, int k, S alpha, const S* a, int lda, const S* b, int ldb,
          S beta, S* c, int ldc) {
  if (m <= 0 || n <= 0) return;
  MapM<S> C(c, m, n, OuterStride<>(ldc));
  if (beta == S(0)) C.setZero();
  else if (beta != S(1)) C *= beta;
  if (k <= 0 || alpha == S(0)) return;
  const char TA = up(ta), TB = up(tb);
  const MapCM<S> A(a, TA == 'N' ? m : k, TA == 'N' ? k : m, OuterStride<>(lda));
  const MapCM<S> B(b, TB == 'N' ? k : n, TB == 'N' ? n : k, OuterStride<>(ldb));
  with_op(TA, A, [&](const auto& opA) { with_op(TB, B, [&](const auto& opB) { C.noalias() += alpha * opA * opB; }); });
}

// C = alpha op(A) op(A)^H + beta C on the `uplo` triangle (syrk for real, herk for complex).
template <typename S>
void herk(const char* uplo, const char* trans, int n, int k, double alpha, const S* a, int lda, double beta, S* c, int ldc) {
  if (n <= 0) return;
  MapM<S> C(c, n, n, OuterStride<>(ldc));
  const bool lower = up(uplo) == 'L';
  auto scale = [&](auto tri) {
    if (beta == 0.0) tri.setZero();
    else if (beta != 1.0) tri *= S(beta);
  };
  if (lower) scale(C.template triangularView<Eigen::Lower>());
  else scale(C.template triangularView<Eigen::Upper>());
  if (k <= 0 || alpha == 0.0) return;
  const bool notrans = up(trans) == 'N';
  const MapCM<S> A(a, notrans ? n : k, notrans ? k : n, OuterStride<>(lda));
  if (notrans) {
    if (lower) C.template selfadjointView<Eigen::Lower>().rankUpdate(A, alpha);
    else C.template selfadjointView<Eigen::Upper>().rankUpdate(A, alpha);
  } else {
    if (lower) C.template selfadjointView<Eigen::Lower>().rankUpdate(A.adjoint(), alpha);
    else C.template selfadjointView<Eigen::Upper>().rankUpdate(A.adjoint(), alpha);
  }
  if constexpr (!std::is_same_v<S, double>) C.diagonal() = C.diagonal().real().template cast<S>();
}

template <int Mode, typename M, typename B>
void tri_solve(bool left, const M& opA, B& X) {
  if (left) opA.template triangularView<Mode>().solveInPlace(X);
  else opA.template triangularView<Mode>().template solveInPlace<Eigen::OnTheRight>(X);
}

// Triangle of op(A): A's triangle, flipped by a transpose.
template <typename M, typename B>
void tri_dispatch(bool lower, bool unit, bool left, const M& opA, B& X) {
  if (lower) unit ? tri_solve<Eigen::UnitLower>(left, opA, X) : tri_solve<Eigen::Lower>(left, opA, X);
  else unit ? tri_solve<Eigen::UnitUpper>(left, opA, X) : tri_solve<Eigen::Upper>(left, opA, X);
}

template <typename S>
void trsm(const char* side, const char* uplo, const char* transa, const char* diag, int m, int n, S alpha, const S* a,
          int lda, S* b, int ldb) {
  if (m <= 0 || n <= 0) return;
  MapM<S> B(b, m, n, OuterStride<>(ldb));
  if (alpha == S(0)) {
    B.setZero();
    return;
  }
  if (alpha != S(1)) B *= alpha;
  const bool left = up(side) == 'L';
  const int na = left ? m : n;
  const MapCM<S> A(a, na, na, OuterStride<>(lda));
  const char T = up(transa);
  const bool lower_a = up(uplo) == 'L', unit = up(diag) == 'U';
  const bool lower_op = T == 'N' ? lower_a : !lower_a;
  with_op(T, A, [&](const auto& opA) { tri_dispatch(lower_op, unit, left, opA, B); });
}

template <typename S>
void gemv(const char* trans, int m, int n, S alpha, const S* a, int lda, const S* x, int incx, S beta, S* y, int incy) {
  if (m <= 0 || n <= 0) return;
  const char T = up(trans);
  const int lx = T == 'N' ? n : m, ly = T == 'N' ? m : n;
  const MapCM<S> A(a, m, n, OuterStride<>(lda));
  if (incx > 0 && incy > 0) {
    MapV<S> Y(y, ly, InnerStride<>(incy));
    const MapCV<S> X(x, lx, InnerStride<>(incx));
    if (beta == S(0)) Y.setZero();
    else if (beta != S(1)) Y *= beta;
    if (alpha == S(0)) return;
    with_op(T, A, [&](const auto& opA) { Y.noalias() += alpha * opA * X; });
    return;
  }
  // Non-positive increments (reference semantics: start from the far end).
  Vec<S> X(lx), Y(ly);
  for (int i = 0; i < lx; ++i) X(i) = x[incx > 0 ? i * incx : (lx - 1 - i) * -incx];
  for (int i = 0; i < ly; ++i) Y(i) = beta == S(0) ? S(0) : beta * y[incy > 0 ? i * incy : (ly - 1 - i) * -incy];
  with_op(T, A, [&](const auto& opA) { Y.noalias() += alpha * opA * X; });
  for (int i = 0; i < ly; ++i) y[incy > 0 ? i * incy : (ly - 1 - i) * -incy] = Y(i);
}

template <typename S>
void trsv(const char* uplo, const char* trans, const char* diag, int n, const S* a, int lda, S* x, int incx) {
  if (n <= 0) return;
  const MapCM<S> A(a, n, n, OuterStride<>(lda));
  const char T = up(trans);
  const bool lower_a = up(uplo) == 'L', unit = up(diag) == 'U';
  const bool lower_op = T == 'N' ? lower_a : !lower_a;
  Vec<S> X(n);
  for (int i = 0; i < n; ++i) X(i) = x[incx > 0 ? i * incx : (n - 1 - i) * -incx];
  with_op(T, A, [&](const auto& opA) { tri_dispatch(lower_op, unit, true, opA, X); });
  for (int i = 0; i < n; ++i) x[incx > 0 ? i * incx : (n - 1 - i) * -incx] = X(i);
}

template <typename S>
void potrf(const char* uplo, int n, S* a, int lda, int* info) {
  *info = 0;
  if (n <= 0) return;
  MapM<S> A(a, n, n, OuterStride<>(lda));
  const Index k = up(uplo) == 'L' ? Eigen::internal::llt_inplace<S, Eigen::Lower>::blocked(A)
                                  : Eigen::internal::llt_inplace<S, Eigen::Upper>::blocked(A);
  *info = k < 0 ? 0 : static_cast<int>(k) + 1;
}

using Z = std::complex<double>;

}  // namespace

extern "C" {

void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc) {
  gemm<double>(ta, tb, *m, *n, *k, *alpha, a, *lda, b, *ldb, *beta, c, *ldc);
}
void zgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const Z* alpha, const Z* a,
            const int* lda, const Z* b, const int* ldb, const Z* beta, Z* c, const int* ldc) {
  gemm<Z>(ta, tb, *m, *n, *k, *alpha, a, *lda, b, *ldb, *beta, c, *ldc);
}
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc) {
  herk<double>(uplo, trans, *n, *k, *alpha, a, *lda, *beta, c, *ldc);
}
void zherk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const Z* a,
            const int* lda, const double* beta, Z* c, const int* ldc) {
  herk<Z>(uplo, trans, *n, *k, *alpha, a, *lda, *beta, c, *ldc);
}
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb) {
  trsm<double>(side, uplo, transa, diag, *m, *n, *alpha, a, *lda, b, *ldb);
}
void ztrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const Z* alpha, const Z* a, const int* lda, Z* b, const int* ldb) {
  trsm<Z>(side, uplo, transa, diag, *m, *n, *alpha, a, *lda, b, *ldb);
}
void dgemv_(const char* trans, const int* m, const int* n, const double* alpha, const double* a, const int* lda,
            const double* x, const int* incx, const double* beta, double* y, const int* incy) {
  gemv<double>(trans, *m, *n, *alpha, a, *lda, x, *incx, *beta, y, *incy);
}
void zgemv_(const char* trans, const int* m, const int* n, const Z* alpha, const Z* a, const int* lda, const Z* x,
            const int* incx, const Z* beta, Z* y, const int* incy) {
  gemv<Z>(trans, *m, *n, *alpha, a, *lda, x, *incx, *beta, y, *incy);
}
void dtrsv_(const char* uplo, const char* trans, const char* diag, const int* n, const double* a, const int* lda,
            double* x, const int* incx) {
  trsv<double>(uplo, trans, diag, *n, a, *lda, x, *incx);
}
void ztrsv_(const char* uplo, const char* trans, const char* diag, const int* n, const Z* a, const int* lda, Z* x,
            const int* incx) {
  trsv<Z>(uplo, trans, diag, *n, a, *lda, x, *incx);
}
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info) { potrf<double>(uplo, *n, a, *lda, info); }
void zpotrf_(const char* uplo, const int* n, Z* a, const int* lda, int* info) { potrf<Z>(uplo, *n, a, *lda, info); }

}  // extern "C"
