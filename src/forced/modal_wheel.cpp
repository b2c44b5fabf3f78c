#include "forced/modal_wheel.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>

#include "forced/reduced_equations.hpp"
#include "forced/shooting.hpp"
#include "frf/sector.hpp"

namespace shroudsim::forced {
namespace {

using Complex = std::complex<double>;

/// A mode of a real index is real up to one phase: the largest entry's.
constexpr double kRealModeTolerance = 1e-8;

bool real_index(int g, int nb) { return g == 0 || 2 * g == nb; }

/// Index g's data as index g (conjugated where stored as Nb - g).
struct IndexView {
  const frf::SectorLinearPart::IndexData* data = nullptr;
  bool conjugate = false;
  Complex psi(Eigen::Index row, Eigen::Index r) const {
    const Complex v = data->psi(row, r);
    return conjugate ? std::conj(v) : v;
  }
};

IndexView view(const frf::SectorLinearPart& sector, int g) {
  IndexView v;
  v.data = sector.index_data(g, v.conjugate);
  if (v.data == nullptr)
    throw std::invalid_argument("the wheel in modal coordinates needs the modes of every harmonic index; index " +
                                std::to_string(g) + " has none");
  return v;
}

}  // namespace

ModalWheel modal_wheel(const frf::SectorLinearPart& sector, const std::vector<contact::PairParameters>& pairs,
                       double excitation_scale) {
  ModalWheel w;
  const int nb = sector.sectors(), m = sector.forcing().engine_order;
  const int c = sector.n_contact(), np = c / 3;
  if (static_cast<int>(pairs.size()) != np)
    throw std::invalid_argument("the wheel: " + std::to_string(pairs.size()) + " pair parameters for " +
                                std::to_string(np) + " pairs");
  w.sectors = nb;
  w.engine_order = m;
  const double alpha = 2.0 * std::numbers::pi / nb, zeta = sector.forcing().damping_ratio;
  // The coordinates and the turn of each real mode.
  std::vector<double> omega;
  std::vector<Complex> turns;
  for (int g = 0; 2 * g <= nb; ++g) {
    const IndexView v = view(sector, g);
    for (Eigen::Index r = 0; r < v.data->omega.size(); ++r) {
      Complex turn = 1.0;
      if (real_index(g, nb)) {
        Eigen::Index big = 0;
        v.data->psi.col(r).cwiseAbs().maxCoeff(&big);
        turn = std::polar(1.0, std::arg(v.psi(big, r)));
        double imag = 0.0, size = 0.0;
        for (Eigen::Index row = 0; row < v.data->psi.rows(); ++row) {
          imag = std::max(imag, std::abs((v.psi(row, r) / turn).imag()));
          size = std::max(size, std::abs(v.psi(row, r)));
        }
        if (imag > kRealModeTolerance * size)
          throw std::invalid_argument("the wheel: mode " + std::to_string(r + 1) + " of harmonic index " +
                                      std::to_string(g) + " is not real (" + std::to_string(imag / size) + ")");
      }
      for (int part = 0; part < (real_index(g, nb) ? 1 : 2); ++part) {
        w.coordinates.push_back({g, static_cast<int>(r), part});
        turns.push_back(turn);
        omega.push_back(v.data->omega[r]);
      }
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(w.coordinates.size());
  Eigen::VectorXd mu(n), om = Eigen::Map<const Eigen::VectorXd>(omega.data(), n);
  for (Eigen::Index k = 0; k < n; ++k) mu[k] = real_index(w.coordinates[k].index, nb) ? nb : 2.0 * nb;
  w.system.mass = mu.asDiagonal();
  w.system.stiffness = mu.cwiseProduct(om.cwiseAbs2()).asDiagonal();
  w.system.damping = (2.0 * zeta) * mu.cwiseProduct(om).asDiagonal();
  // Each coordinate's value on sector j of a row of the modes' psi: Re(kappa psi e^{i j g alpha}).
  const auto value = [&](Eigen::Index k, Eigen::Index row, int j, const IndexView& v) {
    const ModalWheel::Coordinate& co = w.coordinates[static_cast<std::size_t>(k)];
    const Complex kappa = real_index(co.index, nb) ? 1.0 / turns[static_cast<std::size_t>(k)]
                                                   : (co.part == 0 ? Complex(2.0) : Complex(0.0, 2.0));
    return (kappa * v.psi(row, co.mode) * std::polar(1.0, j * co.index * alpha)).real();
  };
  w.system.contact_operator.resize(static_cast<Eigen::Index>(nb) * c, n);
  Eigen::VectorXcd z = Eigen::VectorXcd::Zero(n);  // the excitation's work: Re(e^{i w t} z)
  for (Eigen::Index k = 0; k < n; ++k) {
    const IndexView v = view(sector, w.coordinates[static_cast<std::size_t>(k)].index);
    for (int j = 0; j < nb; ++j) {
      for (Eigen::Index row = 0; row < c; ++row)
        w.system.contact_operator(static_cast<Eigen::Index>(j) * c + row, k) = value(k, row, j, v);
      z[k] += std::polar(1.0, j * m * alpha) * value(k, c + 3, j, v);
    }
  }
  w.system.force = excitation_scale * z.real();
  w.system.force_sin = -excitation_scale * z.imag();
  w.pairs.reserve(static_cast<std::size_t>(nb) * pairs.size());
  for (int j = 0; j < nb; ++j) w.pairs.insert(w.pairs.end(), pairs.begin(), pairs.end());
  return w;
}

void modal_wheel_state(const ModalWheel& wheel, const frf::SectorLinearPart& sector, ReducedEquations& equations,
                       contact::Model model, const Eigen::VectorXd& x, double frequency_hz, Eigen::VectorXd& u0,
                       Eigen::VectorXd& v0, Eigen::VectorXd& sliders0) {
  // Every sector's pairs carry the reference pairs' force harmonic n phase-shifted by
  // e^{i j h_n alpha}; the wheel's periodic state under them and the travelling wave.
  const int nb = wheel.sectors, c = sector.n_contact();
  const double alpha = 2.0 * std::numbers::pi / nb;
  std::vector<Eigen::VectorXcd> forces = equations.contact_force_harmonics(x);
  for (std::size_t n = 0; n < forces.size(); ++n) {
    const int g = sector.harmonic_index(static_cast<int>(n));
    Eigen::VectorXcd all(static_cast<Eigen::Index>(nb) * c);
    for (int j = 0; j < nb; ++j)
      all.segment(static_cast<Eigen::Index>(j) * c, c) = forces[n] * std::polar(1.0, j * g * alpha);
    forces[n] = std::move(all);
  }
  periodic_state(wheel.system, wheel.pairs, model, forces, frequency_hz, u0, v0, sliders0);
}

}  // namespace shroudsim::forced
