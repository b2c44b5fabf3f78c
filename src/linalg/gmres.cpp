#include "linalg/gmres.hpp"

#include <cmath>

namespace shroudsim::linalg {

GmresResult gmres(const VectorOperator& op, const VectorOperator& precondition, const Eigen::VectorXd& b,
                  Eigen::VectorXd& x, const GmresOptions& options) {
  const Eigen::Index m = b.size();
  const int kmax = options.max_iterations;
  const double beta = b.norm();
  GmresResult result;
  if (beta == 0.0) {
    x.setZero(m);
    result.converged = true;
    return result;
  }
  Eigen::MatrixXd V(m, kmax + 1), Z(m, kmax), H = Eigen::MatrixXd::Zero(kmax + 1, kmax);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(kmax + 1), cs(kmax), sn(kmax), w(m), hcol(kmax + 1), z(m);
  V.col(0) = b / beta;
  g[0] = beta;
  int k = 0;
  for (; k < kmax; ++k) {
    precondition(V.col(k), z);
    Z.col(k) = z;
    op(Z.col(k), w);
    auto basis = V.leftCols(k + 1);
    hcol.head(k + 1).noalias() = basis.transpose() * w;
    w.noalias() -= basis * hcol.head(k + 1);
    const Eigen::VectorXd again = basis.transpose() * w;
    w.noalias() -= basis * again;
    hcol.head(k + 1) += again;
    const double hn = w.norm();
    H.col(k).head(k + 1) = hcol.head(k + 1);
    H(k + 1, k) = hn;
    if (hn > 0) V.col(k + 1) = w / hn;
    for (int i = 0; i < k; ++i) {
      const double a = H(i, k), c = H(i + 1, k);
      H(i, k) = cs[i] * a + sn[i] * c;
      H(i + 1, k) = -sn[i] * a + cs[i] * c;
    }
    const double a = H(k, k), c = H(k + 1, k), rho = std::hypot(a, c);
    if (!(rho > 0)) return result;  // breakdown: not converged, no iterations counted
    cs[k] = a / rho;
    sn[k] = c / rho;
    H(k, k) = rho;
    H(k + 1, k) = 0.0;
    g[k + 1] = -sn[k] * g[k];
    g[k] = cs[k] * g[k];
    if (std::abs(g[k + 1]) <= 0.1 * options.tolerance * beta || hn == 0.0) {
      ++k;
      break;
    }
  }
  result.iterations = k;
  const Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
  x.noalias() = Z.leftCols(k) * y;
  // The true residual decides (round-off in the recurrence, a stagnating Krylov space).
  if (!x.allFinite()) return result;
  op(x, w);
  result.converged = (w - b).norm() <= options.tolerance * beta;
  return result;
}

}  // namespace shroudsim::linalg
