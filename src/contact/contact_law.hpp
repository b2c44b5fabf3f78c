#pragma once
// Time-discrete friction contact law of one node-to-node pair (docs/physics.md section 4) and
// its exact derivative through the time recursion (section 5).
//
// Relative displacement samples w(l) = (x, y, z)(l), l = 0..N-1, over one period [m]:
// x, y tangential, z normal (z > 0 presses). Forces F(l) = (Tx, Ty, N)(l) [N]:
//   N(l) = max(0, N0 + kn z(l))                    (1d: N = N0, constant)
//   damper position d (tangential, [m]), T = kt (w_t - d), |T| <= mu N.
// Tangential update of the coupled law (full3d): radial_return takes the trial force
// T* = kt (w_t(l) - d(l-1)) and returns it radially onto |T| <= mu N(l) (first order on 2D
// orbits); exact_linear takes w_t and the slip radius mu N/kt linear within each step and
// integrates the stick/slip evolution exactly (second order; see exact_linear_step). For the
// 1D laws (quasi3d per axis, 1d) both are the exact clamp and coincide.
// The periodic steady state: the period map d_end = Phi(d_start) of the damper position.
// Uncoupled models (quasi3d, 1d): the period is repeated from d = 0 until d at the period's
// end repeats (their slip is memoryless: 2 periods typically). Coupled model (full3d): the
// same plain repetition for up to 4 periods (most states repeat in 2 to 4); if d still moves,
// the fixed point d* = Phi(d*) is solved by a safeguarded Newton iteration on
// g(d) = Phi(d) - d from there, with the 2x2 derivative Phi_d carried through each period
// (contraction where the pair slips, the identity in pure stick where every d is periodic and
// d = 0 is kept; exactly neutral directions are left alone): a Newton step is accepted when
// it reduces max|g|, else the plain repetition d <- Phi(d) is taken. Both stop when
// |d_end - d_start| <= period_tolerance * max_l |w_t(l)| for the returned period (the last
// one computed, started from the accepted iterate), capped by max_periods periods; the
// status says whether it converged. Deterministic: same input, same iterates.
//
// Derivatives: the caller gives a sampled basis E (N x m). Unknown c of direction j
// (j = 0 x, 1 y, 2 z; column j*m + k, P = n_directions * m columns) moves w_j(l) by
// E(l, k). The law returns dF_i(l)/dc (LinearizedPeriod), carried exactly through stick,
// slip, separation and all repeated periods (the derivative of the discrete map as
// computed, which a central difference of the same map reproduces). Coupled model: the
// derivative of the converged periodic map, i.e. of the period started from d*(c) with
// dd*/dc = (I - Phi_d)^{-1} Phi_c at the fixed point (the implicit function theorem; exact
// when the iteration converged, whatever path it took). If the returned period sticks
// throughout (Phi_d = I, Phi_c = 0: every d is periodic) d* is held, dd*/dc = 0; likewise
// along exactly neutral directions of Phi_d (singular values of I - Phi_d <= 1e-10). States
// that repeat within the 4 plain periods keep the derivative carried through them.
#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace shroudsim::contact {

/// Contact model (docs/contract.md [contact] model).
enum class Model {
  full3d,      ///< coupled 2D tangential Coulomb, variable normal load, separation
  quasi3d,     ///< x and y as two independent 1D laws, each with limit mu N(l)
  one_d,       ///< x only, constant normal load N0 ("1d")
  one_d_exact  ///< "1d_exact": time-continuous single-harmonic Jenkins solution (H = 1)
};

/// Tangential update of the coupled law (docs/physics.md section 4).
enum class TangentialUpdate {
  radial_return,  ///< trial force, radial return to the circle mu N (the paper's; 1st order in 2D)
  exact_linear    ///< w_t linear within a step, integrated exactly (2nd order in 2D)
};

std::string to_string(Model model);              ///< "full3d", "quasi3d", "1d", "1d_exact" (contact.model)
std::string to_string(TangentialUpdate update);  ///< "radial_return", "exact_linear" (contact.tangential_update)

/// Directions a model uses: 3 (x, y, z) or 1 (x) for the 1d models.
int n_directions(Model model);

/// Physical parameters of one pair. SI units.
struct PairParameters {
  double tangential_stiffness = 1.0e6;  ///< kt [N/m], > 0
  double normal_stiffness = 1.0e6;      ///< kn [N/m], > 0 (not used by the 1d models)
  double friction_coefficient = 0.3;    ///< mu [-], >= 0
  double normal_preload = 0.25;         ///< N0 [N]; < 0: initial gap -N0/kn (1d models: >= 0)

  /// Appends one message per violated constraint ("key = value violates: ...", keys as in
  /// docs/contract.md [contact]); returns true when valid.
  bool validate(Model model, std::vector<std::string>* errors) const;
};

/// Options of the time-domain law.
struct LawOptions {
  Model model = Model::full3d;
  TangentialUpdate update = TangentialUpdate::exact_linear;
  int max_periods = 200;             ///< cap on repeated periods, >= 1
  double period_tolerance = 1e-12;   ///< relative repeat tolerance of d, in (0, 1e-3]

  bool validate(std::vector<std::string>* errors) const;
};

/// Outcome of the steady-state iteration.
struct PeriodicStatus {
  bool converged = true;  ///< d repeated within tolerance before the cap
  int periods = 0;        ///< periods computed (the last one is returned); after a Newton
                          ///< iteration (full3d) the derivative re-evaluates the last one
                          ///< once more, not counted
};

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
/// Stick runs cost O(1) per sample, so the Fourier projection can use weighted Gram matrices
/// for them (hbm/), and dense rows only where the state slips.
struct LinearizedPeriod {
  struct Run {
    int first = 0, last = 0;  ///< inclusive sample range
    int anchor = -1;          ///< >= 0: X = alpha E_i(anchor) + beta E_z(anchor)
    double alpha = 0.0, beta = 0.0;
  };
  std::array<std::vector<Run>, 2> runs;
  std::array<RowMatrix, 2> run_x;           ///< capacity N rows; row r: X_i in run r (P)
  std::array<std::vector<int>, 2> dense_index;
  std::array<RowMatrix, 2> dense;           ///< capacity N rows; row k: dT_i (P)
  std::array<std::vector<double>, 2> slip_weight;  ///< N each for uncoupled models, else empty
  std::vector<unsigned char> pressed;       ///< N flags (all 0 for the 1d model)
  double kt = 0.0, kn = 0.0;                ///< [N/m]
  int p = 0;                                ///< unknowns

  /// dF_i(l)/dc as N x P matrices, i = x, y, z (for tests and inspection).
  void expand(const Eigen::MatrixXd& basis, std::array<RowMatrix, 3>& df) const;
};

/// The discrete periodic law of one pair with reusable scratch. Not thread-safe: use one
/// instance per thread. Model one_d_exact is not a time recursion and is refused here
/// (see jenkins.hpp).
class PeriodicLaw {
 public:
  explicit PeriodicLaw(LawOptions options);

  /// w: N x 3 samples [m] (columns the model does not use are ignored); f: N x 3 forces
  /// (Tx, Ty, N) [N] of the last (steady) period, unused columns zero.
  /// basis, lin: both null (forces only) or both set; then *lin holds the derivative of the
  /// returned period w.r.t. P = n_directions(model) * basis->cols() unknowns (see
  /// LinearizedPeriod), carried exactly through all repeated periods.
  PeriodicStatus evaluate(const PairParameters& pair, const Eigen::MatrixX3d& w,
                          Eigen::MatrixX3d& f, const Eigen::MatrixXd* basis = nullptr,
                          LinearizedPeriod* lin = nullptr);

  const LawOptions& options() const { return options_; }

 private:
  template <bool kWithDerivative>
  PeriodicStatus run(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                     const Eigen::MatrixXd* basis, LinearizedPeriod* lin);

  struct Anchor {  // uncoupled models: damper derivative X_i = alpha E_i(s) + beta E_z(s)
    int s = 0;
    double alpha = 0.0, beta = 0.0;
  };
  /// One period from the current state (d_, anchor_, xd_, yd_), which it advances. track:
  /// also carry D_ = d(d)/d(d_start) (2 x 2, coupled model) and, with kWithDerivative, the
  /// sensitivities of the recorded rows to d_start (run_d_, dense_q_).
  template <bool kWithDerivative>
  void period(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
              const Eigen::MatrixXd* basis, LinearizedPeriod* lin, bool track);

  LawOptions options_;
  // Derivative scratch of the coupled model: d(damper position)/dc, one row (P) per
  // tangential direction.
  Eigen::RowVectorXd xd_, yd_;
  // Period state: damper position [m], anchors of the uncoupled models.
  std::array<double, 2> d_{0.0, 0.0};
  std::array<Anchor, 2> anchor_{};
  std::array<double, 2> last_start_{0.0, 0.0};  // start of the last plain period (coupled)
  // Coupled model: D_ = d(d)/d(d_start) within the period; slipped_: a sample of the period
  // slipped or separated (else Phi_d = I); per stick run r of direction i the D_ of the run
  // (X_i,r moves by row i of it times dd*/dc), per dense row k dT/d(d_start) (2 x 2).
  Eigen::Matrix2d dd_start_ = Eigen::Matrix2d::Identity();
  bool slipped_ = false;
  std::array<std::vector<Eigen::Matrix2d>, 2> run_d_;
  std::vector<Eigen::Matrix2d> dense_q_;
  Eigen::MatrixXd fixed_point_dc_;  // 2 x P: dd*/dc
};

/// One exact_linear step of the coupled law in elastic-displacement form (exposed for tests).
/// e0 = w_t(l-1) - d(l-1) [m], dw = w_t(l) - w_t(l-1) [m], slip radii a0 = mu N(l-1)/kt >= 0
/// and a1 = mu N(l)/kt > 0 [m]. w_t and the radius are taken linear within the step and the
/// stick/slip evolution integrated exactly: the stick fraction s* from a quadratic, then the
/// slip angle from tan((q - p1)/2) = tan((q - p0)/2) exp(-|dw| int ds/a(s)) (q = arg dw).
/// Returns e1 = w_t(l) - d(l), |e1| <= a1; if jac != nullptr, also
/// de1/d(e0x, e0y, dwx, dwy, a0, a1) (2 x 6).
/// stuck (optional): set when the whole step sticks from an admissible start (e1 = e0 + dw).
Eigen::Vector2d exact_linear_step(const Eigen::Vector2d& e0, const Eigen::Vector2d& dw, double a0,
                                  double a1, Eigen::Matrix<double, 2, 6>* jac = nullptr,
                                  bool* stuck = nullptr);

}  // namespace shroudsim::contact
