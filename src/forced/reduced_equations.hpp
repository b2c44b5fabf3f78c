#pragma once
// The reduced harmonic balance equations on the contact relative displacements
// (docs/physics.md section 3), in real arithmetic:
//     r(W, f) = W - W_lin(w) + G(w) F(W) = 0,      J = dr/dW = I + G(w) dF/dW,
// w = 2 pi f (f in Hz is the continuation parameter). W and F are in the ContactEvaluator
// layout (pairs one after the other, each [x | y | z] blocks of [c0 | c1 s1 | ... | cH sH]);
// G(w) is the real form of the complex receptances G_n(n w) of each harmonic: with
// U_n = c_n - i s_n, (A + iB) U_n maps (c, s) to (A c + B s, A s - B c).
// dF/dW is block diagonal over pairs and G couples only coefficients of the same harmonic, so
// J = I + G D is formed per pair and per harmonic: G_n (real form, 2c x 2c) times the rows of
// harmonic n of the pair's block D_p, O(n^2) flops instead of the O(n^2 b) of a dense product
// (b = 3(2H+1) the pair block). The residual never forms the dense G.
//
// Linear solves (the continuation's (n+1) bordered Newton system). G has
// a low-rank modal part but its residual/static flexibility is full rank over the contact
// DOFs (c = 3 pairs per harmonic), so J - I has full rank and no exact low-rank shortcut
// exists: the structure exploited is that the Jacobian changes little from one Newton
// iteration and continuation step to the next. Below `krylov_min_size` unknowns the
// continuation receives the dense J and the augmented system is solved by a dense LU
// (solve_augmented). From krylov_min_size on the residual is matrix-free for the
// continuation (linearize, solve_bordered): the bordered system is solved by GMRES
// (linalg/gmres.hpp) whose products use the factors of the linearization,
// (I + G D) z = z + G (D z) per pair and per harmonic (O(n b + c^2 H) instead of the O(n^2)
// of a dense product), right-preconditioned by the single-precision LU factors of the dense
// bordered matrix of an earlier linearization (linalg/lagged_lu.hpp). J is formed densely
// only to renew those factors (when GMRES failed, or the preconditioner's counted renewal
// rule says so), never per evaluation, so the worst case is one dense LU per solve. The
// solution is checked by its true residual, ||A d - b|| <= krylov_tolerance ||b||, in
// double precision.
//
// The receptances: where the linear part has a factored form (the modal sector,
// frf::FactoredReceptance: G_n = F_n + Psi_n diag(s_n(w)) Psi_n^H, F_n the massless residual
// or static flexibility), a new frequency costs O(modes) per harmonic, products cost
// O(c^2 + c modes), and G_n is formed densely (O(c^2 modes)) only where a dense Jacobian is
// formed: to renew the preconditioner, or below krylov_min_size. dG_n/dw = Psi_n diag(ds_n)
// Psi_n^H is never formed.
//
// The residual also gives dr/df (f the frequency in Hz) from the linear part's exact
// frequency derivative (no extra contact evaluations), and repeats of an evaluation at the
// same (W, f) (the continuation evaluates the converged point twice) are served from a copy.
#include <Eigen/Core>
#include <vector>

#include "continuation/arclength.hpp"
#include "frf/linear_part.hpp"
#include "hbm/contact_evaluator.hpp"
#include "linalg/lagged_lu.hpp"

namespace shroudsim::forced {

/// Everything reported about one solution point.
struct PointResult {
  double frequency_hz = 0.0;
  double amplitude = 0.0;                   ///< max_t |u_resp(t)| [m]
  double linear_amplitude = 0.0;            ///< the same without contact forces (free) [m]
  std::vector<double> harmonic_amplitudes;  ///< |U_n| [m], n = 0..H
  double excitation_work = 0.0;             ///< per period [J]
  double viscous_dissipation = 0.0;         ///< per period [J]
  double contact_dissipation = 0.0;         ///< per period [J]
  double energy_error = 0.0;                ///< |work - dissipation| / work (0 when work ~ 0)
  int unconverged_pairs = 0;
};

/// How the augmented Newton systems are solved.
struct LinearSolverOptions {
  enum class Kind { dense, krylov, automatic };
  Kind kind = Kind::automatic;      ///< automatic: krylov from krylov_min_size unknowns on
  int krylov_min_size = 250;        ///< (n + 1) below which automatic uses the dense LU
  int krylov_max_iterations = 40;   ///< GMRES iterations before falling back to a new LU
  int refactor_after = 15;          ///< GMRES iterations above which the next solve refactors
                                    ///< (matrix-free solves: once the GMRES iterations since
                                    ///< the last factorization have also cost more flops)
  double krylov_tolerance = 1e-11;  ///< relative true residual ||A d - b|| / ||b||
};

/// Where the time goes (seconds of wall time, counts), accumulated over the object's life.
struct SolverStatistics {
  int evaluations = 0;              ///< residual evaluations that reached the contacts
  int jacobian_evaluations = 0;     ///< of those, with the Jacobian
  int repeated_evaluations = 0;     ///< served from the copy of the previous evaluation
  int dense_factorizations = 0;     ///< LU factorizations of an augmented matrix
  int krylov_solves = 0;            ///< solves done by preconditioned GMRES
  int krylov_iterations = 0;        ///< their GMRES iterations
  int krylov_failures = 0;          ///< GMRES solves that fell back to a new LU
  int double_solves = 0;            ///< bordered solves where the single-precision factors failed
  double contact_seconds = 0.0;     ///< ContactEvaluator::evaluate
  double receptance_seconds = 0.0;  ///< G_n, W_lin,n and their frequency derivatives
  double jacobian_seconds = 0.0;    ///< forming I + G D
  double solve_seconds = 0.0;       ///< solve_augmented and solve_bordered

  /// Adds another's counts and times (work split between equations, e.g. a peak's location).
  SolverStatistics& operator+=(const SolverStatistics& o) {
    evaluations += o.evaluations;
    jacobian_evaluations += o.jacobian_evaluations;
    repeated_evaluations += o.repeated_evaluations;
    dense_factorizations += o.dense_factorizations;
    krylov_solves += o.krylov_solves;
    krylov_iterations += o.krylov_iterations;
    krylov_failures += o.krylov_failures;
    double_solves += o.double_solves;
    contact_seconds += o.contact_seconds;
    receptance_seconds += o.receptance_seconds;
    jacobian_seconds += o.jacobian_seconds;
    solve_seconds += o.solve_seconds;
    return *this;
  }
};

class ReducedEquations : public continuation::ParametricResidual {
 public:
  /// Not owned: linear and contacts outlive this object. contacts' pairs are the linear
  /// part's contact pairs in order (linear.n_contact() == 3 * contacts.n_pairs()).
  ReducedEquations(const frf::LinearPart& linear, hbm::ContactEvaluator& contacts);

  int size() const override { return contacts_.size(); }
  bool evaluate(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dr_dlambda) override;
  /// dr/df [m/Hz] = 2 pi (dG/dw F - s dW_lin/dw), exact from the linear part.
  bool has_lambda_derivative() const override { return true; }
  bool solve_augmented(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) override;
  /// Matrix-free when the Krylov solver is used (krylov, or automatic from krylov_min_size):
  /// the continuation then never receives the dense J.
  bool matrix_free() const override;
  bool linearize(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r,
                 Eigen::VectorXd* dr_dlambda) override;
  /// GMRES with the structured product, preconditioned by the LU factors of the dense
  /// bordered matrix of an earlier linearization (formed and factorized only when GMRES
  /// needed more than refactor_after iterations or failed).
  bool solve_bordered(const continuation::BorderedMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& d) override;

  void set_linear_solver(const LinearSolverOptions& options) {
    solver_ = options;
    preconditioner_.invalidate();
  }
  const LinearSolverOptions& linear_solver() const { return solver_; }
  const SolverStatistics& statistics() const { return stats_; }
  /// Adds another object's statistics (equations of the same model that solved part of the
  /// work, e.g. a peak's location) to these.
  void add_statistics(const SolverStatistics& s) { stats_ += s; }
  /// The Jacobian I + G(f) D formed densely the plain way (G as a dense n x n real matrix times
  /// the block-diagonal D): the reference the structured product is tested against.
  Eigen::MatrixXd dense_jacobian(double frequency_hz, const std::vector<Eigen::MatrixXd>& blocks) const;
  /// Forms J = I + G(f) D from given per-pair blocks D_p (the structured product).
  void jacobian(double frequency_hz, const std::vector<Eigen::MatrixXd>& blocks, Eigen::MatrixXd& J);
  /// The same from the complex G_n of every harmonic.
  void jacobian_from(const std::vector<Eigen::MatrixXcd>& g_n, const std::vector<Eigen::MatrixXd>& blocks,
                     Eigen::MatrixXd& J);

  /// W_lin(w) in the evaluator layout (the contact motion without contact forces).
  Eigen::VectorXd linear_motion(double frequency_hz) const;
  /// The solution if every contact stayed stuck and closed (linear, springs kt, kt, kn and
  /// the preload): a good start for Newton.
  Eigen::VectorXd stuck_solution(double frequency_hz) const;

  /// Scales the excitation: r = W - s W_lin + G F(W) (s = 1 is the case itself; the
  /// continuation in s is forced/excitation_homotopy.hpp).
  void set_excitation_scale(double s) { excitation_scale_ = s; }
  double excitation_scale() const { return excitation_scale_; }

  /// Response, harmonics and energy balance at a solution point.
  PointResult analyse(const Eigen::VectorXd& w, double frequency_hz, int time_points = 512);
  /// The complex contact force harmonics F_n (n = 0..H, each of size c) of the solution w, as
  /// the linear part receives them: F_0 less the static contact load (see analyse).
  std::vector<Eigen::VectorXcd> contact_force_harmonics(const Eigen::VectorXd& w);

  const hbm::HarmonicLayout& pair_layout() const { return contacts_.pair_layout(); }
  hbm::ContactEvaluator& contacts() { return contacts_; }
  int n_pairs() const { return contacts_.n_pairs(); }
  const frf::LinearPart& linear_part() const { return linear_; }
  /// dF_p/dW_p of every pair at w (the contact Jacobian blocks of evaluate(), pair layout);
  /// throws NumericalError when they are not finite.
  std::vector<Eigen::MatrixXd> contact_jacobian(const Eigen::VectorXd& w);

 private:
  /// The complex matrices M_n (c x c) of every harmonic, n = 0..H: dense, or in the linear
  /// part's factored form F_n + Psi_n diag(s_n) Psi_n^H (frf::FactoredReceptance), which is
  /// multiplied without forming M_n and formed densely only where a dense Jacobian is needed.
  struct HarmonicMatrices {
    std::vector<Eigen::MatrixXcd> dense;           ///< when not factored
    std::vector<frf::FactoredReceptance> factors;  ///< when factored (s the modal factors)
    bool factored = false;
  };
  /// G_n and W_lin,n of every harmonic at one frequency (and, when asked, their derivatives
  /// d/dw: dG_n = Psi_n diag(ds_n) Psi_n^H in factored form), kept until the frequency changes.
  struct Harmonics {
    double frequency_hz = -1.0;
    bool derivative = false;
    HarmonicMatrices g, dg;
    std::vector<Eigen::MatrixXcd> g_dense;  ///< G_n formed from a factored g, on demand
    std::vector<Eigen::VectorXcd> w_lin, dw_lin;
    Eigen::VectorXcd w_static;  ///< G_0 F_s: the static state's relative displacement (c)
  };
  const Harmonics& harmonics(double frequency_hz, bool derivative);
  /// The dense G_n of harmonics(frequency_hz) (formed once per frequency when factored).
  const std::vector<Eigen::MatrixXcd>& dense_receptances(double frequency_hz);
  /// M_n densely.
  std::vector<Eigen::MatrixXcd> dense(const HarmonicMatrices& m) const;
  /// M_n z (c-vector).
  Eigen::VectorXcd times(const HarmonicMatrices& m, int n, const Eigen::VectorXcd& z) const;
  /// F_s (c, real): the contact forces of the static state the model is written about, the
  /// normal max(0, N0) of every pair with PairParameters::preload_in_equilibrium, else 0.
  Eigen::VectorXcd static_contact_load() const;
  /// Real form of G(w) (size x size) and W_lin(w) (size).
  void assemble(double frequency_hz, Eigen::MatrixXd& g, Eigen::VectorXd* w_lin,
                std::vector<frf::HarmonicReceptance>* receptances = nullptr) const;
  /// Index of coefficient (pair, direction, harmonic, sine?) in the evaluator layout.
  int index(int pair, int direction, int harmonic, bool sine) const;
  /// Complex harmonic n of a vector in the evaluator layout, as a c-vector (3 per pair).
  Eigen::VectorXcd complex_harmonic(const Eigen::VectorXd& v, int n) const;
  /// out += the evaluator-layout vector whose harmonic n is z (c-vector).
  void add_harmonic(const Eigen::VectorXcd& z, int n, Eigen::VectorXd& out) const;
  /// out = sum_n M_n v_n (M = g or dg of h): a block-diagonal-over-harmonics product.
  void apply(const HarmonicMatrices& m, const Eigen::VectorXd& v, Eigen::VectorXd& out) const;
  bool evaluate_impl(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                     Eigen::VectorXd* dr_dlambda, bool linearize);
  /// y = (I + G D) z with the G_n and D_p of the last Jacobian evaluation: O(n b + c^2 H).
  void apply_jacobian(const Eigen::VectorXd& z, Eigen::VectorXd& y) const;

  const frf::LinearPart& linear_;
  hbm::ContactEvaluator& contacts_;
  int n_directions_;
  double excitation_scale_ = 1.0;
  Eigen::VectorXd f_;                    // scratch: contact forces
  std::vector<Eigen::MatrixXd> blocks_;  // scratch: dF_p/dW_p
  Harmonics harmonics_;
  LinearSolverOptions solver_;
  SolverStatistics stats_;
  // The previous evaluation, for repeats at the same point.
  struct Previous {
    bool valid = false, has_jacobian = false, has_derivative = false, linearized = false;
    double frequency_hz = 0.0, scale = 0.0;
    Eigen::VectorXd w, r, dl;
    Eigen::MatrixXd J;
  } previous_;
  // The factors of the last Jacobian evaluation, for products with J without the dense J.
  HarmonicMatrices jac_g_;
  std::vector<Eigen::MatrixXd> jac_blocks_;
  bool jac_valid_ = false;
  // Lagged preconditioner: single-precision LU factors of an earlier bordered matrix.
  linalg::LaggedLuPreconditioner preconditioner_;
};

}  // namespace shroudsim::forced
