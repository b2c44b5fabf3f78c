#include "hbm/harmonic_layout.hpp"

#include <stdexcept>

namespace shroudsim::hbm {

HarmonicLayout::HarmonicLayout(int n_harmonics, int n_directions)
    : n_harmonics_(n_harmonics), n_directions_(n_directions) {
  if (n_harmonics < 0)
    throw std::invalid_argument("HarmonicLayout: harmonics = " + std::to_string(n_harmonics) +
                                " violates: harmonics >= 0");
  if (n_directions < 1)
    throw std::invalid_argument("HarmonicLayout: directions = " + std::to_string(n_directions) +
                                " violates: directions >= 1");
}

int HarmonicLayout::index(int direction, int harmonic, Part part) const {
  if (direction < 0 || direction >= n_directions_ || harmonic < 0 || harmonic > n_harmonics_ ||
      (harmonic == 0 && part == Part::sine))
    throw std::out_of_range("HarmonicLayout::index: no such coefficient");
  return direction * per_direction() + local_index(harmonic, part);
}

}  // namespace shroudsim::hbm
