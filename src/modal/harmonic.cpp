#include "modal/harmonic.hpp"

#include "core/error.hpp"

namespace shroudsim::modal {

ModalResult solve_harmonic(const cyclic::CyclicSector& sector, int h, const ModalOptions& options) {
  if (sector.is_real(h)) return solve_modes(sector.reduce_real(h), h, options);
  return solve_modes(sector.reduce(h), h, options);
}

std::shared_ptr<const SharedAnalysis> analyse_harmonic_pattern(const cyclic::CyclicSector& sector,
                                                               linalg::FactorMethod method) {
  return analyse_pattern(sector.reduce_real(0), 0.0, method);
}

namespace {

template <typename Scalar>
StiffnessFactor factor_on(const linalg::SparsePair<Scalar>& km, linalg::FactorMethod method,
                          const SharedAnalysis* shared) {
  std::shared_ptr<const linalg::CholmodFactor<Scalar>> f = factor_shifted(km, 0.0, method, nullptr, shared);
  if (f->status() != linalg::FactorStatus::Success)
    throw NumericalError("factorization of the stiffness matrix failed: " + linalg::to_string(f->status()));
  return make_stiffness_factor<Scalar>(std::move(f));
}

}  // namespace

StiffnessFactor factor_harmonic_stiffness(const cyclic::CyclicSector& sector, int h, linalg::FactorMethod method,
                                          const SharedAnalysis* shared) {
  // Without `shared`, factor_shifted analyses afresh: factor_stiffness's computation.
  if (sector.is_real(h)) return factor_on(sector.reduce_real(h), method, shared);
  return factor_on(sector.reduce(h), method, shared);
}

StiffnessFactor HarmonicStiffnessFactors::operator()(int h) const {
  std::call_once(analysed_, [this]() { analysis_ = analyse_harmonic_pattern(sector_, method_); });
  return factor_harmonic_stiffness(sector_, h, method_, analysis_.get());
}

}  // namespace shroudsim::modal
