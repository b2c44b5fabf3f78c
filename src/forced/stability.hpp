#pragma once
// Local stability of a periodic solution of the reduced harmonic balance equations by Hill's
// method (docs/physics.md section 9).
//
// A perturbation of the contact motion e^{lambda t} p(t), p of period T = 2 pi / w, is written
// in complex exponentials p = sum_k P_k e^{i k w t}, k = -H..H. The contact forces respond
// through the contact Jacobian of the harmonic balance, D = dF/dW (the AFT linearization,
// moved from cosine/sine to exponential coefficients), and the linear part through its
// second-order form (frf::SecondOrderForm) at s_k = lambda + i k w:
//   (s_k^2 M_k + s_k C_k + K_k) q_k = -P_k^H F_k,    W_k = P_k q_k - R_k F_k,    F = D W.
// The massless part R (residual flexibility of the modes left out, the static flexibility of
// the mean) is condensed into the contact as quasi-static: W = (I + R D)^-1 P q, so
// F = E P q with E = D (I + R D)^-1. With mu = lambda / w (dimensionless, so the problem and
// its tolerances do not depend on the unit of time) this is the quadratic eigenproblem
//   (mu^2 A2 + mu A1 + A0) q = 0,   A2 = M_k,  A1 = (C_k + 2 i k w M_k) / w,
//   A0 = (K_k + i k w C_k - k^2 w^2 M_k + P_k^H [E P q]_k) / w^2   (blocks over k),
// solved as a linear eigenproblem of twice the size (companion form). Its 2 m (2H + 1)
// eigenvalues hold each Floquet exponent 2H + 1 times, shifted by i k w, when D is
// block-Toeplitz (a memoryless law: the gap, a cubic spring); the truncation spoils the copies
// whose eigenvectors crowd the outer harmonics. The friction slider's memory makes D depend on
// more than k - l (its stick runs' anchors), and the copies are no longer exact; D also takes
// each step of that memory at the period's rate, which ContactMemory (the slider as a state)
// corrects. Selection:
//   symmetry  (default) the exponents whose eigenvector's harmonic centroid
//             sum_k k q_k^H M_k q_k / sum_k q_k^H M_k q_k (mass-weighted: the same in any
//             coordinates) lies within 0.6 harmonics of 0 (a period-doubling exponent's two
//             copies sit near +-0.5);
//   imaginary the 2 m exponents nearest the real axis (m = size of the k = 0 block), to compare.
// FE sector (frf::SectorLinearPart): a perturbation of the travelling-wave solution splits into
// families p = 0..Nb - 1: block k of family p holds the modes of harmonic index p + k m mod Nb
// (the contact Jacobian couples harmonic k to k + j in index + j m, as the solution's own
// harmonics). Family p's exponents have no copies within the family: the copy shifted by i w
// lives in family p + m. So every family p = 0..Nb/2 is solved (Nb - p is its conjugate) and
// each keeps the exponents centred on its block 0 (the symmetry selection): each exponent is
// judged once, in the family of the index it lives in. Modal forms keep the modes up to
// kModeCutoff (H + 1) w; the others, with the residual flexibility, form the massless R,
// with their receptance at s = i k w (the problem stays exact at lambda = 0, where a fold's
// exponent crosses).
// The point is unstable when the largest real part of the selected exponents exceeds
// kNeutralTolerance w. Floquet multipliers are exp(lambda T).
#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "contact/contact_law.hpp"
#include "contact/periodic_law.hpp"
#include "forced/reduced_equations.hpp"

namespace shroudsim::forced {

/// Largest Re(lambda) / w still counted as stable: the round-off of the companion eigenvalues
/// (~1e-16 times the square of the highest modal frequency over w's) stays well below it, and
/// the slowest decay of a model with 1e-6 modal damping (-1e-6) well above it.
constexpr double kNeutralTolerance = 1e-9;

/// The largest companion eigenproblem solved per point (dense, O(size^3)): about 0.4 s per
/// point at 400 on this project's 2-core machines; larger problems are not analysed (the
/// result says why) rather than multiplying the forced response's time.
constexpr int kMaxHillSize = 400;

/// Modes of a modal form above kModeCutoff (H + 1) w leave the Hill problem for the massless
/// part, each with its receptance at the block's harmonic: they cover the sum and difference
/// combinations w_i +- w_j = k w (|k| <= H) of the modes below (H + 1) w, and the cost falls with
/// the cube of the kept modes (docs/physics.md section 9).
constexpr double kModeCutoff = 2.0;

/// The largest contact condensation E = D (I + R D)^-1 (3 pairs x (2H + 1) wide, complex LU per
/// family and point); larger problems are not analysed.
constexpr int kMaxCondensedSize = 600;

/// The largest eigenproblem with the slider as a state (companion plus one unknown per
/// tangential direction and time sample of every pair; dense, O(size^3)); larger problems are
/// not analysed.
constexpr int kMaxSliderStateSize = 1200;

/// The damper positions (slider-state unknowns) the automatic memory sampling allows
/// (memory_samples): kMaxSliderStateSize less room for the companion's unknowns (the default
/// sector's families have 2 s = 154 at 80 Hz to 330 at 220 Hz, its modes below 2 (H + 1) w).
constexpr int kMaxMemoryUnknowns = 800;

/// The time samples of the slider state (response.stability_samples): `requested` (0: automatic)
/// at least 2H + 1 and at most the harmonic balance's N; automatic: N where N x dampers (pairs x
/// tangential directions) fits within kMaxMemoryUnknowns, else the most that fit, at least
/// 2H + 1. docs/physics.md section 9, "Memory samples".
int memory_samples(int requested, int time_samples, int harmonics, int dampers);

/// The friction law's memory at a solution, for Hill's method with the slider as a state
/// (docs/physics.md section 9, "Friction: the slider as a state"): each pair's samples'
/// recursion d(l) = a d(l-1) + b u(l) + c u(l-1) (contact::SampleStep). A perturbation
/// e^{lambda t} p(t) weighs each step by e^{-lambda dt}, dt = T / N, which the harmonic balance's
/// dF/dW takes as 1; here it is the Cayley form (1 - lambda dt / 2) / (1 + lambda dt / 2)
/// (error (lambda dt)^3 / 12 per step), so the eigenproblem stays linear in lambda, with the
/// damper positions of every sample as unknowns. At lambda = 0 it is dF/dW exactly.
struct ContactMemory {
  contact::Model model = contact::Model::full3d;
  std::vector<contact::PairParameters> pairs;
  std::vector<std::vector<contact::SampleStep>> steps;  ///< per pair, the memory's samples
  /// Where the memory is sampled more coarsely than the harmonic balance (contact_memory's
  /// `samples`): per pair (pair_layout order), the harmonic balance's dF/dW minus that of the
  /// coarse samples' periodic law. It joins the memoryless part of the pencil, so that at
  /// lambda = 0 the pencil is still the harmonic balance's own linearization (a fold's exponent
  /// crosses zero where the traced curve folds). Empty at the harmonic balance's N.
  std::vector<Eigen::MatrixXd> correction;
  /// A sample whose damper depends on the sample before (a stick run, a coupled slip, the
  /// motion's previous sample in an exact_linear step): without any, the law is memoryless
  /// and the harmonic balance's dF/dW is exact.
  bool carries_memory() const;
};
/// The memory of the contacts of `equations` at w, sampled at the harmonic balance's N or, with
/// 0 < samples < N, at `samples` points of the period (the law replayed on the same harmonics,
/// docs/physics.md section 9, "Memory samples"): the pencil then has samples instead of N damper
/// positions per pair and tangential direction. `jacobian`: the harmonic balance's dF/dW blocks
/// at w (ReducedEquations::contact_jacobian), needed for the correction when samples < N.
ContactMemory contact_memory(ReducedEquations& equations, const Eigen::VectorXd& w, int samples = 0,
                             const std::vector<Eigen::MatrixXd>* jacobian = nullptr);

enum class ExponentSelection { symmetry, imaginary };

struct FloquetResult {
  bool available = false;  ///< false: no second-order form, or the problem exceeds max_size
  std::string reason;      ///< why not available
  bool stable = true;
  /// The selected Floquet exponents lambda [1/s], by decreasing real part.
  std::vector<std::complex<double>> exponents;
  double max_real = 0.0;  ///< Re of the first one [1/s]
  /// The perturbation family of each exponent (an FE sector: the harmonic index p = 0..Nb/2 of
  /// its block 0, standing also for Nb - p with the conjugate exponent; lumped: 0).
  std::vector<int> exponent_family;
  std::vector<int> families;  ///< the families analysed
  int hill_size = 0;          ///< dimension of the largest companion eigenproblem
  ExponentSelection selection = ExponentSelection::symmetry;
  /// The largest Floquet multiplier modulus, exp(max_real T).
  double spectral_radius(double frequency_hz) const;
};

/// The Floquet exponents of the solution w of `equations` at frequency f [Hz], over the
/// perturbation families the linear part holds (frf::LinearPart::perturbation_families); a
/// modal form keeps its modes up to mode_cutoff (H + 1) w (0: every mode).
/// memory: the contact with the slider as a state (ContactMemory), else the harmonic
/// balance's dF/dW.
FloquetResult floquet_exponents(ReducedEquations& equations, const Eigen::VectorXd& w, double frequency_hz,
                                ExponentSelection selection = ExponentSelection::symmetry, int max_size = kMaxHillSize,
                                double mode_cutoff = kModeCutoff, const ContactMemory* memory = nullptr);
/// The same from the contact Jacobian's blocks at the solution (ReducedEquations::contact_jacobian,
/// one dF_p/dW_p per pair in `layout`): it touches no state of the equations, so several points
/// can be analysed at once.
FloquetResult floquet_exponents(const frf::LinearPart& linear, const hbm::HarmonicLayout& layout,
                                const std::vector<Eigen::MatrixXd>& jacobian, double frequency_hz,
                                ExponentSelection selection = ExponentSelection::symmetry, int max_size = kMaxHillSize,
                                double mode_cutoff = kModeCutoff, const ContactMemory* memory = nullptr);

/// Where the stability changes between two neighbouring points of a branch.
struct StabilityChange {
  enum class Kind { fold, period_doubling, neimark_sacker, unresolved };
  Kind kind = Kind::fold;
  std::size_t point = 0;  ///< the change lies between point and the next judged point of its piece
  double frequency_hz = 0.0, amplitude_m = 0.0;  ///< linear interpolation where max_real crosses 0
};
std::string to_string(StabilityChange::Kind kind);

/// The changes of stability along consecutive points of one piece: the critical exponent's
/// imaginary part names the kind (0: a real exponent crosses, a fold or a branch point; w / 2:
/// period doubling; otherwise a complex pair, Neimark-Sacker). frequency_hz and amplitude_m are
/// the points'; stability the points' results; piece the piece of each point (no change is
/// looked for across pieces).
std::vector<StabilityChange> stability_changes(const std::vector<FloquetResult>& stability,
                                               const std::vector<double>& frequency_hz,
                                               const std::vector<double>& amplitude_m, const std::vector<int>& piece);

}  // namespace shroudsim::forced
