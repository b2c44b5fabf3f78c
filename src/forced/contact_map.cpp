#include "forced/contact_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace shroudsim::forced {

namespace {
// A sample slips when |T| reaches mu N to this relative tolerance (the law returns it on the
// limit to round-off).
constexpr double kOnTheLimit = 1e-9;
}  // namespace

std::vector<PairState> pair_states(hbm::ContactEvaluator& evaluator, const Eigen::VectorXd& w) {
  const int block = evaluator.pair_layout().size();
  const bool has_normal = evaluator.pair_layout().n_directions() == 3;
  std::vector<PairState> out(static_cast<std::size_t>(evaluator.n_pairs()));
  for (int p = 0; p < evaluator.n_pairs(); ++p) {
    const contact::PairParameters& pp = evaluator.pairs()[static_cast<std::size_t>(p)];
    hbm::PairDetail d;
    evaluator.evaluate_pair(p, w.segment(p * block, block), d, false);
    PairState& s = out[static_cast<std::size_t>(p)];
    const Eigen::Index n = d.w.rows();
    if (n == 0) continue;  // the time-continuous 1d_exact law has no samples
    Eigen::MatrixX2d slider(n, 2);
    int open = 0, slip = 0;
    s.normal_load_min_n = std::numeric_limits<double>::infinity();
    s.normal_load_max_n = -std::numeric_limits<double>::infinity();
    for (Eigen::Index l = 0; l < n; ++l) {
      const double nl = has_normal ? d.f(l, 2) : std::max(0.0, pp.normal_preload);
      s.normal_load_min_n = std::min(s.normal_load_min_n, nl);
      s.normal_load_max_n = std::max(s.normal_load_max_n, nl);
      const double t = std::hypot(d.f(l, 0), d.f(l, 1));
      const double limit = pp.friction_coefficient * nl;
      if (!(nl > 0.0)) ++open;
      else if (t >= (1.0 - kOnTheLimit) * limit) ++slip;
      for (int k = 0; k < 2; ++k) slider(l, k) = d.w(l, k) - d.f(l, k) / pp.tangential_stiffness;
    }
    if (!has_normal) slider.col(1).setZero();
    const Eigen::RowVector2d mean = slider.colwise().mean();
    s.slip_amplitude_m = (slider.rowwise() - mean).rowwise().norm().maxCoeff();
    s.open_fraction = static_cast<double>(open) / n;
    s.slip_fraction = static_cast<double>(slip) / n;
    s.stick_fraction = 1.0 - s.open_fraction - s.slip_fraction;
    s.energy_per_cycle_j = hbm::dissipated_energy(evaluator.pair_layout(), w.segment(p * block, block), d.force);
  }
  return out;
}

}  // namespace shroudsim::forced
