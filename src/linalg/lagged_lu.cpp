#include "linalg/lagged_lu.hpp"

namespace shroudsim::linalg {

void LaggedLuPreconditioner::factorize(const Eigen::MatrixXd& A) {
  lu_.compute(A.cast<float>());
  // An exactly zero pivot stays in U (Eigen's partial pivoting does not stop there).
  nonsingular_ = (lu_.matrixLU().diagonal().array() != 0.0f).all();
  iterations_since_factor_ = 0;
  valid_ = true;
  renew_ = false;
}

void LaggedLuPreconditioner::apply(const Eigen::VectorXd& v, Eigen::VectorXd& z) const {
  z = lu_.solve(v.cast<float>()).cast<double>();
}

void LaggedLuPreconditioner::decide_renewal(int iterations, int refactor_after) {
  constexpr double kTriangularSlowdown = 4.0;
  const double m = static_cast<double>(lu_.rows());
  renew_ = iterations > refactor_after &&
           kTriangularSlowdown * 2.0 * m * m * iterations_since_factor_ > (2.0 / 3.0) * m * m * m;
}

}  // namespace shroudsim::linalg
