#include "frf/sector.hpp"

#include <Eigen/SparseCore>
#include <algorithm>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/log.hpp"
#include "linalg/parallel.hpp"

namespace shroudsim::frf {
namespace {
/// A mode's receptance denominator w_r^2 - W^2 + 2 i z w_r W at circular frequency W.
std::complex<double> modal_denominator(double omega_r, double big_w, double z) {
  return std::complex<double>(omega_r * omega_r - big_w * big_w, 2.0 * z * omega_r * big_w);
}

/// A <- (A + A^H) / 2: exactly Hermitian (C K^-1 C^H is, but its computed form only to
/// round-off), so that a product may read one triangle (FactoredReceptance).
void make_hermitian(Eigen::MatrixXcd& a) {
  const Eigen::MatrixXcd h = 0.5 * (a + a.adjoint());
  a = h;
}

using Complex = std::complex<double>;

void add_contact_rows(std::vector<Eigen::Triplet<Complex>>& t, const std::vector<SectorContactPair>& pairs,
                      const cyclic::CyclicSector& sector, int h) {
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const int row = 3 * static_cast<int>(i);
    if (pairs[i].patch.empty()) {
      sector.add_relative_rows(t, row, pairs[i].frame, pairs[i].high_node, pairs[i].low_node, 1.0, h);
    } else {
      for (const PatchNode& m : pairs[i].patch)
        sector.add_relative_rows(t, row, pairs[i].frame, m.high_node, m.low_node, m.weight, h);
    }
  }
}

/// C_h = [B; D; E] (k x n_full) for harmonic index h.
Eigen::SparseMatrix<Complex> selection(const std::vector<SectorContactPair>& pairs, const SectorForcing& f,
                                       const cyclic::CyclicSector& sector, int h, Eigen::Index n_full) {
  std::vector<Eigen::Triplet<Complex>> t;
  add_contact_rows(t, pairs, sector, h);
  const int c = 3 * static_cast<int>(pairs.size());
  for (int a = 0; a < 3; ++a) t.emplace_back(c + a, 3 * f.response_node + a, 1.0);
  for (int a = 0; a < 3; ++a) t.emplace_back(c + 3, 3 * f.excitation_node + a, f.force[a]);
  Eigen::SparseMatrix<Complex> m(c + 4, n_full);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

}  // namespace

Eigen::SparseMatrix<Complex> contact_rows(const std::vector<SectorContactPair>& pairs,
                                          const cyclic::CyclicSector& sector, int h, Eigen::Index n_full) {
  std::vector<Eigen::Triplet<Complex>> t;
  add_contact_rows(t, pairs, sector, h);
  Eigen::SparseMatrix<Complex> m(3 * static_cast<Eigen::Index>(pairs.size()), n_full);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

int harmonic_index(int n, int engine_order, int sectors) { return ((n * engine_order) % sectors + sectors) % sectors; }

int SectorLinearPart::harmonic_index(int n) const { return frf::harmonic_index(n, forcing_.engine_order, sectors_); }

SectorLinearPart::SectorLinearPart(const cyclic::CyclicSector& sector, const std::map<int, modal::ModalBasis>& bases,
                                   const std::function<modal::StiffnessFactor(int)>& factor,
                                   std::vector<SectorContactPair> pairs, SectorForcing forcing, int n_harmonics,
                                   int threads)
    : pairs_(std::move(pairs)), forcing_(forcing), sectors_(sector.sectors()), n_harmonics_(n_harmonics) {
  SHROUDSIM_CHECK(forcing_.excitation_node >= 0 && forcing_.response_node >= 0, "excitation and response nodes set");
  std::set<int> needed;
  for (int n = 1; n <= n_harmonics_; ++n) needed.insert(harmonic_index(n));
  // Static flexibility of the static harmonic (h = 0) and of each dynamic index's residual:
  // C_h K_h^-1 C_h^H, solved for kFlexibilityBlock columns of C_h^H at a time. C_h (k x n) is
  // sparse (each row touches two nodes); all its k columns as one dense right-hand side
  // would be n x k complex, 2.6 GB on a 238k-DOF sector with 227 pairs (and CHOLMOD copies
  // it twice more), where a block of 64 columns is 0.24 GB.
  constexpr Eigen::Index kFlexibilityBlock = 64;
  // keep (not null): K_h^-1 C_h^H itself, the solutions the shapes reuse (static_solution()).
  auto static_flexibility = [&](const modal::StiffnessFactor& k, const Eigen::SparseMatrix<Complex>& ct,
                                Eigen::MatrixXcd* keep) {
    const Eigen::SparseMatrix<Complex> cth = ct.adjoint();
    Eigen::MatrixXcd flex(ct.rows(), ct.rows());
    if (keep) keep->resize(cth.rows(), cth.cols());
    for (Eigen::Index j0 = 0; j0 < cth.cols(); j0 += kFlexibilityBlock) {
      const Eigen::Index nb = std::min(kFlexibilityBlock, cth.cols() - j0);
      const Eigen::MatrixXcd y = k.solve(Eigen::MatrixXcd(cth.middleCols(j0, nb)));
      flex.middleCols(j0, nb).noalias() = ct * y;
      if (keep) keep->middleCols(j0, nb) = y;
    }
    return flex;
  };
  // C_h T_h (k x n_reduced): the rows of the contact, response and excitation DOFs in the
  // reduced coordinates of harmonic index h, kept sparse.
  auto projected = [&](int h) {
    const Eigen::SparseMatrix<Complex> c = selection(pairs_, forcing_, sector, h, sector.n_full());
    const Eigen::SparseMatrix<Complex> t = sector.expansion(h);
    return Eigen::SparseMatrix<Complex>(c * t);
  };
  // Every index with modes: the harmonic balance's h_n, then the further indices the Floquet
  // analysis's perturbation families need (perturbation_form).
  std::vector<int> indices(needed.begin(), needed.end());
  for (const auto& [h, b] : bases)
    if (needed.count(h) == 0) indices.push_back(h);
  for (int h : indices) SHROUDSIM_CHECK(bases.count(h) == 1, "modes of harmonic index " + std::to_string(h) + " given");
  // The work per index is one factorization of K_h and c + 4 solves with it. Index Nb - h is
  // the complex conjugate of index h (K, C and the modes conjugated: the modal stage gives
  // the modes of Nb - h as those of h conjugated), so its data is that of h conjugated, and
  // the groups {h, Nb - h} (with index 0, whose static flexibility is always needed, in
  // group 0) run in parallel, one factor each: the complex ones first, as they cost about
  // twice the real ones (0 and Nb / 2). Each index's data is computed by the same operations
  // whatever the thread count.
  std::map<int, std::vector<int>> groups;  // canonical min(h, Nb - h) -> its indices
  groups[0];
  for (int h : indices) groups[std::min(h, (sectors_ - h) % sectors_)].push_back(h);
  std::vector<std::pair<int, std::vector<int>>> jobs(groups.begin(), groups.end());
  const auto is_real_index = [&](int canonical) { return canonical == 0 || 2 * canonical == sectors_; };
  std::stable_sort(jobs.begin(), jobs.end(),
                   [&](const auto& a, const auto& b) { return !is_real_index(a.first) && is_real_index(b.first); });
  std::vector<std::vector<IndexData>> results(jobs.size());
  std::vector<IndexTimes> times(jobs.size());
  // The static solutions are kept when all of them fit in kKeptSolutionBytes: one per group
  // that factors (index 0, and with residual flexibility the first index of each group).
  std::size_t solved = 0;
  for (const auto& job : jobs) solved += job.first == 0 || forcing_.residual_flexibility ? 1 : 0;
  const double kept_bytes = static_cast<double>(solved) * static_cast<double>(sector.n_reduced()) *
                            static_cast<double>(n_contact() + 4) * static_cast<double>(sizeof(Complex));
  const bool keep_solutions = kept_bytes <= static_cast<double>(kKeptSolutionBytes);
  std::vector<std::pair<int, Eigen::MatrixXcd>> kept(jobs.size(), {-1, Eigen::MatrixXcd()});
  IndexData static_data;
  // full: the static flexibility C_h K_h^-1 C_h^H (null: no residual flexibility).
  auto index_data = [&](int h, const Eigen::SparseMatrix<Complex>& ct, const Eigen::MatrixXcd* full) {
    const modal::ModalBasis& b = bases.at(h);
    IndexData d;
    d.omega = b.omega;
    d.psi = ct * b.phi;
    if (full) {
      d.flex = *full;
      for (Eigen::Index r = 0; r < d.omega.size(); ++r)
        d.flex -= d.psi.col(r) * d.psi.col(r).adjoint() / (d.omega[r] * d.omega[r]);
      make_hermitian(d.flex);
    } else {
      d.flex = Eigen::MatrixXcd::Zero(ct.rows(), ct.rows());
    }
    return d;
  };
  linalg::parallel_for(
      static_cast<int>(jobs.size()), linalg::worker_count(threads, static_cast<int>(jobs.size())), [&](int j) {
        const auto& [canonical, members] = jobs[static_cast<std::size_t>(j)];
        // The factor of the group's first index (index 0 for the static group).
        const int first = canonical == 0 ? 0 : members.front();
        const bool need_factor = canonical == 0 || forcing_.residual_flexibility;
        log::Stopwatch clock;
        const modal::StiffnessFactor k_first = need_factor ? factor(first) : modal::StiffnessFactor();
        IndexTimes& t = times[static_cast<std::size_t>(j)];
        t.indices = members;
        if (canonical == 0 && (members.empty() || members.front() != 0)) t.indices.insert(t.indices.begin(), 0);
        t.factor_seconds = clock.seconds();
        clock.restart();
        std::vector<IndexData>& out = results[static_cast<std::size_t>(j)];
        auto& [solved_index, solution] = kept[static_cast<std::size_t>(j)];
        Eigen::MatrixXcd* keep = keep_solutions && need_factor ? &solution : nullptr;
        if (keep) solved_index = first;
        // Index 0's static flexibility, when index 0 is also dynamic: one solve
        // for both.
        std::optional<Eigen::MatrixXcd> flex_of_first;
        for (int h : members) {
          if (h != members.front()) {  // Nb - h: the data of h conjugated
            IndexData d;
            d.omega = out.front().omega;
            d.psi = out.front().psi.conjugate();
            d.flex = out.front().flex.conjugate();
            out.push_back(std::move(d));
            continue;
          }
          const Eigen::SparseMatrix<Complex> ct = projected(h);
          if (forcing_.residual_flexibility) flex_of_first = static_flexibility(k_first, ct, keep);
          out.push_back(index_data(h, ct, flex_of_first ? &*flex_of_first : nullptr));
        }
        if (canonical == 0) {
          const Eigen::SparseMatrix<Complex> ct = projected(0);
          static_data.flex = flex_of_first && first == members.front() ? std::move(*flex_of_first)
                                                                       : static_flexibility(k_first, ct, keep);
          make_hermitian(static_data.flex);
          // With the modes of index 0 at hand, harmonic 0's second-order form
          // is dynamic (the Floquet analysis: a perturbation's mean oscillates
          // at lambda, not at 0).
          if (auto it = bases.find(0); it != bases.end()) {
            static_data.omega = it->second.omega;
            static_data.psi = ct * it->second.phi;
          }
        }
        t.flexibility_seconds = clock.seconds();
      });
  std::sort(times.begin(), times.end(),
            [](const IndexTimes& a, const IndexTimes& b) { return a.indices.front() < b.indices.front(); });
  build_times_ = std::move(times);
  static_ = std::move(static_data);
  for (std::size_t j = 0; j < jobs.size(); ++j)
    for (std::size_t i = 0; i < jobs[j].second.size(); ++i) dynamic_[jobs[j].second[i]] = std::move(results[j][i]);
  for (auto& [h, y] : kept)
    if (h >= 0) solutions_[h] = std::move(y);
}

SectorLinearPart::SectorLinearPart(Precomputed data, std::vector<SectorContactPair> pairs, SectorForcing forcing,
                                   int sectors, int n_harmonics)
    : pairs_(std::move(pairs)), forcing_(forcing), sectors_(sectors), n_harmonics_(n_harmonics) {
  SHROUDSIM_CHECK(data.fits(n_contact() + 4), "precomputed data of this model's sizes");
  dynamic_ = std::move(data.dynamic);
  static_ = std::move(data.statics);
  for (int n = 1; n <= n_harmonics_; ++n)
    SHROUDSIM_CHECK(dynamic_.count(harmonic_index(n)) == 1,
                    "precomputed data of harmonic index " + std::to_string(harmonic_index(n)));
}

SectorLinearPart SectorLinearPart::modes_only() const {
  if (static_.omega.size() == 0)
    throw std::invalid_argument("the modes-only model needs the modes of harmonic index 0");
  Precomputed data{static_, dynamic_};
  auto modal_static = [](const IndexData& d) {
    return Eigen::MatrixXcd(d.psi * d.omega.cwiseAbs2().cwiseInverse().asDiagonal() * d.psi.adjoint());
  };
  data.statics.flex = modal_static(static_);
  make_hermitian(data.statics.flex);
  for (auto& [h, d] : data.dynamic) d.flex.setZero();
  SectorForcing forcing = forcing_;
  forcing.residual_flexibility = false;
  return SectorLinearPart(std::move(data), pairs_, forcing, sectors_, n_harmonics_);
}

bool SectorLinearPart::Precomputed::fits(Eigen::Index k) const {
  auto fits_block = [k](const IndexData& d) {
    return d.flex.rows() == k && d.flex.cols() == k && d.psi.cols() == d.omega.size() &&
           (d.omega.size() == 0 || d.psi.rows() == k);
  };
  if (!fits_block(statics)) return false;
  for (const auto& [h, d] : dynamic)
    if (!fits_block(d)) return false;
  return true;
}

void SectorLinearPart::scale_force(double a, const Eigen::Vector3d& force) {
  const Eigen::Index e = n_contact() + 3;  // the excitation row
  auto scale = [&](IndexData& d) {
    if (d.psi.rows() > e) d.psi.row(e) *= a;
    d.flex.row(e) *= a;
    d.flex.col(e) *= a;
  };
  scale(static_);
  for (auto& [h, d] : dynamic_) scale(d);
  for (auto& [h, y] : solutions_) y.col(e) *= a;
  forcing_.force = force;
}

const Eigen::MatrixXcd* SectorLinearPart::static_solution(int h, bool& conjugated) const {
  conjugated = false;
  if (auto it = solutions_.find(h); it != solutions_.end()) return &it->second;
  conjugated = true;
  if (auto it = solutions_.find((sectors_ - h) % sectors_); it != solutions_.end()) return &it->second;
  return nullptr;
}

Eigen::MatrixXcd SectorLinearPart::receptance(int n, double w) const {
  if (n == 0) return static_.flex;
  const IndexData& d = dynamic_.at(harmonic_index(n));
  const double big_w = n * w, z = forcing_.damping_ratio;
  Eigen::VectorXcd inv(d.omega.size());
  for (Eigen::Index r = 0; r < d.omega.size(); ++r) inv[r] = 1.0 / modal_denominator(d.omega[r], big_w, z);
  return d.psi * inv.asDiagonal() * d.psi.adjoint() + d.flex;
}

void SectorLinearPart::harmonic(int n, double w, HarmonicReceptance& out) const {
  const Eigen::MatrixXcd q = receptance(n, w);
  const int c = n_contact();
  out.G = q.topLeftCorner(c, c);
  out.H = q.block(c, 0, 3, c);
  if (n == 1) {
    out.w_lin = q.block(0, c + 3, c, 1);
    out.u_lin = q.block(c, c + 3, 3, 1);
  } else {
    out.w_lin = Eigen::VectorXcd::Zero(c);
    out.u_lin = Eigen::VectorXcd::Zero(3);
  }
}

void SectorLinearPart::harmonic_derivative(int n, double w, Eigen::MatrixXcd& dG, Eigen::VectorXcd& dw_lin) const {
  const int c = n_contact();
  if (n == 0) {
    dG = Eigen::MatrixXcd::Zero(c, c);
    dw_lin = Eigen::VectorXcd::Zero(c);
    return;
  }
  const IndexData& d = dynamic_.at(harmonic_index(n));
  const double big_w = n * w, z = forcing_.damping_ratio;
  Eigen::VectorXcd dinv(d.omega.size());
  for (Eigen::Index r = 0; r < d.omega.size(); ++r) {
    const Complex den = modal_denominator(d.omega[r], big_w, z);
    dinv[r] = static_cast<double>(n) * Complex(2.0 * big_w, -2.0 * z * d.omega[r]) / (den * den);
  }
  const auto psi_c = d.psi.topRows(c);
  dG = psi_c * dinv.asDiagonal() * psi_c.adjoint();
  if (n == 1) dw_lin = psi_c * dinv.asDiagonal() * d.psi.row(c + 3).adjoint();
  else dw_lin = Eigen::VectorXcd::Zero(c);
}

void SectorLinearPart::response_harmonic(int n, double w, Eigen::MatrixXcd& H, Eigen::VectorXcd& u_lin) const {
  const int c = n_contact();
  if (n == 0) {  // as harmonic(): the static flexibility's response rows, no static load
    H = static_.flex.block(c, 0, 3, c);
    u_lin = Eigen::VectorXcd::Zero(3);
    return;
  }
  const IndexData& d = dynamic_.at(harmonic_index(n));
  const double big_w = n * w, z = forcing_.damping_ratio;
  Eigen::VectorXcd inv(d.omega.size());
  for (Eigen::Index r = 0; r < d.omega.size(); ++r) inv[r] = 1.0 / modal_denominator(d.omega[r], big_w, z);
  // Rows c..c+2 of Q_n = Psi diag(inv) Psi^H + flex: columns 0..c-1 (H) and c+3 (u_lin).
  const Eigen::MatrixXcd rows = d.psi.middleRows(c, 3) * inv.asDiagonal();
  H = rows * d.psi.topRows(c).adjoint() + d.flex.block(c, 0, 3, c);
  if (n == 1) u_lin = rows * d.psi.row(c + 3).adjoint() + d.flex.block(c, c + 3, 3, 1);
  else u_lin = Eigen::VectorXcd::Zero(3);
}

bool SectorLinearPart::factored_harmonic(int n, double w, bool derivative, FactoredReceptance& out) const {
  const int c = n_contact();
  out.w_lin = Eigen::VectorXcd::Zero(c);
  if (derivative) out.dw_lin = Eigen::VectorXcd::Zero(c);
  if (n == 0) {  // the exact static flexibility, no modes (as receptance(0, w))
    out.flex = &static_.flex;
    out.psi = nullptr;
    out.s.resize(0);
    out.ds.resize(0);
    return true;
  }
  const IndexData& d = dynamic_.at(harmonic_index(n));
  out.flex = forcing_.residual_flexibility ? &d.flex : nullptr;
  out.psi = &d.psi;
  const double big_w = n * w, z = forcing_.damping_ratio;
  const Eigen::Index modes = d.omega.size();
  out.s.resize(modes);
  if (derivative) out.ds.resize(modes);
  for (Eigen::Index r = 0; r < modes; ++r) {
    const Complex den = modal_denominator(d.omega[r], big_w, z);
    out.s[r] = 1.0 / den;
    // As harmonic_derivative: d/dw of 1/den at W = n w.
    if (derivative) out.ds[r] = static_cast<double>(n) * Complex(2.0 * big_w, -2.0 * z * d.omega[r]) / (den * den);
  }
  if (n == 1) {  // the excitation column c + 3 of Q_1
    const auto psi_c = d.psi.topRows(c);
    const Eigen::VectorXcd excitation = d.psi.row(c + 3).adjoint();
    out.w_lin.noalias() = psi_c * out.s.cwiseProduct(excitation);
    if (forcing_.residual_flexibility) out.w_lin += d.flex.block(0, c + 3, c, 1);
    if (derivative) out.dw_lin.noalias() = psi_c * out.ds.cwiseProduct(excitation);
  }
  return true;
}

void SectorLinearPart::energy(double w, const std::vector<Eigen::VectorXcd>& forces, double& excitation_work,
                              double& viscous_dissipation) const {
  constexpr double kPi = std::numbers::pi;
  excitation_work = 0.0;
  viscous_dissipation = 0.0;
  const int c = n_contact();
  for (std::size_t n = 1; n < forces.size(); ++n) {
    // Generalised load g = [-F_n; 0; delta_n1]: f_total = C^H g.
    Eigen::VectorXcd g = Eigen::VectorXcd::Zero(c + 4);
    g.head(c) = -forces[n];
    if (n == 1) g[c + 3] = 1.0;
    const IndexData& d = dynamic_.at(harmonic_index(static_cast<int>(n)));
    const double big_w = static_cast<double>(n) * w, z = forcing_.damping_ratio;
    const Eigen::VectorXcd p = d.psi.adjoint() * g;  // modal loads
    for (Eigen::Index r = 0; r < d.omega.size(); ++r) {
      const Complex q = p[r] / modal_denominator(d.omega[r], big_w, z);
      // Modal viscous force 2 z w_r q'; per fundamental period pi n^2 w c_r |q|^2.
      viscous_dissipation += kPi * static_cast<double>(n * n) * w * 2.0 * z * d.omega[r] * std::norm(q);
    }
    if (n == 1) {
      // E U_1, the displacement along the force: row c + 3 of Q_1 times g, i.e.
      // psi_e diag(1 / den) Psi^H g + flex_e g (the modal loads p = Psi^H g from above).
      Complex u_e = (d.flex.row(c + 3) * g).value();
      for (Eigen::Index r = 0; r < d.omega.size(); ++r)
        u_e += d.psi(c + 3, r) * p[r] / modal_denominator(d.omega[r], big_w, z);
      excitation_work += kPi * (-u_e.imag());  // pi Im(1 * conj(U_e))
    }
  }
}

std::vector<double> SectorLinearPart::resonances_hz() const {
  std::vector<double> f;
  const auto it = dynamic_.find(harmonic_index(1));
  if (it == dynamic_.end()) return f;
  for (Eigen::Index r = 0; r < it->second.omega.size(); ++r)
    f.push_back(it->second.omega[r] / (2.0 * std::numbers::pi));
  std::sort(f.begin(), f.end());
  return f;
}

bool SectorLinearPart::second_order_form(int n, SecondOrderForm& out) const {
  const int c = n_contact();
  if (n == 0) {
    const Eigen::Index m = static_.omega.size();
    out.M = Eigen::MatrixXd::Identity(m, m);
    out.C = (2.0 * forcing_.damping_ratio * static_.omega).asDiagonal();
    out.K = static_.omega.cwiseAbs2().asDiagonal();
    out.P = m > 0 ? Eigen::MatrixXcd(static_.psi.topRows(c)) : Eigen::MatrixXcd(c, 0);
    out.R = static_.flex.topLeftCorner(c, c);
    for (Eigen::Index r = 0; r < m; ++r)
      out.R -= out.P.col(r) * out.P.col(r).adjoint() / (static_.omega[r] * static_.omega[r]);
    return true;
  }
  const IndexData& d = dynamic_.at(harmonic_index(n));
  const Eigen::Index m = d.omega.size();
  out.M = Eigen::MatrixXd::Identity(m, m);
  out.C = (2.0 * forcing_.damping_ratio * d.omega).asDiagonal();
  out.K = d.omega.cwiseAbs2().asDiagonal();
  out.P = d.psi.topRows(c);
  out.R = d.flex.topLeftCorner(c, c);
  return true;
}

bool SectorLinearPart::damped_harmonic(int n, double w, double zeta, bool with_norm, DampedReceptance& out) const {
  const int c = n_contact();
  if (n == 0) {
    out.G = static_.flex.topLeftCorner(c, c);
    out.dG_dw = out.dG_dzeta = Eigen::MatrixXcd::Zero(c, c);
    out.H = static_.flex.block(c, 0, 3, c);
    return out.G.allFinite();
  }
  const IndexData& d = dynamic_.at(harmonic_index(n));
  const Eigen::Index m = d.omega.size();
  const double big_w = n * w, z = forcing_.damping_ratio;
  // 1/den_r and its derivatives: den_r = w_r^2 - W^2 + i W (2 z w_r - zeta), W = n w.
  Eigen::VectorXcd inv(m), dinv_dw(m), dinv_dz(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Complex den(d.omega[r] * d.omega[r] - big_w * big_w, big_w * (2.0 * z * d.omega[r] - zeta));
    const Complex dden_dw = static_cast<double>(n) * Complex(-2.0 * big_w, 2.0 * z * d.omega[r] - zeta);
    const Complex dden_dz(0.0, -big_w);
    inv[r] = 1.0 / den;
    dinv_dw[r] = -dden_dw * inv[r] * inv[r];
    dinv_dz[r] = -dden_dz * inv[r] * inv[r];
  }
  const auto psi_c = d.psi.topRows(c);
  out.G = psi_c * inv.asDiagonal() * psi_c.adjoint() + d.flex.topLeftCorner(c, c);
  out.dG_dw = psi_c * dinv_dw.asDiagonal() * psi_c.adjoint();
  out.dG_dzeta = psi_c * dinv_dz.asDiagonal() * psi_c.adjoint();
  out.H = d.psi.middleRows(c, 3) * inv.asDiagonal() * psi_c.adjoint() + d.flex.block(c, 0, 3, c);
  if (with_norm && n == 1) {
    // q = Phi eta, eta = -diag(inv) psi_c^H F: q^H M q = F^H psi_c diag(|inv|^2) psi_c^H F.
    Eigen::VectorXd n2(m), dn2_dw(m), dn2_dz(m);
    for (Eigen::Index r = 0; r < m; ++r) {
      n2[r] = std::norm(inv[r]);
      dn2_dw[r] = 2.0 * (std::conj(inv[r]) * dinv_dw[r]).real();
      dn2_dz[r] = 2.0 * (std::conj(inv[r]) * dinv_dz[r]).real();
    }
    out.N = psi_c * n2.asDiagonal() * psi_c.adjoint();
    out.dN_dw = psi_c * dn2_dw.asDiagonal() * psi_c.adjoint();
    out.dN_dzeta = psi_c * dn2_dz.asDiagonal() * psi_c.adjoint();
    // e = X_1^H f over the modes: psi_c diag(conj(inv)) (row c + 3 of psi)^H.
    out.e = psi_c * inv.conjugate().asDiagonal() * d.psi.row(c + 3).adjoint();
  }
  return out.G.allFinite();
}

std::string SectorLinearPart::describe() const {
  std::ostringstream s;
  s << "FE sector (Nb = " << sectors_ << ", engine order " << forcing_.engine_order << ", harmonic indices";
  for (const auto& [h, d] : dynamic_) s << " " << h << " (" << d.omega.size() << " modes)";
  s << (forcing_.residual_flexibility ? ", residual flexibility" : ", no residual flexibility") << ")";
  return s.str();
}

std::vector<std::vector<Eigen::VectorXcd>> sector_displacements(
    const cyclic::CyclicSector& sector, const std::map<int, modal::ModalBasis>& bases,
    const std::function<modal::StiffnessFactor(int)>& factor, const std::vector<SectorContactPair>& pairs,
    const SectorForcing& forcing, const std::vector<ShapeLoad>& loads, const SectorLinearPart* kept, int threads) {
  std::vector<std::vector<Eigen::VectorXcd>> out(loads.size());
  if (loads.empty()) return out;
  const int h_max = static_cast<int>(loads.front().forces.size()) - 1;
  const int nb = sector.sectors();
  const Eigen::Index c = 3 * static_cast<Eigen::Index>(pairs.size());
  for (auto& o : out) o.resize(h_max + 1);
  // Harmonics n grouped by harmonic index h, and the indices by pairs {h, Nb - h} that share
  // one K_h factor (index Nb - h's is h's conjugated).
  std::map<int, std::vector<int>> by_index;
  for (int n = 0; n <= h_max; ++n) by_index[harmonic_index(n, forcing.engine_order, nb)].push_back(n);
  std::map<int, std::vector<int>> groups;
  for (const auto& [h, harmonics] : by_index) groups[cyclic::canonical_index(h, nb)].push_back(h);
  std::vector<std::vector<int>> jobs;
  for (auto& [canonical, members] : groups) jobs.push_back(std::move(members));
  linalg::parallel_for(
      static_cast<int>(jobs.size()), linalg::worker_count(threads, static_cast<int>(jobs.size())), [&](int j) {
        std::optional<modal::StiffnessFactor> first_factor;  // of jobs[j].front()
        for (int h : jobs[static_cast<std::size_t>(j)]) {
          const std::vector<int>& harmonics = by_index.at(h);
          const Eigen::SparseMatrix<Complex> rows = selection(pairs, forcing, sector, h, sector.n_full());
          const Eigen::SparseMatrix<Complex> t = sector.expansion(h);
          const Eigen::SparseMatrix<Complex> load_map = t.adjoint() * rows.adjoint();  // n_red x (c + 4)
          const bool dynamic = harmonics.front() != 0 || harmonics.size() > 1;
          const modal::ModalBasis* basis = nullptr;
          if (dynamic) {
            auto it = bases.find(h);
            SHROUDSIM_CHECK(it != bases.end(), "modes of harmonic index " + std::to_string(h) + " given");
            basis = &it->second;
          }
          // x = K_h^-1 g for g = load_map y: from the kept solutions, or a factor.
          bool conjugated = false;
          const Eigen::MatrixXcd* solution = kept ? kept->static_solution(h, conjugated) : nullptr;
          if (solution)
            SHROUDSIM_CHECK(solution->rows() == load_map.rows() && solution->cols() == load_map.cols(),
                            "static solutions of the same sector, pairs and forcing");
          std::optional<modal::StiffnessFactor> k;
          const bool need_factor = harmonics.front() == 0 || forcing.residual_flexibility;
          if (need_factor && !solution) {
            if (!first_factor) first_factor = factor(jobs[static_cast<std::size_t>(j)].front());
            k = h == jobs[static_cast<std::size_t>(j)].front() ? *first_factor : first_factor->conjugate();
          }
          // K_h^-1 g for g = load_map y.
          const auto static_solve = [&](const Eigen::VectorXcd& y, const Eigen::VectorXcd& g) -> Eigen::VectorXcd {
            if (!solution) return k->solve(Eigen::MatrixXcd(g)).col(0);
            if (conjugated) return (*solution * y.conjugate()).conjugate();
            return *solution * y;
          };
          for (std::size_t l = 0; l < loads.size(); ++l) {
            for (int n : harmonics) {
              SHROUDSIM_CHECK(loads[l].forces[n].size() == c, "contact forces of every pair");
              Eigen::VectorXcd y = Eigen::VectorXcd::Zero(c + 4);
              y.head(c) = -loads[l].forces[n];
              if (n == 1 && loads[l].excitation) y(c + 3) = 1.0;
              const Eigen::VectorXcd g = load_map * y;
              Eigen::VectorXcd ur;
              if (n == 0) {
                ur = static_solve(y, g);
              } else {
                const double big_w = n * loads[l].w, z = forcing.damping_ratio;
                const Eigen::VectorXcd modal = basis->phi.adjoint() * g;
                Eigen::VectorXcd q(modal.size());
                for (Eigen::Index r = 0; r < modal.size(); ++r) {
                  const double wr = basis->omega[r];
                  q[r] = modal[r] / Complex(wr * wr - big_w * big_w, big_w * (2.0 * z * wr - loads[l].zeta));
                  if (forcing.residual_flexibility) q[r] -= modal[r] / (wr * wr);
                }
                ur = basis->phi * q;
                if (forcing.residual_flexibility) ur += static_solve(y, g);
              }
              out[l][n] = t * ur;
            }
          }
        }
      });
  return out;
}

}  // namespace shroudsim::frf
