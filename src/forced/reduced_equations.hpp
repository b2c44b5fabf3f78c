#pragma once
// The reduced harmonic balance equations on the contact relative displacements
// (PHYSICS.md section 3), in real arithmetic:
//     r(W, f) = W - W_lin(w) + G(w) F(W) = 0,      J = dr/dW = I + G(w) dF/dW,
// w = 2 pi f (f in Hz is the continuation parameter). W and F are in the ContactEvaluator
// layout (pairs one after the other, each [x | y | z] blocks of [c0 | c1 s1 | ... | cH sH]);
// G(w) is the real form of the complex receptances G_n(n w) of each harmonic: with
// U_n = c_n - i s_n, (A + iB) U_n maps (c, s) to (A c + B s, A s - B c).
// dF/dW is block diagonal over pairs, so J is formed as I + G D block column by block column.
#include <Eigen/Core>
#include <vector>

#include "continuation/arclength.hpp"
#include "frf/linear_part.hpp"
#include "hbm/contact_evaluator.hpp"

namespace shroudsim::forced {

/// Everything reported about one solution point.
struct PointResult {
  double frequency_hz = 0.0;
  double amplitude = 0.0;              ///< max_t |u_resp(t)| [m]
  double linear_amplitude = 0.0;       ///< the same without contact forces (free) [m]
  std::vector<double> harmonic_amplitudes;  ///< |U_n| [m], n = 0..H
  double excitation_work = 0.0;        ///< per period [J]
  double viscous_dissipation = 0.0;    ///< per period [J]
  double contact_dissipation = 0.0;    ///< per period [J]
  double energy_error = 0.0;           ///< |work - dissipation| / work (0 when work ~ 0)
  int unconverged_pairs = 0;
};

class ReducedEquations : public continuation::ParametricResidual {
 public:
  /// Not owned: linear and contacts outlive this object. contacts' pairs are the linear
  /// part's contact pairs in order (linear.n_contact() == 3 * contacts.n_pairs()).
  ReducedEquations(const frf::LinearPart& linear, hbm::ContactEvaluator& contacts);

  int size() const override { return contacts_.size(); }
  bool evaluate(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dr_dlambda) override;

  /// W_lin(w) in the evaluator layout (the contact motion without contact forces).
  Eigen::VectorXd linear_motion(double frequency_hz) const;
  /// The solution if every contact stayed stuck and closed (linear, springs kt, kt, kn and
  /// the preload): a good start for Newton.
  Eigen::VectorXd stuck_solution(double frequency_hz) const;

  /// Scales the excitation: r = W - s W_lin + G F(W) (s = 1 is the case itself).
  void set_excitation_scale(double s) { excitation_scale_ = s; }
  double excitation_scale() const { return excitation_scale_; }

  /// A solution at `frequency_hz` found by continuation in the excitation scale s from 0
  /// (preload only: the stuck solution is exact when the preload alone does not slip) to 1.
  /// Robust where Newton from a guess cycles between contact states. Returns the branch's
  /// status; on success w holds the solution at s = 1.
  continuation::Branch solve_by_excitation_homotopy(double frequency_hz, const continuation::ArclengthOptions& options,
                                                    Eigen::VectorXd& w);
  /// Response, harmonics and energy balance at a solution point.
  PointResult analyse(const Eigen::VectorXd& w, double frequency_hz, int time_points = 512);

  const hbm::HarmonicLayout& pair_layout() const { return contacts_.pair_layout(); }

 private:
  /// Real form of G(w) (size x size) and W_lin(w) (size).
  void assemble(double frequency_hz, Eigen::MatrixXd& g, Eigen::VectorXd* w_lin,
                std::vector<frf::HarmonicReceptance>* receptances = nullptr) const;
  /// Index of coefficient (pair, direction, harmonic, sine?) in the evaluator layout.
  int index(int pair, int direction, int harmonic, bool sine) const;
  /// Complex harmonic n of a vector in the evaluator layout, as a c-vector (3 per pair).
  Eigen::VectorXcd complex_harmonic(const Eigen::VectorXd& v, int n) const;

  const frf::LinearPart& linear_;
  hbm::ContactEvaluator& contacts_;
  int n_directions_;
  double excitation_scale_ = 1.0;
  Eigen::VectorXd f_;                       // scratch: contact forces
  std::vector<Eigen::MatrixXd> blocks_;     // scratch: dF_p/dW_p
};

}  // namespace shroudsim::forced
