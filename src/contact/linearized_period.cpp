#include "contact/linearized_period.hpp"

namespace shroudsim::contact {

void LinearizedPeriod::expand(const Eigen::MatrixXd& basis, std::array<RowMatrix, 3>& df) const {
  const int n = static_cast<int>(basis.rows());
  const int m = static_cast<int>(basis.cols());
  for (auto& d : df) d.setZero(n, p);
  for (int i = 0; i < 2; ++i) {
    for (size_t r = 0; r < runs[i].size(); ++r) {
      const Run& run = runs[i][r];
      for (int l = run.first; l <= run.last; ++l) {
        if (run.anchor < 0) {
          df[i].row(l) = -kt * run_x[i].row(static_cast<Eigen::Index>(r));
        } else {
          df[i].row(l).segment(i * m, m) = -kt * run.alpha * basis.row(run.anchor);
          if (run.beta != 0.0) df[i].row(l).segment(2 * m, m) = -kt * run.beta * basis.row(run.anchor);
        }
        df[i].row(l).segment(i * m, m) += kt * basis.row(l);
      }
    }
    for (size_t l = 0; l < slip_weight[i].size(); ++l)
      if (slip_weight[i][l] != 0.0)
        df[i].row(static_cast<Eigen::Index>(l)).segment(2 * m, m) =
            slip_weight[i][l] * basis.row(static_cast<Eigen::Index>(l));
    for (size_t k = 0; k < dense_index[i].size(); ++k)
      df[i].row(dense_index[i][k]) = dense[i].row(static_cast<Eigen::Index>(k));
  }
  for (int l = 0; l < n; ++l)
    if (!pressed.empty() && pressed[l]) df[2].row(l).segment(2 * m, m) = kn * basis.row(l);
}

void LinearizedPeriod::prepare(int samples, int unknowns, int tangential, double kt_value, double kn_value) {
  kt = kt_value;
  kn = kn_value;
  p = unknowns;
  for (int i = 0; i < 2; ++i) {
    const int rows = i < tangential ? samples : 0;
    if (run_x[i].rows() != rows || run_x[i].cols() != p) run_x[i].resize(rows, p);
    if (dense[i].rows() != rows || dense[i].cols() != p) dense[i].resize(rows, p);
    runs[i].reserve(samples);
    dense_index[i].reserve(samples);
  }
  pressed.assign(samples, 0);
}

PeriodRecorder::PeriodRecorder(LinearizedPeriod& lin, int samples, int slip_directions) : lin_(lin) {
  for (int i = 0; i < 2; ++i) {
    lin_.runs[i].clear();
    lin_.dense_index[i].clear();
    lin_.slip_weight[i].assign(i >= slip_directions ? 0 : samples, 0.0);
  }
}

void PeriodRecorder::radial_return_slip(const Eigen::MatrixXd& basis, int l, double kt, double kn, double mu, double ex,
                                        double ey, double rho, Eigen::RowVectorXd& x, Eigen::RowVectorXd& y) {
  // One fused pass over the P columns, written straight into the dense rows of this sample.
  const int n = static_cast<int>(basis.rows());
  const int m = static_cast<int>(basis.cols());
  const Eigen::Index k = static_cast<Eigen::Index>(lin_.dense_index[0].size());
  double* rx = lin_.dense[0].row(k).data();
  double* ry = lin_.dense[1].row(k).data();
  double* xd = x.data();
  double* yd = y.data();
  const double* el = basis.data() + l;  // column-major: E(l, c) = el[c * n]
  const double mkx = mu * kn * ex, mky = mu * kn * ey, ikt = 1.0 / kt;
  for (int blk = 0; blk < 3; ++blk) {
    const double bx = blk == 0 ? 1.0 : 0.0, by = blk == 1 ? 1.0 : 0.0;
    const double zx = blk == 2 ? mkx : 0.0, zy = blk == 2 ? mky : 0.0;
    for (int k = 0, c = blk * m; k < m; ++k, ++c) {
      const double e = el[static_cast<Eigen::Index>(k) * n];
      const double gx = kt * (bx * e - xd[c]);
      const double gy = kt * (by * e - yd[c]);
      const double pr = ex * gx + ey * gy;
      const double tdx = rho * (gx - ex * pr) + zx * e;
      const double tdy = rho * (gy - ey * pr) + zy * e;
      rx[c] = tdx;
      ry[c] = tdy;
      xd[c] = bx * e - tdx * ikt;
      yd[c] = by * e - tdy * ikt;
    }
  }
  lin_.dense_index[0].push_back(l);
  lin_.dense_index[1].push_back(l);
  release(0);
  release(1);
}

void PeriodRecorder::exact_linear_slip(const Eigen::MatrixXd& basis, int l, int lp, double kt, double kn, double mu,
                                       bool pressed_prev, const Eigen::Matrix<double, 2, 6>& jl, Eigen::RowVectorXd& x,
                                       Eigen::RowVectorXd& y, const std::array<double, 2>& z_prev,
                                       const std::array<double, 2>& z_l) {
  const int n = static_cast<int>(basis.rows());
  const int m = static_cast<int>(basis.cols());
  const double ca = mu * kn / kt;
  const double cp = pressed_prev ? ca : 0.0;
  const Eigen::Index k = static_cast<Eigen::Index>(lin_.dense_index[0].size());
  double* rx = lin_.dense[0].row(k).data();
  double* ry = lin_.dense[1].row(k).data();
  double* xd = x.data();
  double* yd = y.data();
  const double* el = basis.data() + l;
  const double* ep = basis.data() + lp;
  for (int blk = 0; blk < 3; ++blk) {
    // de1_i = -J_i0 dd_x - J_i1 dd_y + u_i E(lp) + v_i E(l) within block blk
    double u[2], v[2];
    for (int i = 0; i < 2; ++i) {
      u[i] = blk == 0 ? jl(i, 0) - jl(i, 2) : blk == 1 ? jl(i, 1) - jl(i, 3) : jl(i, 4) * cp + z_prev[i];
      v[i] = blk == 0 ? jl(i, 2) : blk == 1 ? jl(i, 3) : jl(i, 5) * ca + z_l[i];
    }
    const double bx = blk == 0 ? 1.0 : 0.0, by = blk == 1 ? 1.0 : 0.0;
    for (int k = 0, c = blk * m; k < m; ++k, ++c) {
      const Eigen::Index off = static_cast<Eigen::Index>(k) * n;
      const double e = el[off], eprev = ep[off];
      const double g0 = -jl(0, 0) * xd[c] - jl(0, 1) * yd[c] + u[0] * eprev + v[0] * e;
      const double g1 = -jl(1, 0) * xd[c] - jl(1, 1) * yd[c] + u[1] * eprev + v[1] * e;
      rx[c] = kt * g0;
      ry[c] = kt * g1;
      xd[c] = bx * e - g0;
      yd[c] = by * e - g1;
    }
  }
  lin_.dense_index[0].push_back(l);
  lin_.dense_index[1].push_back(l);
  release(0);
  release(1);
}

void add_fixed_point_term(LinearizedPeriod& lin, const Eigen::MatrixXd& dd_dc,
                          const std::array<std::vector<Eigen::Matrix2d>, 2>& run_d,
                          const std::vector<Eigen::Matrix2d>& dense_q) {
  const auto z0 = dd_dc.row(0);
  const auto z1 = dd_dc.row(1);
  for (int i = 0; i < 2; ++i) {
    for (size_t r = 0; r < lin.runs[i].size(); ++r) {
      const Eigen::Matrix2d& s = run_d[i][r];
      lin.run_x[i].row(static_cast<Eigen::Index>(r)) += s(i, 0) * z0 + s(i, 1) * z1;
    }
    for (size_t k = 0; k < lin.dense_index[i].size(); ++k) {
      const Eigen::Matrix2d& q = dense_q[k];
      lin.dense[i].row(static_cast<Eigen::Index>(k)) += q(i, 0) * z0 + q(i, 1) * z1;
    }
  }
}

}  // namespace shroudsim::contact
