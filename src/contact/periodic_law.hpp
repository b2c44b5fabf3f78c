#pragma once
// The periodic steady state of the time-discrete friction contact law of one pair
// (docs/physics.md section 4) and its exact derivative (section 5), for the vocabulary of
// contact/contact_law.hpp.
//
// One period is the time recursion over the samples l = 0..N-1 (sample 0 follows N-1), each
// sample updated by contact/friction_step.hpp: the period map d_end = Phi(d_start) of the
// damper position. The periodic steady state is a fixed point of Phi:
//  - uncoupled models (quasi3d, 1d): the period is repeated from d = 0 until d at the
//    period's end repeats (their slip is memoryless: 2 periods typically);
//  - coupled model (full3d): the same plain repetition for up to 4 periods (most states
//    repeat in 2 to 4); if d still moves, the fixed point d* = Phi(d*) is solved by a
//    safeguarded Newton iteration on g(d) = Phi(d) - d from there, with the 2x2 derivative
//    Phi_d carried through each period (contraction where the pair slips, the identity in
//    pure stick where every d is periodic and d = 0 is kept; exactly neutral directions are
//    left alone): a Newton step is accepted when it reduces max|g|, else it is halved (up
//    to 4 times) and, if none of those reduces max|g| either, the plain repetition
//    d <- Phi(d) is taken.
// Both stop when |d_end - d_start| <= period_tolerance * max_l |w_t(l)| for the returned
// period (the last one computed, started from the accepted iterate), capped by max_periods
// periods; the status says whether it converged. Deterministic: same input, same iterates.
//
// Derivatives (contact/linearized_period.hpp) are carried exactly through stick, slip,
// separation and all repeated periods. Coupled model: the derivative of the converged
// periodic map, i.e. of the period started from d*(c) with dd*/dc = (I - Phi_d)^{-1} Phi_c at
// the fixed point (the implicit function theorem; exact when the iteration converged,
// whatever path it took). If the returned period sticks throughout (Phi_d = I, Phi_c = 0:
// every d is periodic) d* is held, dd*/dc = 0; likewise along exactly neutral directions of
// Phi_d (singular values of I - Phi_d <= 1e-10). States that repeat within the 4 plain
// periods keep the derivative carried through them.
#include <Eigen/Core>
#include <array>
#include <vector>

#include "contact/contact_law.hpp"
#include "contact/linearized_period.hpp"

namespace shroudsim::contact {

/// Outcome of the steady-state iteration.
struct PeriodicStatus {
  bool converged = true;  ///< d repeated within tolerance before the cap
  int periods = 0;        ///< periods computed (the last one is returned); after a Newton
                          ///< iteration (full3d) the derivative re-evaluates the last one
                          ///< once more, not counted
};

/// One sample of the steady period as a linear recursion of the damper position d (2, x and
/// y; the 1d model's y row is zero), for a perturbation u = (x, y, z) of the relative
/// displacement samples:  d(l) = a d(l-1) + b u(l) + c u(l-1),  and the forces
/// T(l) = kt (w_t(l) - d(l)) (x only for the 1d model), N(l) = kn z(l) where `pressed`
/// (3D models). This is the derivative of section 5 unrolled in time: the damper carries the
/// law's memory from one sample to the next, which a Floquet perturbation e^{lambda t} p(t)
/// weighs by e^{-lambda dt} per sample (docs/physics.md section 9, "Friction: the slider as a
/// state").
struct SampleStep {
  Eigen::Matrix2d a = Eigen::Matrix2d::Zero();
  Eigen::Matrix<double, 2, 3> b = Eigen::Matrix<double, 2, 3>::Zero();
  Eigen::Matrix<double, 2, 3> c = Eigen::Matrix<double, 2, 3>::Zero();
  bool pressed = false;
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
  PeriodicStatus evaluate(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                          const Eigen::MatrixXd* basis = nullptr, LinearizedPeriod* lin = nullptr);

  /// The steady period (as evaluate, forces only) and then its samples' recursion: one more
  /// period from the converged damper state, each sample linearized (steps: N entries).
  PeriodicStatus sample_steps(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                              std::vector<SampleStep>& steps);

  const LawOptions& options() const { return options_; }

 private:
  template <bool kWithDerivative>
  PeriodicStatus run(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f,
                     const Eigen::MatrixXd* basis, LinearizedPeriod* lin);

  // Uncoupled models: the damper derivative X_i = alpha E_i(s) + beta E_z(s), or, after a
  // closing step that sticks (explicit_x), the row xd_ (x) or yd_ (y).
  struct Anchor {
    int s = 0;
    double alpha = 0.0, beta = 0.0;
    bool explicit_x = false;
  };
  /// One period from the current state (d_, anchor_, xd_, yd_), which it advances. track:
  /// also carry D_ = d(d)/d(d_start) (2 x 2, coupled model) and, with kWithDerivative, the
  /// sensitivities of the recorded rows to d_start (run_d_, dense_q_).
  template <bool kWithDerivative>
  void period(const PairParameters& pair, const Eigen::MatrixX3d& w, Eigen::MatrixX3d& f, const Eigen::MatrixXd* basis,
              LinearizedPeriod* lin, bool track);

  /// What a sample's update needs of the motion and the normal load (defined in the .cpp).
  struct Sample;
  // The update of one pressed sample with friction, by model (period() handles separation
  // itself); each advances the period state and, with kWithDerivative, records into rec.
  // Returns (Tx, Ty).
  template <bool kWithDerivative>
  std::array<double, 2> coupled_radial_return(const PairParameters& pair, const Sample& s, const Eigen::MatrixXd* basis,
                                              PeriodRecorder* rec, bool track);
  template <bool kWithDerivative>
  std::array<double, 2> coupled_exact_linear(const PairParameters& pair, const Sample& s, const Eigen::MatrixXd* basis,
                                             PeriodRecorder* rec, bool track);
  template <bool kWithDerivative>
  std::array<double, 2> uncoupled(const PairParameters& pair, const Sample& s, const Eigen::MatrixXd* basis,
                                  PeriodRecorder* rec);
  /// Separation (or no friction): T = 0, the damper follows the motion.
  template <bool kWithDerivative>
  void separate(const Sample& s, const Eigen::MatrixXd* basis, PeriodRecorder* rec, bool track);
  /// Both directions of the coupled model stick at sample l.
  template <bool kWithDerivative>
  void record_coupled_stick(int l, PeriodRecorder* rec, bool track);
  /// A coupled slip sample whose map on d_start is md (D_ <- md).
  template <bool kWithDerivative>
  void track_coupled_slip(const Eigen::Matrix2d& md, double kt);

  LawOptions options_;
  // sample_steps(): the linearized recursion of each sample of the replayed period, else null.
  std::vector<SampleStep>* steps_ = nullptr;
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

}  // namespace shroudsim::contact
