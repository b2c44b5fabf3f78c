// The FE sector's perturbation families for the Floquet analysis (frf/sector.hpp,
// forced/stability.hpp, docs/physics.md section 9).
#include <complex>
#include <vector>

#include "frf/sector.hpp"

namespace shroudsim::frf {

using Complex = std::complex<double>;

const SectorLinearPart::IndexData* SectorLinearPart::index_data(int g, bool& conjugate) const {
  conjugate = false;
  if (g == 0) return static_.omega.size() > 0 ? &static_ : nullptr;
  if (auto it = dynamic_.find(g); it != dynamic_.end()) return &it->second;
  conjugate = true;
  if (auto it = dynamic_.find(sectors_ - g); it != dynamic_.end()) return &it->second;
  return nullptr;
}

int SectorLinearPart::family_block_index(int family, int k) const {
  return ((family + k * forcing_.engine_order) % sectors_ + sectors_) % sectors_;
}

std::vector<int> SectorLinearPart::perturbation_families() const {
  std::vector<int> out;
  bool conjugate = false;
  for (int p = 0; p <= sectors_ / 2; ++p) {
    bool all = true;
    for (int k = -n_harmonics_; k <= n_harmonics_ && all; ++k)
      all = index_data(family_block_index(p, k), conjugate) != nullptr;
    if (all) out.push_back(p);
  }
  return out;
}

bool SectorLinearPart::perturbation_form(int family, int k, double w, double max_omega, SecondOrderForm& out) const {
  bool conjugate = false;
  const int g = family_block_index(family, k);
  const IndexData* d = index_data(g, conjugate);
  if (d == nullptr) return false;
  const int c = n_contact();
  auto psi = [&](Eigen::Index r) -> Eigen::VectorXcd {
    return conjugate ? Eigen::VectorXcd(d->psi.col(r).head(c).conjugate()) : Eigen::VectorXcd(d->psi.col(r).head(c));
  };
  // The massless part: the residual flexibility of the index (index 0's data hold the exact
  // static flexibility: that minus the kept modes' static part), plus each mode above
  // max_omega with its receptance at s = i k w, 1 / (w_r^2 - (k w)^2 + 2 i z w_r k w).
  out.R = conjugate ? Eigen::MatrixXcd(d->flex.topLeftCorner(c, c).conjugate())
                    : Eigen::MatrixXcd(d->flex.topLeftCorner(c, c));
  std::vector<Eigen::Index> kept;
  const double kw = k * w, z = forcing_.damping_ratio;
  for (Eigen::Index r = 0; r < d->omega.size(); ++r) {
    const double wr = d->omega[r];
    const Eigen::VectorXcd v = psi(r);
    if (max_omega <= 0.0 || wr <= max_omega) {
      kept.push_back(r);
      if (g == 0) out.R -= v * v.adjoint() / (wr * wr);
    } else if (g != 0) {
      out.R += v * v.adjoint() / Complex(wr * wr - kw * kw, 2.0 * z * wr * kw);
    } else {
      out.R += v * v.adjoint() * (1.0 / Complex(wr * wr - kw * kw, 2.0 * z * wr * kw) - 1.0 / (wr * wr));
    }
  }
  const Eigen::Index m = static_cast<Eigen::Index>(kept.size());
  Eigen::VectorXd omega(m);
  out.P.resize(c, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    omega[j] = d->omega[kept[static_cast<std::size_t>(j)]];
    out.P.col(j) = psi(kept[static_cast<std::size_t>(j)]);
  }
  out.M = Eigen::MatrixXd::Identity(m, m);
  out.C = (2.0 * forcing_.damping_ratio * omega).asDiagonal();
  out.K = omega.cwiseAbs2().asDiagonal();
  return true;
}

}  // namespace shroudsim::frf
