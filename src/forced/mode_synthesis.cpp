#include "forced/mode_synthesis.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

namespace shroudsim::forced {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
/// Bisection steps in log a for the peak: 2^-60 of a mode-curve step.
constexpr int kBisections = 60;
/// Golden-section steps for min_W |den(W)| on [0.5 w, 1.5 w]: 0.618^100 w, below round-off.
constexpr int kGoldenSteps = 100;
/// A root of the quartic counts as real when its imaginary part is below this fraction of w.
constexpr double kRealRoot = 1e-8;

/// The mode at one amplitude.
struct ModeState {
  double a, omega, damping, contact_damping, force, response;
};
ModeState state(const NonlinearModePoint& p) {
  return {p.amplitude,
          p.omega,
          p.damping_ratio,
          p.contact_damping_ratio,
          std::abs(p.modal_force),
          p.response_per_amplitude};
}
/// Linear in log10 a between points p and q.
ModeState interpolate(const NonlinearModePoint& p, const NonlinearModePoint& q, double l) {
  const double l0 = std::log10(p.amplitude), l1 = std::log10(q.amplitude), t = l1 > l0 ? (l - l0) / (l1 - l0) : 0.0;
  const ModeState s = state(p), e = state(q);
  auto mix = [&](double u, double v) { return u + t * (v - u); };
  return {std::pow(10.0, l),         mix(s.omega, e.omega),
          mix(s.damping, e.damping), mix(s.contact_damping, e.contact_damping),
          mix(s.force, e.force),     mix(s.response, e.response)};
}

/// Viscous and hysteretic parts (as ratios) of the modal equation's damping.
void parts(const ModeState& m, SynthesisDamping d, double& dv, double& dh) {
  dh = d == SynthesisDamping::mixed ? std::clamp(m.contact_damping, 0.0, m.damping) : 0.0;
  dv = m.damping - dh;
}
/// |den(W)| = |w^2 - W^2 + i (2 D_v w W + 2 D_h w^2)|.
double den(const ModeState& m, SynthesisDamping d, double big_w) {
  double dv = 0, dh = 0;
  parts(m, d, dv, dh);
  return std::abs(
      std::complex<double>(m.omega * m.omega - big_w * big_w, 2 * dv * m.omega * big_w + 2 * dh * m.omega * m.omega));
}
/// The W > 0 minimizing |den| (the peak's frequency at this a) and the minimum.
double min_den(const ModeState& m, SynthesisDamping d, double& w_min) {
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double lo = 0.5 * m.omega, hi = 1.5 * m.omega;
  double c = hi - golden * (hi - lo), e = lo + golden * (hi - lo), fc = den(m, d, c), fe = den(m, d, e);
  for (int it = 0; it < kGoldenSteps; ++it) {
    if (fc < fe) {
      hi = e, e = c, fe = fc, c = hi - golden * (hi - lo), fc = den(m, d, c);
    } else {
      lo = c, c = e, fc = fe, e = lo + golden * (hi - lo), fe = den(m, d, e);
    }
  }
  w_min = 0.5 * (lo + hi);
  return den(m, d, w_min);
}
/// s |p| / a - min_W |den|: >= 0 where amplitude a is reached at scale s.
double margin(const ModeState& m, double scale, SynthesisDamping d) {
  double w_min = 0;
  return scale * m.force / m.a - min_den(m, d, w_min);
}
/// The positive real W with |den(W)| = g: the real roots of the quartic
/// (w^2 - W^2)^2 + (2 D_v w W + 2 D_h w^2)^2 - g^2, by the companion matrix.
std::vector<double> frequencies(const ModeState& m, SynthesisDamping d, double g) {
  double dv = 0, dh = 0;
  parts(m, d, dv, dh);
  const double w = m.omega, w2 = w * w, bv = 2 * dv * w, bh = 2 * dh * w2;
  // W^4 + c3 W^3 + c2 W^2 + c1 W + c0.
  const double c3 = 0.0, c2 = -2 * w2 + bv * bv, c1 = 2 * bv * bh, c0 = w2 * w2 + bh * bh - g * g;
  Eigen::Matrix4d comp = Eigen::Matrix4d::Zero();
  comp(0, 3) = -c0;
  comp(1, 3) = -c1;
  comp(2, 3) = -c2;
  comp(3, 3) = -c3;
  comp(1, 0) = comp(2, 1) = comp(3, 2) = 1.0;
  const Eigen::EigenSolver<Eigen::Matrix4d> es(comp, false);
  std::vector<double> out;
  for (int i = 0; i < 4; ++i) {
    const std::complex<double> r = es.eigenvalues()[i];
    if (r.real() > 0 && std::abs(r.imag()) <= kRealRoot * w) out.push_back(r.real());
  }
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

SynthesisPeak synthesis_peak(const std::vector<NonlinearModePoint>& mode, double scale, SynthesisDamping damping) {
  SynthesisPeak peak;
  for (std::size_t i = 0; i + 1 < mode.size(); ++i) {
    if (margin(state(mode[i]), scale, damping) >= 0 && margin(state(mode[i + 1]), scale, damping) < 0) {
      double l0 = std::log10(mode[i].amplitude), l1 = std::log10(mode[i + 1].amplitude);
      for (int it = 0; it < kBisections; ++it) {
        const double lm = 0.5 * (l0 + l1);
        (margin(interpolate(mode[i], mode[i + 1], lm), scale, damping) >= 0 ? l0 : l1) = lm;
      }
      const ModeState m = interpolate(mode[i], mode[i + 1], l0);
      double w_min = 0;
      min_den(m, damping, w_min);
      peak.found = true;
      peak.modal_amplitude = m.a;
      peak.amplitude = m.a * m.response;
      peak.frequency_hz = w_min / kTwoPi;
      return peak;
    }
  }
  return peak;
}

std::vector<SynthesisPoint> synthesize(const std::vector<NonlinearModePoint>& mode, double scale,
                                       SynthesisDamping damping) {
  std::vector<SynthesisPoint> lower, upper;
  for (const auto& p : mode) {
    const ModeState m = state(p);
    if (margin(m, scale, damping) < 0) break;  // beyond the peak
    const std::vector<double> w = frequencies(m, damping, scale * m.force / m.a);
    if (w.empty()) continue;
    if (w.size() >= 2) lower.push_back({w.front() / kTwoPi, m.a * m.response, m.a, false});
    upper.push_back({w.back() / kTwoPi, m.a * m.response, m.a, true});
  }
  const SynthesisPeak peak = synthesis_peak(mode, scale, damping);
  std::vector<SynthesisPoint> out(lower.begin(), lower.end());
  if (peak.found) out.push_back({peak.frequency_hz, peak.amplitude, peak.modal_amplitude, false});
  out.insert(out.end(), upper.rbegin(), upper.rend());
  return out;
}

}  // namespace shroudsim::forced
