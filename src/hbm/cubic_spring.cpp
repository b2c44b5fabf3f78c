#include "hbm/cubic_spring.hpp"

#include <stdexcept>

namespace shroudsim::hbm {

CubicSpring::CubicSpring(int n_harmonics, int n_time_samples, std::vector<double> k3)
    : layout_(n_harmonics, 1),
      k3_(std::move(k3)),
      aft_(n_harmonics, AftOptions{n_time_samples, false}),
      ws_(n_time_samples),
      samples_(n_time_samples),
      weights_(n_time_samples) {
  if (k3_.empty()) throw std::invalid_argument("cubic spring: at least one pair");
}

EvaluationStatus CubicSpring::evaluate(const Eigen::VectorXd& w, Eigen::VectorXd& f,
                                       std::vector<Eigen::MatrixXd>* jacobian) {
  const int b = layout_.size();
  if (w.size() != n_unknowns()) throw std::logic_error("cubic spring: wrong number of unknowns");
  f.resize(w.size());
  if (jacobian) jacobian->resize(k3_.size());
  for (int p = 0; p < n_pairs(); ++p) {
    const double k3 = k3_[static_cast<std::size_t>(p)];
    aft_.to_time(w.data() + p * b, samples_.data(), ws_);
    weights_ = 3.0 * k3 * samples_.array().square();
    samples_ = k3 * samples_.array().cube();
    aft_.to_harmonics(samples_.data(), f.data() + p * b, ws_);
    if (jacobian) {
      Eigen::MatrixXd& jp = (*jacobian)[static_cast<std::size_t>(p)];
      jp.resize(b, b);
      aft_.weighted_gram(weights_.data(), jp, ws_);
    }
  }
  return {};
}

}  // namespace shroudsim::hbm
