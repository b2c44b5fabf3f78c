#pragma once
// Dense products of tall-skinny blocks (n x m times n x b, n >> m, b) through the system
// BLAS (OpenBLAS on a machine set up by tools/setup.sh: vectorised for the CPU it runs on
// and threaded), for the block eigensolver's orthogonalizations. Eigen's own kernels are
// compiled for the baseline x86-64 instruction set and run on one core.
//
//   C = alpha * op(A) * B + beta * C,   op(A) = A or A^H (A^T for real scalars).
// Column-major blocks with any outer stride; sizes are checked.
#include <Eigen/Core>

#include "linalg/sparse.hpp"

namespace shroudsim::linalg {

template <typename Scalar>
using DenseMatrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

enum class Op { None, Adjoint };

template <typename Scalar>
void gemm(Op op_a, Scalar alpha, const Eigen::Ref<const DenseMatrix<Scalar>, 0, Eigen::OuterStride<>>& A,
          const Eigen::Ref<const DenseMatrix<Scalar>, 0, Eigen::OuterStride<>>& B, Scalar beta,
          Eigen::Ref<DenseMatrix<Scalar>, 0, Eigen::OuterStride<>> C);

/// Threads the BLAS may use (OpenBLAS only; elsewhere a no-op). Returns the previous
/// setting, or 0 if the BLAS does not expose one. Call from one thread at a time.
int set_blas_threads(int threads);

/// While at least one of these is alive (in any thread), the BLAS runs on one thread: for
/// code that runs several factorizations in parallel workers, where OpenBLAS's own threads
/// would oversubscribe the cores (2 workers x 2 BLAS threads on 2 cores took 171 s against
/// 104 s for the 2e5-DOF modal benchmark). Nesting and concurrent scopes are safe.
class SerialBlasScope {
 public:
  SerialBlasScope();
  ~SerialBlasScope();
  SerialBlasScope(const SerialBlasScope&) = delete;
  SerialBlasScope& operator=(const SerialBlasScope&) = delete;
};

/// While alive, OpenMP parallel regions started on the calling thread run on that thread
/// alone (max-active-levels 0; restored on destruction). For parallel workers that call a
/// library threaded with OpenMP: CHOLMOD's supernodal factorization opens a team of its own
/// fixed size for each large supernode, whatever OMP_NUM_THREADS says, so 2 workers on 2
/// cores ran 6 threads and switched context 24,000 times in a 1.6 s `modes` run
/// (BENCHMARKS.md, "The reduction in one pass, the mass product by blocks, OpenMP inside the
/// workers, ..."). A no-op when no OpenMP runtime is loaded. One per thread; not to be moved
/// across threads.
class SerialOpenMPScope {
 public:
  SerialOpenMPScope();
  ~SerialOpenMPScope();
  SerialOpenMPScope(const SerialOpenMPScope&) = delete;
  SerialOpenMPScope& operator=(const SerialOpenMPScope&) = delete;

 private:
  int saved_ = -1;  ///< the thread's max-active-levels before, -1: nothing to restore
};

}  // namespace shroudsim::linalg
