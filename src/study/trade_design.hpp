#pragma once
// The design of `study --convergence` (docs/contract.md "study"): every knob of the
// accuracy/speed trade varied one at a time around the case's own setting, each against its
// finest value (the reference), every other knob at the case's setting.
//
// Knobs, coarse to fine (only those the case has):
//  - mesh size (generated sectors): kMeshLadder sizes, each kMeshRatio = 2^(1/3) times finer
//    (about twice the DOFs of the one before: enough for an observed order and a Richardson
//    estimate, study/curves.hpp mesh_convergence);
//  - contact pairs (sectors with a pair count): the case's against "all" node pairs;
//  - modes kept: max(5, m / 2), m, 2 m; residual flexibility off / on (sectors);
//  - harmonics H: 1, 3, H, 2 H (reference at 4 N samples, so that 2 H + 1 <= N holds);
//  - time samples N: N / 8 .. N and 4 N (at least max(16, 2 H + 1));
//  - tangential update (radial return / exact linear, reference at 4 N) and contact model
//    (quasi3d / full3d) for the 2D friction models; Jacobian (finite difference / analytic).
// The exact 1D law has no H, N or Jacobian knobs (it is not sampled).
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "io/case.hpp"

namespace shroudsim::study {

constexpr int kMeshLadder = 4;
inline const double kMeshRatio = std::cbrt(2.0);

struct Knob {
  std::string name, key;
  std::vector<std::string> values;                             ///< TOML value texts, coarse to fine
  std::vector<std::pair<std::string, std::string>> reference;  ///< extra overrides of the reference point
};

/// The knobs of `study --convergence` for case c (empty: nothing to vary).
std::vector<Knob> convergence_knobs(const io::Case& c);

}  // namespace shroudsim::study
