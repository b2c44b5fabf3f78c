#include "hbm/aft.hpp"

#include <fftw3.h>

#include <cmath>
#include <mutex>
#include <new>
#include <numbers>
#include <stdexcept>
#include <string>

namespace shroudsim::hbm {

namespace {
std::mutex& planner_mutex() {  // the FFTW planner is not thread-safe
  static std::mutex m;
  return m;
}
}  // namespace

Aft::Workspace::Workspace(int n_time_samples) {
  real_ = fftw_alloc_real(static_cast<size_t>(n_time_samples));
  spectrum_ = reinterpret_cast<double*>(fftw_alloc_complex(static_cast<size_t>(n_time_samples / 2 + 1)));
  if (!real_ || !spectrum_) throw std::bad_alloc();
}

Aft::Workspace::~Workspace() {
  fftw_free(real_);
  fftw_free(spectrum_);
}

Aft::Aft(int n_harmonics, AftOptions options) : n_harmonics_(n_harmonics), n_(options.n_time_samples) {
  if (n_harmonics < 0)
    throw std::invalid_argument("Aft: harmonics = " + std::to_string(n_harmonics) + " violates: harmonics >= 0");
  if (n_ < 2 * n_harmonics + 1)
    throw std::invalid_argument("Aft: time_samples = " + std::to_string(n_) +
                                " violates: time_samples >= 2*harmonics+1 (= " + std::to_string(2 * n_harmonics + 1) +
                                ")");
  {
    const std::lock_guard<std::mutex> lock(planner_mutex());
    Workspace ws(n_);
    const unsigned flags = options.measure_plans ? FFTW_MEASURE : FFTW_ESTIMATE;
    auto* spec = reinterpret_cast<fftw_complex*>(ws.spectrum());
    plan_c2r_ = fftw_plan_dft_c2r_1d(n_, spec, ws.real(), flags);
    plan_r2c_ = fftw_plan_dft_r2c_1d(n_, ws.real(), spec, flags);
    if (!plan_c2r_ || !plan_r2c_) throw std::runtime_error("Aft: FFTW planning failed");
  }
  const int m = 2 * n_harmonics + 1;
  synthesis_.resize(n_, m);
  analysis_.resize(n_, m);
  for (int l = 0; l < n_; ++l) {
    synthesis_(l, 0) = 1.0;
    analysis_(l, 0) = 1.0 / n_;
    for (int k = 1; k <= n_harmonics; ++k) {
      // Reduce k*l mod N first: exact phases for large k*l.
      const double th = 2.0 * std::numbers::pi * static_cast<double>((static_cast<long>(k) * l) % n_) / n_;
      synthesis_(l, 2 * k - 1) = std::cos(th);
      synthesis_(l, 2 * k) = std::sin(th);
      analysis_(l, 2 * k - 1) = 2.0 / n_ * std::cos(th);
      analysis_(l, 2 * k) = 2.0 / n_ * std::sin(th);
    }
  }
}

Aft::~Aft() {
  const std::lock_guard<std::mutex> lock(planner_mutex());
  fftw_destroy_plan(static_cast<fftw_plan>(plan_c2r_));
  fftw_destroy_plan(static_cast<fftw_plan>(plan_r2c_));
}

void Aft::to_time(const double* coeffs, double* samples, Workspace& ws) const {
  const int nc = n_ / 2 + 1;
  double* s = ws.spectrum();
  for (int i = 0; i < 2 * nc; ++i) s[i] = 0.0;
  s[0] = coeffs[0];
  for (int k = 1; k <= n_harmonics_; ++k) {  // U_k = (ck - i sk)/2, Hermitian half
    s[2 * k] = 0.5 * coeffs[2 * k - 1];
    s[2 * k + 1] = -0.5 * coeffs[2 * k];
  }
  fftw_execute_dft_c2r(static_cast<fftw_plan>(plan_c2r_), reinterpret_cast<fftw_complex*>(s), ws.real());
  for (int l = 0; l < n_; ++l) samples[l] = ws.real()[l];
}

void Aft::to_harmonics(const double* samples, double* coeffs, Workspace& ws) const {
  double* r = ws.real();
  for (int l = 0; l < n_; ++l) r[l] = samples[l];
  double* s = ws.spectrum();
  fftw_execute_dft_r2c(static_cast<fftw_plan>(plan_r2c_), r, reinterpret_cast<fftw_complex*>(s));
  const double inv = 1.0 / n_;
  coeffs[0] = s[0] * inv;
  for (int k = 1; k <= n_harmonics_; ++k) {
    coeffs[2 * k - 1] = 2.0 * inv * s[2 * k];
    coeffs[2 * k] = -2.0 * inv * s[2 * k + 1];
  }
}

void Aft::weighted_gram(const double* weights, Eigen::Ref<Eigen::MatrixXd> gram, Workspace& ws) const {
  double* r = ws.real();
  for (int l = 0; l < n_; ++l) r[l] = weights[l];
  double* s = ws.spectrum();
  fftw_execute_dft_r2c(static_cast<fftw_plan>(plan_r2c_), r, reinterpret_cast<fftw_complex*>(s));
  // S(f) = sum_l w(l) exp(-i f theta_l); C(f) = sum w cos(f theta) = Re S, Sn(f) = sum w sin = -Im S.
  auto re = [&](int f) {
    f = f < 0 ? -f : f;
    return f <= n_ / 2 ? s[2 * f] : s[2 * (n_ - f)];
  };
  auto sn = [&](int f) {
    const double sign = f < 0 ? -1.0 : 1.0;
    f = f < 0 ? -f : f;
    const double im = f <= n_ / 2 ? s[2 * f + 1] : -s[2 * (n_ - f) + 1];
    return -sign * im;
  };
  const int m = 2 * n_harmonics_ + 1;
  for (int k = 0; k < m; ++k) {
    const int a = (k + 1) / 2;
    const bool ksin = k > 0 && k % 2 == 0;
    const double wk = (k == 0 ? 1.0 : 2.0) / n_;
    for (int j = 0; j < m; ++j) {
      const int b = (j + 1) / 2;
      const bool jsin = j > 0 && j % 2 == 0;
      double v;
      if (!ksin && !jsin) v = 0.5 * (re(a - b) + re(a + b));
      else if (ksin && jsin) v = 0.5 * (re(a - b) - re(a + b));
      else if (ksin) v = 0.5 * (sn(a + b) + sn(a - b));
      else v = 0.5 * (sn(a + b) - sn(a - b));
      gram(k, j) = wk * v;
    }
  }
}

}  // namespace shroudsim::hbm
