#pragma once
// The one owner of the harmonic ordering of real Fourier coefficients.
//
// A periodic signal of one direction, u(t) = c0 + sum_{n=1..H} cn cos(n w t) + sn sin(n w t),
// is stored as 2H+1 reals [c0 | c1 s1 | ... | cH sH] (complex convention U_n = cn - i sn,
// u = Re(sum U_n exp(i n w t))). A vector of several directions (x, y, z of a contact pair)
// stores the directions one after the other: [x block | y block | z block].
// Invariant: n_harmonics >= 0, n_directions >= 1.
#include <string>

namespace shroudsim::hbm {

class HarmonicLayout {
 public:
  enum class Part { cosine, sine };

  HarmonicLayout(int n_harmonics, int n_directions);

  int n_harmonics() const { return n_harmonics_; }    ///< H
  int n_directions() const { return n_directions_; }  ///< directions per block set
  int per_direction() const { return 2 * n_harmonics_ + 1; }
  int size() const { return n_directions_ * per_direction(); }

  /// Index of one coefficient. harmonic 0 has only the cosine part (the mean).
  int index(int direction, int harmonic, Part part = Part::cosine) const;
  /// Index inside one direction block.
  static int local_index(int harmonic, Part part) {
    return harmonic == 0 ? 0 : 2 * harmonic - (part == Part::cosine ? 1 : 0);
  }
  /// Smallest admissible number of time samples per period (no aliasing of the H harmonics).
  int min_time_samples() const { return 2 * n_harmonics_ + 1; }

 private:
  int n_harmonics_;
  int n_directions_;
};

}  // namespace shroudsim::hbm
