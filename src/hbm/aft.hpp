#pragma once
// Alternating Frequency/Time transforms between real harmonic coefficients (HarmonicLayout
// order [c0 | c1 s1 | ... | cH sH], one direction) and N equidistant samples of one period,
// theta_l = 2 pi l / N, with FFTW real transforms:
//   u(l) = c0 + sum_n cn cos(n theta_l) + sn sin(n theta_l)                    (to_time)
//   F0 = (1/N) sum_l F(l),  Fn = (2/N) sum_l F(l) exp(-i n theta_l) = Fcn - i Fsn (to_harmonics)
// N >= 2H+1 is required (otherwise harmonics alias); the constructor refuses less.
// Plans are made once per Aft (the FFTW planner is serialised by a mutex) and executed on
// per-thread Workspace buffers (fftw_execute_dft_* is thread-safe), so one Aft serves any
// number of threads, each with its own Workspace.
#include <Eigen/Core>
#include <memory>

namespace shroudsim::hbm {

struct AftOptions {
  int n_time_samples = 512;   ///< N per period; a power of two keeps FFTW fast
  bool measure_plans = true;  ///< FFTW_MEASURE (slower planning, faster transforms) or ESTIMATE
};

class Aft {
 public:
  /// Scratch buffers of one thread (FFTW-aligned). Not shared between threads.
  class Workspace {
   public:
    explicit Workspace(int n_time_samples);
    ~Workspace();
    Workspace(const Workspace&) = delete;
    Workspace& operator=(const Workspace&) = delete;
    double* real() { return real_; }
    double* spectrum() { return spectrum_; }  ///< N/2+1 complex numbers, interleaved

   private:
    double* real_ = nullptr;
    double* spectrum_ = nullptr;
  };

  /// Throws std::invalid_argument unless n_harmonics >= 0 and N >= 2H+1.
  Aft(int n_harmonics, AftOptions options = {});
  ~Aft();
  Aft(const Aft&) = delete;
  Aft& operator=(const Aft&) = delete;

  int n_harmonics() const { return n_harmonics_; }
  int n_time_samples() const { return n_; }

  /// coeffs: 2H+1 values; samples: N values (may not alias).
  void to_time(const double* coeffs, double* samples, Workspace& ws) const;
  /// samples: N values; coeffs: 2H+1 values.
  void to_harmonics(const double* samples, double* coeffs, Workspace& ws) const;

  /// gram = analysis()^T diag(weights) synthesis(), (2H+1) x (2H+1), from one real FFT of
  /// the N weights (products of cos/sin become sums of frequencies up to 2H < N): the
  /// Fourier projection of a sample-wise diagonal derivative in O(N log N + H^2).
  void weighted_gram(const double* weights, Eigen::Ref<Eigen::MatrixXd> gram, Workspace& ws) const;

  /// N x (2H+1): row l is the basis at theta_l, [1, cos theta_l, sin theta_l, ...], so that
  /// u(l) = synthesis().row(l) * c (the derivative of samples w.r.t. coefficients).
  const Eigen::MatrixXd& synthesis() const { return synthesis_; }
  /// N x (2H+1): to_harmonics as a matrix, c = analysis()^T u (weights 1/N, 2/N).
  const Eigen::MatrixXd& analysis() const { return analysis_; }

 private:
  int n_harmonics_;
  int n_;
  void* plan_c2r_ = nullptr;  // fftw_plan, owned
  void* plan_r2c_ = nullptr;  // fftw_plan, owned
  Eigen::MatrixXd synthesis_, analysis_;
};

}  // namespace shroudsim::hbm
