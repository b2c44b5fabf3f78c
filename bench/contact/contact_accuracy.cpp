// Prints the accuracy tables of BENCHMARKS.md, section "Contact pair and AFT":
//  1. analytic Jacobian vs central differences of the same discrete map: median and max
//     relative Frobenius error over seeded random states, every model and update,
//     H = 1, 5, 15 and N = 64, 512, 2048;
//  2. radial_return vs exact_linear against closed forms / a converged reference:
//     1D Jenkins (first harmonic), circular orbit (dissipated energy, lead angle),
//     elliptic orbit with varying normal load (energy vs N = 65536 exact_linear);
//  3. through separation: force harmonics against N on a motion that separates over a third
//     of the period and sticks right after each closing (tests/contact/separation_reference.hpp).
// Usage: contact_accuracy [states_per_cell=16]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <vector>

#include "contact/jenkins.hpp"
#include "contact/periodic_law.hpp"
#include "contact_test_support.hpp"
#include "hbm/contact_evaluator.hpp"
#include "separation_reference.hpp"

using namespace shroudsim;

namespace {

contact::PairParameters pair_params() {
  contact::PairParameters p;
  p.tangential_stiffness = 2.0e5;
  p.normal_stiffness = 5.0e5;
  p.friction_coefficient = 0.4;
  p.normal_preload = 3.0;
  return p;
}

void jacobian_table(int states) {
  std::printf(
      "## Jacobian: analytic vs central differences (relative Frobenius error per pair, %d seeded random states)\n\n",
      states);
  std::printf("| model | update | H | N | median | max | periods (max) |\n|---|---|---|---|---|---|---|\n");
  const contact::PairParameters p = pair_params();
  const std::vector<std::pair<contact::Model, contact::TangentialUpdate>> cases{
      {contact::Model::full3d, contact::TangentialUpdate::radial_return},
      {contact::Model::full3d, contact::TangentialUpdate::exact_linear},
      {contact::Model::quasi3d, contact::TangentialUpdate::radial_return},
      {contact::Model::quasi3d, contact::TangentialUpdate::exact_linear},
      {contact::Model::one_d, contact::TangentialUpdate::radial_return},
      {contact::Model::one_d, contact::TangentialUpdate::exact_linear},
      {contact::Model::one_d_exact, contact::TangentialUpdate::exact_linear}};
  for (const auto& [model, update] : cases) {
    for (int h : {1, 5, 15}) {
      for (int n : {64, 512, 2048}) {
        if (model == contact::Model::one_d_exact && (h != 1 || n != 64)) continue;
        hbm::ContactEvaluatorOptions o;
        o.n_harmonics = h;
        o.n_time_samples = n;
        o.law.model = model;
        o.law.update = update;
        o.measure_plans = false;
        o.threads = 1;
        hbm::ContactEvaluator ev(o, std::vector<contact::PairParameters>(states, p));
        std::mt19937 rng(1000 * h + n);
        const int s = ev.pair_layout().size();
        Eigen::VectorXd w(ev.size());
        for (int i = 0; i < states; ++i) w.segment(i * s, s) = testing::random_contact_state(ev.pair_layout(), p, rng);
        Eigen::VectorXd fa, ff;
        std::vector<Eigen::MatrixXd> ja, jf;
        const auto st = ev.evaluate(w, fa, &ja, hbm::JacobianMethod::analytic);
        ev.evaluate(w, ff, &jf, hbm::JacobianMethod::finite_difference);
        std::vector<double> err;
        double mx = 0.0;
        for (int i = 0; i < states; ++i) {
          err.push_back(testing::relative_error(ja[i], jf[i]));
          mx = std::max(mx, err.back());
        }
        std::printf("| %s | %s | %d | %d | %.1e | %.1e | %d |\n", contact::to_string(model).c_str(),
                    model == contact::Model::one_d_exact ? "-" : contact::to_string(update).c_str(), h,
                    model == contact::Model::one_d_exact ? 0 : n, testing::median(err), mx, st.max_periods);
        std::fflush(stdout);
      }
    }
  }
}

// Force harmonics of one pair.
Eigen::VectorXd force(contact::Model model, contact::TangentialUpdate update, int h, int n,
                      const contact::PairParameters& p, const Eigen::VectorXd& w) {
  hbm::ContactEvaluatorOptions o;
  o.n_harmonics = h;
  o.n_time_samples = n;
  o.law.model = model;
  o.law.update = update;
  o.law.max_periods = 2000;
  o.measure_plans = false;
  hbm::ContactEvaluator ev(o, {p});
  Eigen::VectorXd f;
  ev.evaluate(w, f, nullptr);
  return f;
}

void update_table() {
  constexpr double kPi = std::numbers::pi;
  const contact::PairParameters p = pair_params();
  const double fs = p.friction_coefficient * p.normal_preload;
  const double a_slip = fs / p.tangential_stiffness;
  const auto rr = contact::TangentialUpdate::radial_return;
  const auto el = contact::TangentialUpdate::exact_linear;
  std::printf("\n## radial_return vs exact_linear: relative errors against references\n\n");
  std::printf(
      "1D Jenkins (model 1d, x = 4 a_slip cos), |F1 - F1_exact|/|F1_exact|; circle (full3d, z = 0, r = 4 a_slip): "
      "energy per cycle vs 2 pi r mu N sqrt(1 - (a_slip/r)^2) and lead-angle error [rad]; ellipse "
      "(full3d, x = 4 a_slip cos, y = 2 a_slip sin(t + 1), z = 0.5 N0/kn cos 2t): energy vs exact_linear at N = 65536 (H = 5)\n\n");
  std::printf(
      "| N | 1D radial_return | 1D exact_linear | circle energy radial_return | circle energy exact_linear | "
      "circle lead radial_return | circle lead exact_linear | ellipse energy radial_return | ellipse energy exact_linear |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  // 1D
  const double a1d = 4.0 * a_slip;
  const auto jen = contact::jenkins_single_harmonic(p.tangential_stiffness, fs, 0.0, a1d, 0.0);
  const double f1_exact = std::hypot(jen.fc, jen.fs);
  // circle
  const double r = 4.0 * a_slip;
  const double e_circle = 2.0 * kPi * r * fs * std::sqrt(1.0 - (a_slip / r) * (a_slip / r));
  const double lead_exact = std::acos(a_slip / r);
  hbm::HarmonicLayout l1(1, 3);
  Eigen::VectorXd wc = Eigen::VectorXd::Zero(l1.size());
  wc[1] = r;      // x = r cos
  wc[3 + 2] = r;  // y = r sin
  // ellipse with normal load variation
  const int he = 5;
  hbm::HarmonicLayout l5(he, 3);
  Eigen::VectorXd we = Eigen::VectorXd::Zero(l5.size());
  const int m = l5.per_direction();
  we[1] = 4.0 * a_slip;
  we[m + 1] = 2.0 * a_slip * std::sin(1.0);  // sin(t+1) = sin t cos 1 + cos t sin 1
  we[m + 2] = 2.0 * a_slip * std::cos(1.0);
  we[2 * m + 3] = 0.5 * p.normal_preload / p.normal_stiffness;
  const double e_ref = hbm::dissipated_energy(l5, we, force(contact::Model::full3d, el, he, 65536, p, we));
  Eigen::VectorXd w1 = Eigen::VectorXd::Zero(3);
  w1[1] = a1d;
  for (int n : {16, 32, 64, 128, 256, 512, 1024, 2048, 4096}) {
    double e1d[2], ec[2], lc[2], ee[2];
    int k = 0;
    for (auto upd : {rr, el}) {
      const Eigen::VectorXd f1 = force(contact::Model::one_d, upd, 1, n, p, w1);
      e1d[k] = std::abs(std::hypot(f1[1] - jen.fc, f1[2] - jen.fs)) / f1_exact;
      const Eigen::VectorXd fc = force(contact::Model::full3d, upd, 1, n, p, wc);
      ec[k] = std::abs(hbm::dissipated_energy(l1, wc, fc) / e_circle - 1.0);
      // x force first harmonic: |T| cos(t + lead) -> fc = |T| cos(lead), fs = -|T| sin(lead)
      lc[k] = std::abs(std::atan2(-fc[2], fc[1]) - lead_exact);
      const Eigen::VectorXd fe = force(contact::Model::full3d, upd, he, n, p, we);
      ee[k] = std::abs(hbm::dissipated_energy(l5, we, fe) / e_ref - 1.0);
      ++k;
    }
    std::printf("| %d | %.2e | %.2e | %.2e | %.2e | %.2e | %.2e | %.2e | %.2e |\n", n, e1d[0], e1d[1], ec[0], ec[1],
                lc[0], lc[1], ee[0], ee[1]);
    std::fflush(stdout);
  }
}

// (Tx, Ty, N) harmonics 0..h of the periodic law at n samples shifted by `shift` of a step.
Eigen::VectorXd sampled_forces(const testing::TrigMotion& m, contact::Model model, contact::TangentialUpdate update,
                               const contact::PairParameters& p, int n, double shift, int h) {
  contact::PeriodicLaw law({.model = model, .update = update});
  Eigen::MatrixX3d f;
  law.evaluate(p, m.sample(n, shift), f);
  Eigen::VectorXd out(3 * (2 * h + 1));
  for (int j = 0; j < 3; ++j) out.segment(j * (2 * h + 1), 2 * h + 1) = testing::sampled_harmonics(f.col(j), shift, h);
  return out;
}

void separation_table() {
  constexpr int kH = 7, kShifts = 8;
  const contact::PairParameters p = pair_params();
  const auto el = contact::TangentialUpdate::exact_linear;
  const auto rr = contact::TangentialUpdate::radial_return;
  constexpr double kTheta = 0.5;
  const testing::TrigMotion line = testing::separating_motion(p, kTheta);
  const testing::TrigMotion ellipse = testing::separating_motion(p, -1.0);
  const int s = 2 * kH + 1;
  Eigen::VectorXd ref_line(3 * s), ref_axes(3 * s);
  {
    const auto u = testing::continuous_1d_law(line, kTheta, p, kH);
    ref_line << std::cos(kTheta) * u.tangential, std::sin(kTheta) * u.tangential, u.normal;
    const auto x = testing::continuous_1d_law(ellipse, 0.0, p, kH);
    const auto y = testing::continuous_1d_law(ellipse, 0.5 * std::numbers::pi, p, kH);
    ref_axes << x.tangential, y.tangential, x.normal;
    std::printf(
        "\n## Through separation: force harmonics against N\n\nMotion: open %.0f %% of the period, stick %.0f %%, slip "
        "%.0f %% (line), every closing sticks: %s. Worst relative error of the (Tx, Ty, N) harmonics 0..%d over %d "
        "shifts of the sampling grid. References: the time-continuous law solved event by event (line: full3d; "
        "ellipse: quasi3d per axis); the coupled law on the ellipse against itself at N = 2^17.\n\n",
        100 * u.open, 100 * u.stick, 100 * u.slip, u.stick_after_closing ? "yes" : "no", kH, kShifts);
  }
  const Eigen::VectorXd ref_ellipse = sampled_forces(ellipse, contact::Model::full3d, el, p, 1 << 17, 0.0, kH);
  std::printf(
      "| N | full3d line exact_linear | quasi3d ellipse exact_linear | full3d ellipse exact_linear | full3d ellipse "
      "radial_return |\n|---|---|---|---|---|\n");
  for (int n = 64; n <= 8192; n *= 2) {
    double e[4] = {0, 0, 0, 0};
    for (int k = 0; k < kShifts; ++k) {
      const double shift = static_cast<double>(k) / kShifts;
      auto err = [&](const testing::TrigMotion& m, contact::Model model, contact::TangentialUpdate u,
                     const Eigen::VectorXd& ref) {
        return (sampled_forces(m, model, u, p, n, shift, kH) - ref).norm() / ref.norm();
      };
      e[0] = std::max(e[0], err(line, contact::Model::full3d, el, ref_line));
      e[1] = std::max(e[1], err(ellipse, contact::Model::quasi3d, el, ref_axes));
      e[2] = std::max(e[2], err(ellipse, contact::Model::full3d, el, ref_ellipse));
      e[3] = std::max(e[3], err(ellipse, contact::Model::full3d, rr, ref_ellipse));
    }
    std::printf("| %d | %.2e | %.2e | %.2e | %.2e |\n", n, e[0], e[1], e[2], e[3]);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int states = argc > 1 ? std::atoi(argv[1]) : 16;
  if (states < 1) {
    std::fprintf(stderr, "usage: contact_accuracy [states_per_cell >= 1]\n");
    return 2;
  }
  update_table();
  separation_table();
  std::printf("\n");
  jacobian_table(states);
  return 0;
}
