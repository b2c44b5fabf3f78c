#include "forced/reduced_equations.hpp"

#include <Eigen/LU>
#include <cmath>
#include <numbers>

#include "core/error.hpp"

namespace shroudsim::forced {
namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;

/// max over theta of |Re sum_n U_n exp(i n theta)|: sampled on `samples` points, then the
/// best sample refined by golden-section search (the sampled maximum alone is low by up to
/// 1 - cos(pi / samples)).
double peak_norm(const std::vector<Eigen::VectorXcd>& u, int samples) {
  auto norm_at = [&](double theta) {
    Eigen::VectorXd ut = u[0].real();
    for (std::size_t n = 1; n < u.size(); ++n)
      ut += (u[n] * std::exp(std::complex<double>(0.0, static_cast<double>(n) * theta))).real();
    return ut.norm();
  };
  double best = -1.0, best_theta = 0.0;
  for (int l = 0; l < samples; ++l) {
    const double theta = kTwoPi * l / samples, v = norm_at(theta);
    if (v > best) best = v, best_theta = theta;
  }
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = best_theta - kTwoPi / samples, b = best_theta + kTwoPi / samples;
  double c = b - golden * (b - a), d = a + golden * (b - a), fc = norm_at(c), fd = norm_at(d);
  for (int it = 0; it < 60; ++it) {
    if (fc > fd) {
      b = d, d = c, fd = fc, c = b - golden * (b - a), fc = norm_at(c);
    } else {
      a = c, c = d, fc = fd, d = a + golden * (b - a), fd = norm_at(d);
    }
  }
  return std::max({best, fc, fd});
}
}  // namespace

ReducedEquations::ReducedEquations(const frf::LinearPart& linear, hbm::ContactEvaluator& contacts)
    : linear_(linear), contacts_(contacts), n_directions_(contacts.pair_layout().n_directions()) {
  SHROUDSIM_CHECK(linear.n_contact() == 3 * contacts.n_pairs(), "one linear contact triple per contact pair");
}

int ReducedEquations::index(int pair, int direction, int harmonic, bool sine) const {
  return pair * contacts_.pair_layout().size() +
         contacts_.pair_layout().index(direction, harmonic,
                                       sine ? hbm::HarmonicLayout::Part::sine : hbm::HarmonicLayout::Part::cosine);
}

Eigen::VectorXcd ReducedEquations::complex_harmonic(const Eigen::VectorXd& v, int n) const {
  Eigen::VectorXcd z = Eigen::VectorXcd::Zero(linear_.n_contact());
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    for (int d = 0; d < n_directions_; ++d)
      z[3 * p + d] = n == 0 ? std::complex<double>(v[index(p, d, 0, false)], 0.0)
                            : std::complex<double>(v[index(p, d, n, false)], -v[index(p, d, n, true)]);
  return z;
}

void ReducedEquations::assemble(double frequency_hz, Eigen::MatrixXd& g, Eigen::VectorXd* w_lin,
                                std::vector<frf::HarmonicReceptance>* receptances) const {
  const int size = contacts_.size(), pairs = contacts_.n_pairs(), h = contacts_.pair_layout().n_harmonics();
  const double w = kTwoPi * frequency_hz;
  g.setZero(size, size);
  if (w_lin) w_lin->setZero(size);
  if (receptances) receptances->resize(h + 1);
  frf::HarmonicReceptance rec;
  for (int n = 0; n <= h; ++n) {
    linear_.harmonic(n, w, rec);
    for (int p = 0; p < pairs; ++p)
      for (int d = 0; d < n_directions_; ++d) {
        const int ci = 3 * p + d;
        if (w_lin) {
          if (n == 0) {
            (*w_lin)[index(p, d, 0, false)] = rec.w_lin[ci].real();
          } else {
            (*w_lin)[index(p, d, n, false)] = rec.w_lin[ci].real();
            (*w_lin)[index(p, d, n, true)] = -rec.w_lin[ci].imag();
          }
        }
        for (int q = 0; q < pairs; ++q)
          for (int e = 0; e < n_directions_; ++e) {
            const std::complex<double> gij = rec.G(ci, 3 * q + e);
            if (n == 0) {
              g(index(p, d, 0, false), index(q, e, 0, false)) = gij.real();
            } else {
              const int ic = index(p, d, n, false), is = index(p, d, n, true);
              const int jc = index(q, e, n, false), js = index(q, e, n, true);
              g(ic, jc) = gij.real();
              g(ic, js) = gij.imag();
              g(is, jc) = -gij.imag();
              g(is, js) = gij.real();
            }
          }
      }
    if (receptances) (*receptances)[n] = rec;
  }
}

bool ReducedEquations::evaluate(const Eigen::VectorXd& w, double frequency_hz, Eigen::VectorXd& r,
                                Eigen::MatrixXd* J, Eigen::VectorXd*) {
  if (!w.allFinite() || !std::isfinite(frequency_hz) || frequency_hz <= 0) return false;
  Eigen::MatrixXd g;
  Eigen::VectorXd w_lin;
  assemble(frequency_hz, g, &w_lin);
  contacts_.evaluate(w, f_, J ? &blocks_ : nullptr);
  r = w - excitation_scale_ * w_lin + g * f_;
  if (J) {
    const int block = contacts_.pair_layout().size();
    J->setIdentity(size(), size());
    for (int p = 0; p < contacts_.n_pairs(); ++p)
      J->middleCols(p * block, block).noalias() += g.middleCols(p * block, block) * blocks_[static_cast<std::size_t>(p)];
  }
  return r.allFinite() && (!J || J->allFinite());
}

Eigen::VectorXd ReducedEquations::linear_motion(double frequency_hz) const {
  Eigen::MatrixXd g;
  Eigen::VectorXd w_lin;
  assemble(frequency_hz, g, &w_lin);
  return w_lin;
}

Eigen::VectorXd ReducedEquations::stuck_solution(double frequency_hz) const {
  Eigen::MatrixXd g;
  Eigen::VectorXd w_lin;
  assemble(frequency_hz, g, &w_lin);
  // Stuck, closed contacts: F = Kc W + F_pre (F_pre: the preload in the static normal term).
  const int size = contacts_.size(), block = contacts_.pair_layout().size(), per = contacts_.pair_layout().per_direction();
  Eigen::VectorXd kc = Eigen::VectorXd::Zero(size), f_pre = Eigen::VectorXd::Zero(size);
  for (int p = 0; p < contacts_.n_pairs(); ++p) {
    const auto& pp = contacts_.pairs()[static_cast<std::size_t>(p)];
    for (int d = 0; d < n_directions_; ++d) {
      const bool normal = n_directions_ == 3 && d == 2;
      kc.segment(p * block + d * per, per).setConstant(normal ? pp.normal_stiffness : pp.tangential_stiffness);
    }
    if (n_directions_ == 3) f_pre[index(p, 2, 0, false)] = std::max(0.0, pp.normal_preload);
  }
  Eigen::MatrixXd a = g * kc.asDiagonal();
  a.diagonal().array() += 1.0;
  return Eigen::PartialPivLU<Eigen::MatrixXd>(a).solve(excitation_scale_ * w_lin - g * f_pre);
}

namespace {

/// r(W, s) = W - s W_lin + G F(W) at a fixed frequency: lambda is the excitation scale.
class ExcitationHomotopy : public continuation::ParametricResidual {
 public:
  ExcitationHomotopy(ReducedEquations& eq, double frequency_hz) : eq_(eq), frequency_hz_(frequency_hz) {}
  int size() const override { return eq_.size(); }
  bool has_lambda_derivative() const override { return true; }
  bool evaluate(const Eigen::VectorXd& w, double s, Eigen::VectorXd& r, Eigen::MatrixXd* J,
                Eigen::VectorXd* dl) override {
    eq_.set_excitation_scale(s);
    const bool ok = eq_.evaluate(w, frequency_hz_, r, J, nullptr);
    if (dl) *dl = -lin_;
    return ok;
  }
  Eigen::VectorXd lin_;

 private:
  ReducedEquations& eq_;
  double frequency_hz_;
};

}  // namespace

continuation::Branch ReducedEquations::solve_by_excitation_homotopy(double frequency_hz,
                                                                    const continuation::ArclengthOptions& options,
                                                                    Eigen::VectorXd& w) {
  ExcitationHomotopy homotopy(*this, frequency_hz);
  homotopy.lin_ = linear_motion(frequency_hz);
  continuation::ArclengthOptions o = options;
  o.lambda_start = 0.0;
  o.lambda_end = 1.0;
  o.lambda_scale = 1.0;
  o.initial_step = 0.05;
  o.max_step = 4.0;
  o.max_points = std::min(o.max_points, 2000);  // a start that needs more is not worth waiting for
  o.start_slack = 1.0;  // the path may fold back through s < 0 (the excitation reversed)
  const double saved = excitation_scale_;
  excitation_scale_ = 0.0;
  const Eigen::VectorXd start = stuck_solution(frequency_hz);
  continuation::Branch b = continuation::trace(homotopy, start, o);
  excitation_scale_ = saved;
  if (b.status == continuation::BranchStatus::kReachedEnd) w = b.points.back().x;
  return b;
}

PointResult ReducedEquations::analyse(const Eigen::VectorXd& w, double frequency_hz, int time_points) {
  PointResult res;
  res.frequency_hz = frequency_hz;
  const int h = contacts_.pair_layout().n_harmonics();
  const hbm::EvaluationStatus status = contacts_.evaluate(w, f_, nullptr);
  res.unconverged_pairs = status.unconverged_pairs;
  const double omega = kTwoPi * frequency_hz;
  std::vector<frf::HarmonicReceptance> rec;
  Eigen::MatrixXd g;
  assemble(frequency_hz, g, nullptr, &rec);
  std::vector<Eigen::VectorXcd> u(h + 1), forces(h + 1);
  res.harmonic_amplitudes.resize(h + 1);
  for (int n = 0; n <= h; ++n) {
    forces[n] = complex_harmonic(f_, n);
    u[n] = rec[n].u_lin - rec[n].H * forces[n];
    res.harmonic_amplitudes[n] = u[n].norm();
  }
  // max over one period of |u(t)|, u(t) = Re sum_n U_n exp(i n theta).
  res.amplitude = peak_norm(u, time_points);
  if (h >= 1) {  // free response: harmonic 1 only, no contact forces
    std::vector<Eigen::VectorXcd> free = {Eigen::VectorXcd::Zero(rec[1].u_lin.size()), rec[1].u_lin};
    res.linear_amplitude = peak_norm(free, time_points);
  }
  linear_.energy(omega, forces, res.excitation_work, res.viscous_dissipation);
  const int block = contacts_.pair_layout().size();
  for (int p = 0; p < contacts_.n_pairs(); ++p)
    res.contact_dissipation +=
        hbm::dissipated_energy(contacts_.pair_layout(), w.segment(p * block, block), f_.segment(p * block, block));
  const double scale = std::max({std::abs(res.excitation_work), res.viscous_dissipation, std::abs(res.contact_dissipation)});
  res.energy_error = scale > 0 ? std::abs(res.excitation_work - res.viscous_dissipation - res.contact_dissipation) / scale : 0.0;
  return res;
}

}  // namespace shroudsim::forced
