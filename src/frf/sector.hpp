#pragma once
// The FE sector as the harmonic balance sees it (docs/physics.md sections 2 and 3): modal
// receptances of harmonic index h_n = n m mod Nb between the shroud contact pairs, the
// excitation and the response node, with optional residual flexibility, and the exact
// static flexibility for n = 0.
//
// For each harmonic n, the rows C_n = [B_n; D; E] (c contact rows, 3 response rows, one
// excitation row E = f_ext^T at the excitation node) are mapped to the reduced DOFs of
// h_n by T_h, and Q_n(W) = C_n R_h(W) C_n^H gives G_n, w_lin,n, H_n and u_lin,n as blocks:
//   R_h(W) = sum_r phi_r phi_r^H / (w_r^2 - W^2 + 2 i z w_r W)
//            + [residual] T_h K_h^-1 T_h^H - sum_r phi_r phi_r^H / w_r^2        (n >= 1)
//   R_0    = T_0 K_0^-1 T_0^T                                                 (n = 0)
// Contact pair i joins high node q (shroud_high of sector k) and the low node p' of
// sector k+1, p' = R p with p the matched shroud_low node of the reference sector:
//   W_n,i = L_i (U_q,n - exp(i h_n alpha) R U_p,n),   L_i = [t1; t2; n] (rows),
// or, for a contact patch, the weighted sum of that over the patch's node pairs.
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <complex>
#include <cstddef>
#include <functional>
#include <map>
#include <vector>

#include "cyclic/cyclic_sector.hpp"
#include "frf/linear_part.hpp"
#include "modal/eigensolver.hpp"

namespace shroudsim::frf {

/// One node pair of a contact patch and its weight (frf/contact_patches.hpp).
struct PatchNode {
  int high_node = -1, low_node = -1;
  double weight = 0.0;  ///< a_i / A_P
};

struct SectorContactPair {
  int high_node = -1;                                   ///< q: shroud_high node of the reference sector
  int low_node = -1;                                    ///< p: its matched shroud_low node (x_q = R x_p)
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();  ///< rows t1, t2, n (n outward of shroud_high)
  /// Empty: the element acts on the node pair (high_node, low_node). Otherwise on the
  /// weighted mean of these node pairs, W = L sum_i weight_i (U_q_i - exp(i h alpha) R U_p_i),
  /// and its force is spread over them with the same weights (the transpose).
  std::vector<PatchNode> patch;
};

struct SectorForcing {
  int engine_order = 1;  ///< m: harmonic n lives in h = n m mod Nb
  int excitation_node = -1;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();  ///< amplitude [N], global x y z (harmonic 1)
  int response_node = -1;
  double damping_ratio = 0.001;  ///< modal damping of every mode
  bool residual_flexibility = true;
};

/// The harmonic index h_n = n m mod Nb that temporal harmonic n of engine order m excites.
int harmonic_index(int n, int engine_order, int sectors);

/// The contact rows B_h (3 per pair, n_full columns) of harmonic index h: row 3i + a is
/// L_i(a, :) (u_q - exp(i h alpha) R u_p), summed with weights over a patch.
Eigen::SparseMatrix<std::complex<double>> contact_rows(const std::vector<SectorContactPair>& pairs,
                                                       const cyclic::CyclicSector& sector, int h, Eigen::Index n_full);

/// The largest memory SectorLinearPart keeps for its static solutions K_h^-1 C_h^H (see
/// static_solution()), n_reduced (3 pairs + 4) complex numbers per factored index: 1 GiB holds
/// them for 5 pairs up to ~700k reduced DOFs and for 139 pairs up to ~32k (5 factored indices).
/// On the 77k-DOF sector with 5 pairs they take 117 MB, and the run's peak resident memory fell
/// (3.73 to 3.68 GB) as the shapes no longer factor K_h again. Beyond the budget the shapes
/// factor again (sector_displacements) rather than the continuation hold gigabytes.
constexpr std::size_t kKeptSolutionBytes = std::size_t{1} << 30;

class SectorLinearPart : public LinearPart {
 public:
  /// bases: the modes of every h_n needed (n = 0..H); factor(h): K_h factorization.
  /// Precomputes, per harmonic index, the projections of the modes on C and the static
  /// (residual) flexibility blocks: after construction each harmonic costs O(k^2 modes).
  /// threads (0: all cores): the pairs of conjugate indices {h, Nb - h} are computed in
  /// parallel, each with one factor: factor must then be safe to call from several threads
  /// (it is called once per pair, for the first of its indices the model has, and once for
  /// index 0).
  SectorLinearPart(const cyclic::CyclicSector& sector, const std::map<int, modal::ModalBasis>& bases,
                   const std::function<modal::StiffnessFactor(int)>& factor, std::vector<SectorContactPair> pairs,
                   SectorForcing forcing, int n_harmonics, int threads = 1);

  int n_contact() const override { return 3 * static_cast<int>(pairs_.size()); }
  int n_response() const override { return 3; }
  void harmonic(int n, double w, HarmonicReceptance& out) const override;
  /// Exact: d/dw 1/(w_r^2 - W^2 + 2 i z w_r W) = n (2 W - 2 i z w_r) / (...)^2, W = n w; the
  /// residual and static flexibilities do not depend on the frequency.
  void harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const override;
  /// The response rows of Q_n only: O(3 c modes) against the O(c^2 modes) of harmonic().
  void response_harmonic(int n, double w, Eigen::MatrixXcd& H, Eigen::VectorXcd& u_lin) const override;
  /// F the residual flexibility's contact block (nullptr without residual flexibility), or
  /// for n = 0 the static flexibility with no modes; s_r = 1 / (w_r^2 - W^2 + 2 i z w_r W).
  bool factored_harmonic(int n, double w, bool derivative, FactoredReceptance& out) const override;
  void energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& excitation_work,
              double& viscous_dissipation) const override;
  std::string describe() const override;
  /// The modal frequencies of harmonic index h_1 (the engine order's).
  std::vector<double> resonances_hz() const override;
  /// Modal coordinates of h_n (mass-normalised modes): M = I, C = diag(2 z w_r),
  /// K = diag(w_r^2), P = the modes' contact rows, R = the residual flexibility's contact block
  /// (massless). n = 0: no modes, R = the static flexibility: the mean of a perturbation is
  /// taken quasi-statically, as the harmonic balance takes the mean of the motion.
  bool second_order_form(int n, SecondOrderForm& out) const override;
  /// The families p = 0..Nb/2 whose blocks k = -H..H, in harmonic index p + k m mod Nb, all have
  /// modes (index Nb - g is the conjugate of g; index 0 needs its modes here, not only the
  /// static flexibility): the modes given beyond the h_n decide which families are analysed.
  std::vector<int> perturbation_families() const override;
  /// Block k of family p: the modal form of harmonic index p + k m mod Nb; the modes above
  /// max_omega are moved to R with their receptance at s = i k w (docs/physics.md section 9).
  bool perturbation_form(int family, int k, double w, double max_omega, SecondOrderForm& out) const override;
  /// The same modal form with each mode's denominator w_r^2 - W^2 + i W (2 z w_r - zeta); N and
  /// e over the modes only (the residual part is massless; e is the modal part's projection
  /// of the excitation). n = 0: the static flexibility, no derivatives.
  bool damped_harmonic(int n, double w, double zeta, bool with_norm, DampedReceptance& out) const override;

  /// Harmonic index of temporal harmonic n.
  int harmonic_index(int n) const;

  /// What the construction cost, per group of harmonic indices sharing one K_h factor.
  struct IndexTimes {
    std::vector<int> indices;          ///< index 0 (static flexibility) or h and Nb - h
    double factor_seconds = 0.0;       ///< obtaining the factor (factor(h))
    double flexibility_seconds = 0.0;  ///< the static / residual flexibility solves and projections
  };
  const std::vector<IndexTimes>& build_times() const { return build_times_; }

  /// K_h^-1 C_h^H (n_reduced x (k + 4), C_h T_h as in the receptances: contact, response and
  /// excitation rows) of harmonic index h, kept from the construction's solves when all of them
  /// fit in kKeptSolutionBytes: the operating deflection shapes (sector_displacements) then
  /// need no new factorization. conjugated: the matrix returned is that of Nb - h (index h's
  /// is its complex conjugate). nullptr: not kept.
  const Eigen::MatrixXcd* static_solution(int h, bool& conjugated) const;

  struct IndexData {
    Eigen::VectorXd omega;  ///< modes kept [rad/s]
    Eigen::MatrixXcd psi;   ///< k x modes: C T_h phi
    Eigen::MatrixXcd flex;  ///< k x k: residual flexibility (n >= 1) or static flexibility (h used for n = 0)
  };
  /// What the construction computes from the K_h factors and the modes: all the receptances
  /// need (the receptance stage's cache entry, pipeline/forced_model.cpp).
  struct Precomputed {
    IndexData statics;                 ///< n = 0
    std::map<int, IndexData> dynamic;  ///< per harmonic index
    /// Every block has k x k flex and k x modes psi (k = 3 pairs + 4: contact, response and
    /// excitation rows); the static block may have no modes (and no psi).
    bool fits(Eigen::Index k) const;
  };
  Precomputed precomputed() const { return {static_, dynamic_}; }
  /// The same model with the modes kept only: no residual flexibility, and the static harmonic
  /// through index 0's modes (sum_r psi_r psi_r^H / w_r^2) instead of the exact K_0^-1: the
  /// linear model of a time integration in modal coordinates (forced/modal_wheel.hpp). Needs
  /// index 0's modes; throws std::invalid_argument without them.
  SectorLinearPart modes_only() const;
  /// The data of harmonic index g (0..Nb-1), stored as g or as its conjugate Nb - g (then
  /// `conjugate`: index g's is the complex conjugate of what is returned); nullptr when the
  /// model has no modes of g. Index 0's is the static block: its modes, and in flex the static
  /// flexibility.
  const IndexData* index_data(int g, bool& conjugate) const;
  int sectors() const { return sectors_; }
  const SectorForcing& forcing() const { return forcing_; }
  /// The model from an earlier construction's precomputed data (of the same sector, modes,
  /// pairs and forcing rows): the same receptances, bit for bit, without factorizing; no
  /// static solution is kept (static_solution() is nullptr: the shapes factorize).
  SectorLinearPart(Precomputed data, std::vector<SectorContactPair> pairs, SectorForcing forcing, int sectors,
                   int n_harmonics);
  /// The model for the force a times the one it was built with, given as `force`: the data is
  /// linear in the force (the excitation row of C_h), so the excitation row and column of every
  /// block's psi and flex (flex(k - 1, k - 1) by a^2) and the excitation column of the kept
  /// static solutions are multiplied by a, and `force` replaces the forcing's force.
  void scale_force(double a, const Eigen::Vector3d& force);

 private:
  /// Q_n(W) (k x k).
  Eigen::MatrixXcd receptance(int n, double w) const;
  /// The harmonic index of block k of perturbation family p: p + k m mod Nb.
  int family_block_index(int family, int k) const;

  std::vector<SectorContactPair> pairs_;
  SectorForcing forcing_;
  int sectors_ = 1, n_harmonics_ = 0;
  std::map<int, IndexData> dynamic_;  ///< per harmonic index of n >= 1
  IndexData static_;                  ///< n = 0 (h = 0): exact static flexibility in flex
  std::vector<IndexTimes> build_times_;
  std::map<int, Eigen::MatrixXcd> solutions_;  ///< static_solution(), by the index solved
};

/// The loads of one operating deflection shape: fundamental circular frequency w [rad/s] and
/// the complex contact force harmonics F_n (n = 0..H, 3 per pair in the pair's frame, F_0 about
/// the static state), as the harmonic balance solved them.
struct ShapeLoad {
  double w = 0.0;
  std::vector<Eigen::VectorXcd> forces;
  /// The autonomous motion of a nonlinear mode (forced/nonlinear_modes.hpp): no excitation and
  /// the artificial damping -zeta M, i.e. each mode's denominator w_r^2 - W^2 + i W (2 z w_r - zeta).
  bool excitation = true;
  double zeta = 0.0;  ///< [1/s]
};

/// The displacement harmonics U_n (n = 0..H) of every DOF of the sector (n_full, node-major
/// x y z, global frame) under the excitation (harmonic 1) and the contact forces of each load,
/// with the receptance SectorLinearPart uses: U_n = T_h R_h(n w) T_h^H C_h^H y_n,
/// y_n = (-F_n, 0, delta_n1) on the rows (contact, response, excitation), R_h the modal sum
/// with damping and, with forcing.residual_flexibility, the residual flexibility
/// K_h^-1 - sum_r phi_r phi_r^H / w_r^2; n = 0: the static flexibility K_0^-1 (docs/physics.md
/// section 3). The response and contact rows of U_n are the harmonic balance's response and
/// relative displacements. K_h^-1 is applied through `kept`'s static solutions where it has
/// them (SectorLinearPart::static_solution(), built from the same sector, pairs and forcing),
/// else through one factorization per pair of conjugate indices {h, Nb - h} for all loads,
/// the pairs in parallel on `threads` workers (0: all cores; factor must then be safe to call
/// from several threads). The result does not depend on the thread count.
std::vector<std::vector<Eigen::VectorXcd>> sector_displacements(
    const cyclic::CyclicSector& sector, const std::map<int, modal::ModalBasis>& bases,
    const std::function<modal::StiffnessFactor(int)>& factor, const std::vector<SectorContactPair>& pairs,
    const SectorForcing& forcing, const std::vector<ShapeLoad>& loads, const SectorLinearPart* kept = nullptr,
    int threads = 1);

}  // namespace shroudsim::frf
