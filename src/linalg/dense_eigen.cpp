// LAPACK zgeev: see dense_eigen.hpp.
#include "linalg/dense_eigen.hpp"

#include <algorithm>
#include <complex>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

extern "C" {
// Fortran LAPACK (gfortran calling convention: trailing hidden lengths of the character args).
void zgeev_(const char* jobvl, const char* jobvr, const int* n, std::complex<double>* a, const int* lda,
            std::complex<double>* w, std::complex<double>* vl, const int* ldvl, std::complex<double>* vr,
            const int* ldvr, std::complex<double>* work, const int* lwork, double* rwork, int* info, std::size_t,
            std::size_t);
void dgeev_(const char* jobvl, const char* jobvr, const int* n, double* a, const int* lda, double* wr, double* wi,
            double* vl, const int* ldvl, double* vr, const int* ldvr, double* work, const int* lwork, int* info,
            std::size_t, std::size_t);
}

namespace shroudsim::linalg {
namespace {

/// LAPACK's info of an xGEEV call: > 0, the QR algorithm missed that many eigenvalues.
void check_info(int info, const char* routine, int n) {
  if (info > 0)
    throw NumericalError(std::string("the dense eigenproblem (LAPACK ") + routine + ", size " + std::to_string(n) +
                         ") did not converge: " + std::to_string(info) + " eigenvalues missing");
  if (info < 0)
    throw std::invalid_argument(std::string("dense_eigen: ") + routine + " argument " + std::to_string(-info) +
                                " is invalid");
}

}  // namespace

DenseEigen dense_eigen(const Eigen::MatrixXcd& a, bool with_vectors) {
  if (a.rows() != a.cols()) throw std::invalid_argument("dense_eigen: the matrix is not square");
  DenseEigen out;
  const int n = static_cast<int>(a.rows());
  out.values.resize(n);
  if (n == 0) return out;
  Eigen::MatrixXcd work_a = a;  // overwritten by zgeev
  if (with_vectors) out.vectors.resize(n, n);
  const char jobvl = 'N', jobvr = with_vectors ? 'V' : 'N';
  const int one = 1, ldvr = with_vectors ? n : 1;
  std::complex<double> dummy;
  std::complex<double>* vr = with_vectors ? out.vectors.data() : &dummy;
  Eigen::VectorXd rwork(2 * n);
  int info = 0, lwork = -1;
  std::complex<double> query;
  zgeev_(&jobvl, &jobvr, &n, work_a.data(), &n, out.values.data(), &dummy, &one, vr, &ldvr, &query, &lwork,
         rwork.data(), &info, 1, 1);
  lwork = std::max(1, static_cast<int>(query.real()));
  Eigen::VectorXcd work(lwork);
  zgeev_(&jobvl, &jobvr, &n, work_a.data(), &n, out.values.data(), &dummy, &one, vr, &ldvr, work.data(), &lwork,
         rwork.data(), &info, 1, 1);
  check_info(info, "zgeev", n);
  return out;
}

DenseEigen dense_eigen(const Eigen::MatrixXd& a, bool with_vectors) {
  if (a.rows() != a.cols()) throw std::invalid_argument("dense_eigen: the matrix is not square");
  DenseEigen out;
  const int n = static_cast<int>(a.rows());
  out.values.resize(n);
  if (n == 0) return out;
  Eigen::MatrixXd work_a = a;  // overwritten by dgeev
  Eigen::VectorXd wr(n), wi(n);
  Eigen::MatrixXd vr_real;
  if (with_vectors) vr_real.resize(n, n);
  const char jobvl = 'N', jobvr = with_vectors ? 'V' : 'N';
  const int one = 1, ldvr = with_vectors ? n : 1;
  double dummy = 0.0, query = 0.0;
  double* vr = with_vectors ? vr_real.data() : &dummy;
  int info = 0, lwork = -1;
  dgeev_(&jobvl, &jobvr, &n, work_a.data(), &n, wr.data(), wi.data(), &dummy, &one, vr, &ldvr, &query, &lwork, &info, 1,
         1);
  lwork = std::max(1, static_cast<int>(query));
  Eigen::VectorXd work(lwork);
  dgeev_(&jobvl, &jobvr, &n, work_a.data(), &n, wr.data(), wi.data(), &dummy, &one, vr, &ldvr, work.data(), &lwork,
         &info, 1, 1);
  check_info(info, "dgeev", n);
  for (int j = 0; j < n; ++j) out.values[j] = {wr[j], wi[j]};
  if (with_vectors) {
    // dgeev stores a conjugate pair (wi[j] > 0, then its conjugate) as two real columns,
    // v_j = re + i im and v_{j+1} = re - i im.
    out.vectors.resize(n, n);
    for (int j = 0; j < n; ++j) {
      if (wi[j] != 0.0 && j + 1 < n) {
        out.vectors.col(j) = vr_real.col(j).cast<std::complex<double>>() +
                             std::complex<double>(0.0, 1.0) * vr_real.col(j + 1).cast<std::complex<double>>();
        out.vectors.col(j + 1) = out.vectors.col(j).conjugate();
        ++j;
      } else {
        out.vectors.col(j) = vr_real.col(j).cast<std::complex<double>>();
      }
    }
  }
  return out;
}

}  // namespace shroudsim::linalg
