#include "modal/block_krylov_schur.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <utility>

#include "linalg/blas.hpp"
#include "linalg/orthogonalization.hpp"

namespace shroudsim::modal {

namespace {
constexpr Eigen::Index kDefaultBlock = 4;  // see block_krylov_schur_sizes
}  // namespace

BlockKrylovSchurOptions block_krylov_schur_sizes(Eigen::Index n, int modes, int block_size, int ncv, int max_restarts,
                                                 double tolerance) {
  BlockKrylovSchurOptions o;
  o.nev = std::min<Eigen::Index>(modes, n - 1);
  o.block = std::min<Eigen::Index>(block_size > 0 ? block_size : kDefaultBlock, n / 4);
  Eigen::Index mmax = ncv > 0 ? ncv : std::max<Eigen::Index>(3 * o.nev, o.nev + 3 * o.block);
  o.basis = std::min(std::max(mmax, o.nev + 2 * o.block), n);
  // Ritz vectors kept at a restart: the wanted ones and one block of the next.
  o.keep = std::min(o.nev + o.block, o.basis - o.block);
  o.max_restarts = max_restarts;
  o.tolerance = tolerance;
  return o;
}

template <typename S>
BlockKrylovSchurResult<S> block_krylov_schur(const std::function<Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>(
                                                 const Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>&)>& apply,
                                             Eigen::Index n, const BlockKrylovSchurOptions& options) {
  using Block = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  const Eigen::Index nev = options.nev, b = options.block, mmax = options.basis, keep = options.keep;
  BlockKrylovSchurResult<S> result;

  Block V(n, mmax), T = Block::Zero(mmax, mmax), Q = linalg::deterministic_block<S>(n, b), B;
  linalg::block_qr<S>(V.leftCols(0), Q, B);
  Eigen::Index m = 0;
  Eigen::VectorXd theta;
  Block Y;
  bool converged = false;
  int restarts = 0;
  while (!converged) {
    if (m + b > mmax) {
      if (restarts == options.max_restarts) break;
      // Thick restart on the `keep` largest Ritz pairs (theta ascending: the last columns).
      const Block Yk = Y.rightCols(keep);
      Block U(n, keep);
      linalg::gemm<S>(linalg::Op::None, S(1), V.leftCols(m), Yk, S(0), U);
      V.leftCols(keep) = U;
      T.setZero();
      T.topLeftCorner(keep, keep).diagonal() = theta.tail(keep).template cast<S>();
      m = keep;
      ++restarts;
    }
    V.middleCols(m, b) = Q;
    m += b;
    Block W = apply(Q);
    const Block H = linalg::orthogonalize<S>(V.leftCols(m), W);
    T.block(0, m - b, m, b) = H;
    T.block(m - b, 0, b, m) = H.adjoint();
    T.block(m - b, m - b, b, b) = (0.5 * (H.bottomRows(b) + H.bottomRows(b).adjoint())).eval();
    Q = std::move(W);
    linalg::block_qr<S>(V.leftCols(m), Q, B);
    ++result.steps;

    if (m < nev) continue;
    Eigen::SelfAdjointEigenSolver<Block> es(T.topLeftCorner(m, m));
    if (es.info() != Eigen::Success) break;
    theta = es.eigenvalues();  // ascending; the wanted are the largest
    Y = es.eigenvectors();
    const Block resid = B * Y.bottomRows(b).rightCols(nev);
    converged = true;
    for (Eigen::Index j = 0; j < nev; ++j) {
      const double th = theta(m - nev + j);
      if (!(th > 0.0) || !(resid.col(j).norm() <= options.tolerance * th)) converged = false;
    }
  }
  result.restarts = restarts;
  result.converged = converged;
  if (theta.size() > 0)
    for (Eigen::Index j = 0; j < nev; ++j)
      if (theta(m - nev + j) > 0.0 &&
          (B * Y.bottomRows(b).col(m - nev + j)).norm() <= options.tolerance * theta(m - nev + j))
        ++result.converged_values;
  if (!converged) return result;
  result.theta = theta.tail(nev);
  result.vectors.resize(n, nev);
  linalg::gemm<S>(linalg::Op::None, S(1), V.leftCols(m), Y.rightCols(nev), S(0), result.vectors);
  return result;
}

template BlockKrylovSchurResult<double> block_krylov_schur<double>(
    const std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)>&, Eigen::Index, const BlockKrylovSchurOptions&);
template BlockKrylovSchurResult<linalg::Complex> block_krylov_schur<linalg::Complex>(
    const std::function<Eigen::MatrixXcd(const Eigen::MatrixXcd&)>&, Eigen::Index, const BlockKrylovSchurOptions&);

}  // namespace shroudsim::modal
