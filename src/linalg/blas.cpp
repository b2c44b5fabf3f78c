#include "linalg/blas.hpp"

#include <dlfcn.h>

#include <mutex>

#include "core/error.hpp"

extern "C" {
void dgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc);
void zgemm_(const char* ta, const char* tb, const int* m, const int* n, const int* k, const void* alpha, const void* a,
            const int* lda, const void* b, const int* ldb, const void* beta, void* c, const int* ldc);
}

namespace shroudsim::linalg {

template <typename Scalar>
void gemm(Op op_a, Scalar alpha, const Eigen::Ref<const DenseMatrix<Scalar>, 0, Eigen::OuterStride<>>& A,
          const Eigen::Ref<const DenseMatrix<Scalar>, 0, Eigen::OuterStride<>>& B, Scalar beta,
          Eigen::Ref<DenseMatrix<Scalar>, 0, Eigen::OuterStride<>> C) {
  const bool adj = op_a == Op::Adjoint;
  const Eigen::Index m = adj ? A.cols() : A.rows();
  const Eigen::Index k = adj ? A.rows() : A.cols();
  SHROUDSIM_CHECK(B.rows() == k && C.rows() == m && C.cols() == B.cols(), "gemm: sizes do not match");
  if (m == 0 || B.cols() == 0) return;
  if (k == 0) {
    C *= beta;
    return;
  }
  const int im = static_cast<int>(m), in = static_cast<int>(B.cols()), ik = static_cast<int>(k);
  const int lda = static_cast<int>(std::max<Eigen::Index>(A.outerStride(), 1));
  const int ldb = static_cast<int>(std::max<Eigen::Index>(B.outerStride(), 1));
  const int ldc = static_cast<int>(std::max<Eigen::Index>(C.outerStride(), 1));
  const char ta = adj ? 'C' : 'N', tb = 'N';
  if constexpr (std::is_same_v<Scalar, double>)
    dgemm_(&ta, &tb, &im, &in, &ik, &alpha, A.data(), &lda, B.data(), &ldb, &beta, C.data(), &ldc);
  else zgemm_(&ta, &tb, &im, &in, &ik, &alpha, A.data(), &lda, B.data(), &ldb, &beta, C.data(), &ldc);
}

template void gemm<double>(Op, double, const Eigen::Ref<const DenseMatrix<double>, 0, Eigen::OuterStride<>>&,
                           const Eigen::Ref<const DenseMatrix<double>, 0, Eigen::OuterStride<>>&, double,
                           Eigen::Ref<DenseMatrix<double>, 0, Eigen::OuterStride<>>);
template void gemm<Complex>(Op, Complex, const Eigen::Ref<const DenseMatrix<Complex>, 0, Eigen::OuterStride<>>&,
                            const Eigen::Ref<const DenseMatrix<Complex>, 0, Eigen::OuterStride<>>&, Complex,
                            Eigen::Ref<DenseMatrix<Complex>, 0, Eigen::OuterStride<>>);

int set_blas_threads(int threads) {
  using Set = void (*)(int);
  using Get = int (*)();
  static const auto set = reinterpret_cast<Set>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  static const auto get = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!set || !get) return 0;
  const int previous = get();
  set(std::max(threads, 1));
  return previous;
}

namespace {
std::mutex serial_lock;
int serial_depth = 0;
int serial_saved = 0;
}  // namespace

SerialBlasScope::SerialBlasScope() {
  std::lock_guard<std::mutex> g(serial_lock);
  if (serial_depth++ == 0) serial_saved = set_blas_threads(1);
}

SerialBlasScope::~SerialBlasScope() {
  std::lock_guard<std::mutex> g(serial_lock);
  if (--serial_depth == 0 && serial_saved > 0) set_blas_threads(serial_saved);
}

namespace {
// The OpenMP runtime's entry points, looked up rather than linked: the runtime is whatever
// CHOLMOD loaded (libgomp for Debian's), and a program without one needs no scope.
struct OpenMPLevels {
  using Set = void (*)(int);
  using Get = int (*)();
  Set set = reinterpret_cast<Set>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  Get get = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  bool usable() const { return set && get; }
};
const OpenMPLevels& openmp_levels() {
  static const OpenMPLevels levels;
  return levels;
}
}  // namespace

SerialOpenMPScope::SerialOpenMPScope() {
  const auto& omp = openmp_levels();
  if (!omp.usable()) return;
  saved_ = omp.get();
  omp.set(0);
}

SerialOpenMPScope::~SerialOpenMPScope() {
  if (saved_ >= 0) openmp_levels().set(saved_);
}

}  // namespace shroudsim::linalg
