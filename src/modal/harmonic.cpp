#include "modal/harmonic.hpp"

namespace shroudsim::modal {

ModalResult solve_harmonic(const cyclic::CyclicSector& sector, int h, const ModalOptions& options) {
  if (sector.is_real(h)) return solve_modes(sector.reduce_real(h), h, options);
  return solve_modes(sector.reduce(h), h, options);
}

StiffnessFactor factor_harmonic_stiffness(const cyclic::CyclicSector& sector, int h, linalg::FactorMethod method) {
  if (sector.is_real(h)) return factor_stiffness(sector.reduce_real(h).K, method);
  return factor_stiffness(sector.reduce(h).K, method);
}

}  // namespace shroudsim::modal
