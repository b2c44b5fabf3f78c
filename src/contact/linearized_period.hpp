#pragma once
// The exact derivative of one period of the friction contact law (docs/physics.md section 5)
// in compact form, and the bookkeeping that builds it sample by sample as PeriodicLaw
// (contact/periodic_law.hpp) steps through the period.
//
// Unknowns: the caller gives a sampled basis E (N x m). Unknown c of direction j (j = 0 x,
// 1 y, 2 z; column j*m + k, P = n_directions * m columns) moves w_j(l) by E(l, k). The
// derivative dF_i(l)/dc is the derivative of the discrete map as computed (a central
// difference of the same map reproduces it wherever no sample changes state). Its form:
//  - stick: T = kt (w_t - d) with the damper position d unchanged, so dT_i(l)/dc =
//    kt (E_i(l) - X_i) with the damper derivative X_i = dd_i/dc constant over a run of stick
//    samples: one row per run instead of per sample;
//  - slip of the coupled model: dT_i(l)/dc depends on everything before, a row of P per
//    sample (explicit rows), and X moves;
//  - slip of an uncoupled model: memoryless, dT_i(l)/dc = weight E_z(l), and the damper
//    derivative afterwards is alpha E_i(s) + beta E_z(s) of the last slip or separation
//    sample s (an "anchor"): no P-wide rows at all;
//  - separation: T = 0 and X = E_t(l) (the damper follows).
// Stick runs cost O(1) per sample, so the Fourier projection can use weighted Gram matrices
// for them (hbm/), and dense rows only where the state slips.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace shroudsim::contact {

/// Row-major dense matrix: one row per time sample, written sample by sample.
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The exact derivative of the returned (steady) period in compact form. P unknowns c; E the
/// sampled basis (N x m), E_j(l) = row l of E placed in block j (columns j*m .. j*m+m-1).
/// Tangential direction i (0 x, 1 y; only 0 for the 1d model), sample l, exactly one of:
///  - stick, l in run r of runs[i]:  dT_i(l)/dc = kt (E_i(l) - X_i,r), the damper derivative
///    X_i,r constant over the run: run_x[i].row(r) (coupled model, anchor < 0) or
///    alpha E_i(anchor) + beta E_z(anchor) (uncoupled models: their slip is memoryless);
///  - explicit, l = dense_index[i][k]: dT_i(l)/dc = dense[i].row(k) (coupled slip);
///  - slip of an uncoupled model: dT_i(l)/dc = slip_weight[i][l] E_z(l);
///  - otherwise dT_i(l)/dc = 0 (separation, no friction, or 1d slip at constant load).
/// Normal: dN(l)/dc = kn E_z(l) where pressed[l], else 0.
struct LinearizedPeriod {
  struct Run {
    int first = 0, last = 0;  ///< inclusive sample range
    int anchor = -1;          ///< >= 0: X = alpha E_i(anchor) + beta E_z(anchor)
    double alpha = 0.0, beta = 0.0;
  };
  std::array<std::vector<Run>, 2> runs;
  std::array<RowMatrix, 2> run_x;  ///< capacity N rows; row r: X_i in run r (P)
  std::array<std::vector<int>, 2> dense_index;
  std::array<RowMatrix, 2> dense;                  ///< capacity N rows; row k: dT_i (P)
  std::array<std::vector<double>, 2> slip_weight;  ///< N each for uncoupled models, else empty
  std::vector<unsigned char> pressed;              ///< N flags (all 0 for the 1d model)
  double kt = 0.0, kn = 0.0;                       ///< [N/m]
  int p = 0;                                       ///< unknowns

  /// dF_i(l)/dc as N x P matrices, i = x, y, z (for tests and inspection).
  void expand(const Eigen::MatrixXd& basis, std::array<RowMatrix, 3>& df) const;

  /// Sizes the storage for N = samples, P = unknowns and `tangential` directions (2, or 1 for
  /// the 1d model), keeping capacity across calls; sets kt and kn (0 without a normal
  /// direction). Before the first period of an evaluation.
  void prepare(int samples, int unknowns, int tangential, double kt_value, double kn_value);
};

/// Records one period into a LinearizedPeriod (prepared) sample by sample: the stick runs,
/// slip weights and pressed flags. Starting clears the runs and explicit rows and zeroes the
/// slip weights of the first `slip_directions` directions (uncoupled models; 0 for the
/// coupled one). Each tangential direction is in an open stick run or not; a stick sample
/// extends the open run when its damper derivative is the run's, else opens a new one.
class PeriodRecorder {
 public:
  PeriodRecorder(LinearizedPeriod& lin, int samples, int slip_directions);

  void set_pressed(int l, bool pressed) { lin_.pressed[l] = pressed ? 1 : 0; }
  /// Coupled model: direction i sticks at l with damper derivative x (P). Returns true when
  /// this opened a run (X_i of the run = x).
  bool stick(int i, int l, const Eigen::RowVectorXd& x) {
    const bool opened = !prev_stick_[i];
    if (opened) {
      lin_.runs[i].push_back({l, l, -1, 0.0, 0.0});
      lin_.run_x[i].row(static_cast<Eigen::Index>(lin_.runs[i].size() - 1)) = x;
    } else {
      lin_.runs[i].back().last = l;
    }
    prev_stick_[i] = true;
    return opened;
  }
  /// Uncoupled models: direction i sticks at l, its damper derivative anchored at sample s.
  void stick_anchored(int i, int l, int s, double alpha, double beta) {
    auto& runs = lin_.runs[i];
    if (!prev_stick_[i] || runs.back().anchor != s || runs.back().alpha != alpha || runs.back().beta != beta)
      runs.push_back({l, l, s, alpha, beta});
    else runs.back().last = l;
    prev_stick_[i] = true;
  }
  /// Uncoupled slip of direction i at l: dT_i(l)/dc = weight E_z(l).
  void slip(int i, int l, double weight) {
    lin_.slip_weight[i][l] = weight;
    prev_stick_[i] = false;
  }
  /// Direction i does not stick at this sample (separation): the run closes.
  void release(int i) { prev_stick_[i] = false; }

  /// Coupled radial-return slip at sample l: appends the explicit rows of both directions
  /// and closes their runs; x, y: the damper derivative X (rows of P), advanced in place.
  /// With e = T*/|T*|, rho = mu N / |T*|, E_x, E_y, E_z the basis rows of l in blocks 0, 1, 2:
  ///   dT = mu kn E_z e + rho (I - e e^T) dT*,  dT* = kt (E_t - X),  X <- E_t - dT / kt.
  void radial_return_slip(const Eigen::MatrixXd& basis, int l, double kt, double kn, double mu, double ex, double ey,
                          double rho, Eigen::RowVectorXd& x, Eigen::RowVectorXd& y);
  /// Coupled exact_linear slip at sample l (previous sample lp), the same from the step's
  /// Jacobian jl = de1/d(e0x, e0y, dwx, dwy, a0, a1) (exact_linear_step):
  ///   de1 = J_e0 (E_t(lp) - X) + J_dw (E_t(l) - E_t(lp)) + J_a0 mu kn E_z(lp)/kt [pressed at lp]
  ///         + J_a1 mu kn E_z(l)/kt,          dT = kt de1,  X <- E_t(l) - de1.
  /// z_prev, z_l: further coefficients of E_z(lp) and E_z(l) in de1 (the closing instant's
  /// dependence on the normal motion, periodic_law.cpp; zero otherwise).
  void exact_linear_slip(const Eigen::MatrixXd& basis, int l, int lp, double kt, double kn, double mu,
                         bool pressed_prev, const Eigen::Matrix<double, 2, 6>& jl, Eigen::RowVectorXd& x,
                         Eigen::RowVectorXd& y, const std::array<double, 2>& z_prev = {0.0, 0.0},
                         const std::array<double, 2>& z_l = {0.0, 0.0});

 private:
  LinearizedPeriod& lin_;
  std::array<bool, 2> prev_stick_{false, false};
};

/// Coupled model, a period started from the fixed point d*(c): adds the term through
/// dd*/dc (2 x P) to the rows recorded with the start held fixed: X_i,r += row i of
/// run_d[i][r] times dd*/dc, dense row k of direction i += row i of dense_q[k] times dd*/dc
/// (run_d: d(d)/d(d_start) at each run's opening; dense_q: dT/d(d_start) of each explicit row).
void add_fixed_point_term(LinearizedPeriod& lin, const Eigen::MatrixXd& dd_dc,
                          const std::array<std::vector<Eigen::Matrix2d>, 2>& run_d,
                          const std::vector<Eigen::Matrix2d>& dense_q);

}  // namespace shroudsim::contact
