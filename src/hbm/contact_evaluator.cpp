#include "hbm/contact_evaluator.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numbers>
#include <stdexcept>

#include "contact/jenkins.hpp"
#include "core/error.hpp"

#ifdef SHROUDSIM_HBM_OPENMP
#include <omp.h>
#endif

namespace shroudsim::hbm {

std::string to_string(JacobianMethod method) {
  switch (method) {
    case JacobianMethod::analytic: return "analytic";
    case JacobianMethod::finite_difference: return "finite_difference";
    case JacobianMethod::finite_difference_full: return "finite_difference_full";
  }
  return "unknown";
}

bool ContactEvaluatorOptions::validate(std::vector<std::string>* errors) const {
  bool valid = true;
  auto fail = [&](const std::string& m) {
    valid = false;
    if (errors) errors->push_back(m);
  };
  if (n_harmonics < 0) fail("harmonics = " + std::to_string(n_harmonics) + " violates: harmonics >= 0");
  if (law.model == contact::Model::one_d_exact) {
    if (n_harmonics != 1)
      fail("harmonics = " + std::to_string(n_harmonics) +
           " violates: harmonics = 1 for model 1d_exact (single-harmonic closed form)");
  } else if (n_harmonics >= 0 && n_time_samples < 2 * n_harmonics + 1) {
    fail("time_samples = " + std::to_string(n_time_samples) +
         " violates: time_samples >= 2*harmonics+1 (= " + std::to_string(2 * n_harmonics + 1) + ")");
  }
  if (!(std::isfinite(fd_relative_step) && fd_relative_step > 0.0 && fd_relative_step < 1.0))
    fail("fd_relative_step violates: 0 < fd_relative_step < 1");
  if (threads < 0) fail("threads = " + std::to_string(threads) + " violates: threads >= 0");
  if (!law.validate(errors)) valid = false;
  return valid;
}

struct ContactEvaluator::Workspace {
  Workspace(int n, int p, contact::LawOptions law) : fft(n), law(law) {
    w.setZero(n, 3);
    f.setZero(n, 3);
    weights.setZero(n);
    wp.setZero(p);
    fp.setZero(p);
    fm.setZero(p);
  }
  Aft::Workspace fft;
  contact::PeriodicLaw law;
  Eigen::MatrixX3d w, f;
  contact::LinearizedPeriod lin;
  Eigen::VectorXd weights;
  Eigen::MatrixXd gram, gathered;
  Eigen::VectorXd wp, fp, fm;
};

ContactEvaluator::ContactEvaluator(const ContactEvaluatorOptions& options, std::vector<contact::PairParameters> pairs)
    : options_(options),
      pairs_(std::move(pairs)),
      layout_(std::max(options.n_harmonics, 0), contact::n_directions(options.law.model)) {
  std::vector<std::string> errors;
  if (!options_.validate(&errors)) throw std::invalid_argument("hbm.ContactEvaluator: " + errors[0]);
  for (size_t i = 0; i < pairs_.size(); ++i) {
    if (!pairs_[i].validate(options_.law.model, &errors))
      throw std::invalid_argument("contact pair " + std::to_string(i) + ": " + errors[0]);
  }
  const bool closed_form = options_.law.model == contact::Model::one_d_exact;
  const int n = closed_form ? 1 : options_.n_time_samples;
  if (!closed_form)
    aft_ = std::make_unique<Aft>(options_.n_harmonics,
                                 AftOptions{.n_time_samples = n, .measure_plans = options_.measure_plans});
  int threads = 1;
#ifdef SHROUDSIM_HBM_OPENMP
  threads = options_.threads > 0 ? options_.threads : omp_get_max_threads();
#endif
  threads = std::max(1, std::min<int>(threads, std::max<int>(1, static_cast<int>(pairs_.size()))));
  contact::LawOptions law = options_.law;
  if (closed_form) law.model = contact::Model::one_d;  // the time law is unused then
  for (int t = 0; t < threads; ++t) workspaces_.push_back(std::make_unique<Workspace>(n, layout_.size(), law));
}

ContactEvaluator::~ContactEvaluator() = default;

Eigen::VectorXcd ContactEvaluator::static_load() const {
  Eigen::VectorXcd f = Eigen::VectorXcd::Zero(3 * n_pairs());
  if (layout_.n_directions() != 3) return f;
  for (int p = 0; p < n_pairs(); ++p) {
    const auto& pp = pairs_[static_cast<std::size_t>(p)];
    if (pp.preload_in_equilibrium) f[3 * p + 2] = std::max(0.0, pp.normal_preload);
  }
  return f;
}

double ContactEvaluator::rest_displacement() const {
  double d = 0.0;
  for (const auto& pp : pairs_) {
    if (pp.tangential_stiffness > 0.0)
      d = std::max(d, pp.friction_coefficient * std::abs(pp.normal_preload) / pp.tangential_stiffness);
    if (pp.normal_stiffness > 0.0) d = std::max(d, std::abs(pp.normal_preload) / pp.normal_stiffness);
  }
  return std::isfinite(d) ? d : 0.0;
}

void ContactEvaluator::to_time(const double* w, Workspace& ws) {
  const int m = layout_.per_direction();
  ws.w.setZero();
  for (int j = 0; j < layout_.n_directions(); ++j) aft_->to_time(w + j * m, ws.w.col(j).data(), ws.fft);
}

contact::PeriodicStatus ContactEvaluator::residual(int pair, const double* w, double* f, Workspace& ws) {
  const contact::PairParameters& pp = pairs_[pair];
  if (options_.law.model == contact::Model::one_d_exact) {
    const auto h = contact::jenkins_single_harmonic(pp.tangential_stiffness,
                                                    pp.friction_coefficient * pp.normal_preload, w[0], w[1], w[2]);
    f[0] = h.f0;
    f[1] = h.fc;
    f[2] = h.fs;
    return {true, 1};
  }
  to_time(w, ws);
  const auto status = ws.law.evaluate(pp, ws.w, ws.f);
  const int m = layout_.per_direction();
  for (int j = 0; j < layout_.n_directions(); ++j) aft_->to_harmonics(ws.f.col(j).data(), f + j * m, ws.fft);
  return status;
}

contact::PeriodicStatus ContactEvaluator::analytic(int pair, const double* w, double* f, Eigen::MatrixXd& jac,
                                                   Workspace& ws) {
  const contact::PairParameters& pp = pairs_[pair];
  const int s = layout_.size();
  jac.resize(s, s);
  if (options_.law.model == contact::Model::one_d_exact) {
    const auto h = contact::jenkins_single_harmonic(pp.tangential_stiffness,
                                                    pp.friction_coefficient * pp.normal_preload, w[0], w[1], w[2]);
    f[0] = h.f0;
    f[1] = h.fc;
    f[2] = h.fs;
    jac = h.jacobian;
    return {true, 1};
  }
  to_time(w, ws);
  const auto status = ws.law.evaluate(pp, ws.w, ws.f, &aft_->synthesis(), &ws.lin);
  const int m = layout_.per_direction();
  const int nd = layout_.n_directions();
  const int n = aft_->n_time_samples();
  for (int j = 0; j < nd; ++j) aft_->to_harmonics(ws.f.col(j).data(), f + j * m, ws.fft);
  // dF/dW = A^T dF(l)/dW (A = analysis matrix), projected exactly like the forces, term by
  // term of the compact derivative (contact::LinearizedPeriod):
  //   stick runs: kt A^T diag(stick) E_i  -  kt sum_runs (sum_{l in run} A(l,:))^T X_run
  //   slip rows:  A(rows,:)^T dT(rows)
  //   normal:     kn A^T diag(pressed) E_z
  const Eigen::MatrixXd& a = aft_->analysis();
  const contact::LinearizedPeriod& lin = ws.lin;
  jac.setZero(s, s);
  ws.gram.resize(m, m);
  for (int i = 0; i < std::min(nd, 2); ++i) {
    auto ji = jac.middleRows(i * m, m);
    if (!lin.runs[i].empty()) {
      ws.weights.setZero(n);
      for (const auto& r : lin.runs[i]) ws.weights.segment(r.first, r.last - r.first + 1).setOnes();
      aft_->weighted_gram(ws.weights.data(), ws.gram, ws.fft);
      ji.middleCols(i * m, m) += lin.kt * ws.gram;
      const Eigen::MatrixXd& e = aft_->synthesis();
      for (size_t r = 0; r < lin.runs[i].size(); ++r) {
        const auto& run = lin.runs[i][r];
        const Eigen::RowVectorXd sum = a.middleRows(run.first, run.last - run.first + 1).colwise().sum();
        if (run.anchor < 0) {
          ji.noalias() -= (lin.kt * sum.transpose()) * lin.run_x[i].row(static_cast<Eigen::Index>(r));
        } else {
          if (run.alpha != 0.0)
            ji.middleCols(i * m, m).noalias() -= (lin.kt * run.alpha * sum.transpose()) * e.row(run.anchor);
          if (run.beta != 0.0)
            ji.middleCols(2 * m, m).noalias() -= (lin.kt * run.beta * sum.transpose()) * e.row(run.anchor);
        }
      }
    }
    if (!lin.slip_weight[i].empty()) {  // uncoupled slip: dT_i = weight(l) E_z(l)
      bool any = false;
      for (double v : lin.slip_weight[i]) any = any || v != 0.0;
      if (any) {
        aft_->weighted_gram(lin.slip_weight[i].data(), ws.gram, ws.fft);
        ji.middleCols(2 * m, m) += ws.gram;
      }
    }
    const int rows = static_cast<int>(lin.dense_index[i].size());
    if (rows > 0) {
      if (ws.gathered.rows() != n || ws.gathered.cols() != m) ws.gathered.resize(n, m);  // once
      for (int k = 0; k < rows; ++k) ws.gathered.row(k) = a.row(lin.dense_index[i][k]);
      ji.noalias() += ws.gathered.topRows(rows).transpose() * lin.dense[i].topRows(rows);
    }
  }
  if (nd == 3) {
    for (int l = 0; l < n; ++l) ws.weights[l] = lin.pressed[l] ? 1.0 : 0.0;
    aft_->weighted_gram(ws.weights.data(), ws.gram, ws.fft);
    jac.block(2 * m, 2 * m, m, m) = lin.kn * ws.gram;
  }
  return status;
}

double ContactEvaluator::fd_step(int pair, const double* w, int coefficient) const {
  const contact::PairParameters& pp = pairs_[pair];
  const int m = layout_.per_direction();
  const int dir = coefficient / m;
  double scale = 0.0;
  for (int i = dir * m; i < (dir + 1) * m; ++i) scale = std::max(scale, std::abs(w[i]));
  if (!(scale > 0.0)) {
    scale = dir == 2 ? std::abs(pp.normal_preload) / pp.normal_stiffness
                     : pp.friction_coefficient * std::abs(pp.normal_preload) / pp.tangential_stiffness;
    if (!(scale > 0.0) || !std::isfinite(scale)) {
      for (int i = 0; i < layout_.size(); ++i) scale = std::max(scale, std::abs(w[i]));
      if (!(scale > 0.0)) scale = 1.0;
    }
  }
  return options_.fd_relative_step * scale;
}

contact::PeriodicStatus ContactEvaluator::finite_difference(int pair, const double* w, double* f, Eigen::MatrixXd& jac,
                                                            Workspace& ws) {
  const int s = layout_.size();
  jac.resize(s, s);
  const auto status = residual(pair, w, f, ws);
  for (int c = 0; c < s; ++c) {
    const double h = fd_step(pair, w, c);
    ws.wp = Eigen::Map<const Eigen::VectorXd>(w, s);
    ws.wp[c] = w[c] + h;
    const double hp = ws.wp[c] - w[c];  // the step actually taken (rounding)
    residual(pair, ws.wp.data(), ws.fp.data(), ws);
    ws.wp[c] = w[c] - h;
    const double hm = w[c] - ws.wp[c];
    residual(pair, ws.wp.data(), ws.fm.data(), ws);
    jac.col(c) = (ws.fp - ws.fm) / (hp + hm);
  }
  return status;
}

EvaluationStatus ContactEvaluator::evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                                            std::vector<Eigen::MatrixXd>* jacobian) {
  return evaluate(w, f, jacobian, options_.jacobian);
}

EvaluationStatus ContactEvaluator::evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                                            std::vector<Eigen::MatrixXd>* jacobian, JacobianMethod method) {
  SHROUDSIM_CHECK(w.size() == size(), "ContactEvaluator::evaluate: w has the wrong size");
  if (!w.allFinite()) throw std::invalid_argument("ContactEvaluator::evaluate: non-finite W");
  f.resize(size());
  if (jacobian) jacobian->resize(pairs_.size());
  const int s = layout_.size();
  const int np = n_pairs();
  if (jacobian && method == JacobianMethod::finite_difference_full) {
    // Column c of dF/dW from two evaluations of all pairs with W_c moved by -+h; only the
    // block of c's own pair comes out nonzero (each pair's force depends on its own W).
    const EvaluationStatus status = evaluate(w, f, nullptr, method);
    Eigen::VectorXd wp = w, fp, fm;
    for (int p = 0; p < np; ++p) (*jacobian)[p].resize(s, s);
    for (int c = 0; c < size(); ++c) {
      const int p = c / s, local = c % s;
      const double h = fd_step(p, w.data() + static_cast<std::ptrdiff_t>(p) * s, local);
      wp[c] = w[c] + h;
      const double hp = wp[c] - w[c];
      evaluate(wp, fp, nullptr, method);
      wp[c] = w[c] - h;
      const double hm = w[c] - wp[c];
      evaluate(wp, fm, nullptr, method);
      wp[c] = w[c];
      (*jacobian)[p].col(local) = (fp - fm).segment(static_cast<Eigen::Index>(p) * s, s) / (hp + hm);
    }
    return status;
  }
  std::vector<contact::PeriodicStatus> st(np);
  std::exception_ptr error;
  auto one = [&](int p, Workspace& ws) {
    const double* wp = w.data() + static_cast<std::ptrdiff_t>(p) * s;
    double* fp = f.data() + static_cast<std::ptrdiff_t>(p) * s;
    if (!jacobian) st[p] = residual(p, wp, fp, ws);
    else if (method == JacobianMethod::analytic) st[p] = analytic(p, wp, fp, (*jacobian)[p], ws);
    else st[p] = finite_difference(p, wp, fp, (*jacobian)[p], ws);
  };
  const int threads = static_cast<int>(workspaces_.size());
  if (threads <= 1 || np <= 1) {
    for (int p = 0; p < np; ++p) one(p, *workspaces_[0]);
  } else {
#ifdef SHROUDSIM_HBM_OPENMP
#pragma omp parallel for schedule(dynamic) num_threads(threads)
    for (int p = 0; p < np; ++p) {
      try {
        one(p, *workspaces_[omp_get_thread_num()]);
      } catch (...) {
#pragma omp critical(shroudsim_hbm_error)
        if (!error) error = std::current_exception();
      }
    }
#else
    for (int p = 0; p < np; ++p) one(p, *workspaces_[0]);
#endif
  }
  if (error) std::rethrow_exception(error);
  EvaluationStatus out;
  for (const auto& x : st) {
    if (!x.converged) ++out.unconverged_pairs;
    out.max_periods = std::max(out.max_periods, x.periods);
  }
  return out;
}

std::vector<std::vector<contact::SampleStep>> ContactEvaluator::sample_steps(const Eigen::VectorXd& w) {
  SHROUDSIM_CHECK(options_.law.model != contact::Model::one_d_exact, "sample_steps: 1d_exact is not a recursion");
  SHROUDSIM_CHECK(w.size() == size(), "sample_steps: w has the wrong size");
  if (!w.allFinite()) throw std::invalid_argument("ContactEvaluator::sample_steps: non-finite W");
  Workspace& ws = *workspaces_[0];
  std::vector<std::vector<contact::SampleStep>> out(pairs_.size());
  for (int p = 0; p < n_pairs(); ++p) {
    to_time(w.data() + static_cast<Eigen::Index>(p) * layout_.size(), ws);
    ws.law.sample_steps(pairs_[static_cast<std::size_t>(p)], ws.w, ws.f, out[static_cast<std::size_t>(p)]);
  }
  return out;
}

void ContactEvaluator::evaluate_pair(int pair, const Eigen::VectorXd& w_pair, PairDetail& d, bool with_jacobian) {
  SHROUDSIM_CHECK(pair >= 0 && pair < n_pairs(), "evaluate_pair: no such pair");
  SHROUDSIM_CHECK(w_pair.size() == layout_.size(), "evaluate_pair: w has the wrong size");
  if (!w_pair.allFinite()) throw std::invalid_argument("ContactEvaluator::evaluate_pair: non-finite W");
  Workspace& ws = *workspaces_[0];
  d.force.resize(layout_.size());
  if (with_jacobian) {
    d.status = options_.jacobian == JacobianMethod::analytic
                   ? analytic(pair, w_pair.data(), d.force.data(), d.jacobian, ws)
                   : finite_difference(pair, w_pair.data(), d.force.data(), d.jacobian, ws);  // (either FD)
  } else {
    d.jacobian.resize(0, 0);
    d.status = residual(pair, w_pair.data(), d.force.data(), ws);
  }
  if (options_.law.model == contact::Model::one_d_exact) {
    // Time-continuous law sampled at N points for the loops.
    const int n = std::max(options_.n_time_samples, 3);
    const auto& pp = pairs_[pair];
    d.w.setZero(n, 3);
    d.f.setZero(n, 3);
    for (int l = 0; l < n; ++l) {
      const double th = 2.0 * std::numbers::pi * l / n;
      d.w(l, 0) = w_pair[0] + w_pair[1] * std::cos(th) + w_pair[2] * std::sin(th);
      d.f(l, 0) = contact::jenkins_force(pp.tangential_stiffness, pp.friction_coefficient * pp.normal_preload,
                                         w_pair[0], w_pair[1], w_pair[2], th);
    }
    return;
  }
  // The time histories of the evaluation above: recompute the (cheap) steady period.
  to_time(w_pair.data(), ws);
  ws.law.evaluate(pairs_[pair], ws.w, ws.f);
  d.w = ws.w;
  d.f = ws.f;
}

double dissipated_energy(const HarmonicLayout& layout, const Eigen::VectorXd& w, const Eigen::VectorXd& f) {
  SHROUDSIM_CHECK(w.size() == layout.size() && f.size() == layout.size(), "dissipated_energy sizes");
  double e = 0.0;
  const int m = layout.per_direction();
  for (int j = 0; j < layout.n_directions(); ++j) {
    for (int n = 1; n <= layout.n_harmonics(); ++n) {
      const double c = w[j * m + 2 * n - 1], s = w[j * m + 2 * n];
      const double fc = f[j * m + 2 * n - 1], fs = f[j * m + 2 * n];
      e += std::numbers::pi * n * (fc * s - fs * c);
    }
  }
  return e;
}

}  // namespace shroudsim::hbm
